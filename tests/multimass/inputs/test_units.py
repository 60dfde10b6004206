"""Acceleration units and parsing of amplitudes such as '0.4g' (multimass.inputs.units)."""

import numpy as np
import pytest

from multimass import InputError
from multimass.inputs.units import G, canonical_units, parse_acceleration, to_mps2


def test_g_is_the_design_value():
    assert G == 9.81  # DESIGN.md, Conventions: g = 9.81 m/s²


@pytest.mark.parametrize(
    "units, factor",
    [
        ("g", 9.81),  # DESIGN.md: g = 9.81 m/s²
        ("G", 9.81),
        ("m/s2", 1.0),
        ("m/s^2", 1.0),
        ("mps2", 1.0),
        ("M/S2", 1.0),
        ("m/s²", 1.0),
        ("cm/s2", 0.01),
        ("gal", 0.01),
        ("Gal", 0.01),
        ("cm/s^2", 0.01),
        ("CM/S/S", 0.01),
        ("mm/s2", 0.001),
        ("mm/s^2", 0.001),
    ],
)
def test_to_mps2_factors(units, factor):
    # closed form: 1 cm = 0.01 m, 1 mm = 0.001 m
    assert to_mps2(2.0, units) == pytest.approx(2.0 * factor, rel=1e-15)
    assert isinstance(to_mps2(2.0, units), float)


def test_to_mps2_arrays_and_custom_g():
    out = to_mps2([0.1, -0.2], "g")
    assert isinstance(out, np.ndarray)
    np.testing.assert_allclose(out, [0.981, -1.962], rtol=1e-15)  # closed form: 9.81 × a
    assert to_mps2(1.0, "g", g=9.80665) == 9.80665


@pytest.mark.parametrize("bad", [None, "", "furlongs", "m/s", "kg", 3])
def test_unknown_units_list_the_accepted_ones(bad):
    with pytest.raises(InputError, match=r"`units`.*accepted: g, m/s2"):
        to_mps2(1.0, bad)


def test_canonical_units():
    assert canonical_units(" M/S^2 ") == "m/s2"
    assert canonical_units("GAL") == "cm/s2"


@pytest.mark.parametrize(
    "text, expected",
    [
        ("0.4g", 0.4 * 9.81),  # closed form: 0.4 × 9.81
        ("0.4 g", 0.4 * 9.81),
        ("3.5m/s2", 3.5),
        ("3.5 m/s^2", 3.5),
        ("350gal", 3.5),  # 350 cm/s² = 3.5 m/s²
        ("350 cm/s2", 3.5),
        ("-0.2g", -0.2 * 9.81),  # the sign is kept; excitations reject it
        (".5e1mm/s2", 0.005),  # 5 mm/s²
    ],
)
def test_parse_acceleration(text, expected):
    assert parse_acceleration(text) == pytest.approx(expected, rel=1e-14)


def test_parse_bare_number_needs_explicit_default():
    assert parse_acceleration("0.4", default_units="g") == pytest.approx(3.924, rel=1e-14)
    assert parse_acceleration(2.0, default_units="m/s2") == 2.0
    with pytest.raises(InputError, match=r"`--amp`.*bare number.*0.4g"):
        parse_acceleration("0.4", argument="--amp")


@pytest.mark.parametrize(
    "junk, match",
    [
        ("abc", "expected a number followed by a unit"),
        ("", "expected a number followed by a unit"),
        ("g0.4", "expected a number followed by a unit"),
        ("0.4 furlongs", "unknown unit 'furlongs'"),
        ("0.4gg", "unknown unit"),
        ("1e400g", "finite"),
        ("nan g", "expected a number followed by a unit"),
    ],
)
def test_parse_junk(junk, match):
    with pytest.raises(InputError, match=match):
        parse_acceleration(junk, default_units="g")


def test_parse_rejects_non_strings():
    with pytest.raises(InputError, match="expected"):
        parse_acceleration(True)
    with pytest.raises(InputError, match="expected"):
        parse_acceleration([0.4])
