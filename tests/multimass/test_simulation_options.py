"""`SimulationOptions`: every option of `simulate` validated once, in one place."""

import math

import pytest

from multimass import FreeRelease, InputError, SimulationOptions, simulate, simulate_outcome
from multimass.simulation_options import BACKENDS, DEFAULTS, INTEGRATORS, METHODS


def test_an_options_object_runs_like_the_same_keywords():
    o = SimulationOptions(rtol=1e-9, output_dt=None)
    a = simulate("B6M", FreeRelease(theta0=0.1), "CIM", 2.0, options=o)
    b = simulate("B6M", FreeRelease(theta0=0.1), "CIM", 2.0, rtol=1e-9, output_dt=None)
    assert list(a.peaks) == list(b.peaks) and a.options["rtol"] == 1e-9


def test_keywords_replace_fields_of_the_options_object_and_are_checked_again():
    o = SimulationOptions(rtol=1e-9)
    assert SimulationOptions.of(o, atol=1e-11).rtol == 1e-9
    assert SimulationOptions.of(o) is o
    with pytest.raises(InputError, match="`atol` = -1"):
        SimulationOptions.of(o, atol=-1)
    with pytest.raises(InputError, match="expected a multimass.SimulationOptions"):
        simulate_outcome("B6M", FreeRelease(theta0=0.1), options={"rtol": 1e-9})


def test_an_unknown_option_lists_the_known_ones():
    with pytest.raises(InputError, match=r"`rtoll` is not an option of simulate.*rtol"):
        simulate("B6M", FreeRelease(theta0=0.1), rtoll=1e-9)


@pytest.mark.parametrize(
    "field, value, words",
    [
        ("integrator", "euler", "integrator"),
        ("backend", "gpu", "backend"),
        ("method", "RK4", "use one of RK23"),
        ("chatter_count", 1.5, "chatter_count"),
        ("stop_at_rest", 1, "expected True or False"),
        ("overturn_angle", 2.0, "overturn_angle"),
        ("rtol", math.nan, "rtol"),
    ],
)
def test_each_field_is_validated_when_built(field, value, words):
    with pytest.raises(InputError, match=words):
        SimulationOptions(**{field: value})


def test_the_registries_name_every_choice():
    assert set(INTEGRATORS) == {"solve_ivp", "newmark"}
    assert set(BACKENDS) == {"scipy", "compiled"}
    assert "DOP853" in METHODS and DEFAULTS["method"] == "DOP853"
    assert SimulationOptions(integrator="newmark").engine == "newmark"
    assert SimulationOptions(backend="compiled").engine == "compiled"
    assert SimulationOptions().engine == "solve_ivp"
