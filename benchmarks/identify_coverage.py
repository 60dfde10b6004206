"""Coverage of the identification estimators on synthetic tests they know nothing of.

Run:  python -m benchmarks.identify_coverage [--n 50] [--workers 2] [--seed 0]
          [--out coverage-out] [--specimens S1,S2,S3] [--family DD] [--calibrate-every 5]
          [--records examples/data/records | --no-records] [--resume] [--report-only]

N synthetic traces per specimen (`multimass.bench.coverage_draws`: C_p within ±40 % of
paper 001 Table 2's, ζ1 and ζ2 within ±50 % of the specimen's, corner means ±0.03 and
σ_r 0.01–0.04 per-impact restitution, release 0.05–0.15 rad, 100–1000 Hz, noise
1–5 % and bias of each channel's peak, clock offset; every fifth trace table motion
from a window of a real record), `multimass.identify.restitution` on each and
`multimass.identify.calibrate` on every `--calibrate-every`-th, given only the specimen
and the impact model family. Each case is appended to ``OUT/results.jsonl`` when done
(an interrupted run keeps them; ``--resume`` goes on, ``--report-only`` re-reports);
then ``OUT/estimates.csv`` (+ ``.parquet``), ``cases.csv``, ``summary.json``,
``coverage.md`` and three PNG figures (`multimass.bench.coverage_report`).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

import multimass
from multimass import FreeRelease
from multimass.bench.coverage import CoverageConfig, run_coverage
from multimass.bench.coverage_report import write_report

__all__ = ["main"]

RECORDS = Path(__file__).resolve().parents[1] / "examples" / "data" / "records"


def _commit() -> str:
    """The checkout's commit (short), with "+changes" when the work tree differs."""
    root = Path(__file__).resolve().parents[1]
    try:
        head = subprocess.run(
            ["git", "-C", str(root), "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "-C", str(root), "status", "--porcelain", "--", "multimass"],
            capture_output=True,
            text=True,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return head + ("+changes" if dirty else "")  # fmt: skip


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=50, help="synthetic traces per specimen (50)")
    ap.add_argument("--workers", type=int, default=1, help="processes (1)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", type=Path, default=Path("coverage-out"))
    ap.add_argument("--specimens", default="S1,S2,S3")
    ap.add_argument("--family", default="DD", choices=("DD", "CIM"))
    ap.add_argument("--calibrate-every", type=int, default=5,
                    help="run calibrate on every k-th trace of each specimen (0: never)")  # fmt: skip
    ap.add_argument("--records", type=Path, default=RECORDS, help="folder of the record files")
    ap.add_argument("--no-records", action="store_true", help="free vibration only")
    ap.add_argument("--resume", action="store_true", help="keep the cases already in OUT")
    ap.add_argument("--report-only", action="store_true", help="re-report OUT; run nothing")
    a = ap.parse_args(argv)
    facts = {}
    if not a.report_only:
        cfg = CoverageConfig(
            n=a.n, specimens=tuple(a.specimens.split(",")), seed=a.seed, family=a.family,
            calibrate_every=a.calibrate_every, workers=a.workers,
            records=None if a.no_records else str(a.records), extra={"commit": _commit()},
        )  # fmt: skip
        multimass.simulate("S1", FreeRelease(theta0=0.05), "DD2", 0.2, backend="compiled",
                           progress=False)  # compile (or load) the kernels first  # fmt: skip
        t0 = time.perf_counter()
        run = run_coverage(cfg, a.out, resume=a.resume,
                           say=lambda m: print(m, file=sys.stderr, flush=True))  # fmt: skip
        facts = {"command": "python -m benchmarks.identify_coverage " + " ".join(
            sys.argv[1:] if argv is None else argv)}  # fmt: skip
        print(f"{run['cases_run']} cases in {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    res = write_report(a.out, facts)
    print((a.out / "coverage.md").read_text(encoding="utf-8"))
    return res


if __name__ == "__main__":
    main()
