"""The Gaussian Dirac-delta impact force of paper 001, Eqs 14–17, at the force level.

Reference values are worked out by hand in the comments from the paper's equations, and
the energy the force removes is integrated here with `scipy.integrate.quad`, not with
the code's own integrators.
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from multimass.impact_models.gaussian_force import activation_angle, impact_force, impact_width

# a state of the numbers' choosing: E_ini = 50 J, r = 0.9, n = 0.02 rad, B = 0.3 m
E_INI, R, N, B = 50.0, 0.9, 0.02, 0.3
# Eq 14's amplitude E_ini (1 − r²)/(B n √π) = 50·0.19/(0.3·0.02·1.7724539) = 9.5/0.010634723
PEAK = 893.3001739506142  # N


@pytest.mark.parametrize("side", [1, -1])
def test_eq14_peak_and_shape_by_hand(side):
    """Paper 001, Eq 14: F_i = ±E_ini (1 − r²)/(B n √π) exp(−θ²/n²). At θ = 0 it is the
    amplitude, 893.30 N for the numbers above (worked in the comment); at θ = ±n it is
    e⁻¹ of it (328.63 N). The sign is the impending pivot's (−side), so that the moment
    2B F_i of Eq 5 brakes the approach to θ = 0."""
    assert E_INI * (1 - R**2) / (B * N * math.sqrt(math.pi)) == pytest.approx(PEAK, rel=1e-15)
    assert impact_force(0.0, side, E_INI, R, N, B) == pytest.approx(-side * PEAK, rel=1e-14)
    for theta in (N, -N):
        got = impact_force(theta, side, E_INI, R, N, B)
        assert got == pytest.approx(-side * 328.6267687913042, rel=1e-14)
    # the peak is the maximum of |F_i| over θ
    theta = np.linspace(-5 * N, 5 * N, 1001)
    assert np.max(np.abs(impact_force(theta, side, E_INI, R, N, B))) == pytest.approx(PEAK)


def test_eq15_width_makes_the_peak_the_bound_on_the_support_force():
    """Paper 001, Eq 15 chooses n so that Eq 14's peak equals m_t g/2 + C_p |θ̇_i| (the
    static support force of a corner plus the C_p term, Section 2.4). With m_t = 110 kg,
    g = 9.81 m/s², C_p = 1000 kg m/rad/s, θ̇_i = −0.2 rad/s: 539.55 + 200 = 739.55 N."""
    n = impact_width(E_INI, R, B, 110.0, 9.81, 1000.0, -0.2, 1e-4)
    assert n > 1e-4  # not clipped at n_min
    for side in (1, -1):
        assert abs(impact_force(0.0, side, E_INI, R, n, B)) == pytest.approx(739.55, rel=1e-13)


@pytest.mark.parametrize("side", [1, -1])
def test_eq14_removes_e_ini_times_one_minus_r_squared(side):
    """The energy the force removes, by quadrature of Eq 14 (reference: `quad`).

    The force acts at the impending pivot P', 2B from the pivot P, so its moment about P is
    2B F_i (Eq 5), and while it acts θ runs from the activation angle to 0 (Eqs 16, 17). The
    energy it removes is ∫ 2B F_i dθ along that path, from θ_start to 0 (positive: the
    force opposes the motion). With A = E_ini (1 − r²)/(B n √π) and
    ∫_0^∞ exp(−θ²/n²) dθ = n √π / 2 (one half of the Gaussian, whose unscaled form
    integrates to 1 over the whole line, Section 2.4):

        2B ∫ |F_i| dθ over the half-line = 2B · A · n √π/2 = E_ini (1 − r²),

    the energy loss E_ini (1 − r²) that Section 2.4 scales Eq 14 to give (and the
    classical model's loss, text after Eq 13). Over the activation window
    |θ| ≤ θ_i = 2.576 n/√2 (Eq 16) the share is erf(2.576/√2) = 0.99000: 0.99 E_ini (1 − r²).
    """
    target = E_INI * (1 - R**2)  # 9.5 J

    def removed(theta_start):  # ∫ 2B F_i dθ from θ_start to 0, by quad
        value, err = quad(
            lambda th: 2.0 * B * impact_force(th, side, E_INI, R, N, B), 0.0, theta_start
        )
        assert err < 1e-9 * target
        return -value

    # side +1: rocking on the right pivot, θ > 0 falls to 0; side −1: θ < 0 rises to 0.
    # The half-line is cut at 20 n, where exp(−400) leaves nothing of the Gaussian.
    assert removed(side * 20.0 * N) == pytest.approx(target, rel=1e-10)
    theta_i = activation_angle(2.576, N)
    assert theta_i == pytest.approx(2.576 * N / math.sqrt(2), rel=1e-15)
    assert removed(side * theta_i) == pytest.approx(
        math.erf(2.576 / math.sqrt(2)) * target, rel=1e-10
    )
