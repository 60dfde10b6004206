"""``multimass bench``: speed and accuracy of every method (`multimass.bench`)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

__all__ = ["register", "run"]

#: keys printed first (and always) in the JSON object
HEADLINE = ("speedup_single", "speedup_map", "scaling_2_workers", "peak_error_rad")
ROW_KEYS = (
    "model",
    "method",
    "level_name",
    "tolerance",
    "error",
    "event_time_error_s",
    "energy_error",
    "wall_time_s",
    "n_rhs",
    "failure",
)


def register(sub) -> None:
    p = sub.add_parser(
        "bench",
        help="work-precision charts, failure maps and speed targets of every method",
        description="Run every model (rigid block, S1 with CIM and DD2, the LCP block, NSCD) with "
        "every method (solve_ivp RK45/DOP853/Radau/BDF/LSODA, the compiled path, "
        "Newmark + Newton-Raphson, Moreau-Jean) at several tolerances or time steps "
        "against tight references; detect where methods fail; measure the speed "
        "targets. Writes bench.json, CSV/Markdown tables and PNG charts to --out. "
        "Full run ~10 min on 2 cores; --quick ~2.5 min (targets not judged).",
    )
    size = p.add_mutually_exclusive_group()
    size.add_argument(
        "--quick",
        action="store_true",
        help="fewer tolerances, shorter runs, a 30x30 map (~2.5 min; targets shown, not judged)",
    )
    size.add_argument(
        "--smoke",
        action="store_true",
        help="a tiny configuration that checks the pipeline (seconds; numbers meaningless)",
    )
    p.add_argument("--out", type=Path, required=True, help="folder for the JSON, tables and charts")
    p.add_argument(
        "--scaling",
        action="store_true",
        help="instead: how cost grows, log-log with fitted exponents — map cost against cells "
        "(brute force, adaptive) and workers, column cost against nodes N (scaling.json, "
        "scaling.md, scaling_*.png; full ~12 min on 2 cores, --quick ~2.5 min, --smoke ~10 s)",
    )
    p.add_argument(
        "--coverage",
        action="store_true",
        help="instead: how far restitution and calibrate are from the truth of synthetic tests "
        "whose C_p, damping, restitution, release, sampling, noise, bias and clock they are not "
        "told, and how often their 95 %% intervals hold it (coverage.md, summary.json, "
        "estimates.csv, coverage_*.png; full 10 traces per specimen S1-S3 ~15 min on 2 cores, "
        "--quick 2 per specimen ~3 min, --smoke one S1 trace ~30 s); "
        "python -m benchmarks.identify_coverage runs the large version",
    )
    p.add_argument(
        "--command",
        action="store_true",
        help="instead: `multimass stability` on a 100 x 100 map as a subprocess, start to exit, "
        "against the batched kernel on the same cells, and the solve_ivp path against the "
        "compiled one on a 20 x 20 map, 3 repeats (command_speed.json; ~2 min; --quick one "
        "repeat, --smoke a 10 x 10 map); python -m benchmarks.stability_command runs it too",
    )
    p.add_argument(
        "--records",
        type=Path,
        default=None,
        help="with --coverage: folder of the record files (elcentro_1940_NS.dat, kobe_1995.dat, "
        "northridge_1994.dat, loma_prieta_1989.dat) for the table-motion traces; default none "
        "(free vibration only)",
    )
    p.add_argument(
        "--json",
        action="store_true",
        help="print the result as JSON (targets, then one row per model, method and level)",
    )
    p.set_defaults(func=run)


def run(args) -> int:
    from multimass.bench.config import preset
    from multimass.bench.run import run_bench

    from ._output import output_folder

    size = "smoke" if args.smoke else "quick" if args.quick else "full"
    if getattr(args, "coverage", False):
        if getattr(args, "scaling", False):
            print("multimass bench: give --coverage or --scaling, not both", file=sys.stderr)
            return 2
        return _run_coverage(size, output_folder(args.out), args.json, args.records)
    if args.records is not None:
        print("multimass bench: --records goes with --coverage", file=sys.stderr)
        return 2
    if getattr(args, "scaling", False):
        return _run_scaling(size, output_folder(args.out), args.json)
    if getattr(args, "command", False):
        return _run_command_speed(size, output_folder(args.out), args.json)
    cfg = preset(size)
    quiet = args.json
    res = run_bench(
        cfg,
        output_folder(args.out),
        progress=None if quiet else (lambda m: print(m, file=sys.stderr, flush=True)),
    )
    if args.json:
        rows = [{k: r.get(k) for k in ROW_KEYS} for r in res["rows"] + res["stiffness"]["rows"]]
        head = {k: res[k] for k in HEADLINE}
        rest = {k: v for k, v in res.items() if k not in HEADLINE + ("rows",)}
        print(json.dumps({**head, "rows": rows, **rest}, indent=1))
        return 0
    t = res["targets"]["pass"]
    verdict = {True: "pass", False: "FAIL", None: "not judged: smaller case than the target's"}
    print(f"bench ({cfg.name}) in {res['wall_time_s']:.0f} s -> {args.out}")
    for key, fmt, rule in (
        ("speedup_single", "8.1f", ">= 30"),
        ("peak_error_rad", "8.1e", "<= 1e-6"),
        ("speedup_map", "8.1f", ">= 50"),
        ("scaling_2_workers", "8.2f", ">= 1.7"),
    ):
        print(f"  {key:<17} {res[key]:{fmt}}   ({rule}: {verdict[t[key]]})")
    print(
        f"  {len(res['failures'])} failing runs: see {args.out / 'failures.md'}; charts: "
        + ", ".join(res["charts"])
    )
    return 0


def _run_scaling(size: str, out: Path, as_json: bool) -> int:
    from multimass.bench.config import scaling_preset
    from multimass.bench.scaling import run_scaling

    say = None if as_json else (lambda m: print(m, file=sys.stderr, flush=True))
    res = run_scaling(scaling_preset(size), out, progress=say)
    if as_json:
        print(json.dumps(res, indent=1))
        return 0
    print(f"bench --scaling ({size}) in {res['wall_time_s']:.0f} s -> {out}")
    for part, label in (
        ("cells", "map vs cells"),
        ("workers", "map vs workers"),
        ("nodes", "column vs N"),
    ):
        for key, fit in res[part]["fits"].items():
            b = "—" if fit["exponent"] is None else f"{fit['exponent']:6.2f}"
            print(f"  {label:<15} {key:<24} exponent {b}")
    print(f"  tables: {out / 'scaling.md'}; charts: " + ", ".join(res["charts"]))
    return 0


#: --coverage sizes: traces per specimen, specimens, calibrate on every k-th (0: never)
COVERAGE_SIZES = {"smoke": (1, ("S1",), 0), "quick": (2, ("S1", "S2", "S3"), 0),
                  "full": (10, ("S1", "S2", "S3"), 5)}  # fmt: skip


def _run_coverage(size: str, out: Path, as_json: bool, records) -> int:
    from multimass.bench.coverage import CoverageConfig, run_coverage
    from multimass.bench.coverage_report import write_report

    n, specimens, every = COVERAGE_SIZES[size]
    say = None if as_json else (lambda m: print(m, file=sys.stderr, flush=True))
    cfg = CoverageConfig(n=n, specimens=specimens, calibrate_every=every,
                         records=None if records is None else str(records))  # fmt: skip
    run = run_coverage(cfg, out, say=say)  # a bad --records: InputError, one line from main
    res = write_report(out, {"command": f"multimass bench --coverage ({size})"})
    if as_json:
        print(json.dumps(res, indent=1))
        return 0
    print(
        f"bench --coverage ({size}): {run['cases_run']} traces in {run['wall_time_s']:.0f} s -> {out}"
    )
    print((out / "coverage.md").read_text(encoding="utf-8"))
    return 0


#: --command sizes: (the command's map n, the solve_ivp map n, repeats)
_COMMAND_SIZES = {"full": (100, 20, 3), "quick": (100, 20, 1), "smoke": (10, 4, 1)}


def _run_command_speed(size: str, out: Path, as_json: bool) -> int:
    from multimass.bench.command_speed import measure
    from multimass.bench.run import json_safe

    n, small_n, repeats = _COMMAND_SIZES[size]
    say = None if as_json else (lambda m: print(m, file=sys.stderr, flush=True))
    res = json_safe(measure(n, small_n, repeats, progress=say))
    (out / "command_speed.json").write_text(json.dumps(res, indent=1))
    if as_json:
        print(json.dumps(res, indent=1))
        return 0
    r, s = res["command_over_kernel"], res["small_map"]["scipy_over_compiled"]
    f = res["floor_over_kernel"]
    print(
        f"bench --command ({size}) -> {out / 'command_speed.json'}\n"
        f"  command / kernel per simulation  {r['median']:.2f} [{r['min']:.2f}-{r['max']:.2f}]"
        f"  (target <= {res['targets']['command_over_kernel']}; floor: the kernel, the "
        f"interpreter, numpy and numba's start-up alone {f['median']:.2f})\n"
        f"  solve_ivp / compiled ({small_n}x{small_n})  {s['median']:.0f}x "
        f"[{s['min']:.0f}-{s['max']:.0f}]  (target >= {res['targets']['scipy_over_compiled']:.0f}; "
        f"identical outcomes: {res['small_map']['identical_outcomes']})"
    )
    return 0
