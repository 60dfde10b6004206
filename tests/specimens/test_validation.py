"""Every bad specimen input raises SpecimenError naming the field and the fix."""

import tomllib

import pytest

import specimens
from specimens import SpecimenError


@pytest.fixture
def s1_text():
    return specimens.loader._bundled()["S1"].read_text()


def _write(tmp_path, text):
    p = tmp_path / "bad.toml"
    p.write_text(text)
    return p


def _load_with(tmp_path, text):
    return specimens.load(_write(tmp_path, text))


CASES = [
    # (description, old, new, fragment expected in the message)
    ("missing key", "half_width_m = 0.305", "", "missing key `geometry.half_width_m`"),
    ("unknown key", "zeta_2 = 0.015", "zeta_2 = 0.015\nzeta_3 = 0.02", "unknown key `damping.zeta_3`"),
    ("lengths differ", "[77.3, 6.2, 88.2, 8.2, 46.2]", "[77.3, 6.2, 88.2, 8.2]", "`mass.nodal_kg` has 4 entries"),
    ("heights not increasing", "[0.06, 0.49, 0.93, 1.43, 1.93]", "[0.06, 0.93, 0.49, 1.43, 1.93]",
     "`geometry.heights_m[2]`"),
    ("non-positive mass", "[77.3, 6.2, 88.2, 8.2, 46.2]", "[77.3, 6.2, -88.2, 8.2, 46.2]", "`mass.nodal_kg[2]`"),
    ("zero mass", "[77.3, 6.2, 88.2, 8.2, 46.2]", "[77.3, 0.0, 88.2, 8.2, 46.2]", "`mass.nodal_kg[1]`"),
    ("non-positive stiffness", "youngs_modulus_Pa = 200e9", "youngs_modulus_Pa = 0.0", "`stiffness.youngs_modulus_Pa`"),
    ("negative spring", "rotational_spring_Nm_per_rad = 2.0e6", "rotational_spring_Nm_per_rad = -2.0e6",
     "`stiffness.rotational_spring_Nm_per_rad`"),
    ("negative damping", "zeta_1 = 0.005", "zeta_1 = -0.005", "`damping.zeta_1`"),
    ("restitution above 1", "mean_right = 0.93", "mean_right = 1.2", "`restitution.mean_right`"),
    ("restitution zero", "mean_left = 0.87", "mean_left = 0.0", "`restitution.mean_left`"),
    ("negative base mass", "base_kg = 0.0", "base_kg = -1.0", "`mass.base_kg`"),
    ("wrong type", "half_width_m = 0.305", 'half_width_m = "wide"', "`geometry.half_width_m`"),
    ("unknown kind", 'kind = "column"', 'kind = "tower"', "`kind`"),
    ("unknown reference key", "p_l_rad_per_s = 2.51", "p_l_rad_per_s = 2.51\nomega = 3", "unknown key `reference.omega`"),
    ("empirical restitution out of range", "sigma = 0.025", "sigma = 0.025\nempirical = [0.9, 1.3]",
     "`restitution.empirical[1]`"),
]


@pytest.mark.parametrize("desc, old, new, fragment", CASES, ids=[c[0] for c in CASES])
def test_bad_field_is_named(tmp_path, s1_text, desc, old, new, fragment):
    assert old in s1_text
    with pytest.raises(SpecimenError) as info:
        _load_with(tmp_path, s1_text.replace(old, new, 1))
    msg = str(info.value)
    assert fragment in msg
    assert "bad.toml" in msg          # names the file


def test_value_is_quoted_in_the_message(tmp_path, s1_text):
    with pytest.raises(SpecimenError, match=r"-0\.005"):
        _load_with(tmp_path, s1_text.replace("zeta_1 = 0.005", "zeta_1 = -0.005"))


def test_not_toml(tmp_path):
    with pytest.raises(SpecimenError, match="not a valid TOML"):
        _load_with(tmp_path, "this is = = not toml [\n")


def test_binary_file(tmp_path):
    p = tmp_path / "bin.toml"
    p.write_bytes(b"\xff\xfe\x00\x01")
    with pytest.raises(SpecimenError):
        specimens.load(p)


def test_specimen_error_is_a_value_error():
    assert issubclass(SpecimenError, ValueError)


def test_every_bundled_file_is_strict_toml():
    for name, path in specimens.loader._bundled().items():
        tomllib.loads(path.read_text())
