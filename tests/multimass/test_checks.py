"""The accuracy checks of a run and the status they decide (multimass.checks)."""

import json

import numpy as np
import pytest

import multimass
from multimass import CosinePulse, FreeRelease, G, simulate, simulate_outcome
from multimass.checks import energy_floor
from tests.conftest import RaisingExcitation


def test_a_run_whose_ledger_does_not_close_says_so():
    # B6M released at 0.19 rad, Housner's η, solve_ivp at rtol 1e-3 without a step cap: the
    # ledger is off by ~4e-3 of the initial energy (docs/bench: "energy drift" at rtol 1e-3)
    r = simulate(
        "B6M",
        FreeRelease(0.19),
        "CIM",
        2.5,
        restitution="housner",
        rtol=1e-3,
        atol=1e-5,
        max_step=np.inf,
    )
    assert r.energy_balance_error > 1e-3
    assert r.status == "inaccurate" and r.outcome == "completed"
    assert not r.checks["energy_balance"]["passed"]
    assert r.checks["energy_balance"]["value"] == r.energy_balance_error
    assert len(r.warnings) == 1 and "energy ledger does not close" in r.warnings[0]
    info = json.loads(r.to_json())
    assert info["status"] == "inaccurate" and info["outcome"] == "completed"
    assert info["warnings"] == list(r.warnings)
    assert not r.overturned


def test_the_same_run_at_the_default_tolerance_passes():
    r = simulate("B6M", FreeRelease(0.19), "CIM", 2.5, restitution="housner")
    assert r.status == "completed" and r.checks["energy_balance"]["passed"] and not r.warnings


def test_the_tolerance_is_the_users():
    loose = simulate(
        "B6M",
        FreeRelease(0.19),
        "CIM",
        2.5,
        restitution="housner",
        rtol=1e-3,
        atol=1e-5,
        max_step=np.inf,
        energy_tol=1e-2,
    )
    assert loose.status == "completed" and loose.checks["energy_balance"]["limit"] == 1e-2


def test_a_pulse_the_structure_cannot_follow_is_not_judged_on_round_off():
    # a cosine pulse of 1e9 rad/s (6 ns) is not judged on round-off (its energy balance
    # error would read 1.01): all its energies are ~1e-15 J, round-off against the ~1e-7 J
    # the solver's absolute tolerance resolves (m_t g B atol); the structure does not move,
    # as physics says
    r = simulate("S1", CosinePulse(amplitude=0.4 * G, omega=1e9), "DD2", 2.0)
    st = multimass.column("S1")
    floor = energy_floor(st, 1e-10)
    assert floor == pytest.approx(1e-10 * st.m_t * st.g * st.B)
    assert np.abs(r.series.balance_error).max() < 1e-6 * floor
    assert r.status == "completed" and r.theta_max == 0.0
    # the smallest energy scale: an error of `floor` is energy_tol (1e-3) of it
    assert r.energy_reference == pytest.approx(floor / 1e-3)


def test_outcome_checks_the_ledger_at_the_end():
    # free release: the energy scale is the initial energy for both the Response (largest
    # balance error over the run) and the Outcome (balance error at the end)
    r = simulate("S1", FreeRelease(0.1), "CIM", 2.0, output_dt=1e-3)
    o = simulate_outcome("S1", FreeRelease(0.1), "CIM", 2.0)
    end = abs(r.series.balance_error.iloc[-1]) / r.energy_reference
    assert o.energy_balance_error == pytest.approx(end, rel=1e-3, abs=1e-12)
    assert o.status == "completed" and o.checks["energy_balance"]["passed"]
    loose = simulate_outcome(
        "B6M",
        FreeRelease(0.19),
        "CIM",
        2.5,
        restitution="housner",
        rtol=1e-3,
        atol=1e-5,
        max_step=np.inf,
    )
    assert loose.status == "inaccurate" and loose.outcome == "completed" and loose.warnings


def test_newmark_runs_are_checked_too():
    # paper 004's Newmark at dt = 10 ms on a small-amplitude sine-pulse rocking: O(dt²) energy error
    st = multimass.rigid_block("B6M")
    exc = multimass.SineWave(amplitude=1.066 * st.alpha_cg * st.g, omega=3.0 * st.p)
    coarse = simulate(st, exc, "CIM", exc.duration + 3, integrator="newmark", dt=1e-2)
    fine = simulate(st, exc, "CIM", exc.duration + 3, integrator="newmark", dt=1e-4)
    assert coarse.energy_balance_error > 10 * fine.energy_balance_error
    assert coarse.status == ("inaccurate" if coarse.energy_balance_error > 1e-3 else "completed")
    assert fine.status == "completed"


def test_a_failed_run_stays_failed():
    r = simulate("S1", RaisingExcitation(), "CIM", 1.0, output_dt=None)
    assert r.status == "failed" and r.outcome == "failed" and "energy_balance" not in r.checks


def test_a_balance_error_below_what_the_solver_resolves_passes_any_scale():
    """The ledger's rule: an error of at most m g B · atol (the work of the restoring
    moment over the absolute tolerance on θ) passes however small the run's energies;
    a larger one is judged against energy_tol of the scale, both ways."""
    from multimass.checks import balance_error, energy_check, scale_floor

    st = multimass.rigid_block("B6M")
    atol, tol = 1e-10, 1e-3
    resolved = atol * st.m_t * st.g * st.B  # J, by hand
    floor = scale_floor(st, atol, tol)
    assert floor == pytest.approx(resolved / tol, rel=1e-14)
    tiny = 1e-3 * resolved  # the energies of a block that barely lifts
    assert energy_check(balance_error(0.99 * resolved, 0.0, tiny, tiny, floor), tol)["passed"]
    assert not energy_check(balance_error(1.01 * resolved, 0.0, tiny, tiny, floor), tol)["passed"]
    big = 1e6 * resolved  # a run that rocks: judged on its own scale
    assert energy_check(balance_error(0.99e-3 * big, big, 0.0, 0.0, floor), tol)["passed"]
    assert not energy_check(balance_error(1.01e-3 * big, 0.0, -big, 0.0, floor), tol)["passed"]
