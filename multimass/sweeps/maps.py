"""Overturning maps of rigid blocks under single sine and cosine pulses (paper 004, Figs 4–9).

A map (also under a Ricker wavelet) runs one simulation per cell of a grid over
the normalised pulse frequency ω/p and amplitude a0/(α g), classifies each
outcome — no rocking, rocking then rest, overturned — and can refine the
overturning boundary by bisection in amplitude, which resolves the safe islands
above the first overturning amplitude (the boundary is not monotone).

On the compiled path, with classical impacts and a restitution fixed per corner
(η_M, η_H, a value), the cells run in batches: each worker task runs a chunk of
cells in one compiled call (`multimass.engines.fast.block_runs`), with the same results
as one `map_cell` per cell, bit for bit — once those batch kernels are compiled, or when
the map is large enough to pay for compiling them (`map_cells.BATCH_COMPILE_CELLS`
cells; `BATCHED`). Other cases run one `map_cell` per cell.
"""

from __future__ import annotations

import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from .. import validation as v
from ..errors import InputError
from ..model.structure import Structure, from_specimen
from ..simulation import estimate
from .base import Executor
from .executors import get_executor
from .map_adaptive import ADAPTIVE_COARSE, adaptive_cells, check_coarse
from .map_cells import (
    OUTCOMES,
    UNDECIDED_RETRY,
    CellResults,
    _Cell,
    _Chunk,
    batch_runs,
    map_cell,
    pulse_family,
    pulse_label,
    simulate_cells,
    use_batch,
)
from .map_store import (
    STORE_CHUNK_CELLS,
    WALL_TIME_COVERS,
    StoredMap,
    grid_segments,
    run_stored,
)
from .ranges import check_values

if TYPE_CHECKING:
    import pandas as pd

__all__ = [
    "OverturningMap",
    "overturning_map",
    "map_cell",
    "OUTCOMES",
    "executor_session",
    "default_backend",
    "WALL_TIME_COVERS",
]

#: Run supported maps in compiled chunks: None (default) when the batch kernels are ready
#: or the map is large enough to pay for their compile (`map_cells.use_batch`,
#: `map_cells.BATCH_COMPILE_CELLS`); True always (compiling them if need be); False never:
#: every cell as one `map_cell` job, the reference the batched path is compared with
#: (tests/multimass/sweeps/test_batched_maps.py, benchmarks/batched_maps.py).
BATCHED: bool | None = None


@contextmanager
def executor_session(
    executor,
    workers,
    compiled: bool = False,
    batched: bool = False,
    contact: bool = False,
    columns: bool = False,
    per_run: bool = True,
):
    """One executor for several `run_jobs` calls; closed after unless the caller owns it.

    With `compiled`, a process pool's forkserver loads the compiled kernels once
    (`multimass.engines.fast.preload`, unless `per_run` is False: jobs that run whole
    batches only, as a batched map's chunks, where a cell the batch cannot finish loads
    the per-run kernels if it ever runs; with `batched` the batch kernels of
    `multimass.engines.fast.block_preload`, with `contact` the closed-form full contact of
    `multimass.engines.fast.contact_preload`, with `columns` the whole column runs of
    `multimass.engines.fast.column_preload`), so its workers start with them in memory.
    """
    if isinstance(executor, Executor):
        yield executor
        return
    options = {}
    if compiled and isinstance(executor, str) and executor.lower() == "process":
        options["preload"] = (
            (("multimass.engines.fast.preload",) if per_run or not batched else ())
            + (("multimass.engines.fast.block_preload",) if batched else ())
            + (("multimass.engines.fast.contact_preload",) if contact else ())
            + (("multimass.engines.fast.column_preload",) if columns else ())
        )
    ex = get_executor(executor, workers, **options)
    try:
        yield ex
    finally:
        ex.close()


class _Pending(NamedTuple):
    """A table not built yet: ``pandas.DataFrame(data, columns=columns)`` (`data` a dict
    of columns, or rows with `columns`); `column` reads it meanwhile."""

    data: dict | list
    columns: list | None = None

    def column(self, name: str) -> np.ndarray:
        if isinstance(self.data, dict):
            return np.asarray(self.data[name])
        i = self.columns.index(name)
        return np.array([row[i] for row in self.data], dtype=object)


class _Table:
    """A table field of `OverturningMap`, given as a DataFrame or as a `_Pending` table:
    reading it gives a DataFrame, built at the first read (pandas imported then: a map
    read only through `OverturningMap.summary`, as ``multimass stability --json``, needs
    no pandas)."""

    def __set_name__(self, owner, name):
        self.key = f"_{name}_table"

    def __get__(self, obj, owner=None):
        if obj is None:  # no class-level default: the field stays a required argument
            raise AttributeError(self.key)
        table = obj.__dict__[self.key]
        if isinstance(table, _Pending):
            import pandas as pd

            table = pd.DataFrame(table.data, columns=table.columns)
            obj.__dict__[self.key] = table
        return table

    def __set__(self, obj, value):  # the dataclass's __init__ (frozen: nothing else)
        obj.__dict__[self.key] = value

    def column(self, obj, name: str) -> np.ndarray:
        """Column `name` of `obj`'s table as an array, without building a DataFrame."""
        table = obj.__dict__[self.key]
        if isinstance(table, _Pending):
            return table.column(name)
        return table[name].to_numpy()

    def names(self, obj) -> list:
        """The column names of `obj`'s table."""
        table = obj.__dict__[self.key]
        if isinstance(table, _Pending):
            return list(table.data) if isinstance(table.data, dict) else list(table.columns)
        return list(table.columns)


@dataclass(frozen=True, eq=False)
class OverturningMap:
    """Outcome of `overturning_map`.

    Attributes
    ----------
    block : str
    pulse : str
        "sine", "cosine", "ricker", "mp" or ``mp_g<γ>_nu<ν>`` (`map_cells.pulse_label`).
    omega_p, amp : ndarray
        Grid of ω/p and of a0/(α g).
    cells : pandas.DataFrame
        One row per simulated cell (grid and refinement): ``omega_p``,
        ``amp``, ``outcome``, ``overturn_time``, ``theta_max_over_alpha``,
        ``n_impacts``, ``accurate`` (False if the run's accuracy check failed; its
        outcome is kept and counted in the summary's ``inaccurate``), ``grid``
        (True on the base grid). Built at its first read, as is `boundaries`: the map holds
        its columns until then, and `summary` reads those (pandas is imported with the
        first table).
    boundaries : pandas.DataFrame
        Refined boundary segments per ω/p: ``omega_p``, ``amp_low``,
        ``amp_high``, ``low_outcome``, ``high_outcome``.
    options : dict
    wall_time_s : float
        Seconds from the call of `overturning_map` to its return: validating the
        arguments, loading the compiled kernels, the cells, the boundary refinement and
        assembling these tables (`WALL_TIME_COVERS`; ``multimass stability`` reports the
        whole command instead, from its process start).
    simulation_time_s : float
        The part of `wall_time_s` spent simulating cells (the executor's runs, grid and
        refinement).
    """

    block: str
    pulse: str
    omega_p: np.ndarray
    amp: np.ndarray
    cells: pd.DataFrame = _Table()
    boundaries: pd.DataFrame = _Table()
    options: dict = field(default_factory=dict)
    wall_time_s: float = 0.0
    simulation_time_s: float = 0.0

    @property
    def grid(self) -> np.ndarray:
        """Outcomes on the base grid, shape (len(amp), len(omega_p)) (object array of names)."""
        g = self.cells[self.cells.grid]
        i = _axis_index(self.amp, g.amp.to_numpy())
        j = _axis_index(self.omega_p, g.omega_p.to_numpy())
        if (i < 0).any() or (j < 0).any() or len(g) != self.amp.size * self.omega_p.size:
            raise ValueError("the cells' grid rows do not cover the map's omega_p × amp grid")
        out = np.empty((self.amp.size, self.omega_p.size), dtype=object)
        out[i, j] = g.outcome.to_numpy(dtype=object)
        return out

    def overturned(self) -> np.ndarray:
        """Boolean grid (amp × omega_p): the cell overturned (undecided cells are False)."""
        return self.grid == "overturned"

    def undecided(self) -> np.ndarray:
        """Boolean grid (amp × omega_p): the map could not decide the cell (see `map_cell`)."""
        return self.grid == "undecided"

    def min_overturn_amp(self) -> list:
        """Smallest a0/(α g) that overturns, per ω/p (refined; None if none in range).

        Per ω/p: the smallest amplitude of an overturned cell, lowered to the smallest
        ``amp_high`` of a boundary segment into overturning at or below it.
        """
        cell = lambda name: self._column("cells", name)  # noqa: E731
        n_w = self.omega_p.size
        over = (cell("outcome") == "overturned").astype(bool)
        j = _axis_index(self.omega_p, cell("omega_p")[over])
        first = np.full(n_w, np.inf)
        np.minimum.at(first, j[j >= 0], cell("amp")[over][j >= 0].astype(float))
        segment = lambda name: self._column("boundaries", name)  # noqa: E731
        into = (segment("high_outcome") == "overturned").astype(bool)
        jb, high = (
            _axis_index(self.omega_p, segment("omega_p")[into].astype(float)),
            segment("amp_high")[into].astype(float),
        )
        keep = jb >= 0
        jb, high = jb[keep], high[keep]
        keep = high <= first[jb] + 1e-12
        best = np.full(n_w, np.inf)
        np.minimum.at(best, jb[keep], high[keep])
        low = np.where(np.isfinite(best), best, first)
        return [float(x) if np.isfinite(f) else None for x, f in zip(low, first)]

    def overturn_fraction(self) -> float:
        """Share of base-grid cells that overturn; undecided cells do not count as overturned
        (`undecided_fraction` bounds the error: the true share lies between this and the sum)."""
        return float(np.mean(self.overturned()))

    def undecided_fraction(self) -> float:
        """Share of base-grid cells the map could not decide."""
        return float(np.mean(self.undecided()))

    def n_simulations(self) -> int:
        """Cells simulated: the grid and the refinement (adaptive maps: the computed cells)."""
        if "computed" in vars(OverturningMap)["cells"].names(self):
            return int(self._column("cells", "computed").sum())
        return len(self._column("cells", "grid"))

    def inaccurate_grid_cells(self) -> pd.DataFrame:
        """Grid cells whose run failed its accuracy check (``omega_p``, ``amp``)."""
        return self.cells.loc[self.cells.grid & ~self.cells.accurate, ["omega_p", "amp"]]

    def _column(self, table: str, name: str) -> np.ndarray:
        """Column `name` of the ``cells`` or ``boundaries`` table, no DataFrame built."""
        return vars(OverturningMap)[table].column(self, name)

    def summary(self) -> dict:
        """JSON-ready summary (keys of the `multimass stability --json` object).

        ``wall_time_s`` is this map's (`WALL_TIME_COVERS` says what it covers),
        ``simulation_time_s`` the part of it spent simulating cells.
        """
        grid = self._column("cells", "grid").astype(bool)
        n_grid = int(grid.sum())
        if n_grid != self.amp.size * self.omega_p.size:
            raise ValueError("the cells' grid rows do not cover the map's omega_p × amp grid")
        names, n = np.unique(self._column("cells", "outcome")[grid].astype(str), return_counts=True)
        counts = dict(zip(names.tolist(), n.tolist()))  # fractions: counts over the grid's cells
        return {
            "block": self.block,
            "pulse": self.pulse,
            "restitution": self.options.get("restitution_name"),
            "restitution_value": self.options.get("restitution_value"),
            "k": self.options.get("k"),
            "omega_p": [float(w) for w in self.omega_p],
            "amp": [float(a) for a in self.amp],
            "min_overturn_amp": self.min_overturn_amp(),
            "overturn_fraction": counts.get("overturned", 0) / n_grid,
            "undecided_fraction": counts.get("undecided", 0) / n_grid,
            "outcomes": {k: int(counts.get(k, 0)) for k in OUTCOMES},
            "inaccurate": int((~self._column("cells", "accurate").astype(bool)).sum()),
            "n_simulations": self.n_simulations(),
            "wall_time_s": float(self.wall_time_s),
            "simulation_time_s": float(self.simulation_time_s),
            "wall_time_covers": WALL_TIME_COVERS,
            "options": {k: v for k, v in self.options.items() if k not in ("restitution_name",)},
        }


def default_backend(sim_options: dict) -> dict:
    """Sweeps run the compiled fast path unless told otherwise."""
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
    store=None,
    adaptive: bool = False,
    coarse: int = ADAPTIVE_COARSE,
    **sim_options,
) -> OverturningMap | StoredMap:
    """Overturning map over (ω/p, a0/(α g)) for a single sine or cosine pulse (paper 004).

    Parameters
    ----------
    block : Structure, specimen or str
        A rigid block (e.g. "B6M").
    pulse : {"sine", "cosine", "ricker", "mp"} or MPShape
        Single sine or cosine wave of paper 004, Fig 2, a Ricker wavelet
        (`multimass.Ricker`: ω its ω_p, a0 its peak, default t0), or a
        Mavroeidis–Papageorgiou pulse (`multimass.MPShape`: ω = 2π f_p, a0 its peak
        ground acceleration; "mp" is γ = 2, ν = 0).
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
    store : path, optional
        Stream the map to this folder in Parquet chunks and return a `StoredMap`
        (`multimass.sweeps.map_store`): bounded memory for million-cell grids, and a
        re-run with the same arguments resumes an interrupted map (finished chunks are
        skipped); a folder holding another map is refused (`MapStoreMismatch`).
    adaptive : bool
        Compute only the cells near outcome boundaries, from a coarse lattice of
        spacing `coarse` (a power of 2) refined where neighbouring cells disagree; the
        other cells take the outcome of their block (`multimass.sweeps.map_adaptive`
        gives the rule and what it can miss: islands smaller than coarse × coarse
        cells far from any other boundary). ``cells.computed`` marks the simulated
        cells; the numeric columns of the others are missing. Not with `store`.
    **sim_options :
        Passed to `simulate` (e.g. ``integrator="newmark"``, ``dt``, ``rtol``);
        ``backend="compiled"`` (the fast path) unless given. On the compiled path,
        with classical impacts and a restitution fixed per corner, the cells run in
        compiled chunks (`multimass.engines.fast.block_runs`) with the same results as one
        `map_cell` each — if those batch kernels are compiled already (in numba's disk
        cache: ``multimass warm-up`` compiles them) or the map has at least
        `map_cells.BATCH_COMPILE_CELLS` cells, enough to pay for their one-off compile
        (~35 s); a smaller map on a machine without them runs one `map_cell` per cell.

    Returns
    -------
    OverturningMap, or StoredMap with `store`
        ``wall_time_s`` covers this whole call (`WALL_TIME_COVERS`);
        ``simulation_time_s`` the part of it spent simulating cells.
    """
    started = time.perf_counter()
    st = _block(block)
    if store is not None and adaptive:
        raise InputError("`adaptive` maps are held in memory: give `store` or `adaptive`, not both")
    coarse = check_coarse(coarse)
    make_pulse = pulse_family(pulse)  # validates
    label = pulse_label(pulse)
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
        wa = np.asarray(pairs, dtype=float).reshape(-1, 2)
        omega, a0 = wa[:, 0] * st.p, wa[:, 1] * scale_a
        return [_Chunk(st, pulse, omega[j::k], a0[j::k], t_free, options, runs) for j in range(k)]

    # the options and the longest cell (lowest ω, retried) checked here, before any worker
    slow = cells_for([(omega_p[0], amp[-1])])[0]
    exc = make_pulse(amplitude=slow.a0, omega=slow.omega)
    estimate(st, exc, t_end=exc.duration + UNDECIDED_RETRY * t_free, stop_when_safe=True, **options)

    rest_value = getattr(model.restitution, "k", None)
    map_options = {
        "restitution_name": restitution if isinstance(restitution, str) else "value",
        "restitution_value": model.restitution.describe(),
        "k": rest_value,
        "impact": impact,
        "refine": int(refine),
        "t_free": t_free,
        **{k_: v for k_, v in sim_options.items()},
    }
    expected = omega_p.size * (amp.size + int(refine))  # the grid, a boundary per ω/p refined
    compiled = options.get("backend") == "compiled"
    runs = batch_runs(st, options) if compiled and use_batch(BATCHED, expected) else None
    simulated = [0.0]  # seconds in the executor's runs
    batched = runs is not None
    with executor_session(executor, workers, compiled, batched, per_run=not batched) as ex:

        def simulate(pairs, desc, show=progress):
            t0 = time.perf_counter()
            try:
                return simulate_cells(pairs, cells_for, chunks_for, runs, ex, show, desc)
            finally:
                simulated[0] += time.perf_counter() - t0

        if store is not None:
            return run_stored(
                store,
                st,
                label,
                omega_p,
                amp,
                map_options,
                lambda pairs, desc: simulate(pairs, desc, False),
                refine=int(refine),
                bisect=_bisect,
                progress=progress,
                chunk_cells=STORE_CHUNK_CELLS,
                started=started,
                simulated=simulated,
            )
        if adaptive:
            cells, boundaries = adaptive_cells(
                omega_p, amp, coarse, int(refine), simulate, _bisect, _cells_table
            )
            map_options["adaptive"] = {
                "coarse": int(coarse),
                "computed": int(cells.computed[cells.grid].sum()),
                "cells": int(cells.grid.sum()),
            }
        else:
            w = np.tile(omega_p, amp.size)  # amp-major, as the grid's rows
            a = np.repeat(amp, omega_p.size)
            results = simulate(np.column_stack([w, a]), f"{st.name} {label} map")
            codes = results.outcome.reshape(amp.size, -1)
            extra, boundaries = _bisect(grid_segments(codes, omega_p, amp), int(refine), simulate)
            cells = _cells_columns(w, a, results, True)
            if extra:  # the refinement's rows after the grid's
                ew, ea, er = zip(*extra)
                more = _cells_columns(ew, ea, er, False)
                cells = {k: np.concatenate([col, more[k]]) for k, col in cells.items()}
            cells = _Pending(cells)
    boundaries = _Pending(list(boundaries), _SEGMENT_COLUMNS)
    return OverturningMap(
        block=st.name,
        pulse=label,
        omega_p=omega_p,
        amp=amp,
        cells=cells,
        boundaries=boundaries,
        options=map_options,
        wall_time_s=time.perf_counter() - started,
        simulation_time_s=simulated[0],
    )


_SEGMENT_COLUMNS = ["omega_p", "amp_low", "amp_high", "low_outcome", "high_outcome"]


def _axis_index(axis: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Position of each value in the increasing `axis` (exact match), -1 where absent."""
    values = np.asarray(values, dtype=float)
    j = np.searchsorted(axis, values)
    hit = j < axis.size
    hit[hit] = axis[j[hit]] == values[hit]
    return np.where(hit, j, -1)


def _cells_table(w, a, results, grid: bool) -> pd.DataFrame:
    """The rows of `OverturningMap.cells` for cells (``w``, ``a``) and their `map_cell`
    `results`, as a DataFrame."""
    import pandas as pd

    return pd.DataFrame(_cells_columns(w, a, results, grid))


def _cells_columns(w, a, results, grid: bool) -> dict:
    """The columns of `OverturningMap.cells` for cells (``w``, ``a``) and their `map_cell`
    `results` (`CellResults`, read as columns, or a list of `map_cell` tuples)."""
    if not isinstance(results, CellResults):
        results = CellResults.of_rows(results)
    return {
        "omega_p": np.asarray(w, dtype=float),
        "amp": np.asarray(a, dtype=float),
        "outcome": results.names(),
        "overturn_time": results.overturn_time,
        "theta_max_over_alpha": results.theta_max_over_alpha,
        "n_impacts": results.n_impacts,
        "accurate": results.accurate,
        "grid": np.full(len(results), grid),
    }


def _bisect(segments, rounds, simulate) -> tuple[list, list]:
    """`rounds` bisections of the boundary `segments` ([ω/p, amp_low, amp_high, low_outcome,
    high_outcome]): the simulated (ω/p, amp, result) and the final segments, sorted."""
    extra, stopped = [], []
    for _ in range(rounds):
        if not segments:
            break
        mids = [(s[0], 0.5 * (s[1] + s[2])) for s in segments]
        results = simulate(mids, "refining boundary")
        active = []
        for s, (w, a), r in zip(segments, mids, results):
            extra.append((w, a, r))
            if r[0] == "undecided":  # keep the bracket, refine it no further
                stopped.append(s)
                continue
            active.append(s)
            if (r[0] == "overturned") == (s[3] == "overturned"):
                s[1], s[3] = a, r[0]
            else:
                s[2], s[4] = a, r[0]
        segments = active
    done = sorted(segments + stopped, key=lambda s: (s[0], s[1]))
    return extra, [tuple(s) for s in done]
