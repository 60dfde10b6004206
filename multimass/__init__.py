"""How a rocking structure moves: structures, equations of motion, simulation, sweeps.

>>> import multimass
>>> s1 = multimass.column("S1")
>>> round(s1.J_p)
298
"""

import importlib

# public name -> the module that defines it; loaded on first use (PEP 562), so that
# `import multimass.specimens` loads no other part of the package
_PUBLIC = {
    "errors": ("InputError", "SolverError"),
    "structure": ("Structure", "column", "from_specimen", "rigid_block"),
    "excitations": (
        "CosinePulse",
        "CosineWave",
        "Excitation",
        "FreeRelease",
        "MPPulse",
        "MPShape",
        "Ricker",
        "SineWave",
    ),
    "records": ("Record", "read_at2", "read_record", "read_two_column"),
    "units": ("G", "parse_acceleration", "to_mps2"),
    "result": ("Event", "Result"),
    "response": ("Outcome", "Response"),
    "simulation": ("DEFAULTS", "estimate", "simulate", "simulate_outcome"),
    "simulation_options": ("SimulationOptions",),
    "trace_metrics": ("ChannelMetrics", "compare_trace"),
    "traces": ("Trace", "read_trace"),
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
