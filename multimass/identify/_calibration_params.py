"""The parameters `multimass.identify.calibrate` fits: names, bounds, steps and starts.

* `PARAMETERS` — the fittable names, their default bounds and how they are stepped;
* `parameter_set` — the fit list, start values and bounds checked and laid out;
* `model_of` — the impact model's Table 2 name, checked.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from multimass.impact_models.table2 import IMPACT_MODELS, TABLE_2

from .. import validation as v
from ..errors import InputError

__all__ = [
    "Parameter", "PARAMETERS", "ParameterSet", "parameter_set", "model_of", "default_fit",
    "checked_given",
]  # fmt: skip


@dataclass(frozen=True)
class Parameter:
    """A fittable model parameter.

    ``log`` parameters are fitted as their logarithm (C_p and the damping ratios
    span decades and must stay > 0); `step` is the forward-difference step of the
    Jacobian in those fitted units (a restitution step of 2e-4, a 0.2 % step of C_p),
    `scale` the size of a typical change (the trust region's unit).
    """

    name: str
    what: str
    low: float
    high: float
    log: bool
    step: float
    scale: float
    hard: tuple  # the range any bound given by the user must stay in

    def to_x(self, value: float) -> float:
        return math.log(value) if self.log else float(value)

    def to_value(self, x: float) -> float:
        return math.exp(x) if self.log else float(x)


#: The fittable parameters: name → `Parameter` (bounds are the defaults).
PARAMETERS = {
    "r_er": Parameter(
        "r_er", "mean restitution of impacts on the right corner, r̄_er (paper 001 Table 1)",
        0.3, 1.0, False, 2e-4, 5e-3, (0.01, 1.0),
    ),
    "r_el": Parameter(
        "r_el", "mean restitution of impacts on the left corner, r̄_el (paper 001 Table 1)",
        0.3, 1.0, False, 2e-4, 5e-3, (0.01, 1.0),
    ),
    "cp": Parameter(
        "cp", "C_p of the Dirac-delta impact force, kg m/rad/s (paper 001 Eq 15)",
        50.0, 1e5, True, 2e-3, 0.05, (1.0, 1e7),
    ),
    "zeta1": Parameter(
        "zeta1", "Rayleigh damping of full-contact mode 1, fraction of critical",
        1e-4, 0.2, True, 5e-3, 0.1, (1e-6, 1.0),
    ),
    "zeta2": Parameter(
        "zeta2", "Rayleigh damping of full-contact mode 2, fraction of critical",
        1e-4, 0.2, True, 5e-3, 0.1, (1e-6, 1.0),
    ),
}  # fmt: skip
_SPEC_FIELD = {"r_er": "r_right", "r_el": "r_left", "zeta1": "zeta_1", "zeta2": "zeta_2"}
_IMPACTS = tuple(TABLE_2) + ("DD",)


@dataclass(frozen=True)
class ParameterSet:
    """The model's five parameters: which are fitted, where they start, their bounds."""

    fit: tuple  # fitted names, in the order given
    start: dict  # name -> value, all five
    bounds: dict  # name -> (low, high), the fitted ones

    def physical(self, x: Sequence[float]) -> dict:
        """All five values, with the fitted ones from the fitted units `x`."""
        out = dict(self.start)
        for name, xi in zip(self.fit, x):
            out[name] = PARAMETERS[name].to_value(xi)
        return out

    def x0(self) -> np.ndarray:
        return np.array([PARAMETERS[n].to_x(self.start[n]) for n in self.fit], dtype=float)

    def x_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        lo = [PARAMETERS[n].to_x(self.bounds[n][0]) for n in self.fit]
        hi = [PARAMETERS[n].to_x(self.bounds[n][1]) for n in self.fit]
        return np.array(lo), np.array(hi)

    def steps(self) -> np.ndarray:
        return np.array([PARAMETERS[n].step for n in self.fit])


def model_of(impact) -> str:
    """The upper-case Table 2 name of `impact` (CIM, DD1 … DD5, DD), or InputError."""
    if not isinstance(impact, str) or impact.strip().upper() not in _IMPACTS:
        known = ", ".join(_IMPACTS)
        if isinstance(impact, str) and impact.strip().upper() in IMPACT_MODELS:
            raise InputError(
                f"`impact` = {impact!r}: calibration fits the restitution of CIM and the "
                f"Dirac-delta models; Poisson's law has none. Use one of {known}"
            )
        raise InputError(
            f"`impact` = {impact!r}: give an impact model of paper 001 Table 2 by name: {known}"
        )
    return impact.strip().upper()


def _fit_names(fit, impact: str) -> tuple:
    if isinstance(fit, str):
        fit = [s.strip() for s in fit.split(",") if s.strip()]
    if not isinstance(fit, (list, tuple)) or not fit:
        raise InputError(
            f"`fit` = {fit!r}: give the parameters to fit, some of {', '.join(PARAMETERS)} "
            "(e.g. ('r_er', 'r_el', 'cp'))"
        )
    names = []
    for name in fit:
        key = name.strip().lower().replace("-", "_") if isinstance(name, str) else name
        key = {"c_p": "cp", "zeta_1": "zeta1", "zeta_2": "zeta2"}.get(key, key)
        if key not in PARAMETERS:
            raise InputError(
                f"`fit` names {name!r}, which is not a parameter calibrate can fit; "
                f"use some of {', '.join(PARAMETERS)}"
            )
        if key in names:
            raise InputError(f"`fit` names {key!r} twice; name each parameter once")
        names.append(key)
    if "cp" in names and impact == "CIM":
        raise InputError(
            "`fit` includes 'cp' but `impact` = 'CIM': the classical impact model has no "
            "C_p (paper 001 Table 2); fit cp with a Dirac-delta model (DD2, DD, ...) or "
            "drop it from the fit"
        )
    return tuple(names)


def _checked_value(name: str, value, lo: float, hi: float, label: str) -> float:
    return v.number(label, value, low=lo, high=hi, what=PARAMETERS[name].what)


def default_fit(impact: str, given=None) -> tuple:
    """Every parameter of the model that is not `given`: the restitution means, C_p
    (not for CIM, which has none) and the damping ratios."""
    given = given or {}
    return tuple(n for n in PARAMETERS if n not in given and not (n == "cp" and impact == "CIM"))


def checked_given(given, impact: str, spec) -> dict:
    """The parameters the user gave (name → value), each checked against its hard range;
    InputError naming the field otherwise (C_p with CIM, an unknown name)."""
    if given is None:
        return {}
    if not isinstance(given, Mapping):
        raise InputError(f"`given` = {given!r:.60}: give a mapping of parameter name to value")
    out = {}
    for key, value in given.items():
        name = key.strip().lower().replace("-", "_") if isinstance(key, str) else key
        name = {"c_p": "cp", "zeta_1": "zeta1", "zeta_2": "zeta2"}.get(name, name)
        if name not in PARAMETERS:
            raise InputError(
                f"`given` names {key!r}, not a parameter; use some of {', '.join(PARAMETERS)}"
            )
        if name == "cp" and impact == "CIM":
            raise InputError(
                "`given` has 'cp', but the classical impact model (CIM) has no C_p (paper "
                "001 Table 2); remove it or choose a Dirac-delta model"
            )
        out[name] = _checked_value(name, value, *PARAMETERS[name].hard, f"given[{key!r}]")
    return out


def parameter_set(fit, impact: str, spec, start=None, bounds=None, given=None) -> ParameterSet:
    """The checked fit list, start values (the `given` ones, else the specimen's and
    Table 2's unless `start` gives them) and bounds (the defaults of `PARAMETERS` unless
    given)."""
    given = checked_given(given, impact, spec)
    names = _fit_names(default_fit(impact, given) if fit is None else fit, impact)
    both = [n for n in names if n in given]
    if both:
        raise InputError(
            f"`fit` has {', '.join(both)}, which `given` also gives; a parameter is either "
            "given (used as it is) or fitted: drop it from one of them"
        )
    values = {n: float(getattr(spec, f)) for n, f in _SPEC_FIELD.items()}
    cp = TABLE_2.get(impact, (None, None, 1750.0))[2]
    values["cp"] = float(cp) if cp is not None else float("nan")
    for label, mapping in (("start", start), ("bounds", bounds)):
        if mapping is not None and not isinstance(mapping, Mapping):
            raise InputError(
                f"`{label}` = {mapping!r:.60}: give a mapping of parameter name to value"
            )
        for key in mapping or {}:
            if key not in PARAMETERS:
                raise InputError(
                    f"`{label}` names {key!r}, not a parameter; use some of {', '.join(PARAMETERS)}"
                )
    box = {}
    for n in names:
        p = PARAMETERS[n]
        lo, hi = p.low, p.high
        if bounds and n in bounds:
            pair = bounds[n]
            if not (isinstance(pair, (list, tuple)) and len(pair) == 2):
                raise InputError(f"`bounds[{n!r}]` = {pair!r}: give (low, high)")
            lo = _checked_value(n, pair[0], *p.hard, f"bounds[{n!r}][0]")
            hi = _checked_value(n, pair[1], *p.hard, f"bounds[{n!r}][1]")
            if not lo < hi:
                raise InputError(
                    f"`bounds[{n!r}]` = {pair!r}: the low bound must be below the high"
                )
        box[n] = (lo, hi)
    for n, value in (start or {}).items():
        if n == "cp" and impact == "CIM":
            raise InputError("`start` gives 'cp', but the classical impact model (CIM) has no C_p")
        lo, hi = box.get(n, PARAMETERS[n].hard)
        values[n] = _checked_value(n, value, lo, hi, f"start[{n!r}]")
    values.update(given)
    for n in names:
        lo, hi = box[n]
        if not lo <= values[n] <= hi:
            raise InputError(
                f"the start value of {n!r}, {values[n]:g}, lies outside its bounds "
                f"[{lo:g}, {hi:g}]; give `start` or `bounds`"
            )
    return ParameterSet(names, values, box)
