"""Rigid bodies at rest: when does the ground motion lift them (paper 004; paper 001, Eq 8)."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["next_uplift", "uplift_threshold"]

_EPS = np.finfo(float).eps


def uplift_threshold(st) -> float:
    """|ü_g| above which a rigid body at rest starts to rock: g B m_t / (Hᵀ M 1 + m0 h0).

    For a block this is g tan α (paper 004, Section 2).
    """
    return st.g * st.B * st.m_t / (float(st.m @ st.H) + st.m0 * st.h0)


def next_uplift(st, ag, t0: float, t1: float, step: float = 1e-3, margin: float = 0.05):
    """First time in [t0, t1] at which a rigid body at rest uplifts, and the pivot.

    Uplift about the right pivot needs ü_g < −a_th, about the left ü_g > a_th
    (paper 001, Eq 8 with no elastic motion). |ü_g| is sampled every `step`
    seconds (vectorised); a local maximum of the samples within `margin` below
    the threshold is refined by a bounded scalar search, so an exceedance
    shorter than the step is not missed; the crossing is then located by
    Brent's method.

    Returns
    -------
    (t, side) or None
    """
    a_th = uplift_threshold(st)
    if t1 <= t0:
        return None
    grid = np.linspace(t0, t1, max(3, int(math.ceil((t1 - t0) / step)) + 1))
    a = np.abs(np.asarray(ag(grid), dtype=float))
    if a[0] > a_th:
        return float(grid[0]), (-1 if float(ag(grid[0])) > 0 else 1)
    over = np.nonzero(a > a_th)[0]
    first = int(over[0]) if over.size else a.size
    # local maxima before the first sampled exceedance, close to the threshold
    inner = np.arange(1, min(first, a.size - 1))
    near = inner[
        (a[inner] >= a[inner - 1]) & (a[inner] >= a[inner + 1]) & (a[inner] > (1.0 - margin) * a_th)
    ]
    for j in near:
        from scipy.optimize import minimize_scalar  # here: only a near miss needs SciPy

        lo, hi = grid[j - 1], grid[j + 1]
        best = minimize_scalar(
            lambda t: -abs(float(ag(t))),
            bounds=(lo, hi),
            method="bounded",
            options={"xatol": 1e-12},
        )
        if -best.fun > a_th:
            return _crossing(ag, a_th, lo, float(best.x))
    if not over.size:
        return None
    return _crossing(ag, a_th, grid[first - 1], grid[first])


def _crossing(ag, a_th, lo, hi):
    """The time in [lo, hi] where |ü_g| rises through a_th, and the pivot it lifts about."""
    from scipy.optimize import brentq  # here: only a crossing needs SciPy

    side = -1 if float(ag(hi)) > 0 else 1
    f = lambda t: side * -float(ag(t)) - a_th  # > 0 once uplifted about `side`
    return brentq(f, lo, hi, xtol=1e-13, rtol=4 * _EPS), side
