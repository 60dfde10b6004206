"""Impact models by name: paper 001's Table 2 (CIM, DD1–DD5) and restitution by name.

>>> from multimass.impact_models.table2 import TABLE_2
>>> TABLE_2["DD2"]
('dirac', 'mean', 1750.0)
"""

from __future__ import annotations

import math

from multimass.errors import InputError

from .models import Classical, DiracDelta, ImpactModel
from .sources import (
    AngularMomentumRestitution,
    CornerRestitution,
    EmpiricalRestitution,
    FixedRestitution,
    HousnerRestitution,
    ModifiedRestitution,
    RandomRestitution,
    Restitution,
)

__all__ = ["TABLE_2", "IMPACT_MODELS", "RESTITUTION_NAMES", "impact_model", "restitution_source"]

#: Paper 001, Table 2: model, coefficients of restitution, C_p (kg m/rad/s).
TABLE_2 = {
    "CIM": ("classical", "empirical", None),
    "DD1": ("dirac", "empirical", 1750.0),
    "DD2": ("dirac", "mean", 1750.0),
    "DD3": ("dirac", "empirical", 3000.0),
    "DD4": ("dirac", "empirical", 1000.0),
    "DD5": ("dirac", "random", 1750.0),
}

#: Every impact model by name: Table 2's six, "DD" (Dirac-delta; restitution and C_p as
#: given, else the means and 1750) and "LCP" (Poisson's law, paper 000, with eps_p).
IMPACT_MODELS = TABLE_2 | {"DD": ("dirac", "mean", 1750.0), "LCP": ("poisson", None, None)}

RESTITUTION_NAMES = ("mean", "empirical", "random", "r_h", "housner", "modified")


def _spec_restitution(specimen, key: str):
    """Per-corner data of a column specimen, or raise naming what is missing."""
    value = getattr(specimen, key, None)
    if value is None:
        kind = getattr(specimen, "kind", type(specimen).__name__)
        raise InputError(
            f"restitution needs `{key}`, which a {kind!r} specimen does not have; "
            "give `restitution` explicitly (a value, 'housner' or 'modified')"
        )
    return value


def restitution_source(restitution, specimen=None, k: float | None = None) -> Restitution:
    """A restitution source from a name, a number or a source object.

    Parameters
    ----------
    restitution : str, float or Restitution
        "mean" (per-corner means of the specimen), "empirical" (the
        specimen's impact-specific list, then the means), "random"
        (N(mean, σ_r) per impact), "r_h" (paper 001, Eq 13), "housner"
        (η_H, paper 004 Eq 9), "modified" (η_M(k), paper 004 Eq 10), a
        number in (0, 1], or a `Restitution` instance.
    specimen : specimen object, optional
        Supplies the per-corner means, σ_r, the empirical list, or k.
    k : float, optional
        k of η_M; default: the block specimen's k.
    """
    if isinstance(restitution, Restitution):
        return restitution
    if isinstance(restitution, (int, float)) and not isinstance(restitution, bool):
        return FixedRestitution(float(restitution))
    if isinstance(restitution, str):
        name = restitution.strip().lower()
        try:
            return FixedRestitution(float(name))
        except ValueError:
            pass
        if name == "mean":
            return CornerRestitution(
                _spec_restitution(specimen, "r_right"), _spec_restitution(specimen, "r_left")
            )
        if name == "empirical":
            means = restitution_source("mean", specimen)
            return EmpiricalRestitution(tuple(_spec_restitution(specimen, "r_empirical")), means)
        if name == "random":
            return RandomRestitution(
                _spec_restitution(specimen, "r_right"),
                _spec_restitution(specimen, "r_left"),
                _spec_restitution(specimen, "sigma_r"),
            )
        if name == "r_h":
            return AngularMomentumRestitution()
        if name == "housner":
            return HousnerRestitution()
        if name == "modified":
            kk = k if k is not None else getattr(specimen, "k", None)
            if kk is None:
                raise InputError(
                    "`k` is needed for the modified restitution (paper 004, Eq 10): "
                    "give k or use a block specimen, which carries one"
                )
            return ModifiedRestitution(float(kk))
    raise InputError(
        f"`restitution` = {restitution!r}: use a number in (0, 1], one of "
        f"{', '.join(RESTITUTION_NAMES)}, or a Restitution object"
    )


def impact_model(
    impact,
    specimen=None,
    restitution=None,
    k: float | None = None,
    C_p: float | None = None,
    eps_p: float | None = None,
) -> ImpactModel:
    """An impact model from a Table 2 name, "CIM"/"DD" with options, or a model.

    Parameters
    ----------
    impact : str or ImpactModel
        "CIM", "DD1" … "DD5" (paper 001, Table 2), "DD" (Dirac-delta with
        `restitution` and `C_p`), "LCP" (Poisson's law, paper 000, with
        `eps_p`), or an `ImpactModel` instance (returned as is).
    specimen : specimen object, optional
        Supplies the restitution data of Table 2's configurations.
    restitution : optional
        Overrides Table 2's restitution (see `restitution_source`).
    k, C_p : float, optional
        k for "modified"; C_p overrides Table 2's value.
    eps_p : float, optional
        Poisson's coefficient ε_P of the "LCP" model (default 0).

    Raises
    ------
    ValueError
        For an unknown name (the message lists the known ones).
    """
    if isinstance(impact, ImpactModel):
        return impact
    if not isinstance(impact, str):
        raise InputError(
            f"`impact` = {impact!r}: give a name ({', '.join(TABLE_2)}, DD) or an ImpactModel"
        )
    name = impact.strip().upper()
    if name not in IMPACT_MODELS:
        raise InputError(
            f"`impact` = {impact!r}: unknown impact model; use one of "
            f"{', '.join(TABLE_2)} (paper 001, Table 2), DD, LCP, or an ImpactModel object"
        )
    kind, rest_name, cp = IMPACT_MODELS[name]
    if kind == "poisson":
        from .lcp_model import PoissonLCP  # with its LCP solver: imported by LCP runs only

        return PoissonLCP(eps_p=0.0 if eps_p is None else float(eps_p))
    if eps_p is not None:
        raise InputError(f"`eps_p` = {eps_p!r} applies to impact='LCP' only (got {impact!r})")
    if restitution is None and getattr(specimen, "kind", None) == "block":
        restitution = "modified"  # paper 004: η_M(k) with the block's k
    source = restitution_source(rest_name if restitution is None else restitution, specimen, k)
    if kind == "classical":
        return Classical(source, name=name)
    cp = cp if C_p is None else float(C_p)
    if not (math.isfinite(cp) and cp > 0):
        raise InputError(f"`C_p` = {C_p!r}: must be a positive number (kg m/rad/s)")
    return DiracDelta(source, C_p=cp, name=name)
