"""The step-size controller of the compiled Runge–Kutta path (`multimass.engines.fast._rk`).

References: the PI formula of Gustafsson's controller, h_new = h · 0.9 · err_n^−(1/8 − κβ)
· err_{n−1}^β (Hairer & Wanner, *Solving ODEs II*, Sec. IV.2), worked by hand below; and
SciPy's RungeKutta control (``scipy.integrate._ivp.rk.RungeKutta._step_impl``: factor
0.9 err^−1/8 bounded to [0.2, 10], at most 1 after a rejection), which β = 0 must be bit
for bit, since a rigid block's steps are tested to be solve_ivp's.
"""

from __future__ import annotations

import math

import pytest

from multimass.engines.fast._rk import PI_BETA, PI_ERR_FLOOR, PI_KAPPA, step_control

LN = math.log  # step_control takes ln err_{n−1}

EXP8 = -1.0 / 8.0  # DOP853's error exponent, −1/(7 + 1)
H = 1e-3


def test_accepted_step_grows_by_the_pi_factor():
    # err_n = 0.25, err_{n−1} = 0.5, β = 0.03, κ = 0.75, by hand:
    # 0.25^−(0.125 − 0.0225) = e^(0.1025 · ln 4) = e^0.142095 = 1.152686,
    # 0.5^0.03 = e^(−0.03 · ln 2) = e^−0.020794 = 0.979420,
    # 0.9 · 1.152686 · 0.979420 = 1.016068
    ok, h_next, log_err = step_control(0.25, EXP8, False, H, H, LN(0.5), 0.03, 0.75)
    assert ok and log_err == pytest.approx(LN(0.25), rel=1e-15)  # the next call's err_{n−1}
    assert h_next == pytest.approx(1.016068 * H, rel=1e-6)
    # a larger previous error holds the step back: err_{n−1} = 0.9 instead of 0.5 gives
    # 0.9^0.03 = e^(−0.03 · 0.105361) = 0.996844, so 0.9 · 1.152686 · 0.996844 = 1.034144
    _, h_next, _ = step_control(0.25, EXP8, False, H, H, LN(0.9), 0.03, 0.75)
    assert h_next == pytest.approx(1.034144 * H, rel=1e-6)


def test_the_controller_is_the_chosen_pi():
    # the constants the kernel passes for a column's DOP853 steps: a PI controller whose
    # net exponent on err_n stays negative (κβ < 1/8: a larger error must give a smaller
    # step), with Hairer's floor of err_{n−1}
    assert 0.0 < PI_BETA and 0.0 < PI_KAPPA * PI_BETA < 0.125
    assert PI_ERR_FLOOR == 1e-4


@pytest.mark.parametrize("err", [1e-9, 1e-3, 0.3, 0.999])
@pytest.mark.parametrize("rejected", [False, True])
def test_beta_zero_is_scipys_control_bit_for_bit(err, rejected):
    # SciPy's RungeKutta._step_impl, written out: accepted, factor = min(10, 0.9 err^−1/8),
    # at most 1 after a rejection; the next size h · factor (a full-size step: h = h_abs)
    factor = min(10.0, 0.9 * err**EXP8)
    if rejected:
        factor = min(1.0, factor)
    for err_prev in (1.0, 0.5, PI_ERR_FLOOR):  # ignored at β = 0
        ok, h_next, _ = step_control(err, EXP8, rejected, H, H, LN(err_prev), 0.0, 0.0)
        assert ok and h_next == H * factor


@pytest.mark.parametrize("beta, kappa", [(0.0, 0.0), (PI_BETA, PI_KAPPA)])
def test_a_rejected_step_shrinks_as_scipys_whatever_beta(beta, kappa):
    # err = 4: 0.9 · 4^−1/8 = 0.9 · 0.840896 = 0.756807 (> 0.2); err = 1e6: the 0.2 floor
    ok, h_next, _ = step_control(4.0, EXP8, False, H, H, LN(0.5), beta, kappa)
    assert not ok and h_next == pytest.approx(0.756807 * H, rel=1e-6)
    ok, h_next, _ = step_control(1e6, EXP8, True, H, H, LN(0.5), beta, kappa)
    assert not ok and h_next == pytest.approx(0.2 * H, rel=1e-15)


def test_no_growth_after_a_rejection_and_growth_bounded_by_ten():
    # a tiny error would grow the step (0.9 · (1e-6)^−0.1025 · 0.5^0.03 ≈ 3.6) but the
    # step was rejected once: the next size is this one's
    ok, h_next, _ = step_control(1e-6, EXP8, True, H, H, LN(0.5), PI_BETA, PI_KAPPA)
    assert ok and h_next == H
    # err = 0 and the floor of err_{n−1}: at most 10×
    for err, err_prev in ((0.0, 0.5), (1e-30, PI_ERR_FLOOR), (1e-30, 1.0)):
        ok, h_next, _ = step_control(err, EXP8, False, H, H, LN(err_prev), PI_BETA, PI_KAPPA)
        assert ok and h_next == pytest.approx(10.0 * H, rel=1e-15)
    # the error norm carried to the next step is floored (Hairer's DOP853): 1e-30 → 1e-4,
    # 0 → 1e-4
    for err in (1e-30, 0.0):
        _, _, log_err = step_control(err, EXP8, False, H, H, 0.0, PI_BETA, PI_KAPPA)
        assert log_err == pytest.approx(LN(1e-4), rel=1e-15)


def test_a_step_shortened_to_a_sample_does_not_shorten_the_next():
    # h = H/4 (cut to fit a record sample), proposed H, factor 1.016068 (first test):
    # the next proposal is max(h · factor, H · min(factor, 1)) = H
    ok, h_next, _ = step_control(0.25, EXP8, False, H / 4, H, LN(0.5), 0.03, 0.75)
    assert ok and h_next == H
    # a shrinking factor shrinks the proposal, not the short step: err = 0.999, err_{n−1}
    # = 0.999: 0.9 · 0.999^−0.1025 · 0.999^0.03 = 0.9 · 0.999^−0.0725 = 0.900065
    _, h_next, _ = step_control(0.999, EXP8, False, H / 4, H, LN(0.999), 0.03, 0.75)
    assert h_next == pytest.approx(0.900065 * H, rel=1e-6)


def test_which_runs_take_the_pi_controller():
    # a column's DOP853 steps, released or under a pulse; not under a record (its samples
    # cut the steps), not a rigid block's (no masses: solve_ivp's steps), not RK23/RK45
    from multimass.engines.fast._kernel import controller
    from multimass.engines.fast._maths import EXC_NONE, EXC_RECORD, EXC_SINE
    from multimass.engines.fast._rk import METHOD_CODES

    dop, rk45 = METHOD_CODES["DOP853"], METHOD_CODES["RK45"]
    assert controller(dop, 5, EXC_NONE) == (PI_BETA, PI_KAPPA)
    assert controller(dop, 5, EXC_SINE) == (PI_BETA, PI_KAPPA)
    assert controller(dop, 5, EXC_RECORD) == (0.0, 0.0)
    assert controller(dop, 0, EXC_NONE) == (0.0, 0.0)
    assert controller(rk45, 5, EXC_NONE) == (0.0, 0.0)
