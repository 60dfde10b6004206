"""Uncertainties, flags and status of a calibration (`multimass.identify.calibrate`).

Covariance: stage 2's residuals are whitened by per-channel scales re-estimated from
the fit (each channel's residual RMS), so the residual variance per channel is 1;
what remains is their correlation in time. A misfit (a model that cannot follow the
trace) leaves residuals that are smooth, not white, and each of them then carries
less than one sample's information: the rows of a channel are down-weighted by the
AR(1) variance inflation (1 + ρ₁) / (1 − ρ₁), ρ₁ its residuals' lag-1
autocorrelation, before cov = (J̃ᵀJ̃)⁻¹ (the per-impact deviations' prior rows keep
weight 1). White noise has ρ₁ ≈ 0 and no inflation.
"""

from __future__ import annotations

import math

import numpy as np

from ._calibration_params import PARAMETERS

__all__ = ["covariance", "lag1", "flags", "status_of", "slice_probe", "rough_std", "rough_reason",
           "STATUSES", "LIMITS",
           "MODEL_REL_FLOOR", "SLICE", "SLICE_RATIO"]  # fmt: skip

#: Statuses of a calibration and what they mean.
STATUSES = {
    "converged": "the fit converged, every fitted parameter is constrained and the "
    "residuals are close to white noise: the model reproduces the traces",
    "misfit": "the fit converged and the parameters are constrained, but the residuals "
    "are structured (lag-1 autocorrelation above `LIMITS['rho_misfit']` in some "
    "channel): the model cannot reproduce the traces, the values are the best this "
    "model can do, not the test's truth",
    "ill-posed": "some fitted parameter is not constrained by the traces (its "
    "uncertainty is too large, it sits on a bound, or it is nearly collinear with "
    "another), or the fit does not reproduce the traces within their noise (then none "
    "is): see each parameter's `constrained` flag; fix it or give better traces",
    "failed": "a simulation failed or could not be run; `message` says why (the values "
    "are the starts)",
}

#: Thresholds of the flags: a restitution mean with std above `r_std`, a log-fitted
#: parameter (C_p, ζ) with relative std above `rel_std`, a pair correlated beyond
#: `correlation` is not constrained; residuals with ρ₁ above `rho_misfit` are a misfit.
LIMITS = {"r_std": 0.02, "rel_std": 0.25, "correlation": 0.98, "rho_misfit": 0.5}


#: Relative standard deviation added in quadrature to the ones of C_p and of the
#: damping ratios from the fit's covariance: the model's error, which the noise's
#: covariance does not hold (the runs are recorded at 10 × the trace's rate where the
#: synthetic traces are at 40 ×: S1's a_A1 peak differs by 0.86 %). Measured with
#: `restitution` on twelve synthetic traces (S1–S3, C_p 0.6 and 1.4 × Table 2's,
#: damping 0.5–1.5 ×, 200–1000 Hz, noise 1–5 %): errors up to 2.6 % (ζ2 of S3 at 5 %
#: noise, 2.5 % for C_p and 2.3 % for ζ1 of S1 at 4 %), where the covariance gave
#: 0.03–1 % (ζ1 0.4 % off with a std of 0.03 % on S2 at 1000 Hz; C_p 1.07 % off with
#: 0.07 % on S2 at 2 %). 1.5 % makes the 95 % intervals (± 2.9 % and more) cover them.
#: Checked for `calibrate`'s ζ on 19 synthetic traces of the coverage benchmark's draws
#: it is not judged on (`multimass.bench.coverage_draws`, DD, seeds 1 and 2): the
#: intervals cover ζ1 in 17 of 17 and ζ2 in 16 of 16 where they are estimated (94 %
#: and 94 % without the floor; 2 % would be needed for seed 0's 18, where 1.5 % covers
#: 13 of 16 and 11 of 13 — pooled, 30 of 32 and 27 of 28 with 1.5 %). The largest ζ
#: errors are not the simulation rate's: on S2 (seed 0, index 0; noise 2.9 %) ζ1 is
#: 3.5 % off with a covariance std of 0.34 %, and 0.13 % off with noise 0.2 %; on S2
#: (seed 1, index 0) 2.7 % off with 0.37 %. The noise moves ζ1 of S2 further than the
#: linearised covariance says; a probe of the cost at ± 3 std along ζ's profile
#: direction (the others at their conditional best) did not find it flatter there.
MODEL_REL_FLOOR = 0.015


#: The slice check of a fitted parameter (`slice_probe`): steps of at least this
#: (log units for C_p and ζ; relative to its value for a release angle).
SLICE = 0.01
#: Measured / predicted cost rise beyond which (either way) the Jacobian is not trusted.
SLICE_RATIO = 4.0


def slice_probe(residuals, x: np.ndarray, f0: np.ndarray, J: np.ndarray, j: int, h: float) -> dict:
    """Whether the linearisation holds along unknown `j` of a least-squares fit at `x`.

    The cost is evaluated at x ± `h` along the unknown alone and compared with the rise
    the Jacobian `J` predicts, ‖J_j h‖² (`residuals`: x → the residual vector, `f0` at
    `x`). Where the Dirac-delta force switching or a full-contact transition comes and
    goes, or the run's later impacts move with it, the cost is rough: the measured rise
    differs from the predicted one by more than `SLICE_RATIO` either way, and the value is
    one of nearby minima. Returns ``step``, ``rise`` (at +h, −h), ``predicted``,
    ``trusted``, and the norms of the secant over ±h and of J's column (a rough
    parameter's std is at least h, or the secant's).
    """
    cost0 = float(f0 @ f0)
    predicted = float(np.sum((J[:, j] * h) ** 2))
    rises, slopes = [], []
    for sign in (1.0, -1.0):
        y = x.copy()
        y[j] += sign * h
        f = residuals(y)
        rises.append(float(f @ f) - cost0)
        slopes.append((f - f0) / (sign * h))
    ratio = [r / predicted if predicted > 0 else math.inf for r in rises]
    secant = 0.5 * (slopes[0] + slopes[1])
    return {
        "step": h, "rise": rises, "predicted": predicted,
        "trusted": all(1.0 / SLICE_RATIO <= q <= SLICE_RATIO for q in ratio),
        "secant_norm": float(np.linalg.norm(secant)), "jacobian_norm": float(np.linalg.norm(J[:, j])),
    }  # fmt: skip


def rough_std(std: float, probe: dict) -> float:
    """A rough parameter's std (`slice_probe` not ``trusted``): at least the probe's
    step, and the std the secant over ±step gives in place of the Jacobian's column."""
    secant = std * probe["jacobian_norm"] / max(probe["secant_norm"], 1e-300)
    return max(std, secant, probe["step"])


def rough_reason(probe: dict, unit: str = " %") -> str:
    """Why a rough parameter (`slice_probe` not ``trusted``) is not fixed by the fit."""
    step = f"{100 * probe['step']:.2g} %" if unit == " %" else f"{probe['step']:.3g}{unit}"
    return (
        f"the cost is rough along it (rise {probe['rise'][0]:.3g} / {probe['rise'][1]:.3g} "
        f"at ±{step} where the Jacobian predicts {probe['predicted']:.3g}): the value is "
        "one of nearby minima, its std at least the probe's distance"
    )


def lag1(e: np.ndarray) -> float:
    """Lag-1 autocorrelation of a residual series (0 for fewer than 3 samples)."""
    e = np.asarray(e, dtype=float)
    if e.size < 3:
        return 0.0
    e = e - e.mean()
    den = float(e @ e)
    return float(e[1:] @ e[:-1]) / den if den > 0.0 else 0.0


def covariance(J: np.ndarray, rows: dict, scales: np.ndarray) -> tuple[np.ndarray, dict]:
    """(covariance of the unknowns, per-group (ρ₁, inflation)).

    Parameters
    ----------
    J : ndarray
        Jacobian of the weighted residuals (rows in the order of `rows`).
    rows : dict
        (case, group) → weighted residuals at the solution (``prior`` groups are not
        inflated).
    scales : ndarray
        The unknowns' typical sizes, to condition the inversion.
    """
    weights, info, start = [], {}, 0
    for key, r in rows.items():
        n = r.size
        if key[1] == "prior":
            w, rho, infl = 1.0, 0.0, 1.0
        else:
            rho = lag1(r)
            infl = float(np.clip((1.0 + rho) / (1.0 - rho), 1.0, 1e3)) if rho < 1.0 else 1e3
            var = float(np.mean(r * r)) if n else 1.0
            w = 1.0 / math.sqrt(infl * max(var, 1e-300))
        weights.append(np.full(n, w))
        info[key] = {"rho1": rho, "inflation": infl}
        start += n
    Jw = J * np.concatenate(weights)[:, None]
    A = (Jw * scales).T @ (Jw * scales)
    lam, V = np.linalg.eigh(A)
    floor = max(lam.max(), 1e-300) * 1e-12
    inv = (V / np.maximum(lam, floor)) @ V.T
    cov = inv * np.outer(scales, scales)
    bad = lam < floor
    if np.any(bad):  # directions the data do not see: infinite variance
        weak = np.abs(V[:, bad]).max(axis=1) > 1e-3
        cov[weak, :] = np.inf
        cov[:, weak] = np.inf
    return cov, info


def flags(names, x, std, corr, bounds) -> dict:
    """Per fitted parameter: bound hit ("lower"/"upper"/None) and constrained (bool), with
    the reason when it is not."""
    out = {}
    for i, name in enumerate(names):
        p = PARAMETERS[name]
        lo, hi = (p.to_x(b) for b in bounds[name])
        span = hi - lo
        hit = "lower" if x[i] - lo < 1e-3 * span else "upper" if hi - x[i] < 1e-3 * span else None
        reasons = []
        s = std[i]
        limit = LIMITS["rel_std"] if p.log else LIMITS["r_std"]
        if not math.isfinite(s):
            reasons.append("the traces do not constrain it (singular Jacobian)")
        elif s > limit:
            what = f"relative std {s:.2g}" if p.log else f"std {s:.2g}"
            reasons.append(f"{what} above {limit:g}")
        if hit:
            reasons.append(f"on its {hit} bound")
        for j, other in enumerate(names):
            if j != i and math.isfinite(corr[i, j]) and abs(corr[i, j]) > LIMITS["correlation"]:
                reasons.append(f"correlated with {other} ({corr[i, j]:+.3f})")
        out[name] = {"bound_hit": hit, "constrained": not reasons, "reason": "; ".join(reasons)}
    return out


def status_of(ok: bool, flagged: dict, rho: dict) -> tuple[str, str]:
    """(status, message) from the flags and the residuals' ρ₁; `ok` False (the least
    squares stopped at its evaluation budget) is said in the message."""
    note = "" if ok else "; the least squares stopped at its evaluation budget"
    loose = [n for n, f in flagged.items() if not f["constrained"]]
    if loose:
        why = "; ".join(f"{n}: {flagged[n]['reason']}" for n in loose)
        return "ill-posed", f"not constrained by the traces: {why}{note}"
    worst = max(rho.items(), key=lambda kv: kv[1], default=(None, 0.0))
    if worst[0] is not None and worst[1] > LIMITS["rho_misfit"]:
        bad = sorted(k for k, r in rho.items() if r > LIMITS["rho_misfit"])
        return "misfit", (
            f"the residuals are structured, not noise (lag-1 autocorrelation up to "
            f"{worst[1]:.2f} in {', '.join(f'{c}:{ch}' for c, ch in bad[:4])}): the model "
            f"cannot reproduce the traces{note}"
        )
    return "converged", f"converged; every fitted parameter is constrained{note}"
