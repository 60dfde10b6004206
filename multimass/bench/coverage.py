"""The identification coverage benchmark: how far the estimators' answers are from the
truth of synthetic tests whose hidden parameters they are not told, and how often
their reported 95 % intervals hold it.

`run_coverage` draws `n` synthetic tests per specimen (`multimass.bench.
coverage_draws`: C_p, damping, restitution, release, sampling, noise, bias and clock
away from the specimen file; every fifth with table motion from a real record), runs
`multimass.identify.restitution` on each (and `multimass.identify.calibrate` on every
`calibrate_every`-th) with only the specimen's name and the impact model family, and
appends each case's estimates and truths to ``results.jsonl`` in `out` as soon as it
is done, so an interrupted run keeps what it finished (``resume`` goes on from it).
`write_report` turns that file into ``estimates.csv`` (and ``.parquet``), ``cases.csv``,
``summary.json``, ``coverage.md`` and the figures (`multimass.bench.coverage_report`).

The developer script ``python -m benchmarks.identify_coverage`` and ``multimass bench
--coverage`` call these.
"""

from __future__ import annotations

import json
import os
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass, field
from datetime import UTC, datetime
from pathlib import Path

from .. import validation as v
from ..errors import InputError
from ..progress import Progress
from .coverage_cases import run_case
from .coverage_draws import draw_case

__all__ = ["CoverageConfig", "run_coverage", "read_results", "read_runs", "RESULTS", "RUNS"]

RESULTS = "results.jsonl"
RUNS = "runs.jsonl"  # one line per run (resumed runs add one): start, cases, wall time


@dataclass(frozen=True)
class CoverageConfig:
    """What `run_coverage` runs.

    Attributes
    ----------
    n : int
        Synthetic tests per specimen.
    specimens : tuple of str
    seed : int
        Seeds every draw (with the specimen and the case's index).
    family : str
        The impact model simulated and fitted: "DD" (Dirac-delta) or "CIM".
    calibrate_every : int
        `calibrate` runs on the cases whose index is a multiple of this (0: never).
    records : str or None
        Folder of the record files (`coverage_draws.RECORDS`); None: no table motion.
    workers : int
        Processes (1: in this one).
    """

    n: int = 50
    specimens: tuple = ("S1", "S2", "S3")
    seed: int = 0
    family: str = "DD"
    calibrate_every: int = 5
    records: str | None = None
    workers: int = 1
    extra: dict = field(default_factory=dict)

    def checked(self) -> CoverageConfig:
        n = v.integer("n", self.n, low=1)
        workers = v.integer("workers", self.workers, low=1, high=max(64, os.cpu_count() or 1))
        every = v.integer("calibrate_every", self.calibrate_every, low=0)
        seed = v.integer("seed", self.seed, low=0)
        if self.family not in ("DD", "CIM"):
            raise InputError(f"`family` = {self.family!r}: give DD or CIM")
        if self.records is not None and not Path(self.records).is_dir():
            raise InputError(
                f"`records` = {self.records!r}: not a folder; give the folder of the record "
                "files (e.g. examples/data/records) or none (no table-motion cases)"
            )
        return CoverageConfig(n, tuple(self.specimens), seed, self.family, every,
                              self.records, workers, dict(self.extra))  # fmt: skip


def _tasks(cfg: CoverageConfig, done: set) -> list:
    """(draw, with_calibrate) of every case not done, interleaved across specimens so a
    partial run covers each alike."""
    out = []
    for i in range(cfg.n):
        for spec in cfg.specimens:
            d = draw_case(spec, i, cfg.seed, cfg.family, records=cfg.records is not None)
            if d.case not in done:
                out.append((d, cfg.calibrate_every > 0 and i % cfg.calibrate_every == 0))
    return out


def read_results(out) -> list[dict]:
    """The cases of ``results.jsonl`` in `out` (a line cut short by an interrupted
    write is skipped)."""
    path = Path(out) / RESULTS
    if not path.is_file():
        return []
    cases = []
    for line in path.read_text(encoding="utf-8").splitlines():
        try:
            cases.append(json.loads(line))
        except json.JSONDecodeError:
            continue
    return cases


def read_runs(out) -> list[dict]:
    """The runs recorded in ``runs.jsonl`` in `out`."""
    path = Path(out) / RUNS
    if not path.is_file():
        return []
    return [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines() if line]


def _one(args):
    draw, with_cal, records = args
    try:
        return run_case(draw, records, with_cal)
    except Exception as err:  # a failure of the generator or an estimator is a result
        case = draw.to_dict() | {"error": f"{type(err).__name__}: {str(err)[:300]}"}
        return {"case": case, "rows": []}


def run_coverage(cfg: CoverageConfig, out, resume: bool = False, say=None) -> dict:
    """Run the cases of `cfg`, appending each to ``out/results.jsonl``; the run's facts.

    Parameters
    ----------
    cfg : CoverageConfig
    out : str or Path
        Folder for the results (created).
    resume : bool
        Keep the cases already in ``results.jsonl`` and run the rest; else start anew.
    say : callable, optional
        Called with a line of text per finished case.

    Returns
    -------
    dict
        ``config``, ``cases_run``, ``wall_time_s``.
    """
    cfg = cfg.checked()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    path = out / RESULTS
    done = {c["case"]["case"] for c in read_results(out)} if resume else set()
    if not resume:
        for old in (path, out / RUNS):
            if old.exists():
                old.unlink()
    tasks = _tasks(cfg, done)
    (out / "config.json").write_text(json.dumps(asdict(cfg), indent=1) + "\n", encoding="utf-8")
    wall = time.perf_counter()
    started = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
    args = [(d, c, cfg.records) for d, c in tasks]
    with (
        path.open("a", encoding="utf-8") as fh,
        Progress(len(args), "coverage", show=say is None, unit="cases") as bar,
    ):
        if cfg.workers == 1:
            results = map(_one, args)
        else:
            pool = ProcessPoolExecutor(cfg.workers)
            futures = [pool.submit(_one, a) for a in args]
            results = (f.result() for f in as_completed(futures))
        try:
            for res in results:
                fh.write(json.dumps(res, default=_plain) + "\n")
                fh.flush()
                bar.update(1)
                if say is not None:
                    say(_line(res))
        finally:
            if cfg.workers > 1:
                pool.shutdown(cancel_futures=True)
    run = {
        "started_utc": started,
        "cases_run": len(args),
        "workers": cfg.workers,
        "wall_time_s": round(time.perf_counter() - wall, 1),
        **cfg.extra,
    }
    with (out / RUNS).open("a", encoding="utf-8") as fh:
        fh.write(json.dumps(run) + "\n")
    return {"config": asdict(cfg), **run}


def _plain(x):
    """JSON for numpy scalars."""
    if hasattr(x, "item"):
        return x.item()
    raise TypeError(f"not JSON: {type(x).__name__}")


def _line(res: dict) -> str:
    c = res["case"]
    if "error" in c:
        return f"{c['case']}: {c['error']}"
    times = ", ".join(
        f"{k} {c[k + '_s']:.0f} s ({c[k + '_status']})"
        for k in ("restitution", "calibrate")
        if k + "_s" in c
    )
    ratio = (c["cp"] or 0.0) / (c["cp_table"] or 1.0)
    return f"{c['case']} ({c['kind']}, fs {c['fs']:g} Hz, C_p x{ratio:.2f}): {times}"
