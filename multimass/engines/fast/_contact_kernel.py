"""`contact_phase`: full contact advanced in closed form, for the compiled path.

In full contact the column obeys M ü + C u̇ + K u = −M 1 ü_g (paper 001, Eq 3):
linear, with constant matrices. With classical damping (Rayleigh's is) it
separates into modes, u = Φ q with Φᵀ M Φ = I:

    q̈_i + 2 ζ_i ω_i q̇_i + ω_i² q_i = −Γ_i ü_g,   Γ = Φᵀ M 1.

Wherever ü_g is linear in time, ü_g = a0 + s τ — between two samples of a
record (`multimass.inputs.records` interpolates linearly) and in free vibration — each
mode is solved exactly: the particular solution q_p = c0 + c1 τ, anchored at
the start of the piece (τ = 0), plus the free vibration of e = q − q_p
(`multimass.model._nigam_jennings.free_vibration`; no term cancels as τ → 0). Between
two event checks only (e, ė) is advanced, with the four coefficients of the
piece's regular sub-step tabulated. The ledger's integrals since the anchor are
exact too, and are formed only where the state is wanted (output, events, end):

* damping, ∫ u̇ᵀ C u̇ = Σ 2ζω ∫ q̇²: with q̇ = c1 + ė and, from the free
  equation, d/dt (½ ė² + ½ ω² e²) = −2ζω ė²,
  2ζω ∫ q̇² = 2ζω (c1² τ + 2 c1 Δe) − Δ(½ ė² + ½ ω² e²);
* ground work, −∫ ü_g 1ᵀ M u̇ = −Σ Γ ∫ ü_g q̇ = −Σ Γ ([ü_g q] − s ∫ q) by parts,
  ∫ q = c0 τ + c1 τ²/2 + ∫ e and ω² ∫ e = −(Δė + 2ζω Δe).

The ledger is thus not closed by construction; tests/multimass/engines/test_fast_contact.py
checks that it closes. Events — the uplift of paper 001's Eq 8 — are checked at
points at most `h_max` apart (1/16 of the period of the stiffest oscillating mode,
`multimass.engines.fast.contact_modes`; closer at the start of a phase, `_RAMP`): first
from Eq 8's functions with sums formed in modes, which settles every check far
from uplift; otherwise, and for every root, with the Runge–Kutta kernel's
compiled uplift function (`._maths._uplift`) on the state mapped back to u, u̇,
located by zeroin (`._rk.zeroin_next`) on the exact solution. Where a bound shows
that Eq 8 cannot hold over the rest of a piece (`_no_uplift_before`) the kernel
steps over it without checks; where the bound keeps failing it is tried less often
(`_BACKOFF`). The output grid is filled from the exact solution.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numba.extending import register_jitable

from ...model import _nigam_jennings as nj
from ...model import equations as eq
from ._maths import (
    EP_LREF,
    EP_MREF,
    EV_UPLIFT_RIGHT,
    EXC_RECORD,
    MP_B,
    MP_G,
    MP_H0,
    MP_JP,
    MP_M0,
    MP_MT,
    _uplift,
)
from ._rk import _MAX_BRENT, EVENT, OK, zeroin_next
from ._unowned import unowned

__all__ = ["contact_phase"]

_free_vibration = register_jitable(nj.free_vibration)  # a call: tables serve whole steps
#: An uplift margin below −_SCREEN in modes is negative without asking `_uplift_value`
#: (the two sums differ by round-off, ~1e-12 of the margin's scale).
_SCREEN = 1e-6
#: A step within this many ε·|t| of the sub-grid's step is that step (the grid's times
#: carry the rounding of t; the tabulated map is exact for the step itself).
_ULPS = 64 * 2.220446049250313e-16
#: The first event check of a phase comes this share of `h_max` after its start, and
#: the interval doubles up to the sub-grid's: a column can uplift again within tens of
#: µs of entering full contact (a one-node column at rest, 70 µs), which a check a
#: quarter period later misses. The Runge–Kutta kernel's first steps are as short.
_RAMP = 1.0 / 1024.0
#: Near uplift the bound of `_no_uplift_before` fails check after check, and trying it
#: costs more than a check: after a failure the next try waits twice as many checks
#: (1, 2, 4, ... up to this many), and a success resets the wait to one. Fewer tries
#: can only mean more checks, never fewer.
_BACKOFF = 16


@njit(cache=True, error_model="numpy", inline="always")
def _modal_sums(q, v, screen, gam):
    """HᵀM(ü + 1 ü_g) without its ü_g term, 1ᵀMu and HᵀMu̇ in modes (`ContactModes.screen`)."""
    h_m_acc, smu, h_m_ud = 0.0, 0.0, 0.0
    for i in range(q.size):
        h_m_acc += screen[0, i] * q[i] + screen[1, i] * v[i]
        smu += gam[i] * q[i]
        h_m_ud += screen[2, i] * v[i]
    return h_m_acc, smu, h_m_ud


@njit(cache=True, error_model="numpy", inline="always")
def _eq8_terms(sums, ag, sgn, mp):
    """(M_o^fc, M_res^fc, L_p^fc) of paper 001's Eq 8 about pivot `sgn` from `_modal_sums`."""
    h_m_acc, smu, h_m_ud = sums
    M_o = eq.overturning_moment(h_m_acc, mp[MP_M0] * mp[MP_H0], ag)
    M_res = eq.restoring_moment(sgn, mp[MP_G], mp[MP_MT], mp[MP_B], smu)
    L = eq.pivot_momentum(h_m_ud, 0.0, mp[MP_JP], mp[MP_MT], mp[MP_B], 0.0)
    return M_o, M_res, L


@njit(cache=True, error_model="numpy", inline="always")
def _screen(k, t, sums, ag, ev_code, ev_quiet, ev_ton, mp, ep):
    """Event k (an uplift, as every event of this phase) at t from Eq 8 with the modal
    `sums`, or +inf when it is not clearly negative there and `_uplift_value` must decide."""
    if not (t > ev_ton[k]):
        return ev_quiet[k]
    sgn = 1.0 if ev_code[k] == EV_UPLIFT_RIGHT else -1.0
    M_o, M_res, L = _eq8_terms(sums, ag, sgn, mp)
    g = eq.uplift_margin(sgn, M_o, M_res, L, ep[EP_MREF], ep[EP_LREF])
    return g if g < -_SCREEN else np.inf


@njit(cache=True, error_model="numpy")
def _no_uplift_before(tau_a, tau_b, e, d, a0, s, w, gam, screen, piece, mp, ep, zero, qp, vp):
    """True if neither uplift (Eq 8) can hold anywhere in τ ∈ [τa, τb] of the current piece.

    Eq 8 holds about pivot ± only where both of its conditions do: f1 = (∓M_o − M_res)/M_ref
    ≥ 0 and f2 = ±L/L_ref ≥ 0. Each is linear in the modal state: its particular part is
    linear in τ (largest at an end of the interval) and its free part is bounded by the
    free energy ½ ė² + ½ ω² e², which never grows (|e| ≤ √(2E)/ω, |ė| ≤ √(2E)): so if, for
    both pivots, f1 or f2 stays below zero with those bounds, no check in the interval
    can find an uplift. Eq 8 itself is `equations.uplift_margin` (its other condition set
    to +∞ to read one). `zero` holds zeros; `qp`, `vp` are scratch.
    """
    m_ref, l_ref = ep[EP_MREF], ep[EP_LREF]
    b1 = b2 = 0.0  # bounds of the free parts of f1 and f2
    for i in range(w.size):
        amp = math.sqrt(d[i] * d[i] + w[i] * w[i] * (e[i] * e[i]))  # √(2E)
        b1 += amp * (abs(mp[MP_G] * gam[i] - screen[0, i]) / w[i] + abs(screen[1, i]))
        b2 += amp * abs(screen[2, i])
    b1, b2 = b1 / m_ref, b2 / l_ref
    f1_top = np.full(2, -np.inf)  # particular parts, largest of the two ends, per pivot
    f2_top = np.full(2, -np.inf)
    for tau in (tau_a, tau_b):
        _modes_at(tau, zero, zero, piece, qp, vp)  # the particular part alone
        sums = _modal_sums(qp, vp, screen, gam)
        for j in range(2):
            sgn = 1.0 - 2.0 * j
            M_o, M_res, L = _eq8_terms(sums, a0 + s * tau, sgn, mp)
            f1 = eq.uplift_margin(sgn, M_o, M_res, sgn * np.inf, m_ref, l_ref)
            f2 = eq.uplift_margin(sgn, -sgn * np.inf, M_res, L, m_ref, l_ref)
            f1_top[j], f2_top[j] = max(f1_top[j], f1), max(f2_top[j], f2)
    for j in range(2):
        if not (f1_top[j] + b1 < -_SCREEN or f2_top[j] + b2 < -_SCREEN):
            return False
    return True


@njit(cache=True, error_model="numpy")
def _uplift_value(code, t, y, t_on, quiet, side, m, H, K, C, mp, ep, kind, par, smp):
    """`._maths.event_value` of the phase's events — the uplifts about either pivot
    (`multimass.engines.fast.path`'s contact events), quiet until `t_on` — without compiling
    the rocking events in (seconds of compile time)."""
    if not (t > t_on):
        return quiet
    sgn = 1.0 if code == EV_UPLIFT_RIGHT else -1.0
    return _uplift(sgn, t, y, m, H, K, C, mp, ep, kind, par, smp)


@njit(cache=True, error_model="numpy")
def _anchor(q, v, a0, s, w, z, gam, piece):
    """The particular solution of every mode for ü_g = a0 + s τ from here (τ = 0), and
    the free part's start: rows c0, c1, e, ė, q, ½ ė² + ½ ω² e² of `piece` (module docstring)."""
    for i in range(w.size):
        w2 = w[i] * w[i]
        c1 = -gam[i] * s / w2  # q_p = c0 + c1 τ solves the mode's equation for linear ü_g
        c0 = (-gam[i] * a0 - 2.0 * z[i] * w[i] * c1) / w2
        e, d = q[i] - c0, v[i] - c1
        piece[0, i], piece[1, i], piece[2, i], piece[3, i] = c0, c1, e, d
        piece[4, i], piece[5, i] = q[i], 0.5 * (d * d + w2 * (e * e))


@njit(cache=True, error_model="numpy", inline="always")
def _free(e, d, tau, w, z, table, e_out, d_out):
    """The free part of every mode over `tau` (coefficients from `table` (n, 4), or
    computed when it is empty)."""
    for i in range(w.size):
        if table.shape[0]:
            a11, a12, a21, a22 = table[i, 0], table[i, 1], table[i, 2], table[i, 3]
        else:
            a11, a12, a21, a22 = _free_vibration(w[i], z[i], tau)
        e_out[i], d_out[i] = a11 * e[i] + a12 * d[i], a21 * e[i] + a22 * d[i]


@njit(cache=True, error_model="numpy", inline="always")
def _modes_at(tau, e, d, piece, q, v):
    """q = q_p + e and q̇ = c1 + ė at τ into q, v."""
    for i in range(e.size):
        q[i] = piece[0, i] + piece[1, i] * tau + e[i]
        v[i] = piece[1, i] + d[i]


@njit(cache=True, error_model="numpy")
def _ledger_at(tau, e, d, q, a0, s, w, z, gam, piece, ledger0, out):
    """[D, W_g] at τ: `ledger0` at the anchor plus the exact integrals since (module docstring)."""
    D, W = ledger0[0], ledger0[1]
    for i in range(w.size):
        w2, zw2 = w[i] * w[i], 2.0 * z[i] * w[i]
        c0, c1, ea, da, qa, Ea = (
            piece[0, i],
            piece[1, i],
            piece[2, i],
            piece[3, i],
            piece[4, i],
            piece[5, i],
        )
        de, dd = e[i] - ea, d[i] - da
        D += zw2 * (c1 * c1 * tau + 2.0 * c1 * de) + (Ea - 0.5 * (d[i] * d[i] + w2 * (e[i] * e[i])))
        int_q = c0 * tau + 0.5 * c1 * tau * tau - (dd + zw2 * de) / w2
        W -= gam[i] * ((a0 + s * tau) * q[i] - a0 * qa - s * int_q)
    out[0], out[1] = D, W


@njit(cache=True, error_model="numpy")
def _physical(q, v, ledger, w_f, phi, y):
    """The state vector [u, θ = 0, u̇, θ̇ = 0, D, W_g, W_F] of modal (q, q̇) into `y`."""
    n = q.size
    for i in range(n):
        u, ud = 0.0, 0.0
        for j in range(n):
            u += phi[i, j] * q[j]
            ud += phi[i, j] * v[j]
        y[i], y[n + 1 + i] = u, ud
    y[n], y[2 * n + 1] = 0.0, 0.0
    y[2 * n + 2], y[2 * n + 3], y[2 * n + 4] = ledger[0], ledger[1], w_f


@njit(cache=True, error_model="numpy")
def _piece(t, kind, par, h_max):
    """(start, step, end, slope index) of the linear piece of ü_g holding t: its sub-grid
    of equal steps ≤ h_max from `start`, and the record interval (−1 where ü_g ≡ 0)."""
    if kind == EXC_RECORD and par[0] <= t < par[1]:
        dt = 1.0 / par[2]
        i = min(int((t - par[0]) * par[2]), int(par[3]))
        t_i = par[0] + i * dt
        end = min(par[0] + (i + 1) * dt, par[1])
        if end <= t:  # rounding put t at the end of interval i
            i += 1
            t_i, end = end, min(par[0] + (i + 1) * dt, par[1])
        n_sub = max(1, int(np.ceil(dt / h_max)))
        return t_i, dt / n_sub, end, i
    if kind == EXC_RECORD and t < par[0]:
        return 0.0, h_max, par[0], -1
    start = par[1] if kind == EXC_RECORD else 0.0
    return start, h_max, np.inf, -1


@njit(cache=True, error_model="numpy")
def contact_phase(
    t0,
    t_stop,
    y0,
    t_eval,
    m,
    H,
    K,
    C_,
    mp,
    ev_code,
    ev_dir,
    ev_quiet,
    ev_ton,
    ep,
    kind,
    par,
    smp,
    phi,
    w,
    z,
    gam,
    h_max,
    screen,
):
    """Full contact from (t0, y0) towards t_stop, exactly, with the uplift events.

    Parameters
    ----------
    t0, t_stop, y0, t_eval, m, H, K, C_, mp, ev_code, ev_dir, ev_quiet, ev_ton, ep, kind, par, smp :
        As `multimass.engines.fast._kernel.integrate_phase` (every event is terminal); the
        excitation is a record or none.
    phi, w, z, gam :
        Mass-normalised modes (columns), circular frequencies, damping ratios (≥ 0)
        and participation factors Φᵀ M 1 of full contact.
    h_max : float
        Longest interval between two event checks (s).
    screen : ndarray (3, n)
        `ContactModes.screen`.

    Returns
    -------
    The tuple of `integrate_phase` (status OK or EVENT; no RHS calls and no
    non-terminal events).
    """
    n, ny, ne = m.size, y0.size, ev_code.size
    work = (
        np.zeros(n), np.zeros(n), np.empty(2), np.empty(2), np.empty((6, n)), np.zeros(n),
        np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n),
        np.empty(ny), np.empty(ne), np.empty(ne), np.empty((0, 4)), np.empty((2, n, 4)),
        np.empty(2),
    )  # fmt: skip
    samples = np.empty((t_eval.size, ny))
    status, t, terminal, i_eval = _contact_steps(
        t0, t_stop, y0, t_eval, samples, (m, H, K, C_, mp, ep, kind, par, smp),
        (ev_code, ev_dir, ev_quiet, ev_ton), (phi, w, z, gam, screen), h_max, work,
    )  # fmt: skip
    return _result(status, t, work[12], terminal, samples[:i_eval], ny)


@njit(cache=True, error_model="numpy")
def _contact_steps(t0, t_stop, y0, t_eval, samples, args, events, modes, h_max, work):
    """The loop of `contact_phase` on its arrays (`work` its buffers, the state in
    work[12]; work[16:] the free vibration's coefficients over a record's sub-step and
    over h_max, and their steps): (status, t, terminal event, samples filled).

    Every array is taken as a view without an owner (`._unowned.unowned`):
    `contact_phase` holds them through the call, and numba then counts no references
    to them in the loop.
    """
    m, H, K, C_, mp, ep, kind, par, smp = args
    ev_code, ev_dir, ev_quiet, ev_ton = events
    phi, w, z, gam, screen = modes
    q, v, ledger0, ledger, piece, zero, e, d, e1, d1, er, dr = work[:12]
    y, g, g_new, none, tables, table_h = work[12:]
    y0, t_eval, samples = unowned(y0), unowned(t_eval), unowned(samples)
    m, H, K, C_, mp, ep = unowned(m), unowned(H), unowned(K), unowned(C_), unowned(mp), unowned(ep)
    par, smp, ev_code, ev_dir = unowned(par), unowned(smp), unowned(ev_code), unowned(ev_dir)
    ev_quiet, ev_ton = unowned(ev_quiet), unowned(ev_ton)
    phi, w, z, gam, screen = unowned(phi), unowned(w), unowned(z), unowned(gam), unowned(screen)
    q, v, ledger0, ledger = unowned(q), unowned(v), unowned(ledger0), unowned(ledger)
    piece, zero, e, d = unowned(piece), unowned(zero), unowned(e), unowned(d)
    e1, d1, er, dr = unowned(e1), unowned(d1), unowned(er), unowned(dr)
    y, g, g_new, none = unowned(y), unowned(g), unowned(g_new), unowned(none)
    tables, table_h = unowned(tables), unowned(table_h)
    n, ne = m.size, ev_code.size
    for j in range(n):  # q = Φᵀ M u
        for i in range(n):
            q[j] += phi[i, j] * (m[i] * y0[i])
            v[j] += phi[i, j] * (m[i] * y0[n + 1 + i])
    ledger0[0], ledger0[1], w_f = y0[2 * n + 2], y0[2 * n + 3], y0[2 * n + 4]
    table_h[0], table_h[1] = -1.0, -1.0
    args = (m, H, K, C_, mp, ep, kind, par, smp)
    modes, events, scratch = (w, z, gam, phi), (ev_code, ev_quiet, ev_ton), (er, dr, q, v)
    _physical(q, v, ledger0, w_f, phi, y)
    for k in range(ne):
        g[k] = _uplift_value(ev_code[k], t0, y, ev_ton[k], ev_quiet[k], 0, *args)
    t, i_eval, end = t0, 0, t0
    t_a, a0, s, start, step, seg = t0, 0.0, 0.0, t0, h_max, -1  # set at t0 in the loop
    anchor = (t_a, a0, s, piece, ledger0)
    ramp = h_max * _RAMP
    t_safe = t0  # checks may be skipped up to here (`_no_uplift_before`)
    wait, backoff = 0, 1  # checks until the next bound is tried; its next value
    while True:
        if t >= end:  # a new linear piece of ü_g: anchor its particular solution at t
            if t > t0:
                _modes_at(t - t_a, e, d, piece, q, v)
                _ledger_at(t - t_a, e, d, q, a0, s, w, z, gam, piece, ledger0, ledger)
                ledger0[0], ledger0[1] = ledger[0], ledger[1]
            start, step, end, seg = _piece(t, kind, par, h_max)
            a0, s = 0.0, 0.0
            if seg >= 0:
                a0 = smp[seg] + ((t - par[0]) * par[2] - seg) * (smp[seg + 1] - smp[seg])
                s = (smp[seg + 1] - smp[seg]) * par[2]
            t_a = t
            _anchor(q, v, a0, s, w, z, gam, piece)
            anchor = (t_a, a0, s, piece, ledger0)
            for i in range(n):
                e[i], d[i] = piece[2, i], piece[3, i]
        k_next = np.floor((t - start) / step) + 1.0
        t_new = min(start + k_next * step, end, t_stop)
        if t_new <= t:  # the sub-grid point rounded onto t
            t_new = min(start + (k_next + 1.0) * step, end, t_stop)
        if ramp < step:  # the first checks of the phase: t0 + δ, + 2δ, + 4δ, ...
            t_new = min(t_new, t + ramp)
            ramp *= 2.0
        elif t_safe > t:  # nothing to check up to t_safe: one step there
            t_new = max(t_new, min(t_safe, end, t_stop))
        tau = t_new - t
        table = none
        if abs(tau - step) <= _ULPS * max(1.0, abs(t_new)):  # a whole step: tabulated
            slot = 1 if step == h_max else 0  # a record's sub-steps, or free vibration's
            if table_h[slot] != step:
                table_h[slot] = step
                for i in range(n):
                    a = _free_vibration(w[i], z[i], step)
                    for j in range(4):
                        tables[slot, i, j] = a[j]
            table = tables[slot]
        _free(e, d, tau, w, z, table, e1, d1)
        terminal, t_root = -1, t_new
        if t_new <= t_safe:  # no uplift possible here (`_no_uplift_before`): no checks
            while i_eval < t_eval.size and t_eval[i_eval] <= t_new:
                _out(t_eval[i_eval], t, e, d, anchor, modes, w_f, scratch, ledger, samples[i_eval])
                i_eval += 1
            for i in range(n):
                e[i], d[i] = e1[i], d1[i]
            t = t_new
            if t >= t_stop:
                break
            continue
        _modes_at(t_new - t_a, e1, d1, piece, q, v)
        mapped = False
        sums = _modal_sums(q, v, screen, gam)
        for k in range(ne):
            g_new[k] = _screen(
                k, t_new, sums, a0 + s * (t_new - t_a), ev_code, ev_quiet, ev_ton, mp, ep
            )
            if g_new[k] == np.inf:
                if not mapped:
                    _physical(q, v, ledger0, w_f, phi, y)  # events do not read the ledger
                    mapped = True
                g_new[k] = _uplift_value(ev_code[k], t_new, y, ev_ton[k], ev_quiet[k], 0, *args)
        for k in range(ne):  # then the roots (their search overwrites q, v and y)
            up = g[k] <= 0.0 and g_new[k] >= 0.0
            down = g[k] >= 0.0 and g_new[k] <= 0.0
            dk = ev_dir[k]
            if not ((up and dk > 0.0) or (down and dk < 0.0) or ((up or down) and dk == 0.0)):
                continue
            r = _root(k, t, t_new, g_new[k], e, d, anchor, modes, w_f, events, args, scratch, y)
            if terminal < 0 or r < t_root:
                terminal, t_root = k, r
        t_end = t_root if terminal >= 0 else t_new
        while i_eval < t_eval.size and t_eval[i_eval] <= t_end:
            _out(t_eval[i_eval], t, e, d, anchor, modes, w_f, scratch, ledger, samples[i_eval])
            i_eval += 1
        if terminal >= 0:
            _out(t_root, t, e, d, anchor, modes, w_f, scratch, ledger, y)
            return EVENT, t_root, terminal, i_eval
        for i in range(n):
            e[i], d[i] = e1[i], d1[i]
        for k in range(ne):
            g[k] = g_new[k]
        t = t_new
        horizon = min(end, t_stop)  # the bound holds within the piece (one anchor)
        wait -= 1
        if ne and not (ramp < step) and wait <= 0:
            backoff = min(2 * backoff, _BACKOFF)  # unless a bound below succeeds
            for share in (1.0, 0.125):
                t_try = t + share * (horizon - t)
                if _no_uplift_before(
                    t - t_a, t_try - t_a, e, d, a0, s, w, gam, screen, piece, mp, ep, zero, er, dr
                ):
                    t_safe, backoff = t_try, 1
                    for k in range(ne):
                        g[k] = min(g[k], -_SCREEN)  # negative throughout, whatever the guard
                    break
            wait = backoff
        if t >= t_stop:
            break
    _modes_at(t - t_a, e, d, piece, q, v)  # reached t_stop: the state there
    _ledger_at(t - t_a, e, d, q, a0, s, w, z, gam, piece, ledger0, ledger)
    _physical(q, v, ledger, w_f, phi, y)
    return OK, t, -1, i_eval


@njit(cache=True, error_model="numpy")
def _out(tb, t, e, d, anchor, modes, w_f, scratch, ledger, y):
    """The state vector at tb (in the step from t, where the free part is e, ė) into y,
    ledger included. `anchor` = (t_a, a0, s, piece, ledger0), `modes` = (w, z, gam, phi)."""
    t_a, a0, s, piece, ledger0 = anchor
    w, z, gam, phi = modes
    er, dr, q, v = scratch
    _free(e, d, tb - t, w, z, np.empty((0, 4)), er, dr)
    _modes_at(tb - t_a, er, dr, piece, q, v)
    _ledger_at(tb - t_a, er, dr, q, a0, s, w, z, gam, piece, ledger0, ledger)
    _physical(q, v, ledger, w_f, phi, y)


@njit(cache=True, error_model="numpy", inline="always")  # inlined: one compile, not three
def _result(status, t, y, ev, samples, ny):
    """The tuple `integrate_phase` returns, without RHS calls or non-terminal events."""
    return (
        status,
        t,
        y.copy(),
        ev,
        0,
        samples,
        np.empty(0, np.int64),
        np.empty(0),
        np.empty((0, ny)),
    )


@njit(cache=True, error_model="numpy")
def _root(k, ta, tb, fb, e, d, anchor, modes, w_f, events, args, scratch, y):
    """Root of event k in [ta, tb] on the exact solution from the free part (e, ė) at ta:
    zeroin (`._rk`), from `_uplift_value` at ta (the value kept there may be screened).
    `anchor`, `modes` as `_out`; `events` = (codes, quiet values, guard ends)."""
    t_a, _, _, piece, ledger0 = anchor
    w, z, _, phi = modes
    ev_code, ev_quiet, ev_ton = events
    er, dr, q, v = scratch
    none = np.empty((0, 4))
    _modes_at(ta - t_a, e, d, piece, q, v)
    _physical(q, v, ledger0, w_f, phi, y)
    fa = _uplift_value(ev_code[k], ta, y, ev_ton[k], ev_quiet[k], 0, *args)
    if fa == 0.0:
        return ta
    if fb == 0.0 or (fa > 0.0) == (fb > 0.0):
        return tb
    a, b = ta, tb
    c, fc, dd, ee = b, fb, b - a, b - a
    for _ in range(_MAX_BRENT):
        done, a, fa, b, c, fc, dd, ee = zeroin_next(a, fa, b, fb, c, fc, dd, ee)
        if done:
            return b
        _free(e, d, b - ta, w, z, none, er, dr)
        _modes_at(b - t_a, er, dr, piece, q, v)
        _physical(q, v, ledger0, w_f, phi, y)
        fb = _uplift_value(ev_code[k], b, y, ev_ton[k], ev_quiet[k], 0, *args)
    return b
