"""`integrate_phase`: one phase of the time history in machine code (one solve_ivp call).

The loop mirrors ``solve_ivp`` with events and ``t_eval`` (see `._rk` for the
step, the dense output and the root finder): step; evaluate the event
functions at the step end; locate the roots of the active ones on the dense
output; end at the earliest terminal root; fill the output grid up to the
end of the step (or the terminal root).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._maths import EV_PEAK, EV_ZERO, EXC_RECORD, event_value, piece_end, rhs_call
from ._rk import (
    _A3,
    _A5,
    _A8,
    _B3,
    _B5,
    _B8,
    _C3,
    _C5,
    _C8,
    _DOP,
    _NEXT8,
    _NS8,
    EVENT,
    FAILED,
    OK,
    PI_BETA,
    PI_KAPPA,
    _brent,
    _dense_eval,
    _dense_prepare,
    _error_norm,
    _first_step,
    _rk_step,
    crosses,
    step_control,
    trial_step,
)
from ._unowned import unowned

__all__ = ["integrate_phase", "controller"]


@njit(cache=True, error_model="numpy")
def _tableau(method):
    """(A, B, C, stages, rows of K, error order, dense coefficients) of a method code."""
    if method == _DOP:
        return _A8, _B8, _C8, _NS8, _NEXT8, 7, 7
    if method == 1:
        return _A5, _B5, _C5, 6, 7, 4, 4
    return _A3, _B3, _C3, 3, 4, 2, 3


@njit(cache=True, error_model="numpy", inline="always")
def controller(method, n_masses, kind):
    """(β, κ) of `._rk.step_control` for a phase: a column's DOP853 steps take the PI
    controller (`._rk.PI_BETA`, `PI_KAPPA`), except under a record, whose samples cut
    the steps (`._maths.piece_end`): there it took 0.2–4 % fewer right-hand sides but
    3 % more CPU time for S1 under El Centro (more accepted steps, each with its
    events). A rigid block's (no masses) and the other pairs': SciPy's (β = 0), the same
    steps as solve_ivp's."""
    if method == _DOP and n_masses > 0 and kind != EXC_RECORD:
        return PI_BETA, PI_KAPPA
    return 0.0, 0.0


@njit(cache=True, error_model="numpy")
def _accepted_step(
    t, y, f, h_abs, log_prev, t_stop, max_step, rtol, atol, method, tab, work, model
):
    """One accepted step from (t, y): `._rk.step_control` with the tableau's β and κ
    (SciPy's RungeKutta control at β = 0), `log_prev` ln of the last accepted step's
    error norm (0: none).

    Under a record no step crosses a sample of ü_g (`._maths.piece_end`: ü_g has a kink
    there, which an explicit pair sees as a large local error and answers with a
    rejection and a run of short steps): the rest of the sample's interval is split
    into equal steps no longer than the proposed size, and a step shortened so does
    not shorten the next proposal.

    Returns (ok, t_new, h, next |h|, ln of its error norm, RHS calls); the new state is in work[1]
    and the stages in work[0]. ok is False when |h| fell below 10 ulp(t).
    """
    A, Bw, C, ns, exponent, beta, kappa = tab
    Kst, ynew, ytmp, scale = work
    side, m, H, K, C_, mp, fp, kind, par, smp = model
    nfev = 0
    min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
    if h_abs > max_step:
        h_abs = max_step
    elif h_abs < min_step:
        h_abs = min_step
    piece = piece_end(t, kind, par)
    t_end = min(t_stop, piece)
    rejected = False
    while True:
        if h_abs < min_step:
            return False, t, 0.0, h_abs, log_prev, nfev
        h, t_new = trial_step(t, h_abs, t_end, piece)
        _rk_step(
            t, y, f, h, A, Bw, C, ns, Kst, ynew, ytmp, side, m, H, K, C_, mp, fp, kind, par, smp
        )
        nfev += ns
        for j in range(y.size):
            scale[j] = atol + max(abs(y[j]), abs(ynew[j])) * rtol
        err = _error_norm(method, Kst, h, scale, ns, ytmp)
        accepted, h_abs, log_err = step_control(
            err, exponent, rejected, h, h_abs, log_prev, beta, kappa
        )
        if accepted:
            return True, t_new, h, h_abs, log_err, nfev
        rejected = True


@njit(cache=True, error_model="numpy")
def _event_values(t, y, out, events, ep, model):
    ev_code, _, _, ev_quiet, ev_ton = events
    side, m, H, K, C_, mp, _, kind, par, smp = model
    for k in range(ev_code.size):
        out[k] = event_value(
            ev_code[k], t, y, ev_ton[k], ev_quiet[k], side, m, H, K, C_, mp, ep, kind, par, smp
        )


@njit(cache=True, error_model="numpy")
def _active(g, g_new, ev_dir, active):
    """Events whose sign changed over the step in their direction (0: either)."""
    n_act = 0
    for k in range(g.size):
        if crosses(g[k], g_new[k], ev_dir[k]):
            active[n_act] = k
            n_act += 1
    return n_act


@njit(cache=True, error_model="numpy")
def _sorted_roots(n_act, active, roots, t_old, t, h, y_old, Q, ytmp, method, events, ep, model):
    """Roots of the active events on the dense output, sorted by time (stable)."""
    ev_code, _, _, ev_quiet, ev_ton = events
    side, m, H, K, C_, mp, _, kind, par, smp = model
    for i in range(n_act):
        k = active[i]
        roots[i] = _brent(
            ev_code[k],
            t_old,
            t,
            ev_ton[k],
            ev_quiet[k],
            method,
            t_old,
            h,
            y_old,
            Q,
            ytmp,
            side,
            m,
            H,
            K,
            C_,
            mp,
            ep,
            kind,
            par,
            smp,
        )
    for i in range(1, n_act):
        k, r = active[i], roots[i]
        j = i - 1
        while j >= 0 and roots[j] > r:
            active[j + 1] = active[j]
            roots[j + 1] = roots[j]
            j -= 1
        active[j + 1] = k
        roots[j + 1] = r


@njit(cache=True, error_model="numpy")
def _zero_between(
    n_act, active, roots, g, t_old, h, y_old, Q, ytmp, method, events, ep, model, atol
):
    """The θ = 0 crossing of a step whose ends are both on the rocking side: where θ̇
    changes sign inside the step (its root sorted in `roots`) with θ past zero there by
    more than `atol` (less is within the step's own error) and θ on the rocking side at
    the step's start (not 0, as at an uplift, where θ and θ̇ start at 0), θ crossed zero
    twice in the step — a grazing approach that the sign test of its ends cannot see,
    and the impact (or Eq 17's end of the Dirac-delta force) it must not miss. The first
    crossing, on the dense output in [t_old, θ̇'s root], joins the sorted roots; returns
    their number. A column's phases only (m non-empty): a rigid block's batched
    kernels, which must give its runs bit for bit, have no such test."""
    ev_code, _, _, ev_quiet, ev_ton = events
    side, m, H, K, C_, mp, _, kind, par, smp = model
    if m.size == 0 or not (side * y_old[m.size] > 0.0):
        return n_act
    k_zero, i_peak = -1, -1
    for k in range(ev_code.size):
        if ev_code[k] == EV_ZERO:
            k_zero = k
    for i in range(n_act):
        if ev_code[active[i]] == EV_PEAK:
            i_peak = i
        if active[i] == k_zero:
            return n_act  # its sign changed: found as any other root
    if k_zero < 0 or i_peak < 0 or not (g[k_zero] > 0.0):
        return n_act
    t_p = roots[i_peak]
    _dense_eval(method, t_p, t_old, h, y_old, Q, ytmp)
    at_peak = event_value(  # its code from the array: an int64, as every call's (one compile)
        ev_code[k_zero], t_p, ytmp, ev_ton[k_zero], ev_quiet[k_zero], side, m, H, K, C_, mp, ep, kind,
        par, smp,
    )  # fmt: skip
    if not (at_peak < -atol):
        return n_act
    tz = _brent(
        ev_code[k_zero], t_old, t_p, ev_ton[k_zero], ev_quiet[k_zero], method, t_old, h, y_old, Q, ytmp,
        side, m, H, K, C_, mp, ep, kind, par, smp,
    )  # fmt: skip
    j = n_act  # insert (k_zero, tz) in time order, after equal roots (stable)
    while j > 0 and roots[j - 1] > tz:
        active[j], roots[j] = active[j - 1], roots[j - 1]
        j -= 1
    active[j], roots[j] = k_zero, tz
    return n_act + 1


@njit(cache=True, error_model="numpy")
def _push(buf, n, k, tr, method, t_old, h, y_old, Q):
    """Append a non-terminal root (event k at tr) to buf = (index, t, y), growing it."""
    idx, ts, ys = buf
    if n == idx.size:
        idx2, ts2, ys2 = (
            np.empty(2 * n, np.int64),
            np.empty(2 * n),
            np.empty((2 * n, ys.shape[1])),
        )
        for i in range(n):  # loops, not slices: no shape-check messages to compile
            idx2[i], ts2[i] = idx[i], ts[i]
            for j in range(ys.shape[1]):
                ys2[i, j] = ys[i, j]
        idx, ts, ys = idx2, ts2, ys2
    idx[n], ts[n] = k, tr
    _dense_eval(method, tr, t_old, h, y_old, Q, ys[n])
    return idx, ts, ys


@njit(cache=True, error_model="numpy")
def integrate_phase(
    t0,
    t_stop,
    y0,
    t_eval,
    side,
    m,
    H,
    K,
    C_,
    mp,
    fp,
    ev_code,
    ev_dir,
    ev_term,
    ev_quiet,
    ev_ton,
    ep,
    kind,
    par,
    smp,
    method,
    rtol,
    atol,
    max_step,
    hint,
):
    """Integrate the phase `side` from (t0, y0) towards t_stop with events.

    Parameters
    ----------
    t0, t_stop : float
        Start and stop times (t_stop > t0).
    y0 : ndarray
        Start state [u, θ, u̇, θ̇, D, W_g, W_F].
    t_eval : ndarray
        Output times in (t0, t_stop], increasing.
    side : int
        0 full contact, ±1 rocking.
    m, H, K, C_, mp, fp :
        Model arrays and scalars, the Dirac-delta force (see `._maths`).
    ev_code, ev_dir, ev_term, ev_quiet, ev_ton, ep :
        Event codes, directions, terminal flags (1/0), quiet values, times the
        quiet guard ends, and event parameters.
    kind, par, smp :
        The encoded excitation.
    method : int
        `METHOD_CODES` of ``RK23``, ``RK45`` or ``DOP853``.
    rtol, atol, max_step : float
        As in solve_ivp.
    hint : ndarray (1,) or (2,)
        The first step to try if hint[0] > 0 (else the Hairer–Nørsett–Wanner guess of
        `._rk._first_step`); on return, the step the controller proposes next. A run
        passes the same array from one phase segment to the next, so a segment starts
        at the step size the last one ended with instead of a guess that the
        controller must first cut down (a rejected DOP853 step costs 12 calls). With
        two entries, hint[1] carries the PI controller's ln err_{n−1}
        (`._rk.step_control`; 0: none) the same way.

    Returns
    -------
    status, t, y, ev_index, nfev, samples, nt_index, nt_t, nt_y
        `status` OK (t = t_stop), EVENT (terminal event `ev_index` at t) or
        FAILED (step size underflow at t); the samples on `t_eval` reached;
        non-terminal event roots (index, time, state), in time order.
    """
    _, _, _, _, n_k, _, nq = _tableau(method)
    ny, ne = y0.size, ev_code.size
    work = (
        np.empty((n_k, ny)), np.empty(ny), np.empty(ny), np.empty(ny), np.empty(ny),
        np.empty((nq, ny)), np.empty(ny), np.empty(ne), np.empty(ne),
        np.empty(ne, np.int64), np.empty(ne),
    )  # fmt: skip
    y, samples = y0.copy(), np.empty((t_eval.size, ny))
    buf = (np.empty(8, np.int64), np.empty(8), np.empty((8, ny)))
    status, t, terminal, nfev, i_eval, buf, n_nt = _steps(
        t0, t_stop, y, t_eval, samples, (side, m, H, K, C_, mp, fp, kind, par, smp),
        (ev_code, ev_dir, ev_term, ev_quiet, ev_ton), ep, method, (rtol, atol, max_step),
        hint, work, buf,
    )  # fmt: skip
    return (
        status,
        t,
        y,
        terminal,
        nfev,
        samples[:i_eval],
        buf[0][:n_nt],
        buf[1][:n_nt],
        buf[2][:n_nt],
    )


@njit(cache=True, error_model="numpy")
def _steps(t0, t_stop, y, t_eval, samples, model, events, ep, method, tol, hint, work, buf):
    """The step loop of `integrate_phase` on its arrays (y: y0 on entry, the end state on
    return; `work` its buffers): (status, t, terminal event, RHS calls, samples filled,
    buf, non-terminal roots in buf).

    Every array but `buf` (grown by `_push`) is taken as a view without an owner
    (`._unowned.unowned`): `integrate_phase` holds them through the call, and numba then
    counts no references to them in the loop (they were a quarter of the compiled samples
    of a column run under a record).
    """
    side, m, H, K, C_, mp, fp, kind, par, smp = model
    ev_code, ev_dir, ev_term, ev_quiet, ev_ton = events
    rtol, atol, max_step = tol
    Kst, ynew, ytmp, f, scale, Q, y_old, g, g_new, active, roots = work
    y, t_eval, samples, hint = unowned(y), unowned(t_eval), unowned(samples), unowned(hint)
    m, H, K, C_, mp = unowned(m), unowned(H), unowned(K), unowned(C_), unowned(mp)
    fp, par, smp, ep = unowned(fp), unowned(par), unowned(smp), unowned(ep)
    ev_code, ev_dir, ev_term = unowned(ev_code), unowned(ev_dir), unowned(ev_term)
    ev_quiet, ev_ton = unowned(ev_quiet), unowned(ev_ton)
    Kst, ynew, ytmp = unowned(Kst), unowned(ynew), unowned(ytmp)
    f, scale = unowned(f), unowned(scale)
    Q, y_old, g, g_new = unowned(Q), unowned(y_old), unowned(g), unowned(g_new)
    active, roots = unowned(active), unowned(roots)
    A, Bw, C, ns, _, err_order, _ = _tableau(method)
    ny, ne = y.size, ev_code.size
    model = (side, m, H, K, C_, mp, fp, kind, par, smp)
    events = (ev_code, ev_dir, ev_term, ev_quiet, ev_ton)
    beta, kappa = controller(method, m.size, kind)
    tab = (A, Bw, C, ns, -1.0 / (err_order + 1), beta, kappa)
    log_prev = 0.0  # no memory (a first segment, a block): the factor is err^(exponent + κβ)
    work = (Kst, ynew, ytmp, scale)
    t, i_eval, n_nt = t0, 0, np.int64(0)  # int64, not the literal 0: _push compiles once
    rhs_call(t, y, f, side, m, H, K, C_, mp, fp, kind, par, smp)
    nfev = 1
    h_abs = hint[0]
    if hint.size > 1:
        log_prev = hint[1]
    if not (h_abs > 0.0):
        h_abs = _first_step(
            t, y, f, t_stop, max_step, err_order, rtol, atol, ytmp, ynew, side, m, H, K, C_,
            mp, fp, kind, par, smp,
        )  # fmt: skip
        nfev = 2
    _event_values(t, y, g, events, ep, model)
    while True:
        ok, t_new, h, h_abs, log_prev, calls = _accepted_step(
            t, y, f, h_abs, log_prev, t_stop, max_step, rtol, atol, method, tab, work, model
        )
        nfev += calls
        hint[0] = h_abs
        if hint.size > 1:
            hint[1] = log_prev
        if not ok:
            return FAILED, t, -1, nfev, i_eval, buf, n_nt
        t_old, t = t, t_new
        for j in range(ny):  # loops, not slices: no shape-check messages to compile
            y_old[j] = y[j]
            y[j] = ynew[j]
            f[j] = Kst[ns, j]
        finished = t - t_stop >= 0.0
        dense, terminal = False, -1
        # events: sign changes over the step, roots on the dense output (earliest first)
        _event_values(t, y, g_new, events, ep, model)
        n_act = _active(g, g_new, ev_dir, active)
        if n_act:
            nfev += _dense_prepare(
                method,
                t_old,
                h,
                y_old,
                ynew,
                Kst,
                ns,
                Q,
                ytmp,
                side,
                m,
                H,
                K,
                C_,
                mp,
                fp,
                kind,
                par,
                smp,
            )
            dense = True
            _sorted_roots(
                n_act, active, roots, t_old, t, h, y_old, Q, ytmp, method, events, ep, model
            )
            n_act = _zero_between(
                n_act, active, roots, g, t_old, h, y_old, Q, ytmp, method, events, ep, model, atol
            )
            for i in range(n_act):
                if ev_term[active[i]]:
                    terminal, t = active[i], roots[i]
                    _dense_eval(method, t, t_old, h, y_old, Q, y)
                    break
                buf = _push(buf, n_nt, active[i], roots[i], method, t_old, h, y_old, Q)
                n_nt += 1
        for k in range(ne):
            g[k] = g_new[k]
        # output grid up to t (the end of the step or the terminal root)
        while i_eval < t_eval.size and t_eval[i_eval] <= t:
            if not dense:
                nfev += _dense_prepare(
                    method,
                    t_old,
                    h,
                    y_old,
                    ynew,
                    Kst,
                    ns,
                    Q,
                    ytmp,
                    side,
                    m,
                    H,
                    K,
                    C_,
                    mp,
                    fp,
                    kind,
                    par,
                    smp,
                )
                dense = True
            _dense_eval(method, t_eval[i_eval], t_old, h, y_old, Q, samples[i_eval])
            i_eval += 1
        if terminal >= 0 or finished:
            return (EVENT if terminal >= 0 else OK), t, terminal, nfev, i_eval, buf, n_nt
