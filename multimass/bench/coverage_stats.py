"""Errors and interval coverage of identification estimates against their truths.

`add_errors` works out, for every row of an estimate table (`multimass.bench.
coverage_cases`), the error, whether it is within the accuracy asked of it and whether
the reported 95 % interval holds the truth; `summarise` gives per estimator, specimen
and quantity the error distribution and those shares.

Errors are absolute for the coefficients of restitution, the angles and the clock,
relative (value / truth − 1) for C_p and the damping ratios. The reported interval is
[lo, hi] where the estimator gives one, else value ± 1.96 std (the normal 95 %
interval); an estimate with neither has no interval and is left out of the coverage
(counted in ``n_interval``). The accuracy asked: per-impact r within 0.015, corner
means within 0.01, C_p within 10 %; the other quantities have no threshold.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

__all__ = ["Quantity", "QUANTITIES", "Z95", "add_errors", "summarise", "coverage_interval"]

Z95 = 1.959963984540054  # the standard normal's 97.5 % quantile


@dataclass(frozen=True)
class Quantity:
    """How a quantity's error is measured and judged."""

    label: str
    relative: bool  # error as value / truth − 1
    threshold: float | None  # |error| asked for (None: none asked)


#: The quantities the estimators report, in the order of the tables.
QUANTITIES = {
    "r": Quantity("per-impact r", False, 0.015),
    "r_mean_right": Quantity("corner mean r̄_er", False, 0.01),
    "r_mean_left": Quantity("corner mean r̄_el", False, 0.01),
    "sigma_r": Quantity("σ_r", False, None),
    "cp": Quantity("C_p", True, 0.10),
    "zeta1": Quantity("ζ1", True, None),
    "zeta2": Quantity("ζ2", True, None),
    "theta0": Quantity("θ0 (rad)", False, None),
    "t_offset": Quantity("clock offset (s)", False, None),
    "theta_bias": Quantity("θ bias (rad)", False, None),
}


def add_errors(rows: pd.DataFrame) -> pd.DataFrame:
    """`rows` with ``err`` (signed), ``abs_err``, ``within`` (1/0, NaN without a
    threshold), ``lo95``/``hi95`` (the interval used), ``covered`` (1/0, NaN without an
    interval) and ``covered_nominal`` (the same against ``truth_nominal``, where given).

    Rows without a truth (an estimated impact that matched no simulated one) keep NaN
    errors and are left out of every share.
    """
    df = rows.copy()
    for col in ("std", "lo", "hi", "truth_nominal"):
        if col not in df:
            df[col] = np.nan
    if "constrained" in df:  # calibrate's flag where no status was recorded
        flag = df["constrained"].map({True: "estimated", False: "ill-posed"})
        df["status"] = df["status"].fillna(flag) if "status" in df else flag
    rel = df["quantity"].map(lambda q: QUANTITIES[q].relative if q in QUANTITIES else False)
    rel = rel.to_numpy(dtype=bool)
    value, truth = df["value"].to_numpy(float), df["truth"].to_numpy(float)
    with np.errstate(divide="ignore", invalid="ignore"):
        df["err"] = np.where(rel, value / truth - 1.0, value - truth)
    df["abs_err"] = df["err"].abs()
    thr = df["quantity"].map(lambda q: QUANTITIES[q].threshold if q in QUANTITIES else None)
    thr = thr.astype(float).to_numpy()
    ok = np.isfinite(thr) & np.isfinite(df["abs_err"].to_numpy())
    df["within"] = np.where(ok, (df["abs_err"].to_numpy() <= thr).astype(float), np.nan)
    std = df["std"].to_numpy(float)
    given = np.isfinite(df["lo"].to_numpy(float)) & np.isfinite(df["hi"].to_numpy(float))
    df["lo95"] = np.where(given, df["lo"], value - Z95 * std)
    df["hi95"] = np.where(given, df["hi"], value + Z95 * std)
    df["covered"] = _covered(df["lo95"], df["hi95"], df["truth"])
    df["covered_nominal"] = _covered(df["lo95"], df["hi95"], df["truth_nominal"])
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = np.where(rel, truth, 1.0)
        df["std_in_units"] = std / np.abs(scale)  # the std in the error's units
    return df


def _covered(lo: pd.Series, hi: pd.Series, truth: pd.Series) -> np.ndarray:
    """1 where lo ≤ truth ≤ hi, 0 where not, NaN where the interval or truth is missing
    (an infinite std covers: the estimator says it does not know)."""
    lo, hi, t = (np.asarray(x, dtype=float) for x in (lo, hi, truth))
    known = ~np.isnan(lo) & ~np.isnan(hi) & np.isfinite(t)
    return np.where(known, ((lo <= t) & (t <= hi)).astype(float), np.nan)


def coverage_interval(k: int, n: int, level: float = 0.95) -> tuple[float, float]:
    """The Clopper–Pearson (exact binomial) interval of a coverage from `k` intervals
    holding the truth out of `n` (Clopper & Pearson 1934, Biometrika 26: the β quantiles
    β(α/2; k, n − k + 1) … β(1 − α/2; k + 1, n − k)); (nan, nan) for n = 0. A finite
    benchmark measures the coverage only to this: 36 of 40 (90 %) is 76–97 %."""
    from scipy import stats  # here: the rest of the module needs no SciPy

    if n <= 0:
        return float("nan"), float("nan")
    a = 1.0 - level
    lo = float(stats.beta.ppf(a / 2, k, n - k + 1)) if k > 0 else 0.0
    hi = float(stats.beta.ppf(1 - a / 2, k + 1, n - k)) if k < n else 1.0
    return lo, hi


def summarise(df: pd.DataFrame, by_specimen: bool = True) -> pd.DataFrame:
    """Per estimator, specimen (and "all") and quantity: ``n`` (estimates with a truth),
    ``median``, ``p95``, ``max`` of ``|err|``, ``within`` (share within the threshold; NaN
    without one), ``n_interval`` (estimates with an interval), ``coverage`` (share of
    those whose interval holds the truth), ``coverage_lo`` and ``coverage_hi`` (its 95 %
    Clopper–Pearson interval, `coverage_interval`), ``coverage_nominal``, ``n_ill_posed``
    (estimates whose result says the traces do not fix them: status "ill-posed") and
    ``coverage_ill_posed`` (the share of those whose reported range, the range the fit
    explored, holds the truth). ``n_interval``, ``coverage`` and ``coverage_nominal``
    count only the others: the 95 % intervals of what the result reports as estimated.

    `df` is a table from `add_errors`. Percentiles interpolate linearly
    (`numpy.percentile`'s default).
    """
    df = df[np.isfinite(df["abs_err"])]
    parts = [df.assign(specimen="all")]
    if by_specimen:
        parts.insert(0, df)
    both = pd.concat(parts, ignore_index=True)
    rows = []
    order = {q: i for i, q in enumerate(QUANTITIES)}
    for (est, spec, q), g in both.groupby(["estimator", "specimen", "quantity"], sort=False):
        e = g["abs_err"].to_numpy(float)
        ill = (g["status"] == "ill-posed") if "status" in g else pd.Series(False, index=g.index)
        cov = g.loc[~ill, "covered"].dropna()
        nom = g.loc[~ill, "covered_nominal"].dropna()
        bad = g.loc[ill, "covered"].dropna()
        lo, hi = coverage_interval(int(cov.sum()), int(cov.size))
        rows.append(
            {
                "estimator": est,
                "specimen": spec,
                "quantity": q,
                "n": int(e.size),
                "median": float(np.median(e)),
                "p95": float(np.percentile(e, 95)),
                "max": float(e.max()),
                "within": float(g["within"].mean()) if g["within"].notna().any() else np.nan,
                "n_interval": int(cov.size),
                "coverage": float(cov.mean()) if cov.size else np.nan,
                "coverage_lo": lo,
                "coverage_hi": hi,
                "coverage_nominal": float(nom.mean()) if nom.size else np.nan,
                "n_ill_posed": int(ill.sum()),
                "coverage_ill_posed": float(bad.mean()) if bad.size else np.nan,
                "_order": order.get(q, len(order)),
            }
        )
    out = pd.DataFrame(rows)
    if out.empty:
        return out
    out = out.sort_values(["estimator", "specimen", "_order"], kind="stable")
    return out.drop(columns="_order").reset_index(drop=True)
