"""``multimass suite``: a record/pulse suite with Monte-Carlo restitution, and its fragility."""

from __future__ import annotations

import dataclasses
import json
import time
from pathlib import Path

from ..errors import InputError
from . import _types as types
from ._output import output_folder
from ._sweep_args import add_executor_args, executor_kwargs

METHODS = ("DOP853", "exponential", "auto")  # as multimass.suites.spec.METHODS

__all__ = ["register"]


def register(sub) -> None:
    p = sub.add_parser(
        "suite",
        help="run a suite of records and/or M&P pulses at many intensities; fragility curves",
        description="Runs every motion of SUITE.toml at every intensity level, with Monte-Carlo "
        "restitution draws, on the sweep engine (resumable: a re-run with the same --out "
        "skips finished chunks); writes one row per run (runs.parquet, runs.csv), the "
        "fragility curves (lognormal MLE, Baker 2015) for overturning and θ/α thresholds, "
        "IDA curves per record, the dimensionless pulse fragility (Dimitrakopoulos & "
        "Paraskeva 2015), the IM efficiency table and figures. The file format is in "
        "multimass.suites.spec; examples in examples/suites/.",
    )
    p.add_argument("suite", metavar="SUITE", help="suite TOML file")
    p.add_argument(
        "--out", type=Path, required=True, help="output folder (runs, tables, figures; resumable)"
    )
    p.add_argument(
        "--bootstrap",
        type=types.whole,
        default=200,
        help="bootstrap resamples for the fragility bands (default 200; 0: Fisher bands only)",
    )
    p.add_argument(
        "--chunk-runs",
        type=types.count,
        default=None,
        help="runs per stored chunk (default ~1/40 of the suite, 20–2000)",
    )
    p.add_argument(
        "--max-hours",
        type=types.positive_or_inf,
        default=None,
        help="budget: refuse a suite estimated to take longer (default 1; inf for none)",
    )
    p.add_argument(
        "--method",
        choices=METHODS,
        default=None,
        help="integrator of a column's rocking phases: DOP853, exponential, or auto (chosen "
        "for the column from its stiffness and a sample run timed and checked each way; "
        "multimass.sweeps.method_choice). Default: the suite file's [model] method, else auto "
        "for a column on the compiled path (DOP853 for a bundled specimen: not stiff)",
    )
    add_executor_args(p)
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(func=run)


def run(args) -> int:
    started = time.perf_counter()
    from multimass.suites.report import write_report
    from multimass.suites.runs import run_suite
    from multimass.suites.spec import Suite

    if 0 < args.bootstrap < 10:  # checked now, not after the runs
        raise InputError(
            f"`--bootstrap` = {args.bootstrap}: give 0 (the Fisher band) or ≥ 10 resamples"
        )
    suite = Suite.from_toml(args.suite)
    if args.method is not None:
        suite = dataclasses.replace(suite, options=suite.options | {"method": args.method})
    out = output_folder(args.out)
    ex = executor_kwargs(args)
    result = run_suite(
        suite,
        out=out,
        executor=ex.get("executor", "process"),
        workers=ex.get("workers"),
        chunk_runs=args.chunk_runs,
        progress=ex.get("progress"),
        max_hours=args.max_hours,
    )
    info = write_report(
        result, out, bootstrap=args.bootstrap, started=getattr(args, "started", started)
    )
    if args.json:
        print(json.dumps(info, indent=2))
        return 0
    s = info["summary"]
    print(
        f"{s['suite']}: {s['n_runs']} runs ({s['computed']} computed, {s['resumed']} read back) "
        f"in {s['wall_time_s']:.1f} s"
        + (f", {s['runs_per_s']:.1f} runs/s" if s["runs_per_s"] else "")
    )
    for row in info["fragility"]:
        if row["theta"] is None:
            print(f"  {row['measure']}: no fit — {row['message']}")
        else:
            print(
                f"  {row['measure']}: median {row['im_name']} = {row['theta']:.4g}, "
                f"β = {row['beta']:.3f}"
            )
    failed = result.runs[result.runs.status == "failed"]
    if len(failed):  # the solver's own words, not only a count in the files
        first = failed.iloc[0]
        print(
            f"  {len(failed)} run(s) failed (left out of the fits), e.g. {first['motion']} at "
            f"{s['measure']} = {first['im']:.4g}: {first['message']}"
        )
    print(f"files in {out}/")
    return 0
