"""Foss state-space eigen-solution (paper 001, Eqs 24–25) against closed forms and python-control."""

import control
import numpy as np
import pytest

import multimass
from multimass.modal import (
    LinearSystem,
    foss,
    frequency_and_damping,
    full_contact,
    rocking,
)


def _system(M, C, K, phase="full_contact"):
    n = M.shape[0]
    return LinearSystem(
        phase, M, C, K, r=np.zeros(n), f0=np.zeros(n), dofs=tuple(f"q{i}" for i in range(n))
    )


def test_sdof_eigenvalues_in_closed_form():
    m, k, zeta = 3.0, 1200.0, 0.07
    w = np.sqrt(k / m)
    sys = _system(np.array([[m]]), np.array([[2 * zeta * w * m]]), np.array([[k]]))
    lam = foss(sys).eigenvalues
    expected = -zeta * w + 1j * w * np.sqrt(1 - zeta**2)  # textbook damped SDOF
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
    np.testing.assert_allclose(z[:2], [0.005, 0.015], rtol=1e-9)  # paper 001, Table 1, S1


def test_eigenvectors_satisfy_the_quadratic_eigenproblem():
    sys = rocking(multimass.column("S1"))
    ss = foss(sys)
    for lam, v in zip(ss.eigenvalues, ss.eigenvectors.T):
        residual = (lam**2 * sys.M + lam * sys.C + sys.K) @ v
        scale = np.linalg.norm(sys.K) * np.linalg.norm(v)
        assert np.linalg.norm(residual) <= 1e-10 * scale


# --- the uplifted (rocking-phase) system against hand derivations of paper 001, Eqs 19–21 -------
# The reference eigenvalues are roots of det(Λ² M_L + Λ C_L + K_L) = 0 with M_L, C_L, K_L
# written out from the specimen file's numbers, never taken from the code under test.


def _one_node_quartic(m, H, k, c, J, g):
    """Coefficients of det([[mΛ² + cΛ + k, mHΛ² − gm], [mHΛ² − gm, JΛ² − gmH]]), Λ⁴ first.

    Expanded by hand: (mΛ² + cΛ + k)(JΛ² − gmH) − (mHΛ² − gm)².
    """
    return [
        m * J - (m * H) ** 2,
        c * J,
        k * J + g * m * m * H,
        -g * m * H * c,
        -g * m * (H * k + g * m),
    ]


def _match(ours, ref):
    """Max relative distance from each reference root to the nearest computed eigenvalue."""
    ours, ref = np.asarray(ours, dtype=complex), np.asarray(ref, dtype=complex)
    assert ours.size == ref.size
    return max(np.min(np.abs(ours - r)) / abs(r) for r in ref)


def test_one_node_rocking_eigenvalues_match_the_hand_quartic(tmp_path):
    from multimass import modal
    from tests.conftest import column_toml

    p = column_toml(tmp_path, [1.0], [200.0], name="sdof")
    res = modal.analyse(p)
    # the file's numbers (tests/conftest.py::column_toml from S1.toml): one node at H = 1 m,
    # m = 200 kg; K = K_fp = 5e8 N/m (one node: no beam element, K_rot only holds Ω_1);
    # C = 2 ζ_1 √(k m) with ζ_1 = 0.005; J_p = m (H² + B²) + J0, B = 0.305 m, J0 = 10 kg m²
    m, H, k, g = 200.0, 1.0, 5.0e8, 9.81
    c = 2 * 0.005 * np.sqrt(k * m)
    J = m * (H**2 + 0.305**2) + 10.0
    roots = np.roots(_one_node_quartic(m, H, k, c, J, g))
    assert _match(res.rocking.eigenvalues, roots) < 1e-10
    vib = roots[roots.imag > 0][0]
    assert res.rocking.omega[0] == pytest.approx(abs(vib), rel=1e-10)  # Eq 25
    assert res.rocking.damping[0] == pytest.approx(-vib.real / abs(vib), rel=1e-10)
    real = np.sort(roots[roots.imag == 0].real)[::-1]
    np.testing.assert_allclose(res.rocking_eigenvalues, real, rtol=1e-10)


def _two_node_reference(H1, H2, m1, m2):
    """Eigenvalues of the 2-node rocking system, derived symbolically (SymPy) from the
    S1-like file's numbers: Euler–Bernoulli element (textbook 4×4) between nodes 1 and 2,
    K_fp on u_1 and K_rot on Ω_1, rotations condensed out; Rayleigh C fitted to ζ_1, ζ_2 at
    the two undamped modes; M_L, C_L, K_L of paper 001, Eqs 19–21, written in full."""
    import sympy as sp  # a dependency of the package

    R = lambda x: sp.Rational(str(x))  # noqa: E731  exact decimals
    EI, Kfp, Krot = R(200e9) * R("183.3e-8"), R(5.0e8), R(2.0e6)
    B, J0, g, z1, z2 = R(0.305), R(10), R("9.81"), R("0.005"), R("0.015")
    H1, H2, m1, m2 = R(H1), R(H2), R(m1), R(m2)
    L = H2 - H1
    ke = (
        EI
        / L**3
        * sp.Matrix(
            [
                [12, 6 * L, -12, 6 * L],
                [6 * L, 4 * L**2, -6 * L, 2 * L**2],
                [-12, -6 * L, 12, -6 * L],
                [6 * L, 2 * L**2, -6 * L, 4 * L**2],
            ]
        )
    )
    # element dofs [u1, Ω1, u2, Ω2] -> global [u1, u2, Ω1, Ω2]
    perm = [0, 2, 1, 3]
    Ks = sp.zeros(4, 4)
    for a in range(4):
        for b in range(4):
            Ks[perm[a], perm[b]] += ke[a, b]
    Ks[0, 0] += Kfp
    Ks[2, 2] += Krot
    K = Ks[:2, :2] - Ks[:2, 2:] * Ks[2:, 2:].inv() * Ks[2:, :2]
    M = sp.diag(m1, m2)
    w2 = sp.symbols("w2")
    o1, o2 = sorted(sp.solve((K - w2 * M).det(), w2), key=lambda e: float(e))
    w1, wb = sp.sqrt(sp.N(o1, 60)), sp.sqrt(sp.N(o2, 60))  # 60 digits from here on
    a0, a1 = sp.symbols("a0 a1")
    sol = sp.solve([a0 / (2 * w1) + a1 * w1 / 2 - z1, a0 / (2 * wb) + a1 * wb / 2 - z2], [a0, a1])
    C = sol[a0] * M + sol[a1] * K
    Jp = m1 * (H1**2 + B**2) + m2 * (H2**2 + B**2) + J0
    ML = sp.Matrix([[m1, 0, m1 * H1], [0, m2, m2 * H2], [m1 * H1, m2 * H2, Jp]])
    CL = sp.Matrix([[C[0, 0], C[0, 1], 0], [C[1, 0], C[1, 1], 0], [0, 0, 0]])
    KL = sp.Matrix(
        [
            [K[0, 0], K[0, 1], -g * m1],
            [K[1, 0], K[1, 1], -g * m2],
            [-g * m1, -g * m2, -g * (m1 * H1 + m2 * H2)],
        ]
    )
    lam = sp.symbols("lam")
    poly = sp.Poly(sp.expand((lam**2 * ML + lam * CL + KL).det()), lam)
    coeffs = [sp.N(c, 60) for c in poly.all_coeffs()]
    return np.array([complex(r) for r in sp.Poly(coeffs, lam).nroots(n=30, maxsteps=200)])


def test_two_node_rocking_eigenvalues_match_a_symbolic_derivation(tmp_path):
    from multimass import modal
    from tests.conftest import column_toml

    heights, masses = [0.5, 1.5], [100.0, 50.0]
    p = column_toml(tmp_path, heights, masses, name="two")
    ref = _two_node_reference(*heights, *masses)
    res = modal.analyse(p)
    assert _match(res.rocking.eigenvalues, ref) < 1e-10
    vib = ref[ref.imag > 0]
    vib = vib[np.argsort(np.abs(vib))]
    np.testing.assert_allclose(res.rocking.vibration_eigenvalues, vib, rtol=1e-10)
    real = np.sort(ref[ref.imag == 0].real)[::-1]
    np.testing.assert_allclose(res.rocking_eigenvalues, real, rtol=1e-10)
