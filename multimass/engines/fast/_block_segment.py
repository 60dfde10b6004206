"""One rocking segment of a rigid block: `._kernel.integrate_phase` for its five states.

A rigid block (N = 0) rocks with the state y = [θ, θ̇, D, W_g, W_F]. `rocking_segment`
integrates it from one restart to the first of θ = 0, overturning or the segment's stop,
as ``integrate_phase(t0, t_stop, y0, [t_stop], side, …)`` with the events of a rocking
phase does — the same tableau (`._kernel._tableau`), first step (`._rk._first_step`),
step-size control, error norm (`._rk._error_norm`), dense output (`._rk._dense_prepare`,
`._rk._dense_eval`), event functions (`._maths.event_value`) and root finder
(`._rk._brent`), in the same order, so the same steps, roots and states bit for bit —
with what a block does not need taken out:

* the state's length is the constant `NY`, so the stage sums of the step are unrolled;
* every buffer is made once (`workspace`) and reused by every segment of every cell;
* the step, its stages and the event functions are inlined into the segment's loop,
  every stage's RHS reads the same argument array, and the block's empty node arrays and
  its Dirac-delta force (off) are module constants: numba's atomic reference counts of
  the arrays passed between them took a quarter of the time and more;
* every array it touches is a view without an owner (`._unowned.unowned`), so that numba
  counts no references to it in the step loop;
* the only output sample is the state at t_stop, and the θ̇ = 0 roots (the half-cycle
  peaks) give their |θ| only.

The right-hand side is `._maths.rocking_rhs` (the equations of rocking with no elastic
nodes), inlined here once.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._kernel import _active, _sorted_roots, _tableau
from ._maths import FP_SIZE, event_value, piece_end, rhs_call, rocking_rhs
from ._rk import (
    EVENT,
    FAILED,
    OK,
    _dense_eval,
    _dense_prepare,
    _error_norm,
    _first_step,
    step_control,
    trial_step,
)
from ._unowned import unowned

__all__ = ["NY", "workspace", "rocking_segment"]

#: The state's length for a rigid block: θ, θ̇ and the ledger's D, W_g, W_F.
NY = 5
_ROWS, _DENSE = 16, 7  # rows of the stages (DOP853's extended tableau), of the interpolant
# a rigid body's elastic nodes (none) and its Dirac-delta force (off): module constants,
# which numba freezes into the code, so that no step counts references to them
_M, _MAT, _FP = np.empty(0), np.empty((0, 0)), np.zeros(FP_SIZE)

# `._maths.event_value` (the same function) inlined into the step loop: a call with its
# fifteen arguments cost as much as the three events' work
_event_value = njit(inline="always", error_model="numpy")(event_value.py_func)


@njit(cache=True, error_model="numpy")
def workspace(n_events):
    """The buffers of `rocking_segment`, made once per batch of cells.

    (stages, y_new, y_tmp, f, scale, interpolant, y, y_old, g, g_new, active, roots,
    t_on, sample).
    """
    return (
        np.empty((_ROWS, NY)), np.empty(NY), np.empty(NY), np.empty(NY), np.empty(NY),
        np.empty((_DENSE, NY)), np.empty(NY), np.empty(NY), np.empty(n_events),
        np.empty(n_events), np.empty(n_events, np.int64), np.empty(n_events),
        np.empty(n_events), np.empty(NY),
    )  # fmt: skip


@njit(cache=True, error_model="numpy", inline="always")
def _stages(t, y, f, h, A, Bw, C, ns, Kst, ynew, ytmp, side, mp, kind, par, smp):
    """`._rk._rk_step` for NY states: stages in Kst[0..ns], the solution in ynew.

    Each component's sum runs over k in order, from 0.0, as `_rk_step`'s does (the same
    rounding), in a local variable rather than in memory.
    """
    for j in range(NY):
        Kst[0, j] = f[j]
    for s in range(1, ns + 1):
        last = s == ns
        s0 = s1 = s2 = s3 = s4 = 0.0
        for k in range(s):
            a = Bw[k] if last else A[s, k]
            s0 += Kst[k, 0] * a
            s1 += Kst[k, 1] * a
            s2 += Kst[k, 2] * a
            s3 += Kst[k, 3] * a
            s4 += Kst[k, 4] * a
        if last:  # the solution, y + h Σ b K, and the argument of its slope
            ts = t + h
            ynew[0], ynew[1], ynew[2] = y[0] + h * s0, y[1] + h * s1, y[2] + h * s2
            ynew[3], ynew[4] = y[3] + h * s3, y[4] + h * s4
            for j in range(NY):
                ytmp[j] = ynew[j]
        else:  # a stage's argument, y + (Σ a K) h
            ts = t + C[s] * h
            ytmp[0], ytmp[1], ytmp[2] = y[0] + s0 * h, y[1] + s1 * h, y[2] + s2 * h
            ytmp[3], ytmp[4] = y[3] + s3 * h, y[4] + s4 * h
        # one array for every stage: an array chosen per branch would count references
        rocking_rhs(ts, ytmp, Kst[s], side, _M, _M, _MAT, _MAT, mp, _FP, kind, par, smp)


@njit(cache=True, error_model="numpy", inline="always")
def _accepted_step(t, y, f, h_abs, t_stop, cfg, method, tab, work, model):
    """`._kernel._accepted_step` for NY states: (ok, t_new, h, next |h|, RHS calls)."""
    A, Bw, C, ns, exponent = tab
    Kst, ynew, ytmp, scale = work
    side, mp, kind, par, smp = model
    rtol, atol, max_step = cfg
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
            return False, t, 0.0, h_abs, nfev
        h, t_new = trial_step(t, h_abs, t_end, piece)
        _stages(t, y, f, h, A, Bw, C, ns, Kst, ynew, ytmp, side, mp, kind, par, smp)
        nfev += ns
        for j in range(NY):
            scale[j] = atol + max(abs(y[j]), abs(ynew[j])) * rtol
        err = _error_norm(method, Kst, h, scale, ns, ytmp)
        # SciPy's control (β = 0): a block's steps are solve_ivp's
        accepted, h_abs, _ = step_control(err, exponent, rejected, h, h_abs, 0.0, 0.0, 0.0)
        if accepted:
            return True, t_new, h, h_abs, nfev
        rejected = True


@njit(cache=True, error_model="numpy", inline="always")
def _event_values(t, y, out, events, ep, t_on, model):
    codes, quiet = events[0], events[3]
    side, mp, kind, par, smp = model
    for k in range(codes.size):
        out[k] = _event_value(
            codes[k], t, y, t_on[k], quiet[k], side, _M, _M, _MAT, _MAT, mp, ep, kind, par, smp
        )


@njit(cache=True, error_model="numpy")
def rocking_segment(t0, t_stop, y0, side, method, tol, events, ep, exc, mp, ws):
    """Integrate rocking on pivot `side` from (t0, y0) towards t_stop with `events`.

    Parameters
    ----------
    t0, t_stop : float
        Start and stop (t_stop > t0).
    y0 : ndarray (NY,)
        The start state; on OK or EVENT it becomes the end state (on OK the dense output
        at t_stop, as `integrate_phase`'s sample there), on FAILED it is left as it was.
    side : int
        The pivot, ±1.
    method : int
        `._rk.METHOD_CODES`.
    tol : tuple
        (rtol, atol, max_step), as in solve_ivp.
    events : tuple
        Codes, directions, terminal flags, quiet values, and the times each is held quiet
        until (`integrate_phase`'s ev_code, ev_dir, ev_term, ev_quiet, ev_ton).
    ep, mp : ndarray
        Event parameters and model scalars (`._maths`).
    exc : tuple
        The excitation (kind, par, samples).
    ws : tuple
        `workspace`.

    Returns
    -------
    status, t, event, nfev, peak
        `status` OK, EVENT (terminal event `event` at t) or FAILED (step-size underflow,
        or a state or sample that is not finite); RHS calls as `integrate_phase` counts
        them; max |θ| of the θ̇ = 0 roots before the end.
    """
    Kst, ynew, ytmp, f, scale, Q, y, y_old, g, g_new, active, roots, _, sample = ws
    codes, dirs, term, quiet, t_on = events
    kind, par, smp = exc
    # every array the steps touch, as a view that numba does not count references of
    Kst, ynew, ytmp, f = unowned(Kst), unowned(ynew), unowned(ytmp), unowned(f)
    scale, Q, y, y_old = unowned(scale), unowned(Q), unowned(y), unowned(y_old)
    g, g_new, active, roots = unowned(g), unowned(g_new), unowned(active), unowned(roots)
    sample, y0, ep, mp = unowned(sample), unowned(y0), unowned(ep), unowned(mp)
    par, smp, codes, dirs = unowned(par), unowned(smp), unowned(codes), unowned(dirs)
    term, quiet, t_on = unowned(term), unowned(quiet), unowned(t_on)
    events = (codes, dirs, term, quiet, t_on)
    A, Bw, C, ns, _, err_order, _ = _tableau(method)
    model = (side, mp, kind, par, smp)
    m, mat, fp = _M, _MAT, _FP
    tab = (A, Bw, C, ns, -1.0 / (err_order + 1))
    rtol, atol, max_step = tol
    for j in range(NY):
        y[j] = y0[j]
    t, peak = t0, 0.0
    rhs_call(t, y, f, side, m, m, mat, mat, mp, fp, kind, par, smp)
    h_abs = _first_step(
        t, y, f, t_stop, max_step, err_order, rtol, atol, ytmp, ynew, side, m, m, mat, mat,
        mp, fp, kind, par, smp,
    )  # fmt: skip
    nfev = 2
    _event_values(t, y, g, events, ep, t_on, model)
    while True:
        ok, t_new, h, h_abs, calls = _accepted_step(
            t, y, f, h_abs, t_stop, tol, method, tab, (Kst, ynew, ytmp, scale), model
        )
        nfev += calls
        if not ok:
            return FAILED, t, -1, nfev, peak
        t_old, t = t, t_new
        for j in range(NY):
            y_old[j] = y[j]
            y[j] = ynew[j]
            f[j] = Kst[ns, j]
        finished = t - t_stop >= 0.0
        dense, terminal = False, -1
        _event_values(t, y, g_new, events, ep, t_on, model)
        n_act = _active(g, g_new, dirs, active)
        if n_act:
            nfev += _dense_prepare(
                method, t_old, h, y_old, ynew, Kst, ns, Q, ytmp, side, m, m, mat, mat, mp,
                fp, kind, par, smp,
            )  # fmt: skip
            dense = True
            _sorted_roots(
                n_act, active, roots, t_old, t, h, y_old, Q, ytmp, method,
                (codes, dirs, term, quiet, t_on), ep, (side, m, m, mat, mat, mp, fp, kind, par, smp),
            )  # fmt: skip
            for i in range(n_act):
                if term[active[i]]:
                    terminal, t = active[i], roots[i]
                    _dense_eval(method, t, t_old, h, y_old, Q, y)
                    break
                _dense_eval(method, roots[i], t_old, h, y_old, Q, ytmp)  # a peak
                peak = max(peak, abs(ytmp[0]))
        for k in range(g.size):
            g[k] = g_new[k]
        sampled = t_stop <= t
        if sampled:  # the output grid [t_stop]
            if not dense:
                nfev += _dense_prepare(
                    method, t_old, h, y_old, ynew, Kst, ns, Q, ytmp, side, m, m, mat, mat,
                    mp, fp, kind, par, smp,
                )  # fmt: skip
            _dense_eval(method, t_stop, t_old, h, y_old, Q, sample)
        if terminal >= 0 or finished:
            for j in range(NY):
                if not (math.isfinite(y[j]) and (not sampled or math.isfinite(sample[j]))):
                    return FAILED, t, -1, nfev, peak
            end = y if terminal >= 0 else sample
            for j in range(NY):
                y0[j] = end[j]
            return (EVENT if terminal >= 0 else OK), t, terminal, nfev, peak
