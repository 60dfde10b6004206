"""How a rocking structure moves: structures, equations of motion, simulation, sweeps.

>>> import multimass
>>> s1 = multimass.column("S1")
>>> round(s1.J_p)
298
"""

from .errors import InputError, SolverError
from .structure import Structure, column, from_specimen, rigid_block

__all__ = [
    "InputError",
    "SolverError",
    "Structure",
    "column",
    "from_specimen",
    "rigid_block",
]
