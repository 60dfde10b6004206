"""Compiled maths of one phase: ground motion, right-hand sides and event functions.

The same equations as the reference path, written as numba kernels on flat
arrays so one integration step never leaves machine code:

* `ground_acc` — ü_g(t) of the known excitations (`multimass.excitations`,
  `multimass.records`), from the (kind, params, samples) triple that
  `multimass.fast.excitation.encode` builds;
* `rocking_rhs` / `full_contact_rhs` — `multimass._phase.rocking_rhs` /
  `full_contact_rhs` (paper 001, Eqs 3–5, 14), with the same state layout
  y = [u (N), θ, u̇ (N), θ̇, D, W_g, W_F];
* `event_value` — the event functions of `multimass._events.phase_events`
  (θ = 0, overturning, θ̇ = 0, Dirac-delta activation and deactivation, uplift
  about either pivot), including the quiet guard of `multimass._phase.guard`.

Model scalars travel in one float array `mp` (indices `MP_*`), the
Dirac-delta force in `fp` (`FP_*`) and event parameters in `ep` (`EP_*`).
`tests/multimass/test_fast.py` compares these kernels with the reference
functions at random states.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = [
    "ground_acc",
    "rocking_rhs",
    "full_contact_rhs",
    "rhs",
    "event_value",
    "EXC_NONE",
    "EXC_SINE",
    "EXC_COSINE",
    "EXC_RICKER",
    "EXC_RECORD",
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

# event codes (multimass._events.phase_events)
EV_ZERO = 0
EV_OVERTURN = 1
EV_PEAK = 2
EV_ACTIVATE = 3
EV_DEACTIVATE = 4
EV_UPLIFT_RIGHT = 5
EV_UPLIFT_LEFT = 6

# model scalars (multimass._phase.Model)
MP_JP, MP_HMH, MP_HEIGHT, MP_MT, MP_B, MP_G, MP_M0, MP_H0 = range(8)
MP_SIZE = 8
# Dirac-delta force (multimass._phase.ActiveForce): on (1/0), E_ini, r, n
FP_ON, FP_E, FP_R, FP_N = range(4)
FP_SIZE = 4
# event parameters
EP_TDMIN, EP_OVERTURN, EP_R_PENDING, EP_CP, EP_NMIN, EP_Z, EP_LIMIT, EP_MREF, EP_LREF = range(9)
EP_SIZE = 9

_SQRT_PI = math.sqrt(math.pi)
_SQRT_2 = math.sqrt(2.0)


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
    dur = par[3] if kind == EXC_RICKER else par[2]
    if not (0.0 <= t <= dur):
        return 0.0
    if kind == EXC_SINE:
        return par[0] * math.sin(par[1] * t)  # paper 004, Fig 2
    if kind == EXC_COSINE:
        return par[0] * math.cos(par[1] * t)  # paper 004, Fig 2; paper 001, Sec 4.4
    x2 = (par[1] * (t - par[2])) ** 2  # Ricker wavelet
    return par[0] * (1.0 - 0.5 * x2) * math.exp(-0.25 * x2)


@njit(cache=True, error_model="numpy", inline="always")
def rocking_rhs(t, y, out, side, m, H, K, C, mp, fp, kind, par, samples):
    """dy/dt while rocking about pivot `side` (paper 001, Eqs 4–5), written into `out`."""
    n = m.size
    s = float(side)
    B, g, height = mp[MP_B], mp[MP_G], mp[MP_HEIGHT]
    th, thd = y[n], y[2 * n + 1]
    ag = ground_acc(t, kind, par, samples)
    c, sn = math.cos(th), math.sin(th)
    F = 0.0
    if fp[FP_ON] != 0.0:
        r, w = fp[FP_R], fp[FP_N]
        f_amp = -s * fp[FP_E] * (1.0 - r * r) / (B * w * _SQRT_PI)  # paper 001, Eq 14
        F = f_amp * math.exp(-th * th * (1.0 / (w * w)))
    smu = 0.0
    umu = 0.0
    ud_arm = 0.0
    for i in range(n):
        mu = m[i] * y[i]
        smu += mu
        umu += y[i] * mu
        ud_arm += y[n + 1 + i] * (s * B * m[i] - mu)
    lever = s * B * mp[MP_MT] - smu  # ±1ᵀM(B1 ∓ u) ± m0 B
    # paper 001, Eq 4 (right-hand side), kept in out[n+1:2n+1] until θ̈ is known
    hbu = 0.0
    dissip = 0.0
    mud = 0.0
    for i in range(n):
        cud = 0.0
        ku = 0.0
        for j in range(n):
            cud += C[i, j] * y[n + 1 + j]
            ku += K[i, j] * y[j]
        dissip += y[n + 1 + i] * cud
        mud += y[n + 1 + i] * m[i]
        arm = s * B * m[i] - m[i] * y[i]
        bu = -arm * thd * thd - cud - ku - m[i] * (ag * c - g * sn)
        out[n + 1 + i] = bu
        hbu += H[i] * bu
    # paper 001, Eq 5 (right-hand side)
    bt = (
        2.0 * thd * ud_arm
        - 2.0 * B * F
        - ag * (height * c + lever * sn)
        - g * (-height * sn + lever * c)
    )
    a_tt_minus_hmh = (mp[MP_JP] - mp[MP_HMH]) + umu - 2.0 * s * B * smu
    thdd = (bt - hbu) / a_tt_minus_hmh
    for i in range(n):
        out[i] = y[n + 1 + i]
        out[n + 1 + i] = out[n + 1 + i] / m[i] - H[i] * thdd
    xdot = mud * c + thd * (height * c + lever * sn)
    out[n] = thd
    out[2 * n + 1] = thdd
    out[2 * n + 2] = dissip
    out[2 * n + 3] = -ag * xdot
    out[2 * n + 4] = 2.0 * B * F * thd


@njit(cache=True, error_model="numpy", inline="always")
def full_contact_rhs(t, y, out, m, K, C, kind, par, samples):
    """dy/dt in full contact (paper 001, Eq 3); θ and θ̇ stay 0."""
    n = m.size
    ag = ground_acc(t, kind, par, samples)
    dissip = 0.0
    mud = 0.0
    for i in range(n):
        cud = 0.0
        ku = 0.0
        for j in range(n):
            cud += C[i, j] * y[n + 1 + j]
            ku += K[i, j] * y[j]
        out[i] = y[n + 1 + i]
        out[n + 1 + i] = -(cud + ku) / m[i] - ag  # paper 001, Eq 3
        dissip += y[n + 1 + i] * cud
        mud += m[i] * y[n + 1 + i]
    out[n] = 0.0
    out[2 * n + 1] = 0.0
    out[2 * n + 2] = dissip
    out[2 * n + 3] = -ag * mud
    out[2 * n + 4] = 0.0


@njit(cache=True, error_model="numpy", inline="always")
def rhs(t, y, out, side, m, H, K, C, mp, fp, kind, par, samples):
    """dy/dt of the phase `side` (0: full contact, ±1: rocking)."""
    if side == 0:
        full_contact_rhs(t, y, out, m, K, C, kind, par, samples)
    else:
        rocking_rhs(t, y, out, side, m, H, K, C, mp, fp, kind, par, samples)


@njit(cache=True, error_model="numpy")
def _total_energy(side, y, m, H, K, mp):
    """T + V_g + U relative to rest while rocking (multimass.kinematics.total_energy)."""
    n = m.size
    B, th, thd = mp[MP_B], y[n], y[2 * n + 1]
    kin = 0.0
    hmud = 0.0
    umu = 0.0
    smu = 0.0
    elastic = 0.0
    for i in range(n):
        ud = y[n + 1 + i]
        kin += ud * (m[i] * ud)
        hmud += ud * (m[i] * H[i])
        umu += y[i] * (m[i] * y[i])
        smu += m[i] * y[i]
        ku = 0.0
        for j in range(n):
            ku += K[i, j] * y[j]
        elastic += y[i] * ku
    a_tt = mp[MP_JP] + umu - 2.0 * side * B * smu
    kinetic = 0.5 * kin + thd * hmud + 0.5 * a_tt * thd * thd
    lever = side * (B * mp[MP_MT] - side * smu)
    grav = mp[MP_G] * (mp[MP_HEIGHT] * (math.cos(th) - 1.0) + lever * math.sin(th))
    return kinetic + grav + 0.5 * elastic


@njit(cache=True, error_model="numpy")
def _momentum_new_pivot(y, m, H, mp):
    """L_p about the impending pivot (multimass.kinematics.angular_momentum_new_pivot)."""
    n = m.size
    umu = 0.0
    hmu = 0.0
    for i in range(n):
        umu += y[i] * (m[i] * y[i])
        hmu += H[i] * (m[i] * y[n + 1 + i])
    B = mp[MP_B]
    return hmu + y[2 * n + 1] * (mp[MP_JP] - 2.0 * mp[MP_MT] * B * B + umu)


@njit(cache=True, error_model="numpy")
def _uplift(sgn, t, y, m, H, K, C, mp, ep, kind, par, samples):
    """Uplift function about pivot `sgn` from full contact (paper 001, Eq 8)."""
    n = m.size
    ag = ground_acc(t, kind, par, samples)
    M_o = mp[MP_M0] * mp[MP_H0] * ag
    hm = 0.0
    mu = 0.0
    L = 0.0
    for i in range(n):
        cud = 0.0
        ku = 0.0
        for j in range(n):
            cud += C[i, j] * y[n + 1 + j]
            ku += K[i, j] * y[j]
        uddot = -(cud + ku) / m[i] - ag  # paper 001, Eq 3
        hm += H[i] * (m[i] * (uddot + ag))
        mu += m[i] * y[i]
        L += H[i] * (m[i] * y[n + 1 + i])  # L_p^fc
    M_o = hm + M_o
    res = mp[MP_G] * (mp[MP_MT] * mp[MP_B] - sgn * mu)  # M_res(±)
    moment = (-sgn * M_o - res) / ep[EP_MREF]
    lm = sgn * L / ep[EP_LREF]
    return lm if lm < moment else moment  # paper 001, Eq 8


@njit(cache=True, error_model="numpy")
def _activate(side, y, m, H, K, mp, ep):
    """Dirac-delta activation function (paper 001, Eqs 15–16)."""
    n = m.size
    th, thd = y[n], y[2 * n + 1]
    side_imp = -side
    E = _total_energy(side, y, m, H, K, mp)
    r = ep[EP_R_PENDING]
    width = (
        E
        * (1.0 - r * r)
        / (mp[MP_B] * _SQRT_PI * (0.5 * mp[MP_MT] * mp[MP_G] + ep[EP_CP] * abs(thd)))
    )  # Eq 15
    if width < ep[EP_NMIN]:
        width = ep[EP_NMIN]
    theta_th = ep[EP_Z] * width / _SQRT_2  # Eq 16
    L = _momentum_new_pivot(y, m, H, mp)
    tdm = ep[EP_TDMIN]
    return max(abs(th) / theta_th - 1.0, -side_imp * L / ep[EP_LREF], (tdm - side_imp * thd) / tdm)


@njit(cache=True, error_model="numpy")
def event_value(code, t, y, t_on, quiet, side, m, H, K, C, mp, ep, kind, par, samples):
    """Value of event `code` at (t, y); `quiet` until `t_on` (multimass._phase.guard)."""
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
        return s * y[n] - ep[EP_LIMIT]  # paper 001, Eq 17
    if code == EV_ACTIVATE:
        return _activate(s, y, m, H, K, mp, ep)
    sgn = 1.0 if code == EV_UPLIFT_RIGHT else -1.0
    return _uplift(sgn, t, y, m, H, K, C, mp, ep, kind, par, samples)


def model_params(st) -> np.ndarray:
    """`mp` of a structure (the scalars of `multimass._phase.Model`)."""
    mp = np.zeros(MP_SIZE)
    mp[MP_JP] = st.J_p
    mp[MP_HMH] = float(st.H @ (st.m * st.H))
    mp[MP_HEIGHT] = float(st.m @ st.H + st.m0 * st.h0)
    mp[MP_MT], mp[MP_B], mp[MP_G] = st.m_t, st.B, st.g
    mp[MP_M0], mp[MP_H0] = st.m0, st.h0
    return mp
