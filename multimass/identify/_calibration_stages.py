"""The stages of `multimass.identify.calibrate`, in order (see its module docstring).

0. `align_releases` — each free trace's release angle and clock offset, the starts
   and the centres of their bounds, by `restitution`'s alignment
   (`_restitution_fit.align`) of the samples before the first impact.
1. `stage1` — the free traces' releases and peak ratios: a coarse scan of the
   restitution means, then least squares; its peak-ratio residuals give the first
   guess of each impact's deviation from its corner mean.
2. `stage2` — the time histories of θ and the accelerations over the first `FIRST`
   large half-cycles of each trace, everything fitted, each impact's deviation from
   its corner mean a random effect: its impacts are first seeded one by one on θ,
   then passes follow: after each, the channels' residual scales are re-estimated
   (they weight the channels) and the corner means are re-centred on their impacts'
   deviations (the data see only mean + deviation, so this leaves the fit unchanged
   and minimises the prior); a pass is repeated while the channels' scales changed
   relative to each other by more than 25 % (a common factor leaves the fit as it
   was). Then the window grows `GROWTH` half-cycles at a time, up to `HISTORY`, as
   long as the fit still follows the test (no channel's residual RMS up by more than
   30 %, residuals white); a last fit frees everything on the window reached.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np
from scipy import optimize

from ._calibration_fit import Problem, scan, solve
from ._calibration_model import TrialRejected
from ._calibration_stats import LIMITS, lag1
from ._restitution_fit import EDGE, Track, align

__all__ = [
    "align_releases",
    "stage1",
    "stage2",
    "StageResult",
    "FIRST",
    "HISTORY",
    "GROWTH",
    "MAX_PASSES",
]

#: Large half-cycles of each trace whose time histories stage 2 fits first …
FIRST = 5
#: … and at most, growing `GROWTH` at a time while the fit follows the test.
HISTORY = 9
GROWTH = 2
_GROW_NFEV = 8
_GROWTH_TOL = 1.3  # a longer window may raise a channel's residual RMS by 30 % at most
#: Most stage-2 passes (a pass re-weights the channels by their residuals).
MAX_PASSES = 3
_SCALE_CHANGE = math.log(1.25)
_SEED_SPAN = 0.08  # an impact's deviation is seeded within this of its start
_SEED_TOL = 2e-3
_AHEAD = 0.1  # s: a seed's window stops this long before the next impact
#: Trace samples stage 2's windows stop before the impact that ends their last large
#: half-cycle (`Case.upto`): the anti-alias filter's reach (`restitution`'s `EDGE`, the
#: margin it keeps before an impact). Ending at the impact put part of its filtered
#: spike in the fit, cut where the noisy θ says, followed by that impact's restitution
#: alone: on coverage draw S1-001 (seed 0) ζ1 moved by 0.4–1.4 % per 10 ms of window
#: end (its std 1.5 %); over eight noise draws of that trace, where estimated, 2.7 %
#: low with sd 1.9 % (6 of 8; reported std 2.2 % with the model floor). Stopping `EDGE`
#: samples before: 0.2 % high with sd 0.9 % (7 of 8; reported 2.0 %).
REACH = EDGE


@dataclass
class StageResult:
    """What a stage returns: the unknowns' values by label and its report."""

    values: dict
    info: dict
    problem: Problem | None = None
    x: np.ndarray | None = None
    ok: bool = True


def _info(sol, seconds: float, runs: int, **more) -> dict:
    return {
        "status": int(sol.status),
        "message": str(sol.message),
        "success": bool(sol.status > 0),
        "nfev": int(sol.nfev),
        "njev": int(sol.njev or 0),
        "cost": float(2.0 * sol.cost),
        "n_residuals": int(sol.fun.size),
        "seconds": seconds,
        "simulations": runs,
        **more,
    }


def _labels(p: Problem) -> set:
    return {un.label for un in p.unknowns}


def _scales(p: Problem, x: np.ndarray) -> dict:
    out = {}
    for key, (e, _) in p.raw(x).items():
        rms = float(np.sqrt(np.mean(e * e)))
        out[key] = rms if rms > 0.0 else 1.0
    return out


# ---------------------------------------------------------------------------- stage 0
def align_releases(sim, pset, cases) -> list:
    """The cases with each free trace's release angle and clock offset (`Case.theta0`,
    `Case.tau`) aligned on the samples before its first impact, where no restitution
    acts: `restitution`'s scan of the release time then least squares
    (`_restitution_fit.align`), with the start values of the model parameters.

    The first guess of the clock (where θ leaves its held value) is often the trace's
    first sample on a noisy hold; stage 1's least squares, bounded ±0.2 s about it,
    then stopped in another valley. On the coverage benchmark's 15 free traces (S1–S3,
    seed 0, released 0.006–0.274 s into the trace) the guess was the first sample on 7
    (0.04–0.27 s early) and 0.03–0.09 s early on 5 more; 8 of these 12 calibrated
    ill-posed, with restitution means down to 0.3 for 0.82–0.98. Aligned, every clock
    came within 2e-4 s of the truth and θ0 within 0.0011 rad, in 0.6–2.6 s a trace.
    Table-motion traces (clock fixed at their first sample) are returned as they are.
    """
    out = []
    for c in cases:
        if not c.free or not c.segments.impacts:
            out.append(c)
            continue
        scales = {ch: (c.segments.noise if ch == "theta" else math.inf) for ch in c.channels}
        nuis = {"theta0": c.theta0, "t_offset": c.tau, "theta_bias": c.bias}
        track = Track(sim, c, dict(pset.start), nuis, scales)
        try:
            align(track, c.segments.impacts[0].t)
        except TrialRejected:  # the guesses stand; stage 1 starts from them
            out.append(c)
            continue
        out.append(
            replace(c, theta0=float(track.nuis["theta0"]), tau=float(track.nuis["t_offset"]))
        )
    return out


# ---------------------------------------------------------------------------- stage 1
def stage1(sim, pset, cases, sigma_r: float, max_nfev: int) -> StageResult:
    """Releases and peak ratios of the free traces (nothing to do without one)."""
    p = Problem(sim, pset, cases, 1, False, sigma_r)
    if not p.used_cases:
        return StageResult({}, {"skipped": "no free-vibration trace"})
    wall, runs = time.perf_counter(), sim.n_runs
    start = scan(p)
    p = Problem(sim, pset, cases, 1, False, sigma_r, start=start)
    sol = solve(p, max_nfev)
    values = {un.label: float(x) for un, x in zip(p.unknowns, sol.x)}
    phys, _ = p.decode(sol.x)
    blocks = p.blocks(sol.x)
    means = {"right": phys["r_er"], "left": phys["r_el"]}
    for c in p.used_cases:
        ratios = blocks.get((c.label, "ratios"))
        if ratios is None:
            continue
        dlog = ratios * p.ratio_sigma(c, phys)  # log P_k+1/P_k: simulated − measured
        for k, d in enumerate(dlog):  # log P_k+1/P_k ≈ 2 log r_k
            corner = c.segments.impacts[c.first_impact + k].corner
            dev = means[corner] * (math.exp(-0.5 * float(d)) - 1.0)
            values[f"{c.label}:r[{c.first_impact + k}]"] = float(
                np.clip(dev, -3.0 * sigma_r, 3.0 * sigma_r)
            )
    info = _info(sol, time.perf_counter() - wall, sim.n_runs - runs, scan=start)
    return StageResult(values, info, p, sol.x, ok=sol.status > 0)


# ---------------------------------------------------------------------------- stage 2
def recenter(p: Problem, x: np.ndarray) -> np.ndarray:
    """The corner means moved to the mean of their impacts' deviations (unchanged fit)."""
    if not p.per_impact:
        return x
    y = x.copy()
    lo, hi = p.bounds()
    for corner, name in (("right", "r_er"), ("left", "r_el")):
        if name not in p.index:
            continue
        idx = [
            i for i, un in enumerate(p.unknowns) if un.kind == "deviation" and un.corner == corner
        ]
        if not idx:
            continue
        j = p.index[name]
        new = float(np.clip(y[j] + np.mean(y[idx]), lo[j], hi[j]))
        y[idx] -= new - y[j]
        y[j] = new
    before = float(np.sum(p.residuals(x) ** 2))
    after = float(np.sum(p.residuals(y) ** 2))
    return y if after <= before * (1.0 + 1e-9) else x


def seed(sim, pset, case, j: int, sigma_r: float, values: dict) -> None:
    """The deviation of `case`'s impact `j` (local index) alone, on θ alone, over the
    window up to the half-cycle after it, stopped `_AHEAD` before the impact that ends
    it (that impact's deviation, not yet seeded, acts there: the Dirac-delta force
    before θ = 0 and the anti-alias filter's reach); a bounded Brent search ±0.08
    about its start. θ's cost is a smooth bowl in one impact's restitution (S3: 1.04 ×
    the noise variance at the truth, 1.3 at ±0.01, 2.1 at −0.02)."""
    c = case.upto(j + 2, REACH)
    nxt = c.large[-1]
    if nxt.ends == "impact" and len(c.large) > j + 1:
        c = c.cut(max(nxt.t_peak, nxt.t_stop - _AHEAD))
    lab = f"{c.label}:r[{c.first_impact + j}]"
    full = Problem(sim, pset, [c], 2, True, sigma_r, start=values)
    p = Problem(
        sim, pset, [c], 2, True, sigma_r, start=values,
        frozen=frozenset(_labels(full) - {lab}), only=("theta",),
    )  # fmt: skip
    p.scales = {(c.label, "theta"): max(c.segments.noise, 1e-6)}
    x0 = float(values.get(lab, 0.0))
    res = optimize.minimize_scalar(
        lambda d: float(np.sum(p.residuals(np.array([d])) ** 2)),
        bounds=(x0 - _SEED_SPAN, x0 + _SEED_SPAN), method="bounded",
        options={"xatol": _SEED_TOL},
    )  # fmt: skip
    values[lab] = float(res.x)


def _budgets(max_nfev: int) -> tuple:
    """Evaluations allowed per pass: the first pass only brings the residuals near their
    level (its weights come from the start's residuals, mostly misfit), the second
    converges with weights from the first's residuals, a third only re-weights."""
    return (max(max_nfev // 3, 5), max_nfev, max(max_nfev // 3, 5))[:MAX_PASSES]


def _passes(p: Problem, budgets) -> tuple:
    """Least squares on `p` in passes re-weighting the channels; (x, last solution, log)."""
    passes, sol, x = [], None, p.x0()
    for budget in budgets:
        n0 = p.sim.n_runs
        sol = solve(p, budget)
        x = recenter(p, sol.x)
        new = _scales(p, x)
        logs = [math.log(new[k] / p.scales[k]) for k in new]
        change = max(logs) - min(logs)  # a common factor leaves the weighting as it was
        passes.append(
            {"nfev": int(sol.nfev), "njev": int(sol.njev or 0), "status": int(sol.status),
             "cost": float(2.0 * sol.cost), "scale_change": math.exp(change) - 1.0,
             "simulations": p.sim.n_runs - n0, "half_cycles": len(p.cases[0].large)}
        )  # fmt: skip
        p.scales = new
        p.start = {un.label: float(v) for un, v in zip(p.unknowns, x)}
        p.__post_init__()
        if change < _SCALE_CHANGE and sol.status > 0:
            break
    return x, sol, passes


def _follows(p: Problem, x: np.ndarray, scales: dict) -> bool:
    """The fit of a longer window still follows the test: no channel's residual RMS grew
    by more than `_GROWTH_TOL` over the shorter window's, and the residuals stay white."""
    new = _scales(p, x)
    blocks = p.blocks(x)
    white = all(lag1(r) < LIMITS["rho_misfit"] for k, r in blocks.items() if k[1] != "prior")
    return white and all(new[k] <= _GROWTH_TOL * scales[k] for k in new if k in scales)


def _grow(sim, pset, cases, sigma_r, values, scales, k0: int, history: int, report) -> int:
    """Lengthen the window `GROWTH` half-cycles at a time, up to `history`, while the fit
    follows the test (`_follows`); `values` and `scales` are those of the longest window
    accepted, whose number of half-cycles is returned."""
    longest = min(history, max(len(c.large) for c in cases))
    k = k0
    while k < longest:
        nxt = min(k + GROWTH, longest)
        trial = dict(values)
        for c in cases:
            # the impact ending the shorter window was not seen there (`REACH`):
            # seeded again with the new ones
            for j in range(max(min(k, c.n_impacts) - 1, 0), min(nxt, c.n_impacts)):
                seed(sim, pset, c, j, sigma_r, trial)
        short = [c.upto(nxt, REACH) for c in cases]
        probe = Problem(sim, pset, short, 2, True, sigma_r, start=trial)
        held = {"r_er", "r_el"} | {
            un.label for un in probe.unknowns
            if un.kind == "deviation" and int(un.label.rsplit("[", 1)[1][:-1]) < k - GROWTH
        }  # fmt: skip
        p = Problem(sim, pset, short, 2, True, sigma_r, start=trial, frozen=frozenset(held))
        p.scales = dict(scales)
        sol = solve(p, _GROW_NFEV)
        ok = _follows(p, sol.x, scales)
        report.append({"half_cycles": nxt, "nfev": int(sol.nfev), "accepted": ok})
        if not ok:
            break
        trial.update({un.label: float(v) for un, v in zip(p.unknowns, sol.x)})
        values.clear()
        values.update(trial)
        scales.update(_scales(p, sol.x))
        k = nxt
    return k


def stage2(
    sim, pset, cases, per_impact, sigma_r, start: dict, max_nfev: int, history: int = HISTORY
) -> StageResult:
    """The time histories of the first `FIRST` large half-cycles, everything fitted; then,
    with per-impact deviations, the window grows while the fit follows the test (up to
    `history` half-cycles), and a last fit frees everything on the window reached."""
    wall, runs = time.perf_counter(), sim.n_runs
    values = dict(start)
    k = min(FIRST, history)
    short = [c.upto(k, REACH) for c in cases]
    if per_impact:
        for c in short:
            for j in range(c.n_impacts):
                seed(sim, pset, c, j, sigma_r, values)
    p = Problem(sim, pset, short, 2, per_impact, sigma_r, start=values)
    p.scales = _scales(p, p.x0())
    x, sol, passes = _passes(p, _budgets(max_nfev))
    growth = []
    if per_impact and history > k and sol.status > 0:
        values = {un.label: float(v) for un, v in zip(p.unknowns, x)}
        scales = dict(p.scales)
        reached = _grow(sim, pset, cases, sigma_r, values, scales, k, history, growth)
        if reached > k:
            p = Problem(
                sim, pset, [c.upto(reached, REACH) for c in cases], 2, True, sigma_r, start=values
            )
            p.scales = scales
            x, sol, more = _passes(p, (_GROW_NFEV, _GROW_NFEV))
            passes += more
            k = reached
    values = {un.label: float(v) for un, v in zip(p.unknowns, x)}
    info = _info(sol, time.perf_counter() - wall, sim.n_runs - runs, passes=passes)
    info["cost"] = float(np.sum(p.residuals(x) ** 2))
    info["half_cycles"] = k
    info["growth"] = growth
    return StageResult(values, info, p, x, ok=sol.status > 0)
