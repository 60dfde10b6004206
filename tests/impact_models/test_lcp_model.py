"""Poisson-LCP impacts inside the multi-mass engine (paper 000 applied to paper 001's model)."""

import math

import numpy as np
import pytest

import multimass
from multimass import FreeRelease, simulate
from multimass.impact_models import housner_eta, impact_model
from multimass.impact_models.lcp_model import PoissonLCP, base_mass_matrix


def test_rigid_block_with_eps_0_is_housner():
    # paper 000, Section 3.1: ε_P = 0 with sticking gives η = 1 − 1.5 sin²α (paper 004, Eq 9)
    blk = multimass.rigid_block("B6M")
    tr = PoissonLCP(eps_p=0.0).impact_at_zero(blk, 1, np.zeros(0), np.zeros(0), -0.5, 0.01)
    assert tr.kind == "impact" and tr.phase == -1
    assert tr.thetadot / -0.5 == pytest.approx(housner_eta(blk.alpha_cg), rel=1e-12)


def test_rigid_block_run_equals_classical_housner():
    blk = multimass.rigid_block("B6M")
    a = simulate(blk, FreeRelease(0.19666), "LCP", 1.5, output_dt=None)
    b = simulate(blk, FreeRelease(0.19666), "CIM", 1.5, restitution="housner", output_dt=None)
    np.testing.assert_allclose(a.peaks, b.peaks, atol=1e-9)


def test_mass_matrix_gives_the_kinetic_energy_of_rocking():
    # ½ vᵀ M v with v = [u̇, sBθ̇, θ̇] equals the engine's rocking kinetic energy about pivot s
    from multimass.model.kinematics import kinetic_energy

    s1 = multimass.column("S1")
    rng = np.random.default_rng(4)
    u, ud, thd = rng.normal(size=5) * 1e-3, rng.normal(size=5) * 0.1, 0.37
    for s in (1, -1):
        v = np.concatenate([ud, [s * s1.B * thd, thd]])
        M = base_mass_matrix(s1, u)
        assert 0.5 * v @ M @ v == pytest.approx(kinetic_energy(s1, s, u, ud, thd), rel=1e-12)


def test_impacts_never_create_energy_on_s1():
    from multimass.model.kinematics import kinetic_energy

    s1 = multimass.column("S1")
    rng = np.random.default_rng(9)
    model = PoissonLCP(eps_p=0.0)
    for _ in range(200):
        s = rng.choice([-1, 1])
        u, ud = rng.normal(size=5) * 2e-3, rng.normal(size=5) * 0.2
        thd = -s * abs(rng.normal()) * 0.5
        tr = model.impact_at_zero(s1, s, u, ud, thd, 0.01)
        before = kinetic_energy(s1, s, u, ud, thd)
        after = kinetic_energy(s1, tr.phase, u, tr.udot, tr.thetadot)
        assert after <= before * (1 + 1e-12)


def test_s1_free_release_with_lcp_closes_its_ledger():
    resp = simulate("S1", FreeRelease(-0.11), "LCP", 3.0, output_dt=None)
    assert resp.status == "completed"
    assert resp.n_full_contact >= 3
    assert resp.energy_balance_error <= 1e-5


def test_bounce_is_reported_not_hidden():
    resp = simulate("S1", FreeRelease(0.11), "LCP", 2.0, eps_p=0.5, output_dt=None)
    assert resp.status == "failed" and "flight" in resp.message


@pytest.mark.parametrize("bad", [-0.1, 1.5, math.nan])
def test_eps_p_range(bad):
    with pytest.raises(ValueError, match="eps_p"):
        impact_model("LCP", eps_p=bad)


def test_eps_p_only_for_lcp():
    with pytest.raises(ValueError, match="eps_p"):
        impact_model("CIM", multimass.column("S1").specimen, eps_p=0.2)
