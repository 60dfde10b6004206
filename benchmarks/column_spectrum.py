"""The column spectrum of issue 15: full contact in closed form against integrated.

Run:  python -m benchmarks.column_spectrum [--repeat 3] [--workers 2] [--repeats 20]

S1 (paper 001) under the El Centro 1940 NS record of the README
(``examples/data/elcentro_1940_NS_15s.dat``, units g), 17 scale factors 0.4–2, each
repeated with random restitution (DD5, `job_seeds` of seed 0), 5 s of free rocking
after the record: `multimass.sweeps.spectra.record_spectrum` on the compiled path, two
ways in this process:

* ``integrate``: every phase with the compiled DOP853 pair (``full_contact="integrate"``,
  the compiled path before issue 15's change);
* ``exact``: full contact advanced in closed form between the record's samples
  (``full_contact="auto"``, the default; `multimass.fast._contact_kernel`).

Each repeat runs both on the same process pool size, alternating which goes first; the
ratio of a repeat is integrate's wall time over exact's. The outcomes cannot be equal
run for run: with DD5 a change in the last bits of one state moves θ_max by up to a
few per cent (issue 15's notes), so the two spectra are compared as distributions per
scale (overturned counts, mean θ_max of the completed runs, two-sample KS p-value),
and the deterministic DD2 spectrum (one run per scale) run for run. Prints one JSON
dict; timings depend on the machine and its load, compare medians.
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

__all__ = ["main", "spectra", "compare"]

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


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="timed repeats of each way")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=20, help="DD5 runs per scale")
    args = ap.parse_args(argv)
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
