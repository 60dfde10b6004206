"""Batched overturning maps: whole chunks of cells in one compiled call.

The batch (`multimass.engines.fast.block_runs`) must give what one `map_cell` per cell gives
on the compiled path — the reference, selected with ``maps.BATCHED = False`` — in
every cell: the same outcome, impacts and accuracy flag, and the same overturning
time and peak angle. It runs the same compiled integrator and event code and a port
of the same uplift search, so the two agree bit for bit; the tests allow 1e-12 (s,
and in units of α for the peak) so that a harmless last-bit change would show as a
number, not as a different outcome.
"""

import math

import numpy as np
import pandas as pd
import pytest

import multimass
from multimass import CosineWave, Ricker, SineWave
from multimass.engines._rigid import next_uplift, uplift_threshold
from multimass.engines.fast import block_runs, encode
from multimass.engines.fast import compile as fc
from multimass.engines.fast._block_uplift import next_uplift as compiled_next_uplift
from multimass.sweeps import map_cells, maps
from multimass.sweeps.maps import overturning_map

TOL = 1e-12  # s for overturning times, units of α for peaks (see the module docstring)
GRID = dict(omega_p=np.linspace(0.5, 10, 12), amp=np.linspace(0.25, 8, 12))


def _both(monkeypatch, *args, **kwargs):
    """The map on the per-cell path and on the batched path (forced: compiled if need be)."""
    monkeypatch.setattr(maps, "BATCHED", False)
    reference = overturning_map(*args, **kwargs)
    monkeypatch.setattr(maps, "BATCHED", True)
    return reference, overturning_map(*args, **kwargs)


def _assert_same(a, b):
    ca, cb = a.cells, b.cells
    assert len(ca) == len(cb)
    for col in ("omega_p", "amp", "outcome", "n_impacts", "accurate", "grid"):
        pd.testing.assert_series_equal(ca[col], cb[col])
    for col in ("overturn_time", "theta_max_over_alpha"):
        np.testing.assert_allclose(cb[col], ca[col], rtol=0.0, atol=TOL)
    pd.testing.assert_frame_equal(a.boundaries, b.boundaries)


@pytest.mark.parametrize("pulse", ["sine", "cosine", "ricker", "mp"])
@pytest.mark.parametrize("restitution", ["modified", "housner"])
def test_batched_map_equals_per_cell_map(monkeypatch, pulse, restitution):
    a, b = _both(
        monkeypatch,
        "B6M",
        pulse,
        restitution=restitution,
        refine=1,
        executor="serial",
        **GRID,
    )
    _assert_same(a, b)
    counts = a.cells.outcome.value_counts()
    assert counts.get("overturned", 0) and counts.get("rest", 0) and counts.get("no_rocking", 0)


def test_batched_map_of_a_stocky_block_with_a_given_restitution(monkeypatch):
    a, b = _both(monkeypatch, "B3L", "sine", restitution=0.9, executor="serial", **GRID)
    _assert_same(a, b)


def test_chattering_guard_and_other_options_as_per_cell(monkeypatch):
    # two transitions within 1 s trip the guard (full contact for 1 s) in many of these cells
    kw = dict(chatter_window=1.0, chatter_count=2, method="RK45", rtol=1e-7, max_step=0.02)
    a, b = _both(monkeypatch, "B4M", "cosine", executor="serial", **GRID, **kw)
    _assert_same(a, b)


def test_undecided_cells_are_rerun_as_per_cell(monkeypatch):
    # 0.02 s of free rocking (rerun with 0.08 s): most cells stay undecided (test_maps.py)
    kw = dict(omega_p=[2.0, 4.0, 6.0], amp=[1.5, 3.0, 5.0], executor="serial", refine=2)
    a, b = _both(monkeypatch, "B6M", "sine", t_free=0.02, **kw)
    _assert_same(a, b)
    assert (b.grid == "undecided").sum() >= 3


def test_batched_map_is_the_same_on_two_worker_processes(monkeypatch):
    monkeypatch.setattr(maps, "BATCHED", True)
    kw = dict(restitution="modified", refine=1, **GRID)
    serial = overturning_map("B6M", "sine", executor="serial", **kw)
    pool = overturning_map("B6M", "sine", executor="process", workers=2, **kw)
    pd.testing.assert_frame_equal(serial.cells, pool.cells)
    pd.testing.assert_frame_equal(serial.boundaries, pool.boundaries)


#: The README's map (3 × 3 cells, η_H): too small to pay for compiling the batch kernels.
README_MAP = dict(omega_p=[1, 2, 4], amp=[1, 2, 3], restitution="housner")


def _chunks_run(monkeypatch) -> list:
    """The cell count of every compiled chunk the maps run from now on (serial executor)."""
    sizes, real = [], map_cells._map_chunk

    def counted(chunk):
        sizes.append(len(chunk.omega))
        return real(chunk)

    monkeypatch.setattr(map_cells, "_map_chunk", counted)
    return sizes


def test_a_small_map_runs_per_cell_until_the_batch_kernels_are_compiled(monkeypatch):
    # on a machine without the batch kernels (neither loaded nor in the disk cache) the
    # README's map runs one map_cell per cell, and gives what the batch (forced) gives
    sizes = _chunks_run(monkeypatch)
    monkeypatch.setattr(block_runs, "batch_ready", lambda: False)
    per_cell = overturning_map("B6M", "sine", executor="serial", progress=False, **README_MAP)
    assert sizes == []
    monkeypatch.setattr(maps, "BATCHED", True)
    batched = overturning_map("B6M", "sine", executor="serial", progress=False, **README_MAP)
    assert sum(sizes) == 9
    _assert_same(per_cell, batched)
    assert per_cell.min_overturn_amp() == batched.min_overturn_amp()
    assert len(set(per_cell.cells.outcome)) >= 2  # not a trivial map: outcomes differ
    # once the kernels are ready (loaded, or in the disk cache), the same map is batched
    monkeypatch.setattr(maps, "BATCHED", None)
    monkeypatch.setattr(block_runs, "batch_ready", lambda: True)
    sizes.clear()
    ready = overturning_map("B6M", "sine", executor="serial", progress=False, **README_MAP)
    assert sum(sizes) == 9
    _assert_same(per_cell, ready)


@pytest.mark.parametrize("refine, batched", [(0, False), (1, True)])
def test_a_map_large_enough_to_pay_for_the_compile_is_batched(monkeypatch, refine, batched):
    # the cells a map expects: its grid and, per refinement round, one boundary per ω/p;
    # here the threshold is lowered to 12 cells: 3 × 3 falls short, 3 × (3 + 1) reaches it
    sizes = _chunks_run(monkeypatch)
    monkeypatch.setattr(block_runs, "batch_ready", lambda: False)
    monkeypatch.setattr(map_cells, "BATCH_COMPILE_CELLS", 12)
    kw = README_MAP | dict(refine=refine, executor="serial", progress=False)
    overturning_map("B6M", "sine", **kw)
    assert bool(sizes) is batched


def test_use_batch_is_the_rule_of_maps_and_suites(monkeypatch):
    # BATCHED True or False decides alone; None: ready kernels, or enough runs to pay
    n = map_cells.BATCH_COMPILE_CELLS
    for ready in (False, True):
        monkeypatch.setattr(block_runs, "batch_ready", lambda ready=ready: ready)
        assert map_cells.use_batch(True, 1) and not map_cells.use_batch(False, 10 * n)
        assert map_cells.use_batch(None, 1) is ready
        assert map_cells.use_batch(None, n - 1) is ready

    def not_asked():
        raise AssertionError("a map or suite this large is batched without asking the cache")

    monkeypatch.setattr(block_runs, "batch_ready", not_asked)
    assert map_cells.use_batch(None, n) and map_cells.use_batch(None, 10 * n)


def test_batch_ready_once_the_batch_kernels_are_compiled_or_loaded():
    # after `ensure_ready` this process has them, and numba's disk cache holds them for a
    # new process (the index of `run_cells` for this machine and the current fingerprint)
    block_runs.ensure_ready(progress=False)
    assert block_runs.batch_ready()
    kernel = block_runs.bk.run_cells
    assert fc.cached_on_disk(kernel, block_runs._STAMP, block_runs._sources())


def test_a_cell_the_batch_cannot_finish_runs_per_cell(monkeypatch):
    # the batch marks a run that the per-cell path would end as "failed"; simulate one
    real = block_runs.run_pulses

    def first_fails(*args, **kwargs):
        out = real(*args, **kwargs)
        out.outcome[0] = -1
        out.theta_max[0] = math.nan
        return out

    monkeypatch.setattr(block_runs, "run_pulses", first_fails)
    st = multimass.rigid_block("B6M")
    options = maps.default_backend(dict(impact="CIM", restitution="modified", k=None))
    runs = map_cells.batch_runs(st, options)
    omega, a0 = np.array([3.0 * st.p, 5.0 * st.p]), np.array([2.0, 3.0]) * st.alpha_cg * st.g
    chunk = map_cells._Chunk(st, "sine", omega, a0, 10.0, options, runs)
    got = list(map_cells._map_chunk(chunk))  # map_cell's tuples, read from the columns
    want = [
        map_cells.map_cell(map_cells._Cell(st, "sine", w, a, 10.0, options))
        for w, a in zip(omega, a0)
    ]
    np.testing.assert_equal(got, want)  # NaN overturning times compare equal


@pytest.mark.parametrize(
    "options, batched",
    [
        (dict(impact="CIM", restitution="modified"), True),
        (dict(impact="CIM", restitution="modified", k=0.7), True),
        (dict(impact="CIM", restitution="housner", method="RK45", rtol=1e-7), True),
        (dict(impact="CIM", restitution=0.8), True),
        (dict(impact="DD2"), False),  # a Dirac-delta force
        (dict(impact="LCP"), False),  # Poisson's law
        (dict(impact="CIM", restitution="random"), False),  # a draw per impact
        (dict(impact="CIM", restitution="modified", backend="scipy"), False),
        (dict(impact="CIM", restitution="modified", integrator="newmark"), False),
        (dict(impact="CIM", restitution="modified", method="Radau"), False),
    ],
)
def test_which_maps_and_runs_go_in_batches(options, batched):
    st = multimass.rigid_block("B6M")
    runs = map_cells.batch_runs(st, maps.default_backend(options))
    assert (runs is not None) is batched
    # the same rule for the runs of a suite (block_outcomes.simulate_outcomes)
    assert (block_runs.BlockRuns.of_runs(st, maps.default_backend(options)) is not None) is batched


def test_outcome_codes_match_the_map():
    assert block_runs.OUTCOMES == maps.OUTCOMES


@pytest.mark.parametrize("pulse", ["sine", "cosine", "ricker", "mp"])
def test_pulses_are_encoded_as_encode_does(pulse):
    rng = np.random.default_rng(3)
    a, w = rng.uniform(0.1, 30.0, 50), rng.uniform(0.5, 200.0, 50)
    kind, durations, par = block_runs.encode_pulses(pulse, a, w)
    for i in range(a.size):
        exc = map_cells.PULSES[pulse](amplitude=float(a[i]), omega=float(w[i]))
        k, p, _ = encode(exc)
        assert k == kind and durations[i] == exc.duration
        np.testing.assert_array_equal(par[i], p)


def _uplift_cases(st):
    """(pulse, t0, t1): searches that take every branch of the uplift search."""
    a_th = uplift_threshold(st)
    sine = lambda a, w: SineWave(amplitude=a * a_th, omega=w)  # noqa: E731
    cosine = lambda a, w: CosineWave(amplitude=a * a_th, omega=w)  # noqa: E731
    ricker = lambda a, w: Ricker(amplitude=a * a_th, omega=w)  # noqa: E731
    return [
        (sine(2.0, 20.0), 0.0, None),  # a sampled exceedance
        (sine(1 + 1e-7, 7.3), 0.0, None),  # none sampled: a refined maximum
        (sine(0.97, 7.3), 0.0, None),  # a maximum close below: no uplift
        (sine(3.0, 11.0), 0.21, None),  # from inside the pulse, above at once
        (cosine(1.5, 9.0), 0.0, None),  # above at the start
        (cosine(1 + 1e-9, 5.13), 0.05, 0.9),  # a refined minimum
        (ricker(1.2, 15.0), 0.0, None),
        (ricker(1 + 1e-9, 4.7), 0.0123, None),  # a refined peak
        (sine(0.5, 8.0), 0.0, None),  # never
    ]


@pytest.mark.parametrize("case", range(9))
def test_compiled_uplift_search_is_next_uplift(case):
    st = multimass.rigid_block("B6M")
    exc, t0, t1 = _uplift_cases(st)[case]
    kind, par, smp = encode(exc)
    t1 = exc.duration if t1 is None else t1
    want = next_uplift(st, exc.acceleration, t0, t1)
    found, t, side, ok = compiled_next_uplift(t0, t1, uplift_threshold(st), kind, par, smp)
    assert ok
    assert (found, (t, side) if found else None) == (want is not None, want)


def test_progress_bar_counts_cells_not_chunks(capsys, monkeypatch):
    monkeypatch.setattr(maps, "BATCHED", True)
    overturning_map(
        "B6M", "sine", omega_p=np.linspace(1, 8, 6), amp=np.linspace(1, 6, 5), refine=0,
        executor="serial", progress=True,
    )  # fmt: skip
    err = capsys.readouterr().err
    assert "30/30" in err and "cell" in err
