"""Where a coefficient of restitution comes from, impact by impact.

Every source is a small frozen dataclass with one method,
``value(ctx) -> float``, where `ctx` is an `ImpactContext`: the structure,
the corner about to be hit (the new pivot), the current elastic
displacements, the index of this impact and the run's random generator.
Sources hold no run state, so one source can drive many simulations; the
engine passes a fresh, seeded generator to each run.

Corners: an impact on the **right** corner starts rocking about the right
pivot (θ > 0) and uses paper 001's r̄_er; the left corner uses r̄_el.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from multimass.errors import InputError

from .restitution import housner_eta, modified_eta, r_h

__all__ = [
    "ImpactContext",
    "Restitution",
    "FixedRestitution",
    "CornerRestitution",
    "EmpiricalRestitution",
    "DrawnRestitution",
    "RandomRestitution",
    "AngularMomentumRestitution",
    "HousnerRestitution",
    "ModifiedRestitution",
]


@dataclass(frozen=True)
class ImpactContext:
    """What a restitution source may look at.

    Attributes
    ----------
    structure : multimass.Structure
    side_new : int
        +1 if the right corner is hit (rocking about the right pivot follows), −1 left.
    u : ndarray
        Elastic displacements at impact.
    index : int
        0-based count of restitution values drawn so far in this run.
    rng : numpy.random.Generator
    impact : int
        0-based index of the impact the value is for: the impacts logged so far in
        this run (events of kind "impact"; an impact that ends in full contact is not
        one). A Dirac-delta model draws the value of its next impact when rocking
        starts, so a value drawn at an impact that is followed by full contact and
        uplift is drawn again at the uplift: `index` counts both draws, `impact` is
        the same for both.
    """

    structure: object
    side_new: int
    u: np.ndarray
    index: int
    rng: np.random.Generator
    impact: int


def _is_real(value) -> bool:
    return isinstance(value, numbers.Real)


def _check_r(r: float, what: str) -> float:
    r = float(r)
    if not (math.isfinite(r) and 0.0 < r <= 1.0):
        raise InputError(f"`{what}` = {r!r}: a coefficient of restitution must lie in (0, 1]")
    return r


class Restitution:
    """Base class of restitution sources: subclasses implement `value`."""

    def value(self, ctx: ImpactContext) -> float:  # pragma: no cover - interface
        raise NotImplementedError

    def describe(self) -> dict:
        """Parameters for logs and JSON (nested sources described too)."""

        def plain(v):
            if isinstance(v, Restitution):
                return v.describe()
            if isinstance(v, tuple):
                return [plain(x) for x in v]
            return v

        return {"kind": type(self).__name__, **{k: plain(v) for k, v in vars(self).items()}}


@dataclass(frozen=True)
class FixedRestitution(Restitution):
    """The same r at every impact."""

    r: float

    def __post_init__(self):
        _check_r(self.r, "r")

    def value(self, ctx: ImpactContext) -> float:
        return self.r


@dataclass(frozen=True)
class CornerRestitution(Restitution):
    """Per-corner means (paper 001, Table 1: r̄_er right, r̄_el left)."""

    right: float
    left: float

    def __post_init__(self):
        _check_r(self.right, "right")
        _check_r(self.left, "left")

    def value(self, ctx: ImpactContext) -> float:
        return self.right if ctx.side_new > 0 else self.left


@dataclass(frozen=True)
class EmpiricalRestitution(Restitution):
    """Impact-specific coefficients r_e in impact order, then a fallback.

    Paper 001 (Section 4.3) used impact-specific values for the large
    half-cycles and the per-corner means once they ran out. The k-th value is
    the k-th impact's (`ImpactContext.impact`), whichever impact model draws it
    and whenever; `multimass.identify.restitution` writes such lists.
    """

    values: tuple[float, ...]
    fallback: Restitution

    def __post_init__(self):
        for i, r in enumerate(self.values):
            _check_r(r, f"values[{i}]")

    def value(self, ctx: ImpactContext) -> float:
        if ctx.impact < len(self.values):
            return self.values[ctx.impact]
        return self.fallback.value(ctx)


@dataclass(frozen=True)
class DrawnRestitution(Restitution):
    """Coefficients drawn in advance, per corner: the i-th draw of a run takes
    ``right[i]`` for an impact on the right corner or ``left[i]`` on the left,
    then `fallback` once the tables end.

    A random restitution whose values are known before the run (the synthetic
    traces of `multimass.identify.synthetic` store them as the truth); which entry
    an impact took is in the response's events (``Event.restitution``).

    Attributes
    ----------
    right, left : tuple of float
        One coefficient in (0, 1] per draw, for each corner; equal lengths.
    fallback : Restitution
        The source after the tables (e.g. the per-corner means).
    """

    right: tuple[float, ...]
    left: tuple[float, ...]
    fallback: Restitution

    def __post_init__(self):
        for key in ("right", "left"):
            values = getattr(self, key)
            if isinstance(values, (str, bytes)) or not hasattr(values, "__len__"):
                raise InputError(
                    f"`{key}` = {values!r:.60}: give a sequence of coefficients in (0, 1]"
                )
            bad = next(
                (i for i, r in enumerate(values) if isinstance(r, bool) or not _is_real(r)), None
            )
            if bad is not None:
                raise InputError(
                    f"`{key}[{bad}]` = {values[bad]!r:.60}: give a coefficient of "
                    "restitution in (0, 1] (a number)"
                )
            checked = tuple(_check_r(r, f"{key}[{i}]") for i, r in enumerate(values))
            object.__setattr__(self, key, checked)
        if len(self.right) != len(self.left):
            raise InputError(
                f"`right` has {len(self.right)} values and `left` {len(self.left)}: "
                "give one value per draw for each corner (equal lengths)"
            )
        if not isinstance(self.fallback, Restitution):
            raise InputError(
                f"`fallback` = {self.fallback!r:.60}: give a Restitution, e.g. "
                "CornerRestitution(right, left)"
            )

    def value(self, ctx: ImpactContext) -> float:
        if ctx.index < len(self.right):
            return self.right[ctx.index] if ctx.side_new > 0 else self.left[ctx.index]
        return self.fallback.value(ctx)


@dataclass(frozen=True)
class RandomRestitution(Restitution):
    """Random r per impact from N(mean of the corner, σ), clipped to (0, 1].

    Paper 001, Section 4.4 (DD5). Reproducible: the engine seeds the
    generator per run.
    """

    right: float
    left: float
    sigma: float
    floor: float = 1e-3

    def __post_init__(self):
        _check_r(self.right, "right")
        _check_r(self.left, "left")
        if not (math.isfinite(self.sigma) and self.sigma >= 0.0):
            raise InputError(f"`sigma` = {self.sigma!r}: a standard deviation must be ≥ 0")

    def value(self, ctx: ImpactContext) -> float:
        mean = self.right if ctx.side_new > 0 else self.left
        # min(max(...)) is np.clip of one float, without numpy's per-call overhead
        return float(min(max(float(ctx.rng.normal(mean, self.sigma)), self.floor), 1.0))


@dataclass(frozen=True)
class AngularMomentumRestitution(Restitution):
    """r_h of paper 001, Eq 13, with the current elastic displacements."""

    def value(self, ctx: ImpactContext) -> float:
        s = ctx.structure
        return float(r_h(s.J_p, s.m_t, s.B, s.m, ctx.u, ctx.side_new))


@dataclass(frozen=True)
class HousnerRestitution(Restitution):
    """Housner's η_H = 1 − 1.5 sin²α_cg (paper 004, Eq 9)."""

    def value(self, ctx: ImpactContext) -> float:
        return housner_eta(ctx.structure.alpha_cg)


@dataclass(frozen=True)
class ModifiedRestitution(Restitution):
    """The modified η_M(k) of paper 004, Eq 10."""

    k: float

    def __post_init__(self):
        if not (math.isfinite(self.k) and 0.0 <= self.k <= 1.0):
            raise InputError(f"`k` = {self.k!r}: the impulse position parameter must lie in [0, 1]")

    def value(self, ctx: ImpactContext) -> float:
        return modified_eta(ctx.structure.alpha_cg, self.k)
