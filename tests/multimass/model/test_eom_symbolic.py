"""Independent symbolic check of the rocking-phase EOMs (paper 001, Eqs 4–5).

The reference is `multimass.model.symbolic`, which derives A(q) q̈ = b from the
Lagrangian of the N-node model with sympy (absolute positions of the nodes,
T = Σ ½ m_i |ṙ_i|² + ½ m0 |ṙ_0|² + ½ J0 θ̇², V = gravity + ½ uᵀKu, Rayleigh
D = ½ u̇ᵀCu̇, ground x_g(t) prescribed so that only ü_g survives). It does not
transcribe Eqs 4–5.

Approximations. None is needed to reconcile the two: for the paper's kinematic
model the hand-coded Eqs 4–5 equal the exact Lagrange equations, at any θ and
any u, term by term — including the u-dependent inertia uᵀMu ∓ 2B 1ᵀMu, the
Coriolis term ∓2u̇ᵀM(B1 ∓ u)θ̇, the centripetal term M(±B1 − u)θ̇² and the
u-dependent lever arms 1ᵀM(B1 ∓ u) of ü_g and g. The small-deformation
assumption of paper 001 ("large base rotations and small elastic deformations",
Section 2.2) lives in the kinematics, not in dropped terms: each node keeps its
height H_i in the rotated column frame and moves only by u_i perpendicular to
the column axis (inextensible column, axial shortening from bending ignored),
and the nodal rotations Ω carry no inertia, so the condensed K (Eq 2) is exact
in the rocking phase too. The tests therefore compare everything at 1e-10
relative, with |θ| up to 1 rad and u up to ~0.3 m.

Extension beyond the paper: node 0 may carry its mass at h0 > 0 (eom.py's
module docstring); the Lagrangian then gives J_p = … + m0 (B² + h0²) and the
extra arm m0 h0 in the ü_g and g terms, which eom.py implements.

Impact force: see `test_impact_force_is_the_generalised_force_of_a_force_at_P_prime`.
"""

import dataclasses

import numpy as np
import pytest

from multimass.model.eom import rocking_accelerations, rocking_system
from multimass.model.structure import Structure
from multimass.model.symbolic import derive_rocking, rocking_system_symbolic

RTOL = 1e-10  # relative: the coded EOMs equal the SymPy derivation to round-off


def random_structure(rng, n, h0):
    """A random N-node structure: increasing H, positive masses, SPD K and C."""
    H = np.cumsum(rng.uniform(0.05, 0.8, n))
    m = rng.uniform(1.0, 100.0, n)

    def spd(lo, hi):
        Q, _ = np.linalg.qr(rng.normal(size=(n, n)))
        S = Q @ np.diag(10.0 ** rng.uniform(lo, hi, n)) @ Q.T
        return 0.5 * (S + S.T)

    return Structure(
        name="random",
        H=H,
        m=m,
        m0=rng.uniform(0.0, 50.0),
        J0=rng.uniform(0.0, 20.0),
        B=rng.uniform(0.1, 0.5),
        g=9.81,
        K=spd(3, 6) if n else np.zeros((0, 0)),
        C=spd(1, 3) if n else np.zeros((0, 0)),
        h0=h0,
    )


def random_state(rng, n, side, u_scale=0.05):
    """u, θ (sign of the side, |θ| in (1e-3, 1) rad), u̇, θ̇, ü_g."""
    return dict(
        u=rng.normal(0.0, u_scale, n),
        theta=side * rng.uniform(1e-3, 1.0),
        udot=rng.normal(0.0, 0.5, n),
        thetadot=rng.normal(0.0, 1.5),
        ag=rng.normal(0.0, 5.0),
    )


def assert_close(code, ref):
    """Elementwise within RTOL of the reference, relative to the reference's size."""
    scale = max(np.abs(ref).max(), 1e-300)
    np.testing.assert_allclose(code, ref, rtol=RTOL, atol=RTOL * scale)


CASES = [(n, side, h0) for n in (1, 2, 3) for side in (1, -1) for h0 in (0.0, 0.37)]


# ---- kinematics: the convention the derivation rests on -----------------------------


@pytest.mark.parametrize("side", [1, -1])
def test_rotation_convention_node_moves_by_H_theta(side):
    # paper 001, Fig 1: θ > 0 rocks about the right pivot and the column leans to +x;
    # θ < 0 about the left pivot, leaning to −x. For u = 0: Δx ≈ H θ, and the node rises.
    d = derive_rocking(1, side)
    p = d.params
    x, y = d.positions["node1"]
    vals = {p["H"][0]: 1.7, p["B"]: 0.3, d.q[0]: 0.0}
    th = side * 1e-7
    dx = float(x.subs(vals).subs(d.q[-1], th)) - float(x.subs(vals).subs(d.q[-1], 0.0))
    dy = float(y.subs(vals).subs(d.q[-1], th)) - float(y.subs(vals).subs(d.q[-1], 0.0))
    assert dx == pytest.approx(1.7 * th, rel=1e-6)
    assert dy == pytest.approx(0.3 * abs(th), rel=1e-5)  # closed form: rises by B|θ|
    # the pivot stays put and P' is the opposite corner, 2B away
    P, P2 = d.positions["P"], d.positions["P'"]
    assert [float(v) for v in P.subs(vals)] == [side * 0.3, 0.0]
    assert [float(v) for v in P2.subs(vals).subs(d.q[-1], 0.0)] == pytest.approx([-side * 0.3, 0.0])


# ---- mass matrix and forcing at random states ------------------------------------------


@pytest.mark.parametrize("n, side, h0", CASES)
def test_mass_matrix_and_forcing_equal_the_lagrangian(n, side, h0):
    rng = np.random.default_rng(1000 * n + 10 * (side + 1) + int(h0 > 0))
    for _ in range(5):
        st = random_structure(rng, n, h0)
        for u_scale in (0.05, 0.3):  # exact in u too: no small-u approximation
            x = random_state(rng, n, side, u_scale)
            A, b = rocking_system(st, side, **x)
            A_ref, b_ref = rocking_system_symbolic(st, side, **x)
            assert_close(A, A_ref)
            assert_close(b, b_ref)
            np.testing.assert_array_equal(A, A.T)


@pytest.mark.parametrize("n, side", [(0, 1), (1, -1), (2, 1), (3, -1)])
def test_accelerations_solve_the_symbolic_system(n, side):
    # the solved accelerations, not just A and b: [ü; θ̈] = A_sym⁻¹ b_sym
    rng = np.random.default_rng(90 + n)
    for _ in range(5):
        st = random_structure(rng, n, 0.2)
        x = random_state(rng, n, side, 0.2)
        A_ref, b_ref = rocking_system_symbolic(st, side, **x)
        ref = np.linalg.solve(A_ref, b_ref)
        uddot, thetaddot = rocking_accelerations(st, side, **x)
        # a few ulps times cond(A): 1e-9 relative to the largest acceleration
        atol = 1e-9 * np.abs(ref).max()
        np.testing.assert_allclose(np.append(uddot, thetaddot), ref, rtol=1e-9, atol=atol)


def _variant(st, **fields):
    return dataclasses.replace(st, **fields)


@pytest.mark.parametrize("n, side, h0", CASES)
def test_forcing_term_by_term(n, side, h0):
    # each physical contribution to b separately, so that a large K u cannot hide an
    # error in a small θ̇² or gravity term
    rng = np.random.default_rng(7 + 1000 * n + 10 * (side + 1) + int(h0 > 0))
    st = random_structure(rng, n, h0)
    zero = np.zeros((n, n))
    x = random_state(rng, n, side, 0.2)
    still = dict(x, udot=np.zeros(n), thetadot=0.0, ag=0.0)
    groups = {
        "velocity (θ̇², θ̇u̇)": (_variant(st, g=0.0, K=zero, C=zero), dict(x, ag=0.0)),
        "gravity": (_variant(st, K=zero, C=zero), still),
        "ground acceleration": (_variant(st, g=0.0, K=zero, C=zero), dict(still, ag=x["ag"])),
        "stiffness": (_variant(st, g=0.0, C=zero), still),
        "damping": (_variant(st, g=0.0, K=zero), dict(still, udot=x["udot"])),
    }
    for name, (s, state) in groups.items():
        _, b = rocking_system(s, side, **state)
        _, b_ref = rocking_system_symbolic(s, side, **state)
        assert np.abs(b_ref).max() > 0.0, name
        assert_close(b, b_ref)


# ---- impact force -------------------------------------------------------------------------


@pytest.mark.parametrize("n, side", [(0, 1), (1, 1), (2, -1), (3, 1), (3, -1)])
def test_impact_force_is_the_generalised_force_of_a_force_at_P_prime(n, side):
    # Assumption (paper 001, Section 2.4 and Eq 5): F_i acts on the rigid foundation at
    # the impending pivot P' (the opposite corner, 2B from P), perpendicular to the
    # foundation beam, with the sign for which Eq 5 carries +F_i (2B) on its left-hand
    # side: the force vector is −s F_i n̂, n̂ = R(θ)(0, 1). Its virtual work on δr_P'
    # (P' is on node 0, which does not deform) gives Q_u = 0 and Q_θ = −2 B F_i.
    rng = np.random.default_rng(40 + n)
    st = random_structure(rng, n, 0.1)
    x = random_state(rng, n, side)
    F = rng.uniform(1e2, 1e4)
    _, b0 = rocking_system(st, side, **x)
    _, b1 = rocking_system(st, side, **x, F_i=F)
    _, r0 = rocking_system_symbolic(st, side, **x)
    _, r1 = rocking_system_symbolic(st, side, **x, F_i=F)
    Q = np.zeros(n + 1)
    Q[-1] = -2.0 * st.B * F  # closed form: lever arm 2B about P
    np.testing.assert_allclose(r1 - r0, Q, rtol=1e-12, atol=1e-9 * F)
    np.testing.assert_allclose(b1 - b0, Q, rtol=1e-12, atol=1e-9 * F)


@pytest.mark.parametrize("side", [1, -1])
def test_a_contact_force_pushing_P_prime_off_the_ground_is_minus_side_F_i(side):
    # Physics check of the sign convention: the ground's reaction on P' pushes along +n̂,
    # i.e. F_i = −s |F| in Eq 5's convention; approaching impact (s θ̇ < 0) its power
    # Q_θ θ̇ is negative — it dissipates. (With paper 001 Eq 14's F_i = ±|…|, upper sign
    # for the right pivot, the force would instead pull P' towards the ground.)
    d = derive_rocking(0, side)
    p = d.params
    vals = {
        p["B"]: 0.25,
        p["m0"]: 10.0,
        p["h0"]: 0.5,
        p["J0"]: 1.0,
        p["g"]: 0.0,
        p["ag"]: 0.0,
        d.q[0]: side * 0.01,
        d.qdot[0]: -side * 0.8,
    }
    mag = 300.0
    Q_theta = float(d.forcing[0].subs(vals).subs(p["F_i"], -side * mag))
    assert Q_theta == pytest.approx(side * 2 * 0.25 * mag, rel=1e-14)  # closed form: 2sB|F|
    assert Q_theta * (-side * 0.8) < 0.0


# ---- rigid block: N = 0 against Housner ---------------------------------------------------


@pytest.mark.parametrize("side", [1, -1])
def test_rigid_block_is_housner(side):
    # paper 004, Eq 1 (θ > 0): I_A θ̈ = −m g R sin(α − θ) − m ü_g R cos(α − θ);
    # Eq 2 (θ < 0): I_A θ̈ = +m g R sin(α + θ) − m ü_g R cos(α + θ);
    # I_A = 4/3 m R², R = ½√(b² + h²), α = atan(b/h) (DESIGN.md: not atan(h/b)).
    rng = np.random.default_rng(4 + side)
    for _ in range(10):
        bw, h, mass = rng.uniform(0.05, 0.5), rng.uniform(0.2, 2.0), rng.uniform(0.5, 50.0)
        st = Structure(
            name="block",
            H=np.zeros(0),
            m=np.zeros(0),
            m0=mass,
            J0=mass * (bw**2 + h**2) / 12.0,
            B=bw / 2,
            g=9.81,
            K=np.zeros((0, 0)),
            C=np.zeros((0, 0)),
            h0=h / 2,
        )
        R, alpha = 0.5 * np.hypot(bw, h), np.arctan(bw / h)
        theta, thetadot, ag = side * rng.uniform(1e-3, 1.2), rng.normal(), rng.normal(0, 5)
        I_A = 4.0 / 3.0 * mass * R**2
        a = alpha - side * theta
        housner = (-side * mass * 9.81 * R * np.sin(a) - mass * ag * R * np.cos(a)) / I_A
        for f in (rocking_system, rocking_system_symbolic):
            A, b = f(st, side, np.zeros(0), theta, np.zeros(0), thetadot, ag)
            assert A.shape == (1, 1) and b.shape == (1,)
            assert b[0] / A[0, 0] == pytest.approx(housner, rel=RTOL, abs=RTOL * abs(9.81 / R))
        A, b = rocking_system(st, side, np.zeros(0), theta, np.zeros(0), thetadot, ag)
        A_ref, b_ref = rocking_system_symbolic(
            st, side, np.zeros(0), theta, np.zeros(0), thetadot, ag
        )
        assert_close(A, A_ref)
        assert_close(b, b_ref)


# ---- the derivation itself ----------------------------------------------------------------


@pytest.mark.parametrize("n", [0, 1, 2, 3])
def test_symbolic_system_depends_on_the_ground_only_through_its_acceleration(n):
    # x_g(t) is prescribed: after Lagrange's equations only ẍ_g = ü_g may remain
    d = derive_rocking(n, 1)
    names = {s.name for s in d.forcing.free_symbols | d.mass_matrix.free_symbols}
    assert "ag" in names and not any(nm.startswith("x_g") for nm in names)
    # and the mass matrix is free of velocities, ground motion and stiffness
    bad = set(d.qdot) | {d.params["ag"], d.params["g"], d.params["F_i"]}
    assert not (d.mass_matrix.free_symbols & bad)


def test_bad_side_or_n_is_an_input_error():
    from multimass import InputError

    with pytest.raises(InputError, match="`side`"):
        derive_rocking(1, 0)
    with pytest.raises(InputError, match="`n`"):
        derive_rocking(-1, 1)
