"""Specimen files written back with some tables replaced (multimass.specimens.toml_text)."""

import tomllib

import pytest

from multimass.specimens import SpecimenError, load
from multimass.specimens.toml_text import format_table, replace_tables, specimen_text


def test_replaced_table_keeps_the_rest_of_the_file_and_its_comments():
    text = '# head\nkind = "column"\n[damping]\nzeta_1 = 0.005  # c\n[sensors]\nA1 = 2\n'
    new = replace_tables(text, {"damping": {"zeta_1": 0.007}, "extra": {"x": [1.0, 2.5]}}, note="n")
    data = tomllib.loads(new)
    assert data["damping"] == {"zeta_1": 0.007} and data["sensors"] == {"A1": 2}
    assert data["extra"] == {"x": [1.0, 2.5]} and new.startswith("# head\n")
    assert new.count("# n") == 2


def test_specimen_text_loads_back_with_the_new_values(tmp_path):
    rest = {"mean_right": 0.94, "mean_left": 0.88, "sigma": 0.03, "empirical": [0.9, 0.85]}
    path = tmp_path / "S1_x.toml"
    path.write_text(specimen_text(load("S1"), {"restitution": rest}, name="S1_x"), "utf-8")
    spec = load(path)
    assert (spec.name, spec.r_right, spec.r_left, spec.sigma_r) == ("S1_x", 0.94, 0.88, 0.03)
    assert spec.r_empirical == (0.9, 0.85) and spec.heights == load("S1").heights


def test_invalid_values_and_unknown_files_are_named():
    with pytest.raises(SpecimenError, match="restitution.mean_right"):
        specimen_text(
            load("S1"), {"restitution": {"mean_right": 1.5, "mean_left": 0.8, "sigma": 0.02}}
        )
    with pytest.raises(SpecimenError, match="finite numbers only"):
        format_table("damping", {"zeta_1": float("nan")})
    spec = load("S1")
    with pytest.raises(SpecimenError, match="its TOML file is unknown"):
        specimen_text(spec, {}, path="no_such_specimen_file.toml")
