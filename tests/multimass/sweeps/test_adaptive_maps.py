"""Adaptive overturning maps: identical to brute force, fewer cells.

The adaptive map refines a coarse lattice only where neighbouring cells disagree
(`multimass.sweeps.map_adaptive`); on the B6M maps it must reproduce the brute-force
map in every cell, safe islands included, while simulating a fraction of the cells.
"""

import numpy as np
import pytest

from multimass.errors import InputError
from multimass.sweeps.map_adaptive import _mixed_blocks, adaptive_codes, count_islands
from multimass.sweeps.maps import overturning_map


def _grid(n):
    return dict(omega_p=np.linspace(0.5, 10, n), amp=np.linspace(0.25, 8, n))


@pytest.mark.parametrize("n", [64, 128])
@pytest.mark.parametrize("pulse", ["sine", "cosine"])
def test_adaptive_map_equals_brute_force(n, pulse):
    brute = overturning_map("B6M", pulse, refine=1, executor="serial", **_grid(n))
    adapt = overturning_map("B6M", pulse, refine=1, executor="serial", adaptive=True, **_grid(n))
    np.testing.assert_array_equal(adapt.grid, brute.grid)
    assert count_islands(adapt.grid) == count_islands(brute.grid)
    assert count_islands(brute.grid) > 0  # the maps have safe islands to find
    info = adapt.options["adaptive"]
    assert info["cells"] == n * n
    assert info["computed"] == int(adapt.cells.query("grid").computed.sum())
    assert info["computed"] < (0.55 if n == 64 else 0.35) * n * n  # measured 0.43-0.47, 0.26-0.27
    # computed cells carry the brute-force numbers; the boundaries refine alike
    computed = adapt.cells.query("grid and computed").reset_index(drop=True)
    ref = brute.cells.query("grid").reset_index(drop=True)
    ref = ref.set_index(["amp", "omega_p"]).loc[list(zip(computed.amp, computed.omega_p))]
    np.testing.assert_array_equal(computed.overturn_time, ref.overturn_time)
    np.testing.assert_array_equal(computed.n_impacts.astype(int), ref.n_impacts)
    assert adapt.boundaries.equals(brute.boundaries)
    assert adapt.summary()["n_simulations"] == info["computed"] + int((~adapt.cells.grid).sum())


def _synthetic(truth):
    calls = []

    def evaluate(index):
        calls.append(len(index))
        return truth[index[:, 0], index[:, 1]]

    return evaluate, calls


def test_island_of_coarse_size_is_found_and_smaller_far_one_may_be_missed():
    truth = np.zeros((65, 65), int)
    truth[20:28, 33:41] = 1  # 8 x 8: contains a lattice cell of spacing 8, always found
    codes, computed = adaptive_codes(65, 65, _synthetic(truth)[0], coarse=8)
    np.testing.assert_array_equal(codes, truth)
    assert computed.sum() < truth.size / 2
    lone = np.zeros((65, 65), int)
    lone[3, 3] = 1  # one cell, between lattice cells, far from any boundary: the stated limit
    codes, _ = adaptive_codes(65, 65, _synthetic(lone)[0], coarse=8)
    assert codes[3, 3] == 0
    codes, computed = adaptive_codes(65, 65, _synthetic(lone)[0], coarse=1)  # brute force
    assert codes[3, 3] == 1 and computed.all()


def test_boundary_cells_follow_a_curved_boundary_exactly():
    i, j = np.mgrid[0:100, 0:77]
    truth = ((i - 40) ** 2 + (j - 30) ** 2 < 900).astype(int) + 2 * (j > 60)
    codes, computed = adaptive_codes(100, 77, _synthetic(truth)[0], coarse=16)
    np.testing.assert_array_equal(codes, truth)
    assert computed.sum() < 0.5 * truth.size


@pytest.mark.parametrize("coarse", [3, 0, 2.5, True])
def test_coarse_must_be_a_power_of_two(coarse):
    with pytest.raises(InputError, match="`coarse`"):
        adaptive_codes(8, 8, lambda idx: np.zeros(len(idx)), coarse=coarse)


def test_count_islands():
    g = np.full((6, 7), "overturned", dtype=object)
    g[2, 2] = g[3, 2] = "rest"  # an island of two cells
    g[2, 5] = "rest"
    g[3, 5] = "undecided"  # not surrounded by overturned cells
    g[0, 0] = "rest"  # touches the edge
    assert count_islands(g) == 1


def test_adaptive_and_store_do_not_combine(tmp_path):
    with pytest.raises(InputError, match="`adaptive`"):
        overturning_map("B6M", executor="serial", adaptive=True, store=tmp_path, **_grid(4))


def test_cli_adaptive_reports_the_computed_cells(capsys):
    from multimass.cli import main

    argv = ["stability", "B6M", "--executor", "serial", "--omega-p", "0.5:10:33"]
    assert main(argv + ["--amp", "0.25:8:33", "--adaptive", "--coarse", "4"]) == 0
    out = capsys.readouterr().out
    assert " of 1089 grid cells computed" in out


def test_cli_writes_a_large_adaptive_map_as_parquet(tmp_path, capsys, monkeypatch):
    import pandas as pd

    from multimass.cli import main, stability_cmd

    monkeypatch.setattr(stability_cmd, "STORE_MIN_CELLS", 1000)  # 33 × 33 counts as large
    argv = ["stability", "B6M", "--executor", "serial", "--omega-p", "0.5:10:33"]
    argv += ["--amp", "0.25:8:33", "--adaptive", "--coarse", "4", "--out", str(tmp_path)]
    assert main(argv) == 0
    cells = pd.read_parquet(tmp_path / "B6M_sine_modified_cells.parquet")
    assert int(cells.grid.sum()) == 1089
    assert not (tmp_path / "B6M_sine_modified_cells.csv").exists()


def test_mixed_blocks_as_one_block_at_a_time():
    # the rule of the module docstring, block by block: the computed cells (≥ 0) of the
    # closed block do not all share one class; seeded random grids with uncomputed cells
    rng = np.random.default_rng(3)
    for _ in range(5):
        codes = rng.integers(-1, 3, size=(23, 17)).astype(np.int32)
        codes[rng.random(codes.shape) < 0.5] = -1
        blocks = [
            (a0, min(a0 + da, 22), w0, min(w0 + dw, 16))
            for a0 in range(0, 23, 3)
            for w0 in range(0, 17, 4)
            for da, dw in ((1, 1), (2, 4), (4, 2), (0, 3))
        ]
        expected = []
        for a0, a1, w0, w1 in blocks:
            known = codes[a0 : a1 + 1, w0 : w1 + 1]
            known = known[known >= 0]
            expected.append(bool(known.size) and bool(known.min() != known.max()))
        assert _mixed_blocks(codes, blocks) == expected
        assert any(expected) and not all(expected)
