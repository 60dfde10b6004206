"""Batched block suites: a rigid block's runs in compiled batches, or one run at a time.

The batch (`multimass.sweeps.block_outcomes.simulate_outcomes` over
`multimass.engines.fast.block_runs`) must give what one `simulate_outcome` per run gives on
the compiled path — the reference, selected with ``runs.BATCHED = False`` — in every run:
the same outcome, status, impacts, overturning time and peak angle, bit for bit (the same
compiled integrator and event code; tests/multimass/sweeps/test_batched_maps.py compares
maps the same way). Whether a suite is batched follows the maps' rule
(`multimass.sweeps.map_cells.use_batch`): always or never when `BATCHED` says so; by default
when the batch kernels are ready or the suite has at least `BATCH_COMPILE_CELLS` runs —
and in either case only where the batch reproduces the suite's options.
"""

import dataclasses

import numpy as np
import pandas as pd
import pytest

import multimass
from multimass import G
from multimass.engines.fast import block_runs
from multimass.suites import runs as runs_mod
from multimass.suites.runs import run_suite
from multimass.suites.spec import Distribution, Suite
from multimass.sweeps import block_outcomes, map_cells
from tests.multimass.suites.test_suite_runs import RECORDS, _block_suite


def _counted(monkeypatch) -> dict:
    """How the suites run from now on (serial executor): runs given by the compiled batch,
    runs given by `suite_run`, and the ``batched`` flag of the kernels a pool would preload."""
    seen = {"batch": 0, "per_run": 0, "preload_batched": []}
    outcomes, run, preload = (
        block_outcomes.simulate_outcomes,
        runs_mod.suite_run,
        runs_mod.preload_modules,
    )

    def counted_outcomes(*args):
        r = outcomes(*args)
        seen["batch"] += int(r.batched.sum())
        return r

    def counted_run(job):
        seen["per_run"] += 1
        return run(job)

    def counted_preload(column, record, batched=False):
        seen["preload_batched"].append(batched)
        return preload(column, record, batched)

    monkeypatch.setattr(block_outcomes, "simulate_outcomes", counted_outcomes)
    monkeypatch.setattr(runs_mod, "suite_run", counted_run)
    monkeypatch.setattr(runs_mod, "preload_modules", counted_preload)
    return seen


def _both(monkeypatch, suite):
    """The suite's runs one at a time and in the batch (forced: compiled if need be)."""
    seen = _counted(monkeypatch)
    monkeypatch.setattr(runs_mod, "BATCHED", False)
    per_run = run_suite(suite, executor="serial", progress=False).runs
    assert seen["per_run"] == len(per_run) and seen["batch"] == 0
    monkeypatch.setattr(runs_mod, "BATCHED", True)
    batched = run_suite(suite, executor="serial", progress=False).runs
    assert seen["batch"] == len(batched)  # every run given by the batch, none per run
    return per_run, batched


def test_a_small_block_suite_batched_or_per_run_gives_the_same_runs(monkeypatch):
    # B6M under M&P pulses, η_M of a k drawn per run and a drawn pulse shape: 2 × 4 × 4 runs
    per_run, batched = _both(monkeypatch, _block_suite(draws=4))
    pd.testing.assert_frame_equal(batched, per_run, check_exact=True)  # every column, bit for bit
    assert batched.overturned.any() and (~batched.overturned).any()
    assert batched.n_impacts.gt(0).any()


def test_a_block_under_records_batched_as_per_run(monkeypatch):
    rec = multimass.read_record(RECORDS / "kobe_1995.dat", units="m/s2", name="Kobe")
    s = Suite(
        name="B6M under Kobe",
        structure=multimass.rigid_block("B6M"),
        records=(rec,),
        measure="pga",
        levels=np.array([0.3, 0.6, 0.9]) * G,
        draws=3,
        restitution="modified",
        k=Distribution("normal", 0.82, 0.05),
        t_free=2.0,
    )
    per_run, batched = _both(monkeypatch, s)
    pd.testing.assert_frame_equal(batched, per_run, check_exact=True)
    assert batched.n_impacts.gt(0).any()


#: 2 pulses × 4 levels × 1 draw: the suite's runs, as its cost estimate counts them
SMALL_RUNS = 2 * 4 * 1


@pytest.mark.parametrize(
    "ready, threshold, batched",
    [
        (False, map_cells.BATCH_COMPILE_CELLS, False),  # kernels not compiled, a small suite
        (True, map_cells.BATCH_COMPILE_CELLS, True),  # loaded or in numba's disk cache
        (False, SMALL_RUNS, True),  # as many runs as the threshold: pays for the compile
        (False, SMALL_RUNS + 1, False),  # one run short of it
    ],
)
def test_a_block_suite_is_batched_when_the_kernels_are_ready_or_it_is_large(
    monkeypatch, ready, threshold, batched
):
    seen = _counted(monkeypatch)
    monkeypatch.setattr(block_runs, "batch_ready", lambda: ready)
    monkeypatch.setattr(map_cells, "BATCH_COMPILE_CELLS", threshold)
    s = _block_suite(draws=1)
    assert s.n_runs == SMALL_RUNS
    r = run_suite(s, executor="serial", progress=False).runs
    assert (seen["batch"], seen["per_run"]) == ((len(r), 0) if batched else (0, len(r)))
    assert seen["preload_batched"] == [batched]  # a pool preloads the batch kernels only then


@pytest.mark.parametrize("setting", [None, True])
def test_a_block_suite_the_batch_cannot_reproduce_runs_per_run_without_its_kernels(
    monkeypatch, setting
):
    # the Dirac-delta force (DD5) is not the batch's classical impact
    # (`block_runs.BlockRuns.of`): however many runs, or BATCHED = True, no batch and no
    # batch kernels in a pool
    seen = _counted(monkeypatch)
    monkeypatch.setattr(runs_mod, "BATCHED", setting)
    monkeypatch.setattr(map_cells, "BATCH_COMPILE_CELLS", 1)  # "large enough to pay"
    s = dataclasses.replace(_block_suite(draws=1), impact="DD5")
    r = run_suite(s, executor="serial", progress=False).runs
    assert (seen["batch"], seen["per_run"]) == (0, len(r))
    assert seen["preload_batched"] == [False]
