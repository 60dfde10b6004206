"""What happens at impact: restitution formulas, classical and Dirac-delta impact
models, and impacts as a linear complementarity problem with Poisson's law."""

if __name__ != "multimass.impact_models":  # one import name (a linked folder)
    raise ImportError(
        f"this folder installs as `multimass.impact_models`; import that, not "
        f"`{__name__}` (is the repository's root on sys.path before site-packages?)"
    )

import importlib

from .models import Classical, DiracDelta, ImpactModel, Transition
from .restitution import housner_eta, modified_eta, r_h
from .sources import (
    AngularMomentumRestitution,
    CornerRestitution,
    DrawnRestitution,
    EmpiricalRestitution,
    FixedRestitution,
    HousnerRestitution,
    ImpactContext,
    ModifiedRestitution,
    RandomRestitution,
    Restitution,
)
from .table2 import IMPACT_MODELS, TABLE_2, impact_model, restitution_source

__all__ = [
    "LCPError",
    "LCPSolution",
    "PoissonImpact",
    "lemke",
    "poisson_impact",
    "AngularMomentumRestitution",
    "Classical",
    "CornerRestitution",
    "DiracDelta",
    "DrawnRestitution",
    "EmpiricalRestitution",
    "FixedRestitution",
    "HousnerRestitution",
    "ImpactContext",
    "ImpactModel",
    "ModifiedRestitution",
    "RandomRestitution",
    "Restitution",
    "TABLE_2",
    "IMPACT_MODELS",
    "Transition",
    "housner_eta",
    "impact_model",
    "modified_eta",
    "r_h",
    "restitution_source",
]

#: Names of the LCP and Poisson's law, imported at their first use (~7 ms that the runs
#: with another impact model do not pay).
_LAZY = {
    "LCPError": ".complementarity",
    "LCPSolution": ".complementarity",
    "lemke": ".complementarity",
    "PoissonImpact": ".poisson",
    "poisson_impact": ".poisson",
}


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name], __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
