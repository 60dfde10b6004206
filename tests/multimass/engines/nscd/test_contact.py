"""Single-contact Signorini-Coulomb solution and Gauss-Seidel (paper 002, Eqs 36-44)."""

import numpy as np
import pytest

from multimass.engines.nscd.contact import gauss_seidel, solve_single


def _check_law(W, U, P, mu, sliding):
    """Velocity Signorini (Eq 36) and Coulomb (Eqs 37-38) at U+ = U + W P."""
    Up = U + W @ P
    scale = 1e-10 * (1 + np.abs(U).max())
    assert P[0] >= 0 and Up[0] >= -scale and abs(P[0] * Up[0]) <= scale * (1 + P[0])
    assert abs(P[1]) <= mu * P[0] * (1 + 1e-12) + 1e-15
    if sliding:
        assert P[1] == pytest.approx(-mu * P[0] * np.sign(Up[1]), rel=1e-12, abs=1e-15)
    elif P[0] > 0:
        assert abs(Up[1]) <= scale


def test_open_contact_carries_nothing():
    assert solve_single(2.0, 0.1, 0.1, 1.0, 0.3, -5.0, 0.5) == (0.0, 0.0, False)


def test_sticking():
    W = np.array([[2.0, 0.3], [0.3, 1.0]])
    U = np.array([-1.0, 0.1])
    pn, pt, sl = solve_single(W[0, 0], W[0, 1], W[1, 0], W[1, 1], U[0], U[1], 1.0)
    # closed form: P = -W^-1 U when it lies inside the cone
    assert not sl and (pn, pt) == pytest.approx(tuple(np.linalg.solve(W, -U)), rel=1e-14)


def test_sliding():
    W = np.array([[2.0, 0.3], [0.3, 1.0]])
    U = np.array([-1.0, 3.0])
    mu = 0.2
    pn, pt, sl = solve_single(W[0, 0], W[0, 1], W[1, 0], W[1, 1], U[0], U[1], mu)
    # closed form: U_t stays > 0, P_t = -mu P_n, U_n+ = 0 -> P_n = -U_n / (W_nn - mu W_nt)
    assert (
        sl
        and pn == pytest.approx(1.0 / (2.0 - 0.2 * 0.3), rel=1e-14)
        and pt == pytest.approx(-mu * pn)
    )
    _check_law(W, U, np.array([pn, pt]), mu, sl)


def test_random_cases_satisfy_the_contact_law():
    rng = np.random.default_rng(6)
    for _ in range(2000):
        G = rng.normal(size=(2, 2))
        W = G @ G.T + 0.05 * np.eye(2)
        U = rng.normal(size=2)
        mu = rng.uniform(0.0, 1.5)
        pn, pt, sl = solve_single(W[0, 0], W[0, 1], W[1, 0], W[1, 1], U[0], U[1], mu)
        _check_law(W, U, np.array([pn, pt]), mu, sl)


def test_gauss_seidel_two_sticking_contacts_solve_the_linear_system():
    rng = np.random.default_rng(44)
    G = rng.normal(size=(4, 4))
    Wfull = G @ G.T + 0.5 * np.eye(4)
    U = -Wfull @ np.array([1.0, 0.1, 2.0, -0.2])  # exact stick impulses inside the cone
    W = Wfull.reshape(2, 2, 2, 2).transpose(0, 2, 1, 3).copy()
    P = np.zeros((2, 2))
    sliding = np.zeros(2, dtype=np.bool_)
    it, ok, residual = gauss_seidel(
        W, U.reshape(2, 2).copy(), P, sliding, 2, 10.0, 1e-13, 10000, 1.0
    )
    assert ok and it > 1 and residual <= 1e-13
    # closed form: P = -W^-1 U
    assert P.ravel() == pytest.approx([1.0, 0.1, 2.0, -0.2], abs=1e-9)


def test_gauss_seidel_reports_the_cap():
    rng = np.random.default_rng(45)
    G = rng.normal(size=(4, 4))
    Wfull = G @ G.T + 1e-6 * np.eye(4)  # badly conditioned: slow convergence
    U = -Wfull @ np.array([1.0, 0.1, 2.0, -0.2])
    W = Wfull.reshape(2, 2, 2, 2).transpose(0, 2, 1, 3).copy()
    P = np.zeros((2, 2))
    it, ok, residual = gauss_seidel(
        W, U.reshape(2, 2).copy(), P, np.zeros(2, dtype=np.bool_), 2, 10.0, 1e-14, 3, 1.0
    )
    assert (it, ok) == (3, False) and residual > 1e-14
