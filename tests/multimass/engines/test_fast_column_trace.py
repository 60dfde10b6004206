"""`simulate` of a column in one compiled call (`multimass.engines.fast.column_trace`).

The reference is the same `simulate` (and `simulate_outcome`) run in its Python phase
loop (`_Plan.run_phase_loop`), which hands each segment to the same kernels and writes
the event log, the recorder's rows and the peaks itself. The whole run's log must give
that result bit for bit — the series table, every event's fields and detail, the peaks
and their times, the right-hand side count and the ledger's error — because the kernel
writes the same numbers in the same order; nothing expected here is computed by the
kernel under test.
"""

import numpy as np
import pandas as pd
import pytest

import multimass
from multimass import CosinePulse, FreeRelease, simulation
from multimass.checks import judge
from multimass.engines.fast import _column_kernel as ck
from multimass.engines.fast import column_runs
from multimass.impact_models import AngularMomentumRestitution, Classical
from multimass.model.structure import from_specimen
from multimass.sweeps.seeding import job_seeds

from .test_fast_column_runs import ELCENTRO, _record

SEEDS = job_seeds(0, 4)


@pytest.fixture(scope="module", autouse=True)
def whole_runs_compiled():
    """`simulate` takes its one-call path only where the whole column runs are compiled
    (`columns_ready`); compiled here, so that every test below compares that path."""
    from multimass.engines.fast import compile as fc

    fc.warm_up_columns(progress=False)
    assert fc.columns_ready()


def test_simulate_takes_the_one_call_path_only_when_its_kernels_are_ready(s1, monkeypatch):
    from multimass.engines.fast import column_trace

    calls = []
    real = column_trace.trace
    monkeypatch.setattr(column_trace, "trace", lambda *a, **k: calls.append(1) or real(*a, **k))
    kw = dict(backend="compiled", progress=False, output_dt=None)
    multimass.simulate(s1, FreeRelease(0.11), "DD2", 1.0, **kw)
    assert len(calls) == 1
    monkeypatch.setattr(simulation, "_columns_ready", lambda: False)  # a cold machine
    multimass.simulate(s1, FreeRelease(0.11), "DD2", 1.0, **kw)
    assert len(calls) == 1  # the phase loop, not the compile of the whole runs


def _both(st, exc, impact, t_end, lean=False, **kw):
    """(`simulate` or `simulate_outcome`, the same run in the phase loop)."""
    kw = {"backend": "compiled", "progress": False} | kw
    o = simulation.SimulationOptions.of(None, **kw | ({"output_dt": None} if lean else {}))
    plan = simulation._prepare(st, exc, impact, t_end, o)
    ref = judge(plan.run_phase_loop(lean=lean), o.energy_tol)
    run = simulation.simulate_outcome if lean else simulation.simulate
    return run(st, exc, impact, t_end, **kw), ref


def _same(got, ref):
    assert (got.status, got.message, got.outcome) == (ref.status, ref.message, ref.outcome)
    assert got.events == ref.events  # every field, details included
    assert np.array_equal(got.peaks, ref.peaks)
    assert np.array_equal(got.peak_times, ref.peak_times)
    assert got.n_rhs == ref.n_rhs
    assert got.energy_balance_error == ref.energy_balance_error
    if hasattr(got, "series") and got.series is not None and len(ref.series):
        pd.testing.assert_frame_equal(got.series, ref.series, check_exact=True)


@pytest.fixture(scope="module")
def s1():
    return from_specimen("S1")


@pytest.mark.parametrize("output_dt", [None, 2e-3])
@pytest.mark.parametrize("impact", ["DD2", "CIM"])
def test_a_release_is_the_phase_loops_bit_for_bit(s1, impact, output_dt):
    got, ref = _both(s1, FreeRelease(0.11), impact, 6.0, output_dt=output_dt)
    _same(got, ref)
    assert len(ref.events) > 20 and len(ref.peaks) > 10  # the case rocks


@pytest.mark.parametrize("lean", [False, True])
def test_random_restitution_under_a_record(s1, lean):
    exc = _record().scaled(1.3)
    for seed in SEEDS[:3]:
        got, ref = _both(s1, exc, "DD5", 8.0, lean=lean, seed=seed, output_dt=5e-3)
        _same(got, ref)
    assert any(e.kind == "dd_activate" for e in ref.events)
    assert any(e.kind == "full_contact" for e in ref.events)


def test_overturning_chattering_and_an_integrated_contact(s1):
    rec = multimass.read_record(ELCENTRO, units="g").scaled(2.0)
    got, ref = _both(s1, rec, "DD5", 20.0, seed=SEEDS[0], output_dt=None)
    _same(got, ref)
    assert ref.outcome == "overturned"
    kw = dict(seed=SEEDS[1], chatter_count=3, chatter_window=0.5, output_dt=None)
    got, ref = _both(s1, _record(), "DD5", 10.0, **kw)
    _same(got, ref)
    assert any(e.kind == "chatter_guard" for e in ref.events)
    # a pulse: full contact by the Runge–Kutta pair, not in closed form
    got, ref = _both(s1, CosinePulse(amplitude=6.0, omega=12.0), "CIM", 3.0)
    _same(got, ref)


def test_other_columns_and_the_exponential_method():
    for name in ("S2", "S3"):
        got, ref = _both(from_specimen(name), FreeRelease(0.01), "DD2", 3.0, output_dt=1e-3)
        _same(got, ref)
    rec = multimass.read_record(ELCENTRO, units="g", scale=1.5)
    got, ref = _both("S1", rec, "DD5", 5.0, method="exponential", seed=3, rtol=1e-7, atol=1e-9)
    _same(got, ref)


def test_a_log_that_does_not_fit_is_written_again(s1, monkeypatch):
    calls = []
    real = ck.column_run

    def counting(*a):
        calls.append(a[-1][1].shape[0])  # room for events
        return real(*a)

    monkeypatch.setattr(column_runs, "_FIRST_LOG", 1)
    monkeypatch.setattr(column_runs, "_LOG_PER_S", 0)
    monkeypatch.setattr(ck, "column_run", counting)
    got, ref = _both(s1, FreeRelease(0.11), "DD2", 4.0, output_dt=None)
    _same(got, ref)
    assert calls[0] == 1 and calls[-1] > len(ref.events) - 2  # short, then with room


def test_what_the_kernel_does_not_run_goes_to_the_phase_loop(s1, monkeypatch):
    def refuse(*a):
        raise AssertionError("the whole-run kernel must not be called")

    monkeypatch.setattr(ck, "column_run", refuse)
    model = Classical(restitution=AngularMomentumRestitution())  # r_h of Eq 13: state-dependent
    _same(*_both(s1, _record(), model, 4.0, output_dt=None))
    # a progress bar: the phase loop reports the time as it goes, the kernel cannot
    _same(*_both(s1, FreeRelease(0.11), "DD2", 2.0, output_dt=None, progress=True))


def test_a_run_the_kernel_cannot_finish_goes_to_the_phase_loop(s1, monkeypatch):
    broken = (column_runs.BROKEN,) + (0,) * 8
    monkeypatch.setattr(column_runs.ColumnRun, "trace", lambda self, dt: broken)
    _same(*_both(s1, FreeRelease(0.11), "DD2", 3.0, output_dt=None))


def test_the_log_compiles_once(s1):
    """Every call of the log's writers has the same argument types (floats), so each is
    compiled once: a literal int among them (a phase, a kind) compiles one more. Counted
    where the kernel compiles (a fresh cache, as in CI); loaded from numba's cache, the
    writers come inside `column_run` and list no signature of their own."""
    _both(s1, _record(), "DD5", 4.0, seed=SEEDS[2], output_dt=1e-2)
    _both(s1, FreeRelease(0.11), "CIM", 2.0, output_dt=None)
    assert len(ck._row.signatures) <= 1
    assert len(ck._event.signatures) <= 1
