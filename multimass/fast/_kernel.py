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

from ._maths import event_value, rhs
from ._rk import (_A3, _A5, _A8, _B3, _B5, _B8, _C3, _C5, _C8, _DOP, _MAX_FACTOR, _MIN_FACTOR,
                  _NEXT8, _NS8, _SAFETY, EVENT, FAILED, OK, _brent, _dense_eval, _dense_prepare,
                  _error_norm, _first_step, _rk_step)

__all__ = ["integrate_phase"]


@njit(cache=True, error_model="numpy")
def _tableau(method):
    """(A, B, C, stages, rows of K, error order, dense coefficients) of a method code."""
    if method == _DOP:
        return _A8, _B8, _C8, _NS8, _NEXT8, 7, 7
    if method == 1:
        return _A5, _B5, _C5, 6, 7, 4, 4
    return _A3, _B3, _C3, 3, 4, 2, 3


@njit(cache=True, error_model="numpy")
def integrate_phase(t0, t_stop, y0, t_eval, side, m, H, K, C_, mp, fp,
                    ev_code, ev_dir, ev_term, ev_quiet, ev_ton, ep, kind, par, smp,
                    method, rtol, atol, max_step):
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

    Returns
    -------
    status, t, y, ev_index, nfev, samples, nt_index, nt_t, nt_y
        `status` OK (t = t_stop), EVENT (terminal event `ev_index` at t) or
        FAILED (step size underflow at t); the samples on `t_eval` reached;
        non-terminal event roots (index, time, state), in time order.
    """
    A, Bw, C, ns, n_k, err_order, nq = _tableau(method)
    ny = y0.size
    Kst = np.empty((n_k, ny))
    Q = np.empty((nq, ny))
    y = y0.copy()
    y_old = np.empty(ny)
    ynew = np.empty(ny)
    ytmp = np.empty(ny)
    f = np.empty(ny)
    scale = np.empty(ny)
    t = t0
    rhs(t, y, f, side, m, H, K, C_, mp, fp, kind, par, smp)
    h_abs = _first_step(t, y, f, t_stop, max_step, err_order, rtol, atol, ytmp, ynew,
                        side, m, H, K, C_, mp, fp, kind, par, smp)
    nfev = 2
    exponent = -1.0 / (err_order + 1)
    ne = ev_code.size
    g = np.empty(ne)
    g_new = np.empty(ne)
    for k in range(ne):
        g[k] = event_value(ev_code[k], t, y, ev_ton[k], ev_quiet[k], side, m, H, K, C_, mp, ep,
                           kind, par, smp)
    samples = np.empty((t_eval.size, ny))
    i_eval = 0
    cap = 8
    nt_i = np.empty(cap, np.int64)
    nt_t = np.empty(cap)
    nt_y = np.empty((cap, ny))
    n_nt = 0
    active = np.empty(ne, np.int64)
    roots = np.empty(ne)
    while True:
        # -- one accepted step (step-size control of SciPy's RungeKutta)
        min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
        if h_abs > max_step:
            h_abs = max_step
        elif h_abs < min_step:
            h_abs = min_step
        rejected = False
        while True:
            if h_abs < min_step:
                return (FAILED, t, y, -1, nfev, samples[:i_eval], nt_i[:n_nt], nt_t[:n_nt],
                        nt_y[:n_nt])
            t_new = t + h_abs
            if t_new - t_stop > 0.0:
                t_new = t_stop
            h = t_new - t
            h_abs = abs(h)
            _rk_step(t, y, f, h, A, Bw, C, ns, Kst, ynew, ytmp, side, m, H, K, C_, mp, fp,
                     kind, par, smp)
            nfev += ns
            for j in range(ny):
                scale[j] = atol + max(abs(y[j]), abs(ynew[j])) * rtol
            err = _error_norm(method, Kst, h, scale, ns, ytmp)
            if err < 1.0:
                factor = _MAX_FACTOR if err == 0.0 else _SAFETY * err ** exponent
                if not (factor < _MAX_FACTOR):
                    factor = _MAX_FACTOR
                if rejected and factor > 1.0:
                    factor = 1.0
                h_abs *= factor
                break
            factor = _SAFETY * err ** exponent
            if not (factor > _MIN_FACTOR):
                factor = _MIN_FACTOR
            h_abs *= factor
            rejected = True
        t_old = t
        for j in range(ny):
            y_old[j] = y[j]
            y[j] = ynew[j]
            f[j] = Kst[ns, j]
        t = t_new
        finished = t - t_stop >= 0.0
        dense = False
        terminal = -1
        # -- events: sign changes over the step, roots on the dense output
        n_act = 0
        for k in range(ne):
            g_new[k] = event_value(ev_code[k], t, y, ev_ton[k], ev_quiet[k], side, m, H, K, C_,
                                   mp, ep, kind, par, smp)
            up = g[k] <= 0.0 and g_new[k] >= 0.0
            down = g[k] >= 0.0 and g_new[k] <= 0.0
            d = ev_dir[k]
            if (up and d > 0.0) or (down and d < 0.0) or ((up or down) and d == 0.0):
                active[n_act] = k
                n_act += 1
        if n_act:
            nfev += _dense_prepare(method, t_old, h, y_old, ynew, Kst, ns, Q, ytmp,
                                   side, m, H, K, C_, mp, fp, kind, par, smp)
            dense = True
            for i in range(n_act):
                k = active[i]
                roots[i] = _brent(ev_code[k], t_old, t, ev_ton[k], ev_quiet[k], method, t_old,
                                  h, y_old, Q, ytmp, side, m, H, K, C_, mp, ep, kind, par, smp)
            for i in range(1, n_act):                 # stable sort by root time
                k, r = active[i], roots[i]
                j = i - 1
                while j >= 0 and roots[j] > r:
                    active[j + 1] = active[j]
                    roots[j + 1] = roots[j]
                    j -= 1
                active[j + 1] = k
                roots[j + 1] = r
            for i in range(n_act):
                k = active[i]
                if ev_term[k]:
                    terminal = k
                    t = roots[i]
                    _dense_eval(method, t, t_old, h, y_old, Q, y)
                    break
                if n_nt == cap:                       # grow the non-terminal buffers
                    cap *= 2
                    nt_i2 = np.empty(cap, np.int64)
                    nt_t2 = np.empty(cap)
                    nt_y2 = np.empty((cap, ny))
                    nt_i2[:n_nt] = nt_i[:n_nt]
                    nt_t2[:n_nt] = nt_t[:n_nt]
                    nt_y2[:n_nt] = nt_y[:n_nt]
                    nt_i, nt_t, nt_y = nt_i2, nt_t2, nt_y2
                nt_i[n_nt] = k
                nt_t[n_nt] = roots[i]
                _dense_eval(method, roots[i], t_old, h, y_old, Q, nt_y[n_nt])
                n_nt += 1
        for k in range(ne):
            g[k] = g_new[k]
        # -- output grid up to t (the end of the step or the terminal root)
        while i_eval < t_eval.size and t_eval[i_eval] <= t:
            if not dense:
                nfev += _dense_prepare(method, t_old, h, y_old, ynew, Kst, ns, Q, ytmp,
                                       side, m, H, K, C_, mp, fp, kind, par, smp)
                dense = True
            _dense_eval(method, t_eval[i_eval], t_old, h, y_old, Q, samples[i_eval])
            i_eval += 1
        if terminal >= 0 or finished:
            status = EVENT if terminal >= 0 else OK
            return (status, t, y, terminal, nfev, samples[:i_eval], nt_i[:n_nt], nt_t[:n_nt],
                    nt_y[:n_nt])
