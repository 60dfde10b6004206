"""Equations of motion of the full-contact and rocking phases for a `Structure`.

The structure-level API over `multimass.model.equations` (paper 001, Eqs 3–5, 7):
the mass matrix and forcing of the rocking phase, the accelerations of one
state or of many recorded states at once, and the total node accelerations.

Phase codes: ``0`` full contact, ``+1`` rocking about the right pivot (θ > 0),
``-1`` rocking about the left pivot (θ < 0). In paper 001's ± notation the
upper sign is the right pivot, so ``s = phase`` replaces ± and ∓ = −s.

Node 0 may carry its mass at a height h0 above the pivots (h0 = 0 in paper
001; h0 = h/2 for a rigid block, which makes Eq 5 Housner's equation, paper
004 Eqs 1–2). Its terms follow from the same Lagrangian.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import equations as eq
from .structure import Structure

__all__ = [
    "full_contact_accelerations",
    "rocking_system",
    "rocking_accelerations",
    "solve_rocking",
    "PhaseRows",
    "phase_rows",
    "state_accelerations",
    "total_accelerations",
]


def full_contact_accelerations(structure: Structure, u, udot, ag: float) -> np.ndarray:
    """ü of the full-contact phase: M ü + C u̇ + K u = −M 1 ü_g (`equations.full_contact_acceleration`)."""
    s = structure
    return eq.full_contact_acceleration(s.C @ udot, s.K @ u, s.m, ag)


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
    u, udot = np.asarray(u, dtype=float), np.asarray(udot, dtype=float)
    c, sn = np.cos(theta), np.sin(theta)
    smu = float(m @ u) if n else 0.0
    arm = eq.pivot_arm(sg, B, m, u)
    A = np.empty((n + 1, n + 1))
    b = np.empty(n + 1)
    if n:
        A[:n, :n] = np.diag(m)
        A[:n, n] = m * H
        A[n, :n] = m * H
        b[:n] = eq.rocking_forcing_u(arm, thetadot, st.C @ udot, st.K @ u, m, ag, c, sn, g)
    A[n, n] = eq.rocking_inertia(st.J_p, float(u @ (m * u)) if n else 0.0, sg, B, smu)
    lever = eq.lever_arm(sg, B, st.m_t, smu)
    ud_arm = float(udot @ arm) if n else 0.0
    b[n] = eq.rocking_forcing_theta(thetadot, ud_arm, B, F_i, ag, st.static_moment, lever, c, sn, g)
    return A, b


def solve_rocking(
    m: np.ndarray, H: np.ndarray, a_tt: float, b: np.ndarray
) -> tuple[np.ndarray, float]:
    """Solve [[M, M H], [Hᵀ M, a_tt]] [ü; θ̈] = b by the Schur complement (M diagonal).

    `equations.rocking_theta_acceleration` and `rocking_u_acceleration`: exact, O(N).
    """
    bu = b[:-1]
    thetaddot = eq.rocking_theta_acceleration(b[-1], H @ bu, a_tt, H @ (m * H))
    return eq.rocking_u_acceleration(bu, m, H, thetaddot), float(thetaddot)


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


@dataclass(frozen=True, eq=False)
class PhaseRows:
    """Many states of one phase: their ü and θ̈, and the terms the energies share.

    Attributes
    ----------
    uddot : ndarray, shape (rows, N)
    thetaddot : ndarray, shape (rows,)
        0 in full contact.
    c, sn, smu, umu, lever, a_tt : ndarray, shape (rows,) or None
        cos θ, sin θ, 1ᵀMu, uᵀMu, `equations.lever_arm` and
        `equations.rocking_inertia` of each rocking state; None in full contact.
    """

    uddot: np.ndarray
    thetaddot: np.ndarray
    c: np.ndarray | None = None
    sn: np.ndarray | None = None
    smu: np.ndarray | None = None
    umu: np.ndarray | None = None
    lever: np.ndarray | None = None
    a_tt: np.ndarray | None = None


def phase_rows(st: Structure, side: int, u, theta, udot, thetadot, ag, F_i=0.0) -> PhaseRows:
    """ü and θ̈ of many states of one phase at once (Eq 3 in full contact, Eqs 4–5 rocking).

    Parameters
    ----------
    st : Structure
    side : int
        The phase of every row: 0 full contact, ±1 rocking.
    u, udot : ndarray, shape (rows, N)
        Elastic displacements and velocities.
    theta, thetadot, ag, F_i : float or ndarray, shape (rows,)
        Rotation, its rate, ü_g and the Dirac-delta force of each state.
    """
    m, H, B, g = st.m, st.H, st.B, st.g
    u, udot = np.asarray(u, dtype=float), np.asarray(udot, dtype=float)
    theta, thetadot, ag, F_i = (np.asarray(x, dtype=float) for x in (theta, thetadot, ag, F_i))
    rows = np.broadcast_shapes(u.shape[:-1], theta.shape, thetadot.shape, ag.shape)
    col = lambda x: x[..., None]  # a per-state value against the nodes
    cud, ku = udot @ st.C.T, u @ st.K.T
    if side == 0:
        return PhaseRows(eq.full_contact_acceleration(cud, ku, m, col(ag)), np.zeros(rows))
    c, sn = np.cos(theta), np.sin(theta)
    mu = u * m
    smu, umu = mu.sum(axis=-1), np.einsum("...i,...i->...", u, mu)
    arm = eq.pivot_arm(side, B, m, u)
    bu = eq.rocking_forcing_u(arm, col(thetadot), cud, ku, m, col(ag), col(c), col(sn), g)
    lever = eq.lever_arm(side, B, st.m_t, smu)
    ud_arm = np.einsum("...i,...i->...", udot, arm)
    bt = eq.rocking_forcing_theta(thetadot, ud_arm, B, F_i, ag, st.static_moment, lever, c, sn, g)
    a_tt = eq.rocking_inertia(st.J_p, umu, side, B, smu)
    thdd = np.broadcast_to(eq.rocking_theta_acceleration(bt, bu @ H, a_tt, H @ (m * H)), rows)
    uddot = eq.rocking_u_acceleration(bu, m, H, col(thdd))
    return PhaseRows(uddot, thdd, c, sn, smu, umu, lever, a_tt)


def state_accelerations(st: Structure, side, u, theta, udot, thetadot, ag, F_i=0.0):
    """(ü, θ̈) of many states, each in its own phase (`phase_rows` for each phase).

    `side` is an int (every row in that phase) or an array, shape (rows,), of
    0 / ±1; the other arguments as in `phase_rows`.
    """
    if np.ndim(side) == 0:
        r = phase_rows(st, int(side), u, theta, udot, thetadot, ag, F_i)
        return r.uddot, r.thetaddot
    side = np.asarray(side)
    u, udot = np.asarray(u, dtype=float), np.asarray(udot, dtype=float)
    per_row = [
        np.broadcast_to(np.asarray(x, dtype=float), side.shape) for x in (theta, thetadot, ag, F_i)
    ]
    uddot, thetaddot = np.empty_like(u), np.zeros(side.shape)
    for phase in np.unique(side):
        k = side == phase
        th, thd, a, f = (x[k] for x in per_row)
        r = phase_rows(st, int(phase), u[k], th, udot[k], thd, a, f)
        uddot[k], thetaddot[k] = r.uddot, r.thetaddot
    return uddot, thetaddot


def total_accelerations(
    structure: Structure, side, u, theta, uddot, thetaddot, thetadot, ag, H=None
) -> np.ndarray:
    """Total lateral accelerations of nodes in the direction of u (`equations.total_acceleration`).

    a = ü + H θ̈ + (±B1 − u) θ̇² + ü_g cos θ − 1 g sin θ (paper 001, Eq 7); in
    full contact (``side = 0``: θ, θ̇ and θ̈ are 0) this is ü + ü_g. Scalars
    for one state, or arrays of shape (rows,) with u, ü of shape (rows, N).
    `H` gives the nodes' heights when u, ü are not those of the structure's
    own nodes 1..N (`multimass.scenes.recovery`); default ``structure.H``.
    """
    st = structure
    side, theta, thetaddot, thetadot, ag = (
        np.asarray(x, dtype=float) for x in (side, theta, thetaddot, thetadot, ag)
    )
    full = side == 0
    theta, thetaddot, thetadot = (np.where(full, 0.0, x) for x in (theta, thetaddot, thetadot))
    col = lambda x: x[..., None]
    return eq.total_acceleration(
        col(side),
        st.B,
        st.g,
        np.asarray(u, dtype=float),
        np.asarray(uddot, dtype=float),
        st.H if H is None else np.asarray(H, dtype=float),
        col(thetaddot),
        col(thetadot),
        col(ag),
        col(np.cos(theta)),
        col(np.sin(theta)),
    )
