"""Foss state-space eigen-solution (paper 001, Eqs 24–25) against closed forms and python-control."""

import control
import numpy as np
import pytest

import multimass
from modal import LinearSystem, foss, frequency_and_damping, full_contact, rocking


def _system(M, C, K, phase="full_contact"):
    n = M.shape[0]
    return LinearSystem(phase, M, C, K, r=np.zeros(n), f0=np.zeros(n),
                        dofs=tuple(f"q{i}" for i in range(n)))


def test_sdof_eigenvalues_in_closed_form():
    m, k, zeta = 3.0, 1200.0, 0.07
    w = np.sqrt(k / m)
    sys = _system(np.array([[m]]), np.array([[2 * zeta * w * m]]), np.array([[k]]))
    lam = foss(sys).eigenvalues
    expected = -zeta * w + 1j * w * np.sqrt(1 - zeta**2)    # textbook damped SDOF
    assert lam[np.argmax(lam.imag)] == pytest.approx(expected, rel=1e-12)
    omega, z = frequency_and_damping(lam)
    np.testing.assert_allclose(omega, w, rtol=1e-12)
    np.testing.assert_allclose(z, zeta, rtol=1e-10)


def _independent_state_matrix(sys):
    Minv = np.linalg.inv(sys.M)
    n = sys.n
    return np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ sys.K, -Minv @ sys.C]])


@pytest.mark.parametrize("name", ["S1", "S2", "S3"])
@pytest.mark.parametrize("phase", ["full_contact", "rocking"])
def test_frequency_and_damping_match_control_damp(name, phase):
    s = multimass.column(name)
    sys = full_contact(s) if phase == "full_contact" else rocking(s)
    A = _independent_state_matrix(sys)
    ss = control.ss(A, np.zeros((A.shape[0], 1)), np.eye(A.shape[0]), np.zeros((A.shape[0], 1)))
    wn, zeta, poles = control.damp(ss, doprint=False)
    omega, z = frequency_and_damping(foss(sys).eigenvalues)
    # compare as multisets of (ω, ζ) pairs, sorted by ω then ζ
    ours = sorted(zip(np.round(omega, 6), np.round(z, 8)))
    theirs = sorted(zip(np.round(wn, 6), np.round(zeta, 8)))
    np.testing.assert_allclose(np.array(ours), np.array(theirs), rtol=1e-7, atol=1e-9)


def test_classically_damped_full_contact_returns_rayleigh_ratios():
    # full contact is Rayleigh-damped: Foss must return ζ_n1, ζ_n2 at modes 1 and 2
    s = multimass.column("S1")
    lam = foss(full_contact(s)).eigenvalues
    lam = lam[lam.imag > 0]
    lam = lam[np.argsort(np.abs(lam))]
    _, z = frequency_and_damping(lam)
    np.testing.assert_allclose(z[:2], [0.005, 0.015], rtol=1e-9)   # paper 001, Table 1, S1


def test_eigenvectors_satisfy_the_quadratic_eigenproblem():
    sys = rocking(multimass.column("S1"))
    ss = foss(sys)
    for lam, v in zip(ss.eigenvalues, ss.eigenvectors.T):
        residual = (lam**2 * sys.M + lam * sys.C + sys.K) @ v
        scale = np.linalg.norm(sys.K) * np.linalg.norm(v)
        assert np.linalg.norm(residual) <= 1e-10 * scale
