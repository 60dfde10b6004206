"""Vectorised maximum likelihood of a probit model on grouped binomial counts.

The solver behind `multimass.analysis.fragility`: at levels ``z = ln x`` with ``n`` runs and ``k``
exceedances, maximise ``ℓ = Σ k ln Φ(η) + (n - k) ln Φ(-η)`` with ``η = a + b z``
(J. W. Baker 2015, Earthquake Spectra 31(1), its binomial likelihood, in the probit variables
``a = -ln θ/β``, ``b = 1/β``). ℓ is concave in (a, b); a damped Newton iteration solves
many count vectors (bootstrap resamples, rows of ``k``) at once, as arrays. Rows whose
maximum does not exist are classified first (status codes of `multimass.analysis.fragility.STATUS`).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.special import log_ndtr, ndtri

__all__ = ["fit_many", "loglik", "saturated_loglik", "information"]

_MAX_ITER = 100
_TOL = 1e-10
# A slope whose change of η across the levels, b (max z − min z), is below this is zero
# within the iteration's tolerance (it stops when b moves by less than _TOL (1 + |b|)):
# flat counts converge to b ≈ 1e-17, i.e. β ≈ 1e17, which is no fragility curve.
_FLAT = 100 * _TOL


def fit_many(z, n, k, details=False):
    """Fit every row of k (shape (B, m)) at levels z = ln x; classify degenerate rows.

    Returns theta, beta, status (each shape (B,)) and the bounds (lo, hi) of θ, plus
    a, b and the iteration count when `details`.
    """
    B = k.shape[0]
    x = np.exp(z)
    status = np.zeros(B, dtype=int)
    has_non = k < n  # a level where some run did not exceed
    has_exc = k > 0
    lo = np.where(has_non, x, -np.inf).max(axis=1)  # highest level with a non-exceedance
    hi = np.where(has_exc, x, np.inf).min(axis=1)  # lowest level with an exceedance
    lo_rev = np.where(has_exc, x, -np.inf).max(axis=1)
    hi_rev = np.where(has_non, x, np.inf).min(axis=1)
    none = ~has_exc.any(axis=1)
    every = ~has_non.any(axis=1)
    status[lo_rev <= hi_rev] = 5  # every exceedance below every non-exceedance
    status[lo <= hi] = 3
    if np.unique(z).size == 1:
        status[:] = 4
    status[every] = 2
    status[none] = 1
    bounds = (
        np.where(none, np.max(x), np.where(every, 0.0, lo)),
        np.where(none, np.inf, np.where(every, np.min(x), hi)),
    )
    theta = np.full(B, np.nan)
    beta = np.full(B, np.nan)
    a = np.full(B, np.nan)
    b = np.full(B, np.nan)
    it = 0
    rows = np.flatnonzero(status == 0)
    if rows.size:
        aa, bb, ok, it = _newton(z, n, k[rows])
        a[rows], b[rows] = aa, bb
        status[rows[~ok]] = 6
        rising = bb * (z.max() - z.min()) > _FLAT  # b ≤ 0, or zero within round-off: 5
        status[rows[ok & ~rising]] = 5
        good = rows[ok & rising]
        theta[good] = np.exp(-a[good] / b[good])
        beta[good] = 1.0 / b[good]
    out = (theta, beta, status, bounds)
    return out + (a, b, it) if details else out


def _newton(z, n, k):
    """Damped Newton on the concave probit log-likelihood; rows solved together."""
    zc = z.mean()
    u = z - zc  # centred levels: better conditioned
    # start: weighted least squares of Φ⁻¹ of smoothed fractions on u
    y = ndtri((k + 0.5) / (n + 1.0))
    w = n / n.sum()
    ub = np.sum(w * u)
    b = np.sum(w * (u - ub) * (y - np.sum(w * y, axis=1, keepdims=True)), axis=1) / np.sum(
        w * (u - ub) ** 2
    )
    b = np.where(b > 0, b, 1.0 / max(np.std(u), 1e-3))
    c = np.sum(w * y, axis=1) - b * ub  # intercept in u
    ll = loglik(u, n, k, c, b)
    ok = np.zeros(c.size, dtype=bool)
    n_iter = 0
    for it in range(1, _MAX_ITER + 1):
        n_iter = it
        g1, h = _derivatives(u, n, k, c, b)
        gc, gb = g1.sum(axis=1), (g1 * u).sum(axis=1)
        hcc, hcb, hbb = h.sum(axis=1), (h * u).sum(axis=1), (h * u * u).sum(axis=1)
        det = hcc * hbb - hcb * hcb
        dc = -(hbb * gc - hcb * gb) / det
        db = -(hcc * gb - hcb * gc) / det
        step = 1.0
        new_c, new_b = c + dc, b + db
        new_ll = loglik(u, n, k, new_c, new_b)
        for _ in range(30):  # halve until the likelihood does not decrease
            worse = ~(new_ll >= ll - 1e-12 * np.abs(ll))
            if not worse.any():
                break
            step = np.where(worse, 0.5, 1.0) * step
            new_c, new_b = c + step * dc, b + step * db
            new_ll = loglik(u, n, k, new_c, new_b)
        done = (np.abs(step * dc) < _TOL * (1 + np.abs(c))) & (
            np.abs(step * db) < _TOL * (1 + np.abs(b))
        )
        c, b, ll = new_c, new_b, new_ll
        ok |= done
        if ok.all():
            break
    return c - b * zc, b, ok & np.isfinite(b), n_iter


def _derivatives(z, n, k, a, b):
    """dℓ/dη and d²ℓ/dη² per level (η = a + b z), with Mills ratios in log space."""
    eta = a[:, None] + b[:, None] * z
    pdf = -0.5 * eta * eta - 0.5 * math.log(2 * math.pi)
    l1 = np.exp(pdf - log_ndtr(eta))  # φ/Φ(η)
    l2 = np.exp(pdf - log_ndtr(-eta))  # φ/Φ(-η)
    g = k * l1 - (n - k) * l2
    h = -k * l1 * (l1 + eta) - (n - k) * l2 * (l2 - eta)
    return g, h


def loglik(z, n, k, a, b):
    a, b = np.atleast_1d(a), np.atleast_1d(b)
    eta = a[:, None] + b[:, None] * z
    return np.sum(k * log_ndtr(eta) + (n - k) * log_ndtr(-eta), axis=1)


def saturated_loglik(n, k):
    with np.errstate(divide="ignore", invalid="ignore"):
        p = k / n
        terms = np.where(k > 0, k * np.log(p), 0.0) + np.where(k < n, (n - k) * np.log1p(-p), 0.0)
    return terms.sum()


def information(z, n, a, b):
    """Expected Fisher information of (a, b): Σ n φ²/(Φ(η)Φ(-η)) [1, z; z, z²]."""
    eta = a + b * z
    w = n * np.exp(-eta * eta - math.log(2 * math.pi) - log_ndtr(eta) - log_ndtr(-eta))
    return np.array([[w.sum(), (w * z).sum()], [(w * z).sum(), (w * z * z).sum()]])
