"""Equations of motion of the full-contact and rocking phases (paper 001, Eqs 3–5, 7).

Phase codes: ``0`` full contact, ``+1`` rocking about the right pivot (θ > 0),
``-1`` rocking about the left pivot (θ < 0). In paper 001's ± notation the
upper sign is the right pivot, so ``s = phase`` replaces ± and ∓ = −s.

Node 0 may carry its mass at a height h0 above the pivots (h0 = 0 in paper
001; h0 = h/2 for a rigid block, which makes Eq 5 Housner's equation, paper
004 Eqs 1–2). Its terms follow from the same Lagrangian.
"""

from __future__ import annotations

import numpy as np

from .structure import Structure

__all__ = [
    "full_contact_accelerations",
    "rocking_system",
    "rocking_accelerations",
    "solve_rocking",
    "total_accelerations",
]


def full_contact_accelerations(structure: Structure, u, udot, ag: float) -> np.ndarray:
    """ü of the full-contact phase: M ü + C u̇ + K u = −M 1 ü_g (paper 001, Eq 3)."""
    s = structure
    return -(s.C @ udot + s.K @ u) / s.m - ag  # paper 001, Eq 3 (M is diagonal)


def rocking_system(
    structure: Structure,
    side: int,
    u,
    theta: float,
    udot,
    thetadot: float,
    ag: float,
    F_i: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Mass matrix A and forcing b of the rocking phase: A [ü; θ̈] = b.

    Parameters
    ----------
    structure : Structure
    side : {+1, -1}
        Current pivot: +1 right, −1 left (paper 001's upper / lower sign).
    u, udot : ndarray, shape (N,)
        Elastic displacements and velocities.
    theta, thetadot : float
        Base rotation and its rate.
    ag : float
        Ground acceleration ü_g (m/s²).
    F_i : float
        Dirac-delta impact force (paper 001, Eq 14), acting with the lever arm 2B.

    Returns
    -------
    A : ndarray, shape (N+1, N+1)
        Symmetric mass matrix [[M, M H], [Hᵀ M, J_p + uᵀMu ∓ 2B 1ᵀMu]].
    b : ndarray, shape (N+1,)
        Everything else, moved to the right-hand side of Eqs 4–5.
    """
    st, sg = structure, float(side)
    n, m, H, B, g = st.n, st.m, st.H, st.B, st.g
    c, sn = np.cos(theta), np.sin(theta)
    mu = m * u
    arm = m * (sg * B - u)  # M(±B1 − u)
    A = np.empty((n + 1, n + 1))
    b = np.empty(n + 1)
    if n:
        A[:n, :n] = np.diag(m)
        A[:n, n] = m * H
        A[n, :n] = m * H
        # paper 001, Eq 4
        b[:n] = -arm * thetadot**2 - st.C @ udot - st.K @ u - m * (ag * c - g * sn)
    A[n, n] = st.J_p + u @ mu - 2.0 * sg * B * mu.sum()
    lever = sg * (B * m.sum() - sg * mu.sum()) + sg * st.m0 * B  # ±1ᵀM(B1 ∓ u) ± m0 B
    height = m @ H + st.m0 * st.h0  # Hᵀ M 1 (+ m0 h0)
    # paper 001, Eq 5 (all terms but the inertia moved to the right)
    b[n] = (
        2.0 * sg * (udot @ (m * B - sg * mu)) * thetadot
        - 2.0 * B * F_i
        - ag * (height * c + lever * sn)
        - g * (-height * sn + lever * c)
    )
    return A, b


def solve_rocking(
    m: np.ndarray, H: np.ndarray, a_tt: float, b: np.ndarray
) -> tuple[np.ndarray, float]:
    """Solve [[M, M H], [Hᵀ M, a_tt]] [ü; θ̈] = b by the Schur complement (M diagonal).

    θ̈ = (b_θ − Hᵀ b_u) / (a_tt − Hᵀ M H), ü = b_u / m − H θ̈: exact, O(N),
    and the pivot a_tt − HᵀMH = Σ m (u − sB)² + m0 (B² + h0²) + J0 > 0.
    """
    bu = b[:-1]
    thetaddot = (b[-1] - H @ bu) / (a_tt - H @ (m * H))
    return bu / m - H * thetaddot if m.size else bu.copy(), float(thetaddot)


def rocking_accelerations(
    structure: Structure,
    side: int,
    u,
    theta: float,
    udot,
    thetadot: float,
    ag: float,
    F_i: float = 0.0,
) -> tuple[np.ndarray, float]:
    """ü and θ̈ of the rocking phase, solving (not inverting) Eqs 4–5."""
    A, b = rocking_system(structure, side, u, theta, udot, thetadot, ag, F_i)
    return solve_rocking(structure.m, structure.H, A[-1, -1], b)


def total_accelerations(
    structure: Structure, side: int, u, theta, uddot, thetaddot, thetadot, ag
) -> np.ndarray:
    """Total lateral accelerations of nodes 1..N in the direction of u (paper 001, Eq 7).

    a = ü + H θ̈ + (±B1 − u) θ̇² + ü_g cos θ − 1 g sin θ; in full contact
    (``side = 0``, θ = 0) this is ü + ü_g.
    """
    st = structure
    if side == 0:
        return uddot + ag
    return (
        uddot
        + st.H * thetaddot
        + (side * st.B - u) * thetadot**2  # paper 001, Eq 7
        + ag * np.cos(theta)
        - st.g * np.sin(theta)
    )
