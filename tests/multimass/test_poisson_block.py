"""Rigid block with Poisson LCP impacts (paper 000, Section 3) against Housner's model."""

import math

import numpy as np
import pytest

from impact_models import housner_eta
import multimass
from multimass import InputError
from multimass import SineWave
from multimass.poisson_block import PoissonBlock, _BlockModel, housner_theta, simulate_block


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
    err = np.abs(on_grid(r, grid) + theta_h).max() / block.alpha     # φ = −θ
    assert err < 1e-6
    assert "flight" not in set(r.phase)
    assert len(r.raw.impacts) >= 5


def test_sine_pulse_figure_5_agrees_with_housner():
    # paper 000, Fig 5: H/b = 7, 2b = 1 m, a_g/g = 0.45, ω_g/p = 5.75, ε_P = 0
    block = PoissonBlock.from_slenderness(7.0, width=1.0)
    a_g, w_g = 0.45 * block.g, 5.75 * block.p
    ag = SineWave(amplitude=a_g, omega=w_g)
    r = simulate_block(block, 0.0, 15.0, ag=ag, dt_out=0.01)
    t_up = math.asin(block.g * math.tan(block.alpha) / a_g) / w_g    # closed form: ag = g tan α
    grid = np.round(np.arange(0.0, 15.0, 0.01), 12)
    theta_h = housner_theta(block, ag, t_up, 0.0, grid, housner_eta(block.alpha), side=-1)
    err = np.abs(on_grid(r, grid) + theta_h).max() / block.alpha
    assert err < 1e-6
    assert np.abs(r.phi).max() / block.alpha > 0.5          # it does rock substantially
    uplift = r.events[0]
    assert uplift.kind == "liftoff" and uplift.closed_after == (0,)   # left corner: φ > 0
    assert uplift.time == pytest.approx(t_up, abs=1e-9)
    assert r.phi[np.searchsorted(r.t, t_up + 0.05)] > 0.0   # ag > 0 ⇒ φ > 0 ⇒ θ < 0
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
    assert r.events[-1].kind == "zeno_rest" and r.events[-1].closed_after == (0, 1)
    assert r.phase[-1] == "full"


def test_rocking_that_dies_out_comes_to_rest():
    # Housner's impacts accumulate at a finite time; the Zeno guard ends them in full contact
    block = PoissonBlock.from_slenderness(3.0)
    r = simulate_block(block, 0.0, 8.0, phi0=block.alpha / 3)
    assert r.status == "completed"
    assert r.events[-1].kind == "zeno_rest" and r.events[-1].closed_after == (0, 1)
    assert 4.0 < r.events[-1].time < 5.5
    assert np.abs(r.phi[r.t > r.events[-1].time]).max() < 1e-12


def test_slender_block_flies_after_impact_when_eps_positive():
    # paper 000, Eqs 22, 24: C3 → E3, both corners leave the ground
    block = PoissonBlock.from_slenderness(7.0)
    r = simulate_block(block, 0.5, 3.0, phi0=block.alpha / 3)
    first = r.raw.impacts[0]
    s2 = math.sin(block.alpha) ** 2
    assert first.impact.u_plus[2] / first.impact.u_minus[2] == pytest.approx(
        1 - 1.5 * s2 * 1.5, abs=1e-9)                                      # paper 000, Eq 24
    assert first.closed_after == ()
    assert "flight" in set(r.phase)


@pytest.mark.parametrize("h_over_b, eps", [(0.7, 0.0), (0.7, 0.5), (0.7, 1.0),
                                           (7.0, 0.0), (7.0, 0.5), (7.0, 1.0)])
def test_energy_ledger_closes(h_over_b, eps):
    block = PoissonBlock.from_slenderness(h_over_b)
    r = simulate_block(block, eps, 3.0, phi0=block.alpha / 3)
    E0 = r.raw.energy[0]
    assert np.abs(r.raw.ledger_error).max() < 1e-7 * E0
    assert np.all(np.diff(r.raw.impact_loss) >= -1e-12 * E0)    # impacts never create energy


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
    np.testing.assert_array_equal(W_N, [[0, 0], [1, 1], [-0.5, 0.5]])     # paper 000, Eq 13
    np.testing.assert_array_equal(W_T, [[1], [0], [3.5]])
    assert M[2, 2] == pytest.approx(2.0 * 12.5 / 3)
    # the simulation's contact kinematics reduce to Eq 13 at φ = 0 (both corners' W_T equal)
    g, WN, WT, _, _ = _BlockModel(block, lambda t: 0.0).contacts(np.array([0.0, 3.5, 0.0]),
                                                                 np.zeros(3))
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


@pytest.mark.parametrize("kw, match", [
    (dict(eps_p=1.5), "eps_p"),
    (dict(phi0=2.0), "phi0"),
    (dict(ag=3.0), "ag"),
    (dict(t_end=-1.0), "t_end"),
])
def test_bad_input(kw, match):
    args = dict(block=PoissonBlock(0.5, 1.0), eps_p=0.5, t_end=1.0)
    args.update(kw)
    with pytest.raises(InputError, match=match):
        simulate_block(**args)


@pytest.mark.parametrize("kw", [dict(b=-1.0, h=1.0), dict(b=1.0, h=0.0),
                                dict(b=1.0, h=1.0, mass=float("nan"))])
def test_bad_block(kw):
    with pytest.raises(InputError):
        PoissonBlock(**kw)


@pytest.mark.skipif(not hasattr(multimass, "simulate"), reason="engine not available")
@pytest.mark.parametrize("case", ["free", "sine"])
def test_agrees_with_the_engine_classical_impact(case):
    # the multi-mass engine's rigid block B6M with the classical impact and Housner's η
    st = multimass.rigid_block("B6M")
    block = PoissonBlock(b=st.B, h=st.h0, mass=st.m0)
    if case == "free":
        exc, kw = multimass.FreeRelease(0.1), dict(phi0=-0.1)      # θ0 = 0.1 ⇒ φ0 = −0.1
    else:
        exc = multimass.SineWave(amplitude=0.3 * block.g, omega=3.0 * block.p)
        kw = dict(ag=exc)
    eng = multimass.simulate(st, exc, impact="CIM", restitution="housner", t_end=2.0,
                             rtol=1e-10, atol=1e-12)
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
    eng = multimass.simulate(st, exc, impact="CIM", restitution="housner", t_end=2.0,
                             rtol=1e-10, atol=1e-12)
    df = eng.series
    keep = np.r_[np.diff(df.t) > 0, True]
    theta_engine = np.interp(grid, df.t[keep], df.theta[keep])
    assert np.abs(theta_engine).max() > 0.3 * block.alpha
    assert np.abs(theta_h - theta_engine).max() < 1e-6 * block.alpha
