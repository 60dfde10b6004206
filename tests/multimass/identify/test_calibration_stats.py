"""calibrate's covariance (`multimass.identify._calibration_stats.covariance`): each
channel's rows whitened by their RMS and down-weighted by the AR(1) variance inflation
(1 + ρ₁) / (1 − ρ₁), checked on the simplest least squares — a constant fitted to
autocorrelated noise, whose sample mean's variance has a closed form."""

import numpy as np
import pytest
from scipy import signal

from multimass.identify._calibration_stats import covariance, lag1


def _ar1(rng, rho: float, shape) -> np.ndarray:
    """Stationary AR(1) noise of unit variance: e_t = ρ e_(t−1) + √(1 − ρ²) w_t."""
    w = rng.normal(0.0, 1.0, shape)
    w[..., 0] /= np.sqrt(1.0 - rho**2)  # the first sample from the stationary law
    return signal.lfilter([np.sqrt(1.0 - rho**2)], [1.0, -rho], w, axis=-1)


def _mean_variance(e: np.ndarray, prior: np.ndarray | None = None) -> float:
    """The variance `covariance` gives a constant fitted to `e` (residual y − μ: the
    Jacobian is −1 on every row), with optional prior rows of a second unknown."""
    n = e.shape[-1]
    rows = {("t", "a_A1"): e - e.mean()}
    J = -np.ones((n, 1))
    if prior is not None:
        rows[("t", "prior")] = prior
        J = np.block([[J, np.zeros((n, 1))], [np.zeros((prior.size, 1)), np.ones((prior.size, 1))]])
    cov, _ = covariance(J, rows, np.ones(J.shape[1]))
    return float(cov[0, 0])


def _ar1_mean_variance(n: int, rho: float) -> float:
    """Var(ȳ) of n samples of a unit-variance stationary AR(1): (1/n²)[n + 2 Σ_(k=1)^(n−1)
    (n − k) ρ^k] (Box, Jenkins & Reinsel, Time Series Analysis, 4th ed., Sec 2.1.5: the
    variance of a mean of autocorrelated observations)."""
    k = np.arange(1, n)
    return float(n + 2.0 * np.sum((n - k) * rho**k)) / n**2


@pytest.mark.parametrize("rho", [0.3, 0.6, 0.85])
def test_ar1_residuals_give_the_mean_the_closed_form_variance(rho):
    rng = np.random.default_rng(7)
    n = 40_000
    e = _ar1(rng, rho, n)
    got = _mean_variance(e)
    # reference: the closed form with the true ρ and σ = 1 (Box et al. Sec 2.1.5); the
    # estimate's own ρ₁ and RMS differ from them by their sampling error (≤ 2 % here)
    assert got == pytest.approx(_ar1_mean_variance(n, rho), rel=0.06)
    assert lag1(e) == pytest.approx(rho, abs=0.02)


def test_the_variance_matches_a_monte_carlo_of_the_mean():
    # 4000 series of 400 samples, ρ = 0.7: the spread of their sample means (the truth
    # of what the fit's noise does) against the mean variance the covariance reports
    rng = np.random.default_rng(11)
    e = _ar1(rng, 0.7, (4000, 400))
    empirical = float(np.var(e.mean(axis=1), ddof=1))
    reported = np.mean([_mean_variance(row) for row in e[:400]])
    # sampling error of the empirical variance: √(2/3999) ≈ 2.2 %; the reported one
    # carries ρ₁'s small-sample bias −(1 + 3ρ)/n ≈ −0.008 (Kendall 1954), ≈ −3 % on
    # the factor (1 + ρ)/(1 − ρ)
    assert reported == pytest.approx(empirical, rel=0.08)
    white = 1.0 / 400  # what a fit that took the rows for white noise would report
    assert empirical > 4.0 * white  # the case is one where the inflation matters


def test_white_residuals_are_not_inflated():
    rng = np.random.default_rng(3)
    n = 20_000
    e = rng.normal(0.0, 2.0, n)
    got = _mean_variance(e)
    # σ²/n with the rows' own mean square (the ordinary least-squares variance)
    assert got == pytest.approx(float(np.mean((e - e.mean()) ** 2)) / n, rel=0.03)


def test_prior_rows_keep_unit_weight_and_get_no_inflation():
    rng = np.random.default_rng(5)
    e = _ar1(rng, 0.8, 5000)
    prior = np.array([0.4, -0.9, 1.7])  # residuals δ/σ_r: smooth or not, not noise
    rows = {("t", "a_A1"): e - e.mean(), ("t", "prior"): prior}
    n = e.size
    J = np.block([[-np.ones((n, 1)), np.zeros((n, 1))], [np.zeros((3, 1)), np.ones((3, 1))]])
    cov, info = covariance(J, rows, np.ones(2))
    assert info[("t", "prior")] == {"rho1": 0.0, "inflation": 1.0}
    assert cov[1, 1] == pytest.approx(1.0 / 3.0, rel=1e-12)  # (Σ 1²)⁻¹, the prior alone
    rho = info[("t", "a_A1")]["rho1"]
    assert info[("t", "a_A1")]["inflation"] == pytest.approx((1 + rho) / (1 - rho), rel=1e-12)
