"""The files of a finished suite: the runs table, the fragility tables and the figures.

`write_report` writes into the suite's output folder

* ``runs.parquet`` and ``runs.csv`` — one row per run (`multimass.suites.runs`);
* ``fragility.csv`` — the lognormal fit per damage state in the suite's IM (Baker 2015),
  with its band; ``fragility.png``;
* ``im_efficiency.csv`` / ``.png`` — the dispersion β of overturning in each IM column
  (smaller β: a more efficient IM);
* record runs: ``ida.png`` (IDA curves) and ``ida.csv`` (per record);
* pulse runs: ``pulse_fragility.csv`` (per ω_p/p) and ``pulse_fragility.png`` (the
  dimensionless fragility of Dimitrakopoulos & Paraskeva 2015);
* ``summary.json`` — all of it (`multimass.suites.analysis.summary_dict`) with the run's
  counts and timing; `write_report` returns the same dict.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

from .analysis import as_json, summary_tables
from .plots import plot_fragility, plot_ida, plot_im_efficiency, plot_pulse_fragility
from .runs import SuiteRuns

__all__ = ["write_report", "WHOLE_COMMAND"]

#: What ``wall_time_s`` counts when `write_report` is given the command's start.
WHOLE_COMMAND = (
    "the whole command: from its start (its imports, reading the suite and its records, "
    "loading the compiled kernels, starting the workers) through the runs, the runs table, "
    "the fits, tables and figures written, to this summary"
)


def write_report(
    result: SuiteRuns, out, *, bootstrap: int = 200, seed: int = 0, started: float | None = None
) -> dict:
    """Write the tables and figures of `result` into `out` and return the summary dict.

    Parameters
    ----------
    result : SuiteRuns
    out : path
        An existing folder (the suite's ``--out``).
    bootstrap : int
        Bootstrap resamples of the fragility bands (0: the Fisher band only).
    seed : int
        Seed of the bootstrap.
    started : float, optional
        A `time.perf_counter` reading of when the caller's command started (``multimass
        suite``): the summary's ``wall_time_s`` then counts from it to the summary's
        writing, the runs, tables and figures included (default: the runs' own
        `SuiteRuns.wall_time_s`).
    """
    out = Path(out)
    runs, suite = result.runs, result.suite
    runs.to_parquet(out / "runs.parquet", index=False)
    runs.to_csv(out / "runs.csv", index=False)
    tables = summary_tables(runs, bootstrap=bootstrap, seed=seed)
    summary = result.summary()
    title = suite.name
    tables["fragility"].to_csv(out / "fragility.csv", index=False)
    plot_fragility(
        runs,
        tables["fragility"],
        out / "fragility.png",
        title=f"{title} — {summary['n_runs']} runs",
    )
    eff = tables["im_efficiency"]
    eff.to_csv(out / "im_efficiency.csv", index=False)
    plot_im_efficiency(eff, out / "im_efficiency.png", title=f"{title}: IM efficiency")
    kind = runs.motion_kind.astype(str)
    if tables["ida"] is not None:
        plot_ida(runs[kind == "record"], out / "ida.png", title=f"{title}: IDA curves")
        tables["ida"].to_csv(out / "ida.csv", index=False)
    if tables["pulse"] is not None:
        tables["pulse"].curves.to_csv(out / "pulse_fragility.csv", index=False)
        plot_pulse_fragility(
            runs[kind == "pulse"], out / "pulse_fragility.png", title=f"{title}: pulses"
        )
    if started is not None:  # the whole command, up to this summary
        summary |= result.timing(time.perf_counter() - started, WHOLE_COMMAND)
    info = {"summary": summary} | as_json(tables)
    (out / "summary.json").write_text(json.dumps(info, indent=1))
    return info
