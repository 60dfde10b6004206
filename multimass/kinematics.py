"""Energies, momenta and moments of the multi-mass structure (paper 001, Sections 2.2–2.4).

Geometry (paper 001, Fig 1; see `multimass.structure`): while rocking about
pivot s (+1 right, −1 left), a node at body coordinates (u_i, H_i) sits at
X = (u_i − sB) cos θ + H_i sin θ, Y = −(u_i − sB) sin θ + H_i cos θ from the
pivot; node 0 at (0, h0). Energies are relative to the rest state (θ = 0,
u = 0) and measured in the ground's (accelerating) frame, where the ground
motion acts as the effective force −m ü_g on every mass.
"""

from __future__ import annotations

import numpy as np

from .structure import Structure

__all__ = [
    "kinetic_energy",
    "gravitational_energy",
    "elastic_energy",
    "total_energy",
    "ground_power",
    "angular_momentum_new_pivot",
    "full_contact_moments",
]


def kinetic_energy(st: Structure, side: int, u, udot, thetadot) -> float:
    """T = ½ q̇ᵀ A q̇ with A the rocking mass matrix (½ u̇ᵀMu̇ in full contact)."""
    T = 0.5 * float(udot @ (st.m * udot)) if st.n else 0.0
    if side == 0:
        return T
    a_tt = st.J_p + float(u @ (st.m * u)) - 2.0 * side * st.B * float(st.m @ u)
    return T + float(thetadot * (udot @ (st.m * st.H))) + 0.5 * a_tt * thetadot**2


def gravitational_energy(st: Structure, side: int, u, theta) -> float:
    """V_g − V_g(rest) = g Σ m ΔY (zero in full contact, where θ = 0)."""
    if side == 0:
        return 0.0
    c, s = np.cos(theta), np.sin(theta)
    height = float(st.m @ st.H) + st.m0 * st.h0
    lever = side * (st.B * st.m_t - side * float(st.m @ u))  # ±(1ᵀM(B1 ∓ u) + m0 B)
    return st.g * (height * (c - 1.0) + lever * s)


def elastic_energy(st: Structure, u) -> float:
    """U = ½ uᵀ K u."""
    return 0.5 * float(u @ (st.K @ u)) if st.n else 0.0


def total_energy(st: Structure, side: int, u, theta, udot, thetadot) -> float:
    """T + V_g + U relative to rest (E_ini of paper 001, Eqs 14–15)."""
    return (
        kinetic_energy(st, side, u, udot, thetadot)
        + gravitational_energy(st, side, u, theta)
        + elastic_energy(st, u)
    )


def ground_power(st: Structure, side: int, u, theta, udot, thetadot, ag: float) -> float:
    """Power of the effective ground forces, −ü_g Σ m Ẋ (horizontal relative velocities)."""
    if side == 0:
        return -ag * float(st.m @ udot) if st.n else 0.0
    c, s = np.cos(theta), np.sin(theta)
    xdot = float(st.m @ (udot * c + thetadot * (st.H * c - (u - side * st.B) * s)))
    xdot += st.m0 * thetadot * (side * st.B * s + st.h0 * c)
    return -ag * xdot


def angular_momentum_new_pivot(st: Structure, u, udot, thetadot) -> float:
    """Angular momentum at θ = 0 about the impending pivot, in the sense of θ.

    L_p = Hᵀ M u̇ + θ̇ (J_p − 2 m_t B² + uᵀ M u): the same for either side
    (paper 001, Eq 9's L_p^r and Eq 16's L'_p; with θ̇ = 0 it is the full
    contact L_p^fc of Eq 8; the θ̇ coefficient is the numerator of Eq 13).
    """
    uMu = float(u @ (st.m * u)) if st.n else 0.0
    hmu = float(st.H @ (st.m * udot)) if st.n else 0.0
    return hmu + thetadot * (st.J_p - 2.0 * st.m_t * st.B**2 + uMu)


def full_contact_moments(st: Structure, u, udot, ag: float) -> tuple[float, float, float]:
    """Overturning moment M_o and restoring moments about each pivot (paper 001, Eq 8).

    M_o = Hᵀ M (ü + 1 ü_g) + m0 h0 ü_g is the moment of the inertia of the
    full-contact motion (Eq 3); M_res(±) = g (m_t B ∓ 1ᵀ M u). Uplift about
    the right pivot needs −M_o > M_res(+), about the left M_o > M_res(−).

    Returns
    -------
    (M_o, M_res_right, M_res_left)
    """
    if st.n:
        uddot = -(st.C @ udot + st.K @ u) / st.m - ag  # paper 001, Eq 3
        M_o = float(st.H @ (st.m * (uddot + ag))) + st.m0 * st.h0 * ag
        mu = float(st.m @ u)
    else:
        M_o, mu = st.m0 * st.h0 * ag, 0.0
    return M_o, st.g * (st.m_t * st.B - mu), st.g * (st.m_t * st.B + mu)
