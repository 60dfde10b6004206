"""Poisson impact LCPs (paper 000, Eqs 1–12) against the rigid block's closed forms (Eqs 13–25)."""

import math

import numpy as np
import pytest

from multimass.impact_models import LCPError, PoissonImpact, poisson_impact

ROOT_HALF = 1.0 / math.sqrt(2.0)
H_OVER_B = [
    0.2,
    0.5,
    0.7,
    ROOT_HALF * (1 - 1e-6),
    ROOT_HALF,
    ROOT_HALF * (1 + 1e-6),
    0.72,
    1.0,
    2.0,
    7.0,
    20.0,
]
EPS = [0.0, 0.25, 0.5, 0.75, 1.0]


def block_impact(h_over_b, eps, m=3.0, b=0.4, phidot=-1.7):
    """The block of paper 000, Eq 13, rocking on point '1' and hitting with point '2'."""
    H = h_over_b * b
    I_G = m * (b * b + H * H) / 3.0  # paper 000, after Eq 13
    M = np.diag([m, m, I_G])
    W_N = np.array([[0.0, 0.0], [1.0, 1.0], [-b, b]])  # paper 000, Eq 13
    W_T = np.array([[1.0], [0.0], [H]])  # paper 000, Eq 13
    u_minus = phidot * np.array([-H, b, 1.0])  # pure rotation about point '1'
    alpha = math.atan(b / H)
    return poisson_impact(M, W_N, W_T, u_minus, eps), m, 2.0 * b * phidot, alpha, phidot


def stocky_closed_form(alpha, eps):
    s2 = math.sin(alpha) ** 2
    return dict(
        L0=(1 / (3 * s2) - 0.5, -1 / (3 * s2)),  # paper 000, Eq 14
        LT0=1 / (2 * math.tan(alpha)),  # paper 000, Eq 15
        gp2=-eps,  # paper 000, Eq 20
        Lp=(eps * (1 / (3 * s2) - 0.5), eps * -1 / (3 * s2)),  # Eq 20; Λ_N2⁺ = ε Λ_N2⁰
        LTp=eps / (2 * math.tan(alpha)),  # paper 000, Eq 21
        eta=-eps,
    )  # paper 000, Eq 25


def slender_closed_form(alpha, eps):
    s2, sc = math.sin(alpha) ** 2, math.sin(alpha) * math.cos(alpha)
    return dict(
        g01=1.5 * s2 - 1,
        L0=(0.0, 0.75 * s2 - 1),  # paper 000, Eq 17
        LT0=0.75 * sc,  # paper 000, Eq 18
        gp=((1 + eps) * (1.5 * s2 - 1), -eps),  # paper 000, Eq 22
        Lp=(0.0, eps * (0.75 * s2 - 1)),  # Λ_N⁺ = ε Λ_N⁰ (Eq 22 text)
        LTp=0.75 * eps * sc,  # paper 000, Eq 23
        eta=1 - 1.5 * s2 - 1.5 * eps * s2,
    )  # paper 000, Eq 24


@pytest.mark.parametrize("eps", EPS)
@pytest.mark.parametrize("h_over_b", H_OVER_B)
def test_block_impact_reproduces_the_closed_forms(h_over_b, eps):
    r, m, g2, alpha, phidot = block_impact(h_over_b, eps)
    tol = 1e-12
    if h_over_b <= ROOT_HALF:  # stocky, and the limit (both families agree there)
        cf = stocky_closed_form(alpha, eps)
        np.testing.assert_allclose(r.impulse_compression / (m * g2), cf["L0"], atol=tol)
        np.testing.assert_allclose(r.tangential_impulse_compression / (m * g2), cf["LT0"], atol=tol)
        np.testing.assert_allclose(r.gN_compression / g2, 0.0, atol=tol)
        np.testing.assert_allclose(r.gN_plus[1] / g2, cf["gp2"], atol=tol)
        np.testing.assert_allclose(r.gN_plus[0] / g2, 0.0, atol=tol)
        np.testing.assert_allclose(r.impulse_expansion / (m * g2), cf["Lp"], atol=tol)
        np.testing.assert_allclose(r.tangential_impulse_expansion / (m * g2), cf["LTp"], atol=tol)
        assert r.u_plus[2] / phidot == pytest.approx(cf["eta"], abs=tol)
        assert r.states[1] == ("closed", "separating" if eps > 0 else "closed")
    if h_over_b >= ROOT_HALF:  # slender, and the limit
        cf = slender_closed_form(alpha, eps)
        assert r.gN_compression[0] / g2 == pytest.approx(cf["g01"], abs=tol)
        assert r.gN_compression[1] / g2 == pytest.approx(0.0, abs=tol)
        np.testing.assert_allclose(r.impulse_compression / (m * g2), cf["L0"], atol=tol)
        np.testing.assert_allclose(r.tangential_impulse_compression / (m * g2), cf["LT0"], atol=tol)
        np.testing.assert_allclose(r.gN_plus / g2, cf["gp"], atol=tol)
        np.testing.assert_allclose(r.impulse_expansion / (m * g2), cf["Lp"], atol=tol)
        np.testing.assert_allclose(r.tangential_impulse_expansion / (m * g2), cf["LTp"], atol=tol)
        assert r.u_plus[2] / phidot == pytest.approx(cf["eta"], abs=tol)
    # tangential sticking: ġ_T = 0 after both phases (paper 000, Eqs 5, 10)
    assert abs(r.u_compression[0] + h_over_b * 0.4 * r.u_compression[2]) < 1e-12
    assert abs(r.u_plus[0] + h_over_b * 0.4 * r.u_plus[2]) < 1e-12


@pytest.mark.parametrize(
    "h_over_b, expect",
    [
        (0.5, (("closed", "closed"), ("closed", "separating"))),  # Fig 3 C2 → E1: bouncing
        (7.0, (("separating", "separating"), ("closed", "separating"))),  # Fig 3 C3 → E3: flight
    ],
)
def test_post_impact_states_of_figure_3(h_over_b, expect):
    r = block_impact(h_over_b, 0.5)[0]
    assert r.states == expect
    assert r.final_states == (expect[0][1], expect[1][1])


def test_slender_plastic_impact_is_housner():
    # paper 000, Eq 24 with ε_P = 0 is Housner's η = 1 − 3/2 sin²α (paper 004, Eq 9)
    from multimass.impact_models import housner_eta

    for hb in (1.0, 3.0, 7.0):
        r, _, _, alpha, phidot = block_impact(hb, 0.0)
        assert r.u_plus[2] / phidot == pytest.approx(housner_eta(alpha), abs=1e-13)


def test_point_mass_on_a_floor():
    # closed form: a single frictionless contact reverses the normal velocity, u⁺ = −ε u⁻
    r = poisson_impact([[2.0]], [[1.0]], None, [-3.0], 0.6)
    assert r.u_plus[0] == pytest.approx(1.8, rel=1e-14)
    assert r.impulse_compression[0] == pytest.approx(6.0, rel=1e-14)
    assert r.impulse_expansion[0] == pytest.approx(3.6, rel=1e-14)
    assert r.energy_loss == pytest.approx(0.5 * 2.0 * (9.0 - 1.8**2), rel=1e-14)
    assert isinstance(r, PoissonImpact)


def test_sticking_stops_a_slipping_contact():
    # a point mass landing obliquely: sticking makes ġ_T = 0 already after compression
    r = poisson_impact(np.eye(2), [[0.0], [1.0]], [[1.0], [0.0]], [2.0, -1.0], 0.5)
    np.testing.assert_allclose(r.u_compression, [0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(r.u_plus, [0.0, 0.5], atol=1e-15)
    np.testing.assert_allclose(r.tangential_impulse, [-2.0], atol=1e-15)


def random_problem(rng, uniform_eps):
    n = int(rng.integers(1, 7))
    kN = int(rng.integers(1, n + 3))
    kT = int(rng.integers(0, n))
    A = rng.normal(size=(n, n))
    M = A @ A.T + 0.05 * np.eye(n)
    W_N, W_T = rng.normal(size=(n, kN)), rng.normal(size=(n, kT))
    eps = rng.random() if uniform_eps else rng.choice([0.0, 0.3, 1.0], size=kN)
    return M, W_N, W_T, rng.normal(size=n), eps


@pytest.mark.parametrize("uniform_eps", [True, False])
def test_impacts_never_create_energy_and_never_penetrate(uniform_eps):
    rng = np.random.default_rng(123)
    for _trial in range(2000):
        M, W_N, W_T, u, eps = random_problem(rng, uniform_eps)
        r = poisson_impact(M, W_N, W_T, u, eps)
        T = 0.5 * u @ M @ u
        scale = np.abs(r.gN_minus).max() + np.abs(W_T.T @ u).max(initial=0.0)
        assert r.energy_loss >= -1e-10 * T
        assert r.gN_compression.min() >= -1e-8 * scale  # paper 000, Eq 7
        assert r.gN_plus.min() >= -1e-8 * scale  # paper 000, Eq 12
        assert r.impulse_compression.min() >= 0.0
        assert r.impulse_np.min() >= 0.0
        np.testing.assert_allclose(W_T.T @ r.u_plus, 0.0, atol=1e-8 * scale)


def test_block_random_pre_impact_states_lose_energy():
    rng = np.random.default_rng(5)
    for _trial in range(500):
        hb, eps = rng.uniform(0.2, 10.0), rng.random()
        b, m = 0.5, 2.0
        H = hb * b
        M = np.diag([m, m, m * (b * b + H * H) / 3])
        W_N = np.array([[0.0, 0.0], [1.0, 1.0], [-b, b]])
        W_T = np.array([[1.0], [0.0], [H]])
        u = rng.normal(size=3)
        r = poisson_impact(M, W_N, W_T, u, eps)
        assert r.energy_loss >= -1e-12 * (0.5 * u @ M @ u)


def test_elastic_single_contact_conserves_energy():
    rng = np.random.default_rng(9)
    for _trial in range(100):
        A = rng.normal(size=(3, 3))
        M = A @ A.T + 0.1 * np.eye(3)
        w = rng.normal(size=(3, 1))
        u, Miw = rng.normal(size=3), np.linalg.solve(M, w[:, 0])
        u -= (w[:, 0] @ u + 1.0) * Miw / (w[:, 0] @ Miw)  # ġ_N⁻ = −1: approaching
        r = poisson_impact(M, w, None, u, 1.0)
        assert r.energy_loss == pytest.approx(0.0, abs=1e-12 * (u @ M @ u))
        assert r.gN_plus[0] == pytest.approx(-r.gN_minus[0], rel=1e-12)


GOOD = dict(
    M=np.diag([1.0, 1.0, 0.5]),
    W_N=np.array([[0.0, 0.0], [1.0, 1.0], [-1.0, 1.0]]),
    W_T=np.array([[1.0], [0.0], [2.0]]),
    u_minus=np.array([-2.0, 1.0, 1.0]),
    eps_p=0.5,
)


@pytest.mark.parametrize(
    "field, value, match",
    [
        ("M", np.array([[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.5]]), "not symmetric"),
        ("M", np.diag([1.0, -1.0, 0.5]), "not positive definite"),
        ("M", np.ones((3, 2)), "square"),
        ("W_N", np.ones((2, 2)), "`W_N`"),
        ("W_N", np.ones((3, 0)), "`W_N`"),
        ("W_T", np.ones((4, 1)), "`W_T`"),
        ("W_T", np.array([[1.0, 2.0], [0.0, 0.0], [2.0, 4.0]]), "linearly dependent"),
        ("u_minus", np.ones(2), "`u_minus`"),
        ("u_minus", np.array([np.nan, 0.0, 0.0]), "NaN"),
        ("eps_p", 1.5, r"\[0, 1\]"),
        ("eps_p", -0.1, r"\[0, 1\]"),
        ("eps_p", float("nan"), r"\[0, 1\]"),
        ("eps_p", [0.5, 0.5, 0.5], "`eps_p`"),
    ],
)
def test_bad_input(field, value, match):
    kw = dict(GOOD, **{field: value})
    with pytest.raises(LCPError, match=match):
        poisson_impact(**kw)
    assert issubclass(LCPError, ValueError)


def test_energy_loss_identity_for_uniform_eps():
    # closed form: with ġ_T⁻ = 0 and one ε, T⁻ − T⁺ = ½(1 − ε²)Λ⁰ᵀAΛ⁰ + ½Λ_NPᵀAΛ_NP,
    # A = G_NN − G_NT G_TT⁻¹ G_TN (paper 000, Eq 6), from Eqs 2, 7, 8, 12
    rng = np.random.default_rng(4)
    for _trial in range(300):
        n = int(rng.integers(2, 6))
        kN, kT = int(rng.integers(1, n + 1)), int(rng.integers(0, n))
        B = rng.normal(size=(n, n))
        M = B @ B.T + 0.1 * np.eye(n)
        W_N, W_T = rng.normal(size=(n, kN)), rng.normal(size=(n, kT))
        u = rng.normal(size=n)
        if kT:  # remove the tangential slip: ġ_T⁻ = 0
            MiT = np.linalg.solve(M, W_T)
            u -= MiT @ np.linalg.solve(W_T.T @ MiT, W_T.T @ u)
        eps = rng.random()
        r = poisson_impact(M, W_N, W_T, u, eps)
        Mi = np.linalg.inv(M)
        A = W_N.T @ Mi @ W_N
        if kT:
            A -= W_N.T @ Mi @ W_T @ np.linalg.solve(W_T.T @ Mi @ W_T, W_T.T @ Mi @ W_N)
        L0, LP = r.impulse_compression, r.impulse_np
        expected = 0.5 * (1 - eps**2) * L0 @ A @ L0 + 0.5 * LP @ A @ LP
        assert r.energy_loss == pytest.approx(expected, abs=1e-8 * (0.5 * u @ M @ u))
