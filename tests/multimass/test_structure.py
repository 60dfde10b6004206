"""Derived quantities of the multi-mass structure (paper 001, Section 2 and Table 1)."""

import numpy as np
import pytest

from tests.conftest import column_toml

import multimass
from multimass import InputError
from multimass.damping import rayleigh_damping
import specimens


@pytest.mark.parametrize("name, J_p, H_cg, alpha_cg, p_l", [
    ("S1", 298, 0.84, 0.35, 2.51),    # paper 001, Table 1
    ("S3", 413, 1.02, 0.29, 2.35),    # paper 001, Table 1
])
def test_derived_parameters_agree_with_table_1(name, J_p, H_cg, alpha_cg, p_l):
    s = multimass.column(name)
    assert abs(s.J_p - J_p) <= 1.0
    assert abs(s.H_cg - H_cg) <= 0.01
    assert abs(s.alpha_cg - alpha_cg) <= 0.01
    assert abs(s.p_l - p_l) <= 0.01


def test_s2_published_values_disagree_with_its_own_inputs():
    # DESIGN.md: S2's H and M give J_p ≈ 495 and H_cg ≈ 1.165, not Table 1's 509 and 1.18
    s = multimass.column("S2")
    assert s.J_p == pytest.approx(495.0, abs=0.5)
    assert s.H_cg == pytest.approx(1.165, abs=0.001)
    assert abs(s.J_p - 509) > 1.0


def test_derived_quantities_by_hand():
    # paper 001, after Eq 5: J_p = R0ᵀ M R0 + m0 B² + J0; Eq 6: p_l = sqrt(1ᵀMH g / J_p)
    s = multimass.column("S1")
    H, m, B = np.array(s.H), np.array(s.m), 0.305
    J_p = sum(mi * (hi**2 + B**2) for mi, hi in zip(m, H)) + 10.0
    assert s.J_p == pytest.approx(J_p, rel=1e-14)
    assert s.m_t == pytest.approx(226.1, rel=1e-14)
    assert s.R0 == pytest.approx(np.sqrt(H**2 + B**2))
    assert s.p_l == pytest.approx(np.sqrt(9.81 * (m @ H) / J_p), rel=1e-14)
    assert s.alpha_cg == pytest.approx(np.arctan(B / ((m @ H) / 226.1)), rel=1e-14)


def test_rayleigh_damping_reproduces_zeta_at_modes_1_and_2():
    s = multimass.column("S1")
    w2, phi = np.linalg.eig(np.linalg.solve(s.M, s.K))
    order = np.argsort(w2)
    for k, zeta in zip(order[:2], (0.005, 0.015)):      # paper 001, Table 1, S1
        v = phi[:, k].real
        c = v @ s.C @ v
        m = v @ s.M @ v
        assert c / (2.0 * np.sqrt(w2[k].real) * m) == pytest.approx(zeta, rel=1e-10)


def test_rayleigh_single_dof_gives_exact_zeta():
    M, K = np.array([[2.0]]), np.array([[800.0]])
    C, (a0, a1) = rayleigh_damping(M, K, 0.03, 0.5)
    assert C[0, 0] / (2.0 * np.sqrt(800.0 * 2.0)) == pytest.approx(0.03, rel=1e-14)
    assert a0 == 0.0


def test_one_node_column_is_the_sdof_oscillator(tmp_path):
    p = column_toml(tmp_path, [1.2], [150.0], name="sdof")
    s = multimass.column(p)
    assert s.n == 1
    assert s.K[0, 0] == pytest.approx(5.0e8)           # the horizontal spring alone
    assert s.full_contact_omega[0] == pytest.approx(np.sqrt(5.0e8 / 150.0))
    assert s.J_p == pytest.approx(150.0 * (1.2**2 + 0.305**2) + 10.0)


def test_e_s_override():
    base = multimass.column("S1")
    stiff = multimass.column("S1", E_s=210e9)
    assert stiff.full_contact_omega[0] > base.full_contact_omega[0]
    with pytest.raises(InputError, match="E_s"):
        multimass.column("S1", E_s=-1.0)


def test_rigid_block_is_housner():
    # paper 004, after Eq 2: I_A = (4/3) m R², p = sqrt(3 g / (4 R))
    blk = multimass.rigid_block("B6M")
    spec = specimens.load("B6M")
    assert blk.n == 0 and blk.is_rigid
    assert blk.J_p == pytest.approx(4.0 / 3.0 * spec.mass * spec.R**2, rel=1e-14)
    assert blk.p == pytest.approx(np.sqrt(3 * 9.81 / (4 * spec.R)), rel=1e-14)
    assert blk.alpha_cg == pytest.approx(np.arctan(spec.b / spec.h), rel=1e-14)
    assert multimass.from_specimen("B6M").J_p == blk.J_p
    with pytest.raises(InputError, match="block"):
        multimass.rigid_block("S1")
