"""Right-hand sides and event functions of one phase, for `scipy.integrate.solve_ivp`.

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


_SQRT_PI = math.sqrt(math.pi)


def rocking_rhs(model: Model, side: int, ag_fn, force: ActiveForce | None):
    """dy/dt of the rocking phase about pivot `side` (paper 001, Eqs 4–5)."""
    mdl, s = model, float(side)
    n, m, H, K, C, B, g = mdl.n, mdl.m, mdl.H, mdl.K, mdl.C, mdl.B, mdl.g
    pivot_arm = s * B * m  # M (±B 1)
    schur0 = mdl.J_p - mdl.HmH
    lever0 = s * B * mdl.m_t  # ±(1ᵀ M B 1 + m0 B)
    if force is not None:
        f_amp = -s * force.E_ini * (1.0 - force.r**2) / (B * force.n * _SQRT_PI)  # paper 001, Eq 14
        inv_n2 = 1.0 / force.n**2

    def rhs(t, y):
        u, th, ud, thd = y[:n], y[n], y[n + 1 : 2 * n + 1], y[2 * n + 1]
        ag = ag_fn(t)
        c, sn = math.cos(th), math.sin(th)
        F = f_amp * math.exp(-th * th * inv_n2) if force is not None else 0.0
        mu = m * u
        smu = mu.sum() if n else 0.0
        Cud = C @ ud if n else ud
        # paper 001, Eq 4 (right-hand side)
        bu = -(pivot_arm - mu) * thd * thd - Cud - (K @ u if n else u) - m * (ag * c - g * sn)
        lever = lever0 - smu  # ±1ᵀM(B1 ∓ u) ± m0 B, using s² = 1
        # paper 001, Eq 5 (right-hand side)
        bt = (
            2.0 * thd * (ud @ (pivot_arm - mu) if n else 0.0)
            - 2.0 * B * F
            - ag * (mdl.height * c + lever * sn)
            - g * (-mdl.height * sn + lever * c)
        )
        a_tt_minus_hmh = schur0 + (u @ mu if n else 0.0) - 2.0 * s * B * smu
        thdd = (bt - (H @ bu if n else 0.0)) / a_tt_minus_hmh
        udd = bu / m - H * thdd if n else bu
        xdot = (
            (ud @ m) * c + thd * (mdl.height * c + lever * sn)
            if n
            else thd * (mdl.height * c + lever * sn)
        )
        out = np.empty_like(y)
        out[:n] = ud
        out[n] = thd
        out[n + 1 : 2 * n + 1] = udd
        out[2 * n + 1] = thdd
        out[-3] = ud @ Cud if n else 0.0
        out[-2] = -ag * xdot
        out[-1] = 2.0 * B * F * thd
        return out

    return rhs


def full_contact_rhs(model: Model, ag_fn):
    """dy/dt of the full-contact phase (paper 001, Eq 3); θ and θ̇ stay 0."""
    n, m, K, C = model.n, model.m, model.K, model.C

    def rhs(t, y):
        u, ud = y[:n], y[n + 1 : 2 * n + 1]
        ag = ag_fn(t)
        Cud = C @ ud
        out = np.zeros_like(y)
        out[:n] = ud
        out[n + 1 : 2 * n + 1] = -(Cud + K @ u) / m - ag  # paper 001, Eq 3
        out[-3] = ud @ Cud
        out[-2] = -ag * (m @ ud)
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
