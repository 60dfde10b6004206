"""What `multimass.simulate` reports of a whole compiled column run (`ColumnRun.trace`).

`multimass.simulate` with ``backend="compiled"`` runs a column whose parts the
whole-run kernel knows (`multimass.engines.fast.column_runs`) in one compiled call
with a log: the rows its `Recorder` would store, the event log and the half-cycles'
peaks, written by the kernel in the order the Python phase loop writes them
(`._column_kernel`). `trace` turns that log into the phase loop's `Event` list,
`ActiveForce` objects and `Recorder` rows, so the `Response` (or `Outcome`) is built by
the same code as the phase loop's, from the same numbers.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ...model._phase import ActiveForce
from ...result import Event
from .._events import DETAIL_AT_ZERO, DETAIL_AWAY, activation_detail, chatter_detail
from . import _column_kernel as ck
from .column_runs import BROKEN, ColumnRun

__all__ = ["Trace", "trace"]


@dataclass(frozen=True, eq=False)
class Trace:
    """A whole compiled column run, as the phase loop would have left it.

    Attributes
    ----------
    outcome : str
        "completed" or "overturned".
    events : list of Event
        The event log, its "release" first (`multimass.engines._run.PhaseLoop`).
    rows : tuple
        (t, Y, phase, impact loss so far, force, forces) of
        `multimass.engines._recorder.Recorder.response_of`.
    peaks : tuple
        (``|θ|`` of each half-cycle, its time), arrays.
    n_rhs : int
    energy_balance_error : float
        `PhaseLoop.end_balance_error` of the run's end.
    wall_time_s : float
        The kernel's call, with its log's reruns.
    """

    outcome: str
    events: list
    rows: tuple
    peaks: tuple
    n_rhs: int
    energy_balance_error: float
    wall_time_s: float


def trace(run: ColumnRun, output_dt: float | None, chatter: tuple[int, float]) -> Trace | None:
    """The `Trace` of `run` with rows every `output_dt` s (None: at segment ends and
    transitions only), or None if the kernel could not finish it (the phase loop then
    runs it, for its message). `chatter` is (chatter_count, chatter_window) of the run's
    options (the guard's event detail)."""
    wall = time.perf_counter()
    outcome, _, _, _, n_rhs, err, rows, evs, pks = run.trace(output_dt)
    wall = time.perf_counter() - wall
    if outcome == BROKEN:
        return None
    n = run.model[0].size  # y = [u, θ, u̇, θ̇, D, W_g, W_F]
    events, forces = _events(evs, run.phase, float(run.y0[n]), chatter)
    return Trace(
        outcome,
        events,
        _rows(rows, forces),
        (pks[:, 0].copy(), pks[:, 1].copy()),
        int(n_rhs),
        float(err),
        wall,
    )


def _events(evs: np.ndarray, phase0: int, theta0: float, chatter) -> tuple[list, list]:
    """The `Event` list of the kernel's event log and the `ActiveForce` of each activation."""
    events = [Event("release", 0.0, phase0, phase0, theta=theta0)]
    forces = []
    guard = chatter_detail(*chatter)
    for row in evs.tolist():
        code, t, before, after, th, thd_m, thd_p, r, d_e, width, th_i, e_ini = row
        code = int(code)
        detail = ""
        if code == ck.L_ACTIVATE:
            detail = activation_detail(width, th_i)
            forces.append(ActiveForce(E_ini=e_ini, r=r, n=width, theta_i=th_i, thetadot_i=thd_m))
        elif code == ck.L_AWAY:
            detail = DETAIL_AWAY
        elif code == ck.L_AT_ZERO:
            detail = DETAIL_AT_ZERO
        elif code == ck.L_CHATTER:
            detail = guard
        events.append(
            Event(
                ck.LOG_KINDS[code],
                t,
                int(before),
                int(after),
                theta=th,
                thetadot_minus=thd_m,
                thetadot_plus=thd_p,
                restitution=None if math.isnan(r) else r,
                energy_change=d_e,
                detail=detail,
            )
        )
    return events, forces


def _rows(rows: np.ndarray, forces: list) -> tuple:
    """`Recorder.response_of`'s rows: a row's force is its number in [None, *forces]."""
    phase = rows[:, 1].astype(np.int64)
    code = rows[:, 2].astype(np.int64) + 1  # −1: none
    return rows[:, 0].copy(), rows[:, ck.ROW_Y :], phase, rows[:, 3].copy(), code, [None, *forces]
