"""An overturning map's tables and timing, against one `map_cell` per cell.

`overturning_map` assembles its cells column by column and summarises them with array
operations; the references here are built the plain way — one `map_cell` call per
cell, one row per cell, one filter per ω/p — so a change of the fast assembly that
altered a value, a type or an order shows. ``wall_time_s`` must cover the whole call,
the assembly of the tables included: a slow step patched in shows in it.
"""

import dataclasses
import math
import time

import numpy as np
import pandas as pd
import pytest

import multimass
from multimass.sweeps import map_cells, maps
from multimass.sweeps.map_cells import _Cell, map_cell
from multimass.sweeps.maps import default_backend, overturning_map

GRID = dict(omega_p=np.linspace(0.5, 10, 7), amp=np.linspace(0.25, 8, 6))


@pytest.fixture(scope="module")
def block():
    return multimass.rigid_block("B6M")


@pytest.fixture(scope="module")
def refined(block):
    return overturning_map(block, "sine", refine=2, executor="serial", progress=False, **GRID)


def _per_cell(block, w, a):
    """`map_cell` of the cell (ω/p, a0/(α g)) = (w, a), on the map's default options."""
    options = default_backend(dict(impact="CIM", restitution="modified", k=None))
    cell = _Cell(
        block, "sine", float(w * block.p), float(a * block.alpha_cg * block.g), 10.0, options
    )
    return map_cell(cell)


def test_every_cell_is_what_map_cell_gives_for_it(block, refined):
    rows = []
    for w, a, grid in zip(refined.cells.omega_p, refined.cells.amp, refined.cells.grid):
        outcome, t_over, theta, impacts, _, accurate = _per_cell(block, w, a)
        rows.append(
            {
                "omega_p": w,
                "amp": a,
                "outcome": outcome,
                "overturn_time": t_over,
                "theta_max_over_alpha": theta,
                "n_impacts": impacts,
                "accurate": accurate,
                "grid": grid,
            }
        )
    reference = pd.DataFrame(rows)  # one row per cell: the plain assembly
    # batched and per-cell runs agree bit for bit (test_batched_maps.py); 1e-12 as there
    for col in ("omega_p", "amp", "outcome", "n_impacts", "accurate", "grid"):
        pd.testing.assert_series_equal(refined.cells[col], reference[col])
    for col in ("overturn_time", "theta_max_over_alpha"):
        np.testing.assert_allclose(refined.cells[col], reference[col], rtol=0.0, atol=1e-12)
    n_grid = GRID["omega_p"].size * GRID["amp"].size
    assert refined.cells.grid.sum() == n_grid and len(refined.cells) > n_grid  # refined too
    assert set(refined.cells.outcome) >= {"overturned", "rest", "no_rocking"}


def test_grid_is_the_pivot_of_the_grid_cells(refined):
    g = refined.cells[refined.cells.grid]
    pivot = g.pivot(index="amp", columns="omega_p", values="outcome")
    expected = pivot.loc[refined.amp, refined.omega_p].to_numpy()
    np.testing.assert_array_equal(refined.grid, expected)


def test_min_overturn_amp_filtered_per_omega(refined):
    expected = []  # the rule of its docstring, one filter per ω/p
    b, c = refined.boundaries, refined.cells
    for w in refined.omega_p:
        over = c[(c.omega_p == w) & (c.outcome == "overturned")]
        if over.empty:
            expected.append(None)
            continue
        first = float(over.amp.min())
        seg = b[(b.omega_p == w) & (b.high_outcome == "overturned") & (b.amp_high <= first + 1e-12)]
        expected.append(float(seg.amp_high.min()) if not seg.empty else first)
    assert refined.min_overturn_amp() == expected
    assert any(x is None for x in expected) and any(x is not None for x in expected)


def test_summary_counts_the_grid(refined):
    s = refined.summary()
    values, counts = np.unique(refined.grid.astype(str), return_counts=True)
    assert s["outcomes"] == {k: int(dict(zip(values, counts)).get(k, 0)) for k in maps.OUTCOMES}
    assert s["overturn_fraction"] == np.mean(refined.grid == "overturned")
    assert 0.0 < s["simulation_time_s"] <= s["wall_time_s"]
    assert "assembling the tables" in s["wall_time_covers"]


@pytest.mark.parametrize("adaptive", [False, True])
def test_wall_time_covers_the_assembly(block, monkeypatch, adaptive):
    pause = 0.3
    columns = maps._cells_columns

    def slow_columns(*args):  # the assembly of a cells table, made slow on purpose
        time.sleep(pause)
        return columns(*args)

    monkeypatch.setattr(maps, "_cells_columns", slow_columns)
    kw = dict(adaptive=True, coarse=2) if adaptive else {}
    m = overturning_map(block, "sine", refine=1, executor="serial", progress=False, **GRID, **kw)
    # at least one table (the refined cells; the grid's too when not adaptive) slept
    assert m.wall_time_s - m.simulation_time_s >= pause


def test_wall_time_covers_loading_and_checking_before_the_cells(block, monkeypatch):
    pause = 0.2
    batch_runs = map_cells.batch_runs

    def slow_batch(*args):  # laying out the compiled batch, before any cell runs
        time.sleep(pause)
        return batch_runs(*args)

    monkeypatch.setattr(maps, "batch_runs", slow_batch)
    m = overturning_map(block, "sine", executor="serial", progress=False, **GRID)
    assert m.wall_time_s - m.simulation_time_s >= pause
    assert math.isfinite(m.simulation_time_s) and m.simulation_time_s > 0.0


def test_a_map_summarises_the_same_before_and_after_its_tables_are_built(block):
    # the tables stay columns until read (a summary needs no pandas); the reference: the
    # same map given its tables as DataFrames
    m = overturning_map(block, "sine", refine=2, executor="serial", progress=False, **GRID)
    before = (m.summary(), m.min_overturn_amp(), m.n_simulations())
    framed = dataclasses.replace(m, cells=m.cells.copy(), boundaries=m.boundaries.copy())
    assert isinstance(m.cells, pd.DataFrame) and isinstance(m.boundaries, pd.DataFrame)
    for built in (m, framed):
        assert (built.summary(), built.min_overturn_amp(), built.n_simulations()) == before
    assert before[2] == len(m.cells) and before[0]["inaccurate"] == (~m.cells.accurate).sum()
    with pytest.raises(dataclasses.FrozenInstanceError):
        m.cells = m.cells


def test_a_map_without_boundaries_has_an_empty_segment_table(block):
    # below a0 = α g the block does not rock (paper 004): no boundary to refine
    low = dict(omega_p=GRID["omega_p"], amp=np.linspace(0.1, 0.9, 3))
    m = overturning_map(block, "sine", refine=2, executor="serial", progress=False, **low)
    assert (
        m.min_overturn_amp() == dataclasses.replace(m, boundaries=m.boundaries).min_overturn_amp()
    )
    assert list(m.boundaries.columns) == maps._SEGMENT_COLUMNS and m.boundaries.empty
    assert m.cells.grid.all() and len(m.cells) == low["omega_p"].size * low["amp"].size
    assert m.min_overturn_amp() == [None] * low["omega_p"].size


def test_serial_chunks_do_not_change_the_cells(block, refined, monkeypatch):
    # one process runs the cells in chunks of SERIAL_CHUNK_CELLS (fewer compiled calls);
    # any chunking gives the same cells in the same order
    assert map_cells.chunk_count(1, 1) == 1
    assert map_cells.chunk_count(2 * map_cells.SERIAL_CHUNK_CELLS + 1, 1) == 3
    assert map_cells.chunk_count(40, 2) == 2 * map_cells.CHUNKS_PER_WORKER  # spread
    assert map_cells.chunk_count(10_000, 2) == math.ceil(10_000 / map_cells.CHUNK_CELLS)
    monkeypatch.setattr(map_cells, "SERIAL_CHUNK_CELLS", 5)
    small = overturning_map(block, "sine", refine=2, executor="serial", progress=False, **GRID)
    pd.testing.assert_frame_equal(small.cells, refined.cells)
    pd.testing.assert_frame_equal(small.boundaries, refined.boundaries)


def test_the_cells_are_the_batch_kernels_own_numbers_bit_for_bit(block, monkeypatch):
    # the map reads the compiled batch's columns, never a tuple per cell: every value of
    # every cell, grid and refinement, is the kernel's own, bit for bit — the reference
    # is one `run_pulses` call on the same cells here, whatever the map's chunking
    from multimass.engines.fast import block_runs

    monkeypatch.setattr(maps, "BATCHED", True)
    monkeypatch.setattr(map_cells, "SERIAL_CHUNK_CELLS", 5)  # several strided chunks
    got, simulate = [], maps.simulate_cells

    def kept(*args):
        got.append(simulate(*args))
        return got[-1]

    monkeypatch.setattr(maps, "simulate_cells", kept)
    m = overturning_map(block, "sine", refine=2, executor="serial", progress=False, **GRID)
    cells = m.cells
    options = default_backend(dict(impact="CIM", restitution="modified", k=None))
    b = block_runs.run_pulses(
        map_cells.batch_runs(block, options),
        "sine",
        cells.amp.to_numpy() * (block.alpha_cg * block.g),  # as the map scales its axes
        cells.omega_p.to_numpy() * block.p,
        10.0,
    )
    bits = lambda x: np.asarray(x, dtype=float).view(np.int64)  # noqa: E731  (NaN == NaN)
    assert len(got) == 3 and sum(map(len, got)) == len(cells)  # the grid, two rounds
    assert cells.outcome.tolist() == [block_runs.OUTCOMES[c] for c in b.outcome.tolist()]
    np.testing.assert_array_equal(bits(cells.overturn_time), bits(b.overturn_time))
    np.testing.assert_array_equal(
        bits(cells.theta_max_over_alpha), bits(b.theta_max / block.alpha_cg)
    )
    np.testing.assert_array_equal(cells.n_impacts.to_numpy(), b.n_impacts)
    np.testing.assert_array_equal(cells.accurate.to_numpy(), b.accurate)
    np.testing.assert_array_equal(np.concatenate([r.n_rhs for r in got]), b.n_rhs)
    # read cell by cell, the columns give map_cell's tuples, the kernel's numbers in them
    i = int(np.flatnonzero(cells.outcome.to_numpy() == "overturned")[0])
    real = (b.overturn_time[i], b.theta_max[i] / block.alpha_cg)
    ints = (b.n_impacts[i], b.n_rhs[i])
    assert got[0][i] == ("overturned", *map(float, real), *map(int, ints), bool(b.accurate[i]))
    assert [type(x) for x in got[0][i]] == [type(x) for x in _per_cell(block, 1.0, 2.0)]
