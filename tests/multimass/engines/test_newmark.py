"""Paper 004's Newmark integrator for the rigid rocking block (multimass.engines.newmark).

References used below, none computed by the code under test:

* the first integral of Housner's equation (paper 004, Eqs 1–2 are conservative between
  impacts): from rest at θ0 the block reaches θ = 0 with the energy m g R [cos(α − θ0)
  − cos α]; θ̇+ = η θ̇− keeps η² of it, so the next peak θ1 solves
  cos(α − θ1) = cos α + η² [cos(α − θ0) − cos α]  ("closed form: energy");
* paper 002, Section 6.2 (specimens' reference.first_peak_deg): simulated first
  post-impact peaks 8.28°, 7.76°, 6.18° of B4M, B6M, B8M from 14.839°, 11.268°, 7.731°;
* the uplift condition of paper 004, Eq 1 at θ = 0: |ü_g| > g tan α = g b / h;
* an event-driven reference written here: scipy's DOP853 (rtol 1e-12) on paper 004,
  Eqs 1–2 with terminal events at θ = 0 and |θ| = π/2.
"""

import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import multimass
from multimass import InputError, specimens
from multimass.engines import _newmark_kernel as kern
from multimass.engines.newmark import NewmarkResult, newmark_block, rocking_energy
from multimass.impact_models.restitution import housner_eta
from multimass.inputs.excitations import SineWave
from multimass.model.eom import rocking_accelerations
from multimass.result import EVENT_KINDS, LEDGER_NAMES, OUTCOMES, STATUSES, Event, Result

G = 9.81


def _block(name):
    """Closed-form block data from the specimen's b, h, m (paper 004, after Eq 2)."""
    sp = specimens.load(name)
    R = 0.5 * math.hypot(sp.b, sp.h)
    alpha = math.atan(sp.b / sp.h)  # DESIGN.md: atan(b/h)
    return sp, R, alpha, 4.0 / 3.0 * sp.mass * R * R, 3.0 * G / (4.0 * R)  # I_A, p²


def _energy(name, theta, thetadot):
    sp, R, alpha, I_A, _ = _block(name)
    return 0.5 * I_A * thetadot**2 + sp.mass * G * R * (
        np.cos(alpha - np.abs(theta)) - math.cos(alpha)
    )


def _free(name, dt, t_end=1.2, engine="auto", **kw):
    sp, _, alpha, _, _ = _block(name)
    return newmark_block(
        multimass.rigid_block(name),
        lambda t: 0.0,
        t_end,
        dt=dt,
        restitution=housner_eta(alpha),
        engine=engine,
        theta0=math.radians(sp.reference.theta0_deg),
        **kw,
    )


def _exact_first_peak(name):
    sp, _, alpha, _, _ = _block(name)
    eta = 1.0 - 1.5 * math.sin(alpha) ** 2  # paper 004, Eq 9
    th0 = math.radians(sp.reference.theta0_deg)
    c = math.cos(alpha) + eta**2 * (math.cos(alpha - th0) - math.cos(alpha))  # closed form: energy
    return alpha - math.acos(c)


def _sine(a0, omega):
    """ü_g = a0 sin(ω t) on [0, 2π/ω], zero elsewhere; scalar only (math, if)."""

    def ag(t):
        return a0 * math.sin(omega * t) if 0.0 <= t <= 2.0 * math.pi / omega else 0.0

    return ag


def _reference(name, ag, t0, side, t_end, r):
    """Event-driven DOP853 on paper 004, Eqs 1–2; returns impacts, peaks, overturn time."""
    _, _, alpha, _, p2 = _block(name)

    def rhs(t, y, s):
        ph = alpha - s * y[0]
        return [y[1], -p2 * (s * math.sin(ph) + ag(t) / G * math.cos(ph))]  # paper 004, Eqs 1–2

    impacts, peaks, t, y, s = [], [], t0, [0.0, 0.0], side
    for _ in range(20):
        ev0 = lambda t, y, s: y[0]  # noqa: E731
        ev0.terminal, ev0.direction = True, -s
        ev1 = lambda t, y, s: abs(y[0]) - math.pi / 2  # noqa: E731
        ev1.terminal, ev1.direction = True, 1
        sol = solve_ivp(
            rhs,
            (t, t_end),
            y,
            method="DOP853",
            rtol=1e-12,
            atol=1e-14,
            args=(s,),
            events=(ev0, ev1),
            dense_output=True,
        )
        peaks.append(np.abs(sol.sol(np.linspace(sol.t[0], sol.t[-1], 20001))[0]).max())
        if sol.t_events[1].size:
            return impacts, peaks, sol.t_events[1][0]
        if not sol.t_events[0].size:
            return impacts, peaks, None
        impacts.append((sol.t_events[0][0], sol.y_events[0][0][1]))
        t, y, s = sol.t_events[0][0], [0.0, r * sol.y_events[0][0][1]], -s
    return impacts, peaks, None


# ---------------------------------------------------------------------------- equation
@pytest.mark.parametrize(
    "theta, side, ag",
    [(0.1, 1, 0.0), (0.3, 1, -4.0), (-0.2, -1, 3.0), (0.0, -1, -1.0), (1.2, 1, 7.5)],
)
def test_kernel_equation_is_housner_and_the_structure_equation(theta, side, ag):
    _, R, alpha, _, p2 = _block("B6M")
    s = side  # paper 004, Eq 1 (s = +1) and Eq 2 (s = −1)
    housner = -p2 * (s * math.sin(alpha - s * theta) + ag / G * math.cos(alpha - s * theta))
    st = multimass.rigid_block("B6M")
    got = kern.rhs(theta, side, ag, st.p**2, st.alpha_cg, st.g)
    assert got == pytest.approx(housner, rel=1e-12, abs=1e-12)
    _, via_eom = rocking_accelerations(st, side, np.zeros(0), theta, np.zeros(0), 0.0, ag)
    assert got == pytest.approx(via_eom, rel=1e-12, abs=1e-12)


# ---------------------------------------------------------------------------- free rocking
@pytest.mark.parametrize("name", ["B4M", "B6M", "B8M"])
def test_first_post_impact_peak_free_rocking(name):
    res = _free(name, dt=1e-3)
    exact = _exact_first_peak(name)
    sp = specimens.load(name)
    assert res.peaks[0] == pytest.approx(math.radians(sp.reference.theta0_deg), abs=1e-15)
    assert abs(res.peaks[1] - exact) < 1e-6  # closed form: energy
    assert (
        abs(math.degrees(res.peaks[1]) - sp.reference.first_peak_deg) < 0.03
    )  # paper 002, Sec 6.2
    release, first = res.events[:2]
    assert (release.kind, release.time, release.theta) == ("release", 0.0, res.peaks[0])
    assert first.kind == "impact" and first.thetadot_minus < 0.0
    assert (first.phase_before, first.phase_after) == (1, -1)


def test_first_peak_error_is_second_order_in_dt():
    exact = _exact_first_peak("B4M")  # B4M: the largest error of the three
    errs = [abs(_free("B4M", dt=dt, t_end=0.7).peaks[1] - exact) for dt in (2e-3, 1e-3, 5e-4)]
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all((orders > 1.8) & (orders < 2.2)), (errs, orders)


def test_energy_conserved_in_flight_and_scaled_by_r_squared_at_impacts():
    name = "B6M"
    eta = housner_eta(_block(name)[2])
    devs = []
    for dt in (1e-3, 5e-4):
        res = _free(name, dt=dt, t_end=1.5, engine="python")
        e = _energy(name, res.theta, res.thetadot)
        rows = np.searchsorted(res.t, [ev.time for ev in res.events if ev.kind == "impact"])
        assert rows.size == 4
        bounds = [0, *rows, res.t.size]
        devs.append(
            max(np.max(np.abs(e[a:b] / e[a] - 1.0)) for a, b in zip(bounds[:-1], bounds[1:]))
        )
        for i in rows:  # post-impact row / last row before it
            assert e[i] / e[i - 1] == pytest.approx(eta**2, abs=1e-8)
        for ev in res.events:
            assert ev.thetadot_plus == pytest.approx(eta * ev.thetadot_minus, rel=1e-15)
    assert devs[0] < 2e-7
    assert 3.5 < devs[0] / devs[1] < 4.5  # O(dt²)


def test_small_impacts_end_in_full_contact():
    res = _free("B4M", dt=1e-3, t_end=2.0)
    kinds = [ev.kind for ev in res.events]
    assert kinds[-1] == "full_contact" and kinds.count("full_contact") == 1
    fc = res.events[-1]
    assert abs(fc.thetadot_minus) <= 0.01 < abs(res.events[-2].thetadot_minus)  # paper 001, Eq 9
    after = res.t >= fc.time
    assert np.all(res.theta[after] == 0.0) and np.all(res.thetadot[after] == 0.0)
    assert res.status == "completed" and res.t[-1] == 2.0


def test_time_grid_and_inserted_impact_rows():
    res = _free("B6M", dt=1e-3)
    assert np.all(np.diff(res.t) > 0.0)
    impacts = [ev for ev in res.events if ev.kind == "impact"]
    for ev in impacts:
        i = int(np.flatnonzero(res.t == ev.time)[0])
        assert res.theta[i] == 0.0 and res.thetadot[i] == ev.thetadot_plus
    on_grid = np.isin(res.t, np.arange(1201) * 1e-3)
    assert np.count_nonzero(~on_grid) == len(impacts)
    assert res.t.size == 1201 + len(impacts)


def test_trapezoidal_rule_is_time_reversible():
    st = multimass.rigid_block("B6M")
    th0, thd0, n, dt = 0.05, 0.2, 100, 1e-3  # stays in θ > 0 over 0.1 s (no impact)
    fwd = newmark_block(
        st, lambda t: 0.0, n * dt, dt=dt, restitution=0.9, theta0=th0, thetadot0=thd0, tol=1e-13
    )
    assert [e.kind for e in fwd.events] == ["release"] and np.all(fwd.theta > 0.0)
    back = newmark_block(
        st,
        lambda t: 0.0,
        n * dt,
        dt=dt,
        restitution=0.9,
        theta0=fwd.theta[-1],
        thetadot0=-fwd.thetadot[-1],
        tol=1e-13,
    )
    assert back.theta[-1] == pytest.approx(th0, abs=1e-12)
    assert back.thetadot[-1] == pytest.approx(-thd0, abs=1e-10)
    np.testing.assert_allclose(back.theta[::-1], fwd.theta, atol=1e-12)


# ---------------------------------------------------------------------------- uplift
def test_no_rocking_at_the_uplift_threshold():
    sp, _, alpha, _, p2 = _block("B6M")
    a_up = G * sp.b / sp.h  # paper 004, Eq 1 at θ = 0: g tan α
    res = newmark_block(
        multimass.rigid_block("B6M"),
        SineWave(amplitude=(1 - 1e-9) * a_up, omega=2 * math.sqrt(p2)),
        2.0,
        restitution=housner_eta(alpha),
    )
    assert [e.kind for e in res.events] == ["release"] and res.status == "completed"
    assert (res.events[0].phase_before, res.events[0].phase_after) == (0, 0)  # at rest
    assert np.all(res.theta == 0.0) and res.peaks.size == 0


def test_rocking_just_above_threshold_starts_at_the_exact_instant():
    sp, _, alpha, _, p2 = _block("B6M")
    a_up, omega = G * sp.b / sp.h, 2 * math.sqrt(p2)
    a0 = 1.001 * a_up
    res = newmark_block(
        multimass.rigid_block("B6M"), _sine(a0, omega), 1.0, restitution=housner_eta(alpha)
    )
    up = res.events[1]  # after the release (at rest, full contact)
    assert up.kind == "uplift"
    assert (up.phase_before, up.phase_after) == (0, -1)  # ü_g > 0 first: left pivot, θ < 0
    assert up.time == pytest.approx(math.asin(a_up / a0) / omega, abs=1e-13)  # closed form
    assert res.theta.min() < 0.0
    assert sum(ev.kind == "uplift" for ev in res.events) == 2  # again on the right in the 2nd half
    assert [ev.phase_after for ev in res.events if ev.kind == "uplift"] == [-1, 1]


# ---------------------------------------------------------------------------- forced response
def test_large_sine_pulse_overturns_at_the_reference_time():
    _, _, alpha, _, p2 = _block("B6M")
    a0, omega = 3 * alpha * G, math.sqrt(p2)  # a0/(α g) = 3, ω/p = 1
    exc = SineWave(amplitude=a0, omega=omega)
    t_u = math.asin(G * 0.045 / 0.2025 / a0) / omega
    _, _, t_over = _reference("B6M", exc, t_u, -1, 2.0, housner_eta(alpha))
    errs = []
    for dt in (1e-3, 5e-4):
        res = newmark_block(
            multimass.rigid_block("B6M"),
            exc,
            2.0,
            dt=dt,
            restitution=housner_eta(alpha),
            rest_after=exc.duration,
        )
        assert res.status == "overturned" and res.overturned
        assert res.events[-1].kind == "overturn" and res.events[-1].time == res.overturn_time
        assert res.theta[-1] == -math.pi / 2 and res.t[-1] == res.overturn_time
        assert np.all(np.abs(res.theta[:-1]) < math.pi / 2)
        errs.append(abs(res.overturn_time - t_over))
    assert errs[0] < 2e-6 and 3.5 < errs[0] / errs[1] < 4.5


def test_impacts_and_peaks_agree_with_event_driven_reference():
    _, _, alpha, _, p2 = _block("B6M")
    eta = housner_eta(alpha)
    exc = SineWave(amplitude=1.5 * alpha * G, omega=4 * math.sqrt(p2))
    t_u = math.asin(G * 0.045 / 0.2025 / exc.amplitude) / exc.omega
    impacts, peaks, _ = _reference("B6M", exc, t_u, -1, 1.0, eta)
    res = newmark_block(multimass.rigid_block("B6M"), exc, 1.0, dt=2.5e-4, restitution=eta)
    got = [ev for ev in res.events if ev.kind == "impact"]
    assert len(got) == len(impacts) >= 3
    for ev, (t_ref, thd_ref) in zip(got, impacts):
        assert ev.time == pytest.approx(t_ref, abs=3e-5)
        assert ev.thetadot_minus == pytest.approx(thd_ref, abs=3e-5)
    n = len(impacts) + 1  # uplift half-cycle, then one per impact
    np.testing.assert_allclose(res.peaks[:n], peaks[:n], atol=2e-5)


def test_mirrored_excitation_gives_mirrored_response():
    _, _, alpha, _, p2 = _block("B4M")
    a0, omega = 3.0 * alpha * G, 6 * math.sqrt(p2)  # 8 impacts, no overturning
    st, eta = multimass.rigid_block("B4M"), housner_eta(alpha)
    pos = newmark_block(st, _sine(a0, omega), 1.5, restitution=eta)
    neg = newmark_block(st, _sine(-a0, omega), 1.5, restitution=eta)
    assert len(pos.events) > 3
    np.testing.assert_array_equal(pos.t, neg.t)
    np.testing.assert_allclose(neg.theta, -pos.theta, rtol=0, atol=1e-14)
    np.testing.assert_allclose(neg.thetadot, -pos.thetadot, rtol=0, atol=1e-12)
    assert [(ev.phase_before, ev.phase_after) for ev in neg.events] == [
        (-ev.phase_before, -ev.phase_after) for ev in pos.events
    ]
    np.testing.assert_allclose(neg.peaks, pos.peaks, atol=1e-14)


def test_numba_kernel_matches_python_reference():
    _, _, alpha, _, p2 = _block("B6M")
    exc = SineWave(amplitude=2.0 * alpha * G, omega=6 * math.sqrt(p2))  # 5 impacts, no overturning
    runs = [
        newmark_block(
            multimass.rigid_block("B6M"), exc, 1.5, restitution=housner_eta(alpha), engine=e
        )
        for e in ("python", "numba")
    ]
    py, nb = runs
    assert [(e.kind, e.phase_after) for e in nb.events] == [
        (e.kind, e.phase_after) for e in py.events
    ]
    assert len(py.events) > 3 and py.status == nb.status
    np.testing.assert_allclose(
        [e.time for e in nb.events], [e.time for e in py.events], rtol=0, atol=1e-12
    )
    for f in ("t", "theta", "thetadot", "thetaddot", "peaks"):
        np.testing.assert_allclose(getattr(nb, f), getattr(py, f), rtol=1e-10, atol=1e-12)
    assert py.n_steps == nb.n_steps


def test_scalar_only_callable_and_vectorised_excitation_agree():
    _, _, alpha, _, p2 = _block("B6M")
    a0, omega = 2.5 * alpha * G, 5 * math.sqrt(p2)
    a = newmark_block(multimass.rigid_block("B6M"), _sine(a0, omega), 1.0, restitution=0.93)
    b = newmark_block(
        multimass.rigid_block("B6M"), SineWave(amplitude=a0, omega=omega), 1.0, restitution=0.93
    )
    np.testing.assert_allclose(a.theta, b.theta, atol=1e-13)
    assert [ev.kind for ev in a.events] == [ev.kind for ev in b.events]


def test_restitution_callable_gets_velocity_and_new_side():
    calls = []

    def r(thd_minus, new_side):
        calls.append((thd_minus, new_side))
        return 0.8

    res = newmark_block(
        multimass.rigid_block("B6M"), lambda t: 0.0, 0.8, restitution=r, theta0=0.15
    )
    impacts = [ev for ev in res.events if ev.kind == "impact"]
    assert len(calls) == len(impacts) >= 2
    for (thd, side), ev in zip(calls, impacts):
        assert thd == ev.thetadot_minus and side == ev.phase_after == int(math.copysign(1, thd))
        assert ev.restitution == 0.8


# ---------------------------------------------------------------------------- early stop
def test_rest_after_stops_early_and_matches_the_full_run():
    _, _, alpha, _, p2 = _block("B6M")
    exc = SineWave(amplitude=1.5 * alpha * G, omega=4 * math.sqrt(p2))
    full = newmark_block(multimass.rigid_block("B6M"), exc, 3.0, restitution=housner_eta(alpha))
    early = newmark_block(
        multimass.rigid_block("B6M"),
        exc,
        3.0,
        restitution=housner_eta(alpha),
        rest_after=exc.duration,
    )
    assert early.outcome == "rest" and early.status == "completed"
    assert early.events[-1].kind == "rest"
    assert exc.duration <= early.t[-1] < 3.0
    n = early.t.size
    np.testing.assert_array_equal(early.t, full.t[:n])
    np.testing.assert_array_equal(early.theta, full.theta[:n])
    # it stopped with |θ| < α and energy below m g R (1 − cos α): closed form barrier
    _, R, _, _, _ = _block("B6M")
    e = _energy("B6M", early.theta[-1], early.thetadot[-1])
    assert abs(early.theta[-1]) < alpha and e < 1.0896 * G * R * (1.0 - math.cos(alpha))
    assert full.status == "completed" and not full.overturned


def test_free_release_with_rest_after_zero_stops_at_once():
    res = _free("B6M", dt=1e-3, rest_after=0.0)
    assert res.outcome == "rest" and res.status == "completed"
    assert res.t.size == 1 and [e.kind for e in res.events] == ["release", "rest"]


def test_block_beyond_alpha_at_pulse_end_is_not_declared_safe():
    # regression: past θ = α the energy test alone (E < mgR(1 − cos α)) would say "rest"
    _, _, alpha, _, p2 = _block("B6M")
    exc = SineWave(amplitude=1.5 * alpha * G, omega=math.sqrt(p2))
    res = newmark_block(
        multimass.rigid_block("B6M"),
        exc,
        3.0,
        restitution=housner_eta(alpha),
        rest_after=exc.duration,
    )
    assert res.status == "overturned" and res.overturn_time > exc.duration


def test_newton_failure_is_a_status_not_nan():
    res = _free("B6M", dt=1e-3, max_iter=1)
    assert res.status == "failed" and "max_iter" in res.message
    assert np.all(np.isfinite(res.theta)) and res.t.size >= 1


# ---------------------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    "kw, field",
    [
        ({"dt": 0.0}, "`dt`"),
        ({"dt": -1e-3}, "`dt`"),
        ({"t_end": 0.0}, "`t_end`"),
        ({"t_end": -1.0}, "`t_end`"),
        ({"restitution": 0.0}, "`restitution`"),
        ({"restitution": 1.2}, "`restitution`"),
        ({"restitution": lambda *_: 1.5}, "`restitution`"),
        ({"theta0": 2.0}, "`theta0`"),
        ({"overturn_angle": 2.0}, "`overturn_angle`"),
        ({"max_iter": 0}, "`max_iter`"),
        ({"tol": 0.0}, "`tol`"),
        ({"engine": "c"}, "`engine`"),
        ({"ag": 3.0}, "`ag`"),
        ({"ag": lambda t: float("nan")}, "`ag`"),
        ({"rest_after": -1.0}, "`rest_after`"),
    ],
)
def test_bad_input_is_rejected_with_the_field_named(kw, field):
    args = {
        "structure": multimass.rigid_block("B6M"),
        "ag": lambda t: 0.0,
        "t_end": 1.0,
        "restitution": 0.9,
        "theta0": 0.1,
    }
    args.update(kw)
    with pytest.raises(InputError, match=field):
        newmark_block(args.pop("structure"), args.pop("ag"), args.pop("t_end"), **args)


def test_non_rigid_structure_is_rejected():
    with pytest.raises(InputError, match=r"`structure`.*rigid_block"):
        newmark_block(multimass.column("S1"), lambda t: 0.0, 1.0, restitution=0.9)


def test_result_is_frozen():
    res = _free("B8M", dt=1e-3, t_end=0.1)
    assert isinstance(res, NewmarkResult)
    with pytest.raises(AttributeError):
        res.status = "x"


# ---------------------------------------------------------------------------- result contract
def _no_nan(text):
    """json.loads that refuses NaN and infinities (not JSON)."""

    def refuse(c):
        raise ValueError(f"{c} in JSON")

    return json.loads(text, parse_constant=refuse)


@pytest.mark.parametrize("case", ["free", "forced", "rest"])
def test_result_contract(case):
    st = multimass.rigid_block("B6M")
    _, _, alpha, _, p2 = _block("B6M")
    exc = SineWave(amplitude=1.5 * alpha * G, omega=4 * math.sqrt(p2))
    if case == "free":
        res = _free("B6M", dt=1e-3)
    else:
        res = newmark_block(
            st,
            exc,
            3.0,
            restitution=housner_eta(alpha),
            rest_after=exc.duration if case == "rest" else None,
        )
    assert isinstance(res, Result) and res.engine == "newmark_block"
    assert res.status in STATUSES and res.outcome in OUTCOMES
    assert res.status == OUTCOMES[res.outcome]  # every check passed
    assert res.outcome == {"free": "completed", "forced": "completed", "rest": "rest"}[case]
    assert res.checks["energy_balance"]["passed"] and res.warnings == ()
    assert res.events and all(isinstance(e, Event) for e in res.events)
    assert {e.kind for e in res.events} <= EVENT_KINDS
    for a, b in zip(res.events, res.events[1:]):  # the phases chain
        assert b.phase_before == a.phase_after
    # peaks in rad, one time each, in order; a free release starts with θ0
    assert res.peaks.size == res.peak_times.size > 1
    assert np.all(np.diff(res.peak_times) > 0.0) and np.all(res.peaks < alpha)
    if case == "free":
        assert res.peaks[0] == math.radians(specimens.load("B6M").reference.theta0_deg)
        assert res.peak_times[0] == 0.0
    assert res.theta_max == res.peaks.max()
    # series and ledger
    assert list(res.series.columns[:3]) == ["t", "theta", "thetadot"]
    np.testing.assert_array_equal(res.series["theta"], res.theta)
    led = res.ledger
    assert set(led.columns) <= set(LEDGER_NAMES) and {"t", "energy"} <= set(led.columns)
    np.testing.assert_allclose(led["energy"], rocking_energy(st, res.theta, res.thetadot))
    scale = max(led["energy"].iloc[0], np.abs(led["ground_work"]).max())
    err = np.abs(led["balance_error"]).max() / scale
    assert err == pytest.approx(res.checks["energy_balance"]["value"], rel=1e-12) and err < 1e-3
    # JSON: radians, degrees only beside them, no NaN
    info = _no_nan(res.to_json())
    assert info["engine"] == "newmark_block" and info["status"] == res.status
    assert info["peaks"] == pytest.approx(list(res.peaks), abs=0.0)
    assert info["peaks_deg"] == pytest.approx([math.degrees(x) for x in res.peaks])
    assert info["n_impacts"] == sum(e.kind == "impact" for e in res.events)


def test_free_rocking_peaks_fall_midway_between_impacts():
    # closed form: free rocking is conservative and time-reversible between impacts, so
    # each half-cycle after an impact peaks halfway to the next impact
    res = _free("B6M", dt=5e-4, t_end=1.5)
    imp = [e.time for e in res.events if e.kind == "impact"]
    assert len(imp) == 4
    mid = [(a + b) / 2 for a, b in zip(imp, imp[1:])]
    np.testing.assert_allclose(res.peak_times[1 : len(mid) + 1], mid, atol=1e-8)


def test_impact_events_carry_their_energy_change():
    # ½ J_p (θ̇+² − θ̇−²) = ½ J_p (r² − 1) θ̇−² (paper 004, Sec 2.3); the ledger books it
    st = multimass.rigid_block("B6M")
    res = _free("B6M", dt=1e-3)
    assert res.events[0].kind == "release" and res.events[0].energy_change == 0.0
    for e in res.events[1:]:
        assert e.kind == "impact" and e.restitution == housner_eta(st.alpha_cg)
        expected = 0.5 * st.J_p * (e.restitution**2 - 1.0) * e.thetadot_minus**2
        assert e.energy_change == pytest.approx(expected, rel=1e-12)
    lost = -sum(e.energy_change for e in res.events)
    assert res.ledger["impact"].iloc[-1] == pytest.approx(lost, rel=1e-12)


def test_a_coarse_step_is_flagged_inaccurate():
    # dt = 0.05 s against 1/p ≈ 0.27 s: the ledger no longer closes to 1e-3
    _, _, alpha, _, p2 = _block("B6M")
    exc = SineWave(amplitude=3 * alpha * G, omega=math.sqrt(p2))
    st, eta = multimass.rigid_block("B6M"), housner_eta(alpha)
    coarse = newmark_block(st, exc, 3.0, dt=0.05, restitution=eta)
    assert coarse.outcome == "overturned" and coarse.status == "inaccurate"
    assert not coarse.overturned  # the contract's overturned needs passing checks
    assert not coarse.checks["energy_balance"]["passed"]
    assert len(coarse.warnings) == 1 and "reduce `dt`" in coarse.warnings[0]
    loose = newmark_block(st, exc, 3.0, dt=0.05, restitution=eta, energy_tol=0.1)
    assert loose.status == "overturned"
    with pytest.raises(InputError, match="`energy_tol`"):
        newmark_block(st, exc, 3.0, restitution=eta, energy_tol=0.0)


def test_a_failed_run_ends_with_a_failed_event():
    res = _free("B6M", dt=1e-3, max_iter=1)
    assert res.status == res.outcome == "failed" and res.checks == {}
    assert res.events[-1].kind == "failed" and "max_iter" in res.events[-1].detail


# B6M under one-cycle sine pulses a0 = amp α g, ω = ratio p that end safe: "rising" ends the
# pulse while |θ| still grows, "returning" while θ heads back to 0 before a free swing higher
# than the forced peaks; an early stop before that peak under-reported max |θ|. The stop now
# adds the peak of the swing under way from its energy (equations.free_rocking_peak).
@pytest.mark.parametrize("ratio, amp", [(5.214, 2.5), (6.143, 3.9)], ids=["rising", "returning"])
def test_rest_after_finds_the_peak_after_the_pulse(ratio, amp):
    _, _, alpha, _, p2 = _block("B6M")
    exc = SineWave(amplitude=amp * alpha * G, omega=ratio * math.sqrt(p2))
    kw = dict(restitution=housner_eta(alpha))
    full = newmark_block(multimass.rigid_block("B6M"), exc, exc.duration + 5.0, **kw)
    early = newmark_block(
        multimass.rigid_block("B6M"), exc, exc.duration + 5.0, rest_after=exc.duration, **kw
    )
    assert early.outcome == "rest" and full.status == "completed" and not full.overturned
    assert full.peak_times[np.argmax(full.peaks)] > exc.duration  # after the pulse
    # the energy's peak against Newmark's: O(dt²), 1.3e-6 at most over the map below
    assert early.theta_max == pytest.approx(full.theta_max, rel=1e-5, abs=0.0)
    n = early.t.size
    np.testing.assert_array_equal(early.theta, full.theta[:n])


def test_rest_after_keeps_theta_max_over_a_sine_map():
    # every cell of an 8 × 8 map: a stopped run's θ_max is the full run's, to Newmark's
    # O(dt²) error of the peak (dt = 1e-3: 1.3e-6; dt = 5e-4: 3.3e-7)
    _, _, alpha, _, p2 = _block("B6M")
    st, kw, stopped = multimass.rigid_block("B6M"), dict(restitution=housner_eta(alpha)), 0
    for ratio in np.linspace(1.5, 8.0, 8):
        for amp in np.linspace(1.1, 6.0, 8):
            exc = SineWave(amplitude=amp * alpha * G, omega=ratio * math.sqrt(p2))
            t_end = exc.duration + 5.0
            full = newmark_block(st, exc, t_end, **kw)
            early = newmark_block(st, exc, t_end, rest_after=exc.duration, **kw)
            assert early.status == full.status, (ratio, amp)
            assert early.theta_max == pytest.approx(full.theta_max, rel=1e-5), (ratio, amp)
            stopped += early.outcome == "rest"
    assert stopped >= 20  # the rule is exercised
