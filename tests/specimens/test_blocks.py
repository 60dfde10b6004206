"""Rigid block specimens (paper 004 Table 1; paper 002 Table 1)."""

import math

import pytest

from multimass import specimens
from multimass.specimens import BlockSpecimen, SpecimenError


@pytest.mark.parametrize(
    "name, b, h, m, alpha, R, p",
    [
        # paper 004, Table 1 (p for B6M and B3L from R rounded to 4 decimals: DESIGN.md)
        ("B3M", 0.045, 0.10125, 0.5444, 0.4182, 0.0554, 11.524),
        ("B6M", 0.045, 0.2025, 1.0896, 0.2187, 0.1037, 8.423),
        ("B3L", 0.06, 0.135, 1.2843, 0.4182, 0.0739, 9.978),
        ("B6L", 0.06, 0.27, 2.5692, 0.2187, 0.1383, 7.294),
    ],
)
def test_paper_004_blocks(name, b, h, m, alpha, R, p):
    blk = specimens.load(name)
    assert isinstance(blk, BlockSpecimen)
    assert (blk.b, blk.h, blk.mass, blk.depth) == (b, h, m, b)  # depth = b (paper 004, Section 3.1)
    assert round(blk.alpha, 4) == alpha
    assert round(blk.R, 4) == R
    p_from_rounded_R = math.sqrt(3 * 9.81 / (4 * round(blk.R, 4)))
    assert round(p_from_rounded_R, 3) == p


@pytest.mark.parametrize(
    "name, k", [("B6M", 0.8241), ("B6L", 0.7214), ("B3M", 0.7595), ("B3L", 0.7259)]
)
def test_block_specific_k(name, k):
    # paper 004, Section 3 (block-specific values from its ref. [1])
    assert specimens.load(name).k == k


@pytest.mark.parametrize(
    "name, b, h, m, alpha, s, theta0",
    [
        # paper 002, Table 1 and Section 6.2
        ("B4M", 0.045, 0.135, 0.7272, 0.3218, 0.0712, 14.839),
        ("B6M", 0.045, 0.2025, 1.0896, 0.2187, 0.1037, 11.268),
        ("B8M", 0.045, 0.30375, 1.634, 0.1471, 0.1535, 7.731),
    ],
)
def test_paper_002_blocks(name, b, h, m, alpha, s, theta0):
    blk = specimens.load(name)
    assert (blk.b, blk.h, blk.mass) == (b, h, m)
    assert round(blk.alpha, 4) == alpha and round(blk.R, 4) == s
    assert blk.reference.theta0_deg == theta0


def test_k_out_of_range(tmp_path):
    text = specimens.loader._bundled()["B6M"].read_text().replace("k = 0.8241", "k = 1.3")
    p = tmp_path / "b.toml"
    p.write_text(text)
    with pytest.raises(SpecimenError, match="`restitution.k`"):
        specimens.load(p)


def test_depth_defaults_to_width_and_can_be_given(tmp_path):
    text = (
        specimens.loader._bundled()["B6M"]
        .read_text()
        .replace("height_m = 0.2025", "height_m = 0.2025\ndepth_m = 0.1")
    )
    p = tmp_path / "b.toml"
    p.write_text(text)
    assert specimens.load(p).depth == 0.1
