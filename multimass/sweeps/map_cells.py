"""One cell of an overturning map, simulated alone or with many others in a compiled chunk.

`map_cell` runs one cell — one `simulate_outcome`, rerun once with more free rocking
while undecided — and classifies its outcome. `simulate_cells` runs a list of cells
on an executor: in compiled chunks (`multimass.engines.fast.block_runs`, one call per chunk
of cells, no Python per cell) when `batch_runs` says the batch reproduces these cells
exactly, else as one `map_cell` job per cell; either way it returns `CellResults`, the
results as columns (the kernel's arrays, never a tuple per cell). `use_batch` decides
whether a map's cells, or a suite's runs, are worth the batch: a small map or suite on a
machine without the batch kernels compiled runs per cell.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ..engines._run import QUIET_DELAY
from ..errors import InputError
from ..inputs.excitations import CosineWave, MPShape, Ricker, SineWave
from ..model.structure import Structure
from ..simulation import simulate_outcome
from .engine import run_jobs

__all__ = [
    "map_cell",
    "CellResults",
    "simulate_cells",
    "batch_runs",
    "use_batch",
    "BATCH_COMPILE_CELLS",
    "OUTCOMES",
    "PULSES",
    "pulse_family",
    "pulse_label",
    "UNDECIDED_RETRY",
    "CHUNK_CELLS",
    "CHUNKS_PER_WORKER",
    "SERIAL_CHUNK_CELLS",
    "chunk_count",
]

OUTCOMES = ("no_rocking", "rest", "overturned", "undecided")
#: An undecided cell is run once more with this many times the free-rocking time.
UNDECIDED_RETRY = 4.0
#: The pulses of a map: name → excitation (Ricker: ω is its ω_p, a0 its peak, default t0;
#: mp: the M&P pulse of γ = 2, ν = 0 with peak acceleration a0 and f_p = ω/2π).
PULSES = {"sine": SineWave, "cosine": CosineWave, "ricker": Ricker, "mp": MPShape()}


def pulse_family(pulse):
    """The constructor ``(amplitude=, omega=) → Excitation`` of a map's pulse.

    Parameters
    ----------
    pulse : {"sine", "cosine", "ricker", "mp"} or MPShape
        A name of `PULSES`, or an M&P pulse shape of any γ and ν.

    Raises
    ------
    InputError
        For anything else.
    """
    if isinstance(pulse, MPShape):
        return pulse
    if isinstance(pulse, str) and pulse in PULSES:
        return PULSES[pulse]
    raise InputError(
        f"`pulse` = {pulse!r}: use one of {', '.join(repr(p) for p in PULSES)} or "
        "multimass.MPShape(gamma=..., nu=...)"
    )


def pulse_label(pulse) -> str:
    """The pulse's name in tables, titles and file names ("mp_g2.5_nu1.57" for a shape)."""
    if isinstance(pulse, MPShape):
        if pulse == PULSES["mp"]:
            return "mp"
        return f"mp_g{pulse.gamma:g}_nu{pulse.nu:g}"
    return str(pulse)


#: A map of fewer cells (a suite of fewer runs) runs one `map_cell` per cell unless the
#: batch kernels are ready (`use_batch`): their one-off compile costs more than the batch
#: saves on so few cells (2-core machine, load 3: compile 47 s, per-cell path ~1.0 ms per
#: cell, batched ~0.07 ms; quiet: 0.49 and 0.11 ms, a compile of 25-35 s; break-even
#: 50 000-90 000 cells; docs/guide/speed.md).
BATCH_COMPILE_CELLS = 50_000
#: Cells per chunk of a batched map (one compiled call each; ~5-20 ms of work).
CHUNK_CELLS = 64
#: A batched map is cut into at least this many chunks per worker (small maps spread too).
CHUNKS_PER_WORKER = 8
#: Cells per chunk when one process runs them all (serial, or a pool of one): nothing to
#: spread, so fewer and longer compiled calls (~60 ms each on a 2-core machine; each call
#: costs ~0.1 ms of Python), the progress bar still moving at every chunk.
SERIAL_CHUNK_CELLS = 1024


class _Cell(NamedTuple):
    """One map cell as sent to a worker: a named tuple of plain floats pickles and
    unpickles ~3x and ~8x faster than a dataclass holding numpy scalars (the parent's
    share of a sweep competes with the workers for the cores)."""

    structure: Structure
    pulse: object  # a name of PULSES or an MPShape
    omega: float
    a0: float
    t_free: float
    options: dict


class _Chunk(NamedTuple):
    """Cells sent to a worker as one job of a batched map (`_map_chunk`)."""

    structure: Structure
    pulse: object  # a name of PULSES or an MPShape
    omega: np.ndarray
    a0: np.ndarray
    t_free: float
    options: dict
    runs: object  # multimass.engines.fast.block_runs.BlockRuns


class CellResults:
    """`map_cell` results of many cells, as columns: one array per field of its tuple.

    Attributes
    ----------
    outcome : ndarray of int8
        Position in `OUTCOMES`.
    overturn_time, theta_max_over_alpha : ndarray of float
    n_impacts, n_rhs : ndarray of int64
    accurate : ndarray of bool

    Indexing and iterating give `map_cell`'s tuples (outcome name, overturn time,
    max|θ|/α, impacts, rhs evaluations, accurate), the same floats; whole maps read the
    columns instead, with no Python per cell.
    """

    FIELDS = ("outcome", "overturn_time", "theta_max_over_alpha", "n_impacts", "n_rhs", "accurate")
    _DTYPES = (np.int8, float, float, np.int64, np.int64, bool)
    __slots__ = FIELDS

    def __init__(self, outcome, overturn_time, theta_max_over_alpha, n_impacts, n_rhs, accurate):
        values = (outcome, overturn_time, theta_max_over_alpha, n_impacts, n_rhs, accurate)
        for name, dtype, value in zip(self.FIELDS, self._DTYPES, values):
            setattr(self, name, np.asarray(value, dtype=dtype))

    @classmethod
    def empty(cls, n: int) -> CellResults:
        """Columns for `n` cells, to be filled."""
        return cls(*(np.empty(n, dtype) for dtype in cls._DTYPES))

    @classmethod
    def of_rows(cls, rows) -> CellResults:
        """The columns of a list of `map_cell` tuples."""
        out = cls.empty(len(rows))
        for i, row in enumerate(rows):
            out[i] = row
        return out

    def __len__(self) -> int:
        return self.outcome.size

    def __getitem__(self, i: int) -> tuple:
        return (
            OUTCOMES[self.outcome[i]],
            float(self.overturn_time[i]),
            float(self.theta_max_over_alpha[i]),
            int(self.n_impacts[i]),
            int(self.n_rhs[i]),
            bool(self.accurate[i]),
        )

    def __setitem__(self, i: int, row: tuple) -> None:
        """Cell `i` from a `map_cell` tuple."""
        for name, value in zip(self.FIELDS, (OUTCOMES.index(row[0]), *row[1:])):
            getattr(self, name)[i] = value

    def __iter__(self):
        return (self[i] for i in range(len(self)))

    def names(self) -> np.ndarray:
        """The outcomes as names (an object array)."""
        return np.array(OUTCOMES, dtype=object)[self.outcome]

    def put(self, index, other: CellResults) -> None:
        """Cells `index` (an index array or slice) from `other`'s columns."""
        for name in self.FIELDS:
            getattr(self, name)[index] = getattr(other, name)

    def __reduce__(self):  # __slots__ without __dict__: pickle through the constructor
        return (type(self), tuple(getattr(self, name) for name in self.FIELDS))


def _classify(resp) -> str:
    if resp.outcome == "overturned":
        return "overturned"
    if not any(e.kind == "uplift" for e in resp.events):
        return "no_rocking"
    if any(e.kind == "rest" for e in resp.events):
        return "rest"
    return "undecided"


def map_cell(cell: _Cell) -> tuple:
    """Simulate one cell: (outcome, overturn time or nan, max|θ|/α, impacts, rhs evaluations,
    accurate).

    Outcomes: "no_rocking" (never uplifted), "rest" (rocked, then could no longer
    overturn: its energy fell below what reaching θ = α needs), "overturned", and
    "undecided": still rocking with enough energy to overturn at the end of the run,
    even after a second run with `UNDECIDED_RETRY` times the free-rocking time. An
    undecided cell counts neither as overturned nor as safe (`OverturningMap.undecided`).
    ``accurate`` is False when the run's accuracy check failed (status "inaccurate",
    e.g. Newmark's energy error at a coarse step): the outcome is kept, and flagged.
    """
    st = cell.structure
    exc = pulse_family(cell.pulse)(amplitude=cell.a0, omega=cell.omega)
    for t_free in (cell.t_free, UNDECIDED_RETRY * cell.t_free):
        resp = simulate_outcome(
            st, exc, t_end=exc.duration + t_free, stop_when_safe=True, **cell.options
        )
        if resp.status == "failed":
            raise RuntimeError(
                f"cell ω = {cell.omega:.6g} rad/s, a0 = {cell.a0:.6g} m/s²: {resp.message}"
            )
        outcome = _classify(resp)
        if outcome != "undecided":
            break
    t_over = next((e.time for e in resp.events if e.kind == "overturn"), math.nan)
    return (
        outcome,
        t_over,
        resp.theta_max / st.alpha_cg,
        resp.n_impacts,
        resp.n_rhs,
        resp.status != "inaccurate",
    )


def _map_chunk(chunk: _Chunk) -> CellResults:
    """`map_cell` of every cell of a chunk, in one compiled call (`multimass.engines.fast.block_runs`).

    A cell the batch cannot finish as `map_cell` would (its run fails) is run by
    `map_cell`, which reports the failure.
    """
    from multimass.engines.fast.block_runs import run_pulses

    st = chunk.structure
    b = run_pulses(chunk.runs, chunk.pulse, chunk.a0, chunk.omega, chunk.t_free)
    out = CellResults(
        b.outcome,
        b.overturn_time,
        b.theta_max / st.alpha_cg,  # the same division as map_cell's, per cell
        b.n_impacts,
        b.n_rhs,
        b.accurate,
    )
    for i in np.flatnonzero(b.outcome < 0).tolist():
        out[i] = map_cell(
            _Cell(
                st,
                chunk.pulse,
                float(chunk.omega[i]),
                float(chunk.a0[i]),
                chunk.t_free,
                chunk.options,
            )
        )
    return out


def use_batch(setting: bool | None, runs: int) -> bool:
    """Whether `runs` runs of a rigid block go in the compiled batch, where it reproduces them
    (the rule of maps and suites alike).

    Parameters
    ----------
    setting : bool or None
        True: always, compiling the batch kernels if need be; False: never. None: when the
        batch kernels are ready (`multimass.engines.fast.block_runs.batch_ready`: loaded, or
        in numba's disk cache) or there are at least `BATCH_COMPILE_CELLS` runs, enough to
        pay for their one-off compile. The per-run path gives the same results.
    runs : int
        The runs (map cells, suite runs) expected.
    """
    if setting is not None:
        return bool(setting)
    if runs >= BATCH_COMPILE_CELLS:
        return True
    from multimass.engines.fast import block_runs

    return block_runs.batch_ready()


def batch_runs(st, options):
    """The compiled batch for a map's cells (`BlockRuns`), or None if it cannot reproduce
    them (then they run one `map_cell` each). Whether it is worth it: `use_batch`."""
    if options.get("backend") != "compiled":
        return None
    from multimass.engines.fast import block_runs

    return block_runs.BlockRuns.of(st, options, QUIET_DELAY, UNDECIDED_RETRY)


def chunk_count(n: int, workers: int) -> int:
    """Compiled chunks for `n` cells on `workers` processes: chunks of at most
    `SERIAL_CHUNK_CELLS` on one process; else of at most `CHUNK_CELLS`, and at least
    `CHUNKS_PER_WORKER` per worker (while there are cells), so the workers share them."""
    if workers == 1:
        return math.ceil(n / SERIAL_CHUNK_CELLS)
    return max(math.ceil(n / CHUNK_CELLS), min(n, CHUNKS_PER_WORKER * workers))


def simulate_cells(pairs, cells_for, chunks_for, runs, executor, progress, desc) -> CellResults:
    """`map_cell` results of the (ω/p, a0/(α g)) `pairs` (a list, or an (n, 2) array), in
    order, as `CellResults`: in compiled chunks when `runs` is a `BlockRuns`
    (``chunks_for(pairs, k)``: k strided chunks), else one job per cell
    (``cells_for(pairs)``)."""
    n = len(pairs)
    if runs is None or n == 0:
        cells = cells_for(pairs)
        done = run_jobs(map_cell, cells, executor=executor, progress=progress, desc=desc)
        return CellResults.of_rows(done)
    k = chunk_count(n, executor.workers)
    done = run_jobs(
        _map_chunk,
        chunks_for(pairs, k),
        executor=executor,
        progress=progress,
        desc=desc,
        weights=[len(range(j, n, k)) for j in range(k)],  # chunk j: cells j, j + k, ...
        unit="cell",
    )
    out = CellResults.empty(n)
    for j, results in enumerate(done):  # chunk j holds cells j, j + k, j + 2k, ...
        out.put(slice(j, None, k), results)
    return out
