"""`multimass.simulate` with a user's own arguments: strict validation, an
excitation that must act before t_end, the cost refused before a run starts, progress."""

import math

import numpy as np
import pytest

import multimass
from multimass import (
    CosinePulse,
    FreeRelease,
    InputError,
    Record,
    SineWave,
    estimate,
    simulate,
    simulate_outcome,
)


@pytest.mark.parametrize(
    "kwargs, fragment",
    [
        (dict(t_end="10"), r"`t_end` = '10': expected a number"),
        (dict(t_end=True), r"`t_end` = True: expected a number"),
        (dict(t_end=math.nan), r"`t_end` = nan: expected a finite number"),
        (dict(seed=-1), r"`seed` = -1: must be ≥ 0"),
        (dict(seed=1.5), r"`seed` = 1.5: expected a whole number"),
        (dict(chatter_count=2.5), r"`chatter_count` = 2.5: expected a whole number"),
        (dict(rtol="1e-8"), r"`rtol` = '1e-8': expected a number"),
        (dict(max_step=0.0), r"`max_step` = 0.0: must lie in \(0"),
        (dict(output_dt=-1e-3), r"`output_dt` = -0.001"),
        (dict(overturn_angle=2.0), r"`overturn_angle` = 2.0: must lie in \(0, 1.5708\]"),
        (dict(stop_when_safe="yes"), r"`stop_when_safe` = 'yes': expected True or False"),
        (dict(integrator="euler"), r"`integrator` = 'euler': use one of 'solve_ivp', 'newmark'"),
        (dict(backend="gpu"), r"`backend` = 'gpu'"),
        (dict(energy_tol=0), r"`energy_tol` = 0"),
        (dict(max_hours=-1), r"`max_hours` = -1"),
        (dict(progress="auto"), r"`progress` = 'auto'"),
        (dict(dt=math.nan, integrator="newmark"), r"`dt` = nan"),
    ],
)
def test_arguments_are_strict(kwargs, fragment):
    args = dict(t_end=1.0) | kwargs
    with pytest.raises(InputError, match=fragment):
        simulate("B6M", FreeRelease(0.1), "CIM", **args)


def test_unknown_option_of_simulate_outcome_is_named():
    with pytest.raises(InputError, match=r"`rtoll` is not an option of simulate"):
        simulate_outcome("S1", FreeRelease(0.05), "DD2", 1.0, rtoll=1e-6)


def test_structure_that_is_not_one_is_refused():
    with pytest.raises(InputError, match=r"`specimen` = None"):
        simulate(None, FreeRelease(0.05), "DD2", 1.0)


def test_record_that_starts_after_t_end_is_refused():
    # a record whose first sample is at t = 1e6 s with t_end = 2 s would report
    # "completed, θ = 0" although the structure never saw the motion: refused
    t = 1e6 + np.arange(0.0, 2.0, 0.01)
    with pytest.raises(InputError, match=r"later than a day"):  # the reader's check
        Record.from_arrays(t, 0.3 * np.sin(10.0 * t), units="g")
    t = 50.0 + np.arange(0.0, 2.0, 0.01)
    rec = Record.from_arrays(t, 0.3 * np.sin(10.0 * t), units="g")
    with pytest.raises(InputError, match=r"starts at t = 50 s, at or after t_end = 2 s"):
        simulate("S1", rec, "DD2", 2.0)
    # a record that starts later than 0 but before t_end is the user's choice: it runs
    late = Record.from_arrays(0.5 + np.arange(0.0, 0.5, 0.01), np.zeros(50), units="g")
    assert simulate("S1", late, "DD2", 1.0, output_dt=None).status == "completed"


def test_an_end_time_of_1e9_s_is_refused_before_it_starts():
    # t_end = 1e9 would need a 7 TiB output grid: refused with its estimate, no MemoryError
    with pytest.raises(InputError) as err:
        simulate("S1", FreeRelease(0.1), "DD2", 1e9)
    msg = str(err.value)
    assert "over the budget of 1 h" in msg and "its output would need" in msg
    assert "TiB" in msg and "shorten t_end" in msg and "max_hours" in msg


def test_a_pulse_of_two_months_is_refused_and_named():
    # --omega 1e-6 makes a pulse of 6.3e6 s (46.8 GiB of output grid): refused, named
    exc = SineWave(amplitude=3.9, omega=1e-6)
    with pytest.raises(InputError, match=r"the excitation lasts 6.28e\+06 s"):
        simulate("S1", exc, "DD2", exc.duration + 5.0)


def test_the_budget_can_be_raised_and_memory_still_counts():
    cost = estimate("S1", FreeRelease(0.1), "DD2", 1e5, output_dt=None, max_hours=math.inf)
    assert cost.seconds > 3600.0 and cost.memory == 0.0
    with pytest.raises(InputError, match="its output would need"):
        estimate("S1", FreeRelease(0.1), "DD2", 1e8, max_hours=math.inf)


def test_estimate_validates_like_simulate():
    with pytest.raises(InputError, match="`rtol`"):
        estimate("S1", FreeRelease(0.1), "DD2", 1.0, rtol=-1.0)
    cost = estimate("S1", FreeRelease(0.1), "DD2", 10.0)
    assert 0.0 < cost.seconds < 3600.0 and cost.steps > 1000


def test_progress_is_shown_when_asked(capsys):
    simulate("B6M", FreeRelease(0.1), "CIM", 1.0, progress=True, output_dt=None)
    err = capsys.readouterr().err
    assert "simulate B6M: estimated" in err
    simulate("B6M", FreeRelease(0.1), "CIM", 1.0, progress=False, output_dt=None)
    assert capsys.readouterr().err == ""


def test_progress_does_not_change_the_result():
    a = simulate("S1", FreeRelease(0.1), "DD2", 1.0, progress=False)
    b = simulate("S1", FreeRelease(0.1), "DD2", 1.0, progress=True)
    np.testing.assert_array_equal(a.series.theta.to_numpy(), b.series.theta.to_numpy())


def test_a_non_finite_state_is_a_failed_run_not_data():
    class Exploding:
        duration, breakpoints = 1.0, ()

        def __call__(self, t):
            big = 1e300 if np.ndim(t) == 0 and t > 0.2 else 0.0
            return big if np.ndim(t) == 0 else np.where(np.asarray(t) > 0.2, 1e300, 0.0)

        acceleration = __call__

    resp = simulate("S1", Exploding(), "DD2", 1.0)
    assert resp.status == "failed"
    assert np.all(np.isfinite(resp.series.select_dtypes("number").to_numpy()))


def test_swapped_pulse_arguments_cannot_happen():
    # CosinePulse(0.4*G, 15) read positionally would overturn S1: positional pulses are refused
    with pytest.raises(InputError, match="by keyword"):
        CosinePulse(0.4 * multimass.G, 15.0)
