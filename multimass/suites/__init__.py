"""Record suites and fragility: many motions, intensities and restitution draws.

* `spec` — `Suite`: one structure, records and/or M&P pulses, intensity levels in a
  chosen IM, Monte-Carlo restitution draws, seeds; read from TOML and checked;
* `runs` — `run_suite`: every run on the sweep engine, resumable, one row per run;
* `analysis` — fragility curves (lognormal MLE, Baker 2015), IDA, IM efficiency, the
  dimensionless pulse fragility (Dimitrakopoulos & Paraskeva 2015);
* `plots` and `report` — the figures and the files of ``multimass suite``.

Python::

    from multimass.suites import Suite, run_suite, fragility_curves
    suite = Suite.from_toml("examples/suites/S1_records.toml")
    runs = run_suite(suite, out="report/suite_S1").runs
    fragility_curves(runs, im="pga")
"""

import importlib

# public name -> the module that defines it; loaded on first use (PEP 562), so that
# `import multimass.suites.spec` does not load pandas' analysis or matplotlib
_PUBLIC = {
    "spec": ("Suite", "PulseSet", "Distribution"),
    "runs": ("run_suite", "SuiteRuns", "SuiteMismatch"),
    "analysis": (
        "exceedance_counts",
        "fragility_curves",
        "im_efficiency",
        "ida_curves",
        "ida_summary",
        "pulse_fragility",
        "summary_dict",
    ),
    "report": ("write_report",),
}
_WHERE = {name: module for module, names in _PUBLIC.items() for name in names}

__all__ = [name for names in _PUBLIC.values() for name in names]


def __getattr__(name: str):
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module 'multimass.suites' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
