"""Rigid bodies at rest: when does the ground motion lift them (paper 004; paper 001, Eq 8)."""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

__all__ = ["next_uplift", "uplift_threshold"]


def uplift_threshold(st) -> float:
    """|ü_g| above which a rigid body at rest starts to rock: g B m_t / (Hᵀ M 1 + m0 h0).

    For a block this is g tan α (paper 004, Section 2).
    """
    return st.g * st.B * st.m_t / (float(st.m @ st.H) + st.m0 * st.h0)


def next_uplift(st, ag, t0: float, t1: float, step: float = 1e-4):
    """First time in [t0, t1] at which a rigid body at rest uplifts, and the pivot.

    Uplift about the right pivot needs ü_g < −a_th, about the left ü_g > a_th
    (paper 001, Eq 8 with no elastic motion). The excitation is sampled every
    `step` seconds (vectorised) and the crossing refined by Brent's method.

    Returns
    -------
    (t, side) or None
    """
    a_th = uplift_threshold(st)
    if t1 <= t0:
        return None
    grid = np.linspace(t0, t1, max(2, int(math.ceil((t1 - t0) / step)) + 1))
    a = np.asarray(ag(grid), dtype=float)
    over = np.abs(a) > a_th
    if not over.any():
        return None
    i = int(np.argmax(over))
    side = -1 if a[i] > 0 else 1
    if i == 0:
        return float(grid[0]), side
    f = lambda t: side * -float(ag(t)) - a_th         # > 0 once uplifted about `side`
    return brentq(f, grid[i - 1], grid[i], xtol=1e-13, rtol=4 * np.finfo(float).eps), side
