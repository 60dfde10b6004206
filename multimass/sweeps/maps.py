"""Overturning maps of rigid blocks under single sine and cosine pulses (paper 004, Figs 4–9).

A map (also under a Ricker wavelet) runs one simulation per cell of a grid over
the normalised pulse frequency ω/p and amplitude a0/(α g), classifies each
outcome — no rocking, rocking then rest, overturned — and can refine the
overturning boundary by bisection in amplitude, which resolves the safe islands
above the first overturning amplitude (the boundary is not monotone).

On the compiled path, with classical impacts and a restitution fixed per corner
(η_M, η_H, a value), the cells run in batches: each worker task runs a chunk of
cells in one compiled call (`multimass.fast.block_runs`), with the same results
as one `map_cell` per cell, bit for bit. Other cases run one `map_cell` per cell.
"""

from __future__ import annotations

import time
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .. import validation as v
from ..errors import InputError
from ..simulation import estimate
from ..structure import Structure, from_specimen
from .base import Executor
from .executors import get_executor
from .map_cells import (
    OUTCOMES,
    PULSES,
    UNDECIDED_RETRY,
    _Cell,
    _Chunk,
    batch_runs,
    map_cell,
    simulate_cells,
)
from .ranges import check_values

__all__ = [
    "OverturningMap",
    "overturning_map",
    "map_cell",
    "OUTCOMES",
    "executor_session",
    "default_backend",
]

#: Run supported maps in compiled chunks; False runs every cell as one `map_cell` job, the
#: reference the batched path is compared with (tests/multimass/sweeps/test_batched_maps.py,
#: benchmarks/batched_maps.py).
BATCHED = True


@contextmanager
def executor_session(executor, workers, compiled: bool = False, batched: bool = False):
    """One executor for several `run_jobs` calls; closed after unless the caller owns it.

    With `compiled`, a process pool's forkserver loads the compiled kernels once
    (`multimass.fast.preload`; with `batched` also the batch kernels of
    `multimass.fast.block_preload`), so its workers start with them in memory.
    """
    if isinstance(executor, Executor):
        yield executor
        return
    options = {}
    if compiled and isinstance(executor, str) and executor.lower() == "process":
        options["preload"] = ("multimass.fast.preload",) + (
            ("multimass.fast.block_preload",) if batched else ()
        )
    ex = get_executor(executor, workers, **options)
    try:
        yield ex
    finally:
        ex.close()


@dataclass(frozen=True, eq=False)
class OverturningMap:
    """Outcome of `overturning_map`.

    Attributes
    ----------
    block : str
    pulse : {"sine", "cosine"}
    omega_p, amp : ndarray
        Grid of ω/p and of a0/(α g).
    cells : pandas.DataFrame
        One row per simulated cell (grid and refinement): ``omega_p``,
        ``amp``, ``outcome``, ``overturn_time``, ``theta_max_over_alpha``,
        ``n_impacts``, ``accurate`` (False if the run's accuracy check failed; its
        outcome is kept and counted in the summary's ``inaccurate``), ``grid``
        (True on the base grid).
    boundaries : pandas.DataFrame
        Refined boundary segments per ω/p: ``omega_p``, ``amp_low``,
        ``amp_high``, ``low_outcome``, ``high_outcome``.
    options : dict
    wall_time_s : float
    """

    block: str
    pulse: str
    omega_p: np.ndarray
    amp: np.ndarray
    cells: pd.DataFrame
    boundaries: pd.DataFrame
    options: dict = field(default_factory=dict)
    wall_time_s: float = 0.0

    @property
    def grid(self) -> np.ndarray:
        """Outcomes on the base grid, shape (len(amp), len(omega_p))."""
        g = self.cells[self.cells.grid]
        table = g.pivot(index="amp", columns="omega_p", values="outcome")
        return table.loc[self.amp, self.omega_p].to_numpy()

    def overturned(self) -> np.ndarray:
        """Boolean grid (amp × omega_p): the cell overturned (undecided cells are False)."""
        return self.grid == "overturned"

    def undecided(self) -> np.ndarray:
        """Boolean grid (amp × omega_p): the map could not decide the cell (see `map_cell`)."""
        return self.grid == "undecided"

    def min_overturn_amp(self) -> list:
        """Smallest a0/(α g) that overturns, per ω/p (refined; None if none in range)."""
        out = []
        for w in self.omega_p:
            b = self.boundaries[
                (self.boundaries.omega_p == w) & (self.boundaries.high_outcome == "overturned")
            ]
            cells = self.cells[(self.cells.omega_p == w) & (self.cells.outcome == "overturned")]
            if cells.empty:
                out.append(None)
                continue
            first = float(cells.amp.min())
            below = b[b.amp_high <= first + 1e-12]
            out.append(float(below.amp_high.min()) if not below.empty else first)
        return out

    def overturn_fraction(self) -> float:
        """Share of base-grid cells that overturn; undecided cells do not count as overturned
        (`undecided_fraction` bounds the error: the true share lies between this and the sum)."""
        return float(np.mean(self.overturned()))

    def undecided_fraction(self) -> float:
        """Share of base-grid cells the map could not decide."""
        return float(np.mean(self.undecided()))

    def summary(self) -> dict:
        """JSON-ready summary (keys of the `multimass stability --json` object)."""
        counts = self.cells[self.cells.grid].outcome.value_counts().to_dict()
        return {
            "block": self.block,
            "pulse": self.pulse,
            "restitution": self.options.get("restitution_name"),
            "restitution_value": self.options.get("restitution_value"),
            "k": self.options.get("k"),
            "omega_p": [float(w) for w in self.omega_p],
            "amp": [float(a) for a in self.amp],
            "min_overturn_amp": self.min_overturn_amp(),
            "overturn_fraction": self.overturn_fraction(),
            "undecided_fraction": self.undecided_fraction(),
            "outcomes": {k: int(counts.get(k, 0)) for k in OUTCOMES},
            "inaccurate": int((~self.cells.accurate).sum()),
            "n_simulations": int(len(self.cells)),
            "wall_time_s": float(self.wall_time_s),
            "options": {k: v for k, v in self.options.items() if k not in ("restitution_name",)},
        }


def default_backend(sim_options: dict) -> dict:
    """Sweeps run the compiled fast path unless told otherwise (issue 7)."""
    if sim_options.get("integrator", "solve_ivp") == "solve_ivp":
        return {"backend": "compiled"} | sim_options
    return dict(sim_options)


def _block(block) -> Structure:
    st = block if isinstance(block, Structure) else from_specimen(block)
    if st.n != 0:
        raise InputError(
            f"`block` = {st.name!r} is not a rigid block; overturning maps are "
            "for rigid blocks (use a rocking spectrum for columns)"
        )
    return st


def overturning_map(
    block,
    pulse: str = "sine",
    omega_p=np.linspace(1, 10, 10),
    amp=np.linspace(0.5, 5, 10),
    *,
    impact: str = "CIM",
    restitution="modified",
    k: float | None = None,
    refine: int = 0,
    t_free: float = 10.0,
    executor="process",
    workers: int | None = None,
    progress=None,
    **sim_options,
) -> OverturningMap:
    """Overturning map over (ω/p, a0/(α g)) for a single sine or cosine pulse (paper 004).

    Parameters
    ----------
    block : Structure, specimen or str
        A rigid block (e.g. "B6M").
    pulse : {"sine", "cosine", "ricker"}
        Single sine or cosine wave of paper 004, Fig 2, or a Ricker wavelet
        (`multimass.Ricker`: ω its ω_p, a0 its peak, default t0).
    omega_p, amp : array_like
        Increasing values of ω/p (> 0) and a0/(α g) (≥ 0); p = sqrt(m g R / J_p),
        α = α_cg.
    impact, restitution, k :
        Impact model (classical) and restitution ("modified" η_M(k), "housner"
        η_H, or a value); k defaults to the block's published k.
    refine : int
        Bisection rounds in amplitude on every boundary between overturning
        and not overturning, per ω/p (each halves the boundary bracket).
    t_free : float
        Free rocking after the pulse (s); runs stop earlier once the block
        cannot overturn any more (`simulate(..., stop_when_safe=True)`).
    executor, workers, progress :
        Passed to `run_jobs` ("serial", "process" (default), "dask" or an Executor).
    **sim_options :
        Passed to `simulate` (e.g. ``integrator="newmark"``, ``dt``, ``rtol``);
        ``backend="compiled"`` (the fast path) unless given. On the compiled path,
        with classical impacts and a restitution fixed per corner, the cells run in
        compiled chunks (`multimass.fast.block_runs`) with the same results as one
        `map_cell` each.

    Returns
    -------
    OverturningMap
    """
    st = _block(block)
    if pulse not in PULSES:
        raise InputError(f"`pulse` = {pulse!r}: use 'sine', 'cosine' or 'ricker'")
    omega_p = check_values("omega_p", omega_p, positive=True)
    amp = check_values("amp", amp, nonnegative=True)
    refine = v.integer("refine", refine, low=0, what="bisection rounds")
    t_free = v.positive("t_free", t_free, "free rocking after the pulse, s")
    from multimass.impact_models import impact_model

    model = impact_model(impact, st.specimen, restitution, k)  # validates restitution and k
    sim_options = default_backend(sim_options)
    options = dict(impact=impact, restitution=restitution, k=k) | sim_options
    scale_a = st.alpha_cg * st.g

    def cells_for(pairs):
        return [
            _Cell(st, pulse, float(w * st.p), float(a * scale_a), t_free, options) for w, a in pairs
        ]

    def chunks_for(pairs, k):  # the same ω and a0 as cells_for, strided into k chunks
        wa = np.array(pairs, dtype=float).reshape(-1, 2)
        omega, a0 = wa[:, 0] * st.p, wa[:, 1] * scale_a
        return [_Chunk(st, pulse, omega[j::k], a0[j::k], t_free, options, runs) for j in range(k)]

    # the options and the longest cell (lowest ω, retried) checked here, before any worker
    slow = cells_for([(omega_p[0], amp[-1])])[0]
    exc = PULSES[pulse](amplitude=slow.a0, omega=slow.omega)
    estimate(st, exc, t_end=exc.duration + UNDECIDED_RETRY * t_free, stop_when_safe=True, **options)

    wall = time.perf_counter()
    pairs = [(w, a) for a in amp for w in omega_p]
    runs = batch_runs(st, options) if BATCHED else None
    compiled = options.get("backend") == "compiled"
    with executor_session(executor, workers, compiled, runs is not None) as ex:
        simulate = lambda pairs, desc: simulate_cells(  # noqa: E731
            pairs, cells_for, chunks_for, runs, ex, progress, desc
        )
        results = simulate(pairs, f"{st.name} {pulse} map")
        rows = [_row(w, a, r, True) for (w, a), r in zip(pairs, results)]
        boundaries = _refine(rows, omega_p, int(refine), simulate)
    rows += boundaries.pop("extra")
    wall = time.perf_counter() - wall
    rest_value = getattr(model.restitution, "k", None)
    return OverturningMap(
        block=st.name,
        pulse=pulse,
        omega_p=omega_p,
        amp=amp,
        cells=pd.DataFrame(rows),
        boundaries=pd.DataFrame(
            boundaries["segments"],
            columns=["omega_p", "amp_low", "amp_high", "low_outcome", "high_outcome"],
        ),
        options={
            "restitution_name": restitution if isinstance(restitution, str) else "value",
            "restitution_value": model.restitution.describe(),
            "k": rest_value,
            "impact": impact,
            "refine": int(refine),
            "t_free": t_free,
            **{k_: v for k_, v in sim_options.items()},
        },
        wall_time_s=wall,
    )


def _row(w, a, result, grid):
    outcome, t_over, theta, impacts, _, accurate = result
    return {
        "omega_p": float(w),
        "amp": float(a),
        "outcome": outcome,
        "overturn_time": t_over,
        "theta_max_over_alpha": theta,
        "n_impacts": impacts,
        "accurate": bool(accurate),
        "grid": grid,
    }


def _refine(rows, omega_p, rounds, simulate) -> dict:
    """Bisect, in amplitude, every grid interval whose ends differ in overturning."""
    columns: dict[float, list] = {}  # rows by ω/p: one pass, not one per ω/p
    for r in rows:
        columns.setdefault(r["omega_p"], []).append(r)
    segments = []
    for w in omega_p:
        col = sorted(columns.get(float(w), ()), key=lambda r: r["amp"])
        for lo, hi in zip(col, col[1:]):  # undecided cells bound no boundary
            if "undecided" in (lo["outcome"], hi["outcome"]):
                continue
            if (lo["outcome"] == "overturned") != (hi["outcome"] == "overturned"):
                segments.append([float(w), lo["amp"], hi["amp"], lo["outcome"], hi["outcome"]])
    extra, stopped = [], []
    for _ in range(rounds):
        if not segments:
            break
        mids = [(s[0], 0.5 * (s[1] + s[2])) for s in segments]
        results = simulate(mids, "refining boundary")
        active = []
        for s, (w, a), r in zip(segments, mids, results):
            row = _row(w, a, r, False)
            extra.append(row)
            if row["outcome"] == "undecided":  # keep the bracket, refine it no further
                stopped.append(s)
                continue
            active.append(s)
            if (row["outcome"] == "overturned") == (s[3] == "overturned"):
                s[1], s[3] = a, row["outcome"]
            else:
                s[2], s[4] = a, row["outcome"]
        segments = active
    done = sorted(segments + stopped, key=lambda s: (s[0], s[1]))
    return {"segments": [tuple(s) for s in done], "extra": extra}
