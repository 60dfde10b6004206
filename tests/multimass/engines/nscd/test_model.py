"""Input checks of the block-on-beam model: ranges with a reason, strict numbers, field names."""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from multimass import specimens
from multimass.engines import nscd
from multimass.engines.nscd.fe_beam import build_beam, static_deflection
from multimass.engines.nscd.model import (
    E_MAX,
    check_elements,
    check_exponent,
    check_inputs,
    flex_range,
    min_modulus,
)
from multimass.errors import InputError


def test_softest_beam_deflects_l_over_30():
    # independent calculation: the FE beam (Hermite elements are nodally exact) under the
    # block's weight at midspan and its self-weight, at E = min_modulus, deflects L/30
    blk, bm = specimens.load("B6M"), specimens.load("beam_mudric2024")
    E = min_modulus(blk, bm)
    beam = build_beam(bm.span, E, bm.area, bm.second_moment, bm.rho, 6, g=bm.g)
    q = static_deflection(beam, beam.p_self + beam.point_load(bm.span / 2, 0.0, -blk.mass * blk.g))
    assert beam.deflection(q, bm.span / 2) == pytest.approx(-bm.span / 30, rel=1e-9)


def test_modulus_range_ends():
    E_min = min_modulus("B6M")
    check_inputs("B6M", theta0=0.1, dt=1e-4, E=E_min * 1.0001)
    with pytest.raises(InputError, match=r"`E` = .* too soft .* give E >= "):
        check_inputs("B6M", theta0=0.1, dt=1e-4, E=E_min * 0.9999)
    # paper 002, Section 6.1: E = 1e24 Pa is the rigid base, inside the range
    assert check_inputs("B6M", theta0=0.1, dt=1e-4, E=1e24).E == 1e24
    assert check_inputs("B6M", theta0=0.1, dt=1e-4, E=E_MAX).E == E_MAX
    with pytest.raises(InputError, match="above 1e"):
        check_inputs("B6M", theta0=0.1, dt=1e-4, E=E_MAX * 1.01)


def test_flex_exponent_range_matches_the_modulus_range():
    low, high = flex_range("B6M")
    Ebar = nscd.flexible_modulus("B6M")
    # invariant: the exponent range is the modulus range seen through E = Ebar 10^n
    assert Ebar * 10.0**low == pytest.approx(min_modulus("B6M"), rel=1e-12)
    assert Ebar * 10.0**high == pytest.approx(E_MAX, rel=1e-12)
    # paper 002, Section 6.3 uses n = 0 ... 8
    assert low < 0 < 8 < high
    # 10.0**1000 overflowed before the check (the reviewer's --flex 1000)
    with pytest.raises(InputError, match=r"`--flex` = 1000"):
        check_exponent(1000, "B6M", name="--flex")
    with pytest.raises(InputError, match="expected a finite number"):
        check_exponent(math.inf, "B6M")


def test_element_cap_gives_the_cost():
    assert check_elements(1000) == 1000
    with pytest.raises(InputError) as err:
        check_elements(100000, "--elements")
    msg = str(err.value)
    # 3e5 degrees of freedom: a dense 3e5 x 3e5 matrix alone is 8 * 9e10 B = 671 GiB
    assert msg.startswith("`--elements` = 100000: at most 1000 elements") and "TiB" in msg


def test_names_are_the_callers():
    names = {"dt": "--dt", "n_elements": "--elements", "x_centre": "--x-centre"}
    for kw, flag in (
        ({"dt": 0.0}, "--dt"),
        ({"n_elements": 2}, "--elements"),
        ({"x_centre": 0.29}, "--x-centre"),
    ):
        with pytest.raises(InputError, match=f"`{flag}`"):
            check_inputs("B6M", **{"theta0": 0.1, "dt": 1e-4, **kw}, names=names)


def test_beam_file_modulus_is_checked_too(tmp_path):
    text = specimens.loader._bundled()["beam_mudric2024"].read_text()
    soft = tmp_path / "soft.toml"
    soft.write_text(text.replace("youngs_modulus_Pa = 1e24", "youngs_modulus_Pa = 1e9"))
    with pytest.raises(InputError, match="youngs_modulus_Pa` of beam .* too soft"):
        check_inputs("B6M", soft, theta0=0.1, dt=1e-4)


@settings(max_examples=300, deadline=None)
@given(
    field=st.sampled_from(
        ["theta0", "dt", "E", "n_elements", "theta_method", "mu", "restitution", "x_centre"]
    ),
    value=st.one_of(
        st.floats(allow_nan=True, allow_infinity=True),
        st.integers(-(10**9), 10**9),
        st.booleans(),
        st.text(max_size=4),
        st.none(),
    ),
)
def test_any_value_is_accepted_or_refused_with_its_name(field, value):
    kw = {"theta0": 0.1, "dt": 1e-4, field: value}
    try:
        inp = check_inputs("B6M", **kw)
    except InputError as err:
        assert f"`{field}`" in str(err)
    else:  # accepted: finite, in range, of the right type
        assert all(
            math.isfinite(x)
            for x in (
                inp.theta0,
                inp.dt,
                inp.E,
                inp.theta_method,
                inp.mu,
                inp.restitution,
                inp.x_centre,
            )
        )
        assert 3 <= inp.n_elements <= 1000 and inp.dt > 0 and abs(inp.theta0) < inp.block.alpha
