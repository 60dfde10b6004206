"""How a rocking structure moves: structures, equations of motion, simulation, sweeps.

The rooms of the package, lowest layer first (each may import only from below it;
``lint-imports`` checks the layers of pyproject.toml):

* `specimens`, `impact_models` — what is simulated, and what happens at impact;
* `model` — the structure, its matrices, kinematics and equations of motion;
* `inputs` — excitations, pulses, records, test traces, units;
* `engines` — the phase loop, Newmark, the contact engine, Moreau–Jean (`engines.nscd`)
  and the compiled kernels (`engines.fast`);
* `simulation` — `simulate`, the one entry point to every engine;
* `analysis`, `modal` — intensity measures, fragility, trace metrics and figures; modal
  analysis of the linearised phases;
* `identify`, `sweeps`, `suites`, `scenes` — test traces back to the model, many runs,
  record suites and fragility, the choice of a model;
* `bench`, `cli` — speed and accuracy benchmarks, the ``multimass`` command.

The root keeps the shared contract: `errors`, `result`, `response`, `validation`,
`progress`, `checks`, `cost` and `simulation_options`. Module paths written before the
rooms (``multimass.fragility``, ``multimass.fast``, …) still import (`multimass._paths`).

>>> import multimass
>>> s1 = multimass.column("S1")
>>> round(s1.J_p)
298
"""

import importlib

from . import _paths

_paths.install()  # the old module paths (multimass.fragility, multimass.fast, ...) keep working

# public name -> the module that defines it; loaded on first use (PEP 562), so that
# `import multimass.specimens` loads no other part of the package
_PUBLIC = {
    "errors": ("InputError", "SolverError"),
    "model.structure": ("Structure", "column", "from_specimen", "rigid_block"),
    "inputs.excitations": (
        "CosinePulse",
        "CosineWave",
        "Excitation",
        "FreeRelease",
        "MPPulse",
        "MPShape",
        "Ricker",
        "SineWave",
    ),
    "inputs.records": ("Record", "read_at2", "read_record", "read_two_column"),
    "inputs.units": ("G", "parse_acceleration", "to_mps2"),
    "result": ("Event", "Result"),
    "response": ("Outcome", "Response"),
    "simulation": ("DEFAULTS", "estimate", "simulate", "simulate_outcome"),
    "simulation_options": ("SimulationOptions",),
    "analysis.trace_metrics": ("ChannelMetrics", "compare_trace"),
    "inputs.traces": ("Trace", "read_trace"),
    "scenes": ("Scene", "choose"),
}
_WHERE = {name: module for module, names in _PUBLIC.items() for name in names}

__all__ = [
    "InputError",
    "SolverError",
    "Structure",
    "column",
    "from_specimen",
    "rigid_block",
    "Excitation",
    "FreeRelease",
    "SineWave",
    "CosineWave",
    "CosinePulse",
    "Ricker",
    "MPPulse",
    "MPShape",
    "Record",
    "read_record",
    "read_two_column",
    "read_at2",
    "G",
    "to_mps2",
    "parse_acceleration",
    "Result",
    "Event",
    "Response",
    "DEFAULTS",
    "SimulationOptions",
    "simulate",
    "simulate_outcome",
    "estimate",
    "Outcome",
    "Trace",
    "ChannelMetrics",
    "read_trace",
    "compare_trace",
    "Scene",
    "choose",
]


def __getattr__(name: str):
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module 'multimass' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value  # later lookups skip __getattr__
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
