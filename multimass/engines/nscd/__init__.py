"""Event-capturing Moreau–Jean time stepping of a rigid block rocking on a
finite-element beam (paper 002, Mudrić et al. 2024).

>>> import math
>>> from multimass import nscd
>>> res = nscd.simulate("B6M", theta0=math.radians(11.268), dt=1e-4, t_end=0.6)
>>> res.status
'completed'
"""

from .fe_beam import BeamModel, build_beam
from .model import System, build_system, flexible_modulus, min_modulus
from .result import NSCDResult
from .run import estimate_cost, run_system, simulate

__all__ = [
    "BeamModel",
    "NSCDResult",
    "System",
    "build_beam",
    "build_system",
    "estimate_cost",
    "flexible_modulus",
    "min_modulus",
    "run_system",
    "simulate",
]
