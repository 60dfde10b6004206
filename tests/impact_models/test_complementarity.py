"""Lemke's method against brute-force enumeration of complementary bases."""

import itertools

import numpy as np
import pytest

from multimass.impact_models import LCPError, lemke


def brute_force(M, q, tol=1e-9):
    """All solutions w = Mz + q ≥ 0, z ≥ 0, wᵀz = 0 over the 2ⁿ complementary bases."""
    n = len(q)
    sols = []
    for size in range(n + 1):
        for alpha in itertools.combinations(range(n), size):
            a = list(alpha)
            z = np.zeros(n)
            if a:
                Maa = M[np.ix_(a, a)]
                if abs(np.linalg.det(Maa)) < 1e-12:
                    continue
                z[a] = np.linalg.solve(Maa, -q[a])
            w = M @ z + q
            if z.min() >= -tol and w.min() >= -tol:
                sols.append((z, w))
    return sols


def assert_solves(M, q, sol, tol=1e-9):
    scale = 1.0 + np.abs(q).max() + np.abs(M).max() * np.abs(sol.z).max()
    assert sol.z.min() >= -tol * scale
    assert sol.w.min() >= -tol * scale
    assert np.abs(sol.z * sol.w).max() <= tol * scale * max(1.0, np.abs(sol.z).max())
    np.testing.assert_allclose(sol.w, M @ sol.z + q, atol=1e-12 * scale)


def random_p_matrix(rng, n, kind):
    A = rng.normal(size=(n, n))
    if kind == "spd":
        return A @ A.T + 0.1 * np.eye(n)
    if kind == "pd_nonsymmetric":  # S + K, S ≻ 0, K skew: xᵀMx > 0 ⇒ P-matrix
        K = rng.normal(size=(n, n))
        return A @ A.T + 0.1 * np.eye(n) + (K - K.T)
    B = rng.normal(size=(n, n))  # strictly row diagonally dominant, positive diagonal
    np.fill_diagonal(B, np.abs(B).sum(axis=1) + 0.1)
    return B


@pytest.mark.parametrize("kind", ["spd", "pd_nonsymmetric", "diag_dominant"])
def test_p_matrix_problems_match_the_unique_enumerated_solution(kind):
    rng = np.random.default_rng(20240501)
    for _trial in range(150):
        n = int(rng.integers(1, 7))
        M = random_p_matrix(rng, n, kind)
        q = rng.normal(size=n)
        sols = brute_force(M, q)
        assert len(sols) == 1  # closed form: a P-matrix LCP has exactly one solution
        sol = lemke(M, q)
        assert_solves(M, q, sol)
        np.testing.assert_allclose(sol.z, sols[0][0], atol=1e-10, rtol=1e-10)


@pytest.mark.parametrize(
    "M, q",
    [
        # ties in the first ratio test (q_i/d_i all equal)
        (np.array([[1.0, 2.0, 0.0], [0.0, 1.0, 2.0], [2.0, 0.0, 1.0]]), -np.ones(3)),
        # zeros in q: degenerate basic solutions from the start
        (np.array([[2.0, 1.0, 0.0], [1.0, 2.0, 1.0], [0.0, 1.0, 2.0]]), np.array([-1.0, 0.0, 0.0])),
        (np.array([[1.0, -1.0], [1.0, 1.0]]), np.array([0.0, -2.0])),
        # singular PSD matrix: a continuum of solutions (z1 + z2 = 1), w unique
        (np.ones((2, 2)), np.array([-1.0, -1.0])),
        (
            np.array([[1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 0.0]]),
            np.array([-1.0, -1.0, 0.0]),
        ),
        # repeated rows and ties at every step
        (
            np.array([[1.0, 1.0, 1.0], [1.0, 1.0, 1.0], [1.0, 1.0, 2.0]]),
            np.array([-1.0, -1.0, -1.0]),
        ),
    ],
)
def test_degenerate_problems(M, q):
    sol = lemke(M, q)
    assert_solves(M, q, sol)
    sols = brute_force(M, q)
    assert sols, "the problem is feasible (enumeration finds a solution)"
    # for a P- or symmetric PSD matrix w is the same in every solution
    if np.allclose(M, M.T) or len(sols) == 1:
        np.testing.assert_allclose(sol.w, sols[0][1], atol=1e-10)


@pytest.mark.parametrize("kind", ["spd", "low_rank_psd"])
def test_random_degenerate_problems(kind):
    # q = M z* + w* with z*, w* ≥ 0 complementary and both zero on some indices
    # (degenerate: z_i = w_i = 0), so a solution is known to exist
    rng = np.random.default_rng(7)
    for _trial in range(200):
        n = int(rng.integers(2, 7))
        B = rng.normal(size=(n if kind == "spd" else int(rng.integers(1, n)), n))
        M = B.T @ B + (0.1 * np.eye(n) if kind == "spd" else 0.0)
        role = rng.integers(0, 3, size=n)  # 0: z > 0, 1: w > 0, 2: both zero
        z_star = np.where(role == 0, rng.random(n) + 0.1, 0.0)
        w_star = np.where(role == 1, rng.random(n) + 0.1, 0.0)
        q = w_star - M @ z_star
        sol = lemke(M, q)
        assert_solves(M, q, sol, tol=1e-8)
        np.testing.assert_allclose(sol.w, w_star, atol=1e-9)  # w unique for symmetric PSD M


def test_trivial_solution_when_q_is_nonnegative():
    sol = lemke(np.eye(3), [1.0, 0.0, 2.0])
    assert sol.pivots == 0
    np.testing.assert_array_equal(sol.z, 0.0)
    np.testing.assert_array_equal(sol.w, [1.0, 0.0, 2.0])


def test_two_by_two_by_hand():
    # closed form: both z > 0 ⇒ M z = −q ⇒ z = (4/3, 7/3)
    sol = lemke([[2.0, 1.0], [1.0, 2.0]], [-5.0, -6.0])
    np.testing.assert_allclose(sol.z, [4 / 3, 7 / 3], rtol=1e-14)
    np.testing.assert_allclose(sol.w, 0.0, atol=1e-14)


@pytest.mark.parametrize(
    "M, q",
    [
        (np.array([[-1.0]]), np.array([-1.0])),  # w = −z − 1 < 0
        (np.array([[0.0]]), np.array([-1.0])),  # w = −1
        (
            np.array([[1.0, -1.0], [-1.0, 1.0]]),
            np.array([-1.0, -1.0]),
        ),  # y = (1,1): Mᵀy = 0, yᵀq < 0
    ],
)
def test_infeasible_problems_end_on_a_ray(M, q):
    assert not brute_force(M, q)
    with pytest.raises(LCPError, match="ray"):
        lemke(M, q)


def test_random_infeasible_psd_problems_end_on_a_ray():
    # Farkas: y ≥ 0 with My = 0 and yᵀq < 0 proves infeasibility for PSD M
    rng = np.random.default_rng(11)
    for _trial in range(50):
        n = int(rng.integers(2, 6))
        y = rng.random(n) + 0.1
        B = rng.normal(size=(n, n))
        B -= np.outer(B @ y, y) / (y @ y)  # B y = 0
        M = B.T @ B
        q = rng.normal(size=n)
        q -= (q @ y + 1.0) / (y @ y) * y  # yᵀq = −1
        with pytest.raises(LCPError, match="ray"):
            lemke(M, q)


@pytest.mark.parametrize(
    "M, q, match",
    [
        (np.eye(2), [1.0, 2.0, 3.0], "`M`"),
        (np.eye(2), [[1.0, 2.0]], "`q`"),
        (np.array([[1.0, np.nan], [0.0, 1.0]]), [1.0, -1.0], "NaN"),
    ],
)
def test_bad_input(M, q, match):
    with pytest.raises(LCPError, match=match):
        lemke(M, q)


def test_pivot_limit_is_reported():
    M = np.array([[2.0, 1.0], [1.0, 2.0]])
    with pytest.raises(LCPError, match="max_pivots"):
        lemke(M, [-5.0, -6.0], max_pivots=1)
