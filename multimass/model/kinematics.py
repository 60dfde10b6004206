"""Energies, momenta and moments of the multi-mass structure (paper 001, Sections 2.2–2.4).

The structure-level API over the expressions of `multimass.model.equations`.

Geometry (paper 001, Fig 1; see `multimass.model.structure`): while rocking about
pivot s (+1 right, −1 left), a node at body coordinates (u_i, H_i) sits at
X = (u_i − sB) cos θ + H_i sin θ, Y = −(u_i − sB) sin θ + H_i cos θ from the
pivot; node 0 at (0, h0). Energies are relative to the rest state (θ = 0,
u = 0) and measured in the ground's (accelerating) frame, where the ground
motion acts as the effective force −m ü_g on every mass.
"""

from __future__ import annotations

import math

import numpy as np

from . import equations as eq
from .structure import Structure

__all__ = [
    "kinetic_energy",
    "gravitational_energy",
    "elastic_energy",
    "total_energy",
    "ground_power",
    "angular_momentum_new_pivot",
    "full_contact_moments",
    "uplift_margin",
]


def kinetic_energy(st: Structure, side: int, u, udot, thetadot) -> float:
    """T = ½ q̇ᵀ A q̇ with A the rocking mass matrix (½ u̇ᵀMu̇ in full contact)."""
    u, udot = np.asarray(u, dtype=float), np.asarray(udot, dtype=float)
    ud_m_ud = float(udot @ (st.m * udot)) if st.n else 0.0
    if side == 0:
        return eq.kinetic_energy(ud_m_ud, 0.0, 0.0, 0.0)
    smu, umu = _sums(st, u)
    a_tt = eq.rocking_inertia(st.J_p, umu, side, st.B, smu)
    h_m_ud = float(udot @ (st.m * st.H)) if st.n else 0.0
    return float(eq.kinetic_energy(ud_m_ud, h_m_ud, a_tt, thetadot))


def gravitational_energy(st: Structure, side: int, u, theta) -> float:
    """V_g − V_g(rest) = g Σ m ΔY (zero in full contact, where θ = 0)."""
    if side == 0:
        return 0.0
    lever = eq.lever_arm(side, st.B, st.m_t, _sums(st, u)[0])
    return float(
        eq.gravitational_energy(st.g, st.static_moment, lever, np.cos(theta), np.sin(theta))
    )


def elastic_energy(st: Structure, u) -> float:
    """U = ½ uᵀ K u."""
    return 0.5 * float(u @ (st.K @ u)) if st.n else 0.0


def total_energy(st: Structure, side: int, u, theta, udot, thetadot) -> float:
    """T + V_g + U relative to rest (E_ini of paper 001, Eqs 14–15) of one state.

    The sum of `kinetic_energy`, `gravitational_energy` and `elastic_energy`, with
    the node sums formed once (every transition and activation calls it).
    """
    # a.dot(b) is a @ b (the same BLAS ddot / dgemv) with less per-call overhead
    n = st.n
    if n:
        u, udot = np.asarray(u, dtype=float), np.asarray(udot, dtype=float)
        m_ud = st.m * udot
        ud_m_ud, elastic = float(udot.dot(m_ud)), 0.5 * float(u.dot(st.K.dot(u)))
    else:
        ud_m_ud = elastic = 0.0
    if side == 0:
        return eq.kinetic_energy(ud_m_ud, 0.0, 0.0, 0.0) + elastic
    smu, umu = _sums(st, u)
    h_m_ud = float(st.H.dot(m_ud)) if n else 0.0
    a_tt = eq.rocking_inertia(st.J_p, umu, side, st.B, smu)
    lever = eq.lever_arm(side, st.B, st.m_t, smu)
    theta = float(theta)
    kinetic = eq.kinetic_energy(ud_m_ud, h_m_ud, a_tt, float(thetadot))
    grav = eq.gravitational_energy(st.g, st.static_moment, lever, math.cos(theta), math.sin(theta))
    return float(kinetic + grav + elastic)


def ground_power(st: Structure, side: int, u, theta, udot, thetadot, ag: float) -> float:
    """Power of the effective ground forces, −ü_g Σ m Ẋ (horizontal relative velocities)."""
    m_ud = float(st.m @ udot) if st.n else 0.0
    if side == 0:
        return float(eq.ground_power(ag, m_ud, 0.0, 0.0, 0.0, 1.0, 0.0))
    lever = eq.lever_arm(side, st.B, st.m_t, _sums(st, u)[0])
    c, sn = np.cos(theta), np.sin(theta)
    return float(eq.ground_power(ag, m_ud, thetadot, st.static_moment, lever, c, sn))


def angular_momentum_new_pivot(st: Structure, u, udot, thetadot) -> float:
    """Angular momentum at θ = 0 about the impending pivot, in the sense of θ.

    L_p = Hᵀ M u̇ + θ̇ (J_p − 2 m_t B² + uᵀ M u) (`equations.pivot_momentum`):
    the same for either side (paper 001, Eq 9's L_p^r and Eq 16's L'_p; with
    θ̇ = 0 it is the full contact L_p^fc of Eq 8; the θ̇ coefficient is the
    numerator of Eq 13).
    """
    h_m_ud = float(st.H.dot(st.m * np.asarray(udot, dtype=float))) if st.n else 0.0
    umu = _sums(st, u)[1]
    return float(eq.pivot_momentum(h_m_ud, thetadot, st.J_p, st.m_t, st.B, umu))


def full_contact_moments(st: Structure, u, udot, ag: float) -> tuple[float, float, float]:
    """Overturning moment M_o and restoring moments about each pivot (paper 001, Eq 8).

    M_o = Hᵀ M (ü + 1 ü_g) + m0 h0 ü_g is the moment of the inertia of the
    full-contact motion (Eq 3); M_res(±) = g (m_t B ∓ 1ᵀ M u). Uplift about
    the right pivot needs −M_o > M_res(+), about the left M_o > M_res(−).

    Returns
    -------
    (M_o, M_res_right, M_res_left)
    """
    h_m_acc = 0.0
    if st.n:
        uddot = eq.full_contact_acceleration(st.C @ udot, st.K @ u, st.m, ag)
        h_m_acc = float(st.H @ (st.m * (uddot + ag)))
    M_o = eq.overturning_moment(h_m_acc, st.m0 * st.h0, ag)
    smu = _sums(st, u)[0]
    right, left = (eq.restoring_moment(s, st.g, st.m_t, st.B, smu) for s in (1.0, -1.0))
    return float(M_o), float(right), float(left)


def uplift_margin(st: Structure, side: int, u, udot, ag: float, m_ref: float, l_ref: float):
    """Both uplift conditions about pivot `side` as one value, positive once they hold.

    `equations.uplift_margin` of this state's moments and full-contact momentum
    L_p^fc, scaled by `m_ref` (a moment) and `l_ref` (an angular momentum).
    """
    M_o, right, left = full_contact_moments(st, u, udot, ag)
    L = angular_momentum_new_pivot(st, u, udot, 0.0)  # L_p^fc
    return eq.uplift_margin(side, M_o, right if side > 0 else left, L, m_ref, l_ref)


def _sums(st: Structure, u) -> tuple[float, float]:
    """1ᵀMu and uᵀMu."""
    if not st.n:
        return 0.0, 0.0
    u = np.asarray(u, dtype=float)
    mu = st.m * u
    # np.add.reduce is mu.sum() (the same reduction) without its Python wrapper
    return float(np.add.reduce(mu, axis=None)), float(u.dot(mu))
