"""Intensity measures: closed forms, an independent time stepping, and bad input."""

from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from multimass.analysis.intensity import (
    arias_intensity,
    ground_motion,
    intensity_measure,
    pga,
    pgd,
    pgv,
    scale_to,
    spectral_acceleration,
)
from multimass.errors import InputError
from multimass.model._nigam_jennings import coefficients

ELCENTRO = Path(__file__).resolve().parents[3] / "examples" / "data" / "elcentro_1940_NS_15s.dat"
G = 9.81


@pytest.mark.parametrize("wh", [1.0, 0.1, 0.049, 1e-3, 1e-5, 0.0])
@pytest.mark.parametrize("z", [0.0, 0.05, 0.5, 0.95])
def test_recurrence_equals_matrix_exponential(wh, z):
    # independent: the exact map of the augmented linear system [u, u̇, a, ȧ] (ȧ constant);
    # small ωh exercises the series that replaces the cancelling closed forms
    from scipy.linalg import expm

    w = 2 * np.pi / 0.7
    h = wh / w
    a11, a12, a21, a22, b11, b12, b21, b22 = coefficients(w, z, h)
    got = np.array([[a11, a12, b11, b12], [a21, a22, b21, b22]], dtype=float)
    if h == 0:
        np.testing.assert_array_equal(got, [[1, 0, 0, 0], [0, 1, 0, 0]])
        return
    M = np.array([[0, 1, 0, 0], [-w * w, -2 * z * w, -1, 0], [0, 0, 0, 1], [0, 0, 0, 0.0]])
    to_ends = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, -1 / h, 1 / h]])
    ref = (expm(M * h) @ to_ends)[:2]  # columns: u, u̇, a_i, a_{i+1}
    np.testing.assert_allclose(got, ref, rtol=1e-11, atol=1e-15 * np.abs(ref).max())


def test_sa_of_a_harmonic_input_is_the_steady_state_amplitude():
    # a_g = A sin Ωt with a slow cosine ramp (60 s), then 60 s steady: the peak is the
    # steady state ω²|H(ω)| A, |H| = 1/sqrt((ω²-Ω²)² + (2ζωΩ)²). The straight lines through
    # samples h apart carry the fundamental scaled by sinc²(Ωh/2) (triangle-kernel filter).
    z, Om, A, h = 0.05, 2 * np.pi / 0.7, 1.0, 0.01
    t = np.arange(0, 120, h)
    ramp = 0.5 - 0.5 * np.cos(np.pi * np.clip(t / 60, 0, 1))
    ag = A * np.sin(Om * t) * ramp
    T = np.array([0.2, 0.5, 0.7, 1.0, 2.0])
    w = 2 * np.pi / T
    H = 1 / np.sqrt((w**2 - Om**2) ** 2 + (2 * z * w * Om) ** 2)
    x = Om * h / 2
    closed = w * w * H * A * (np.sin(x) / x) ** 2
    sa = spectral_acceleration(t, ag, T, damping=z)
    np.testing.assert_allclose(sa, closed, rtol=5e-4)  # measured: ≤ 2.2e-4 (the ramp)
    np.testing.assert_allclose(sa[2], closed[2], rtol=1e-9)  # at resonance: 1e-12


def _reference_sa(t, a, T, z):
    """Independent: DOP853 (rtol 1e-10) on the linearly interpolated record, one sample
    interval at a time (no kinks inside a call), all periods as one system; the peak is
    read from 201 points per interval (sampling error ≤ (π·1e-4/T)²/2 ≈ 2e-5 at T = 0.05)."""
    w = 2 * np.pi / np.asarray(T)
    m = w.size
    y, peak = np.zeros(2 * m), np.zeros(m)
    for i in range(t.size - 1):
        t0, slope = t[i], (a[i + 1] - a[i]) / (t[i + 1] - t[i])

        def rhs(tt, y, t0=t0, a0=a[i], slope=slope):
            u, v = y[:m], y[m:]
            return np.concatenate([v, -(a0 + slope * (tt - t0)) - 2 * z * w * v - w * w * u])

        sol = solve_ivp(
            rhs, (t0, t[i + 1]), y, method="DOP853", rtol=1e-10, atol=1e-14,
            t_eval=np.linspace(t0, t[i + 1], 201),
        )  # fmt: skip
        peak = np.maximum(peak, np.abs(sol.y[:m]).max(axis=1))
        y = sol.y[:, -1]
    return w * w * peak


def test_sa_of_el_centro_matches_an_independent_integration():
    t, a = np.loadtxt(ELCENTRO, unpack=True)  # t (s), a (g)
    T = np.array([0.05, 0.2, 1.0, 3.0])
    sa = spectral_acceleration(t, a * G, T) / G
    ref = _reference_sa(t, a * G, T, 0.05) / G
    np.testing.assert_allclose(sa, ref, rtol=5e-3)  # the 0.5 %
    assert np.max(np.abs(sa / ref - 1)) < 2e-5  # measured: ≤ 4.5e-6 (reference's sampling)
    # units follow ag: the record in g gives Sa in g
    np.testing.assert_allclose(spectral_acceleration(t, a, T), sa, rtol=1e-12)


@pytest.mark.parametrize("jitter", ["fixed", "random"])
def test_non_uniform_steps_are_exact(jitter):
    # the same piecewise-linear signal with extra samples on its straight lines: two step
    # lengths (tabulated coefficients) or hundreds (coefficients built step by step)
    t = np.arange(0, 5, 0.02)
    a = np.sin(7 * t) * np.exp(-0.3 * t)
    frac = 0.35 if jitter == "fixed" else np.random.default_rng(4).uniform(0.05, 0.95, t.size - 1)
    tm = np.sort(np.concatenate([t, t[:-1] + 0.02 * frac]))
    am = np.interp(tm, t, a)
    T = [0.1, 0.5, 2.0, 50.0]
    np.testing.assert_allclose(
        spectral_acceleration(tm, am, T), spectral_acceleration(t, a, T), rtol=1e-9
    )


def test_the_modules_are_leaves():
    # numpy/scipy and the error family only: importing them loads no engine
    import subprocess
    import sys

    code = (
        "import sys, multimass.analysis.intensity, multimass.analysis.fragility; "
        "print(sorted(m for m in sys.modules if m.startswith('multimass')))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert eval(out.stdout) == [
        "multimass",
        "multimass._paths",  # the package root's finder of old module paths (standard library)
        "multimass.analysis",
        "multimass.analysis._probit",
        "multimass.analysis.fragility",
        "multimass.analysis.intensity",
        "multimass.errors",
        "multimass.model",
        "multimass.model._nigam_jennings",
    ]


def test_pgv_pgd_of_a_sine_are_the_closed_forms():
    # a = A sin ωt from rest: v = A(1 - cos ωt)/ω, d = A(t/ω - sin ωt/ω²)
    A, w = 2.0, 3.0
    t = np.linspace(0, 2 * np.pi / w * 1.25, 4001)
    v_ref = A * (1 - np.cos(w * t)) / w
    d_ref = A * (t / w - np.sin(w * t) / w**2)
    v, d = ground_motion(t, A * np.sin(w * t))
    np.testing.assert_allclose(v, v_ref, atol=1e-6 * A / w)
    np.testing.assert_allclose(d, d_ref, atol=1e-6 * np.abs(d_ref).max())  # O(h²)
    assert pgv(t, A * np.sin(w * t)) == pytest.approx(2 * A / w, rel=1e-6)
    assert pgd(t, A * np.sin(w * t)) == pytest.approx(d_ref[-1], rel=1e-6)
    assert pga(t, A * np.sin(w * t)) == pytest.approx(A, rel=1e-6)


def test_pgv_pgd_are_exact_for_straight_lines_between_samples():
    # a = 1, -1 on two samples: v peaks mid-step (0.25); d peaks where v = 0 again (t = 1)
    t, a = np.array([0.0, 1.0]), np.array([1.0, -1.0])
    assert pgv(t, a) == pytest.approx(0.25, rel=1e-14)
    # a = 1 - 3σ over a step h (σ = t/h): v = h(σ - 1.5σ²) vanishes at σ = 2/3 inside the
    # step, where d = h²(σ²/2 - σ³/2) = 2h²/27; at both samples d = 0
    for h in (1.0, 0.5, 0.02):
        t3, a3 = np.array([0.0, h]), np.array([1.0, -2.0])
        assert np.abs(ground_motion(t3, a3)[1]).max() == pytest.approx(0.0, abs=1e-15)
        assert pgd(t3, a3) == pytest.approx(2 * h * h / 27, rel=1e-13)


def test_arias_of_constant_and_linear_signals():
    t = np.array([0.0, 1.0, 3.0])
    assert arias_intensity(t, [2.0, 2.0, 2.0]) == pytest.approx(np.pi / (2 * G) * 4 * 3)
    # a = t on [0, 3]: ∫ t² = 9
    assert arias_intensity(t, t, g=1.0) == pytest.approx(np.pi / 2 * 9, rel=1e-14)


@pytest.mark.parametrize(
    "im,period", [("pga", None), ("pgv", None), ("pgd", None), ("arias", None), ("sa", 0.5)]
)
def test_scale_to_hits_its_target(im, period):
    t, a = np.loadtxt(ELCENTRO, unpack=True)
    scaled, factor = scale_to(t, a * G, im, 0.7, period=period)
    assert intensity_measure(t, scaled, im, period=period) == pytest.approx(0.7, rel=1e-12)
    assert factor > 0


@pytest.mark.parametrize(
    "kwargs,match",
    [
        ({"t": [0, 1, 1, 2]}, "increase strictly"),
        ({"ag": [0, np.nan, 0, 0]}, "non-finite"),
        ({"periods": [0.0, 1.0]}, "> 0"),
        ({"damping": 5}, r"\[0, 1\)"),
        ({"damping": 1.0}, r"\[0, 1\)"),
        ({"periods": [0.3]}, "Nyquist"),
    ],
)
def test_bad_input_is_a_named_error(kwargs, match):
    args = {"t": [0, 0.2, 0.4, 0.6], "ag": [0, 1, -1, 0], "periods": [1.0], "damping": 0.05}
    args.update(kwargs)
    with pytest.raises(InputError, match=match):
        spectral_acceleration(args["t"], args["ag"], args["periods"], args["damping"])


def test_short_periods_allowed_on_request():
    t, a = [0, 0.2, 0.4, 0.6], [0, 1, -1, 0]
    assert np.isfinite(spectral_acceleration(t, a, [0.1], min_period_ratio=0)).all()


def test_scale_to_rejects_an_all_zero_record_and_unknown_im():
    with pytest.raises(InputError, match="all-zero"):
        scale_to([0, 1], [0, 0], "pga", 1.0)
    with pytest.raises(InputError, match="one of"):
        intensity_measure([0, 1], [0, 1], "cav")


def test_pgv_pgd_of_el_centro_bound_a_refined_sampling():
    # the same piecewise-linear record sampled 200× finer: v and d are exact at every
    # sample, so their peaks approach pgv/pgd from below
    t, a = np.loadtxt(ELCENTRO, unpack=True)
    tf = np.linspace(t[0], t[-1], 200 * (t.size - 1) + 1)
    vf, df = ground_motion(tf, np.interp(tf, t, a))
    for exact, fine in ((pgv(t, a), np.abs(vf).max()), (pgd(t, a), np.abs(df).max())):
        assert fine <= exact * (1 + 1e-12)
        assert exact == pytest.approx(fine, rel=1e-6)
