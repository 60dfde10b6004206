"""`column_run`: a whole run of a flexible column in machine code.

`multimass.simulate`'s phase loop is Python (`multimass.engines._run.PhaseLoop`), which,
with ``backend="compiled"``, hands each phase segment to the compiled kernels
(`multimass.engines.fast.path.FastPath.integrate`). This kernel runs the same loop
without leaving machine code — for a spectrum, which wants a run's outcome only (θ_max,
status, impacts, the overturning time and the energy check), and for `simulate` itself
(with a log, below). It makes the same segments (the closed-form full contact of
`._contact_kernel` or the Runge–Kutta kernel of `._kernel`), with the same event tables
(`multimass.engines.fast.path`), and the transitions of
`multimass.engines._events.handle_event` and `PhaseLoop` (uplift, overturning, the
Dirac-delta force's activation and release, the end of a half-cycle at θ = 0, the
chattering guard) with the same functions of `multimass.model.equations`,
`multimass.impact_models` and `._maths`, in the same order. A run is therefore the
per-run compiled path's, bit for bit (tests/multimass/engines/test_fast_column_runs.py).

With a log (``cfg[CF_LOG]``), the kernel also writes what `multimass.simulate` reports of
the run — the rows its `Recorder` stores (each segment's samples on the output grid and the
states before and after each transition), the event log and the half-cycles' peaks — in
the order the phase loop writes them; `multimass.engines.fast.column_trace` turns them into
the same `Response`.

Restitution comes in as data (`multimass.engines.fast.column_runs` lays it out): a value
per corner, a table by impact (empirical) or, for a random source, the run's
standard normal draws, taken in order; a run that needs more draws than it was
given returns `MORE_DRAWS` and is run again with more.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numba.extending import register_jitable

from ...checks import balance_error
from ...impact_models import gaussian_force as gf
from ...impact_models import models as im
from ._contact_kernel import contact_phase
from ._exp_kernel import exp_phase, new_cache
from ._kernel import integrate_phase
from ._maths import (
    EP_LIMIT,
    EP_R_PENDING,
    EV_ACTIVATE,
    EV_DEACTIVATE,
    EV_OVERTURN,
    EV_UPLIFT_LEFT,
    EV_UPLIFT_RIGHT,
    EV_ZERO,
    FP_E,
    FP_N,
    FP_ON,
    FP_R,
    FP_SIZE,
    MP_B,
    MP_G,
    MP_MT,
    _pivot_momentum,
    _total_energy,
)
from ._rk import EVENT, FAILED

__all__ = [
    "column_run",
    "COMPLETED",
    "OVERTURNED",
    "BROKEN",
    "MORE_DRAWS",
    "R_CORNERS",
    "R_RANDOM",
    "R_TABLE",
    "MORE_LOG",
    "LOG_KINDS",
    "ROW_Y",
    "EV_SIZE",
]

for _f in (im.next_phase_is_rocking, im.classical_rebound, im.full_contact_velocities):
    register_jitable(inline="always")(_f)

# outcome codes
COMPLETED, OVERTURNED, BROKEN, MORE_DRAWS, MORE_LOG = 0, 1, 2, 3, 4
# restitution kinds (`multimass.impact_models.sources`): a value per corner (fixed,
# per-corner means, Housner, modified); N(mean of the corner, σ) clipped to
# [floor, 1] from the given standard normals; a table by impact, then the corners
R_CORNERS, R_RANDOM, R_TABLE = 0, 1, 2

# cfg layout (`multimass.engines.fast.column_runs.lay_out`)
(
    CF_TDMIN,
    CF_DELAY,
    CF_WINDOW,
    CF_COUNT,
    CF_METHOD,
    CF_RTOL,
    CF_ATOL,
    CF_MAX_STEP,
    CF_FORCE,
    CF_CP,
    CF_NMIN,
    CF_Z,
    CF_RELEASE,
    CF_R_KIND,
    CF_R_RIGHT,
    CF_R_LEFT,
    CF_SIGMA,
    CF_FLOOR,
    CF_EXACT,
    CF_FLOOR_E,
    CF_EXPONENTIAL,
    CF_LOG,
    CF_OUTPUT_DT,
) = range(23)
CF_SIZE = 23

# the log (cfg[CF_LOG]): a row is (t, phase, force number or −1, impact loss so far, y...);
# an event (kind, t, phase before, phase after, θ, θ̇⁻, θ̇⁺, restitution or NaN, energy
# change, n, θ_i, E_ini); a peak (|θ|, t). The kinds, in the names of `result.EVENT_KINDS`:
LOG_KINDS = (
    "uplift",
    "overturn",
    "dd_activate",
    "dd_deactivate",  # moving away (Eq 17)
    "dd_deactivate",  # at θ = 0 (Eq 17)
    "impact",
    "full_contact",
    "chatter_guard",
)
# (floats, as every argument of `_row` and `_event`: one compiled signature each)
L_UPLIFT, L_OVERTURN, L_ACTIVATE, L_AWAY, L_AT_ZERO, L_IMPACT, L_CONTACT, L_CHATTER = map(
    float, range(8)
)
ROW_Y = 4  # the first column of y in a row
EV_SIZE = 12

# event tables (`multimass.engines.fast.path._EVENTS`): contact, rocking, activate, deactivate
T_CONTACT, T_ROCKING, T_ACTIVATE, T_DEACTIVATE = range(4)


@njit(cache=True, error_model="numpy")
def _draw(side_new, k, n_impacts, cfg, draws):
    """The k-th restitution of the run, for an impact onto `side_new` (`PhaseLoop.draw`);
    NaN when the random draws have run out."""
    kind = cfg[CF_R_KIND]
    corner = cfg[CF_R_RIGHT] if side_new > 0 else cfg[CF_R_LEFT]
    if kind == R_RANDOM:  # RandomRestitution.value: rng.normal(mean, σ) = mean + σ z
        if k >= draws.size:
            return math.nan
        return min(max(corner + cfg[CF_SIGMA] * draws[k], cfg[CF_FLOOR]), 1.0)
    if kind == R_TABLE and n_impacts < draws.size:  # EmpiricalRestitution.value
        return draws[n_impacts]
    return corner


@njit(cache=True, error_model="numpy")
def _chatters(ring, count, t, window):
    """`PhaseLoop.note_transition`: append t to the window of the last transitions
    (`ring`, `count` of them held); True if the guard trips. Returns (trips, count)."""
    size = ring.size
    if count == size:
        for i in range(size - 1):
            ring[i] = ring[i + 1]
        ring[size - 1] = t
    else:
        ring[count] = t
        count += 1
    return count == size and t - ring[0] < window, count


@njit(cache=True, error_model="numpy")
def _row(rows, i, t, phase, force, loss, y):
    """Write the row i of the log (if it fits) and return i + 1 (`Recorder._row`)."""
    if i < rows.shape[0]:
        rows[i, 0], rows[i, 1], rows[i, 2], rows[i, 3] = t, phase, force, loss
        for j in range(y.size):
            rows[i, ROW_Y + j] = y[j]
    return i + 1


@njit(cache=True, error_model="numpy")
def _event(evs, i, kind, t, before, after, th, thd_m, thd_p, r, d_e, width, th_i, e_ini):
    """Write the event i of the log (if it fits) and return i + 1 (`result.Event`)."""
    if i < evs.shape[0]:
        e = evs[i]
        e[0], e[1], e[2], e[3], e[4], e[5] = kind, t, before, after, th, thd_m
        e[6], e[7], e[8], e[9], e[10], e[11] = thd_p, r, d_e, width, th_i, e_ini
    return i + 1


@njit(cache=True, error_model="numpy")
def _candidate(cand, a, t):
    """`Recorder._candidate`: (|θ|, t) of the half-cycle's peak so far, NaN for none."""
    if cand[0] != cand[0] or a > cand[0]:
        cand[0], cand[1] = a, t


@njit(cache=True, error_model="numpy")
def _close(pks, i, cand):
    """`Recorder.end_phase` of a rocking phase: the half-cycle's peak, then none."""
    if i < pks.shape[0]:
        pks[i, 0], pks[i, 1] = cand[0], cand[1]
    cand[0] = cand[1] = math.nan
    return i + 1


@njit(cache=True, error_model="numpy")
def _grid(t0, t1, dt):
    """`Recorder.grid`: the output times in (t0, t1) on the dt grid, then t1."""
    k0, k1 = math.floor(t0 / dt) + 1, math.floor(t1 / dt)
    cut = t1 - 1e-12 * max(1.0, abs(t1))
    out = np.empty(max(k1 - k0 + 1, 0) + 1)
    c = 0
    for k in range(k0, k1 + 1):
        p = k * dt
        if p > t0 and p < cut:
            out[c] = p
            c += 1
    out[c] = t1
    return out[: c + 1]


@njit(cache=True, error_model="numpy")
def column_run(
    t_end,
    phase0,
    y0,
    breakpoints,
    m,
    H,
    K,
    C_,
    mp,
    kind,
    par,
    smp,
    modes,
    rock,
    tables,
    ep0,
    cfg,
    draws,
    log,
):
    """One run of a column from (0, phase0, y0) to t_end, overturning or a failure.

    Parameters
    ----------
    t_end : float
    phase0 : int
        0 full contact, ±1 rocking.
    y0 : ndarray
        [u, θ, u̇, θ̇, D, W_g, W_F] at t = 0.
    breakpoints : ndarray
        `PhaseLoop.breakpoints`: the ends of the segments, increasing, the last t_end.
    m, H, K, C_, mp, kind, par, smp :
        As `FastPath` (model arrays, scalars, encoded excitation).
    modes : tuple
        (phi, w, z, gam, h_max, screen) of `ContactModes` (used if cfg[CF_EXACT]).
    rock : tuple
        (L, lam, V, W, wt) of `RockingModes`: the rocking phases by the exponential
        method of `._exp_kernel` if cfg[CF_EXPONENTIAL] (full contact as cfg[CF_METHOD]).
    tables : tuple
        Per key (T_CONTACT, ...), the tuple (codes, directions, terminal, quiet,
        guarded) of `multimass.engines.fast.path`'s event tables.
    ep0, cfg, draws : ndarray
        Event parameters (`event_params`), options (``CF_*``) and restitution data.
    log : tuple
        (rows, events, peaks), 2-D arrays the log is written into if cfg[CF_LOG]
        (the module docstring lists their columns); samples on the output grid of
        step cfg[CF_OUTPUT_DT] if it is > 0, else at the segments' ends only.

    Returns
    -------
    code, t_over, theta_max, n_impacts, n_rhs, energy_balance_error, n_log
        `code` COMPLETED, OVERTURNED, BROKEN (the solver failed or a state was not
        finite: the Python loop gives the message), MORE_DRAWS or MORE_LOG (the log's
        arrays were too short: `n_log` holds the numbers of rows, events and peaks the
        run has written so far).
    """
    n = m.size
    phi, w, z, gam, h_max, screen = modes
    L_r, lam_r, V_r, W_r, wt_r = rock
    exp_cache = new_cache(lam_r.size)
    hints = (np.zeros(2), np.zeros(2))  # integrate_phase's next step: full contact, rocking
    has_force = cfg[CF_FORCE] != 0.0
    tdmin, delay, window = cfg[CF_TDMIN], cfg[CF_DELAY], cfg[CF_WINDOW]
    ring = np.empty(int(cfg[CF_COUNT]))
    n_ring = 0
    ep, fp, t_eval = ep0.copy(), np.zeros(FP_SIZE), np.empty(1)
    y = y0.copy()
    t, phase, hold = 0.0, int(phase0), 0.0
    force_on, fE, fr, fn, fth = False, 0.0, 0.0, 0.0, 0.0
    k_draw, n_impacts, n_rhs = 0, 0, 0
    loss, top, t_over = 0.0, 0.0, math.nan
    code = -1  # running
    e0 = _total_energy(float(phase), y, m, H, K, mp)  # PhaseLoop: the ledger starts here
    r_pending = math.nan
    logging, dt_out = cfg[CF_LOG] != 0.0, cfg[CF_OUTPUT_DT]
    rows, evs, pks = log
    n_log = np.zeros(3, np.int64)  # rows, events, peaks written
    cand = np.full(2, math.nan)  # Recorder.cand
    force_no, n_forces, last_t = -1, 0, 0.0
    if logging:
        n_log[0] = _row(rows, n_log[0], 0.0, float(phase), -1.0, loss, y)  # Recorder.start_phase
        if phase != 0:
            _candidate(cand, abs(y[n]), 0.0)
    if phase != 0:
        top = abs(y[n])  # Recorder.start_phase
        if has_force:
            r_pending = _draw(-phase, k_draw, n_impacts, cfg, draws)
            k_draw += 1
    while t < t_end and code < 0:
        if r_pending != r_pending and has_force and phase != 0:  # NaN: out of draws
            code = MORE_DRAWS
            break
        j = 0
        while breakpoints[j] <= t:  # the first breakpoint after t
            j += 1
        t_stop = breakpoints[j]
        t_eval[0] = t_stop
        grid = _grid(t, t_stop, dt_out) if logging and dt_out > 0.0 else t_eval
        # the phase's events (FastPath.events)
        ep[EP_R_PENDING], ep[EP_LIMIT] = 0.0, 0.0
        fp[FP_ON] = fp[FP_E] = fp[FP_R] = fp[FP_N] = 0.0
        if phase == 0:
            key, t_start = T_CONTACT, t + max(delay, hold - t)
        else:
            key, t_start = T_ROCKING, t + delay
            if has_force and not force_on:
                key = T_ACTIVATE
                ep[EP_R_PENDING] = r_pending
            elif force_on:
                key = T_DEACTIVATE
                ep[EP_LIMIT] = gf.deactivation_angle(cfg[CF_RELEASE], fth)
                fp[FP_ON], fp[FP_E], fp[FP_R], fp[FP_N] = 1.0, fE, fr, fn
        codes, dirs, term, quiet, guarded = tables[key]
        ton = np.empty(codes.size)  # the quiet guard's ends
        for i in range(codes.size):
            ton[i] = t_start if guarded[i] else -np.inf
        if phase == 0 and cfg[CF_EXACT] != 0.0:
            status, t_new, y_new, ev, nfev, samples, _, nt_t, nt_y = contact_phase(
                t, t_stop, y, grid, m, H, K, C_, mp, codes, dirs, quiet, ton, ep, kind, par,
                smp, phi, w, z, gam, h_max, screen,
            )  # fmt: skip
        elif phase != 0 and cfg[CF_EXPONENTIAL] != 0.0:
            status, t_new, y_new, ev, nfev, samples, _, nt_t, nt_y = exp_phase(
                t, t_stop, y, grid, phase, m, H, K, C_, mp, fp, codes, dirs, term, quiet,
                ton, ep, kind, par, smp, L_r, lam_r, V_r, W_r, wt_r, exp_cache, cfg[CF_RTOL],
                cfg[CF_ATOL], cfg[CF_MAX_STEP],
            )  # fmt: skip
        else:
            status, t_new, y_new, ev, nfev, samples, _, nt_t, nt_y = integrate_phase(
                t, t_stop, y, grid, phase, m, H, K, C_, mp, fp, codes, dirs, term, quiet,
                ton, ep, kind, par, smp, int(cfg[CF_METHOD]), cfg[CF_RTOL], cfg[CF_ATOL],
                cfg[CF_MAX_STEP], hints[0 if phase == 0 else 1],
            )  # fmt: skip
        n_rhs += nfev
        finite = True
        for i in range(y_new.size):
            finite = finite and math.isfinite(y_new[i])
        for r in range(samples.shape[0]):
            for i in range(samples.shape[1]):
                finite = finite and math.isfinite(samples[r, i])
        if status == FAILED or not finite:
            code = BROKEN
            break
        if phase != 0:  # Recorder.segment: the θ̇ = 0 peaks
            for r in range(nt_y.shape[0]):
                top = max(top, abs(nt_y[r, n]))
        if logging:  # Recorder.segment: the samples, then the peaks' candidates
            ph, fo = float(phase), float(force_no)
            for r in range(samples.shape[0]):
                n_log[0] = _row(rows, n_log[0], grid[r], ph, fo, loss, samples[r])
                last_t = grid[r]
            if phase != 0:
                for r in range(nt_y.shape[0]):
                    _candidate(cand, abs(nt_y[r, n]), nt_t[r])
        if status != EVENT:
            t = t_stop
            for i in range(y.size):
                y[i] = samples[samples.shape[0] - 1, i]
            continue
        t = t_new
        for i in range(y.size):
            y[i] = y_new[i]
        ev_code = codes[ev]
        trips = False
        if ev_code == EV_UPLIFT_RIGHT or ev_code == EV_UPLIFT_LEFT:  # handle_event: uplift
            y[n], y[2 * n + 1] = 0.0, 0.0  # θ̇⁺ = 0, u̇⁺ = u̇⁻ (paper 001, Sec 2.3)
            side = 1 if ev_code == EV_UPLIFT_RIGHT else -1  # PhaseLoop.start_rocking
            if logging:  # the event, Recorder.end_phase (full contact), .start_phase
                n_log[1] = _event(evs, n_log[1], L_UPLIFT, t, 0.0, float(side), 0.0, 0.0, 0.0,
                                  math.nan, 0.0, 0.0, 0.0, 0.0)  # fmt: skip
                n_log[0] = _row(rows, n_log[0], t, 0.0, -1.0, loss, y)
                n_log[0] = _row(rows, n_log[0], t, float(side), -1.0, loss, y)
                last_t = t
                cand[0] = cand[1] = math.nan
                _candidate(cand, abs(y[n]), t)
            phase = side
            if has_force:
                r_pending = _draw(-phase, k_draw, n_impacts, cfg, draws)
                k_draw += 1
            trips, n_ring = _chatters(ring, n_ring, t, window)
        elif ev_code == EV_OVERTURN:
            top = max(top, abs(y[n]))
            t_over, code = t, OVERTURNED
            if logging:  # the event, Recorder.end_phase
                p = float(phase)
                n_log[1] = _event(evs, n_log[1], L_OVERTURN, t, p, p, y[n],
                                  y[2 * n + 1], 0.0, math.nan, 0.0, 0.0, 0.0, 0.0)  # fmt: skip
                n_log[0] = _row(rows, n_log[0], t, float(phase), -1.0, loss, y)
                last_t = t
                _candidate(cand, abs(y[n]), t)
                n_log[2] = _close(pks, n_log[2], cand)
        elif ev_code == EV_ACTIVATE:  # _events._activate
            E = _total_energy(float(phase), y, m, H, K, mp)
            thd = y[2 * n + 1]
            fn = gf.impact_width(
                E, r_pending, mp[MP_B], mp[MP_MT], mp[MP_G], cfg[CF_CP], thd, cfg[CF_NMIN]
            )
            fth = phase * gf.activation_angle(cfg[CF_Z], fn)
            force_on, fE, fr = True, E, r_pending
            if logging:
                p = float(phase)
                n_log[1] = _event(evs, n_log[1], L_ACTIVATE, t, p, p, y[n], thd, 0.0,
                                  fr, 0.0, fn, fth, fE)  # fmt: skip
                force_no, n_forces = n_forces, n_forces + 1
        elif ev_code == EV_DEACTIVATE:
            force_on, force_no = False, -1
            if logging:
                p = float(phase)
                n_log[1] = _event(evs, n_log[1], L_AWAY, t, p, p, y[n], y[2 * n + 1],
                                  0.0, fr, 0.0, 0.0, 0.0, 0.0)  # fmt: skip
        elif ev_code == EV_ZERO:  # _events._at_zero: next_phase_is_rocking, then at_zero
            side_old, side_new, thd = phase, -phase, y[2 * n + 1]
            r = fr if force_on else math.nan
            r_used = r
            if logging and force_on:
                p = float(phase)
                n_log[1] = _event(evs, n_log[1], L_AT_ZERO, t, p, p, 0.0, thd, 0.0,
                                  fr, 0.0, 0.0, 0.0, 0.0)  # fmt: skip
            y[n] = 0.0
            force_on, force_no = False, -1
            L_new = _pivot_momentum(y, m, H, mp)
            rocks = im.next_phase_is_rocking(side_new, L_new, thd, tdmin)
            if not has_force:
                r = 1.0
                if rocks:
                    r = _draw(side_new, k_draw, n_impacts, cfg, draws)
                    k_draw += 1
                    if r != r:
                        code = MORE_DRAWS
                        break
            elif r != r:
                r = 1.0
            before = _total_energy(float(side_old), y, m, H, K, mp)
            if logging:  # Recorder.end_phase, before the transition's velocities
                n_log[0] = _row(rows, n_log[0], t, float(side_old), -1.0, loss, y)
                last_t = t
                _candidate(cand, abs(y[n]), t)
                n_log[2] = _close(pks, n_log[2], cand)
            if rocks:  # ImpactModel.at_zero: a new half-cycle (CIM: classical_rebound)
                phase = side_new
                if not has_force:
                    y[2 * n + 1] = im.classical_rebound(thd, r)
                n_impacts += 1
            else:  # to full contact (full_contact_velocities)
                ud = im.full_contact_velocities(H, y[n + 1 : 2 * n + 1], thd)
                for i in range(n):
                    y[n + 1 + i] = ud[i]
                y[2 * n + 1] = 0.0
                phase = 0
            after = _total_energy(float(phase), y, m, H, K, mp)
            loss += before - after
            if logging:  # the event (Transition), Recorder.start_phase
                kind_ = L_IMPACT if rocks else L_CONTACT
                r_ = r if rocks and not has_force else r_used
                n_log[1] = _event(evs, n_log[1], kind_, t, float(side_old), float(phase), 0.0, thd,
                                  y[2 * n + 1], r_, after - before, 0.0, 0.0, 0.0)  # fmt: skip
                n_log[0] = _row(rows, n_log[0], t, float(phase), -1.0, loss, y)
                if phase != 0:
                    _candidate(cand, abs(y[n]), t)
            if phase != 0 and has_force:
                r_pending = _draw(-phase, k_draw, n_impacts, cfg, draws)
                k_draw += 1
            trips, n_ring = _chatters(ring, n_ring, t, window)
        if trips:  # PhaseLoop.trip_guard: full contact for one window
            before = _total_energy(float(phase), y, m, H, K, mp)
            th_g, thd_g = y[n], y[2 * n + 1]
            if logging:  # Recorder.end_phase
                n_log[0] = _row(rows, n_log[0], t, float(phase), -1.0, loss, y)
                last_t = t
                if phase != 0:
                    _candidate(cand, abs(y[n]), t)
                    n_log[2] = _close(pks, n_log[2], cand)
                cand[0] = cand[1] = math.nan
            if phase != 0:
                top = max(top, abs(y[n]))  # Recorder.end_phase
                ud = im.full_contact_velocities(H, y[n + 1 : 2 * n + 1], y[2 * n + 1])
                for i in range(n):
                    y[n + 1 + i] = ud[i]
            y[n], y[2 * n + 1] = 0.0, 0.0
            after = _total_energy(0.0, y, m, H, K, mp)
            loss += before - after
            if logging:  # the event, Recorder.start_phase (full contact)
                n_log[1] = _event(evs, n_log[1], L_CHATTER, t, float(phase), 0.0, th_g, thd_g, 0.0,
                                  math.nan, -(before - after), 0.0, 0.0, 0.0)  # fmt: skip
                n_log[0] = _row(rows, n_log[0], t, 0.0, -1.0, loss, y)
            n_ring = 0
            phase, force_on, hold, force_no = 0, False, t + window, -1
    if code == BROKEN or code == MORE_DRAWS:
        return code, math.nan, 0.0, 0, n_rhs, 0.0, n_log
    if phase != 0:  # Recorder.finish closes the last half-cycle
        top = max(top, abs(y[n]))
    if logging and not (last_t == t and cand[0] != cand[0]):  # Recorder.finish
        n_log[0] = _row(rows, n_log[0], t, float(phase), -1.0, loss, y)
        if phase != 0:
            _candidate(cand, abs(y[n]), t)
            n_log[2] = _close(pks, n_log[2], cand)
    if n_log[0] > rows.shape[0] or n_log[1] > evs.shape[0] or n_log[2] > pks.shape[0]:
        return MORE_LOG, math.nan, 0.0, 0, n_rhs, 0.0, n_log
    E = _total_energy(float(phase), y, m, H, K, mp)
    D, Wg, WF = y[2 * n + 2], y[2 * n + 3], y[2 * n + 4]
    balance = E + D + WF + loss - Wg - e0  # PhaseLoop.end_balance_error
    err = balance_error(balance, e0, Wg, E, cfg[CF_FLOOR_E])
    outcome = OVERTURNED if code == OVERTURNED else COMPLETED
    return outcome, t_over, top, n_impacts, n_rhs, err, n_log
