"""Whole runs of a rigid block under an excitation, many per compiled call.

`run_cells` runs, for each cell (an excitation — a pulse or a record — with its own
restitution pair and end time), what ``simulate_outcome(block, excitation, "CIM",
t_end, backend="compiled")`` runs — the phase loop of `multimass.engines._run.PhaseLoop` for
a rigid body (N = 0) with classical impacts, ``stop_when_safe`` on or off — and, for
a map, the rerun of an undecided cell of `multimass.sweeps.map_cells.map_cell`,
without returning to Python:

* at rest: the uplift search of `multimass.engines._rigid.next_uplift` (`._block_uplift`),
  then rocking with θ̇⁺ = 0 (paper 001, Sec 2.3);
* rocking: one `._block_segment.rocking_segment` call per segment (`._kernel.integrate_phase`
  for the block's five states, step for step), with the events of
  `multimass.engines.fast.path.FastPath.events` (θ = 0 and overturning, held quiet for
  `QUIET_DELAY` after a restart; θ̇ = 0 peaks); segments end at the breakpoints of
  `PhaseLoop`: the excitation's start and end (when within (0, t_end)) and t_end;
* at θ = 0: paper 001's Eq 9 (`next_phase_is_rocking`) chooses a new half-cycle
  with θ̇⁺ = r θ̇⁻ (Eq 11, `classical_rebound`; r of the impacted corner) or full
  contact (Eq 10); the transition's energy loss enters the ledger;
* the chattering guard, the stop at rest once the excitation is over, and (when
  ``CFG_STOP_WHEN_SAFE`` is set) ``stop_when_safe``: after the excitation, a block
  with ``|θ|`` < α and less energy E than m g R (1 − cos α) cannot overturn (event
  "rest"); the run stops in full contact, or rocking away from θ = 0 (or at a turning
  point, θ = 0 after an impact included), the swing's peak then following from E
  (`multimass.model.equations.free_rocking_peak`, no later swing peaks higher), and goes on
  to the impact while rocking toward θ = 0;
* per cell: the outcome code, the overturning time, max ``|θ|`` over the half-cycle
  peaks (as `Recorder.peaks`), the impacts, the RHS evaluations and the end-of-run
  energy balance error (`PhaseLoop.end_balance_error`).

The physics is the compiled code of the per-cell path: the steps of `integrate_phase`, the
energies and momenta of `._maths`, and the transition rules of
`multimass.impact_models.models`, compiled unchanged. A run the per-cell path would
end with status "failed" (step-size underflow, a non-finite state, a root search
that SciPy would refuse) gets code `FAILED` here, and its caller reruns it on the
per-cell path.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numba.extending import register_jitable

from ...checks import balance_error
from ...impact_models.models import classical_rebound, next_phase_is_rocking
from ...model import equations as eq
from ._block_segment import rocking_segment, workspace
from ._block_uplift import next_uplift
from ._maths import EV_OVERTURN, _pivot_momentum, _total_energy, ground_acc
from ._rk import EVENT
from ._rk import FAILED as KERNEL_FAILED

# paper 001's transition rules, compiled unchanged (as `._maths` does for the equations)
for _fn in (classical_rebound, next_phase_is_rocking):
    register_jitable(_fn)

__all__ = ["run_cells", "CFG_SIZE", "NO_ROCKING", "REST", "OVERTURNED", "UNDECIDED", "FAILED"]

# outcome codes: positions in multimass.sweeps.map_cells.OUTCOMES, and FAILED
NO_ROCKING, REST, OVERTURNED, UNDECIDED, FAILED = 0, 1, 2, 3, -1

# cfg: the run options and the block's constants
(
    CFG_A_TH,  # uplift threshold g B m_t / h (multimass.engines._rigid.uplift_threshold)
    CFG_ALPHA,  # α_cg
    CFG_SAFE,  # m g R (1 − cos α): below it the block cannot overturn
    CFG_FLOOR,  # multimass.checks.scale_floor
    CFG_TDMIN,  # θ̇_min
    CFG_WINDOW,  # chatter_window
    CFG_R_RIGHT,  # restitution of an impact on the right corner (rocking on θ > 0 follows);
    CFG_R_LEFT,  # run_cells sets both from each cell's pair
    CFG_DELAY,  # the quiet guard after a restart (multimass.engines._run.QUIET_DELAY)
    CFG_RTOL,  # max(rtol, 100 ε), as FastPath.integrate
    CFG_ATOL,
    CFG_MAX_STEP,
    CFG_METHOD,  # METHOD_CODES
    CFG_STOP_AT_REST,  # 1.0 or 0.0
    CFG_CHATTER,  # chatter_count
    CFG_RETRY,  # a map's undecided cell reruns with this many times the free rocking
    CFG_STOP_WHEN_SAFE,  # 1.0 or 0.0
) = range(17)
CFG_SIZE = 17

_RUNNING, _OVER, _FAIL = 0, 1, 2  # a run's status
_AT_STOP, _AT_ZERO, _AT_OVERTURN, _BROKEN = 0, 1, 2, 3  # how a rocking segment ended


@njit(cache=True, error_model="numpy")
def _energy(side, y, none, mp):
    """E = T + V_g relative to rest (`multimass.model.kinematics.total_energy`, 0 in full contact).

    `none` = (empty node array, empty matrix): a rigid body has no elastic nodes.
    """
    if side == 0:
        return 0.0
    return _total_energy(side, y, none[0], none[0], none[1], mp)


@njit(cache=True, error_model="numpy")
def _chatters(ring, state, t, window):
    """Note a transition at t; True if the chattering guard trips (`PhaseLoop.note_transition`).

    `ring` holds the last len(ring) times; state = [count, next slot].
    """
    cap = ring.size
    ring[state[1]] = t
    state[1] = (state[1] + 1) % cap
    if state[0] < cap:
        state[0] += 1
    if state[0] == cap and t - ring[state[1]] < window:
        state[0] = state[1] = 0  # the guard clears the window
        return True
    return False


@njit(cache=True, error_model="numpy")
def _at_zero(side_old, y, cfg, none, mp):
    """Paper 001, Eq 9, then Eq 11 or Eq 10, at θ = 0 (`multimass.engines._events._at_zero`).

    Sets θ = 0 and θ̇⁺ in `y`; returns (new phase, energy lost, 1 if an impact).
    """
    thd = y[1]
    y[0] = 0.0
    L = _pivot_momentum(y, none[0], none[0], mp)
    side_new = -side_old
    before = _energy(side_old, y, none, mp)
    if next_phase_is_rocking(side_new, L, thd, cfg[CFG_TDMIN]):  # Classical.at_zero
        r = cfg[CFG_R_RIGHT] if side_new > 0 else cfg[CFG_R_LEFT]  # PhaseLoop.draw
        phase, y[1], impact = side_new, classical_rebound(thd, r), 1
    else:
        phase, y[1], impact = 0, 0.0, 0  # θ̇⁺ = 0 (Eq 10)
    return phase, before - _energy(phase, y, none, mp), impact


@njit(cache=True, error_model="numpy")
def _next_stop(t, start, duration, t_end):
    """The first breakpoint after t (`PhaseLoop.breakpoints`: the excitation's start and
    end where within (0, t_end), then t_end)."""
    if 0.0 < start < t_end and t < start:
        return start
    if 0.0 < duration < t_end and t < duration:
        return duration
    return t_end


@njit(cache=True, error_model="numpy")
def _uplift(t0, t1, duration, a_th, kind, par, smp):
    """`next_uplift` on [t0, t1] of a pulse that ends at `duration` (ü_g ≡ 0 after it).

    From the end of the pulse on, the search's first sample (t0 itself, at most
    `duration`) is the only one that can exceed a_th: no need to sample the rest.
    """
    if t0 < duration:
        return next_uplift(t0, t1, a_th, kind, par, smp)
    a = ground_acc(t0, kind, par, smp)
    return abs(a) > a_th, t0, (-1 if a > 0.0 else 1), True


@njit(cache=True, error_model="numpy")
def _segment(t, t_stop, y, phase, ctx):
    """One rocking segment (`multimass.engines.fast.path.FastPath.integrate`).

    Returns (end, t, RHS calls, max |θ| of the segment's peaks), `end` one of
    _AT_STOP (t = t_stop), _AT_ZERO (θ = 0), _AT_OVERTURN or _BROKEN (a failed run);
    `y` becomes the end state (unchanged for _BROKEN).
    """
    cfg, mp, ep, events, kind, par, smp, none, ws = ctx
    codes, dirs, term, quiet, guarded = events
    t_on = ws[12]
    for k in range(codes.size):  # the quiet guard after a restart
        t_on[k] = t + cfg[CFG_DELAY] if guarded[k] else -np.inf
    status, t_new, ev, nfev, top = rocking_segment(
        t, t_stop, y, np.int64(phase), int(cfg[CFG_METHOD]),
        (cfg[CFG_RTOL], cfg[CFG_ATOL], cfg[CFG_MAX_STEP]), (codes, dirs, term, quiet, t_on),
        ep, (kind, par, smp), mp, ws,
    )  # fmt: skip
    if status == KERNEL_FAILED:
        return _BROKEN, t, nfev, 0.0
    if status != EVENT:
        return _AT_STOP, t_stop, nfev, top
    if codes[ev] == EV_OVERTURN:  # Recorder.end_phase at the overturning angle
        return _AT_OVERTURN, t_new, nfev, max(top, abs(y[0]))
    return _AT_ZERO, t_new, nfev, top


@njit(cache=True, error_model="numpy")
def _run(t_end, start, duration, ctx, ring):
    """One run from rest (`multimass.engines._run.PhaseLoop.run`; see the module docstring), of an
    excitation that starts at `start` and ends at `duration`.

    Returns (code, overturn time, max |θ| of the peaks, impacts, RHS calls, energy
    balance error); code NO_ROCKING, REST, OVERTURNED, UNDECIDED or FAILED.
    """
    cfg, mp, kind, par, smp, none = ctx[0], ctx[1], ctx[4], ctx[5], ctx[6], ctx[7]
    chatter, y = np.zeros(2, dtype=np.int64), np.zeros(5)  # y = [θ, θ̇, D, W_g, W_F]
    t, phase, hold, status, loss, top, t_over = 0.0, 0, 0.0, _RUNNING, 0.0, 0.0, math.nan
    n_rhs = n_impacts = 0
    uplifted = rest = False
    while t < t_end and status == _RUNNING:
        t_stop = _next_stop(t, start, duration, t_end)
        trip = integrated = False
        if phase == 0:  # PhaseLoop.rest_until_uplift (θ = θ̇ = 0 at rest, so θ̇⁺ = 0)
            t0, found, ok = max(t, hold), False, True
            if t0 < t_stop:
                found, t, side, ok = _uplift(t0, t_stop, duration, cfg[CFG_A_TH], kind, par, smp)
            if not ok:
                status = _FAIL
            elif found:
                phase, uplifted = side, True
                trip = _chatters(ring, chatter, t, cfg[CFG_WINDOW])
            elif cfg[CFG_STOP_AT_REST] != 0.0 and t_stop >= duration:
                rest = True  # the pulse is over and the block rests
                break
            else:
                t = t_stop
        else:
            integrated = True
            end, t, nfev, peak = _segment(t, t_stop, y, phase, ctx)
            n_rhs, top = n_rhs + nfev, max(top, peak)
            if end == _BROKEN:
                status = _FAIL
            elif end == _AT_OVERTURN:
                t_over, status = t, _OVER
            elif end == _AT_ZERO:
                phase, lost, impact = _at_zero(phase, y, cfg, none, mp)
                loss, n_impacts = loss + lost, n_impacts + impact
                trip = _chatters(ring, chatter, t, cfg[CFG_WINDOW])
        if trip:  # PhaseLoop.trip_guard: full contact for one window
            loss += _energy(phase, y, none, mp)  # − E(full contact) = 0
            top = max(top, abs(y[0]))
            y[0] = y[1] = 0.0
            phase, hold = 0, t + cfg[CFG_WINDOW]
        safe = cfg[CFG_STOP_WHEN_SAFE] != 0.0 and duration <= t < t_end  # PhaseLoop.safe_peak
        # in full contact, or rocking away from θ = 0 (±θ̇ ≥ 0 on pivot ±1; toward it: on)
        if integrated and status == _RUNNING and safe and phase * y[1] >= 0.0:
            E = _energy(phase, y, none, mp)
            if abs(y[0]) < cfg[CFG_ALPHA] and E < cfg[CFG_SAFE]:
                # the swing peaks where E is all potential (energy of free rocking)
                top = max(top, eq.free_rocking_peak(cfg[CFG_ALPHA], E / cfg[CFG_SAFE]))
                rest = True
                break
    if status == _FAIL:
        return FAILED, math.nan, 0.0, 0, n_rhs, 0.0
    if phase != 0:  # Recorder.finish closes the last half-cycle
        top = max(top, abs(y[0]))
    E = _energy(phase, y, none, mp)
    balance = E + y[2] + y[4] + loss - y[3] - 0.0  # PhaseLoop.end_balance_error, e0 = 0
    err = balance_error(balance, 0.0, y[3], E, cfg[CFG_FLOOR])
    if status == _OVER:
        return OVERTURNED, t_over, top, n_impacts, n_rhs, err
    if not uplifted:
        return NO_ROCKING, t_over, top, n_impacts, n_rhs, err
    return (REST if rest else UNDECIDED), t_over, top, n_impacts, n_rhs, err


@njit(cache=True, error_model="numpy")
def run_cells(
    kinds, pars, smp, spans, bounds, t_ends, r_pairs, cfg, mp, ep, events, out_code, out_real,
    out_int,
):  # fmt: skip
    """Run every cell (a row of `pars`), rerunning an undecided one if it has a second t_end.

    Parameters
    ----------
    kinds : int64 (n,)
        The excitation kind of each cell (`._maths` ``EXC_*``).
    pars : ndarray (n, PAR_SIZE)
        Encoded excitations (`multimass.engines.fast.excitation.encode`).
    smp : ndarray (m,)
        Every cell's samples (a record's accelerations), one after the other.
    spans : int64 (n, 2)
        Cell i's samples are ``smp[spans[i, 0]:spans[i, 1]]`` (empty for a pulse).
    bounds : ndarray (n, 2)
        The excitation's breakpoints (s): its start (0 for most) and its end
        (``duration``, after which ü_g ≡ 0).
    t_ends : ndarray (n, a)
        The end time of each run (s): column 0 the first run; column j > 0, if finite,
        the rerun of a cell still undecided after run j − 1 (a map's longer free
        rocking); NaN for none.
    r_pairs : ndarray (n, 2)
        Restitution of an impact onto the right and onto the left corner, per cell.
    cfg, mp, ep : ndarray
        Options (``CFG_*``; ``CFG_R_*`` are taken from `r_pairs`), model scalars
        (`._maths.model_params`), event parameters (`multimass.engines.fast.path.event_params`).
    events : tuple
        Codes, directions, terminal flags, quiet values and guarded flags (1/0) of
        the events of a rocking phase (`multimass.engines.fast.path.ROCKING_EVENTS`).
    out_code : int64 (n,); out_real : float64 (n, 3); out_int : int64 (n, 2)
        Filled: the code; overturn time, max ``|θ|``, energy balance error; impacts,
        RHS calls — of the last run of each cell.
    """
    ring = np.empty(int(cfg[CFG_CHATTER]))
    ws = workspace(events[0].size)
    none = (np.empty(0), np.empty((0, 0)))  # no elastic nodes; mutable, as FastPath's arrays
    c = cfg.copy()
    for i in range(kinds.size):
        c[CFG_R_RIGHT], c[CFG_R_LEFT] = r_pairs[i, 0], r_pairs[i, 1]
        par, samples = pars[i], smp[spans[i, 0] : spans[i, 1]]
        ctx = (c, mp, ep, events, kinds[i], par, samples, none, ws)
        code, t_over, top, n_imp, n_rhs, err = UNDECIDED, math.nan, 0.0, 0, 0, 0.0
        for j in range(t_ends.shape[1]):
            if j > 0 and (code != UNDECIDED or not math.isfinite(t_ends[i, j])):
                break
            code, t_over, top, n_imp, n_rhs, err = _run(
                t_ends[i, j], bounds[i, 0], bounds[i, 1], ctx, ring
            )
        out_code[i] = code
        out_real[i, 0], out_real[i, 1], out_real[i, 2] = t_over, top, err
        out_int[i, 0], out_int[i, 1] = n_imp, n_rhs
