"""Rigid block with Poisson LCP impacts (paper 000, Section 3) against Housner's model."""

import json
import math

import numpy as np
import pytest

import multimass
from multimass import InputError, SineWave
from multimass.engines.poisson_block import (
    BlockResponse,
    PoissonBlock,
    _BlockModel,
    housner_theta,
    simulate_block,
)
from multimass.impact_models import housner_eta
from multimass.result import EVENT_KINDS, LEDGER_NAMES, OUTCOMES, STATUSES, Result


def on_grid(resp, grid):
    """The response's φ at the grid times (the simulation samples every dt_out)."""
    t, phi = resp.t, resp.phi
    idx = np.searchsorted(t, grid - 1e-12)
    assert np.allclose(t[idx], grid, atol=1e-12)
    return phi[idx]


@pytest.mark.parametrize("h_over_b, t_end", [(3.0, 4.0), (7.0, 8.0)])
def test_free_rocking_with_plastic_impacts_is_housner(h_over_b, t_end):
    # t_end stays before the accumulation point of Housner's impacts (≈ 4.7 s for H/b = 3)
    block = PoissonBlock.from_slenderness(h_over_b)
    phi0 = block.alpha / 3
    r = simulate_block(block, 0.0, t_end, phi0=phi0, dt_out=0.01)
    grid = np.round(np.arange(0.0, t_end, 0.01), 12)
    theta_h = housner_theta(block, lambda t: 0.0, 0.0, -phi0, grid, housner_eta(block.alpha))
    err = np.abs(on_grid(r, grid) + theta_h).max() / block.alpha  # φ = −θ
    assert err < 1e-6
    assert "flight" not in set(r.phase)
    assert len(r.raw.impacts) >= 5


def test_sine_pulse_figure_5_agrees_with_housner():
    # paper 000, Fig 5: H/b = 7, 2b = 1 m, a_g/g = 0.45, ω_g/p = 5.75, ε_P = 0
    block = PoissonBlock.from_slenderness(7.0, width=1.0)
    a_g, w_g = 0.45 * block.g, 5.75 * block.p
    ag = SineWave(amplitude=a_g, omega=w_g)
    r = simulate_block(block, 0.0, 15.0, ag=ag, dt_out=0.01)
    t_up = math.asin(block.g * math.tan(block.alpha) / a_g) / w_g  # closed form: ag = g tan α
    grid = np.round(np.arange(0.0, 15.0, 0.01), 12)
    theta_h = housner_theta(block, ag, t_up, 0.0, grid, housner_eta(block.alpha), side=-1)
    err = np.abs(on_grid(r, grid) + theta_h).max() / block.alpha
    assert err < 1e-6
    assert np.abs(r.phi).max() / block.alpha > 0.5  # it does rock substantially
    uplift = r.events[1]  # after the release, upright at rest
    assert uplift.kind == "uplift" and uplift.closed_after == (0,)  # left corner: φ > 0
    assert (uplift.phase_before, uplift.phase_after) == (0, -1)  # full contact → left pivot
    assert uplift.time == pytest.approx(t_up, abs=1e-9)
    assert r.phi[np.searchsorted(r.t, t_up + 0.05)] > 0.0  # ag > 0 ⇒ φ > 0 ⇒ θ < 0
    assert r.theta[np.searchsorted(r.t, t_up + 0.05)] < 0.0


def test_stocky_block_plastic_impact_ends_in_full_contact():
    # paper 000, Eq 25 with ε_P = 0: η = 0, the block stays down after the first impact
    block = PoissonBlock.from_slenderness(0.7)
    r = simulate_block(block, 0.0, 3.0, phi0=block.alpha / 3)
    assert len(r.raw.impacts) == 1
    imp = r.raw.impacts[0]
    assert imp.closed_after == (0, 1)
    after = r.t > imp.time
    assert np.all(r.phase[after] == "full")
    np.testing.assert_allclose(r.phi[after], 0.0, atol=1e-12)


def test_stocky_block_elastic_impacts_bounce_without_loss():
    # paper 000, Sec 3.3: with ε_P = 1 a stocky block bounces back on the same corner
    block = PoissonBlock.from_slenderness(0.7)
    phi0 = block.alpha / 3
    r = simulate_block(block, 1.0, 4.0, phi0=phi0)
    assert set(r.phase) == {"rock_left"}
    assert len(r.raw.impacts) >= 5
    for ev in r.raw.impacts:
        assert ev.impact.u_plus[2] / ev.impact.u_minus[2] == pytest.approx(-1.0, abs=1e-9)
        assert abs(ev.impact.energy_loss) < 1e-9 * r.raw.energy[0]
    assert r.phi.max() == pytest.approx(phi0, rel=1e-8)
    assert r.phi.min() > -1e-9


def test_stocky_block_partial_restitution_decays_to_rest():
    # paper 000, Eq 25: each impact reverses φ̇ with η = −ε_P; the sequence accumulates
    block = PoissonBlock.from_slenderness(0.7)
    r = simulate_block(block, 0.5, 3.0, phi0=block.alpha / 3)
    ratios = [ev.impact.u_plus[2] / ev.impact.u_minus[2] for ev in r.events if ev.kind == "impact"]
    np.testing.assert_allclose(ratios, -0.5, atol=1e-9)
    assert r.events[-1].kind == "rest" and r.events[-1].detail == "zeno_rest"
    assert r.events[-1].closed_after == (0, 1) and r.events[-1].phase_after == 0
    assert r.phase[-1] == "full"


def test_rocking_that_dies_out_comes_to_rest():
    # Housner's impacts accumulate at a finite time; the Zeno guard ends them in full contact
    block = PoissonBlock.from_slenderness(3.0)
    r = simulate_block(block, 0.0, 8.0, phi0=block.alpha / 3)
    assert r.status == "completed"
    assert r.events[-1].kind == "rest" and r.events[-1].detail == "zeno_rest"
    assert r.events[-1].closed_after == (0, 1)
    assert 4.0 < r.events[-1].time < 5.5
    assert np.abs(r.phi[r.t > r.events[-1].time]).max() < 1e-12


def test_slender_block_flies_after_impact_when_eps_positive():
    # paper 000, Eqs 22, 24: C3 → E3, both corners leave the ground
    block = PoissonBlock.from_slenderness(7.0)
    r = simulate_block(block, 0.5, 3.0, phi0=block.alpha / 3)
    first = r.raw.impacts[0]
    s2 = math.sin(block.alpha) ** 2
    assert first.impact.u_plus[2] / first.impact.u_minus[2] == pytest.approx(
        1 - 1.5 * s2 * 1.5, abs=1e-9
    )  # paper 000, Eq 24
    assert first.closed_after == ()
    assert "flight" in set(r.phase)


@pytest.mark.parametrize(
    "h_over_b, eps", [(0.7, 0.0), (0.7, 0.5), (0.7, 1.0), (7.0, 0.0), (7.0, 0.5), (7.0, 1.0)]
)
def test_energy_ledger_closes(h_over_b, eps):
    block = PoissonBlock.from_slenderness(h_over_b)
    r = simulate_block(block, eps, 3.0, phi0=block.alpha / 3)
    E0 = r.raw.energy[0]
    assert np.abs(r.raw.ledger_error).max() < 1e-7 * E0
    assert np.all(np.diff(r.raw.impact_loss) >= -1e-12 * E0)  # impacts never create energy


def test_forced_ledger_closes_and_pulse_can_overturn():
    block = PoissonBlock.from_slenderness(4.0, width=0.4)
    ag = SineWave(amplitude=1.2 * block.g, omega=2.0 * block.p)
    r = simulate_block(block, 0.0, 10.0, ag=ag)
    assert r.status == "overturned"
    ref = np.abs(r.raw.ground_work).max()
    assert np.abs(r.raw.ledger_error).max() < 1e-7 * ref


def test_geometry():
    block = PoissonBlock(b=0.5, h=3.5, mass=2.0)
    assert block.alpha == pytest.approx(math.atan(1 / 7), rel=1e-15)
    assert block.R == pytest.approx(math.sqrt(12.5), rel=1e-15)
    assert block.p == pytest.approx(math.sqrt(3 * 9.81 / (4 * math.sqrt(12.5))), rel=1e-15)
    M, W_N, W_T = block.impact_matrices()
    np.testing.assert_array_equal(W_N, [[0, 0], [1, 1], [-0.5, 0.5]])  # paper 000, Eq 13
    np.testing.assert_array_equal(W_T, [[1], [0], [3.5]])
    assert M[2, 2] == pytest.approx(2.0 * 12.5 / 3)
    # the simulation's contact kinematics reduce to Eq 13 at φ = 0 (both corners' W_T equal)
    g, WN, WT, _, _ = _BlockModel(block, lambda t: 0.0).contacts(
        np.array([0.0, 3.5, 0.0]), np.zeros(3)
    )
    np.testing.assert_allclose(g, 0.0, atol=1e-15)
    np.testing.assert_allclose(WN, W_N, atol=1e-15)
    np.testing.assert_allclose(WT, np.hstack([W_T, W_T]), atol=1e-15)
    q, v = block.rocking_state(0.2, -0.3)
    # the left corner (−b, −h) of the rotated block sits at (−b, 0) and does not move
    c, s = math.cos(0.2), math.sin(0.2)
    corner = q[:2] + np.array([-0.5 * c + 3.5 * s, -0.5 * s - 3.5 * c])
    np.testing.assert_allclose(corner, [-0.5, 0.0], atol=1e-15)
    vel = v[:2] + v[2] * np.array([0.5 * s + 3.5 * c, -0.5 * c + 3.5 * s])
    np.testing.assert_allclose(vel, 0.0, atol=1e-15)


@pytest.mark.parametrize(
    "kw, match",
    [
        (dict(eps_p=1.5), "eps_p"),
        (dict(phi0=2.0), "phi0"),
        (dict(ag=3.0), "ag"),
        (dict(t_end=-1.0), "t_end"),
    ],
)
def test_bad_input(kw, match):
    args = dict(block=PoissonBlock(0.5, 1.0), eps_p=0.5, t_end=1.0)
    args.update(kw)
    with pytest.raises(InputError, match=match):
        simulate_block(**args)


@pytest.mark.parametrize(
    "kw",
    [
        dict(b=-1.0, h=1.0),
        dict(b=1.0, h=0.0),
        dict(b=1.0, h=1.0, mass=float("nan")),
        dict(b=1.0, h=10**400),
        dict(b=1.0, h=1e308),
        dict(b=1e-300, h=1e-300, mass=1e-300),
    ],
)
def test_bad_block(kw):
    with pytest.raises(InputError):
        PoissonBlock(**kw)


@pytest.mark.parametrize("case", ["free", "sine"])
def test_agrees_with_the_engine_classical_impact(case):
    # the multi-mass engine's rigid block B6M with the classical impact and Housner's η
    st = multimass.rigid_block("B6M")
    block = PoissonBlock(b=st.B, h=st.h0, mass=st.m0)
    if case == "free":
        exc, kw = multimass.FreeRelease(0.1), dict(phi0=-0.1)  # θ0 = 0.1 ⇒ φ0 = −0.1
    else:
        exc = multimass.SineWave(amplitude=0.3 * block.g, omega=3.0 * block.p)
        kw = dict(ag=exc)
    eng = multimass.simulate(
        st, exc, impact="CIM", restitution="housner", t_end=2.0, rtol=1e-10, atol=1e-12
    )
    r = simulate_block(block, 0.0, 2.0, dt_out=0.001, **kw)
    df = eng.series
    keep = np.r_[np.diff(df.t) > 0, True]
    grid = np.arange(0.0, 1.9, 0.001)
    theta_engine = np.interp(grid, df.t[keep], df.theta[keep])
    theta_lcp = r.theta[np.searchsorted(r.t, grid, side="right") - 1]
    assert np.abs(theta_engine).max() > 0.3 * block.alpha
    assert np.abs(theta_lcp - theta_engine).max() < 1e-6 * block.alpha


@pytest.mark.parametrize("case", ["free", "sine"])
def test_housner_reference_agrees_with_the_engine(case):
    # housner_theta (the Fig 5 reference) against the multi-mass engine's rigid block,
    # an independent implementation of the same model (paper 004, Eqs 1–2, 9)
    st = multimass.rigid_block("B6M")
    block = PoissonBlock(b=st.B, h=st.h0, mass=st.m0)
    grid = np.arange(0.0, 1.9, 0.001)
    if case == "free":
        exc = multimass.FreeRelease(0.1)
        theta_h = housner_theta(block, lambda t: 0.0, 0.0, 0.1, grid)
    else:
        exc = multimass.SineWave(amplitude=0.3 * block.g, omega=3.0 * block.p)
        t_up = math.asin(block.g * math.tan(block.alpha) / (0.3 * block.g)) / (3.0 * block.p)
        theta_h = housner_theta(block, exc.acceleration, t_up, 0.0, grid, side=-1)
    eng = multimass.simulate(
        st, exc, impact="CIM", restitution="housner", t_end=2.0, rtol=1e-10, atol=1e-12
    )
    df = eng.series
    keep = np.r_[np.diff(df.t) > 0, True]
    theta_engine = np.interp(grid, df.t[keep], df.theta[keep])
    assert np.abs(theta_engine).max() > 0.3 * block.alpha
    assert np.abs(theta_h - theta_engine).max() < 1e-6 * block.alpha


# -- runs that start on the ground: the given state, its energy, its first peak


def b6m_block():
    st = multimass.rigid_block("B6M")
    return PoissonBlock(b=st.B, h=st.h0, mass=st.m0, g=st.g)


def first_peak(block, dphi):
    """Closed form: ½ I_O φ̇² = m g R (cos(α − φ_max) − cos α), I_O = 4/3 m R² (rotation
    about the pivot corner; the centre of mass sits at height R cos(α − |φ|))."""
    from scipy.optimize import brentq

    a, R, g = block.alpha, block.R, block.g
    e = 0.5 * (4.0 / 3.0) * R * R * dphi * dphi
    return brentq(lambda p: g * R * (math.cos(a - p) - math.cos(a)) - e, 0.0, a, xtol=1e-15)


@pytest.mark.parametrize("dphi", [0.25, -0.25, 0.5, -0.5, 1.0, -1.0, 1.5])
def test_upright_block_with_a_spin_rocks_to_the_closed_form_peak(dphi):
    # started upright with a spin, the block rocks: the spin is not projected away by
    # closing every touching corner, and the ledger starts from the given state
    block = b6m_block()
    r = simulate_block(block, 0.0, 0.12 if abs(dphi) <= 1.0 else 0.3, dphi0=dphi, dt_out=1e-5)
    peak = first_peak(block, dphi)
    assert first_peak(block, 0.5) == pytest.approx(0.008277339614, rel=1e-9)  # reviewer's value
    assert np.abs(r.phi).max() == pytest.approx(peak, rel=1e-6)
    assert np.sign(r.phi[np.argmax(np.abs(r.phi))]) == np.sign(dphi)
    assert r.phase[0] == ("rock_left" if dphi > 0 else "rock_right")
    E0 = 0.5 * (4.0 / 3.0) * block.mass * block.R**2 * dphi**2
    assert r.raw.t[0] == 0.0 and r.raw.energy[0] == pytest.approx(E0, rel=1e-14)
    assert np.abs(r.raw.ledger_error).max() < 1e-7 * E0
    assert r.status == "completed" and r.checks["energy_balance"]["passed"]


def test_spin_threshold_of_overturning():
    # closed form: the block overturns iff ½ I_O φ̇0² > m g R (1 − cos α)
    block = b6m_block()
    w_c = math.sqrt(1.5 * block.g * (1.0 - math.cos(block.alpha)) / block.R)
    assert simulate_block(block, 0.0, 1.0, dphi0=1.01 * w_c).status == "overturned"
    below = simulate_block(block, 0.0, 1.0, dphi0=0.99 * w_c)
    assert below.status == "completed" and np.abs(below.phi).max() < block.alpha


@pytest.mark.parametrize("phi0, dphi", [(0.0, 0.0), (0.05, 0.0), (-0.1, 0.3), (0.1, -0.7)])
def test_ledger_starts_from_the_given_state(phi0, dphi):
    # E(t0) = ½ I_O φ̇0² + m g (R cos(α − |φ0|) − h): the state the user gave
    block = b6m_block()
    r = simulate_block(block, 0.5, 0.3, phi0=phi0, dphi0=dphi)
    m, R, a = block.mass, block.R, block.alpha
    E0 = 0.5 * (4 / 3) * m * R * R * dphi**2 + m * block.g * (R * math.cos(a - abs(phi0)) - block.h)
    assert r.raw.t[0] == 0.0 and r.phi[0] == phi0
    assert r.raw.energy[0] == pytest.approx(E0, rel=1e-13, abs=1e-18)
    assert np.abs(r.raw.ledger_error).max() <= 1e-7 * max(E0, 1e-300)


@pytest.mark.parametrize("eps", [0.0, 0.5])
def test_spin_towards_the_other_corner_is_an_impact_at_t0(eps):
    # φ0 ≈ 0 on the left corner, rotating towards the right one: an impact at t = 0,
    # resolved by the Poisson LCPs; η = 1 − 3/2 sin²α − 3/2 ε sin²α (paper 000, Eq 24)
    block, w = b6m_block(), -0.5
    r = simulate_block(block, eps, 0.12, phi0=1e-12, dphi0=w, dt_out=1e-5)
    ev = r.events[1]  # after the release
    assert (ev.kind, ev.time, ev.closed_before) == ("impact", 0.0, (0,))
    s2 = math.sin(block.alpha) ** 2
    eta = 1.0 - 1.5 * s2 - 1.5 * eps * s2
    assert ev.impact.u_plus[2] / w == pytest.approx(eta, rel=1e-9)
    I_O = 4.0 / 3.0 * block.mass * block.R**2
    E0 = r.raw.energy[0]
    assert E0 == pytest.approx(0.5 * I_O * w * w, rel=1e-9)
    if eps == 0.0:  # plastic: rocks on the right corner with ηφ̇
        assert ev.closed_after == (1,)
        assert ev.impact.energy_loss == pytest.approx(0.5 * I_O * w * w * (1 - eta**2), rel=1e-9)
        assert np.abs(r.phi).max() == pytest.approx(first_peak(block, eta * w), rel=1e-6)
    else:  # paper 000, Eq 22: flight
        assert ev.closed_after == ()
    assert np.abs(r.raw.ledger_error).max() < 1e-7 * E0
    assert r.raw.impact_loss[-1] >= ev.impact.energy_loss > 0.0


# -- friction demand of the sticking corners


@pytest.mark.parametrize(
    "amp, mu, flagged", [(0.5, 0.4, True), (0.5, 0.7, False), (0.8, 0.7, True)]
)
def test_full_contact_friction_demand_is_ag_over_g(amp, mu, flagged):
    # closed form: a rigid block that stays in full contact needs |T/N| = |a_g|/g (the
    # classical sliding condition); h/b = 1 keeps it down (rocking needs a_g > g tan α = g)
    block = PoissonBlock(b=0.3, h=0.3)
    w = 3.0 * block.p
    r = simulate_block(block, 0.0, 3.0, ag=SineWave(amplitude=amp * block.g, omega=w), mu=mu)
    assert set(r.phase) == {"full"}
    assert r.friction.smooth == pytest.approx(amp, rel=1e-9)
    t_peak = r.friction.smooth_time
    assert min(abs(t_peak - 0.5 * math.pi / w), abs(t_peak - 1.5 * math.pi / w)) < 1e-6
    assert r.friction.impact == 0.0 and r.friction.impact_time is None
    assert r.outcome == "completed"
    assert r.checks["friction_smooth"]["passed"] is not flagged
    if flagged:
        assert r.status == "inaccurate"
        assert any(f"mu = {mu:g}" in s and "slide" in s for s in r.warnings)
    else:
        assert r.status == "completed" and r.warnings == ()
    no_mu = simulate_block(block, 0.0, 3.0, ag=SineWave(amplitude=amp * block.g, omega=w))
    assert "friction_smooth" not in no_mu.checks and no_mu.status == "completed"
    assert no_mu.friction.smooth == pytest.approx(amp, rel=1e-9)


def pivot_demand(block, phi0, phi):
    """|T/N| at the left pivot of a block released from rest at φ0, at φ (0 ≤ φ ≤ φ0), by
    Newton–Euler: r = G − O = (b cos φ − h sin φ, b sin φ + h cos φ), I_O φ̈ = −m g r_x,
    φ̇² from energy, T = m ẍ_G, N = m (ÿ_G + g)."""
    b, h, g = block.b, block.h, block.g
    I_O = 4.0 / 3.0 * block.R**2  # per unit mass
    rx = b * math.cos(phi) - h * math.sin(phi)
    ry = b * math.sin(phi) + h * math.cos(phi)
    ry0 = b * math.sin(phi0) + h * math.cos(phi0)
    w2, acc = 2.0 * g * (ry0 - ry) / I_O, -g * rx / I_O
    xdd, ydd = -ry * acc - rx * w2, rx * acc - ry * w2
    return abs(xdd) / (ydd + g)


@pytest.mark.parametrize("b, h", [(0.5, 0.25), (0.5, 0.35)])
def test_rocking_friction_demand_of_a_squat_block(b, h):
    # the first half-cycle of a stocky block (ε_P = 0: it then stays down, Eq 25): the
    # pivot's |T/N| peaks inside the half-cycle; reference: Newton–Euler on a fine φ grid
    block = PoissonBlock(b=b, h=h)
    phi0 = block.alpha / 3
    r = simulate_block(block, 0.0, 0.5, phi0=phi0)
    grid = np.linspace(0.0, phi0, 20001)
    ref = max(pivot_demand(block, phi0, p) for p in grid)
    assert r.friction.smooth == pytest.approx(ref, rel=1e-8)
    assert 0.0 < r.friction.smooth_time < r.raw.impacts[0].time
    # its one impact needs |Λ_T/Λ_N| = h/b (paper 000, Eqs 14–15)
    assert r.friction.impact == pytest.approx(h / b, rel=1e-9)
    assert r.friction.impact_time == r.raw.impacts[0].time


def test_slender_block_needs_little_friction_a_squat_one_more():
    # μ = 0.7: paper 000's slender block (H/b = 7) rocks within it — impacts need
    # 3 sin α cos α / (4 − 3 sin²α) (Eqs 17–18) — while a squat block bouncing with
    # ε_P = 0.5 exceeds it between impacts
    slender = PoissonBlock.from_slenderness(7.0)
    r = simulate_block(slender, 0.0, 3.0, phi0=slender.alpha / 3, mu=0.7)
    s, c = math.sin(slender.alpha), math.cos(slender.alpha)
    assert r.friction.impact == pytest.approx(3 * s * c / (4 - 3 * s * s), rel=1e-9)
    assert r.friction.largest < 0.7 and r.status == "completed"
    squat = PoissonBlock(b=0.5, h=0.25)
    r = simulate_block(squat, 0.5, 3.0, phi0=squat.alpha / 3, mu=0.7)
    assert r.friction.smooth > 0.7 and r.friction.impact == pytest.approx(0.5, rel=1e-9)
    assert r.status == "inaccurate" and r.outcome == "completed"
    assert r.checks["friction_smooth"]["passed"] is False
    assert r.checks["friction_impact"]["passed"] is True


def test_lift_off_into_flight_needs_unbounded_friction():
    # squat block under a strong sine: the pivot unloads while the ground pushes it sideways
    block = PoissonBlock(b=0.5, h=0.25)
    ag = SineWave(amplitude=1.5 * block.g * math.tan(block.alpha), omega=4.0 * block.p)
    r = simulate_block(block, 0.0, 3.0, ag=ag, mu=5.0)
    flights = [e for e in r.events if e.kind == "uplift" and e.closed_after == ()]
    assert all(e.phase_after is None for e in flights)  # flight has no phase
    assert flights and r.friction.smooth == math.inf
    assert r.friction.smooth_time == pytest.approx(flights[0].time, abs=1e-12)
    assert r.status == "inaccurate" and any("unbounded" in s for s in r.warnings)


@pytest.mark.parametrize(
    "kw, match",
    [
        (dict(mu=0.0), "`mu`"),
        (dict(mu=float("nan")), "`mu`"),
        (dict(mu="high"), "`mu`"),
        (dict(dphi0=float("inf")), "`dphi0`"),
        (dict(t_end=float("inf")), "`t_end`"),
    ],
)
def test_bad_new_input(kw, match):
    args = dict(block=PoissonBlock(0.5, 1.0), eps_p=0.5, t_end=1.0)
    args.update(kw)
    with pytest.raises(InputError, match=match):
        simulate_block(**args)


def test_a_ground_acceleration_that_is_not_finite_is_refused():
    block = PoissonBlock(b=0.3, h=0.6)
    with pytest.raises(InputError, match=r"`ag` returned nan at t = 0 s"):
        simulate_block(block, 0.0, 1.0, ag=lambda t: float("nan"))
    # a record that turns NaN mid-run stops the run with the time, not with NaN results
    with pytest.raises(InputError, match=r"`ag` returned nan at t = 0\.2"):
        simulate_block(
            block, 0.0, 1.0, ag=lambda t: float("nan") if t >= 0.2 else 1.0, locked_dt=0.05
        )
    with pytest.raises(InputError, match="`ag`"):
        simulate_block(block, 0.0, 1.0, ag=lambda t: "1 g")


# -- the one result contract (multimass.result)


def _no_nan(text):
    """json.loads that refuses NaN and infinities (not JSON)."""

    def refuse(c):
        raise ValueError(f"{c} in JSON")

    return json.loads(text, parse_constant=refuse)


def housner_peaks(alpha, theta0, n):
    """Closed form (energy): cos(α − θ_{k+1}) = cos α + η² [cos(α − θ_k) − cos α]."""
    eta, peaks = housner_eta(alpha), [theta0]
    for _ in range(n - 1):
        c = math.cos(alpha) + eta**2 * (math.cos(alpha - peaks[-1]) - math.cos(alpha))
        peaks.append(alpha - math.acos(c))
    return peaks


def test_block_response_follows_the_result_contract():
    # H/b = 7, ε_P = 0 is Housner's block (Fig 5): its peaks are the closed form's
    block = PoissonBlock.from_slenderness(7.0)
    phi0 = block.alpha / 3
    r = simulate_block(block, 0.0, 4.0, phi0=phi0, dt_out=0.01)
    assert isinstance(r, BlockResponse) and isinstance(r, Result) and r.engine == "contact"
    assert r.status in STATUSES and r.outcome in OUTCOMES and r.status == "completed"
    assert r.message == r.raw.message and {e.kind for e in r.events} <= EVENT_KINDS
    # peaks in rad, release first: |θ0| = φ0, then Housner's energy closed form
    assert r.peaks[0] == phi0 and r.peak_times[0] == 0.0
    assert r.peaks.size == r.n_impacts + 1 == 4
    np.testing.assert_allclose(r.peaks, housner_peaks(block.alpha, phi0, 4), atol=1e-9)
    imp = [e.time for e in r.events if e.kind == "impact"]
    assert np.all((r.peak_times[1:-1] > imp[:-1]) & (r.peak_times[1:-1] < imp[1:]))
    # the impacts alternate the pivots: released on the left (φ0 > 0, θ0 < 0) → right, …
    assert [(e.kind, e.phase_before, e.phase_after) for e in r.events] == [
        ("release", -1, -1),
        ("impact", -1, 1),
        ("impact", 1, -1),
        ("impact", -1, 1),
    ]
    # series: θ = −φ, the integer phase beside the named one
    df = r.series
    assert list(df.columns[:4]) == ["t", "theta", "thetadot", "phase"]
    assert {"x", "y", "phi", "phidot"} <= set(df.columns)
    np.testing.assert_array_equal(df["theta"], -r.phi)
    np.testing.assert_array_equal(df["thetadot"], -df["phidot"])
    named = {"rock_left": -1, "rock_right": 1, "full": 0}
    assert [named[p] for p in r.phase] == df["phase"].tolist()
    led = r.ledger
    assert set(led.columns) <= set(LEDGER_NAMES) and {"t", "energy"} <= set(led.columns)
    assert np.abs(led["balance_error"]).max() < 1e-7 * led["energy"].iloc[0]
    info = _no_nan(r.to_json())
    assert info["peaks"] == list(r.peaks) and info["eps_p"] == 0.0
    assert info["theta_max"] == phi0 and info["model"] == "poisson_block"


def test_overturning_block_ends_with_an_overturn_event():
    block = PoissonBlock.from_slenderness(4.0, width=0.4)
    ag = SineWave(amplitude=1.2 * block.g, omega=2.0 * block.p)
    r = simulate_block(block, 0.0, 10.0, ag=ag)
    last = r.events[-1]
    assert r.outcome == r.status == "overturned" and r.overturned
    assert last.kind == "overturn" and abs(last.theta) == pytest.approx(math.pi / 2, abs=1e-12)
    assert r.peaks[-1] == pytest.approx(math.pi / 2, abs=1e-12)
    assert r.events[1].kind == "uplift" and r.events[1].phase_before == 0
    info = _no_nan(r.to_json())
    assert info["status"] == "overturned" and info["overturn_time"] == last.time


def test_flight_has_no_phase():
    # paper 000, Eq 22: a slender block with ε_P > 0 leaves the ground after its first impact
    block = PoissonBlock.from_slenderness(7.0)
    r = simulate_block(block, 0.5, 3.0, phi0=block.alpha / 3)
    first = r.raw.impacts[0]
    assert (first.phase_before, first.phase_after) == (-1, None)
    flight = r.phase == "flight"
    assert flight.any() and r.series["phase"][flight].isna().all()
    assert r.series["phase"][~flight].notna().all()
