"""Every bad specimen input raises SpecimenError naming the field and the fix."""

import tomllib

import pytest

from multimass import specimens
from multimass.specimens import SpecimenError


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
    (
        "unknown key",
        "zeta_2 = 0.015",
        "zeta_2 = 0.015\nzeta_3 = 0.02",
        "unknown key `damping.zeta_3`",
    ),
    (
        "lengths differ",
        "[77.3, 6.2, 88.2, 8.2, 46.2]",
        "[77.3, 6.2, 88.2, 8.2]",
        "`mass.nodal_kg` has 4 entries",
    ),
    (
        "heights not increasing",
        "[0.06, 0.49, 0.93, 1.43, 1.93]",
        "[0.06, 0.93, 0.49, 1.43, 1.93]",
        "`geometry.heights_m[2]`",
    ),
    (
        "non-positive mass",
        "[77.3, 6.2, 88.2, 8.2, 46.2]",
        "[77.3, 6.2, -88.2, 8.2, 46.2]",
        "`mass.nodal_kg[2]`",
    ),
    (
        "zero mass",
        "[77.3, 6.2, 88.2, 8.2, 46.2]",
        "[77.3, 0.0, 88.2, 8.2, 46.2]",
        "`mass.nodal_kg[1]`",
    ),
    (
        "non-positive stiffness",
        "youngs_modulus_Pa = 200e9",
        "youngs_modulus_Pa = 0.0",
        "`stiffness.youngs_modulus_Pa`",
    ),
    (
        "negative spring",
        "rotational_spring_Nm_per_rad = 2.0e6",
        "rotational_spring_Nm_per_rad = -2.0e6",
        "`stiffness.rotational_spring_Nm_per_rad`",
    ),
    ("negative damping", "zeta_1 = 0.005", "zeta_1 = -0.005", "`damping.zeta_1`"),
    ("restitution above 1", "mean_right = 0.93", "mean_right = 1.2", "`restitution.mean_right`"),
    ("restitution zero", "mean_left = 0.87", "mean_left = 0.0", "`restitution.mean_left`"),
    ("negative base mass", "base_kg = 0.0", "base_kg = -1.0", "`mass.base_kg`"),
    ("wrong type", "half_width_m = 0.305", 'half_width_m = "wide"', "`geometry.half_width_m`"),
    ("unknown kind", 'kind = "column"', 'kind = "tower"', "`kind`"),
    (
        "unknown reference key",
        "p_l_rad_per_s = 2.51",
        "p_l_rad_per_s = 2.51\nomega = 3",
        "unknown key `reference.omega`",
    ),
    (
        "empirical restitution out of range",
        "sigma = 0.025",
        "sigma = 0.025\nempirical = [0.9, 1.3]",
        "`restitution.empirical[1]`",
    ),
]


@pytest.mark.parametrize("desc, old, new, fragment", CASES, ids=[c[0] for c in CASES])
def test_bad_field_is_named(tmp_path, s1_text, desc, old, new, fragment):
    assert old in s1_text
    with pytest.raises(SpecimenError) as info:
        _load_with(tmp_path, s1_text.replace(old, new, 1))
    msg = str(info.value)
    assert fragment in msg
    assert "bad.toml" in msg  # names the file


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
    for _name, path in specimens.loader._bundled().items():
        tomllib.loads(path.read_text())


# ---------------------------------------------------------------------------- types
@pytest.mark.parametrize("kind", [[], {}, 1, None, True, 2.5])
def test_non_string_kind_is_named(kind):
    data = tomllib.loads(specimens.loader._bundled()["S1"].read_text()) | {"kind": kind}
    with pytest.raises(
        SpecimenError, match=r"`kind` = .*unknown kind; use one of 'beam', 'block', 'column'"
    ):
        specimens.from_mapping(data)


@pytest.mark.parametrize("name", ["B6M", "S1", "beam_mudric2024"])
@pytest.mark.parametrize(
    "field, value, fragment",
    [
        ("name", [], "expected a string"),
        ("name", 7, "expected a string"),
        ("name", "  ", "expected a non-empty string"),
        ("description", {"a": 1}, "expected a string"),
        ("source", True, "expected a string"),
    ],
)
def test_non_string_text_fields_are_named(name, field, value, fragment):
    data = tomllib.loads(specimens.loader._bundled()[name].read_text()) | {field: value}
    with pytest.raises(SpecimenError, match=rf"`{field}` = .*{fragment}"):
        specimens.from_mapping(data, "mine.toml")


@pytest.mark.parametrize("data", [None, 5, "kind = 'column'", ["kind"], b"x"])
def test_from_mapping_needs_a_mapping(data):
    with pytest.raises(SpecimenError, match="expected a mapping of specimen fields"):
        specimens.from_mapping(data)


def test_non_string_keys_are_reported_not_sorted():
    data = tomllib.loads(specimens.loader._bundled()["S1"].read_text())
    data["geometry"] = {**data["geometry"], 1: 2.0}
    with pytest.raises(SpecimenError, match="unknown key `geometry.1`"):
        specimens.from_mapping(data)


def test_integer_beyond_the_float_range():
    data = tomllib.loads(specimens.loader._bundled()["S1"].read_text())
    data["mass"] = {**data["mass"], "base_kg": 10**400}
    with pytest.raises(SpecimenError, match=r"`mass.base_kg` = .*beyond the float range"):
        specimens.from_mapping(data)


@pytest.mark.parametrize("value", [None, 123, 1.5, b"S1", "S1\0", ["S1"]])
def test_load_needs_a_name_or_a_path(value):
    with pytest.raises(SpecimenError, match=r"`specimen` = .*bundled name"):
        specimens.load(value)


def test_a_directory_is_not_a_specimen(tmp_path):
    with pytest.raises(SpecimenError, match="is a directory; give a specimen TOML file"):
        specimens.load(tmp_path)


# ---------------------------------------------------------------------------- unit slips
SLIPS = [
    # (bundled, old, new, message fragment: field, value, range, likely fix)
    (
        "S1",
        "youngs_modulus_Pa = 200e9",
        "youngs_modulus_Pa = 200",
        r"`stiffness.youngs_modulus_Pa` = 200: implausible Young's modulus 200 Pa.*\[1e6, 1e15\] Pa"
        r".*did you type GPa\? write 200e9",
    ),
    (
        "S1",
        "youngs_modulus_Pa = 200e9",
        "youngs_modulus_Pa = 200000",
        r"did you type MPa\? write 200000e6",
    ),
    (
        "S1",
        "youngs_modulus_Pa = 200e9",
        "youngs_modulus_Pa = 1e300",
        r"give it in Pa \(steel is 200e9",
    ),
    (
        "S1",
        "youngs_modulus_Pa = 200e9",
        "youngs_modulus_Pa = 1e-300",
        r"implausible Young's modulus 1e-300",
    ),
    (
        "S1",
        "youngs_modulus_Pa = 200e9",
        "youngs_modulus_Pa = 5e-324",
        r"implausible Young's modulus",
    ),
    (
        "S1",
        "second_moment_m4 = 183.3e-8",
        "second_moment_m4 = 183.3",
        r"`stiffness.second_moment_m4` = 183.3: implausible second moment of area 183.3 m\^4: a section "
        r"that fits in the column's footprint 2B x 2B \(B = `geometry.half_width_m` = 0.305 m\) has "
        r"I <= \(2B\)\^4/12 = 0.01154 m\^4; did you type cm\^4\? write 183.3e-8",
    ),
    (
        "S1",
        "[0.06, 0.49, 0.93, 1.43, 1.93]",
        "[60, 490, 930, 1430, 1930]",
        r"`geometry.heights_m\[3\]` = 1430: implausible length.*did you type mm\? write 1.43",
    ),
    (
        "S1",
        "[0.06, 0.49, 0.93, 1.43, 1.93]",
        "[0.06e-300, 0.49e-300, 0.93e-300, 1.43e-300, 1.93e-300]",
        r"`geometry.heights_m\[0\]` = 6e-302: implausible length",
    ),
    ("S1", "half_width_m = 0.305", "half_width_m = 1e300", r"`geometry.half_width_m` = 1e\+300"),
    ("S1", "gravity_m_per_s2 = 9.81", "gravity_m_per_s2 = 1", r"did you type g\? write 9.81"),
    (
        "S1",
        "sigma = 0.025",
        "sigma = 2.5",
        r"`restitution.sigma` = 2.5.*did you type %\? write 0.025",
    ),
    ("S1", "base_inertia_kgm2 = 10.0", "base_inertia_kgm2 = 1e300", r"`mass.base_inertia_kgm2`"),
    (
        "S1",
        "horizontal_spring_N_per_m = 5.0e8",
        "horizontal_spring_N_per_m = 5e-324",
        r"`stiffness.horizontal_spring_N_per_m`.*implausible spring stiffness",
    ),
    (
        "S1",
        "[77.3, 6.2, 88.2, 8.2, 46.2]",
        "[77.3, 6.2, 88.2, 8.2, 46.2e300]",
        r"`mass.nodal_kg\[4\]`",
    ),
    (
        "S1",
        "[0.06, 0.49, 0.93, 1.43, 1.93]",
        "[0.06, 0.49, 0.93, 1.4300001, 1.43002]",
        r"`geometry.heights_m\[4\]` = 1.43002 is only 1.99e-05 m above node 4.*merge the two nodes",
    ),
    (
        "S1",
        "full_contact_freq_hz = [7.6, 41.4]",
        "full_contact_freq_hz = [7.6, 5e-324]",
        r"`reference.full_contact_freq_hz\[1\]`",
    ),
    (
        "B6M",
        "width_m = 0.045",
        "width_m = 45",
        r"`mass.mass_kg` = 1.0896: implausible mean density"
        r" mass / \(b h depth\) = 0.002657 kg/m\^3 .*give `geometry.depth_m`",
    ),
    (
        "B6M",
        "mass_kg = 1.0896",
        "mass_kg = 1089.6",
        r"implausible mean density .* = 2.657e\+06 kg/m\^3",
    ),
    ("B6M", "height_m = 0.2025", "height_m = 1e300", r"`geometry.height_m` = 1e\+300"),
    ("B6M", "theta0_deg = 11.268", "theta0_deg = 1e300", r"`reference.theta0_deg`"),
    (
        "beam_mudric2024",
        "youngs_modulus_Pa = 1e24",
        "youngs_modulus_Pa = 70",
        r"implausible Young's modulus 70 Pa.*paper 002's rigid-base convention 1e24 Pa.*write 70e9",
    ),
    (
        "beam_mudric2024",
        "youngs_modulus_Pa = 1e24",
        "youngs_modulus_Pa = 1e25",
        r"\[1e6, 1e24\] Pa",
    ),
    (
        "beam_mudric2024",
        "density_kg_per_m3 = 2795.0",
        "density_kg_per_m3 = 2.795",
        r"did you type g/cm\^3\? write 2795",
    ),
    (
        "beam_mudric2024",
        "section_height_m = 0.00171",
        "section_height_m = 1.71",
        r"`geometry.section_height_m` = 1.71 m is not less than the span",
    ),
    ("beam_mudric2024", "n_elements = 6", "n_elements = 1000000", r"`mesh.n_elements` = 1000000"),
    (
        "beam_mudric2024",
        "friction_coefficient = 0.364",
        "friction_coefficient = 1e300",
        r"`contact.friction_coefficient`",
    ),
]


@pytest.mark.parametrize(
    "name, old, new, fragment", SLIPS, ids=[f"{c[0]}:{c[2]}"[:60] for c in SLIPS]
)
def test_unit_slips_are_refused_with_the_likely_fix(tmp_path, name, old, new, fragment):
    text = specimens.loader._bundled()[name].read_text()
    assert old in text
    with pytest.raises(SpecimenError, match=fragment) as info:
        _load_with(tmp_path, text.replace(old, new, 1))
    assert "bad.toml" in str(info.value) and "\n" not in str(info.value)


def test_beam_keeps_paper_002_rigid_base_convention(tmp_path):
    # paper 002, Section 6.1: E = 1e24 Pa is the rigid base; the bundled beam uses it
    assert specimens.load("beam_mudric2024").E == 1e24


@pytest.mark.parametrize(
    "old, new",
    [
        ("width_m = 0.045", "width_m = 0.045\ndepth_m = 4.5"),  # depth: density 26.6 kg/m3
        ("mass_kg = 1.0896", "mass_kg = 5.0"),  # a steel block: 12 190 kg/m3
    ],
)
def test_plausible_blocks_pass(tmp_path, old, new):
    text = specimens.loader._bundled()["B6M"].read_text()
    assert specimens.load(_write(tmp_path, text.replace(old, new, 1))).name == "B6M"
