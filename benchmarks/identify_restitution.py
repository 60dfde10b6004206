"""Restitution identification on synthetic S1–S3 free-vibration traces (issue 14, item 1).

0.11 rad release, 10 s, 200 Hz, noise 2 % of each channel's peak, seeds 1–3; the
model fitted is the trace's own family (DD for DD2, CIM for CIM). The truth of each
impact is the r the run drew (`synthetic_trace`; a Dirac-delta force that never
switched on is r = 1: no energy lost); its half-cycles are the largest |θ| of the
simulation between consecutive impacts (the truth's own `theta_before`/`theta_after`
are the nearest local peaks, which can be a ripple of a few 1e-4 rad just after an
impact). Printed per case: the impacts whose truth half-cycles are both ≥ 0.01 rad,
the largest error of the model-based r over them (and over those ≥ 0.025 rad), the
corner means against the mean truth of the impacts they average, the energy
estimate's mean and largest error (≥ 0.01 rad), the share of the estimated impacts
with |error| ≤ 2.5 r_std, and the wall and CPU time of `restitution` (the CPU time
counts this process only: on a shared machine the wall time is longer).

    python benchmarks/identify_restitution.py [--noise 0.02] [--specimens S1,S2]
        [--models DD2,CIM] [--seeds 1,2,3]

With ``--cp-factor F`` the Dirac-delta traces are made with F × Table 2's C_p, with
``--zeta-factors A,B`` with the specimen's ζ1 × A and ζ2 × B (and ``--fs``,
``--t-end``, ``--theta0`` for the test); nothing is given to `restitution` (C_p and
the damping are estimated) unless ``--given``, which gives it the trace's. Then also
printed: the share of the estimated impacts within 1.96 r_std and the C_p estimated
against the trace's.

    python benchmarks/identify_restitution.py --models DD2 --cp-factor 1.4 --t-end 5
"""

import argparse
import time
from dataclasses import replace

import numpy as np

from multimass import FreeRelease
from multimass.identify import synthetic_trace
from multimass.identify.impacts import restitution
from multimass.impact_models.table2 import TABLE_2
from multimass.structure import column, from_specimen

_FIT = {"DD2": "DD", "CIM": "CIM"}


def truth_impacts(syn) -> list[dict]:
    """The truth's impacts with r (1 where no force acted) and their half-cycles' peaks."""
    resp = syn.response
    t, th = np.asarray(resp.t), np.abs(np.asarray(resp.theta))
    imps = syn.truth["impacts"]
    tm = [e["t_model"] for e in imps]
    out = []
    for j, e in enumerate(imps):
        a = tm[j - 1] if j else 0.0
        b = tm[j + 1] if j + 1 < len(tm) else t[-1]
        before = th[(t >= a) & (t <= tm[j])].max()
        after = th[(t >= tm[j]) & (t <= b)].max()
        r = 1.0 if e["r"] is None else e["r"]
        out.append({"t": e["t"], "corner": e["corner"], "r": r, "small": min(before, after)})
    return out


def case(spec: str, model: str, seed: int, noise: float, a=None) -> dict:
    st, kw, given = from_specimen(spec), {}, {}
    t_end, theta0, fs = (10.0, 0.11, 200.0) if a is None else (a.t_end, a.theta0, a.fs)
    if a is not None and (a.cp_factor != 1.0 or a.zeta_factors != "1,1"):
        z1, z2 = (float(x) for x in a.zeta_factors.split(","))
        sp = st.specimen
        st = column(replace(sp, zeta_1=sp.zeta_1 * z1, zeta_2=sp.zeta_2 * z2))
        if model != "CIM":
            kw["C_p"] = a.cp_factor * TABLE_2[model][2]
    if a is not None and a.given:
        given = {"zeta1": st.specimen.zeta_1, "zeta2": st.specimen.zeta_2}
        if model != "CIM":
            given["C_p"] = kw.get("C_p", TABLE_2[model][2])
    syn = synthetic_trace(
        st, FreeRelease(theta0=theta0), model, t_end, seed=seed, noise=noise, fs=fs, **kw
    )
    wall, cpu = time.perf_counter(), time.process_time()
    est = restitution(syn.trace, spec, _FIT[model], progress=False, **given)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    rows = est.impacts
    truth = truth_impacts(syn)
    err = {0.01: [], 0.025: []}
    e_err = []
    for tr in truth:
        row = rows.iloc[int(np.argmin(np.abs(rows["t"].to_numpy() - tr["t"])))]
        for lim in err:
            if tr["small"] >= lim:
                err[lim].append(row["r"] - tr["r"])
        if tr["small"] >= 0.01:
            e_err.append(row["r_energy"] - tr["r"])
    by_corner = {"right": [], "left": []}
    covered, within95 = [], []
    for _, row in rows[rows["estimated"]].iterrows():
        tr = min(truth, key=lambda e: abs(e["t"] - row["t"]))
        by_corner[row["corner"]].append(tr["r"])
        covered.append(abs(row["r"] - tr["r"]) <= 2.5 * row["r_std"])
        within95.append(abs(row["r"] - tr["r"]) <= 1.96 * row["r_std"])
    dm = (
        est.r_mean_right - np.mean(by_corner["right"] or [np.nan]),
        est.r_mean_left - np.mean(by_corner["left"] or [np.nan]),
    )
    return {
        "n": len(err[0.01]),
        "max01": np.max(np.abs(err[0.01])) if err[0.01] else np.nan,
        "max025": np.max(np.abs(err[0.025])) if err[0.025] else np.nan,
        "dm": dm,
        "energy": (np.mean(e_err), np.max(np.abs(e_err))) if e_err else (np.nan, np.nan),
        "coverage": (sum(covered), len(covered)),
        "coverage95": (sum(within95), len(within95)),
        "cp": (est.parameters["cp"]["value"], est.parameters["cp"]["status"], kw.get("C_p")),
        "wall": wall,
        "cpu": cpu,
    }


def _cp(cp) -> str:
    value, status, truth = cp
    if value is None:
        return status
    return f"{value:.5g} {status}" + (f" ({truth:.5g})" if truth else "")


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--noise", type=float, default=0.02)
    ap.add_argument("--specimens", default="S1,S2,S3")
    ap.add_argument("--models", default="DD2,CIM")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--cp-factor", type=float, default=1.0)
    ap.add_argument("--zeta-factors", default="1,1")
    ap.add_argument("--fs", type=float, default=200.0)
    ap.add_argument("--t-end", type=float, default=10.0)
    ap.add_argument("--theta0", type=float, default=0.11)
    ap.add_argument("--given", action="store_true")
    a = ap.parse_args()
    print(
        "| specimen | trace (fitted) | seed | n ≥ 0.01 | max err r (≥ 0.01) | max err r (≥ 0.025) "
        "| Δr̄_er | Δr̄_el | energy err mean / max | within 2.5 r_std | within 1.96 r_std "
        "| C_p (trace's) | wall / CPU (s) |\n|" + "---|" * 13,
        flush=True,
    )
    for spec in a.specimens.split(","):
        for model in a.models.split(","):
            for seed in (int(s) for s in a.seeds.split(",")):
                c = case(spec, model, seed, a.noise, a)
                print(
                    f"| {spec} | {model} ({_FIT[model]}) | {seed} | {c['n']} | {c['max01']:.4f} "
                    f"| {c['max025']:.4f} | {c['dm'][0]:+.4f} | {c['dm'][1]:+.4f} "
                    f"| {c['energy'][0]:+.4f} / {c['energy'][1]:.4f} "
                    f"| {c['coverage'][0]}/{c['coverage'][1]} "
                    f"| {c['coverage95'][0]}/{c['coverage95'][1]} "
                    f"| {_cp(c['cp'])} | {c['wall']:.1f} / {c['cpu']:.1f} |",
                    flush=True,
                )
