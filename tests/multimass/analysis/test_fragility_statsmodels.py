"""Lognormal fragility fits against statsmodels, a library this toolkit did not write.

A lognormal fragility curve P = Φ((ln x − ln θ)/β) fitted to binomial counts by maximum
likelihood is a probit GLM of the counts on (1, ln x) with a = −ln θ/β, b = 1/β
(Baker 2015, Earthquake Spectra 31(1)). statsmodels' GLM (Binomial family, probit link,
IRLS) gives (a, b), their covariance from the expected information, the log-likelihood
with the binomial constants, and the band of the mean as Φ(η ± z σ_η).
"""

import numpy as np
import pytest
import statsmodels.api as sm
from scipy.special import gammaln

from multimass.analysis.fragility import fit_lognormal

#: Counts of overturned runs per level: a curve rising through the levels, one with a
#: steep rise, and one with few runs per level.
DATA = [
    ([0.1, 0.2, 0.3, 0.4, 0.6, 0.8, 1.0], [20, 20, 25, 20, 20, 30, 20], [0, 2, 6, 9, 13, 25, 19]),
    ([0.5, 0.7, 0.9, 1.1, 1.3], [50, 50, 50, 50, 50], [1, 9, 27, 44, 49]),
    ([0.2, 0.4, 0.8, 1.6, 3.2], [5, 5, 5, 5, 5], [0, 1, 2, 4, 5]),
]


def _glm(levels, n, k):
    x = sm.add_constant(np.log(levels))
    family = sm.families.Binomial(link=sm.families.links.Probit())
    return sm.GLM(np.column_stack([k, np.subtract(n, k)]), x, family=family).fit(tol=1e-14)


@pytest.mark.parametrize("levels, n, k", DATA)
def test_fit_and_covariance_match_the_probit_glm(levels, n, k):
    fit = fit_lognormal(levels, n, k)
    res = _glm(levels, n, k)
    a, b = res.params
    assert fit.status == 0
    np.testing.assert_allclose(fit.theta, np.exp(-a / b), rtol=1e-9)
    np.testing.assert_allclose(fit.beta, 1.0 / b, rtol=1e-9)
    # Delta method from (a, b) to (ln θ, ln β) = (−a/b, −ln b).
    jac = np.array([[-1.0 / b, a / b**2], [0.0, -1.0 / b]])
    cov = jac @ res.cov_params() @ jac.T
    np.testing.assert_allclose(fit.cov, cov, rtol=1e-7, atol=1e-8 * np.max(np.diag(cov)))
    # Our log-likelihood leaves out the binomial coefficients ln C(n, k).
    const = np.sum(gammaln(np.add(n, 1)) - gammaln(np.add(k, 1)) - gammaln(np.subtract(n, k) + 1))
    np.testing.assert_allclose(fit.loglik + const, res.llf, rtol=1e-10)


@pytest.mark.parametrize("levels, n, k", DATA)
def test_confidence_band_matches_the_glm_prediction_interval(levels, n, k):
    fit = fit_lognormal(levels, n, k)
    x = np.geomspace(min(levels) / 2, max(levels) * 2, 9)
    band = fit.confidence(0.95, x)
    pred = _glm(levels, n, k).get_prediction(sm.add_constant(np.log(x))).conf_int(alpha=0.05)
    np.testing.assert_allclose(band.lower, pred[:, 0], rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(band.upper, pred[:, 1], rtol=1e-6, atol=1e-12)
