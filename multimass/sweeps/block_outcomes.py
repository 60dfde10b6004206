"""A list of `simulate_outcome` runs of one rigid block, in compiled batches where possible.

`simulate_outcomes` gives, run for run, what ``simulate_outcome(st, excitation,
t_end=..., **options)`` gives: the runs the compiled block batch reproduces exactly
(`multimass.engines.fast.block_runs`: classical impacts, a restitution fixed per corner — η_M
of each run's own k, or its own value — an explicit method on the compiled backend)
go in one compiled call; the others, and any run the batch cannot finish, run one at a
time. The suites of `multimass.suites` call it per chunk of runs.
"""

from __future__ import annotations

import math

import numpy as np

from ..engines.fast import block_runs as br
from ..engines.fast._block_kernel import FAILED
from ..engines.fast.block_runs import EXCITATIONS, BlockRuns, ExcitationRuns, restitution_pairs
from ..errors import InputError
from ..simulation import simulate_outcome
from .map_cells import OUTCOMES, _classify

__all__ = ["simulate_outcomes"]


def _outcome_code(resp) -> int:
    """The `OUTCOMES` index of a `simulate_outcome` result (`map_cells` classifies), or
    `FAILED`."""
    return FAILED if resp.status == "failed" else OUTCOMES.index(_classify(resp))


def simulate_outcomes(st, excitations, t_end, options) -> ExcitationRuns:
    """``simulate_outcome(st, excitations[i], t_end=t_end[i], **options[i])`` of every run,
    batched where the batch reproduces it (`BlockRuns.of_runs`, `restitution_pairs`,
    `EXCITATIONS`), else — and for a run the batch cannot finish — one run at a time.

    Parameters
    ----------
    st : Structure
        A rigid block (any structure: its runs go per run).
    excitations : sequence
    t_end : float or array_like
        End time of each run (s).
    options : dict or sequence of dict
        The options of every run, or of each (``impact`` included; differing in
        ``restitution``, ``k`` and ``seed`` only, else the runs go per run).

    Returns
    -------
    ExcitationRuns
        ``batched`` says which runs the batch gave.
    """
    excitations = list(excitations)
    n = len(excitations)
    per_run = [dict(o) for o in options] if not isinstance(options, dict) else [options] * n
    if len(per_run) != n:
        raise InputError(f"{len(per_run)} option sets for {n} excitations: give one per run")
    t_ends = np.broadcast_to(np.asarray(t_end, dtype=float), (n,))
    mine = np.array([type(e) in EXCITATIONS for e in excitations], dtype=bool)
    runs = BlockRuns.of_runs(st, per_run[0]) if n else None
    pairs = restitution_pairs(st, per_run) if runs is not None else None
    if runs is None or pairs is None:
        mine[:] = False
    idx = np.flatnonzero(mine)
    out = ExcitationRuns(
        outcome=np.full(n, FAILED, np.int64),
        status=np.full(n, "failed", dtype="<U11"),
        message=[""] * n,
        overturn_time=np.full(n, math.nan),
        theta_max=np.zeros(n),
        n_impacts=np.zeros(n, np.int64),
        n_rhs=np.zeros(n, np.int64),
        energy_balance_error=np.zeros(n),
        accurate=np.ones(n, bool),
        batched=np.zeros(n, bool),
    )
    if idx.size:
        b = br.run_excitations(runs, [excitations[i] for i in idx], t_ends[idx], pairs[idx])
        for name in ("outcome", "status", "overturn_time", "theta_max", "n_impacts", "n_rhs"):
            getattr(out, name)[idx] = getattr(b, name)
        out.energy_balance_error[idx], out.accurate[idx] = b.energy_balance_error, b.accurate
        out.batched[idx] = b.outcome != FAILED
        for i, m in zip(idx.tolist(), b.message):
            out.message[i] = m
    for i in np.flatnonzero(~out.batched).tolist():
        resp = simulate_outcome(st, excitations[i], t_end=float(t_ends[i]), **per_run[i])
        out.outcome[i], out.status[i], out.message[i] = (
            _outcome_code(resp),
            resp.status,
            resp.message,
        )
        out.overturn_time[i] = next((e.time for e in resp.events if e.kind == "overturn"), math.nan)
        out.theta_max[i], out.n_impacts[i], out.n_rhs[i] = (
            resp.theta_max,
            resp.n_impacts,
            resp.n_rhs,
        )
        out.energy_balance_error[i] = resp.energy_balance_error
        out.accurate[i] = resp.status != "inaccurate"
    return out
