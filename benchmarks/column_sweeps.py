"""Column spectra and suites: the command's wall time per run against the bare kernel's.

Run:  python -m benchmarks.column_sweeps [--repeat 3] [--workers 2] [--out FILE.json]

Cases, each timed `--repeat` times (median and range):

* ``spectrum``: ``multimass spectrum S1 --record examples/data/elcentro_1940_NS_15s.dat
  --units g --scale 0.4:2:17 --repeats 3`` (DD5, seed 0: 51 runs), the standard S1 El
  Centro spectrum of benchmarks/column_spectrum.py;
* ``suite``: ``multimass suite`` of S1 under Kobe 1995 and Loma Prieta 1989
  (examples/data/records) at PGA 0.2, 0.5 and 0.8 g, 4 draws (DD5: 24 runs), its
  report with ``--bootstrap 0``;

each with ``--executor serial`` and ``--executor process --workers 2``, in a fresh
process: the command's ``wall_time_s`` (its whole computing, from its start to its JSON:
imports, loading the kernels, starting the pool, the runs, the table, the files) and the
process's own wall time (the interpreter's start too). Against them, the *bare kernel*:
the same cells (scale, seed and restitution of each row of the command's table) as
prebuilt `multimass.engines.fast.column_runs.ColumnRun` objects, run in this process
(serial) or mapped in equal chunks on a warm 2-worker pool (process): the compiled runs
alone, nothing the command adds. The ratio command / kernel is what the command costs
beyond its runs.

* ``20-node``: `pulse_spectrum` of a uniform 20-node column
  (`multimass.bench.scaling.uniform_column`; its stiffest mode near 24 kHz) under
  cosine pulses ω = 8, 12, 16, 20 rad/s, 0.4 g, DD2, serial, with ``method="DOP853"``
  and ``method="auto"`` (`multimass.sweeps.method_choice`: the choice, its reason and
  its sample runs inside the auto spectrum's wall time); θ_max of the two compared.

With ``--against DIR`` (a source tree of the code before, e.g. ``git archive REV | tar -x
-C DIR``) each command also runs with that code in the same repeat, and its process's
wall time is reported beside (``before_process``, ``before_over_now``).

The machine is shared and noisy: compare medians and ratios within one run.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

__all__ = ["main", "command", "bare_serial", "bare_pool", "spectrum_args", "suite_file"]

ROOT = Path(__file__).resolve().parents[1]
RECORD = ROOT / "examples" / "data" / "elcentro_1940_NS_15s.dat"
RECORDS = ROOT / "examples" / "data" / "records"
T_FREE = {"spectrum": 5.0, "suite": 2.0}


def spectrum_args() -> list[str]:
    """The spectrum command's arguments (without the executor)."""
    return ["spectrum", "S1", "--record", str(RECORD), "--units", "g", "--scale", "0.4:2:17",
            "--repeats", "3", "--seed", "0", "--t-free", str(T_FREE["spectrum"])]  # fmt: skip


def suite_file(folder: Path) -> Path:
    """The suite's TOML, written into `folder`."""
    path = folder / "S1_two_records.toml"
    path.write_text(
        'name = "S1 under two records"\n[structure]\nspecimen = "S1"\n'
        f'[model]\nimpact = "DD5"\nt_free_s = {T_FREE["suite"]}\n'
        "[monte_carlo]\ndraws = 4\nseed = 11\n"
        '[intensity]\nmeasure = "pga"\nlevels = [0.2, 0.5, 0.8]\nunit = "g"\n'
        f'[[records]]\npath = "{RECORDS / "kobe_1995.dat"}"\nunits = "m/s2"\nname = "Kobe"\n'
        f'[[records]]\npath = "{RECORDS / "loma_prieta_1989.dat"}"\nunits = "m/s2"\n'
        'name = "LomaPrieta"\n'
    )
    return path


_CHILD = "import sys\nfrom multimass.cli import main\nsys.exit(main(sys.argv[1:]))\n"


def command(argv: list[str], source: Path | None = None) -> tuple[float, float, dict]:
    """(the command's wall_time_s, the process's wall time, its JSON) of one fresh run;
    `source`: the checkout the child imports multimass from (default: this one)."""
    env = os.environ | {"PYTHONPATH": str(source or ROOT), "MULTIMASS_QUIET": "1"}
    t0 = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-c", _CHILD, *argv, "--json", "--no-progress"],
        capture_output=True,
        text=True,
        check=True,
        env=env,
    )
    elapsed = time.perf_counter() - t0
    info = json.loads(done.stdout)
    wall = info["summary"]["wall_time_s"] if "summary" in info else info["wall_time_s"]
    return float(wall), elapsed, info


def _cells_of_spectrum(info: dict) -> list[tuple]:
    """(structure, excitation, impact, t_end, seed) of each row of a spectrum's JSON."""
    import multimass

    st, rec = multimass.column("S1"), multimass.read_record(RECORD, units="g")
    t_end = rec.duration + T_FREE["spectrum"]
    return [(st, rec.scaled(r["scale"]), "DD5", t_end, r["seed"]) for r in info["rows"]]


def _cells_of_suite(out: Path) -> list[tuple]:
    """The same, for each row of a suite's runs table."""
    import pandas as pd

    import multimass

    st = multimass.column("S1")
    recs = {
        "Kobe": multimass.read_record(RECORDS / "kobe_1995.dat", units="m/s2"),
        "LomaPrieta": multimass.read_record(RECORDS / "loma_prieta_1989.dat", units="m/s2"),
    }
    runs = pd.read_parquet(out / "runs.parquet")
    return [
        (st, recs[r.motion].scaled(r.scale), "DD5", recs[r.motion].duration + T_FREE["suite"],
         int(r.seed))
        for r in runs.itertuples()
    ]  # fmt: skip


def _column_runs(cells) -> list:
    """The `ColumnRun` of each cell, as `outcome_summary` prepares it (kernels loaded)."""
    from multimass.simulation import SimulationOptions, _prepare

    out = []
    for st, exc, impact, t_end, seed in cells:
        o = SimulationOptions.of(
            None, seed=seed, backend="compiled", progress=False, output_dt=None
        )
        out.append(_prepare(st, exc, impact, t_end, o).column_run())
    return out


def run_chunk(runs: list) -> int:
    """Run prebuilt column runs (a pool task); how many."""
    for r in runs:
        r.run()
    return len(runs)


def bare_serial(runs: list) -> float:
    """Seconds of the compiled runs alone, one after the other in this process."""
    t0 = time.perf_counter()
    run_chunk(runs)
    return time.perf_counter() - t0


def bare_pool(ex, runs: list, workers: int) -> float:
    """Seconds of the compiled runs alone on a warm pool: `workers` × 4 strided chunks."""
    k = 4 * workers
    chunks = [runs[i::k] for i in range(k)]
    t0 = time.perf_counter()
    assert sum(n for _, n in ex.map_unordered(run_chunk, chunks)) == len(runs)
    return time.perf_counter() - t0


def _twenty_node(method: str):
    from multimass import G
    from multimass.bench.scaling import uniform_column
    from multimass.sweeps.spectra import pulse_spectrum

    return pulse_spectrum(
        uniform_column(20), "cosine", [8.0, 12.0, 16.0, 20.0], 0.4 * G, impact="DD2",
        t_free=3.0, executor="serial", progress=False, method=method,
    )  # fmt: skip


def _stats(values) -> dict:
    return {
        "median": statistics.median(values),
        "min": min(values),
        "max": max(values),
        "values": [round(x, 5) for x in values],
    }


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", type=Path, default=None, help="write the JSON here too")
    ap.add_argument(
        "--against",
        type=Path,
        default=None,
        help="a source tree of the code before (e.g. `git archive REV | tar -x -C DIR`): "
        "each command runs with it too, in the same repeat, its process wall time beside",
    )
    a = ap.parse_args(argv)
    from multimass.engines.fast.compile import warm_up_columns, warm_up_contact
    from multimass.sweeps.executors import ProcessExecutor
    from multimass.sweeps.kernel_pools import preload_modules

    warm_up_contact(progress=False)
    warm_up_columns(progress=False)
    tmp = Path(tempfile.mkdtemp(prefix="column_sweeps_"))
    suite = suite_file(tmp)
    executors = {"serial": ["--executor", "serial"],
                 "process": ["--executor", "process", "--workers", str(a.workers)]}  # fmt: skip
    times: dict = {}
    auto_reason = None
    if a.against is not None:  # its kernels compiled or loaded before the clock
        command(spectrum_args() + ["--executor", "serial", "--scale", "1"], a.against)
    with ProcessExecutor(a.workers, preload=preload_modules(True, True)) as pool:
        pool.prepare(run_chunk)  # its forkserver preloads the kernels (as `run_jobs` does)
        warm = _column_runs(_cells_of_spectrum({"rows": [{"scale": 1.0, "seed": 0}]}))
        list(pool.map_unordered(run_chunk, [warm] * (2 * a.workers)))  # workers up, kernels in
        for i in range(a.repeat):
            for case in ("spectrum", "suite"):
                for ex, flags in executors.items():
                    if case == "spectrum":
                        wall, elapsed, info = command(spectrum_args() + flags)
                        runs = _column_runs(_cells_of_spectrum(info))
                    else:
                        out = tmp / f"suite_{i}_{ex}"
                        argv = ["suite", str(suite), "--out", str(out), "--bootstrap", "0"]
                        wall, elapsed, info = command(argv + flags)
                        runs = _column_runs(_cells_of_suite(out))
                    kernel = (
                        bare_serial(runs) if ex == "serial" else bare_pool(pool, runs, a.workers)
                    )
                    row = times.setdefault(f"{case} {ex}", {"runs": len(runs)})
                    if a.against is not None:  # the same command with the code before
                        argv = spectrum_args() if case == "spectrum" else [
                            "suite", str(suite), "--out", str(tmp / f"before_{i}_{ex}"),
                            "--bootstrap", "0"]  # fmt: skip
                        before = command(argv + flags, a.against)[1]
                        row.setdefault("before_process", []).append(before / len(runs))
                        row.setdefault("before_over_now", []).append(before / elapsed)
                    for key, value in (("command", wall), ("process", elapsed), ("kernel", kernel)):
                        row.setdefault(key, []).append(value / len(runs))
                    row.setdefault("ratio", []).append(wall / kernel)
            for method in ("DOP853", "auto"):
                sp = _twenty_node(method)
                row = times.setdefault(f"20-node {method}", {"runs": len(sp.table)})
                row.setdefault("spectrum_s", []).append(sp.wall_time_s)
                row.setdefault("theta_max", sp.table.theta_max.tolist())
                if method == "auto":
                    auto_reason = sp.options["method_choice"]["reason"]
            print(f"repeat {i + 1} of {a.repeat} done", file=sys.stderr)
    result = {"cases": {}, "auto_choice": auto_reason}
    for name, row in times.items():
        result["cases"][name] = {
            k: (_stats(v) if k not in ("runs", "theta_max") else v) for k, v in row.items()
        }
    dop, auto = times["20-node DOP853"], times["20-node auto"]
    result["20-node"] = {
        "speedup_median": statistics.median(dop["spectrum_s"])
        / statistics.median(auto["spectrum_s"]),
        "max_rel_theta_diff": float(
            np.max(np.abs(np.array(auto["theta_max"]) / np.array(dop["theta_max"]) - 1.0))
        ),
    }
    text = json.dumps(result, indent=1)
    print(text)
    print(_markdown(result), file=sys.stderr)
    if a.out is not None:
        a.out.write_text(text)
    return result


def _markdown(result: dict) -> str:
    """The figures as a Markdown table (ms per run: median [min–max])."""
    ms = lambda d: f"{1e3 * d['median']:.1f} [{1e3 * d['min']:.1f}–{1e3 * d['max']:.1f}]"
    lines = [
        "| sweep | runs | command ms/run | process ms/run | bare kernel ms/run | command / kernel |",
        "|---|---|---|---|---|---|",
    ]
    for name, row in result["cases"].items():
        if "command" in row:
            r = row["ratio"]
            lines.append(
                f"| {name} | {row['runs']} | {ms(row['command'])} | {ms(row['process'])} | "
                f"{ms(row['kernel'])} | {r['median']:.2f} [{r['min']:.2f}–{r['max']:.2f}] |"
            )
    for name, row in result["cases"].items():
        if "before_process" in row:
            b, r = row["before_process"], row["before_over_now"]
            lines.append(
                f"| {name}, the code before | {row['runs']} | | {ms(b)} | | before / now "
                f"{r['median']:.2f} [{r['min']:.2f}–{r['max']:.2f}] |"
            )
    for name in ("20-node DOP853", "20-node auto"):
        d = result["cases"][name]["spectrum_s"]
        lines.append(
            f"| {name} spectrum | 4 | {d['median']:.2f} s [{d['min']:.2f}–{d['max']:.2f}] | | | |"
        )
    lines.append(f"\nauto: {result['auto_choice']}")
    return "\n".join(lines)


if __name__ == "__main__":
    main()
