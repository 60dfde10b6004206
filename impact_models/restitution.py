"""Coefficients of restitution of rocking impacts (paper 004, Eqs 9–10; paper 001, Eq 13)."""

from __future__ import annotations

import math

import numpy as np

from multimass.errors import InputError

__all__ = ["housner_eta", "modified_eta", "r_h"]


def _check_alpha(alpha: float) -> float:
    a = float(alpha)
    if not 0.0 < a < math.pi / 2:
        raise InputError(f"`alpha` = {alpha!r}: the slenderness angle must lie in (0, π/2) rad")
    return a


def housner_eta(alpha: float) -> float:
    """Housner's restitution η_H = 1 − (3/2) sin²α (paper 004, Eq 9)."""
    return 1.0 - 1.5 * math.sin(_check_alpha(alpha)) ** 2  # paper 004, Eq 9


def modified_eta(alpha: float, k: float) -> float:
    """Modified restitution η_M(k) (paper 004, Eq 10; Kalliontzis et al.).

    η_M = (4 − 3 sin²α (1 + k²)) / (4 − 3 sin²α (1 − k²)), with k = b̄/(b/2)
    the position of the contact impulse; k = 1 gives η_H.
    """
    k = float(k)
    if not 0.0 <= k <= 1.0:
        raise InputError(f"`k` = {k!r}: the impulse position parameter must lie in [0, 1]")
    s2 = math.sin(_check_alpha(alpha)) ** 2
    return (4.0 - 3.0 * s2 * (1.0 + k * k)) / (4.0 - 3.0 * s2 * (1.0 - k * k))  # paper 004, Eq 10


def r_h(J_p: float, m_t: float, B: float, M_diag, u, side_new: int) -> float:
    """Restitution from angular momentum about the impacting corner (paper 001, Eq 13).

    r_h = (J_p − 2 m_t B² + uᵀMu) / (J_p ± 2B 1ᵀMu + uᵀMu). "m_l" in the
    paper is the total mass m_t (DESIGN.md). For u = 0 and a uniform block
    this is Housner's 1 − 1.5 sin²α.

    Sign (decided): the denominator must be the θ̇ coefficient of the angular
    momentum about the new pivot after impact, J_p + uᵀMu ∓ 2B 1ᵀMu with ∓
    the new pivot (`side_new` = +1 right, −1 left) — Eq 5's inertia term.
    So Eq 13's ± is the sign of the pivot *before* impact; read with the
    impending pivot it would not conserve angular momentum, which is how the
    paper derives it (tests/impact_models/test_restitution.py).
    """
    m = np.asarray(M_diag, dtype=float)
    u = np.asarray(u, dtype=float)
    uMu = float(u @ (m * u))
    return (J_p - 2.0 * m_t * B * B + uMu) / (
        J_p - side_new * 2.0 * B * float(m @ u) + uMu
    )  # paper 001, Eq 13
