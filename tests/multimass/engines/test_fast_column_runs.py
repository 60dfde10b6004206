"""Whole column runs in one compiled call (`multimass.engines.fast.column_runs`, `._column_kernel`).

The reference is the per-run compiled path: `multimass.simulate_outcome` with
``backend="compiled"`` run in its Python phase loop (`_loop_outcome`:
`multimass.engines._run.PhaseLoop`, `multimass.engines._events`), which hands each
segment to the same kernels. The whole run must be
that run bit for bit — θ_max, status, impacts, overturning time — because it makes
the same calls in the same order; none of the expected values is computed by the
kernel under test. Random restitution (DD5) makes a run chaotic in its last bits,
so bit-identity is the only comparison that can catch a transition done out of order.
"""

import math
from pathlib import Path

import numpy as np
import pytest

import multimass
from multimass import CosinePulse, FreeRelease, Record, simulation
from multimass.checks import judge
from multimass.engines.fast import _column_kernel as ck
from multimass.engines.fast import column_runs
from multimass.impact_models import (
    AngularMomentumRestitution,
    Classical,
    CornerRestitution,
    DiracDelta,
    EmpiricalRestitution,
)
from multimass.model.structure import from_specimen
from multimass.simulation import outcome_summary, simulate_outcome
from multimass.sweeps.seeding import job_seeds
from multimass.sweeps.spectra import record_spectrum

SEEDS = job_seeds(0, 8)
ELCENTRO = Path(__file__).resolve().parents[3] / "examples" / "data" / "elcentro_1940_NS_15s.dat"


def _record(seed=3, n=400, dt=0.02, peak=4.0):
    rng = np.random.default_rng(seed)
    acc = peak * np.sin(np.arange(n) * dt * 2 * np.pi * 2.5) * rng.uniform(0.3, 1.0, n)
    return Record.from_arrays(np.arange(n) * dt, acc, units="m/s2")


def _loop_outcome(st, exc, impact, t_end, **kw):
    """`simulate_outcome` with ``backend="compiled"`` in its Python phase loop (which
    `simulate_outcome` itself leaves for the whole-run kernel where that applies)."""
    kw = {"backend": "compiled", "output_dt": None, "progress": False} | kw
    plan = simulation._prepare(st, exc, impact, t_end, simulation.SimulationOptions.of(None, **kw))
    return judge(plan.run_phase_loop(lean=True), plan.options.energy_tol)


def _reference(st, exc, impact, t_end, **kw):
    """The per-run compiled path's summary (the Python phase loop)."""
    r = _loop_outcome(st, exc, impact, t_end, **kw)
    t_over = next((e.time for e in r.events if e.kind == "overturn"), math.nan)
    return r.theta_max, r.status, r.n_impacts, t_over


def _whole(st, exc, impact, t_end, **kw):
    got = outcome_summary(st, exc, impact, t_end, backend="compiled", **kw)
    return tuple(got[i] for i in (0, 2, 3, 4))


def _same(a, b):
    assert a[1:3] == b[1:3]
    assert a[0] == b[0]  # bit for bit
    assert (math.isnan(a[3]) and math.isnan(b[3])) or a[3] == b[3]


@pytest.fixture(scope="module")
def s1():
    return from_specimen("S1")


@pytest.mark.parametrize("impact", ["DD5", "DD2", "CIM"])
@pytest.mark.parametrize("scale", [0.5, 1.0, 1.6])
def test_whole_run_is_the_per_run_path_bit_for_bit(s1, impact, scale):
    exc = _record().scaled(scale)
    for seed in SEEDS[:3]:
        ref = _reference(s1, exc, impact, 10.0, seed=seed)
        got = _whole(s1, exc, impact, 10.0, seed=seed)
        _same(got, ref)
    assert ref[2] > 0  # the case rocks


def test_whole_run_overturns_at_the_same_time(s1):
    exc = multimass.read_record(ELCENTRO, units="g").scaled(2.0)
    for seed in SEEDS[:4]:
        ref = _reference(s1, exc, "DD5", 20.0, seed=seed)
        _same(_whole(s1, exc, "DD5", 20.0, seed=seed), ref)
    assert ref[1] == "overturned"


@pytest.mark.parametrize("name", ["S2", "S3"])
def test_other_columns_and_a_release(name):
    st = from_specimen(name)
    for exc, t_end in ((FreeRelease(theta0=0.01), 3.0), (_record().scaled(0.8), 8.0)):
        for impact in ("DD5", "CIM"):
            ref = _reference(st, exc, impact, t_end, seed=SEEDS[1])
            _same(_whole(st, exc, impact, t_end, seed=SEEDS[1]), ref)


def test_a_pulse_integrates_full_contact_and_still_matches(s1):
    exc = CosinePulse(amplitude=6.0, omega=12.0)
    ref = _reference(s1, exc, "DD5", 4.0, seed=SEEDS[2])
    assert ref[2] > 0
    _same(_whole(s1, exc, "DD5", 4.0, seed=SEEDS[2]), ref)


def test_running_out_of_random_draws_reruns_with_more(s1, monkeypatch):
    exc = _record()
    ref = _reference(s1, exc, "DD5", 10.0, seed=SEEDS[3])
    assert ref[2] > 8  # needs more than the first draws below
    calls = []
    real = ck.column_run

    def counting(*a):
        calls.append(a[-2].size)  # the draws
        return real(*a)

    monkeypatch.setattr(column_runs, "_FIRST_DRAWS", 2)
    monkeypatch.setattr(ck, "column_run", counting)
    _same(_whole(s1, exc, "DD5", 10.0, seed=SEEDS[3]), ref)
    assert calls[0] == 2 and len(calls) > 1  # it ran short, then again with more


def test_impact_specific_restitution_then_corner_means(s1):
    exc = _record()
    source = EmpiricalRestitution((0.9, 0.5, 0.7, 0.95), CornerRestitution(0.8, 0.75))
    for model in (Classical(restitution=source), DiracDelta(restitution=source)):
        ref = _reference(s1, exc, model, 10.0)
        assert ref[2] > 4  # past the table
        _same(_whole(s1, exc, model, 10.0), ref)


def _column_run(st, exc, impact, t_end, **kw):
    """`ColumnRun.run` of a run laid out as `outcome_summary` does."""
    from multimass.engines._run import segment_ends

    o = simulation.SimulationOptions.of(None, backend="compiled", output_dt=None, **kw)
    plan = simulation._prepare(st, exc, impact, t_end, o)
    ends = segment_ends(plan.ground[2], plan.ground[1], t_end)
    run = column_runs.ColumnRun.of(plan.st, plan.model, plan.fast, plan.start, ends, t_end, o)
    return run.run()


@pytest.mark.parametrize("impact", ["DD5", "CIM"])
def test_same_solver_calls_and_the_same_energy_ledger(s1, impact):
    exc = _record().scaled(1.3)
    ref = _loop_outcome(s1, exc, impact, 10.0, seed=SEEDS[7])
    outcome, _, top, n_impacts, n_rhs, err = _column_run(s1, exc, impact, 10.0, seed=SEEDS[7])
    assert (outcome, top, n_impacts) == (ref.outcome, ref.theta_max, ref.n_impacts)
    assert n_rhs == ref.n_rhs  # every segment the same, to the right-hand side call
    assert err == ref.energy_balance_error  # and the impacts' losses, in the same order


def test_chattering_guard_and_a_failed_energy_check(s1):
    exc = _record()
    kw = dict(seed=SEEDS[4], chatter_count=3, chatter_window=0.5)
    r = _loop_outcome(s1, exc, "DD5", 10.0, **kw)
    assert any(e.kind == "chatter_guard" for e in r.events)  # the case trips the guard
    ref = _reference(s1, exc, "DD5", 10.0, **kw)
    _same(_whole(s1, exc, "DD5", 10.0, **kw), ref)
    # an error below what the solver resolves (m g B · atol, `checks.scale_floor`) always
    # passes: atol = 1e-15 lowers that floor under this run's round-off, so energy_tol
    # = 1e-16 fails the check on both paths
    strict = dict(energy_tol=1e-16, atol=1e-15)
    tight = _reference(s1, exc, "CIM", 10.0, **strict)
    assert tight[1] == "inaccurate"
    _same(_whole(s1, exc, "CIM", 10.0, **strict), tight)


def test_what_the_kernel_does_not_know_runs_in_python(s1, monkeypatch):
    def refuse(*a):
        raise AssertionError("the whole-run kernel must not be called")

    monkeypatch.setattr(ck, "column_run", refuse)
    exc = _record()
    model = Classical(restitution=AngularMomentumRestitution())  # r_h of Eq 13: state-dependent
    _same(_whole(s1, exc, model, 5.0), _reference(s1, exc, model, 5.0))
    block = from_specimen("B6M")  # a rigid block: no columns' kernel
    pulse = CosinePulse(amplitude=8.0, omega=18.0)
    _same(_whole(block, pulse, "CIM", 3.0), _reference(block, pulse, "CIM", 3.0))
    scipy_ = outcome_summary(s1, exc, "CIM", 2.0, backend="scipy")
    ref = simulate_outcome(s1, exc, "CIM", 2.0, backend="scipy")
    assert (scipy_.theta_max, scipy_.status, scipy_.n_impacts) == (
        ref.theta_max,
        ref.status,
        ref.n_impacts,
    )


def test_a_broken_run_falls_back_for_its_message(s1, monkeypatch):
    monkeypatch.setattr(column_runs.ColumnRun, "run", lambda self: (column_runs.BROKEN,) * 6)
    exc = _record()
    got = outcome_summary(s1, exc, "DD5", 5.0, backend="compiled", seed=SEEDS[5])
    _same(tuple(got[i] for i in (0, 2, 3, 4)), _reference(s1, exc, "DD5", 5.0, seed=SEEDS[5]))


def test_the_warm_up_compiles_the_signature_of_real_runs(s1):
    from multimass.engines.fast.compile import warm_up_columns

    warm_up_columns()
    _whole(s1, _record(), "DD5", 2.0, seed=SEEDS[6])
    _whole(s1, CosinePulse(amplitude=6.0, omega=12.0), "CIM", 2.0)
    assert len(ck.column_run.signatures) == 1


def test_record_spectrum_is_the_per_run_path_run_for_run(s1, monkeypatch):
    rec = _record(n=250)
    kw = dict(scale=[0.6, 1.2, 1.8], repeats=3, seed=1, executor="serial", progress=False)
    whole = record_spectrum(s1, rec, **kw)
    monkeypatch.setattr(simulation._Plan, "whole_run", lambda self: None)
    per_run = record_spectrum(s1, rec, **kw)
    cols = ["theta_max", "status", "n_impacts", "overturn_time"]
    assert whole.table[cols].equals(per_run.table[cols])
