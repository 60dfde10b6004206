"""Rocking response spectra (paper 001, Section 4.4, Figs 10 and 12).

θ_max of a structure against the frequency or the amplitude of a pulse, or
against the scale factor of a recorded ground motion, each point optionally
repeated with random restitution (DD5) to show the spread.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .. import validation as v
from ..errors import InputError
from ..inputs.excitations import MPShape
from ..inputs.excitations import pulse as make_pulse
from ..inputs.records import Record
from ..model.structure import Structure, from_specimen
from ..simulation import estimate, outcome_summaries, outcome_summary
from .engine import run_batches
from .kernel_pools import kernel_session, preload_modules
from .map_cells import pulse_label
from .maps import default_backend
from .method_choice import resolve, sweep_method
from .ranges import check_values
from .seeding import job_seeds

__all__ = ["Spectrum", "pulse_spectrum", "record_spectrum", "spectrum_point", "spectrum_points"]


@dataclass(frozen=True)
class _Point:
    """One run of a spectrum. A record's run carries the unscaled record and its `scale`
    (scaled where it runs), so a batch sends the record once, not a copy per run."""

    structure: Structure
    excitation: object
    t_end: float
    seed: int
    options: dict
    scale: float | None = None

    def ground(self):
        """The run's excitation."""
        return self.excitation if self.scale is None else self.excitation.scaled(self.scale)


def _checked(p: _Point, r) -> tuple:
    """(θ_max, status, impacts, overturn time or nan) of a run's `RunSummary`."""
    if r.status == "failed":
        raise RuntimeError(f"{p.ground().describe()}: {r.message}")
    return r.theta_max, r.status, r.n_impacts, r.overturn_time


def spectrum_point(p: _Point) -> tuple:
    """One simulation of a spectrum: (θ_max, status, impacts, overturn time or nan).

    `multimass.simulation.outcome_summary`: a column on the compiled path runs whole
    in one compiled call (`multimass.engines.fast.column_runs`).
    """
    exc = p.ground()
    return _checked(p, outcome_summary(p.structure, exc, t_end=p.t_end, seed=p.seed, **p.options))


def spectrum_points(points: list) -> list[tuple]:
    """`spectrum_point` of each point of a batch, the runs of a column prepared once
    (`multimass.simulation.outcome_summaries`: the same results, run for run)."""
    same = lambda a, b: a.structure is b.structure and a.options == b.options
    out: list = []
    k = 0
    while k < len(points):  # the points of one structure and options run together
        p = points[k]
        j = k + 1
        while j < len(points) and same(points[j], p):
            j += 1
        group = points[k:j]
        runs = outcome_summaries(
            p.structure, [(q.ground(), q.t_end, q.seed) for q in group], **p.options
        )
        out += [_checked(q, r) for q, r in zip(group, runs)]
        k = j
    return out


@dataclass(frozen=True, eq=False)
class Spectrum:
    """A rocking spectrum: one row per run in `table`.

    ``table`` columns: the swept parameter(s) (``omega``, ``amp`` in m/s²,
    ``scale``), ``repeat``, ``seed``, ``theta_max`` (rad), ``status``
    ("completed", "overturned" or "inaccurate", see `multimass.simulate`),
    ``n_impacts``, ``overturn_time``.

    One convention for every summary of θ_max (`stats`, the CLI's printed lines,
    JSON and `multimass.sweeps.plots.plot_spectrum`): the mean, spread and range
    are over the runs that completed — neither overturned (θ_max would only
    say "π/2") nor inaccurate (not to be trusted); those are counted apart.
    """

    structure: str
    kind: str
    table: pd.DataFrame
    options: dict = field(default_factory=dict)
    #: Seconds from the call of `pulse_spectrum` or `record_spectrum` to its return: the
    #: checks, loading the compiled kernels, starting the workers, the runs and the table.
    wall_time_s: float = 0.0

    def stats(self, by: str) -> pd.DataFrame:
        """Per value of `by`: ``n`` runs; ``mean``, ``std``, ``min``, ``max`` of θ_max over
        the ``completed`` ones (NaN if none); counts ``overturned`` and ``inaccurate``."""
        t = self.table
        values = np.unique(t[by].to_numpy())
        done = t[t.status == "completed"].groupby(by).theta_max.agg(["mean", "std", "min", "max"])
        out = done.reindex(values).rename_axis(by).reset_index()
        count = lambda st: t[t.status == st].groupby(by).size().reindex(values, fill_value=0)
        out["n"] = t.groupby(by).size().reindex(values).to_numpy()
        out["completed"] = count("completed").to_numpy()
        out["overturned"] = count("overturned").to_numpy()
        out["inaccurate"] = count("inaccurate").to_numpy()
        return out

    def summary(self) -> dict:
        return {
            "structure": self.structure,
            "kind": self.kind,
            "rows": self.table.replace({np.nan: None}).to_dict(orient="records"),
            "n_simulations": int(len(self.table)),
            "wall_time_s": float(self.wall_time_s),
            "wall_time_covers": "the spectrum's call: its checks, loading the compiled "
            "kernels, starting the workers, the runs and the table",
            "options": self.options,
        }


def _common(repeats, seed, t_free) -> tuple:
    """Validated (repeats, seed, t_free) of a spectrum."""
    repeats = v.integer("repeats", repeats, low=1, what="runs per point")
    if seed is not None:
        seed = v.integer("seed", seed, low=0)
    return repeats, seed, v.positive("t_free", t_free, "free response after the excitation, s")


def _check_in_parent(points, progress=None) -> tuple[list, dict]:
    """Validate the options and the cost of the longest run here, before any worker starts;
    with ``method="auto"``, choose the method on that run (`multimass.sweeps.method_choice`;
    of the longest, the last: the largest scale or amplitude, the one that rocks most).

    Returns the points with the method chosen, and the choice to report (or {})."""
    p = max(reversed(points), key=lambda q: q.t_end)
    options, chosen = resolve(p.structure, p.ground(), p.t_end, p.seed, p.options, progress)
    if chosen:
        points = [dataclasses.replace(q, options=options) for q in points]
    estimate(p.structure, p.ground(), t_end=p.t_end, seed=p.seed, **options)
    return points, chosen


def _run(st, points, sweep_cols, executor, workers, progress, desc, kind, options, started):
    """The spectrum of `points`; its wall time counts from `started`."""
    with kernel_session(executor, workers, _preload(st, kind, options)) as ex:
        # one task per batch of the engine's plan, its runs prepared together
        results = run_batches(
            spectrum_points, points, executor=ex, progress=progress, desc=desc, unit="run"
        )
    table = _table(sweep_cols, results)
    return Spectrum(st.name, kind, table, options, time.perf_counter() - started)


def _preload(st, kind: str, options: dict) -> tuple[str, ...]:
    """The kernels a process pool's workers load for this spectrum (`preload_modules`)."""
    if options.get("backend") != "compiled":
        return ()
    contact = kind == "record" and options.get("full_contact") != "integrate"
    return preload_modules(column=st.n > 0, record=contact)


def _table(sweep_cols: dict, results: list) -> pd.DataFrame:
    """The spectrum's table: the swept columns, then each run's outcome."""
    table = pd.DataFrame(sweep_cols)
    for k, name in enumerate(("theta_max", "status", "n_impacts", "overturn_time")):
        table[name] = [r[k] for r in results]
    return table


def pulse_spectrum(
    structure,
    pulse: str = "cosine",
    omega=15.0,
    amp=0.4 * 9.81,
    *,
    impact: str = "DD2",
    repeats: int = 1,
    seed: int | None = 0,
    t_free: float = 5.0,
    executor="process",
    workers=None,
    progress=None,
    **sim_options,
) -> Spectrum:
    """θ_max over pulse frequencies and amplitudes (paper 001, Fig 10).

    Parameters
    ----------
    structure : Structure, specimen or str
    pulse : {"cosine", "sine", "ricker", "mp"} or MPShape
        "cosine": paper 001's cosine pulse (`CosinePulse`); "mp" or an `MPShape`: the
        Mavroeidis–Papageorgiou pulse with f_p = ω/2π and peak acceleration `amp`.
    omega : float or array_like
        Circular frequencies (rad/s, > 0).
    amp : float or array_like
        Amplitudes (m/s², ≥ 0; the peak acceleration of an M&P pulse).
    impact : str or ImpactModel
    repeats : int
        Runs per point; with random restitution (DD5) each gets its own seed.
    seed : int
        Base seed; job k uses `job_seeds(seed, n)[k]`, so results do not
        depend on the executor.
    t_free : float
        Free response after the pulse (s).
    **sim_options :
        Passed to `simulate`; ``backend="compiled"`` (the fast path) unless given.
        ``method="auto"`` (a column's default on the compiled path,
        `multimass.sweeps.method_choice.sweep_method`): DOP853 or the exponential rocking
        integrator, chosen for the structure on the spectrum's longest run
        (`multimass.sweeps.method_choice`); the choice and why are in
        ``options["method_choice"]``. ``method="DOP853"`` keeps DOP853 without a choice.

    Returns
    -------
    Spectrum
        Its ``wall_time_s`` is the whole call, from its start to its table.
    """
    started = time.perf_counter()
    st = structure if isinstance(structure, Structure) else from_specimen(structure)
    omegas = check_values("omega", omega, positive=True)
    amps = check_values("amp", amp, nonnegative=True)
    repeats, seed, t_free = _common(repeats, seed, t_free)
    kind = getattr(st.specimen, "kind", "column")
    grid = [(w, a, r) for a in amps for w in omegas for r in range(int(repeats))]
    seeds = job_seeds(seed, len(grid))
    options = sweep_method(st, dict(impact=impact) | default_backend(sim_options))
    if isinstance(pulse, MPShape):
        build, label = pulse, pulse_label(pulse)
    else:
        build = lambda **kw: make_pulse(pulse, structure_kind=kind, **kw)
        label = pulse
    points = []
    for (w, a, _), s in zip(grid, seeds):
        exc = build(amplitude=a, omega=w)
        points.append(_Point(st, exc, exc.duration + t_free, s, options))
    points, chosen = _check_in_parent(points, progress)
    cols = {
        "omega": [g[0] for g in grid],
        "amp": [g[1] for g in grid],
        "repeat": [g[2] for g in grid],
        "seed": list(seeds),
    }
    return _run(
        st,
        points,
        cols,
        executor,
        workers,
        progress,
        f"{st.name} {label} spectrum",
        f"{label}_pulse",
        points[0].options | {"pulse": label, "t_free": t_free, "seed": seed} | chosen,
        started,
    )


def record_spectrum(
    structure,
    record: Record,
    scale=np.linspace(0.5, 1.5, 5),
    *,
    impact: str = "DD5",
    repeats: int = 3,
    seed: int | None = 0,
    t_free: float = 5.0,
    executor="process",
    workers=None,
    progress=None,
    **sim_options,
) -> Spectrum:
    """θ_max over scale factors of a record, repeated with random restitution (paper 001, Fig 12).

    Parameters
    ----------
    record : Record
        The unscaled record; each run uses it scaled by `scale`.
    scale : array_like
        Scale factors A_sc (> 0).
    impact : str
        Default DD5 (random restitution per impact).
    repeats : int
        Runs per scale factor, each with its own seed.

    The other parameters, ``method="auto"`` and the result's ``wall_time_s`` are as in
    `pulse_spectrum`.
    """
    started = time.perf_counter()
    st = structure if isinstance(structure, Structure) else from_specimen(structure)
    scales = check_values("scale", scale, positive=True)
    if not isinstance(record, Record):
        raise InputError(f"`record` = {record!r}: give a Record (multimass.read_record)")
    repeats, seed, t_free = _common(repeats, seed, t_free)
    grid = [(s, r) for s in scales for r in range(int(repeats))]
    seeds = job_seeds(seed, len(grid))
    options = sweep_method(st, dict(impact=impact) | default_backend(sim_options))
    points = [
        _Point(st, record, record.duration + t_free, sd, options, float(s))
        for (s, _), sd in zip(grid, seeds)
    ]
    points, chosen = _check_in_parent(points, progress)
    cols = {"scale": [g[0] for g in grid], "repeat": [g[1] for g in grid], "seed": list(seeds)}
    return _run(
        st,
        points,
        cols,
        executor,
        workers,
        progress,
        f"{st.name} record spectrum",
        "record",
        points[0].options | {"record": record.name, "t_free": t_free, "seed": seed} | chosen,
        started,
    )
