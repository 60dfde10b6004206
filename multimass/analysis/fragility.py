"""Fragility curves by maximum likelihood: a lognormal CDF fitted to counts of exceedance.

At each intensity level ``x_j`` a number of runs ``n_j`` was made and ``k_j`` of them
exceeded the damage state (overturned, or θ/α above a threshold). The fragility model is

    P(exceed | IM = x) = Φ(ln(x/θ) / β),          (Baker 2015, the lognormal model)

with median θ and log standard deviation β, and the counts are binomial, so θ and β
maximise the log-likelihood

    ℓ(θ, β) = Σ_j [k_j ln p_j + (n_j - k_j) ln(1 - p_j)],  p_j = Φ(ln(x_j/θ)/β)
                                      (Baker 2015, binomial likelihood)

(the binomial coefficients are constants and are left out of ℓ). In the variables
``η = a + b ln x`` (``b = 1/β``, ``a = -ln θ / β``) this is a probit regression whose
log-likelihood is concave, so a damped Newton iteration from a least-squares start finds
the maximum when it exists. Many fits (bootstrap resamples) are solved at once, as arrays.

The maximum does not exist, and no number is returned for it, when

* no run exceeds at any level (θ lies above the highest level; status 1),
* every run exceeds at every level (θ lies below the lowest level; status 2),
* the data are separated: every level with a non-exceedance lies at or below every level
  with an exceedance (β → 0; θ is only bounded, status 3),
* all runs are at one level (θ and β cannot both be identified; status 4),
* exceedance does not increase with the IM (the slope 1/β would be ≤ 0, or is zero
  within the iteration's tolerance — flat counts — ; status 5).

`FragilityFit.status` and `.message` say which, and `.theta_bounds` gives what the data
do say about θ. Invalid input (levels ≤ 0 or non-finite, counts that are negative,
non-integer, or above the number of runs) raises `multimass.errors.InputError`.

Confidence bands come two ways: asymptotic, from the Fisher information at the optimum
(`FragilityFit.confidence`, delta method on ln θ and ln β), and by a seeded bootstrap
that resamples the runs *within each level* with replacement, i.e. draws
``k*_j ~ Binomial(n_j, k_j/n_j)`` (`FragilityFit.bootstrap`, percentile intervals).

References
----------
J. W. Baker (2015), Efficient analytical fragility function fitting using dynamic
structural analysis, Earthquake Spectra 31(1), 579–599.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.special import ndtr, ndtri

from ..errors import InputError
from ._probit import fit_many as _fit_many
from ._probit import information as _information
from ._probit import loglik as _loglik
from ._probit import saturated_loglik as _saturated_loglik

__all__ = ["STATUS", "Band", "FragilityFit", "fit_lognormal"]

#: Status codes of `FragilityFit` and what they mean.
STATUS = {
    0: "converged: the maximum-likelihood estimate exists and was found",
    1: "no run exceeded at any level",
    2: "every run exceeded at every level",
    3: "separated data: β → 0",
    4: "a single intensity level: θ and β are not both identifiable",
    5: "exceedance does not increase with the intensity measure",
    6: "the Newton iteration did not converge",
}


# --------------------------------------------------------------------------- results
@dataclass(frozen=True)
class Band:
    """A confidence band of a fragility fit.

    Attributes
    ----------
    method : str
        ``"fisher"`` (asymptotic, delta method) or ``"bootstrap"`` (percentile).
    level : float
        Two-sided confidence level, e.g. 0.95.
    theta, beta : tuple of float
        (lower, upper) bounds of θ and β.
    x : ndarray
        Intensity levels at which the curve band is given.
    lower, upper : ndarray
        Band of P(exceed | x) at `x`.
    n_resamples, n_degenerate : int
        Bootstrap resamples drawn, and how many of them had no finite maximum (their
        separated cases enter with β = 0 and θ at the geometric middle of its bounds; the
        all-zero, all-one and decreasing ones are left out). Zero for ``"fisher"``.
    """

    method: str
    level: float
    theta: tuple[float, float]
    beta: tuple[float, float]
    x: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    n_resamples: int = 0
    n_degenerate: int = 0


@dataclass(frozen=True)
class FragilityFit:
    """A lognormal fragility curve fitted by maximum likelihood (`fit_lognormal`).

    Attributes
    ----------
    theta : float
        Median θ, in the units of the levels (nan when `status` ≠ 0, except a separated
        fit whose bounds coincide).
    beta : float
        Log standard deviation β (0.0 for separated data, nan for the other statuses).
    loglik : float
        Maximised log-likelihood (Baker 2015, binomial, without its constants).
    converged : bool
        True when the maximum exists and was found (status 0).
    status : int
        See `STATUS`.
    message : str
        What happened and what to do about it.
    theta_bounds : tuple of float
        What the data say about θ: (θ, θ) when converged, otherwise an interval.
    levels, n_runs, n_exceed : ndarray
        The data fitted.
    cov : ndarray or None
        Asymptotic covariance of (ln θ, ln β) from the Fisher information.
    n_iter : int
        Newton iterations used.
    """

    theta: float
    beta: float
    loglik: float
    converged: bool
    status: int
    message: str
    theta_bounds: tuple[float, float]
    levels: np.ndarray = field(repr=False)
    n_runs: np.ndarray = field(repr=False)
    n_exceed: np.ndarray = field(repr=False)
    cov: np.ndarray | None = field(default=None, repr=False)
    n_iter: int = 0

    def probability(self, x) -> np.ndarray:
        """P(exceed | IM = x) = Φ(ln(x/θ)/β) (a step at θ when β = 0)."""
        x = np.asarray(x, dtype=float)
        return _curve(x, np.atleast_1d(self.theta), np.atleast_1d(self.beta))[0].reshape(x.shape)

    def as_dict(self) -> dict:
        """The fit as plain JSON-ready values (nan and inf become None)."""

        def clean(v):
            return v if math.isfinite(v) else None

        return {
            "theta": clean(self.theta),
            "beta": clean(self.beta),
            "loglik": clean(self.loglik),
            "converged": self.converged,
            "status": self.status,
            "message": self.message,
            "theta_bounds": [clean(float(b)) for b in self.theta_bounds],
            "levels": self.levels.tolist(),
            "n_runs": self.n_runs.tolist(),
            "n_exceed": self.n_exceed.tolist(),
            "n_iter": self.n_iter,
        }

    def _require(self, what: str):
        if not self.converged:
            raise InputError(f"no {what} for a fit without a maximum: {self.message}")

    def confidence(self, level: float = 0.95, x=None) -> Band:
        """Asymptotic band from the Fisher information (delta method on ln θ, ln β).

        Intervals are symmetric on the log scale, ``exp(ln θ ± z σ)``; the curve band is
        ``Φ(η(x) ± z σ_η(x))`` with ``η = a + b ln x``.

        Raises
        ------
        multimass.errors.InputError
            A fit without a maximum (`status` ≠ 0), or counts so weak that an interval
            of θ or β has no finite end.
        """
        self._require("confidence band")
        q = _quantile(level)
        sd = np.sqrt(np.diag(self.cov))
        lt, lb = math.log(self.theta), math.log(self.beta)
        ends = np.array([lt, lt, lb, lb]) + q * np.repeat(sd, 2) * np.array([-1, 1, -1, 1])
        if not np.all(np.isfinite(ends) & (np.abs(ends) < 700.0)):  # exp(±700) ~ 1e±304
            raise InputError(
                f"no {level:g} confidence band: the counts leave ln θ ± {sd[0]:.3g} and "
                f"ln β ± {sd[1]:.3g} (one σ), an interval without a finite end; add levels "
                "or runs where the curve rises, or use bootstrap()"
            )
        x = self._grid(x)
        a, b = -lt / self.beta, 1.0 / self.beta
        cov_ab = _cov_ab(a, b, self.cov)
        z = np.log(x)
        eta = a + b * z
        s_eta = np.sqrt(cov_ab[0, 0] + 2 * z * cov_ab[0, 1] + z * z * cov_ab[1, 1])
        return Band(
            "fisher",
            level,
            (math.exp(lt - q * sd[0]), math.exp(lt + q * sd[0])),
            (math.exp(lb - q * sd[1]), math.exp(lb + q * sd[1])),
            x,
            ndtr(eta - q * s_eta),
            ndtr(eta + q * s_eta),
        )

    def bootstrap(
        self, n_resamples: int = 1000, level: float = 0.95, seed: int = 0, x=None
    ) -> Band:
        """Percentile band from resampling the runs within each level (seeded).

        Each resample draws ``k*_j ~ Binomial(n_j, k_j/n_j)`` — the same as drawing the
        ``n_j`` runs of level j with replacement — and is refitted; all resamples are
        fitted together as arrays.
        """
        self._require("bootstrap band")
        if int(n_resamples) < 10:
            raise InputError(f"`n_resamples` must be ≥ 10; got {n_resamples!r}.")
        q = _quantile(level)  # validates level
        del q
        rng = np.random.default_rng(seed)
        p = self.n_exceed / self.n_runs
        k = rng.binomial(self.n_runs, p, size=(int(n_resamples), p.size))
        theta, beta, status, bounds = _fit_many(np.log(self.levels), self.n_runs, k)
        sep = status == 3
        theta = np.where(sep, np.sqrt(bounds[0] * bounds[1]), theta)
        beta = np.where(sep, 0.0, beta)
        keep = (status == 0) | sep
        lo, hi = (1 - level) / 2, (1 + level) / 2
        x = self._grid(x)
        curves = _curve(x, theta[keep], beta[keep])
        qs = [lo, hi]
        th = np.quantile(theta[keep], qs, method="inverted_cdf")
        be = np.quantile(beta[keep], qs, method="inverted_cdf")
        band = np.quantile(curves, qs, axis=0, method="inverted_cdf")
        return Band(
            "bootstrap",
            level,
            (float(th[0]), float(th[1])),
            (float(be[0]), float(be[1])),
            x,
            band[0],
            band[1],
            int(n_resamples),
            int(np.count_nonzero(status != 0)),
        )

    def _grid(self, x):
        if x is None:
            lo, hi = np.min(self.levels), np.max(self.levels)
            return np.geomspace(lo / 2, hi * 2, 101)
        x = np.atleast_1d(np.asarray(x, dtype=float))
        if np.any(~np.isfinite(x) | (x <= 0)):
            raise InputError("`x` must hold finite intensity levels > 0.")
        return x


# ----------------------------------------------------------------------- the fit
def fit_lognormal(levels, n_runs, n_exceed) -> FragilityFit:
    """Fit ``P(exceed | x) = Φ(ln(x/θ)/β)`` to binomial counts by maximum likelihood.

    Parameters
    ----------
    levels : array_like, shape (m,)
        Intensity-measure levels x_j (> 0, any units; θ comes in the same units).
        Repeated levels are allowed.
    n_runs : int or array_like, shape (m,)
        Runs at each level (≥ 1); one integer for all levels.
    n_exceed : array_like, shape (m,)
        Runs that exceeded the damage state at each level, 0 ≤ k_j ≤ n_j.

    Returns
    -------
    FragilityFit
        ``theta``, ``beta``, ``loglik``, ``converged``, ``status``, ``message`` and the
        bands `FragilityFit.confidence` (Fisher) and `FragilityFit.bootstrap`.

    Raises
    ------
    multimass.errors.InputError
        Levels non-finite or ≤ 0, counts negative or not integers, ``n_exceed > n_runs``,
        mismatched lengths, or no levels.

    References
    ----------
    J. W. Baker (2015), Earthquake Spectra 31(1), 579–599 (not in papers/; equation numbers not checked).
    """
    x, n, k = _validate(levels, n_runs, n_exceed)
    z = np.log(x)
    theta, beta, status, bounds, a, b, it = _fit_many(z, n, k[None, :], details=True)
    st = int(status[0])
    bounds_t = (float(bounds[0][0]), float(bounds[1][0]))
    th, be = float(theta[0]), float(beta[0])
    cov, ll = None, float("nan")
    if st == 0:
        cov_ab = np.linalg.inv(_information(z, n, a[0], b[0]))
        J = np.array([[-1.0 / b[0], a[0] / b[0] ** 2], [0.0, -1.0 / b[0]]])
        cov = J @ cov_ab @ J.T
        ll = float(_loglik(z, n, k, a[0], b[0])[0])
        bounds_t = (th, th)
    elif st == 3:
        ll = float(_saturated_loglik(n, k))
        be = 0.0
        th = bounds_t[0] if bounds_t[0] == bounds_t[1] else float("nan")
    elif st in (4, 5, 6):
        bounds_t = (0.0, math.inf)
    return FragilityFit(
        th,
        be,
        ll,
        st == 0,
        st,
        _message(st, bounds_t, it),
        bounds_t,
        x,
        n,
        k,
        cov,
        int(it),
    )


def _validate(levels, n_runs, n_exceed):
    x = np.atleast_1d(np.asarray(levels, dtype=float))
    if x.ndim != 1 or x.size == 0:
        raise InputError(f"`levels` must be a non-empty 1-D array; got shape {x.shape}.")
    bad = np.flatnonzero(~np.isfinite(x) | (x <= 0))
    if bad.size:
        raise InputError(
            f"`levels` must be finite and > 0 (the fragility is lognormal in the IM); "
            f"levels[{bad[0]}] = {x[bad[0]]}. Drop that level or fix its intensity."
        )
    n = np.broadcast_to(_counts("n_runs", n_runs), x.shape).copy()
    k = _counts("n_exceed", n_exceed)
    if k.shape != x.shape:
        raise InputError(f"`n_exceed` needs one count per level: {x.size} levels, {k.size} counts.")
    bad = np.flatnonzero(n < 1)
    if bad.size:
        raise InputError(
            f"level {x[bad[0]]:g} has n_runs = {n[bad[0]]}; every level needs ≥ 1 run "
            "(drop the levels no run reached)."
        )
    bad = np.flatnonzero(k > n)
    if bad.size:
        j = bad[0]
        raise InputError(
            f"at level {x[j]:g}, n_exceed = {k[j]} is more than n_runs = {n[j]}; "
            "check the counts (exceedances are a subset of the runs)."
        )
    return x, n, k


def _counts(name, value):
    c = np.atleast_1d(np.asarray(value, dtype=float))
    if np.any(~np.isfinite(c)) or np.any(c != np.round(c)) or np.any(c < 0):
        raise InputError(f"`{name}` must hold non-negative integers; got {value!r}.")
    return c.astype(np.int64)


def _message(status, bounds, it):
    lo, hi = bounds
    if status == 0:
        return f"converged in {it} Newton iterations"
    if status == 1:
        return (
            f"{STATUS[1]}: θ lies above the highest level ({lo:g}) and β is unknown. "
            "Add levels above it, or report 'P(exceed) < 1/n at every level'."
        )
    if status == 2:
        return (
            f"{STATUS[2]}: θ lies below the lowest level ({hi:g}) and β is unknown. "
            "Add levels below it."
        )
    if status == 3:
        head = (
            f"{STATUS[3]} (every level with a non-exceedance lies at or below every level "
            "with an exceedance)"
        )
        if lo == hi:
            return f"{head}; θ = {lo:g}, β unknown. Add levels on either side of it."
        return f"{head}; θ lies between {lo:g} and {hi:g}. Add levels inside that range."
    if status == 4:
        return f"{STATUS[4]}. Run at least two distinct levels."
    if status == 5:
        return (
            f"{STATUS[5]}; a fragility curve (β > 0) does not fit these counts. Check that "
            "levels and counts are paired correctly."
        )
    return f"{STATUS[6]} in {it} iterations; report this data set."


def _cov_ab(a, b, cov_lt_lb):
    """Covariance of (a, b) back from that of (ln θ, ln β): a = -ln θ/β, b = 1/β."""
    beta = 1.0 / b
    lt = -a / b
    J = np.array([[-1.0 / beta, lt / beta], [0.0, -1.0 / beta]])  # d(a, b)/d(ln θ, ln β)
    return J @ cov_lt_lb @ J.T


def _curve(x, theta, beta):
    """P(exceed | x) for each (θ, β) row: shape (len(theta), len(x)); β = 0 is a step."""
    lx = np.log(np.ravel(x))[None, :]
    lt = np.log(theta)[:, None]
    be = beta[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        p = ndtr((lx - lt) / be)
    step = np.where(lx > lt, 1.0, np.where(lx < lt, 0.0, 0.5))
    return np.where(be == 0, step, p)


def _quantile(level):
    lv = float(level)
    if not (0 < lv < 1):
        raise InputError(f"`level` is a confidence level in (0, 1), e.g. 0.95; got {level!r}.")
    return float(ndtri(0.5 + lv / 2))
