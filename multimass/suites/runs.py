"""Run a suite: every motion × intensity level × restitution draw, resumable, on any executor.

`run_suite` scales each motion to each level of the suite's intensity measure (records:
one factor per record and level, from the record's own IM; pulses: the M&P pulse's
amplitude), draws each run's restitution from its own seed, runs the runs on the sweep
engine (serial, process pool or Dask; `multimass.sweeps.engine.run_jobs`) in chunks, and
writes one row per run (the columns of `RUN_COLUMNS`). With ``out``, each finished chunk
goes to ``OUT/runs/part-NNNNN.parquet`` at once and ``OUT/manifest.json`` holds the
suite's description: a re-run of the same suite skips the chunks on disk, and a suite
that differs is refused. A run's randomness depends only on (suite seed, run index), so
results do not depend on the executor, the worker count, the chunking or a resume.

The IM columns of every run (``pga``, ``pgv``, ``pgd``, ``arias``, ``sa_<T>s``) are
computed on the scaled motion by `multimass.analysis.intensity` (records exactly, as piecewise
linear; pulses sampled at 1000 points per pulse period), so any of them can be the
fragility's IM afterwards (`multimass.suites.analysis.im_efficiency`).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..analysis import intensity as im
from ..engines._rigid import uplift_threshold
from ..errors import InputError
from ..inputs.excitations import TWO_PI, MPShape
from ..progress import RunCost, budget_seconds, format_duration
from ..simulation import estimate, outcome_summaries, outcome_summary
from ..sweeps.base import available_workers, validate_workers
from ..sweeps.engine import _Bar, run_batches, run_jobs
from ..sweeps.kernel_pools import kernel_session, preload_modules
from ..sweeps.map_cells import use_batch
from ..sweeps.maps import default_backend
from ..sweeps.method_choice import AUTO, resolve, sweep_method
from ..sweeps.seeding import job_seed
from .spec import Distribution, Suite

__all__ = ["run_suite", "suite_cost", "SuiteRuns", "SuiteMismatch", "RUN_COLUMNS", "motions"]

#: Columns of the runs table, in order (``sa_<T>s`` columns follow for the suite's periods).
RUN_COLUMNS = [
    "structure", "alpha", "p", "motion", "motion_kind", "im_name", "im", "level", "draw",
    "seed", "scale", "restitution_draw", "theta_max_over_alpha", "overturned", "n_impacts",
    "status", "overturn_time", "message", "pga", "pgv", "pgd", "arias",
    "omega_p_over_p", "amp_over_g_tan_alpha", "fp", "gamma", "nu",
]  # fmt: skip
MANIFEST = "manifest.json"
_PULSE_SAMPLES = 1000  # samples per pulse period for a pulse's IMs (PGA to ~1e-5)


class SuiteMismatch(InputError):
    """The output folder holds runs of another suite."""


# --------------------------------------------------------------------------- motions
@dataclass(frozen=True)
class _Motion:
    """One motion at unit scale: how to scale it and its IMs at unit scale.

    A pulse whose γ or ν is drawn per run (`PulseSet.drawn`) has ``shape`` None and
    only its unit PGA in ``ims``; `shape_for` draws the run's shape.
    """

    name: str
    kind: str  # "record" | "pulse"
    unit: object  # Record (scale 1) | (ratio, gamma, nu, omega, a_unit)
    ims: dict  # IM name -> value at unit scale
    pulse: dict  # omega_p_over_p, fp, gamma, nu (NaN for records and drawn shapes)
    shape: MPShape | None = None

    @property
    def drawn(self) -> bool:
        return self.kind == "pulse" and self.shape is None

    def shape_for(self, seed: int) -> MPShape:
        """The run's pulse shape: fixed, or γ and ν drawn from the run's seed."""
        if self.shape is not None:
            return self.shape
        _, gamma, nu, _, _ = self.unit
        rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(2,)))
        g = gamma.draw(rng) if isinstance(gamma, Distribution) else gamma
        n = nu.draw(rng) if isinstance(nu, Distribution) else nu
        return MPShape(gamma=g, nu=n)

    def excitation(self, f: float, seed: int = 0):
        if self.kind == "record":
            return self.unit if f == 1.0 else self.unit.scaled(f)
        _, _, _, omega, a_unit = self.unit
        return self.shape_for(seed)(amplitude=f * a_unit, omega=omega)

    def factor(self, measure: str, level: float) -> float:
        """The scale factor that brings this motion to `level` of `measure`."""
        if measure in ("scale", "amp_over_g_tan_alpha"):
            return float(level)
        unit = self.ims[measure]
        if measure == "arias":  # I_A grows with the square of the scale
            return math.sqrt(level / unit)
        return level / unit


def pulse_ims(pulse, suite) -> dict:
    """The IMs of an M&P pulse, sampled at `_PULSE_SAMPLES` points per pulse period."""
    n = max(2001, int(_PULSE_SAMPLES * pulse.duration * pulse.fp) + 1)
    t = np.linspace(0.0, pulse.duration, n)
    return _ims(t, pulse.acceleration(t), suite)


@dataclass(frozen=True)
class _ImSpec:
    """What the IMs of a motion depend on (sent to workers instead of the whole suite)."""

    sa_periods: tuple
    damping: float
    period: float | None

    @classmethod
    def of(cls, suite: Suite) -> _ImSpec:
        return cls(tuple(suite.sa_periods), float(suite.damping), suite.period)


def _ims(t, a, suite) -> dict:
    """PGA, PGV, PGD, Arias and the Sa columns of `suite` (a Suite or `_ImSpec`)."""
    out = {
        "pga": im.pga(t, a),
        "pgv": im.pgv(t, a),
        "pgd": im.pgd(t, a),
        "arias": im.arias_intensity(t, a),
    }
    if suite.sa_periods:
        sa = im.spectral_acceleration(t, a, np.array(suite.sa_periods), damping=suite.damping)
        out |= {_sa_name(T): float(x) for T, x in zip(suite.sa_periods, sa)}
    if suite.period is not None:
        out["sa"] = out[_sa_name(suite.period)]
    return out


def _sa_name(T: float) -> str:
    return f"sa_{T:.3f}s"


def motions(suite: Suite) -> list[_Motion]:
    """The suite's motions at unit scale, with their IMs (records first, then pulses).

    Raises
    ------
    InputError
        Sa asked at a period a record's step cannot resolve (names the record, its dt
        and the shortest period it supports).
    """
    st = suite.structure
    out = []
    nan = dict(omega_p_over_p=math.nan, fp=math.nan, gamma=math.nan, nu=math.nan)
    for r in suite.records:
        try:
            ims = _ims(r.time, r.accel, suite)
        except InputError as exc:
            raise InputError(
                f"{suite.source}: record {r.name!r} (dt = {r.dt:g} s): {exc}. Drop the Sa periods "
                "below the record's resolution from [intensity], or use a finer record"
            ) from None
        out.append(_Motion(r.name, "record", r, ims, nan))
    if suite.pulses is not None:
        p = getattr(st, "p", None)
        if p is None or not math.isfinite(p):
            raise InputError(f"{suite.source}: {st.name} has no frequency parameter p for pulses")
        a_unit = uplift_threshold(st)  # g tan α for a block
        for ratio, gamma, nu in suite.pulses.combinations():
            omega = ratio * p
            unit = (ratio, gamma, nu, omega, a_unit)
            meta = dict(omega_p_over_p=ratio, fp=omega / TWO_PI, gamma=math.nan, nu=math.nan)
            if isinstance(gamma, Distribution) or isinstance(nu, Distribution):
                tag = lambda x, s: f"_{s}{x:g}" if not isinstance(x, Distribution) else ""
                name = f"mp_wp{ratio:g}" + tag(gamma, "g") + tag(nu, "nu")
                out.append(_Motion(name, "pulse", unit, {"pga": a_unit}, meta))
                continue
            shape = MPShape(gamma=gamma, nu=nu)
            ims = pulse_ims(shape(amplitude=a_unit, omega=omega), suite)
            name = f"mp_wp{ratio:g}_g{gamma:g}_nu{nu:g}"
            meta |= dict(gamma=gamma, nu=nu)
            out.append(_Motion(name, "pulse", unit, ims, meta, shape))
    return out


# --------------------------------------------------------------------------- one run
@dataclass(frozen=True)
class _Job:
    """One run. A record's run carries the unscaled record and its `scale` (scaled where it
    runs), so a batch of runs sends each record once, not a copy per run."""

    structure: object
    excitation: object
    t_end: float
    seed: int
    options: dict
    ims: _ImSpec | None = None  # compute the IMs of this (drawn) pulse in the worker
    draw: float = math.nan  # the restitution value drawn for this run (k or r), if any
    scale: float | None = None

    def ground(self):
        """The run's excitation."""
        return self.excitation if self.scale is None else self.excitation.scaled(self.scale)


def _draw_options(suite: Suite, seed: int) -> tuple[dict, float]:
    """The run's restitution options and the drawn value (NaN if none), from its seed."""
    opts = {"impact": suite.impact}
    if suite.restitution is not None:
        opts["restitution"] = suite.restitution
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(1,)))
    if suite.k is not None:
        k = suite.k.draw(rng)
        return opts | {"k": k}, k
    if suite.restitution_value is not None:
        r = suite.restitution_value.draw(rng)
        return opts | {"restitution": r}, r
    return opts, math.nan


def _result(job: _Job, theta_max, overturned, n_impacts, status, t_over, message) -> tuple:
    """The tuple of one run (see `suite_run`), from its outcome's numbers."""
    theta = theta_max / job.structure.alpha_cg
    if not math.isfinite(theta):
        theta = math.nan if status == "failed" else 0.0
    return (
        float(theta),
        bool(overturned),
        int(n_impacts),
        str(status),
        float(t_over),
        message if status in ("failed", "inaccurate") else "",
        None if job.ims is None else pulse_ims(job.excitation, job.ims),
    )


def _summary_result(job: _Job, r) -> tuple:
    """The tuple of one run from its `multimass.simulation.RunSummary`."""
    overturned = r.outcome == "overturned"
    return _result(job, r.theta_max, overturned, r.n_impacts, r.status, r.overturn_time, r.message)


def suite_run(job: _Job) -> tuple:
    """One run: (θ_max/α, overturned, impacts, status, overturn time or NaN, message, IMs
    of the excitation or None)."""
    r = outcome_summary(job.structure, job.ground(), t_end=job.t_end, seed=job.seed, **job.options)
    return _summary_result(job, r)


def suite_columns(jobs: list) -> list[tuple]:
    """`suite_run` of every job of a batch, the runs of a column with the same options
    prepared once (`multimass.simulation.outcome_summaries`: the same results, run for run)."""
    out: list = []
    k = 0
    while k < len(jobs):
        j = k + 1
        while j < len(jobs) and jobs[j].options == jobs[k].options:
            j += 1
        group, first = jobs[k:j], jobs[k]
        runs = outcome_summaries(
            first.structure, [(b.ground(), b.t_end, b.seed) for b in group], **first.options
        )
        out += [_summary_result(b, r) for b, r in zip(group, runs)]
        k = j
    return out


def _batch_reproduces(st, options: dict) -> bool:
    """Whether the compiled batch gives a rigid block's runs with these options (one run's:
    the runs differ in their restitution draws and seed only), as `suite_batch` would find
    run by run (`multimass.engines.fast.block_runs.BlockRuns.of_runs`,
    `restitution_pairs`): if not, every run goes per run and a pool need not load the
    batch kernels."""
    from ..engines.fast.block_runs import BlockRuns, restitution_pairs

    return (
        BlockRuns.of_runs(st, options) is not None and restitution_pairs(st, [options]) is not None
    )


def suite_batch(jobs: list) -> list[tuple]:
    """`suite_run` of every job, a rigid block's in compiled batches where they reproduce
    `simulate_outcome` run for run (`multimass.sweeps.block_outcomes.simulate_outcomes`; the
    others, and runs the batch cannot finish, one at a time)."""
    from ..sweeps.block_outcomes import simulate_outcomes

    st = jobs[0].structure
    r = simulate_outcomes(
        st,
        [j.ground() for j in jobs],
        [j.t_end for j in jobs],
        [j.options | {"seed": j.seed} for j in jobs],
    )
    return [
        _result(
            j,
            r.theta_max[i],
            r.overturned[i],
            r.n_impacts[i],
            r.status[i],
            r.overturn_time[i],
            r.message[i],
        )
        for i, j in enumerate(jobs)
    ]


#: Memory of one row of the runs table (bytes): 27 columns, the strings as Python objects
#: (measured 2026-11-28 with pandas' deep memory usage: 0.26 kB per row of a pulse suite,
#: 0.33 kB of a record suite), twice over for the copy made while the chunks are joined.
ROW_BYTES = 700.0


def _parallel_workers(executor, workers) -> int:
    """Workers the suite's runs are spread over: known for "serial" and a local process
    pool; 1 for an executor object or a cluster, whose size is not known beforehand."""
    if not isinstance(executor, str) or executor.lower() == "dask":
        return 1
    if executor.lower() == "serial":
        return 1
    return validate_workers(workers) or available_workers()


def suite_cost(suite: Suite, n: int, one: RunCost, executor="process", workers=None) -> RunCost:
    """The estimated cost of a whole suite: its `n` runs × the cost of its longest run.

    Parameters
    ----------
    suite : Suite
    n : int
        Runs of the suite (motions × levels × draws).
    one : RunCost
        `multimass.simulation.estimate` of the suite's longest run (longest motion,
        highest level), so the estimate errs long.
    executor, workers :
        As `run_suite`: the wall time is divided among a local pool's workers.

    Returns
    -------
    RunCost
        Steps and seconds of all runs, and the memory of the runs table.
    """
    k = _parallel_workers(executor, workers)
    basis = (
        f"{n:,} runs ({suite.n_motions} motions × {len(suite.levels)} levels × "
        f"{int(suite.draws):,} draws) × {format_duration(one.seconds)} for the longest run"
        + (f", on {k} workers" if k > 1 else "")
    )
    return RunCost(
        steps=n * one.steps, seconds=n * one.seconds / k, memory=n * ROW_BYTES, basis=basis
    )


#: Rigid-block suites in compiled batches (`suite_batch`), where the batch reproduces their
#: options (`_batch_reproduces`; else one job per run): None (default) when the batch
#: kernels are ready or the suite has enough runs to pay for their compile
#: (`multimass.sweeps.map_cells.use_batch`, the maps' rule); True always (compiling them if
#: need be); False never: one job per run (`suite_run`), the same results.
BATCHED: bool | None = None
#: A chunk of a batched suite is cut into this many jobs (strided, so they cost alike).
BATCHES_PER_CHUNK = 8
#: Column suites on the compiled path run a batch per task, prepared once (`suite_columns`);
#: False: one job per run (`suite_run`).
COLUMNS_BATCHED = True


# --------------------------------------------------------------------------- the table
@dataclass(frozen=True, eq=False)
class SuiteRuns:
    """What `run_suite` returns.

    Attributes
    ----------
    suite : Suite
    runs : pandas.DataFrame
        One row per run (`RUN_COLUMNS`, then ``sa_<T>s`` columns).
    wall_time_s : float
        Seconds from the call of `run_suite` to its return: reading the motions and their
        IMs, the checks, loading the compiled kernels, starting the workers, the runs, the
        chunks written and the table joined (a resumed suite: the chunks read back, the
        missing ones run).
    computed, resumed : int
        Runs computed by this call, and read back from finished chunks.
    chosen : dict
        With ``method = "auto"``: ``{"method_choice": ...}``, the method the runs used and
        why (`multimass.sweeps.method_choice`); else empty.
    """

    suite: Suite
    runs: pd.DataFrame
    wall_time_s: float
    computed: int
    resumed: int
    chosen: dict = field(default_factory=dict)  # {"method_choice": ...} of method "auto"

    def summary(self) -> dict:
        r = self.runs
        status = r.status.value_counts().to_dict()
        return (
            {
                "suite": self.suite.name,
                "structure": self.suite.structure.name,
                "n_runs": int(len(r)),
                "n_motions": int(r.motion.nunique()),
                "n_levels": int(len(self.suite.levels)),
                "draws": int(self.suite.draws),
                "measure": self.suite.measure,
                "overturned": int(r.overturned.sum()),
                "status": {k: int(v) for k, v in status.items()},
                "computed": self.computed,
                "resumed": self.resumed,
            }
            | self.timing(self.wall_time_s, _CALL)
            | self.chosen
        )

    def timing(self, seconds: float, covers: str) -> dict:
        """``wall_time_s``, what it covers and ``runs_per_s`` (runs computed per second)."""
        return {
            "wall_time_s": round(seconds, 3),
            "wall_time_covers": covers,
            "runs_per_s": round(self.computed / seconds, 2) if seconds else None,
        }


_CALL = (
    "the call of run_suite: the motions and their IMs, the checks, loading the compiled "
    "kernels, starting the workers, the runs and the table"
)


def _manifest(suite: Suite) -> dict:
    desc = suite.describe()
    text = json.dumps(desc, sort_keys=True, default=str)
    return {"format": 1, "suite": desc, "hash": hashlib.sha256(text.encode()).hexdigest()}


def _recorded(folder: Path, manifest: dict) -> dict | None:
    """The manifest of a folder's earlier runs of this suite, None for a new folder.

    Raises `SuiteMismatch` for a folder of another suite (or of other settings)."""
    path = folder / MANIFEST
    if not path.exists():
        return None
    try:
        old = json.loads(path.read_text())
    except (OSError, ValueError):
        old = {}
    if old.get("hash") != manifest["hash"]:
        raise SuiteMismatch(
            f"{folder}: holds the runs of another suite ({old.get('suite', {}).get('name')!r} "
            "or other settings); give another --out folder, or delete this one to start over"
        )
    return old


def _open(folder: Path, manifest: dict, old: dict | None) -> None:
    """Write the manifest of a new folder, or add to an old one what it lacks (the method
    of its runs: folders written before it was recorded)."""
    folder.mkdir(parents=True, exist_ok=True)
    if old is None or any(k not in old for k in manifest):
        (folder / MANIFEST).write_text(json.dumps((old or {}) | manifest, indent=1, default=str))


def _write(path: Path, table: pd.DataFrame) -> None:
    tmp = path.with_name(f".{path.name}.tmp")
    table.to_parquet(tmp, index=False)
    os.replace(tmp, path)


def run_suite(
    suite: Suite,
    *,
    out=None,
    executor="process",
    workers: int | None = None,
    chunk_runs: int | None = None,
    progress: bool | None = None,
    max_hours: float | None = None,
) -> SuiteRuns:
    """Run every run of `suite`; resume from `out` if it holds finished chunks.

    Parameters
    ----------
    suite : Suite
    out : path, optional
        Folder for ``runs/part-*.parquet`` and ``manifest.json`` (resumable).
    executor, workers :
        As `multimass.sweeps.engine.run_jobs` ("serial", "process", "dask" or an Executor).
    chunk_runs : int, optional
        Runs per stored chunk (default: about 1/40 of the suite, 20 to 2000).
    progress : bool, optional
        A progress bar over the runs (default: on a terminal).
    max_hours : float, optional
        The budget: a suite whose estimated time (`suite_cost`) is longer is refused
        before its first run (default one hour, `multimass.progress.DEFAULT_BUDGET_S`;
        ``math.inf`` for none).

    Returns
    -------
    SuiteRuns
        Its ``wall_time_s`` is the whole call. With ``suite.options["method"] = "auto"``
        (``[model] method``), the method of a column's runs is chosen on the suite's
        longest run at its highest level (`multimass.sweeps.method_choice`) and reported
        in ``chosen``.

    Raises
    ------
    InputError
        For a level a record reaches only with a factor above ``suite.max_scale``, Sa
        at a period a record cannot resolve, an output folder of another suite, or a
        suite over the budget or beyond the memory (`suite_cost`).
    """
    st = suite.structure
    wall = time.perf_counter()
    ms = motions(suite)
    levels = np.asarray(suite.levels, dtype=float)
    factors = np.array([[m.factor(suite.measure, L) for L in levels] for m in ms])
    for i, m in enumerate(ms):
        if m.kind == "record" and factors[i].max() > suite.max_scale:
            j = int(np.argmax(factors[i]))
            raise InputError(
                f"{suite.source}: record {m.name!r} reaches {suite.measure} = {levels[j]:.4g} "
                f"(level {j}) only scaled by {factors[i, j]:.3g}, above max_scale = "
                f"{suite.max_scale:g}: no run of it reaches that level undistorted. Lower the "
                "highest level, drop the record, or raise [model] max_scale"
            )
    n_l, n_d = len(levels), int(suite.draws)
    n = len(ms) * n_l * n_d
    options = sweep_method(st, default_backend(dict(suite.options)))
    chosen = {}
    folder = Path(out) if out is not None else None
    manifest = _manifest(suite)
    before = _recorded(folder, manifest) if folder is not None else None
    p = float(getattr(st, "p", math.nan) or math.nan)

    def job(i: int) -> _Job:
        mi, rest = divmod(i, n_l * n_d)
        j = rest // n_d
        m = ms[mi]
        seed = job_seed(suite.seed, i)  # derived per run: never a list of the suite's seeds
        f = float(factors[mi, j])
        opts, drawn = _draw_options(suite, seed)
        ims = _ImSpec.of(suite) if m.drawn else None
        if m.kind == "record" and f != 1.0:  # scaled where it runs (`_Job.ground`)
            t_end = m.unit.duration + suite.t_free
            return _Job(st, m.unit, t_end, seed, options | opts, ims, drawn, f)
        exc = m.excitation(f, seed)
        return _Job(st, exc, exc.duration + suite.t_free, seed, options | opts, ims, drawn)

    # the options and the longest run checked here, and the whole suite's cost, before any
    # worker starts
    longest = max(range(len(ms)), key=lambda mi: ms[mi].excitation(1.0, 0).duration)
    probe = job(longest * n_l * n_d + (n_l - 1) * n_d)
    if options.get("method") == AUTO:  # the suite's method, chosen on its longest run
        if before is not None and ("method" in before or "method" not in suite.options):
            # resumed: the method its runs used, as recorded (a folder from before the
            # record, of a suite naming no method: DOP853, the default then)
            picked, chosen = {"method": before.get("method", "DOP853")}, before.get("chosen", {})
        else:
            picked, chosen = resolve(
                st, probe.ground(), probe.t_end, probe.seed, probe.options, progress
            )
        options = options | {"method": picked["method"]}  # `job` reads it from here on
        probe = job(longest * n_l * n_d + (n_l - 1) * n_d)
    one = estimate(st, probe.ground(), t_end=probe.t_end, seed=probe.seed, **probe.options)
    suite_cost(suite, n, one, executor, workers).check(
        f"{suite.source}: suite {suite.name!r} of {n:,} runs",
        "lower [monte_carlo] draws, the number of [intensity] levels or of motions",
        max_seconds=budget_seconds(max_hours),
    )

    def rows(index: np.ndarray, jobs: list, results: list) -> pd.DataFrame:
        mi, rest = np.divmod(index, n_l * n_d)
        j, d = np.divmod(rest, n_d)
        f = factors[mi, j]
        cols = {
            "structure": st.name,
            "alpha": float(st.alpha_cg),
            "p": p,
            "motion": [ms[k].name for k in mi],
            "motion_kind": [ms[k].kind for k in mi],
            "im_name": suite.measure,
            "im": levels[j],
            "level": j,
            "draw": d,
            "seed": [jb.seed for jb in jobs],
            "scale": f,
            "restitution_draw": [j.draw for j in jobs],
        }
        names = ("theta_max_over_alpha", "overturned", "n_impacts", "status", "overturn_time")
        for c, name in enumerate(names + ("message",)):
            cols[name] = [r[c] for r in results]
        for key in ["pga", "pgv", "pgd", "arias"] + [_sa_name(T) for T in suite.sa_periods]:
            power = 2.0 if key == "arias" else 1.0
            cols[key] = [
                r[6][key] if r[6] is not None else ms[k].ims[key] * fk**power
                for k, fk, r in zip(mi, f, results)
            ]
        for key in ("omega_p_over_p", "fp", "gamma", "nu"):
            cols[key] = [ms[k].pulse[key] for k in mi]
        for row, (k, jb) in enumerate(zip(mi, jobs)):
            if ms[k].drawn:  # the run's own shape, drawn in `job`
                cols["gamma"][row], cols["nu"][row] = jb.excitation.gamma, jb.excitation.nu
        pulse = np.array([ms[k].kind == "pulse" for k in mi])
        cols["amp_over_g_tan_alpha"] = np.where(pulse, f, np.nan)
        cols["fp"] = np.asarray(cols["fp"], dtype=float)  # a_p = f · g tan α; f_p = ω_p/2π
        return pd.DataFrame(cols)[RUN_COLUMNS + [_sa_name(T) for T in suite.sa_periods]]

    chunk = int(chunk_runs) if chunk_runs else int(np.clip(math.ceil(n / 40), 20, 2000))
    n_chunks = -(-n // chunk)
    if folder is not None:  # with the method of its runs: a resumed suite keeps it
        _open(folder, manifest | {"method": options.get("method"), "chosen": chosen}, before)
        (folder / "runs").mkdir(exist_ok=True)
    part = lambda c: folder / "runs" / f"part-{c:05d}.parquet"
    todo = [c for c in range(n_chunks) if folder is None or not part(c).exists()]
    done = n - sum(min(chunk, n - c * chunk) for c in todo)
    show = progress if progress is not None else bool(getattr(sys.stderr, "isatty", bool)())
    bar = _Bar(
        total=n, initial=done, desc=suite.name, unit="run", file=sys.stderr, disable=not show
    )
    tables = {}
    compiled = options.get("backend") == "compiled"
    batched = (  # n: as in `suite_cost`; the probe's options are every run's but the draws
        compiled and st.n == 0 and _batch_reproduces(st, probe.options) and use_batch(BATCHED, n)
    )
    try:
        columns = compiled and st.n > 0  # whole runs (`multimass.engines.fast.column_runs`)
        preload = preload_modules(st.n > 0, bool(suite.records), batched) if compiled else ()
        with kernel_session(executor, workers, preload) as ex:
            for c in todo:
                index = np.arange(c * chunk, min((c + 1) * chunk, n))
                jobs = [job(int(i)) for i in index]
                if batched:
                    k = min(BATCHES_PER_CHUNK, len(jobs))
                    batches = [jobs[b::k] for b in range(k)]
                    parts_ = run_jobs(suite_batch, batches, executor=ex, progress=False)
                    results = [None] * len(jobs)
                    for b, part_results in enumerate(parts_):
                        results[b::k] = part_results
                elif columns and COLUMNS_BATCHED:  # a task per batch of the plan, prepared together
                    results = run_batches(suite_columns, jobs, executor=ex, progress=False)
                else:
                    results = run_jobs(suite_run, jobs, executor=ex, progress=False)
                tables[c] = rows(index, jobs, results)
                if folder is not None:
                    _write(part(c), tables[c])
                bar.update(len(index))
    finally:
        bar.close()
    parts = [tables[c] if c in tables else pd.read_parquet(part(c)) for c in range(n_chunks)]
    runs = pd.concat(parts, ignore_index=True)
    computed = sum(len(tables[c]) for c in tables)
    return SuiteRuns(suite, runs, time.perf_counter() - wall, computed, n - computed, chosen)
