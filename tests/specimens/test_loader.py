"""Loading bundled and user specimens (paper 001, Table 1)."""

import dataclasses
import shutil

import pytest

from multimass import specimens
from multimass.specimens import ColumnSpecimen, SpecimenError


def test_available_lists_the_bundled_columns():
    assert {"S1", "S2", "S3"} <= set(specimens.available())


@pytest.mark.parametrize("name", ["S1", "S2", "S3"])
def test_bundled_specimens_load_as_frozen_columns(name):
    spec = specimens.load(name)
    assert isinstance(spec, ColumnSpecimen)
    assert spec.name == name
    with pytest.raises(dataclasses.FrozenInstanceError):
        spec.B = 1.0


def test_s1_holds_table_1_inputs():
    # paper 001, Table 1 (S1 column and the common parameters under it)
    s1 = specimens.load("S1")
    assert s1.heights == (0.06, 0.49, 0.93, 1.43, 1.93)
    assert s1.masses == (77.3, 6.2, 88.2, 8.2, 46.2)
    assert (s1.m0, s1.J0, s1.B) == (0.0, 10.0, 0.305)
    assert s1.E_s == 200e9 and s1.I_s == pytest.approx(183.3e-8)
    assert s1.K_rot == 2.0e6 and s1.K_fp == 5.0e8
    assert (s1.zeta_1, s1.zeta_2) == (0.005, 0.015)  # fractions (DESIGN.md)
    assert (s1.r_right, s1.r_left, s1.sigma_r) == (0.93, 0.87, 0.025)
    ref = s1.reference
    assert (ref.J_p, ref.H_cg, ref.alpha_cg, ref.p_l) == (298, 0.84, 0.35, 2.51)
    # paper 001, Section 4.2: 7.6 / 41.4 Hz full contact, 20.7 / 46.9 Hz uplifted
    assert ref.full_contact_freq_hz == (7.6, 41.4)
    assert ref.rocking_freq_hz == (20.7, 46.9)


def test_names_are_case_insensitive():
    assert specimens.load("s2") == specimens.load("S2")


def test_a_user_file_loads_like_a_bundled_one(tmp_path):
    src = specimens.load("S3")
    path = tmp_path / "mine.toml"
    shutil.copy(specimens.loader._bundled()["S3"], path)
    assert specimens.load(path) == src
    assert specimens.load(str(path)) == src


def test_unknown_name_lists_the_bundled_ones():
    with pytest.raises(SpecimenError, match="S1, S2, S3"):
        specimens.load("S9")


def test_specimens_pickle_for_process_pools():
    import pickle

    s1 = specimens.load("S1")
    assert pickle.loads(pickle.dumps(s1)) == s1


def test_a_file_is_read_again_when_it_changes(tmp_path):
    # the loader keeps what it read until the file's modification time or size changes
    path = tmp_path / "mine.toml"
    shutil.copy(specimens.loader._bundled()["S1"], path)
    first = specimens.load(path)
    assert specimens.load(path) is first  # unchanged: the same frozen specimen
    path.write_text(path.read_text().replace('name = "S1"', 'name = "edited"'))
    again = specimens.load(path)
    assert again.name == "edited" and first.name == "S1"
    path.write_text("kind = 'column'\nname = [")  # now broken: the error, not the old one
    with pytest.raises(SpecimenError, match="not a valid TOML"):
        specimens.load(path)
