"""Plausible ranges of specimen inputs (specimens.ranges)."""

import numpy as np
import pytest

from multimass import specimens
from multimass.specimens import SpecimenError
from multimass.specimens.ranges import RANGES, SECTION_FACTOR, check, fmt, written


@pytest.mark.parametrize(
    "x, factor, text",
    [
        (200, 1e9, "200e9"),  # GPa typed
        (183.3, 1e-8, "183.3e-8"),  # cm^4 typed
        (1930, 1e-3, "1.93"),  # mm typed
        (1, 9.81, "9.81"),  # g typed
        (2.5, 1e-2, "0.025"),  # % typed
    ],
)
def test_the_fix_is_written_as_a_user_types_it(x, factor, text):
    assert written(x, factor) == text


def test_fmt_drops_the_plus_and_leading_zeros():
    assert (fmt(1e6), fmt(1e-300), fmt(0.305), fmt(1e15)) == ("1e6", "1e-300", "0.305", "1e15")


@pytest.mark.parametrize(
    "quantity, value, hint",
    [
        ("youngs_modulus", 200, "did you type GPa? write 200e9"),
        (
            "youngs_modulus",
            200_000,
            "did you type MPa? write 200000e6",
        ),  # not GPa: 2e14 is no material
        ("youngs_modulus", 30_000, "did you type MPa? write 30000e6"),
        ("youngs_modulus", 2e21, "give it in Pa (steel is 200e9, concrete 30e9)"),
        ("length", 1930, "did you type mm? write 1.93"),
        ("length", 1e-4, "did you type km? write 0.1"),
        ("mass", 1e-5, "did you type t? write 0.01"),
        ("gravity", 1, "did you type g? write 9.81"),
        ("density", 2.7, "did you type g/cm^3? write 2700"),
    ],
)
def test_hint_names_the_likely_slip(quantity, value, hint):
    with pytest.raises(SpecimenError) as info:
        check("f.toml", "x", value, quantity)
    assert str(info.value).endswith(hint)


@pytest.mark.parametrize("value", [True, "200e9", None, [1.0], float("nan"), float("inf")])
def test_check_refuses_what_is_not_a_finite_number(value):
    with pytest.raises(SpecimenError, match="`x` = "):
        check("f.toml", "x", value, "youngs_modulus")


def test_bounds_are_inclusive_and_low_open_refuses_the_bound():
    assert (
        check("f", "x", 1e6, "youngs_modulus") == 1e6
        and check("f", "x", 1e15, "youngs_modulus") == 1e15
    )
    assert check("f", "x", 0.0, "base_mass") == 0.0
    with pytest.raises(SpecimenError, match=r"must lie in \(0, 1\]"):
        check("f", "x", 0.0, "restitution", low_open=True)


def test_every_range_is_an_interval_with_a_reason():
    for key, rng in RANGES.items():
        assert rng.low < rng.high and rng.why, key
        for factor, unit in rng.slips:
            assert factor > 0 and unit, key


def test_section_bound_is_the_full_square_of_the_footprint():
    # I = ∫∫ y² dA over the square |x|, |y| <= B, by the midpoint rule (independent of 4B^4/3)
    B, n = 0.305, 2000
    y = -B + (np.arange(n) + 0.5) * (2 * B / n)
    I_numeric = (2 * B) * np.sum(y**2) * (2 * B / n)
    assert SECTION_FACTOR * B**4 == pytest.approx(I_numeric, rel=1e-6)


def test_bundled_specimens_lie_inside_the_ranges():
    # specimens.load applies every range. S1's section (paper 001, Table 1: 183.3 cm^4) is
    # 1.6e-4 of its footprint's bound, so a cm^4 slip (x 1e8) is far above it
    for name in specimens.available():
        specimens.load(name)
    s1 = specimens.load("S1")
    assert 1e-4 < s1.I_s / (SECTION_FACTOR * s1.B**4) < 1e-3
