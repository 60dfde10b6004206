"""Right-hand sides and event functions of one phase, for `scipy.integrate.solve_ivp`.

The right-hand sides evaluate the equations of `multimass.model.equations` with
NumPy sums over the nodes; the compiled path (`multimass.engines.fast._maths`)
compiles the same functions.

State layout in every phase: y = [u (N), θ, u̇ (N), θ̇, D, W_g, W_F], where the
last three are quadratures for the energy ledger: damping dissipation
D = ∫ u̇ᵀCu̇ dt, work of the effective ground forces W_g = ∫ −ü_g Σ m Ẋ dt and
work dissipated by the Dirac-delta force W_F = ∫ 2B F_i θ̇ dt. In full
contact θ ≡ θ̇ ≡ 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from multimass.impact_models import gaussian_force as gf

from . import equations as eq
from .structure import Structure

__all__ = ["Model", "ActiveForce", "rocking_rhs", "full_contact_rhs", "guard"]


@dataclass(frozen=True, eq=False)
class Model:
    """Arrays of a structure laid out for fast right-hand sides."""

    st: Structure
    n: int
    m: np.ndarray
    H: np.ndarray
    K: np.ndarray
    C: np.ndarray
    mH: np.ndarray
    HmH: float
    height: float  # Hᵀ M 1 + m0 h0
    m_sum: float  # 1ᵀ M 1
    J_p: float
    B: float
    g: float
    m0: float
    h0: float
    m_t: float

    @classmethod
    def of(cls, st: Structure) -> Model:
        return cls(
            st=st,
            n=st.n,
            m=st.m,
            H=st.H,
            K=st.K,
            C=st.C,
            mH=st.m * st.H,
            HmH=float(st.H @ (st.m * st.H)),
            height=float(st.m @ st.H + st.m0 * st.h0),
            m_sum=float(st.m.sum()),
            J_p=st.J_p,
            B=st.B,
            g=st.g,
            m0=st.m0,
            h0=st.h0,
            m_t=st.m_t,
        )

    def split(self, y):
        n = self.n
        return y[:n], y[n], y[n + 1 : 2 * n + 1], y[2 * n + 1]


@dataclass(frozen=True)
class ActiveForce:
    """Parameters of an activated Dirac-delta force (paper 001, Eqs 14–16)."""

    E_ini: float
    r: float
    n: float
    theta_i: float
    thetadot_i: float


def rocking_rhs(model: Model, side: int, ag_fn, force: ActiveForce | None):
    """dy/dt of the rocking phase about pivot `side` (Eqs 4–5 of `multimass.model.equations`)."""
    mdl, s = model, float(side)
    n, m, H, K, C, B, g = mdl.n, mdl.m, mdl.H, mdl.K, mdl.C, mdl.B, mdl.g
    h, m_t, J_p, h_m_h = mdl.height, mdl.m_t, mdl.J_p, mdl.HmH

    def rhs(t, y):
        u, th, ud, thd = y[:n], y[n], y[n + 1 : 2 * n + 1], y[2 * n + 1]
        ag = ag_fn(t)
        c, sn = math.cos(th), math.sin(th)
        F = gf.impact_force(th, s, force.E_ini, force.r, force.n, B) if force is not None else 0.0
        out = np.empty_like(y)
        if n:
            mu = m * u
            smu = float(mu.sum())
            cud = C @ ud
            arm = eq.pivot_arm(s, B, m, u)
            bu = eq.rocking_forcing_u(arm, thd, cud, K @ u, m, ag, c, sn, g)
            ud_arm, umu, h_bu = float(ud @ arm), float(u @ mu), float(H @ bu)
            m_ud, dissipation = float(m @ ud), float(ud @ cud)
        else:  # a rigid body: no nodes, every sum over them is 0 (twice as fast as empty arrays)
            smu = ud_arm = umu = h_bu = m_ud = dissipation = 0.0
        lever = eq.lever_arm(s, B, m_t, smu)
        bt = eq.rocking_forcing_theta(thd, ud_arm, B, F, ag, h, lever, c, sn, g)
        a_tt = eq.rocking_inertia(J_p, umu, s, B, smu)
        thdd = eq.rocking_theta_acceleration(bt, h_bu, a_tt, h_m_h)
        out[:n] = ud
        out[n] = thd
        if n:
            out[n + 1 : 2 * n + 1] = eq.rocking_u_acceleration(bu, m, H, thdd)
        out[2 * n + 1] = thdd
        out[-3] = dissipation
        out[-2] = eq.ground_power(ag, m_ud, thd, h, lever, c, sn)
        out[-1] = eq.impact_power(B, F, thd)
        return out

    return rhs


def full_contact_rhs(model: Model, ag_fn):
    """dy/dt of the full-contact phase (Eq 3 of `multimass.model.equations`); θ and θ̇ stay 0."""
    n, m, K, C = model.n, model.m, model.K, model.C

    def rhs(t, y):
        u, ud = y[:n], y[n + 1 : 2 * n + 1]
        ag = ag_fn(t)
        cud = C @ ud
        out = np.zeros_like(y)
        out[:n] = ud
        out[n + 1 : 2 * n + 1] = eq.full_contact_acceleration(cud, K @ u, m, ag)
        out[-3] = ud @ cud
        out[-2] = eq.ground_power(ag, float(m @ ud), 0.0, 0.0, 0.0, 1.0, 0.0)
        return out

    return rhs


def guard(
    fn, t_start: float, delay: float, quiet: float, terminal: bool = True, direction: float = 0.0
):
    """Wrap an event function so it cannot fire within `delay` after `t_start`.

    Before `t_start + delay` it returns `quiet` (a value on the side the event
    does not fire from), so a phase never re-triggers the event that started
    it; after, the true value. Sets solve_ivp's ``terminal``/``direction``.
    """
    t_on = t_start + delay

    def event(t, y):
        return fn(t, y) if t > t_on else quiet

    event.terminal = terminal
    event.direction = direction
    return event
