"""Compiled maths of one phase: ground motion, right-hand sides and event functions.

The equations of `multimass.model.equations` and `multimass.impact_models.gaussian_force`,
compiled unchanged, called from numba kernels that form the sums over the nodes
in loops on flat arrays, so one integration step never leaves machine code:

* `ground_acc` — ü_g(t) of the known excitations (`multimass.inputs.excitations`,
  `multimass.inputs.records`), from the (kind, params, samples) triple that
  `multimass.engines.fast.excitation.encode` builds;
* `rocking_rhs` / `full_contact_rhs` — as `multimass.model._phase.rocking_rhs` /
  `full_contact_rhs` (the sums in loops instead of NumPy), with the same state layout
  y = [u (N), θ, u̇ (N), θ̇, D, W_g, W_F];
* `event_value` — the event functions of `multimass.engines._events.phase_events`
  (θ = 0, overturning, θ̇ = 0, Dirac-delta activation and deactivation, uplift
  about either pivot), including the quiet guard of `multimass.model._phase.guard`.

Model scalars travel in one float array `mp` (indices `MP_*`), the
Dirac-delta force in `fp` (`FP_*`) and event parameters in `ep` (`EP_*`).
`tests/multimass/engines/test_fast.py` compares these kernels with the solve_ivp
path's functions at random states (the loops against the NumPy sums).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numba.extending import register_jitable

from ... import checks
from ...impact_models import gaussian_force as gf
from ...inputs import pulse_shapes as ps
from ...model import equations as eq

# The physics, compiled unchanged from the plain functions the solve_ivp path runs
for _mod in (eq, gf, ps):
    for _name in _mod.__all__:
        register_jitable(inline="always")(getattr(_mod, _name))
# and the accuracy check's rule (`multimass.checks`), the same source as every engine's
for _fn in (checks.energy_scale, checks.balance_error):
    register_jitable(_fn)

__all__ = [
    "ground_acc",
    "piece_end",
    "rocking_rhs",
    "full_contact_rhs",
    "rhs",
    "rhs_call",
    "event_value",
    "activation_angle_at",
    "EXC_NONE",
    "EXC_SINE",
    "EXC_COSINE",
    "EXC_RICKER",
    "EXC_RECORD",
    "EXC_MP",
    "PAR_SIZE",
    "EV_ZERO",
    "EV_OVERTURN",
    "EV_PEAK",
    "EV_ACTIVATE",
    "EV_DEACTIVATE",
    "EV_UPLIFT_RIGHT",
    "EV_UPLIFT_LEFT",
    "MP_SIZE",
    "FP_SIZE",
    "EP_SIZE",
    "model_params",
]

# excitation kinds: params layout in the comment
EXC_NONE = 0  # free release: ü_g ≡ 0
EXC_SINE = 1  # [a0, ω, duration]
EXC_COSINE = 2  # [a0, ω, duration] (CosineWave; CosinePulse with a0 = amplitude)
EXC_RICKER = 3  # [a_p, ω_p, t0, duration]
EXC_RECORD = 4  # [t_start, t_end, 1/dt, last interval index]; samples = ü_g
EXC_MP = 5  # [A, f_p, γ, ν, t0, start, duration] (MPPulse)
#: Length of an excitation's parameter array.
PAR_SIZE = 8
#: A record's sample closer than this share of its interval ahead of t is t's own.
_PIECE_EPS = 1e-9

# event codes (multimass.engines._events.phase_events)
EV_ZERO = 0
EV_OVERTURN = 1
EV_PEAK = 2
EV_ACTIVATE = 3
EV_DEACTIVATE = 4
EV_UPLIFT_RIGHT = 5
EV_UPLIFT_LEFT = 6

# model scalars (multimass.model._phase.Model)
MP_JP, MP_HMH, MP_HEIGHT, MP_MT, MP_B, MP_G, MP_M0, MP_H0 = range(8)
MP_SIZE = 8
# Dirac-delta force (multimass.model._phase.ActiveForce): on (1/0), E_ini, r, n
FP_ON, FP_E, FP_R, FP_N = range(4)
FP_SIZE = 4
# event parameters
EP_TDMIN, EP_OVERTURN, EP_R_PENDING, EP_CP, EP_NMIN, EP_Z, EP_LIMIT, EP_MREF, EP_LREF = range(9)
EP_SIZE = 9


@njit(cache=True, error_model="numpy", inline="always")
def ground_acc(t, kind, par, samples):
    """ü_g(t) in m/s² of an encoded excitation (the `_scalar` methods of each class)."""
    if kind == EXC_NONE:
        return 0.0
    if kind == EXC_RECORD:
        if t < par[0] or t > par[1]:
            return 0.0
        x = (t - par[0]) * par[2]  # index arithmetic on the uniform grid
        i = int(x)
        last = int(par[3])
        if i > last:
            i = last
        ai = samples[i]
        return ai + (x - i) * (samples[i + 1] - ai)
    if kind == EXC_MP:
        if not (par[5] <= t <= par[6]):
            return 0.0
        return ps.mp_acceleration(t, par[0], par[1], par[2], par[3], par[4])  # MPPulse._scalar
    dur = par[3] if kind == EXC_RICKER else par[2]
    if not (0.0 <= t <= dur):
        return 0.0
    if kind == EXC_SINE:
        return par[0] * math.sin(par[1] * t)  # paper 004, Fig 2
    if kind == EXC_COSINE:
        return par[0] * math.cos(par[1] * t)  # paper 004, Fig 2; paper 001, Sec 4.4
    x2 = (par[1] * (t - par[2])) ** 2  # Ricker wavelet, in Ricker._shape_scalar's order of
    return par[0] * ((1.0 - 0.5 * x2) * math.exp(-0.25 * x2))  # operations (same rounding)


@njit(cache=True, error_model="numpy")
def piece_end(t, kind, par):
    """The next sample of a record after t (ü_g is linear between samples, `ground_acc`):
    its start before it, +inf after its end or for other excitations (their breakpoints
    end the phase loop's segments). A sample closer than `_PIECE_EPS` of an interval
    ahead of t is t's own."""
    if kind != EXC_RECORD or t >= par[1]:
        return np.inf
    if t < par[0]:
        return par[0]
    x = (t - par[0]) * par[2]
    i = math.floor(x)
    if i + 1 - x < _PIECE_EPS:
        i += 1
    return min(par[0] + (i + 1) / par[2], par[1])


@njit(cache=True, error_model="numpy", inline="always")
def rocking_rhs(t, y, out, side, m, H, K, C, mp, fp, kind, par, samples):
    """dy/dt while rocking about pivot `side` (Eqs 4–5 of `multimass.model.equations`), into `out`."""
    n = m.size
    s = float(side)
    B, g, h = mp[MP_B], mp[MP_G], mp[MP_HEIGHT]
    th, thd = y[n], y[2 * n + 1]
    ag = ground_acc(t, kind, par, samples)
    c, sn = math.cos(th), math.sin(th)
    F = 0.0
    if fp[FP_ON] != 0.0:
        F = gf.impact_force(th, s, fp[FP_E], fp[FP_R], fp[FP_N], B)
    smu = 0.0
    umu = 0.0
    ud_arm = 0.0
    h_bu = 0.0
    dissip = 0.0
    m_ud = 0.0
    for i in range(n):
        cud = 0.0
        ku = 0.0
        for j in range(n):
            cud += C[i, j] * y[n + 1 + j]
            ku += K[i, j] * y[j]
        ud = y[n + 1 + i]
        arm = eq.pivot_arm(s, B, m[i], y[i])
        smu += m[i] * y[i]
        umu += y[i] * (m[i] * y[i])
        ud_arm += ud * arm
        dissip += ud * cud
        m_ud += ud * m[i]
        bu = eq.rocking_forcing_u(arm, thd, cud, ku, m[i], ag, c, sn, g)
        out[n + 1 + i] = bu  # b_u, until θ̈ is known
        h_bu += H[i] * bu
    lever = eq.lever_arm(s, B, mp[MP_MT], smu)
    bt = eq.rocking_forcing_theta(thd, ud_arm, B, F, ag, h, lever, c, sn, g)
    a_tt = eq.rocking_inertia(mp[MP_JP], umu, s, B, smu)
    thdd = eq.rocking_theta_acceleration(bt, h_bu, a_tt, mp[MP_HMH])
    for i in range(n):
        out[i] = y[n + 1 + i]
        out[n + 1 + i] = eq.rocking_u_acceleration(out[n + 1 + i], m[i], H[i], thdd)
    out[n] = thd
    out[2 * n + 1] = thdd
    out[2 * n + 2] = dissip
    out[2 * n + 3] = eq.ground_power(ag, m_ud, thd, h, lever, c, sn)
    out[2 * n + 4] = eq.impact_power(B, F, thd)


@njit(cache=True, error_model="numpy", inline="always")
def full_contact_rhs(t, y, out, m, K, C, kind, par, samples):
    """dy/dt in full contact (Eq 3 of `multimass.model.equations`); θ and θ̇ stay 0."""
    n = m.size
    ag = ground_acc(t, kind, par, samples)
    dissip = 0.0
    m_ud = 0.0
    for i in range(n):
        cud = 0.0
        ku = 0.0
        for j in range(n):
            cud += C[i, j] * y[n + 1 + j]
            ku += K[i, j] * y[j]
        out[i] = y[n + 1 + i]
        out[n + 1 + i] = eq.full_contact_acceleration(cud, ku, m[i], ag)
        dissip += y[n + 1 + i] * cud
        m_ud += m[i] * y[n + 1 + i]
    out[n] = 0.0
    out[2 * n + 1] = 0.0
    out[2 * n + 2] = dissip
    out[2 * n + 3] = eq.ground_power(ag, m_ud, 0.0, 0.0, 0.0, 1.0, 0.0)
    out[2 * n + 4] = 0.0


@njit(cache=True, error_model="numpy", inline="always")
def rhs(t, y, out, side, m, H, K, C, mp, fp, kind, par, samples):
    """dy/dt of the phase `side` (0: full contact, ±1: rocking)."""
    if side == 0:
        full_contact_rhs(t, y, out, m, K, C, kind, par, samples)
    else:
        rocking_rhs(t, y, out, side, m, H, K, C, mp, fp, kind, par, samples)


@njit(cache=True, error_model="numpy")
def rhs_call(t, y, out, side, m, H, K, C, mp, fp, kind, par, samples):
    """`rhs` as a function call, for the few calls off the hot loop.

    `rhs` is inlined where it is called (numba IR inlining, the fastest code), but
    each inlined copy costs ~2 s of compile time: the hot RK stage loop inlines it
    once, every other caller calls this one compiled copy.
    """
    rhs(t, y, out, side, m, H, K, C, mp, fp, kind, par, samples)


@njit(cache=True, error_model="numpy")
def _total_energy(side, y, m, H, K, mp):
    """T + V_g + U relative to rest while rocking (as `multimass.model.kinematics.total_energy`)."""
    n = m.size
    B, th, thd = mp[MP_B], y[n], y[2 * n + 1]
    ud_m_ud = 0.0
    h_m_ud = 0.0
    umu = 0.0
    smu = 0.0
    uku = 0.0
    for i in range(n):
        ud = y[n + 1 + i]
        ud_m_ud += ud * (m[i] * ud)
        h_m_ud += ud * (m[i] * H[i])
        umu += y[i] * (m[i] * y[i])
        smu += m[i] * y[i]
        ku = 0.0
        for j in range(n):
            ku += K[i, j] * y[j]
        uku += y[i] * ku
    a_tt = eq.rocking_inertia(mp[MP_JP], umu, side, B, smu)
    lever = eq.lever_arm(side, B, mp[MP_MT], smu)
    c, sn = math.cos(th), math.sin(th)
    return (
        eq.kinetic_energy(ud_m_ud, h_m_ud, a_tt, thd)
        + eq.gravitational_energy(mp[MP_G], mp[MP_HEIGHT], lever, c, sn)
        + 0.5 * uku
    )


@njit(cache=True, error_model="numpy")
def _pivot_momentum(y, m, H, mp):
    """L_p about the impending pivot (as `multimass.model.kinematics.angular_momentum_new_pivot`)."""
    n = m.size
    umu = 0.0
    h_m_ud = 0.0
    for i in range(n):
        umu += y[i] * (m[i] * y[i])
        h_m_ud += H[i] * (m[i] * y[n + 1 + i])
    return eq.pivot_momentum(h_m_ud, y[2 * n + 1], mp[MP_JP], mp[MP_MT], mp[MP_B], umu)


@njit(cache=True, error_model="numpy")
def _uplift(sgn, t, y, m, H, K, C, mp, ep, kind, par, samples):
    """Uplift about pivot `sgn` from full contact (as `multimass.engines._events`' uplift)."""
    n = m.size
    ag = ground_acc(t, kind, par, samples)
    h_m_acc = 0.0
    smu = 0.0
    h_m_ud = 0.0
    for i in range(n):
        cud = 0.0
        ku = 0.0
        for j in range(n):
            cud += C[i, j] * y[n + 1 + j]
            ku += K[i, j] * y[j]
        uddot = eq.full_contact_acceleration(cud, ku, m[i], ag)
        h_m_acc += H[i] * (m[i] * (uddot + ag))
        smu += m[i] * y[i]
        h_m_ud += H[i] * (m[i] * y[n + 1 + i])
    M_o = eq.overturning_moment(h_m_acc, mp[MP_M0] * mp[MP_H0], ag)
    M_res = eq.restoring_moment(sgn, mp[MP_G], mp[MP_MT], mp[MP_B], smu)
    L = eq.pivot_momentum(h_m_ud, 0.0, mp[MP_JP], mp[MP_MT], mp[MP_B], 0.0)  # L_p^fc
    return eq.uplift_margin(sgn, M_o, M_res, L, ep[EP_MREF], ep[EP_LREF])


@njit(cache=True, error_model="numpy")
def _activate(side, y, m, H, K, mp, ep):
    """Dirac-delta activation (as `multimass.engines._events`' activate)."""
    n = m.size
    thd = y[2 * n + 1]
    L = _pivot_momentum(y, m, H, mp)
    theta_i = activation_angle_at(side, y, m, H, K, mp, ep)
    return gf.activation_margin(y[n], theta_i, side, L, ep[EP_LREF], thd, ep[EP_TDMIN])


@njit(cache=True, error_model="numpy")
def activation_angle_at(side, y, m, H, K, mp, ep):
    """The activation angle ``|θ_i|`` of state y: Eq 15's width at its energy and θ̇."""
    E = _total_energy(side, y, m, H, K, mp)
    width = gf.impact_width(
        E, ep[EP_R_PENDING], mp[MP_B], mp[MP_MT], mp[MP_G], ep[EP_CP], y[2 * m.size + 1],
        ep[EP_NMIN],
    )  # fmt: skip
    return gf.activation_angle(ep[EP_Z], width)


@njit(cache=True, error_model="numpy")
def event_value(code, t, y, t_on, quiet, side, m, H, K, C, mp, ep, kind, par, samples):
    """Value of event `code` at (t, y); `quiet` until `t_on` (multimass.model._phase.guard)."""
    if not (t > t_on):
        return quiet
    n = m.size
    s = float(side)
    if code == EV_ZERO:
        return s * y[n]  # θ = 0
    if code == EV_OVERTURN:
        return s * y[n] - ep[EP_OVERTURN]
    if code == EV_PEAK:
        return y[2 * n + 1]  # θ̇ = 0
    if code == EV_DEACTIVATE:
        return gf.deactivation_margin(s, y[n], ep[EP_LIMIT])
    if code == EV_ACTIVATE:
        return _activate(s, y, m, H, K, mp, ep)
    sgn = 1.0 if code == EV_UPLIFT_RIGHT else -1.0
    return _uplift(sgn, t, y, m, H, K, C, mp, ep, kind, par, samples)


def model_params(st) -> np.ndarray:
    """`mp` of a structure (the scalars of `multimass.model._phase.Model`)."""
    mp = np.zeros(MP_SIZE)
    mp[MP_JP] = st.J_p
    mp[MP_HMH] = float(st.H @ (st.m * st.H))
    mp[MP_HEIGHT] = float(st.m @ st.H + st.m0 * st.h0)
    mp[MP_MT], mp[MP_B], mp[MP_G] = st.m_t, st.B, st.g
    mp[MP_M0], mp[MP_H0] = st.m0, st.h0
    return mp
