"""How a rocking structure moves: structures, equations of motion, simulation, sweeps.

>>> import multimass
>>> s1 = multimass.column("S1")
>>> round(s1.J_p)
298
"""

from .errors import InputError, SolverError
from .structure import Structure, column, from_specimen, rigid_block
from .excitations import (CosinePulse, CosineWave, Excitation, FreeRelease, Ricker,
                          SineWave)
from .records import Record, read_at2, read_record, read_two_column
from .units import G, parse_acceleration, to_mps2
from .response import Event, Response
from .simulate import DEFAULTS, Outcome, estimate, simulate, simulate_outcome
from .trace_metrics import ChannelMetrics, compare_trace
from .traces import Trace, read_trace
from .scenes import Scene, choose

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
    "Record",
    "read_record",
    "read_two_column",
    "read_at2",
    "G",
    "to_mps2",
    "parse_acceleration",
    "Event",
    "Response",
    "DEFAULTS",
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
