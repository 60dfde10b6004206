"""The exponential rocking integrator against DOP853 on the compiled path: work and precision.

Run:  python -m benchmarks.exponential_rocking [--repeat 3] [--rtols 1e-6 1e-8 1e-10]
      [--quick] [--chart docs/bench/exponential_wp.png] [--compile] [--no-scipy]

Cases (each a whole compiled run, `multimass.simulation.outcome_summary`, the
path of spectra and suites): S1, S2, S3 of paper 001 released from 0.11 rad (DD2,
10 s) and under El Centro 1940 NS (``../shared/data/ground_motions`` beside the repository, units g,
DD5 with seed 3, 20 s: the issue's case), a uniform 20-node column like S1 released
(`multimass.bench.scaling.uniform_column`) and a near-rigid column (S1 with E_s,
K_rot, K_fp × 100, `multimass.bench.cases.scaled_column`) released. Each case runs at
each rtol (atol = rtol / 100, max_step = inf for both methods: DOP853 is held by
stability anyway, and the default 5 ms would cap the exponential method's steps)
with ``method="DOP853"`` and ``method="exponential"``, `--repeat` times, alternating
which goes first; the ratio of a repeat is DOP853's wall time over the exponential's
(> 1: the exponential method is faster). Errors are against the compiled DOP853 at
rtol 1e-12, atol 1e-14: θ_max, every half-cycle's peak and the impact times (when
both runs have as many) and the ledger's closure; they come from `simulate_outcome` (the
same kernels, bit for bit: tests/multimass/test_fast_exponential.py).

Beside them, the solve_ivp path (``backend="scipy"``: SciPy's DOP853 on the same
equations, its events located by solve_ivp) at the same tolerances, timed `--scipy-repeat`
times (once by default: a run takes seconds to a minute, and the compiled methods'
ratio to it is what the chart shows), its errors against the same reference.

The machine is shared and noisy (2 cores, other jobs): compare medians and ratios
within one run, never absolute times across runs.

The physical limit (the cost floor of a run at the record's own time scale) is
printed beside: an exponential step costs 5 + 1 right-hand sides (O(N²) each: K u,
C u̇; 3 more when it starts at a record sample) and 14 transforms in and out of the
modes (complex (N+2) × (2N+2) products), about 6·4N² + 14·4(N+2)(2N+2) flops; a
record sampled at 20 ms needs at least one step per sample while the column rocks.
With `--compile` the cold compile time of each kernel group is measured in a fresh
process with an empty cache.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

__all__ = ["main", "cases", "measure", "physical_limit", "compile_times"]

#: ../shared beside the repository (the read-only data of the tests)
SHARED = Path(__file__).resolve().parents[2] / "shared"
ELCENTRO = str(SHARED / "data" / "ground_motions" / "elcentro_1940_NS.dat")
METHODS = ("DOP853", "exponential")
#: The solve_ivp path's series (SciPy's DOP853, ``backend="scipy"``).
SCIPY = "solve_ivp"
REF = dict(method="DOP853", rtol=1e-12, atol=1e-14)


def cases(quick: bool = False) -> list[tuple]:
    """(name, structure, excitation, impact, t_end, seed) of the benchmark's runs."""
    import multimass
    from multimass import FreeRelease
    from multimass.bench.cases import scaled_column
    from multimass.bench.scaling import uniform_column

    rec = multimass.read_record(ELCENTRO, units="g")
    out = []
    for name in ("S1",) if quick else ("S1", "S2", "S3"):
        st = multimass.column(name)
        out.append((f"{name} release DD2", st, FreeRelease(0.11), "DD2", 10.0, None))
        out.append((f"{name} El Centro DD5", st, rec, "DD5", 20.0, 3))
    if not quick:
        out.append(("20-node release DD2", uniform_column(20), FreeRelease(0.11), "DD2", 5.0, None))
        out.append(("S1 x100 stiff release DD2", scaled_column(100.0), FreeRelease(0.11), "DD2",
                    5.0, None))  # fmt: skip
    return out


def _run(case, lean: bool, **kw):
    from multimass import simulate_outcome
    from multimass.simulation import outcome_summary

    _, st, exc, impact, t_end, seed = case
    opts = dict(backend="compiled", max_step=math.inf, seed=seed) | kw
    if lean:
        return outcome_summary(st, exc, impact, t_end, **opts)
    return simulate_outcome(st, exc, impact, t_end, output_dt=None, progress=False, **opts)


def _impacts(r) -> np.ndarray:
    return np.array([e.time for e in r.events if e.kind == "impact"])


def _peak_error(r, ref) -> float | None:
    """Largest |peak − reference| over the half-cycles' peaks (rad), None if the runs
    do not have the same number of peaks."""
    a, b = np.asarray(r.peaks), np.asarray(ref.peaks)
    return float(np.abs(a - b).max()) if a.size == b.size and a.size else None


def _errors(r, ref) -> dict:
    """θ_max, peak, impact-time and ledger errors of run `r` against the reference."""
    a, b = _impacts(r), _impacts(ref)
    return dict(
        n_rhs=int(r.n_rhs),
        theta_max_error=abs(r.theta_max - ref.theta_max),
        peak_error=_peak_error(r, ref),
        impact_time_error=float(np.abs(a - b).max()) if a.size == b.size and a.size else None,
        impacts=(int(a.size), int(b.size)),
        energy_balance_error=float(r.energy_balance_error),
        status=r.status,
    )


def measure(case, rtols, repeat: int, scipy_repeat: int = 1) -> list[dict]:
    """Rows of one case: per rtol and method, wall times (ms), RHS calls and errors
    (with `scipy_repeat` > 0, the solve_ivp path's row too)."""
    ref = _run(case, False, **REF)
    rows = []
    for rtol in rtols:
        tol = dict(rtol=rtol, atol=rtol * 1e-2)
        for method in METHODS:  # compile / load and warm up outside the clock
            _run(case, True, method=method, **tol)
        times = {m: [] for m in METHODS}
        for i in range(repeat):
            for method in METHODS if i % 2 == 0 else METHODS[::-1]:
                t0 = time.perf_counter()
                _run(case, True, method=method, **tol)
                times[method].append(1e3 * (time.perf_counter() - t0))
        ratios = [d / e for d, e in zip(times["DOP853"], times["exponential"])]
        for method in METHODS:
            r = _run(case, False, method=method, **tol)
            rows.append(
                dict(
                    case=case[0],
                    rtol=rtol,
                    method=method,
                    ms_median=statistics.median(times[method]),
                    ms_min=min(times[method]),
                    ms_max=max(times[method]),
                    dop853_over_exponential=statistics.median(ratios),
                    ratio_spread=(min(ratios), max(ratios)),
                )
                | _errors(r, ref)
            )
        if scipy_repeat > 0:
            ms = []
            for _ in range(scipy_repeat):
                t0 = time.perf_counter()
                r = _run(case, False, method="DOP853", backend="scipy", **tol)
                ms.append(1e3 * (time.perf_counter() - t0))
            dop = statistics.median(times["DOP853"])
            rows.append(
                dict(
                    case=case[0],
                    rtol=rtol,
                    method=SCIPY,
                    ms_median=statistics.median(ms),
                    ms_min=min(ms),
                    ms_max=max(ms),
                    over_compiled_dop853=statistics.median(ms) / dop,
                    over_exponential=statistics.median(ms)
                    / statistics.median(times["exponential"]),
                )
                | _errors(r, ref)
            )
    return rows


def physical_limit(case, rtol: float) -> dict:
    """The exponential method's flops per step, the steps it took and the floor of one
    step per record sample while rocking, beside the measured time per step."""
    _, st, exc, impact, t_end, seed = case
    n = st.n
    nm, k = 2 * n + 2, n + 2
    flops = 6 * 4 * n * n + 14 * 4 * k * nm
    r = _run(case, False, method="exponential", rtol=rtol, atol=rtol * 1e-2)
    rocking = 0.0
    t_prev, phase = 0.0, 0
    for e in r.events:  # time spent rocking, from the transitions
        if phase != 0:
            rocking += e.time - t_prev
        t_prev, phase = e.time, (e.phase_after or 0)
    if phase != 0:
        rocking += t_end - t_prev
    dt = getattr(exc, "dt", None)
    floor_steps = rocking / dt if dt else None
    return dict(
        case=case[0],
        nodes=n,
        flops_per_step=flops,
        rocking_time_s=rocking,
        steps_taken_max=r.n_rhs / 6.0,  # RHS calls / 6 (full contact in closed form: none)
        floor_steps_one_per_sample=floor_steps,
        floor_ms_at_1_gflops=(floor_steps * flops * 1e-6) if floor_steps else None,
    )


def compile_times() -> dict:
    """Cold compile time (s) of each kernel group, in a fresh process, empty cache."""
    code = (
        "import time, json\n"
        "from multimass.engines.fast import warm_up, warm_up_contact, warm_up_exponential\n"
        "from multimass.engines.fast.compile import warm_up_columns\n"
        "out = {}\n"
        "for f in (warm_up, warm_up_contact, warm_up_exponential, warm_up_columns):\n"
        "    out[f.__name__] = f(progress=False).seconds\n"
        "print(json.dumps(out))\n"
    )
    with tempfile.TemporaryDirectory() as cache:
        env = os.environ | {"NUMBA_CACHE_DIR": cache, "MULTIMASS_QUIET": "1"}
        got = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    return json.loads(got.stdout.strip().splitlines()[-1])


def chart(rows, path) -> None:
    """Work-precision chart: wall time against the largest peak error, one panel per
    case (a run whose peaks do not pair with the reference's is left out)."""
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FormatStrFormatter, NullFormatter

    names = list(dict.fromkeys(r["case"] for r in rows))
    cols = min(4, len(names))
    fig, axes = plt.subplots(
        math.ceil(len(names) / cols), cols, figsize=(3.6 * cols, 3.0 * math.ceil(len(names) / cols))
    )
    for ax, name in zip(np.atleast_1d(axes).ravel(), names):
        for method, mark in zip(METHODS + (SCIPY,), ("o-", "s--", "^:")):
            sel = [
                r
                for r in rows
                if r["case"] == name and r["method"] == method and r["peak_error"] is not None
            ]
            err = [max(r["peak_error"], 1e-16) for r in sel]
            label = f"{method} (compiled)" if method in METHODS else "solve_ivp (DOP853)"
            ax.loglog(err, [r["ms_median"] for r in sel], mark, label=label)
            for r, e in zip(sel, err):
                ax.annotate(f"{r['rtol']:.0e}", (e, r["ms_median"]), fontsize=6)
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.yaxis.set_major_formatter(FormatStrFormatter("%g"))
        lo, hi = ax.get_ylim()  # minor labels only within a decade (else they crowd)
        ax.yaxis.set_minor_formatter(FormatStrFormatter("%g") if hi < 10 * lo else NullFormatter())
        ax.set_title(name, fontsize=8)
        ax.set_xlabel("largest |peak − reference| (rad)", fontsize=7)
        ax.set_ylabel("wall time per run (ms)", fontsize=7)
        ax.tick_params(labelsize=6, which="both")
    np.atleast_1d(axes).ravel()[0].legend(fontsize=7)
    for ax in np.atleast_1d(axes).ravel()[len(names) :]:
        ax.axis("off")
    fig.suptitle("Whole runs: the compiled DOP853 and exponential rocking integrator, and "
                 "solve_ivp (labels: rtol; shared noisy machine, medians)", fontsize=8)  # fmt: skip
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main(argv=None) -> dict:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--rtols", type=float, nargs="+", default=[1e-6, 1e-8, 1e-10])
    p.add_argument("--quick", action="store_true", help="S1 only")
    p.add_argument("--chart", default=None, help="PNG of the work-precision chart")
    p.add_argument("--compile", action="store_true", help="also the cold compile times")
    p.add_argument("--scipy-repeat", type=int, default=1, help="timed solve_ivp runs (1)")
    p.add_argument("--no-scipy", action="store_true", help="without the solve_ivp path")
    a = p.parse_args(argv)
    os.environ.setdefault("MULTIMASS_QUIET", "1")
    from multimass.engines.fast import warm_up, warm_up_contact, warm_up_exponential
    from multimass.engines.fast.compile import warm_up_columns

    for f in (warm_up, warm_up_contact, warm_up_exponential, warm_up_columns):
        f(progress=False)
    out = {"rows": [], "limit": []}
    for case in cases(a.quick):
        out["rows"] += measure(case, a.rtols, a.repeat, 0 if a.no_scipy else a.scipy_repeat)
        out["limit"].append(physical_limit(case, 1e-8))
        print(json.dumps([r for r in out["rows"] if r["case"] == case[0]]), file=sys.stderr)
    if a.compile:
        out["compile_s"] = compile_times()
    if a.chart:
        chart(out["rows"], a.chart)
    print(json.dumps(out, indent=1))
    return out


if __name__ == "__main__":
    main()
