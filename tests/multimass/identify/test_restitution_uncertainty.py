"""What the restitution estimate says of its own uncertainty: the χ² test of the fit
against the trace's noise (an impact whose half-cycle the fit does not reproduce is
not estimated, a run that does not reproduce the trace makes its parameters
ill-posed), the 95 % interval of σ_r, and calibrate's σ_r from too few impacts."""

import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from scipy import stats

import multimass
from multimass import FreeRelease, modal
from multimass.identify import _parameter_status as ps
from multimass.identify import synthetic_trace
from multimass.identify._calibration_stats import (
    MODEL_REL_FLOOR,
    SLICE_RATIO,
    rough_reason,
    rough_std,
    slice_probe,
)
from multimass.identify._restitution_fit import (
    MISFIT_P,
    NOISE_TOL,
    consider_covariance,
    misfit_test,
    theta_misfit,
)
from multimass.identify._restitution_report import (
    _damping_shown,
    _entry,
    _explored,
    _misfit,
    consider_std,
    mean_std,
    sigma_interval,
)
from multimass.identify.calibration import Calibration
from multimass.identify.impacts import restitution
from multimass.inputs.traces import Trace


def test_white_noise_passes_the_misfit_test_at_its_false_alarm_rate():
    # residuals that are the noise itself: mean square / σ² is χ²_n / n (closed form),
    # above the limit with probability below MISFIT_P (the noise tolerance makes it less)
    rng = np.random.default_rng(0)
    sigma, n, trials = 0.002, 120, 4000
    flagged = 0
    for _ in range(trials):
        ratio, limit = theta_misfit(rng.normal(0.0, sigma, n), sigma)
        flagged += ratio > limit
    assert flagged / trials <= 3 * MISFIT_P
    # the limit is the χ² quantile (scipy's, an independent implementation) with the tolerance
    _, limit = theta_misfit(np.zeros(n), sigma)
    assert limit == pytest.approx(stats.chi2.ppf(1 - MISFIT_P, n) / n * (1 + NOISE_TOL))


def test_a_residual_the_noise_cannot_make_fails_the_misfit_test():
    # the noise plus an offset of one σ doubles the mean square: far above the limit
    rng = np.random.default_rng(1)
    sigma, n = 0.002, 200
    ratio, limit = theta_misfit(rng.normal(sigma, sigma, n), sigma)
    assert ratio == pytest.approx(2.0, rel=0.25) and ratio > limit


def _disturbed_after_third_impact(channel, add):
    """S1 DD2, 3 s (seed 1), with ``add(t, a, b)`` added to `channel` over the
    half-cycle (a, b) after the third impact: (the disturbed trace, a)."""
    syn = synthetic_trace("S1", FreeRelease(theta0=0.11), "DD2", 3.0, seed=1)
    tr = syn.trace
    hits = [e["t"] for e in syn.truth["impacts"]]
    t = np.asarray(tr.time)
    x = np.array(tr.channels[channel], dtype=float)
    a, b = hits[2], hits[3]
    m = (t > a) & (t < b)
    x[m] += add(t[m], a, b)
    trace = Trace(tr.time, dict(tr.channels) | {channel: x}, dict(tr.units),
                  source="bump.csv", specimen="S1")  # fmt: skip
    return trace, a


def test_an_impact_whose_half_cycle_the_model_cannot_follow_is_not_estimated():
    """S1 DD2, 3 s at 200 Hz, 2 % noise (σ_θ 0.0022 rad): a bump of ±0.008 rad added to θ
    over the half-cycle after the third impact, which no coefficient of the model makes.
    Measured over that half-cycle alone: its mean square 4.5 × the noise variance (the
    others 0.8–0.9), its r_std still 5e-4 — the covariance at the fit knows nothing of
    the bump. The χ² test over the two half-cycles that set an r takes that impact
    and the one before out of the estimated impacts, and the run's parameters are
    ill-posed (the whole span fails the test too)."""

    def bump(t, a, b):
        u = (t - a) / (b - a)
        return 0.008 * np.sin(np.pi * u) ** 2 * np.sign(np.sin(2 * np.pi * u))

    trace, a = _disturbed_after_third_impact("theta", bump)
    est = restitution(trace, "S1", "DD", progress=False, C_p=1750.0, zeta1=0.005, zeta2=0.015)
    rows = est.impacts
    bumped = int(np.argmin(np.abs(rows["t"].to_numpy() - a)))
    # the bumped half-cycle follows impact 2 and is the second of impact 1's test span
    assert not rows["estimated"].iloc[bumped] and not rows["estimated"].iloc[bumped - 1]
    assert rows["misfit"].iloc[bumped] > 1.0 and rows["misfit_channel"].iloc[bumped] == "theta"
    assert rows["estimated"].iloc[[0, bumped + 1, bumped + 2]].all()
    assert any("does not reproduce the trace" in w for w in est.warnings)
    assert est.status == ps.ILL_POSED
    assert "does not reproduce the trace" in est.parameters["theta0"]["reason"]


def test_a_run_that_fails_the_misfit_test_makes_its_estimates_ill_posed():
    out = {
        "cp": ps.estimated(1750.0, 0.01, log=True),
        "zeta1": ps.given(0.005),
        "theta0": ps.estimated(0.1, 1e-4),
    }
    _misfit(SimpleNamespace(misfit=(0.9, "theta")), out)  # passes: nothing changes
    assert out["cp"]["status"] == ps.ESTIMATED
    _misfit(SimpleNamespace(misfit=(4.0, "a_A1")), out)
    assert out["cp"]["status"] == ps.ILL_POSED and out["theta0"]["status"] == ps.ILL_POSED
    assert "a_A1's residual mean square 4 ×" in out["cp"]["reason"]
    assert out["zeta1"]["status"] == ps.GIVEN  # given stays given


def test_an_accelerometer_is_tested_against_its_own_residuals_before_the_first_impact():
    # both spans white noise of one variance: the ratio of their mean squares is
    # F(n, n_ref) (closed form), above the limit with probability MISFIT_P
    rng = np.random.default_rng(3)
    n, n_ref, trials, flagged = 150, 60, 4000, 0
    for _ in range(trials):
        ref = rng.normal(0.0, 0.3, n_ref)
        ratio, limit = misfit_test(rng.normal(0.0, 0.3, n), float(np.mean(ref**2)), n_ref)
        flagged += ratio > limit
    assert flagged / trials <= 3 * MISFIT_P
    assert limit == pytest.approx(stats.f.ppf(1 - MISFIT_P, n, n_ref))
    # twice the noise's RMS after the impact: far above
    ratio, limit = misfit_test(rng.normal(0.0, 0.6, n), 0.09, n_ref)
    assert ratio > limit


def test_sigma_interval_covers_the_spread_95_percent_of_the_time():
    # n coefficients on two corners, each drawn about its corner mean with spread σ and
    # estimated with its own error s: the interval holds σ in 95 % of draws (Monte Carlo)
    rng = np.random.default_rng(2)
    sigma, s, trials, held = 0.02, 0.006, 2000, 0
    for _ in range(trials):
        right = 0.93 + rng.normal(0, sigma, 5) + rng.normal(0, s, 5)
        left = 0.89 + rng.normal(0, sigma, 4) + rng.normal(0, s, 4)
        dev = np.concatenate([right - right.mean(), left - left.mean()])
        lo, hi = sigma_interval(dev, np.full(9, s), 2)
        held += lo <= sigma <= hi
    assert 0.93 <= held / trials <= 0.97
    # without the estimates' own share the interval is too high: it misses σ more often
    dev = np.array([0.02, -0.02] * 4 + [0.0])
    lo, hi = sigma_interval(dev, np.zeros(9), 2)
    lo_own, hi_own = sigma_interval(dev, np.full(9, 0.01), 2)
    assert hi_own < hi and lo_own < lo


def test_sigma_interval_needs_a_degree_of_freedom():
    assert sigma_interval([0.01, -0.01], [0.001, 0.001], 2) is None
    lo, hi = sigma_interval([0.01, -0.01, 0.0], [0.0, 0.0, 0.0], 1)
    # ν = 2, S = 2e-4: S / χ²₂(0.975) … S / χ²₂(0.025), χ²₂ quantiles −2 ln(1 − q)
    assert lo == pytest.approx(math.sqrt(2e-4 / (-2 * math.log(0.025))))
    assert hi == pytest.approx(math.sqrt(2e-4 / (-2 * math.log(0.975))))


def test_calibrate_sigma_r_from_fewer_than_three_impacts_is_not_estimated():
    two = SimpleNamespace(nuisance={"a": {"impacts": [{"deviation": 0.01}, {"deviation": -0.02}]}})
    assert Calibration._sigma_r(two) is None
    three = SimpleNamespace(
        nuisance={"a": {"impacts": [{"deviation": d} for d in (0.01, -0.02, 0.01)]}}
    )
    # pooled about the two corner means: sqrt(Σ d² / (n − 2))
    assert Calibration._sigma_r(three) == pytest.approx(math.sqrt(6e-4 / 1))


def test_a_noisy_hold_before_the_release_does_not_misplace_the_release():
    """The coverage benchmark's case S3-006 (seed 0, `multimass.bench.coverage_draws`):
    S3 held at 0.0767 rad until 0.284 s, 4.6 % noise, 263 Hz. The release time's first
    guess is the trace's first sample; least squares from there alone released the model
    from 0.100 rad at 0.184 s and left the r 0.02–0.06 off (r_std 1e-3). The scan of the
    release time finds it (measured: θ0 0.07681, clock 0.28388 s, every r within 0.0011)."""
    from multimass.bench.coverage_draws import draw_case, make_trace

    draw = draw_case("S3", 6, seed=0, family="DD", records=False)
    syn, _ = make_trace(draw)
    est = restitution(syn.trace, "S3", "DD", progress=False)
    assert est.alignment["theta0"] == pytest.approx(draw.theta0, abs=1e-3)
    assert est.alignment["t_offset"] == pytest.approx(draw.t_offset, abs=2e-3)
    truth = [(e["t"], e["corner"], 1.0 if e["r"] is None else e["r"]) for e in syn.truth["impacts"]]
    rows = est.impacts[est.impacts["estimated"]]
    assert len(rows) >= 8
    for _, row in rows.iterrows():
        near = min((x for x in truth if x[1] == row["corner"]), key=lambda x: abs(x[0] - row["t"]))
        assert abs(row["r"] - near[2]) <= 0.005


def test_an_accelerometer_the_model_cannot_follow_takes_its_impact_out():
    """The same S1 trace with θ as recorded and a_A1 disturbed instead over the
    half-cycle after the third impact (a 5 Hz sine of 0.75 m/s², 5 × its noise): θ passes, the
    F test of a_A1 against its residuals before the first impact does not."""
    trace, a = _disturbed_after_third_impact(
        "a_A1", lambda t, a, b: 0.75 * np.sin(2 * np.pi * 5.0 * (t - a))
    )
    est = restitution(trace, "S1", "DD", progress=False, C_p=1750.0, zeta1=0.005, zeta2=0.015)
    rows = est.impacts
    bumped = int(np.argmin(np.abs(rows["t"].to_numpy() - a)))
    assert not rows["estimated"].iloc[bumped]
    assert rows["misfit_channel"].iloc[bumped] == "a_A1"
    assert rows["estimated"].iloc[0]


def test_an_ill_posed_parameter_reports_the_range_its_fit_explored_not_a_95_interval():
    # ill-posed C_p (std beyond LIMITS) and θ0 (its run's misfit): each reports the bounds
    # of its least squares, no std; the estimated ζ1 keeps its 95 % interval
    track = SimpleNamespace(explored={"cp": (500.0, 1e4), "theta0": (0.07, 0.13),
                                      "zeta1": (1e-4, 0.2)})  # fmt: skip
    bad = ps.estimated(2100.0, 0.6, log=True, what="C_p") | {"status": ps.ILL_POSED,
                                                             "reason": "relative std 0.6"}  # fmt: skip
    th0 = ps.estimated(0.1003, 2e-5, what="θ0") | {"status": ps.ILL_POSED, "reason": "misfit"}
    out = {"cp": bad, "theta0": th0, "zeta1": ps.estimated(0.005, 0.02, log=True)}
    _explored(track, out)
    assert out["cp"]["interval"] == [500.0, 1e4] and out["cp"]["std"] is None
    assert out["cp"]["interval_kind"] == ps.EXPLORED == "explored range"
    assert out["cp"]["value"] == 2100.0 and "not an estimate" in out["cp"]["value_kind"]
    assert out["theta0"]["interval"] == [0.07, 0.13] and out["theta0"]["std"] is None
    assert out["zeta1"]["interval_kind"] == "95 %" and out["zeta1"]["std"] > 0
    # ζ1's 95 %: exp(log 0.005 ± 1.96 × 0.02) (the log-normal interval)
    assert out["zeta1"]["interval"][1] == pytest.approx(0.005 * math.exp(ps.Z95 * 0.02))
    text = ps.lines(out)
    assert "not fixed by the traces: anywhere in 500 … 10000" in text[0]
    assert "best fit 2100, not an estimate" in text[0] and "±" not in text[0]
    assert "95 %" in text[2] and "anywhere" not in text[2]


def test_theta0_carries_the_model_parameters_error_floor_through_their_covariance():
    # θ0 correlated with log ζ1 in the fit's covariance: an error δ of log ζ1 the noise
    # does not explain (MODEL_REL_FLOOR) moves θ0 by b δ, b = Σ_θζ / Σ_ζζ, so its
    # variance is Σ_θθ + b² F (the consider covariance, closed form for one parameter)
    s_th, s_z, rho = 5e-6, 4e-3, 0.8
    cov = {("theta0", "theta0"): s_th**2, ("zeta1", "zeta1"): s_z**2,
           ("theta0", "zeta1"): rho * s_th * s_z, ("zeta1", "theta0"): rho * s_th * s_z}  # fmt: skip
    track = SimpleNamespace(covariance=cov, estimate=("zeta1",), nuis={"theta0": 0.1},
                            std={"theta0": s_th, "zeta1": s_z})  # fmt: skip
    b = rho * s_th / s_z
    want = math.sqrt(s_th**2 + (b * MODEL_REL_FLOOR) ** 2)
    assert consider_std(track, "theta0") == pytest.approx(want, rel=1e-9) and want > 2 * s_th
    # reported, with the release angle's own floor beside it (0.05 % of θ0 = 0.1)
    entry = _entry(track, "theta0", False, None, {}, "θ0")
    assert entry["std"] == pytest.approx(math.hypot(want, 5e-4 * 0.1), rel=1e-9)
    # an independent calculation (Monte Carlo): linear least squares y = θ0 + s ζ + noise
    # with the parameter's total error e ~ N(0, Σ_ζζ + F) (its reported std, the floor
    # with it) and θ0 refitted with ζ held there: the spread of θ0 against consider_std
    rng = np.random.default_rng(3)
    n, sigma, floor = 50, 0.01, MODEL_REL_FLOOR
    A = np.column_stack([np.ones(n), np.linspace(0.0, 1.0, n)])
    joint = np.linalg.inv(A.T @ A) * sigma**2
    c = {("theta0", "theta0"): joint[0, 0], ("zeta1", "zeta1"): joint[1, 1],
         ("theta0", "zeta1"): joint[0, 1], ("zeta1", "theta0"): joint[0, 1]}  # fmt: skip
    tr = SimpleNamespace(covariance=c, estimate=("zeta1",), nuis={}, std={})
    m = 20000
    e = rng.normal(0.0, math.sqrt(joint[1, 1] + floor**2), m)
    noise = rng.normal(0.0, sigma, (m, n))
    x = (noise - np.outer(e, A[:, 1])).mean(axis=1)  # θ0's least squares, ζ held at e
    assert consider_std(tr, "theta0") == pytest.approx(np.std(x), rel=0.03)  # MC: 0.5 %
    assert np.std(x) > 1.5 * math.sqrt(joint[0, 0])  # the floor matters here


def _linear_fit(seed: int = 4):
    """A linear least squares y = A [r1, r2, p1, p2] + noise standing for the last fit:
    two coefficients and two model parameters, correlated through A (its columns
    overlap), and the joint covariance σ² (AᵀA)⁻¹."""
    rng = np.random.default_rng(seed)
    n, sigma = 60, 0.01
    u = np.linspace(0.0, 1.0, n)
    A = np.column_stack([np.ones(n), u, u**2 + 0.3 * rng.normal(size=n), np.sin(3 * u)])
    return A, sigma, np.linalg.inv(A.T @ A) * sigma**2


def test_consider_covariance_is_the_closed_form_for_one_parameter():
    # one parameter p considered: Σ + F b bᵀ with b = Σ_·p / Σ_pp (the regression on p),
    # its own variance Σ_pp + F; written out by hand here
    _, _, cov = _linear_fit()
    F = MODEL_REL_FLOOR**2
    got = consider_covariance(cov, [2])
    b = cov[:, 2] / cov[2, 2]
    assert got == pytest.approx(cov + F * np.outer(b, b), rel=1e-10, abs=1e-18)
    assert got[2, 2] == pytest.approx(cov[2, 2] + F, rel=1e-12)
    assert got[0, 1] != pytest.approx(cov[0, 1], rel=1e-3)  # the coefficients co-vary
    assert np.array_equal(consider_covariance(cov, []), cov)


def test_consider_covariance_matches_a_monte_carlo_of_the_parameters_held_off():
    # an independent calculation: the model parameters held at errors e ~ N(0, Σ_pp + F I)
    # (their reported uncertainty, the model's error floor with it) and the coefficients
    # refitted by least squares with them held: the coefficients' sample covariance and
    # that of their mean against consider_covariance (and `mean_std` from it)
    A, sigma, cov = _linear_fit()
    F = MODEL_REL_FLOOR**2
    rng = np.random.default_rng(5)
    m = 40000
    e = rng.multivariate_normal(np.zeros(2), cov[2:, 2:] + F * np.eye(2), m)
    y = rng.normal(0.0, sigma, (m, A.shape[0])) - e @ A[:, 2:].T
    x = np.linalg.lstsq(A[:, :2], y.T, rcond=None)[0].T  # r1, r2 with p held at e
    got = consider_covariance(cov, [2, 3])
    mc = np.cov(x.T)
    assert got[:2, :2] == pytest.approx(mc, rel=0.03)  # MC: ~1 % on 4e4 draws
    assert np.all(np.sqrt(np.diag(mc)) > 2 * np.sqrt(np.diag(cov)[:2]))  # the floor matters
    labels = ["r[0]", "r[1]"]
    track = SimpleNamespace(
        covariance={}, consider={(a, b): got[i, j] for i, a in enumerate(labels)
                                 for j, b in enumerate(labels)})  # fmt: skip
    rows = pd.DataFrame({"model_impact": [0, 1], "r_std": np.sqrt(np.diag(got)[:2])})
    w = np.array([1.0, 2.0])
    assert mean_std(track, rows, w) == pytest.approx(np.std(x @ w / w.sum()), rel=0.03)


def test_consider_covariance_leaves_unseen_directions_alone():
    # a parameter the data do not see (infinite variance, `covariance`'s rows of inf) is
    # not considered: its marginal variance is infinite already; the others' stay finite
    _, _, cov = _linear_fit()
    cov = cov.copy()
    cov[3, :] = cov[:, 3] = np.inf
    got = consider_covariance(cov, [2, 3])
    assert np.all(np.isfinite(got[:3, :3])) and np.isinf(got[3, 3])
    assert got[:3, :3] == pytest.approx(consider_covariance(cov[:3, :3], [2]), rel=1e-10)


def test_each_r_std_carries_the_model_parameters_error_floor(monkeypatch):
    # nothing given (C_p, ζ estimated): each impact's r_std is its variance in the last
    # fit's consider covariance (`consider_covariance`: the floor of log C_p and log ζ
    # carried through their regression), with the fit's floor, not the bare marginal
    from multimass.identify import _restitution_fit as fitting

    seen = {}
    fit = fitting.fit_impacts

    def keep(track, *args):
        seen["track"] = track
        seen["fitted"] = fit(track, *args)
        return seen["fitted"]

    monkeypatch.setattr(fitting, "fit_impacts", keep)
    syn = synthetic_trace("S1", FreeRelease(theta0=0.11), "DD2", 2.0, seed=4, C_p=2450.0)
    restitution(syn.trace, "S1", "DD", progress=False)
    track, fitted = seen["track"], seen["fitted"]
    labels = [lab for lab in dict.fromkeys(a for a, _ in track.covariance) if lab[:2] == "r["]
    cov = np.array([[track.covariance[(a, b)] for b in labels + list(track.estimate)]
                    for a in labels + list(track.estimate)])  # fmt: skip
    want = consider_covariance(cov, range(len(labels), cov.shape[0]))
    grew = 0
    for f in fitted.values():
        i = labels.index(f"r[{f.model_impact}]")
        floor = math.hypot(fitting.R_STD_FLOOR, fitting.R_STD_BOUNCE if f.bounce else 0.0)
        assert f.r_std == pytest.approx(math.hypot(math.sqrt(want[i, i]), floor), rel=1e-9)
        grew += want[i, i] > 1.01 * cov[i, i]
    assert grew >= 1


def test_slice_probe_trusts_a_quadratic_cost_and_not_a_neighbouring_minimum():
    # linear residuals f = A x − y: the cost rises by exactly ‖A_j h‖² (closed form)
    A = np.array([[1.0, 0.2], [0.3, 2.0], [0.5, -1.0]])
    x, y = np.array([0.4, -0.1]), np.array([0.1, 0.2, 0.3])
    f = lambda z: A @ z - y  # noqa: E731
    xs = np.linalg.lstsq(A, y, rcond=None)[0]
    probe = slice_probe(f, xs, f(xs), A, 1, 0.05)
    assert probe["trusted"] and probe["predicted"] == pytest.approx(np.sum((A[:, 1] * 0.05) ** 2))
    assert probe["rise"] == pytest.approx([probe["predicted"]] * 2, rel=1e-9)
    assert rough_std(1e-3, probe) >= 1e-3
    # a periodic residual sin(50 (z − x)): one period (h = 2π/50) away it is 0 again, a
    # neighbouring minimum the local Jacobian (slope 50) cannot see; the rise at ±h is 0
    # where ‖J h‖² = (2π)² is predicted
    g = lambda z: np.array([np.sin(50.0 * (z[0] - x[0])), 0.01 * (z[1] - x[1])])  # noqa: E731
    J = np.array([[50.0, 0.0], [0.0, 0.01]])
    probe = slice_probe(g, x, g(x), J, 0, 2 * np.pi / 50)
    assert not probe["trusted"] and max(probe["rise"]) < probe["predicted"] / SLICE_RATIO
    assert rough_std(1e-4, probe) >= 2 * np.pi / 50  # known no better than the probe's step
    assert "rough" in rough_reason(probe, " rad") and "rad" in rough_reason(probe, " rad")


def test_a_rough_theta0_is_ill_posed_with_the_probe_distance_as_its_std():
    track = SimpleNamespace(covariance={("theta0", "theta0"): 1e-12}, estimate=(),
                            nuis={"theta0": 0.0593}, std={"theta0": 1e-6},
                            rough={"theta0": {"step": 5.9e-4, "rise": [3.2e5, 1.7e5],
                                              "predicted": 1.7e7, "trusted": False,
                                              "secant_norm": 1.0, "jacobian_norm": 1.0}})  # fmt: skip
    entry = _entry(track, "theta0", False, None, {}, "θ0")
    assert entry["status"] == ps.ILL_POSED and "rough" in entry["reason"]
    assert entry["std"] == pytest.approx(5.9e-4)
    track.rough["theta0"]["trusted"] = True  # a smooth cost: the covariance's std, with
    entry = _entry(track, "theta0", False, None, {}, "θ0")  # 0.05 % of θ0 beside it
    assert entry["status"] == ps.ESTIMATED
    assert entry["std"] == pytest.approx(math.hypot(1e-6, 5e-4 * 0.0593))


def test_theta0_is_known_to_no_better_than_its_floor_and_the_others_have_none():
    # a fit's covariance of 1e-7 rad at θ0 = 0.12 rad: reported 0.05 % of θ0 = 6e-5 rad
    # (hypot), its 95 % interval θ0 ± 1.96 × that; the clock and the θ bias keep theirs
    track = SimpleNamespace(covariance={}, estimate=(), nuis={"theta0": 0.12, "t_offset": 0.2},
                            std={"theta0": 1e-7, "t_offset": 1e-7})  # fmt: skip
    entry = _entry(track, "theta0", False, None, {}, "θ0")
    assert entry["status"] == ps.ESTIMATED
    assert entry["std"] == pytest.approx(math.hypot(1e-7, 6e-5), rel=1e-12)
    lo, hi = entry["interval"]
    assert (lo, hi) == pytest.approx(
        (0.12 - 1.959964 * entry["std"], 0.12 + 1.959964 * entry["std"])
    )
    assert _entry(track, "t_offset", False, None, {}, "clock")["std"] == pytest.approx(1e-7)


@pytest.mark.parametrize("fs, zeta2_status", [(120.0, ps.ILL_POSED), (300.0, ps.ESTIMATED)])
def test_zeta2_needs_the_trace_to_show_mode_2(fs, zeta2_status):
    # S2's full-contact modes are at 5.2 and 97.9 Hz, its uplifted ones at 20.5 and
    # 100.1 Hz (`modal.analyse` of the bundled S2, the analysis tests/modal checks
    # against paper 001 §4.2): at 120 Hz the anti-alias passband (0.4 fs = 48 Hz) keeps
    # modes 1 only, at 300 Hz (120 Hz) both — asserted below from the analysis itself
    st = multimass.column("S2")
    model = modal.analyse(st)
    assert max(model.full_contact.freq_hz[1], model.rocking.freq_hz[1]) < 0.4 * 300.0
    assert min(model.full_contact.freq_hz[1], model.rocking.freq_hz[1]) > 0.4 * 120.0
    case = SimpleNamespace(free=True, fs=fs, segments=SimpleNamespace(full_contact=((0, 9),)),
                           trace=SimpleNamespace(source="trace.csv"))  # fmt: skip
    track = SimpleNamespace(case=case, sim=SimpleNamespace(st=st))
    out = {n: ps.estimated(0.01, 0.05, log=True) for n in ("zeta1", "zeta2")}
    _damping_shown(track, out)
    assert out["zeta1"]["status"] == ps.ESTIMATED
    assert out["zeta2"]["status"] == zeta2_status
    if zeta2_status == ps.ILL_POSED:
        assert "mode 2" in out["zeta2"]["reason"] and "do not show" in out["zeta2"]["reason"]


def test_a_parameter_that_could_not_be_estimated_makes_the_result_ill_posed():
    """A parameter left at the specimen file's value because nothing could estimate it
    (no impact fitted) is not an estimate: the result is ill-posed and says which and
    why, where it said "every parameter not given was estimated"."""
    params = {"cp": ps.estimated(1750.0, 0.01, log=True), "zeta1": ps.given(0.005)}
    assert ps.overall(params)[0] == ps.ESTIMATED
    params["zeta2"] = ps.not_estimated(0.015, "ζ2", "no impact fitted to estimate it")
    status, message = ps.overall(params)
    assert status == ps.ILL_POSED
    assert "zeta2: no impact fitted to estimate it (the specimen file's value stands in)" in message
    assert params["zeta2"]["status"] == ps.FIXED and params["zeta2"]["value"] == 0.015
    # a parameter the user left out of the fit is fixed, and no reason for ill-posed
    assert ps.overall({"cp": ps.fixed(1750.0, "C_p", "not in the fit list")})[0] == ps.ESTIMATED


def test_a_table_motion_trace_with_no_impact_fitted_is_not_reported_estimated():
    """Coverage draw S2-044 (seed 0: Northridge 1994 window, 271 Hz, C_p × 0.66): the model
    at the specimen's values has no impact near the trace's first one (14 ms from it),
    so no impact is fitted and C_p, ζ1, ζ2 keep the file's values. Reported as
    "estimated, every parameter not given was estimated" before; ill-posed now."""
    from pathlib import Path

    from multimass.bench.coverage_cases import make_trace
    from multimass.bench.coverage_draws import draw_case

    records = Path(__file__).resolve().parents[3] / "examples" / "data" / "records"
    draw = draw_case("S2", 44, 0, "DD", records=True)
    syn, _ = make_trace(draw, records)
    est = restitution(syn.trace, "S2", "DD", progress=False)
    assert not est.impacts["estimated"].any()  # the case this test is about
    assert est.status == ps.ILL_POSED
    for name in ("cp", "zeta1", "zeta2"):
        assert est.parameters[name]["not_estimated"] == "no impact fitted to estimate it"
        assert f"{name}: no impact fitted" in est.message
    # under table motion the clock is the trace's (the recorded ag): no offset to fit
    assert est.parameters["t_offset"]["status"] == ps.NOT_USED
    assert est.parameters["theta0"]["status"] == ps.NOT_USED
