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
from pathlib import Path

import pandas as pd

from .analysis import ida_summary, im_efficiency, json_ready, pulse_fragility, summary_dict
from .plots import plot_fragility, plot_ida, plot_im_efficiency, plot_pulse_fragility
from .runs import SuiteRuns

__all__ = ["write_report"]


def write_report(result: SuiteRuns, out, *, bootstrap: int = 200, seed: int = 0) -> dict:
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
    """
    out = Path(out)
    runs, suite = result.runs, result.suite
    runs.to_parquet(out / "runs.parquet", index=False)
    runs.to_csv(out / "runs.csv", index=False)
    info = summary_dict(runs, bootstrap=bootstrap, seed=seed)
    info = {"summary": result.summary()} | info
    curves = pd.DataFrame(info["fragility"])
    curves.to_csv(out / "fragility.csv", index=False)
    title = suite.name
    from .analysis import fragility_curves

    plot_fragility(
        runs,
        fragility_curves(runs, bootstrap=bootstrap, seed=seed),
        out / "fragility.png",
        title=f"{title} — {result.summary()['n_runs']} runs",
    )
    eff = im_efficiency(runs)
    eff.to_csv(out / "im_efficiency.csv", index=False)
    plot_im_efficiency(eff, out / "im_efficiency.png", title=f"{title}: IM efficiency")
    kind = runs.motion_kind.astype(str)
    if (kind == "record").any():
        rec = runs[kind == "record"]
        plot_ida(rec, out / "ida.png", title=f"{title}: IDA curves")
        ida_summary(rec).to_csv(out / "ida.csv", index=False)
    if (kind == "pulse").any():
        pf = pulse_fragility(runs[kind == "pulse"])
        pf.curves.to_csv(out / "pulse_fragility.csv", index=False)
        plot_pulse_fragility(
            runs[kind == "pulse"], out / "pulse_fragility.png", title=f"{title}: pulses"
        )
    info = json_ready(info)
    (out / "summary.json").write_text(json.dumps(info, indent=1))
    return info
