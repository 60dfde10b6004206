"""Event-driven contact engine (paper 000): the start from a given state, the ledger, checks.

The block model of `multimass.engines.poisson_block` is driven through `simulate_contacts`
with explicit initial states; the reference values are closed forms derived in the
comments (angular momentum about a corner, paper 000's impact states, Eqs 13–25).
"""

import json
import math

import numpy as np
import pytest

from multimass import InputError
from multimass.engines._contact_checks import (
    ENERGY_LIMIT,
    FrictionDemand,
    friction_ratio,
    impact_ratio,
    run_checks,
)
from multimass.engines.contact_dynamics import (
    ContactEvent,
    ContactResponse,
    half_cycle_peaks,
    model_stop,
    simulate_contacts,
)
from multimass.engines.poisson_block import PoissonBlock, _BlockModel
from multimass.impact_models import poisson_impact
from multimass.result import EVENT_KINDS, LEDGER_NAMES, OUTCOMES, STATUSES, Event, Result


def block_run(block, q0, v0, t_end=0.2, eps=0.0, **kw):
    model = _BlockModel(block, kw.pop("ag", lambda t: 0.0), kw.pop("quiet", 0.0))
    opts = dict(
        dt_out=1e-3,
        gap_tol=1e-9 * block.R,
        locked_dt=0.002,
        zeno_velocity=1e-4 * math.sqrt(block.g * block.R),
    )
    opts.update(kw)
    return simulate_contacts(model, q0, v0, t_end, eps, **opts)


# -- the start: a sliding block whose corners stick at t0 trips over its leading corner


@pytest.mark.parametrize("b, h", [(0.5, 0.25), (0.25, 0.5), (0.5, 3.5)])
def test_slip_at_the_start_is_an_impact_that_trips_the_block(b, h):
    # Both corners down, sliding at V: sticking stops the slip at t0 (paper 000, Eq 5 with
    # ġ_T⁻ ≠ 0). Hand calculation, ε_P = 0: the impulses act at the corners only, so the
    # angular momentum about the leading (right) corner is conserved, m V h = I_O |ω|,
    # I_O = 4/3 m R²; the trailing corner lifts (ġ_N = 2b|ω| > 0). Hence ω = −3hV/(4R²),
    # ẋ⁺ = −hω, ẏ⁺ = −bω, Λ_T = m(ẋ⁺ − V), Λ_N = m ẏ⁺, and the loss ½mV² − ½I_O ω².
    block, V = PoissonBlock(b=b, h=h, mass=2.0), 0.3
    r = block_run(block, [0.0, h, 0.0], [V, 0.0, 0.0])
    R2 = b * b + h * h
    w = -3.0 * h * V / (4.0 * R2)
    release, ev = r.events[:2]
    assert (release.kind, release.time, release.closed_before) == ("release", 0.0, (0, 1))
    assert (ev.kind, ev.time, ev.closed_before, ev.closed_after) == ("impact", 0.0, (0, 1), (1,))
    np.testing.assert_allclose(ev.impact.u_plus, [-h * w, -b * w, w], rtol=1e-12, atol=1e-15)
    loss = 0.5 * 2.0 * V * V - 0.5 * (4.0 / 3.0) * 2.0 * R2 * w * w
    assert ev.impact.energy_loss == pytest.approx(loss, rel=1e-12)
    # friction demand of the trip: |Λ_T|/Λ_N = (4b² + h²)/(3bh) ≥ 4/3
    assert r.friction.impact == pytest.approx((4 * b * b + h * h) / (3 * b * h), rel=1e-10)
    assert r.friction.impact_time == 0.0
    # the ledger starts from the given (sliding) state and books the loss
    assert r.t[0] == 0.0 and r.energy[0] == pytest.approx(0.5 * 2.0 * V * V, rel=1e-15)
    assert np.abs(r.ledger_error).max() < 1e-7 * r.energy[0]
    assert r.status == "completed" and r.checks["energy_balance"]["passed"]


def test_a_resting_block_stays_at_rest_with_an_exact_ledger():
    block = PoissonBlock(b=0.3, h=0.6)
    r = block_run(block, [0.0, 0.6, 0.0], np.zeros(3), t_end=1.0)
    assert [e.kind for e in r.events] == ["release"] and set(r.closed) == {3}
    assert (r.events[0].phase_before, r.events[0].phase_after) == (0, 0)  # full contact
    np.testing.assert_array_equal(r.energy, 0.0)
    assert r.friction == FrictionDemand(0.0, 0.0, 0.0, None)
    assert r.status == "completed" and r.warnings == ()


@pytest.mark.parametrize("dphi", [0.4, -0.4])
def test_a_corner_separating_at_the_start_is_open(dphi):
    # upright (g_N = 0 at both corners), spinning about one corner: the other corner leaves
    block = PoissonBlock(b=0.2, h=0.5)
    q0, v0 = block.rocking_state(0.0, dphi)
    r = block_run(block, q0, v0, t_end=0.05)
    pivot = 0 if dphi > 0 else 1
    assert r.closed[0] == 1 << pivot and set(r.closed) == {1 << pivot}
    assert [e.kind for e in r.events] == ["release"]
    assert r.events[0].phase_after == (-1 if dphi > 0 else 1)  # θ = −φ: φ̇ > 0 tips left
    assert r.energy[0] == pytest.approx(0.5 * (4 / 3) * block.R**2 * dphi**2, rel=1e-14)
    assert abs(r.q[-1, 2]) > 0.01 * block.alpha


# -- validation


def test_bad_input_names_the_field():
    block = PoissonBlock(b=0.2, h=0.5)
    model = _BlockModel(block, lambda t: 0.0)
    ok = dict(model=model, q0=[0.0, 0.5, 0.0], v0=[0.0, 0.0, 0.0], t_end=1.0, eps_p=0.0)
    cases = [
        (dict(q0=[0.0, 0.5]), "q0"),
        (dict(v0=[0.0, np.nan, 0.0]), "v0"),
        (dict(q0=[0.0, 0.49, 0.0]), "penetrates"),
        (dict(t_end=np.inf), "t_end"),
        (dict(t_end=np.nan), "t_end"),
        (dict(dt_out=0.0), "dt_out"),
        (dict(rtol=-1.0), "rtol"),
        (dict(max_events=0), "max_events"),
        (dict(gap_tol=np.nan), "gap_tol"),
        (dict(zeno_velocity=-1.0), "zeno_velocity"),
        (dict(breakpoints=[np.nan]), "breakpoints"),
        (dict(eps_p="hard"), "eps_p"),
        (dict(eps_p=[0.1, 0.2, 0.3]), "eps_p"),
        (dict(eps_p=1.5), "eps_p"),
        (dict(max_events=True), "max_events"),
        (dict(t_end=10**400), "t_end"),
    ]
    cases += [(dict(mu=mu), "`mu`") for mu in (0.0, -0.5, np.nan, np.inf, "rough")]
    for kw, match in cases:
        with pytest.raises(InputError, match=match):
            simulate_contacts(**dict(ok, **kw))


# -- friction demand of a Poisson impact: paper 000's closed-form states


def block_impact(h_over_b, eps, b=0.4, m=3.0, phidot=-1.7):
    H = h_over_b * b
    M = np.diag([m, m, m * (b * b + H * H) / 3.0])
    W_N = np.array([[0.0, 0.0], [1.0, 1.0], [-b, b]])  # paper 000, Eq 13
    W_T = np.array([[1.0], [0.0], [H]])  # paper 000, Eq 13
    return poisson_impact(M, W_N, W_T, phidot * np.array([-H, b, 1.0]), eps), math.atan(b / H)


@pytest.mark.parametrize("eps", [0.0, 0.5, 1.0])
@pytest.mark.parametrize("h_over_b", [0.3, 0.5, 0.7, 0.75, 2.0, 7.0])
def test_impact_friction_ratio_matches_the_closed_forms(h_over_b, eps):
    # Both corners share the tangential direction of Eq 13, so the demand is |Λ_T|/ΣΛ_N.
    # Stocky (H/b < 1/√2), Eqs 14–15: ΣΛ_N⁰ = −m ġ⁻/2, Λ_T⁰ = m ġ⁻ cot α / 2 ⇒ cot α = H/b;
    # Eqs 20–21 scale both by ε. Slender, Eqs 17–18: Λ_N2⁰ = m ġ⁻(3s²/4 − 1),
    # Λ_T⁰ = (3/4) m ġ⁻ s c ⇒ 3sc/(4 − 3s²); Eqs 22–23 scale both by ε.
    r, alpha = block_impact(h_over_b, eps)
    s, c = math.sin(alpha), math.cos(alpha)
    expected = h_over_b if h_over_b < 1 / math.sqrt(2) else 3 * s * c / (4 - 3 * s * s)
    assert impact_ratio(r, ((0, 1),)) == pytest.approx(expected, rel=1e-10)


def test_impact_friction_ratio_of_an_oblique_point_mass():
    # unit point mass landing at (ġ_T, ġ_N) = (2, −1), ε = 0.5: compression stops both
    # (Λ_T⁰ = −2, Λ_N⁰ = 1: ratio 2), expansion is normal only (Λ_N⁺ = 0.5, Λ_T⁺ = 0)
    r = poisson_impact(np.eye(2), [[0.0], [1.0]], [[1.0], [0.0]], [2.0, -1.0], 0.5)
    assert impact_ratio(r, ((0,),)) == pytest.approx(2.0, rel=1e-14)


def test_friction_ratio_groups_and_limits():
    # two corners sharing one tangential direction: |T| / (N1 + N2)
    assert friction_ratio(np.array([3.0, 1.0]), np.array([2.0]), ((0, 1),), 1e-12) == 0.5
    assert friction_ratio(np.array([0.0]), np.array([1.0]), ((0,),), 1e-12) == math.inf
    assert friction_ratio(np.array([0.0]), np.array([0.0]), ((0,),), 1e-12) == 0.0
    assert friction_ratio(np.array([2.0]), np.zeros(0), (), 1e-12) == 0.0


# -- the run-status contract


def test_checks_turn_status_inaccurate_and_keep_the_outcome():
    E = np.array([1.0, 1.0, 1.0])
    W = np.zeros(3)
    ok, warn = run_checks(E, np.array([0.0, 1e-4, 0.0]), W, 0.0, FrictionDemand(), None)
    assert set(ok) == {"energy_balance", "projection"} and warn == ()
    bad, warn = run_checks(
        E, np.array([0.0, 2e-3, 0.0]), W, 0.0, FrictionDemand(0.9, 0.3, 0.2, 0.5), 0.7
    )
    assert bad["energy_balance"] == {"value": 2e-3, "limit": ENERGY_LIMIT, "passed": False}
    assert bad["friction_smooth"] == {"value": 0.9, "limit": 0.7, "passed": False}
    assert bad["friction_impact"]["passed"]
    assert len(warn) == 2 and "rtol" in warn[0] and "0.9" in warn[1] and "t = 0.3" in warn[1]


def test_loose_tolerances_are_flagged_inaccurate():
    block = PoissonBlock.from_slenderness(4.0, width=0.4)
    q0, v0 = block.rocking_state(block.alpha / 2)
    loose = block_run(block, q0, v0, t_end=3.0, rtol=1e-3, atol=1e-3)
    assert loose.status == "inaccurate" and loose.outcome == "completed"
    assert loose.checks["energy_balance"]["value"] > ENERGY_LIMIT
    assert any("tighten rtol/atol" in w for w in loose.warnings)
    tight = block_run(block, q0, v0, t_end=3.0)
    assert tight.status == tight.outcome == "completed" and tight.warnings == ()
    assert tight.checks["energy_balance"]["value"] < 1e-6


def test_a_contact_that_must_slide_ends_failed_with_its_history():
    # squat block under a 4 g sine: sticking needs a tensile force where opening the
    # corner would penetrate (a real corner slides); the run returns, status "failed"
    block = PoissonBlock(b=0.5, h=0.25)
    a, w = 2.0 * block.g * math.tan(block.alpha), 2.0 * block.p
    r = block_run(
        block,
        [0.0, 0.25, 0.0],
        np.zeros(3),
        t_end=3.0,
        ag=lambda t: a * math.sin(w * t) if t < 2 * math.pi / w else 0.0,
        quiet=2 * math.pi / w,
    )
    assert r.status == r.outcome == "failed"
    assert "no consistent set of closed contacts" in r.message and "slides" in r.message
    assert 0.5 < r.t[-1] < 3.0
    assert np.all(np.isfinite(r.energy))
    assert r.friction.smooth == math.inf  # the pivot unloaded while pushed sideways
    # the failure is an event of the log, and the JSON has no Infinity (the demand is null)
    assert r.events[-1].kind == "failed"
    assert r.events[-1].time == r.t[-1] and r.events[-1].detail == r.message
    info = json.loads(r.to_json(), parse_constant=lambda c: pytest.fail(f"{c} in JSON"))
    assert info["friction_demand"]["smooth"] is None


# -- the one result contract (multimass.result)


def _no_nan(text):
    """json.loads that refuses NaN and infinities (not JSON)."""

    def refuse(c):
        raise ValueError(f"{c} in JSON")

    return json.loads(text, parse_constant=refuse)


def test_contact_response_follows_the_result_contract():
    # a slender block released from φ0 > 0 (θ0 = −φ0 < 0, rocking on the left corner)
    block = PoissonBlock.from_slenderness(4.0, width=0.4)
    phi0 = block.alpha / 2
    q0, v0 = block.rocking_state(phi0)
    r = block_run(block, q0, v0, t_end=3.0, dt_out=2e-3)
    assert isinstance(r, ContactResponse) and isinstance(r, Result) and r.engine == "contact"
    assert r.status in STATUSES and r.outcome in OUTCOMES and r.status == "completed"
    assert all(isinstance(e, ContactEvent) and isinstance(e, Event) for e in r.events)
    assert {e.kind for e in r.events} <= EVENT_KINDS and r.n_impacts == len(r.impacts) > 3
    # phases from the corners: left only −1, right only +1 (θ > 0 rocks on the right pivot)
    first = r.impacts[0]
    assert (first.closed_before, first.closed_after) == ((0,), (1,))
    assert (first.phase_before, first.phase_after) == (-1, 1)
    assert first.thetadot_minus > 0.0 and first.thetadot_plus > 0.0  # θ grows through 0
    assert first.energy_change == pytest.approx(-first.impact.energy_loss, rel=1e-15)
    assert first.restitution == 0.0
    # θ = −φ, peaks in rad: the release angle first, then one per half-cycle
    np.testing.assert_array_equal(r.theta, -r.q[:, 2])
    assert r.peaks[0] == phi0 and r.peak_times[0] == 0.0
    assert r.peaks.size == r.n_impacts + 1 and np.all(np.diff(r.peaks) < 0.0)
    assert np.all(np.diff(r.peak_times) > 0.0)
    # series and ledger
    df = r.series
    assert list(df.columns[:4]) == ["t", "theta", "thetadot", "phase"]
    assert {"q0", "q1", "q2", "v2", "closed"} <= set(df.columns)
    assert set(df["phase"].dropna()) == {-1, 1}
    led = r.ledger
    assert set(led.columns) <= set(LEDGER_NAMES) and {"t", "energy"} <= set(led.columns)
    np.testing.assert_array_equal(led["impact"], r.impact_loss)
    np.testing.assert_array_equal(led["balance_error"], r.ledger_error)
    info = _no_nan(r.to_json())
    assert info["engine"] == "contact" and info["peaks"] == list(r.peaks)
    assert info["n_impacts"] == r.n_impacts and "friction_demand" in info


def test_a_model_without_rotation_or_pivots_has_no_theta():
    class Bare(_BlockModel):  # the same block, without the two optional attributes
        rotation = None
        pivots = None

    block = PoissonBlock(b=0.2, h=0.5)
    q0, v0 = block.rocking_state(0.1)
    r = simulate_contacts(Bare(block, lambda t: 0.0), q0, v0, 1.0, 0.0, dt_out=1e-2)
    assert r.rotation is None and np.all(np.isnan(r.theta)) and r.peaks.size == 0
    assert r.impacts and all(e.phase_before is e.phase_after is None for e in r.events)
    assert r.series["phase"].isna().all()
    info = _no_nan(r.to_json())
    assert info["peaks"] == [] and info["theta_max"] == 0.0


@pytest.mark.parametrize(
    "name, kind, outcome",
    [
        ("overturned", "overturn", "overturned"),
        ("overturn", "overturn", "overturned"),
        ("rest", "rest", "rest"),
        ("fell_off_beam", "fell_off_beam", "fell_off_beam"),
        ("impact", "impact", "completed"),
        ("hits_the_wall", "stopped", "completed"),
    ],
)
def test_model_events_map_to_the_contract(name, kind, outcome):
    assert model_stop(name) == (kind, outcome)
    assert kind in EVENT_KINDS and outcome in OUTCOMES


def test_a_model_event_stops_the_run_with_its_name_in_detail():
    class Wall(_BlockModel):
        def __init__(self, *a):
            super().__init__(*a)
            self.events = (("hits_the_wall", lambda t, q, v: q[2] - 0.05),)

    block = PoissonBlock(b=0.2, h=0.5)
    q0, v0 = block.rocking_state(0.0, 1.0)  # spins about the left corner, φ grows
    r = simulate_contacts(Wall(block, lambda t: 0.0), q0, v0, 1.0, 0.0, dt_out=1e-3)
    last = r.events[-1]
    assert (last.kind, last.detail) == ("stopped", "hits_the_wall")
    assert last.theta == pytest.approx(-0.05, abs=1e-12) and last.phase_after == -1
    assert r.outcome == r.status == "completed" and "hits_the_wall" in r.message


def test_running_out_of_events_fails():
    # outcome "max_events" (the budget ran out before t_end): status "failed"
    block = PoissonBlock.from_slenderness(4.0, width=0.4)
    q0, v0 = block.rocking_state(block.alpha / 2)
    r = block_run(block, q0, v0, t_end=3.0, max_events=2)
    assert r.outcome == "max_events" and r.status == "failed"
    assert [e.kind for e in r.events] == ["release", "impact", "impact"]  # release not counted
    assert _no_nan(r.to_json())["status"] == "failed"


def test_half_cycle_peaks_of_a_damped_release():
    # closed form: θ = θ0 e^{−t} cos(2π t) has |θ| extrema where tan(2π t) = −1/(2π);
    # the first sample is the release, |θ0|
    t = np.arange(0.0, 2.0 + 1e-12, 1e-3)
    theta = 0.2 * np.exp(-t) * np.cos(2 * np.pi * t)
    peaks, times = half_cycle_peaks(np.r_[0.0, t], np.r_[theta[0], theta])  # t0 twice
    k = np.arange(1, 4)
    t_ext = (k * np.pi - np.arctan(1 / (2 * np.pi))) / (2 * np.pi)
    assert peaks[0] == 0.2 and times[0] == 0.0 and len(peaks) == 5
    np.testing.assert_allclose(times[1:4], t_ext, atol=1e-6)
    np.testing.assert_allclose(
        peaks[1:4], 0.2 * np.exp(-t_ext) * np.abs(np.cos(2 * np.pi * t_ext)), rtol=1e-6
    )
