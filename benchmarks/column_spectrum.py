"""The column spectrum: full contact in closed form against integrated.

Run:  python -m benchmarks.column_spectrum [--repeat 3] [--workers 2] [--repeats 20]

S1 (paper 001) under the El Centro 1940 NS record of the README
(``examples/data/elcentro_1940_NS_15s.dat``, units g), 17 scale factors 0.4–2, each
repeated with random restitution (DD5, `job_seeds` of seed 0), 5 s of free rocking
after the record: `multimass.sweeps.spectra.record_spectrum` on the compiled path, two
ways in this process:

* ``integrate``: every phase with the compiled DOP853 pair (``full_contact="integrate"``,
  the per-run compiled path);
* ``exact``: full contact advanced in closed form between the record's samples
  (``full_contact="auto"``, the default; `multimass.engines.fast._contact_kernel`).

Each repeat runs both on the same process pool size, alternating which goes first; the
ratio of a repeat is integrate's wall time over exact's. The outcomes cannot be equal
run for run: with DD5 a change in the last bits of one state moves θ_max by up to a
few per cent, so the two spectra are compared as distributions per
scale (overturned counts, mean θ_max of the completed runs, two-sample KS p-value),
and the deterministic DD2 spectrum (one run per scale) run for run. Prints one JSON
dict; timings depend on the machine and its load, compare medians.

A baseline (for instance commit d97163c, the code before whole compiled column runs) is another
installation of the package, timed in the same run by its own interpreter:

    python -m benchmarks.column_spectrum --against d97163c --repeat 5

``--against`` takes a git revision of this repository (installed once, with pip from
the package registries, in a virtual environment under ``~/.cache/multimass/bench``)
or the path of a Python interpreter that has the baseline installed.

Each repeat then runs the same default spectrum (``record_spectrum`` with its defaults,
as a user calls it) once under each interpreter, in fresh processes that first warm
up (load the compiled kernels, start the pool), alternating which goes first; the
ratio of a repeat is the baseline's wall time over this checkout's. ``--specimen``
takes S2, S3 or ``uniform20`` (`multimass.bench.scaling.uniform_column`: a uniform
20-node column like S1) instead of S1; ``--method`` gives this checkout's spectrum a
method (``auto``, ``exponential``; the baseline keeps its default, DOP853), for what a
user who asks for it waits:

    python -m benchmarks.column_spectrum --against 9d845f3 --specimen uniform20 \
        --method auto --repeats 2 --repeat 3
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time
from pathlib import Path

import numpy as np
import scipy.stats

__all__ = ["main", "spectra", "compare", "against", "baseline_python"]

RECORD = Path(__file__).resolve().parents[1] / "examples" / "data" / "elcentro_1940_NS_15s.dat"
SCALES = np.linspace(0.4, 2.0, 17)


def spectra(full_contact: str, repeats: int, workers: int, impact: str = "DD5"):
    """(wall time s, Spectrum) of the S1 El Centro spectrum with `full_contact`."""
    import multimass
    from multimass.sweeps.spectra import record_spectrum

    rec = multimass.read_record(RECORD, units="g")
    t = time.perf_counter()
    sp = record_spectrum(
        "S1",
        rec,
        SCALES,
        impact=impact,
        repeats=repeats,
        seed=0,
        executor="process" if workers > 1 else "serial",
        workers=workers,
        progress=False,
        full_contact=full_contact,
    )
    return time.perf_counter() - t, sp


def compare(a, b) -> dict:
    """Per scale: overturned counts, mean θ_max of completed runs, KS p-value; and the
    largest relative θ_max difference run for run."""
    rows = []
    ta, tb = a.table, b.table
    for s in SCALES:
        xa, xb = ta[np.isclose(ta.scale, s)], tb[np.isclose(tb.scale, s)]
        ca = xa[xa.status == "completed"].theta_max.to_numpy()
        cb = xb[xb.status == "completed"].theta_max.to_numpy()
        p = None
        if ca.size > 1 and cb.size > 1:
            p = float(scipy.stats.ks_2samp(ca, cb, method="asymp").pvalue)
        count = lambda x, st: int((x.status == st).sum())
        mean = lambda c: float(c.mean()) if c.size else None
        rows.append(
            {
                "scale": round(float(s), 3),
                "overturned": [count(xa, "overturned"), count(xb, "overturned")],
                "inaccurate": [count(xa, "inaccurate"), count(xb, "inaccurate")],
                "mean_theta_max": [mean(ca), mean(cb)],
                "ks_p": p,
            }
        )
    both = (ta.status == "completed") & (tb.status == "completed")
    rel = (ta.theta_max[both] - tb.theta_max[both]).abs() / ta.theta_max[both]
    return {
        "per_scale": rows,
        "same_status_runs": int((ta.status == tb.status).sum()),
        "runs": int(len(ta)),
        "max_rel_theta_diff": float(rel.max()) if both.any() else None,
        "median_rel_theta_diff": float(rel.median()) if both.any() else None,
    }


#: The columns ``--specimen`` takes: a bundled specimen's name, or ``uniform20``.
SPECIMENS = ("S1", "S2", "S3", "uniform20")

# One timed spectrum in a fresh process of either installation (its API as of d97163c;
# uniform20 as of 9d845f3): argv = record, workers, repeats, table path, specimen,
# method ("" for the default); prints the wall time.
_CHILD = """
import sys, time
import numpy as np
import multimass
from multimass.sweeps.spectra import record_spectrum
rec = multimass.read_record(sys.argv[1], units="g")
workers, repeats = int(sys.argv[2]), int(sys.argv[3])
st = sys.argv[5]
if st == "uniform20":
    from multimass.bench.scaling import uniform_column
    st = uniform_column(20)
kw = dict(seed=0, executor="process" if workers > 1 else "serial", workers=workers, progress=False)
kw |= dict(method=sys.argv[6]) if sys.argv[6] else {}
record_spectrum(st, rec, np.linspace(0.4, 2.0, 17)[:2], repeats=1, **kw)  # warm up
t = time.perf_counter()
sp = record_spectrum(st, rec, np.linspace(0.4, 2.0, 17), impact="DD5", repeats=repeats, **kw)
wall = time.perf_counter() - t
sp.table.to_pickle(sys.argv[4])
print(wall)
"""


def _child(
    python: str,
    workers: int,
    repeats: int,
    table: Path,
    env=None,
    specimen: str = "S1",
    method: str = "",
):
    """(wall time s, table) of one spectrum of `specimen` (`method`, or the default if
    empty) under the interpreter `python`, in the environment `env` (this process's if
    None)."""
    import subprocess

    import pandas as pd

    args = [python, "-c", _CHILD, str(RECORD), str(workers), str(repeats), str(table)]
    args += [specimen, method]
    out = subprocess.run(args, check=True, capture_output=True, text=True, cwd="/", env=env)
    return float(out.stdout.strip().splitlines()[-1]), pd.read_pickle(table)


def baseline_python(spec: str) -> str:
    """The interpreter of `spec`: a Python executable as given, or a git revision of this
    repository installed (once) in its own virtual environment."""
    import subprocess
    import sys

    if Path(spec).is_file():
        return spec
    repo = Path(__file__).resolve().parents[1]
    rev = subprocess.run(
        ["git", "-C", str(repo), "rev-parse", "--short=12", spec],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.strip()
    home = Path(os.path.expanduser("~")) / ".cache" / "multimass" / "bench" / rev
    python = home / "venv" / "bin" / "python"
    if not python.is_file():
        print(f"installing {spec} ({rev}) in {home} ...", file=sys.stderr)
        src = home / "src"
        src.mkdir(parents=True, exist_ok=True)
        archive = subprocess.run(
            ["git", "-C", str(repo), "archive", rev], check=True, capture_output=True
        ).stdout
        subprocess.run(["tar", "-x", "-C", str(src)], input=archive, check=True)
        subprocess.run([sys.executable, "-m", "venv", str(home / "venv")], check=True)
        subprocess.run([str(python), "-m", "pip", "install", "-q", str(src)], check=True)
    return str(python)


def against(
    python: str, repeat: int, workers: int, repeats: int, specimen: str = "S1", method: str = ""
) -> dict:
    """The default spectrum of `specimen` under the baseline interpreter `python` and under
    this one (with `method` if given)."""
    import sys
    import tempfile
    from types import SimpleNamespace

    times, ratios = {"baseline": [], "this": []}, []
    # the baseline runs without PYTHONPATH: a checkout on it would shadow its installation
    bare = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(repeat):
            ways = [("baseline", python, bare, ""), ("this", sys.executable, None, method)]
            got = {}
            for name, exe, env, how in ways if r % 2 == 0 else ways[::-1]:
                table = Path(tmp) / f"{name}.pkl"
                got[name] = _child(exe, workers, repeats, table, env, specimen, how)
            for name in times:
                times[name].append(got[name][0])
            ratios.append(got["baseline"][0] / got["this"][0])
    stat = lambda x: {"median": statistics.median(x), "min": min(x), "max": max(x)}
    tables = {k: SimpleNamespace(table=v[1]) for k, v in got.items()}
    return {
        "case": f"{specimen}, El Centro 15 s, DD5, {len(SCALES)} scales x {repeats} repeats, "
        + (f"method {method} here, the baseline's default" if method else "defaults"),
        "baseline": python,
        "workers": workers,
        "cpus": os.cpu_count(),
        "load_avg": os.getloadavg(),
        "wall_s": {k: stat(v) for k, v in times.items()},
        "ms_per_run": {
            k: 1e3 * statistics.median(v) / (len(SCALES) * repeats) for k, v in times.items()
        },
        "ratio": stat(ratios),
        "dd5": compare(tables["baseline"], tables["this"]),
    }


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="timed repeats of each way")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=20, help="DD5 runs per scale")
    ap.add_argument(
        "--against",
        metavar="REV_OR_PYTHON",
        help="time a baseline: a git revision (installed once) or a Python interpreter",
    )
    ap.add_argument("--specimen", choices=SPECIMENS, default="S1", help="with --against")
    ap.add_argument(
        "--method",
        choices=("auto", "exponential"),
        default="",
        help="with --against: this checkout's method (the baseline keeps DOP853)",
    )
    args = ap.parse_args(argv)
    if args.against:
        python = baseline_python(args.against)
        out = against(python, args.repeat, args.workers, args.repeats, args.specimen, args.method)
        print(json.dumps(out, indent=1))
        return out
    spectra("auto", 1, args.workers)  # warm: compile and start the pool's imports once
    times = {"integrate": [], "exact": []}
    ratios, last = [], {}
    for r in range(args.repeat):
        order = ("integrate", "auto") if r % 2 == 0 else ("auto", "integrate")
        got = {}
        for how in order:
            got[how] = spectra(how, args.repeats, args.workers)
        times["integrate"].append(got["integrate"][0])
        times["exact"].append(got["auto"][0])
        ratios.append(got["integrate"][0] / got["auto"][0])
        last = got
    dd2 = {how: spectra(how, 1, args.workers, impact="DD2")[1] for how in ("integrate", "auto")}
    stat = lambda x: {"median": statistics.median(x), "min": min(x), "max": max(x)}
    runs = len(SCALES) * args.repeats
    out = {
        "case": f"S1, El Centro 15 s, DD5, {len(SCALES)} scales x {args.repeats} repeats",
        "workers": args.workers,
        "cpus": os.cpu_count(),
        "load_avg": os.getloadavg(),
        "wall_s": {k: stat(v) for k, v in times.items()},
        "ms_per_run": {k: 1e3 * statistics.median(v) / runs for k, v in times.items()},
        "ratio": stat(ratios),
        "dd5": compare(last["integrate"][1], last["auto"][1]),
        "dd2": compare(dd2["integrate"], dd2["auto"]),
    }
    print(json.dumps(out, indent=1))
    return out


if __name__ == "__main__":
    main()
