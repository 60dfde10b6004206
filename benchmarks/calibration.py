"""Calibration of S1–S3 against synthetic free-vibration traces.

Run:  python -m benchmarks.calibration [--specimens S1,S2,S3] [--seeds 1,2,3] [--history 9]
                                        [--impact DD2] [--fit r_er,r_el,cp] [--json FILE]

For each specimen and seed: a synthetic trace of paper 001 Section 4.3's large free
vibration (0.11 rad release, 10 s, DD2, 200 Hz, noise 2 % of each channel's peak,
bias, clock offset; `multimass.identify.synthetic_trace`), then
`multimass.identify.calibrate` from a start 20 % off (restitution means 20 % low, C_p
20 % high). Prints, per fitted restitution mean, the value ± std against three
truths — the corner's nominal mean (what the draws scatter about), the mean of every
drawn value the trace used (the truth file's r_mean_*), and the mean of the drawn
values of the impacts in the window fitted — and C_p against 1750; the status, the
residual scales in units of the noise, and the wall time (the kernels compiled
beforehand, so the first case does not pay for it). Times depend on the machine and
its load.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

import multimass
from multimass import FreeRelease
from multimass.identify import synthetic_trace
from multimass.identify.calibration import calibrate

__all__ = ["main", "one"]

CP = 1750.0  # paper 001 Table 2, DD2


def one(spec: str, seed: int, impact: str, fit, history: int) -> dict:
    """Calibrate one synthetic trace; a JSON-ready row of the results."""
    syn = synthetic_trace(spec, FreeRelease(theta0=0.11), impact, 10.0, seed=seed)
    sp = multimass.from_specimen(spec).specimen
    start = {"r_er": 0.8 * sp.r_right, "r_el": 0.8 * sp.r_left}
    if "cp" in fit:
        start["cp"] = 1.2 * CP
    wall = time.perf_counter()
    cal = calibrate(syn.trace, spec, impact, fit=fit, start=start, history=history, progress=False)
    wall = time.perf_counter() - wall
    truth, label = syn.truth, next(iter(cal.nuisance))
    drawn = [i["r"] for i in truth["impacts"]]
    row = {"specimen": spec, "seed": seed, "status": cal.status, "seconds": wall,
           "simulations": cal.n_simulations}  # fmt: skip
    for name, corner in (("r_er", "right"), ("r_el", "left")):
        if name not in cal.parameters:
            continue
        p = cal.parameters[name]
        window = [  # None: a Dirac-delta force that never switched on (no r drawn)
            drawn[i["index"]]
            for i in cal.nuisance[label]["impacts"]
            if i["corner"] == corner and drawn[i["index"]] is not None
        ]
        row[name] = {
            "value": p["value"], "std": p["std"], "constrained": p["constrained"],
            "nominal": truth["restitution"]["means"][corner],
            "drawn_all": truth[f"r_mean_{corner}"],
            "n_all": sum(i["corner"] == corner for i in truth["impacts"]),
            "drawn_window": float(np.mean(window)) if window else None,
            "n_window": len(window),
        }  # fmt: skip
    if "cp" in cal.parameters:
        p = cal.parameters["cp"]
        row["cp"] = {"value": p["value"], "std": p["std"], "error_rel": p["value"] / CP - 1.0}
    row["residual_over_noise"] = {
        key.split(":")[1]: r["scale"] / truth["noise"]["std"][key.split(":")[1]]
        for key, r in cal.residuals.items()
    }
    row["t_offset_error_s"] = cal.nuisance[label]["t_offset"] - truth["t_offset"]
    return row


def _print(row: dict) -> None:
    print(
        f"{row['specimen']} seed {row['seed']}: {row['status']}, {row['seconds']:.1f} s, "
        f"{row['simulations']} simulations, t_offset error {1e3 * row['t_offset_error_s']:+.2f} ms"
    )
    for name in ("r_er", "r_el"):
        if name in row:
            r = row[name]
            print(
                f"  {name} {r['value']:.4f} ± {r['std']:.4f} | nominal {r['nominal']:.3f} "
                f"({r['value'] - r['nominal']:+.4f}) | drawn, all {r['n_all']} impacts "
                f"{r['drawn_all']:.4f} ({r['value'] - r['drawn_all']:+.4f}) | drawn, the "
                f"{r['n_window']} in the window {r['drawn_window']:.4f} "
                f"({r['value'] - r['drawn_window']:+.4f})"
            )
    if "cp" in row:
        c = row["cp"]
        print(f"  cp {c['value']:.1f} ± {c['std']:.1f} ({100 * c['error_rel']:+.2f} % of {CP:g})")
    res = ", ".join(f"{k} {v:.2f}" for k, v in row["residual_over_noise"].items())
    print(f"  residual RMS / noise: {res}")


def main(argv=None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--specimens", default="S1,S2,S3")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--impact", default="DD2")
    ap.add_argument("--fit", default="r_er,r_el,cp")
    ap.add_argument("--history", type=int, default=9)
    ap.add_argument("--json", default=None, help="also write the rows to this JSON file")
    args = ap.parse_args(argv)
    fit = tuple(args.fit.split(","))
    multimass.simulate("S1", FreeRelease(theta0=0.05), "DD2", 0.2, backend="compiled",
                       progress=False)  # compile (or load) the kernels first  # fmt: skip
    rows = []
    for spec in args.specimens.split(","):
        for seed in (int(s) for s in args.seeds.split(",")):
            rows.append(one(spec, seed, args.impact, fit, args.history))
            _print(rows[-1])
    if args.json:
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump(rows, fh, indent=1)
    return rows


if __name__ == "__main__":
    main()
