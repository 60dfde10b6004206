"""The goodness-of-fit test of `restitution` and `calibrate`: does a fit reproduce the trace?

A least-squares fit's covariance is a curvature at the point where it stopped; where
that point is not the trace's parameters it says nothing of their error. `misfit_test`
compares the residuals' mean square with the variance a fit at the trace's parameters
leaves (θ: the trace's noise, `theta_misfit`; an accelerometer: its own residuals
before the first impact, where no restitution and no C_p act) and says when the fit
does not reproduce the trace.
"""

from __future__ import annotations

import numpy as np
from scipy import stats

__all__ = ["misfit_test", "theta_misfit", "MISFIT_P", "NOISE_TOL", "THETA_MODEL_FLOOR", "REF_MIN"]

#: The goodness-of-fit test (`misfit_test`): a fit whose θ residual's mean square over
#: a span exceeds the trace's noise variance by more than the χ² quantile of this upper
#: tail probability (and `NOISE_TOL`), or an accelerometer's exceeds its mean square
#: before the first impact by more than the F quantile, does not reproduce the trace
#: there. Its
#: covariance, a curvature at a point that is not the trace's, says nothing of the
#: error: on synthetic S2 (C_p 1.02 × Table 2's, 233 Hz, 2 % noise) a fit stuck with C_p
#: 11 % high left θ residuals 2.3–7 × the noise's RMS from the second impact on, and its
#: r 0.02–0.04 off with r_std 6e-4; at the truth the same spans were at 0.94–1.10 ×
#: (the accelerometers' too: 0.33–0.35 m/s² for a noise of 0.33 on a_A1).
MISFIT_P = 1e-3
#: … the relative tolerance on the noise variance the trace gives (`Segments.noise`,
#: a robust spread of θ less its low-passed self; 0.88–1.22 × at the truth over single
#: half-cycles of that trace, within the χ² quantile of their 116–230 samples)
NOISE_TOL = 0.1
#: … and a floor of the θ noise (rad), added in quadrature, that keeps the test of a
#: noiseless trace finite: the fit's θ error there is the model's alone (runs recorded
#: at 10 × the trace's rate, the synthetic traces at 40 ×), 3e-8 rad RMS on noiseless
#: S1 (DD2, 0.11 rad, 200 Hz, 4 s)
THETA_MODEL_FLOOR = 1e-5
#: The fewest samples before the first impact that test the accelerometers (their
#: reference mean square; fewer: the accelerometers are not tested)
REF_MIN = 20


def theta_misfit(e: np.ndarray, noise: float) -> tuple[float, float]:
    """`misfit_test` of the θ residuals `e` against the trace's noise `noise` (rad, with
    `THETA_MODEL_FLOOR` in quadrature).

    A ratio above its limit says the fit is not at the trace's parameters (or the model
    cannot follow it) there; its covariance then does not bound the error."""
    return misfit_test(e, noise**2 + THETA_MODEL_FLOOR**2)


def misfit_test(e: np.ndarray, var: float, n_ref: int | None = None) -> tuple[float, float]:
    """(ratio, limit): the mean square of the residuals `e` over the variance `var` of
    a fit that reproduces the trace, and the largest ratio such a fit leaves with
    probability 1 − `MISFIT_P` (white noise: each residual one sample of it).

    `var` known (the trace's noise, `n_ref` None): the χ² quantile of the residuals'
    count n over n, times 1 + `NOISE_TOL` for the noise's estimate. `var` itself a mean
    square of `n_ref` residuals of the same fit (an accelerometer before the first
    impact, where no restitution acts): the F(n, n_ref) quantile.
    """
    e = np.asarray(e, dtype=float)
    n = max(e.size, 1)
    ratio = float(np.mean(e * e)) / var if e.size else 0.0
    if n_ref is None:
        limit = float(stats.chi2.ppf(1.0 - MISFIT_P, n) / n) * (1.0 + NOISE_TOL)
    else:
        limit = float(stats.f.ppf(1.0 - MISFIT_P, n, max(n_ref, 1)))
    return ratio, limit
