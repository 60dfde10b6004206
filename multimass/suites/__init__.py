"""Record suites and fragility: many motions, intensities and restitution draws (issue 16).

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

from .analysis import (
    exceedance_counts,
    fragility_curves,
    ida_curves,
    ida_summary,
    im_efficiency,
    pulse_fragility,
    summary_dict,
)
from .report import write_report
from .runs import SuiteMismatch, SuiteRuns, run_suite
from .spec import Distribution, PulseSet, Suite

__all__ = [
    "Suite",
    "PulseSet",
    "Distribution",
    "run_suite",
    "SuiteRuns",
    "SuiteMismatch",
    "exceedance_counts",
    "fragility_curves",
    "im_efficiency",
    "ida_curves",
    "ida_summary",
    "pulse_fragility",
    "summary_dict",
    "write_report",
]
