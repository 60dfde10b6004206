"""Batched rigid-block runs under pulses and records, each with its own restitution.

`multimass.engines.fast.block_runs.run_excitations` (and
`multimass.sweeps.block_outcomes.simulate_outcomes`, which falls back to one
`simulate_outcome` per run) must give, run by run, what
``simulate_outcome(st, excitation, t_end=..., impact="CIM", restitution=..., k=...,
backend="compiled")`` gives: the same outcome, status, message, impacts, RHS
evaluations and accuracy flag, and the same peak angle, overturning time and energy
balance error. The batch runs the same compiled code, so they agree bit for bit; the
tests allow 1e-12 (rad, s) on the two numbers a suite keeps, so that a harmless
last-bit change would show as a number, not as a different outcome.
"""

import math
from pathlib import Path

import numpy as np
import pytest

import multimass
from multimass import CosinePulse, CosineWave, FreeRelease, MPPulse, MPShape, Ricker, SineWave
from multimass.engines._rigid import uplift_threshold
from multimass.engines.fast import block_runs
from multimass.errors import InputError
from multimass.impact_models import CornerRestitution
from multimass.inputs.records import Record, read_record
from multimass.simulation import simulate_outcome
from multimass.sweeps import block_outcomes

TOL = 1e-12  # rad for θ_max, s for overturning times (see the module docstring)
RECORDS = Path(__file__).parents[3] / "examples" / "data" / "records"
CIM = dict(impact="CIM", backend="compiled")


def _reference(st, excitations, t_end, options):
    """One `simulate_outcome` per run."""
    t_end = np.broadcast_to(np.asarray(t_end, dtype=float), (len(excitations),))
    options = [options] * len(excitations) if isinstance(options, dict) else options
    return [
        simulate_outcome(st, e, t_end=float(te), **o)
        for e, te, o in zip(excitations, t_end, options)
    ]


def _assert_same(got, want):
    """The batch's columns equal the per-run `Outcome`s, run by run."""
    assert len(got) == len(want)
    for i, r in enumerate(want):
        t_over = next((e.time for e in r.events if e.kind == "overturn"), math.nan)
        assert got.status[i] == r.status, i
        assert bool(got.overturned[i]) == (r.outcome == "overturned"), i
        assert got.message[i] == r.message, i
        assert got.n_impacts[i] == r.n_impacts, i
        assert got.n_rhs[i] == r.n_rhs, i
        assert bool(got.accurate[i]) == (r.status != "inaccurate"), i
        assert got.outcome[i] == block_outcomes._outcome_code(r), i
        assert abs(got.theta_max[i] - r.theta_max) <= TOL, i
        assert math.isnan(t_over) == math.isnan(got.overturn_time[i]), i
        if not math.isnan(t_over):
            assert abs(got.overturn_time[i] - t_over) <= TOL, i
        assert got.energy_balance_error[i] == pytest.approx(r.energy_balance_error, abs=1e-15)


def _batched(st, excitations, t_end, options):
    """`run_excitations` with the per-run restitution of `options` (a list of dicts)."""
    runs = block_runs.BlockRuns.of_runs(st, options[0])
    assert runs is not None
    pairs = block_runs.restitution_pairs(st, options)
    assert pairs is not None
    return block_runs.run_excitations(runs, excitations, t_end, pairs)


def _mp_runs(st, n, seed):
    """n M&P pulses of random shape and intensity, each with a random k of η_M."""
    rng = np.random.default_rng(seed)
    a_th = uplift_threshold(st)
    excitations, options = [], []
    for _ in range(n):
        shape = MPShape(gamma=float(rng.uniform(1.5, 3.0)), nu=float(rng.uniform(0.0, np.pi)))
        amp, ratio = rng.uniform(0.8, 8.0) * a_th, rng.uniform(1.0, 10.0)
        excitations.append(shape(amplitude=float(amp), omega=float(ratio * st.p)))
        k = float(np.clip(rng.normal(0.82, 0.05), 0.0, 1.0))
        options.append(CIM | dict(restitution="modified", k=k))
    return excitations, options


def _records():
    return (
        read_record(RECORDS / "elcentro_1940_NS.dat", units="g"),
        read_record(RECORDS / "kobe_1995.dat", units="m/s2"),
    )


def _record_runs(st, n, seed):
    """n runs of the two records scaled to PGA/(g tan α) in 0.5-3, each with a random k."""
    rng = np.random.default_rng(seed)
    a_th = uplift_threshold(st)
    excitations, options = [], []
    for i, record in enumerate(_records() * (n // 2)):
        f = float(rng.uniform(0.5, 3.0) * a_th / record.pga)
        excitations.append(record if i < 2 else record.scaled(f))  # two at scale 1
        options.append(CIM | dict(restitution="modified", k=float(rng.uniform(0.6, 1.0))))
    return excitations, options


@pytest.mark.parametrize("block", ["B6M", "B3L"])
def test_mp_pulses_of_random_shape_with_random_k_equal_simulate_outcome(block):
    st = multimass.rigid_block(block)
    excitations, options = _mp_runs(st, 60, seed=11)
    t_end = [e.duration + 5.0 for e in excitations]
    got = _batched(st, excitations, t_end, options)
    _assert_same(got, _reference(st, excitations, t_end, options))
    outcomes = set(got.outcome.tolist())
    assert {block_runs.OUTCOMES.index(o) for o in ("rest", "overturned")} <= outcomes


@pytest.mark.parametrize("block", ["B6M", "B3L"])
def test_scaled_records_with_random_k_equal_simulate_outcome(block):
    st = multimass.rigid_block(block)
    excitations, options = _record_runs(st, 12, seed=5)
    t_end = [e.duration + 2.0 for e in excitations]
    got = _batched(st, excitations, t_end, options)
    _assert_same(got, _reference(st, excitations, t_end, options))
    assert got.overturned.any() and not got.overturned.all()


def test_mixed_excitations_and_restitution_values_per_run():
    # every kind in one call, a fixed restitution drawn per run, tighter and looser options
    st = multimass.rigid_block("B4M")
    a = uplift_threshold(st)
    elcentro = _records()[0]
    excitations = [
        SineWave(amplitude=3.0 * a, omega=2.0 * st.p),
        CosineWave(amplitude=2.0 * a, omega=4.0 * st.p),
        CosinePulse(amplitude=4.0 * a, omega=3.0 * st.p),
        Ricker(amplitude=5.0 * a, omega=5.0 * st.p),
        MPShape(gamma=2.5, nu=1.0)(amplitude=4.0 * a, omega=3.0 * st.p),
        elcentro.scaled(1.5 * a / elcentro.pga),
    ] * 2
    rng = np.random.default_rng(7)
    common = CIM | dict(method="RK45", rtol=1e-7, max_step=0.05, energy_tol=1e-6)
    options = [common | dict(restitution=float(r)) for r in rng.uniform(0.7, 0.98, 12)]
    t_end = [e.duration + 3.0 for e in excitations]
    got = _batched(st, excitations, t_end, options)
    _assert_same(got, _reference(st, excitations, t_end, options))
    assert "inaccurate" in set(got.status.tolist())  # energy_tol 1e-6 fails some runs


@pytest.mark.parametrize(
    "options",
    [
        dict(restitution="modified", stop_when_safe=True),  # a suite may stop safe runs early
        dict(restitution="housner", stop_at_rest=False),  # full contact until t_end
        dict(restitution=0.9, chatter_window=1.0, chatter_count=2),  # the guard trips
    ],
)
def test_run_options_as_given(options):
    st = multimass.rigid_block("B6M")
    excitations, _ = _mp_runs(st, 20, seed=3)
    t_end = [e.duration + 4.0 for e in excitations]
    runs = block_runs.BlockRuns.of_runs(st, CIM | options)
    got = block_runs.run_excitations(runs, excitations, t_end)  # the options' restitution
    _assert_same(got, _reference(st, excitations, t_end, CIM | options))


def test_excitations_that_start_late():
    # the start is a breakpoint of the phase loop: an uplift search ends there, and the
    # next one finds this record's first sample (above the threshold) at once
    st = multimass.rigid_block("B6M")
    a = uplift_threshold(st)
    elcentro = _records()[0]
    accel = elcentro.accel * (1.2 * a / elcentro.pga)
    accel[0] = 1.5 * a
    late = Record(time=elcentro.time + 0.3713, accel=accel)  # off the 1 ms search grid
    pulse = MPPulse(amplitude=0.8, fp=1.0, gamma=2.0, nu=0.5, t0=1.7)
    assert pulse.start > 0.0 and late.breakpoints[0] > 0.0
    excitations = [late, pulse, pulse]
    t_end = [late.duration + 1.0, pulse.duration + 5.0, 0.9]  # the last ends before its end
    options = [CIM | dict(restitution="modified", k=k) for k in (0.8, 0.85, 0.9)]
    got = _batched(st, excitations, t_end, options)
    want = _reference(st, excitations, t_end, options)
    _assert_same(got, want)
    assert next(e.time for e in want[0].events if e.kind == "uplift") == late.breakpoints[0]


def test_simulate_outcomes_batches_what_it_can_and_runs_the_rest():
    st = multimass.rigid_block("B6M")
    excitations, options = _mp_runs(st, 6, seed=8)
    excitations[2] = FreeRelease(theta0=0.1)  # not from rest: per run
    t_end = 4.0
    got = block_outcomes.simulate_outcomes(st, excitations, t_end, options)
    np.testing.assert_array_equal(got.batched, [True, True, False, True, True, True])
    _assert_same(got, _reference(st, excitations, t_end, options))
    dd = block_outcomes.simulate_outcomes(st, excitations[:2], t_end, dict(impact="DD2"))
    assert not dd.batched.any()  # Dirac-delta impacts: per run
    _assert_same(dd, _reference(st, excitations[:2], t_end, dict(impact="DD2")))


def test_a_run_the_batch_cannot_finish_runs_per_run(monkeypatch):
    # the batch marks a run the per-run path would end as "failed"; simulate one
    real = block_runs.run_excitations

    def second_fails(*args, **kwargs):
        out = real(*args, **kwargs)
        out.outcome[1], out.status[1], out.theta_max[1] = -1, "failed", math.nan
        return out

    monkeypatch.setattr(block_runs, "run_excitations", second_fails)
    st = multimass.rigid_block("B6M")
    excitations, options = _record_runs(st, 4, seed=1)
    got = block_outcomes.simulate_outcomes(st, excitations, 12.0, options)
    np.testing.assert_array_equal(got.batched, [True, False, True, True])
    _assert_same(got, _reference(st, excitations, 12.0, options))


def test_restitution_pairs():
    st = multimass.rigid_block("B6M")
    ks = [0.7, 0.8, 0.9, 0.8]
    pairs = block_runs.restitution_pairs(st, [CIM | dict(restitution="modified", k=k) for k in ks])
    for k, (right, left) in zip(ks, pairs):
        runs = block_runs.BlockRuns.of_runs(st, CIM | dict(restitution="modified", k=k))
        assert (right, left) == runs.r_pair and right == left
    assert pairs[0, 0] != pairs[1, 0]
    other = [CIM | dict(restitution=0.8), CIM | dict(restitution=0.8, method="RK45")]
    assert block_runs.restitution_pairs(st, other) is None  # one batch: one set of options
    random = [CIM | dict(restitution="random", seed=s) for s in range(2)]
    assert block_runs.restitution_pairs(st, random) is None


def test_what_the_batch_refuses():
    st = multimass.rigid_block("B6M")
    runs = block_runs.BlockRuns.of_runs(st, CIM | dict(restitution="modified"))
    with pytest.raises(InputError, match="FreeRelease"):
        block_runs.run_excitations(runs, [FreeRelease(theta0=0.1)], 1.0)
    pulse = MPPulse(amplitude=0.8, fp=1.0, t0=3.0)
    with pytest.raises(InputError, match="t_end"):
        block_runs.run_excitations(runs, [pulse], 1.0)  # it starts at 2 s


def _sine_map(st, n=8):
    """One-cycle sine pulses a0 = amp α g, ω = ratio p of an n × n map."""
    return [
        SineWave(amplitude=float(amp * st.alpha_cg * st.g), omega=float(ratio * st.p))
        for ratio in np.linspace(1.5, 8.0, n)
        for amp in np.linspace(1.1, 6.0, n)
    ]


@pytest.mark.parametrize("ratio, amp", [(5.214, 2.5), (6.143, 3.9)], ids=["rising", "returning"])
def test_stop_when_safe_finds_the_peak_after_the_pulse(ratio, amp):
    # "rising" ends the pulse while |θ| still grows, "returning" while θ heads back to 0
    # before a free swing higher than the forced peaks: stopping before that peak (at the
    # pulse's end, or at the impact after it) under-reported θ_max; the stop now adds the
    # peak of the swing under way from its energy (equations.free_rocking_peak)
    st = multimass.rigid_block("B6M")
    exc = [SineWave(amplitude=amp * st.alpha_cg * st.g, omega=ratio * st.p)]
    t_end = exc[0].duration + 5.0
    got = {}
    for stop in (True, False):
        runs = block_runs.BlockRuns.of_runs(
            st, CIM | dict(restitution="modified", stop_when_safe=stop)
        )
        got[stop] = block_runs.run_excitations(runs, exc, t_end)
    early, full = got[True], got[False]
    assert early.outcome[0] == block_runs.OUTCOMES.index("rest")
    assert early.status[0] == full.status[0] == "completed" and not full.overturned[0]
    assert early.n_rhs[0] < full.n_rhs[0]  # it did stop early
    # the energy's peak against the integrator's (rtol 1e-8)
    assert early.theta_max[0] == pytest.approx(full.theta_max[0], rel=1e-7, abs=0.0)


def test_stop_when_safe_keeps_theta_max_over_a_sine_map():
    # every cell of an 8 × 8 map: a stopped run's θ_max is the unstopped run's (the energy's
    # peak against the integrator's), and the batch still equals simulate_outcome run by run
    st = multimass.rigid_block("B6M")
    excitations = _sine_map(st)
    t_end = [e.duration + 5.0 for e in excitations]
    got = {}
    for stop in (True, False):
        options = CIM | dict(restitution="modified", stop_when_safe=stop)
        runs = block_runs.BlockRuns.of_runs(st, options)
        got[stop] = block_runs.run_excitations(runs, excitations, t_end)
        _assert_same(got[stop], _reference(st, excitations, t_end, options))
    early, full = got[True], got[False]
    np.testing.assert_array_equal(early.status, full.status)
    np.testing.assert_array_equal(early.overturned, full.overturned)
    np.testing.assert_allclose(early.theta_max, full.theta_max, rtol=1e-7, atol=0.0)
    assert np.sum(early.n_rhs < full.n_rhs) >= 20  # the rule is exercised


def test_unequal_corners_restitute_the_impacting_corner_as_simulate_outcome():
    """Restitution fixed per corner (paper 001, Table 1's r̄_er right, r̄_el left), here
    0.95 and 0.7: an impact that starts rocking about the right pivot (the right corner
    strikes) takes 0.95, one onto the left corner 0.7. The batch must take the impacting
    corner's value, as the per-run path does; reference: one `simulate_outcome` per run
    (the same compiled solver: equal to 1e-12, see the module docstring). The per-run
    path's own choice is checked against the definition on a full run's impact log."""
    st = multimass.rigid_block("B6M")
    excitations, _ = _mp_runs(st, 40, seed=4)
    excitations += _sine_map(st, 5)
    options = CIM | dict(restitution=CornerRestitution(0.95, 0.7))
    t_end = [e.duration + 5.0 for e in excitations]
    runs = block_runs.BlockRuns.of_runs(st, options)
    assert runs is not None and runs.r_pair == (0.95, 0.7)
    got = block_runs.run_excitations(runs, excitations, t_end)
    want = _reference(st, excitations, t_end, options)
    _assert_same(got, want)
    outcomes = set(got.outcome.tolist())
    assert {block_runs.OUTCOMES.index(o) for o in ("rest", "overturned")} <= outcomes
    # the corners matter in these runs: with them swapped (the restitution of the pivot
    # before the impact) θ_max or the outcome changes in most runs with an impact
    swapped = block_runs.run_excitations(runs, excitations, t_end, [(0.7, 0.95)] * len(t_end))
    hit = got.n_impacts > 0
    changed = (swapped.outcome != got.outcome) | (np.abs(swapped.theta_max - got.theta_max) > 1e-6)
    assert hit.sum() >= 20 and changed[hit].mean() > 0.5
    # the solve_ivp per-run path (Python transitions, SciPy's integrator) on every 4th
    # run: the same outcomes and impacts, θ_max within the solvers' rtol (1e-8)
    some = range(0, len(t_end), 4)
    scipy_options = options | dict(backend="scipy")
    scipy = _reference(st, [excitations[i] for i in some], [t_end[i] for i in some], scipy_options)
    assert [r.outcome for r in scipy] == [
        "overturned" if got.overturned[i] else "completed" for i in some
    ]
    assert [r.n_impacts for r in scipy] == got.n_impacts[list(some)].tolist()
    np.testing.assert_allclose([r.theta_max for r in scipy], got.theta_max[list(some)], atol=1e-8)
    # the reference's impacts, one by one: r of the corner struck (the new pivot)
    i = int(np.argmax(got.n_impacts * (got.outcome != block_runs.OUTCOMES.index("overturned"))))
    full = multimass.simulate(st, excitations[i], "CIM", t_end[i], **_simulate_options(options))
    impacts = [e for e in full.events if e.kind == "impact"]
    assert len(impacts) == got.n_impacts[i] >= 3
    assert {e.phase_after for e in impacts} == {1, -1}
    for e in impacts:
        assert e.restitution == (0.95 if e.phase_after == 1 else 0.7)
        assert e.thetadot_plus == pytest.approx(e.restitution * e.thetadot_minus, rel=1e-14)


def _simulate_options(options):
    """`simulate_outcome`'s options as `simulate` takes them (impact given apart)."""
    return {k: v for k, v in options.items() if k != "impact"} | dict(progress=False)
