"""Overdamped modes: classified, paired and reported, against closed forms (modal.pairing)."""

import numpy as np
import pytest
import scipy.linalg as sla

import multimass
from multimass import modal
from multimass.modal import LinearSystem
from multimass.modal.analysis import phase_modes
from tests.conftest import column_toml

# A fixed-free chain of N equal masses m and springs k: closed-form undamped modes
# (e.g. Meirovitch, Fundamentals of Vibrations, 2001, chain of N masses):
#   ω_j = 2 √(k/m) sin((2j − 1) π / (2(2N + 1))),  φ_j(i) = sin((2j − 1) π i / (2N + 1)).
N_CHAIN, K_SPRING, MASS = 8, 1.0e4, 1.0


def _chain_omega(j):
    return 2.0 * np.sqrt(K_SPRING / MASS) * np.sin((2 * j - 1) * np.pi / (2 * (2 * N_CHAIN + 1)))


def _chain_shape(j):
    i = np.arange(1, N_CHAIN + 1)
    return np.sin((2 * j - 1) * np.pi * i / (2 * N_CHAIN + 1))


def _rayleigh_for(zeta_low, zeta_high):
    """(a0, a1) with ζ(ω_1) = zeta_low and ζ(ω_N) = zeta_high; ζ(ω) = a0/(2ω) + a1 ω/2."""
    w1, wn = _chain_omega(1), _chain_omega(N_CHAIN)
    A = np.array([[1 / (2 * w1), w1 / 2], [1 / (2 * wn), wn / 2]])
    return np.linalg.solve(A, [zeta_low, zeta_high])


@pytest.fixture(scope="module")
def chain():
    """Rayleigh-damped chain whose lowest and highest modes are overdamped, the middle not."""
    n = N_CHAIN
    K = K_SPRING * (2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))
    K[-1, -1] = K_SPRING  # free end
    M = MASS * np.eye(n)
    a0, a1 = _rayleigh_for(1.1, 1.6)  # modes 1 and 4-8 overdamped
    sys = LinearSystem(
        "full_contact",
        M,
        a0 * M + a1 * K,
        K,
        r=np.zeros(n),
        f0=np.zeros(n),
        dofs=tuple(f"u{i + 1}" for i in range(n)),
    )
    modes, _ = phase_modes(sys, np.arange(n))
    j = np.arange(1, n + 1)
    w = _chain_omega(j)
    zeta = a0 / (2 * w) + a1 * w / 2  # Rayleigh, per mode (classical damping)
    return modes, w, zeta


def test_the_chain_case_discriminates(chain):
    # the test system is built so that pairing real eigenvalues by sorting would be wrong:
    # several overdamped modes at both ends, and their roots interleave
    _, w, zeta = chain
    over = zeta > 1
    assert over.sum() >= 4 and over[0] and over[-1] and not over.all()
    slow = -zeta[over] * w[over] + w[over] * np.sqrt(zeta[over] ** 2 - 1)
    fast = -zeta[over] * w[over] - w[over] * np.sqrt(zeta[over] ** 2 - 1)
    roots = np.sort(np.r_[slow, fast])
    adjacent = {tuple(sorted(roots[i : i + 2])) for i in range(0, roots.size, 2)}
    truth = {tuple(sorted(p)) for p in zip(fast, slow)}
    assert adjacent != truth


def test_overdamped_modes_are_the_closed_form_ones(chain):
    modes, w, zeta = chain
    expected = np.flatnonzero(zeta > 1) + 1
    np.testing.assert_array_equal(modes.overdamped_mode, expected)
    k = expected - 1
    root = w[k] * np.sqrt(zeta[k] ** 2 - 1)  # λ1,2 = −ζω ∓ ω√(ζ² − 1)
    np.testing.assert_allclose(
        modes.overdamped_eigenvalues[:, 0], -zeta[k] * w[k] - root, rtol=1e-10
    )
    np.testing.assert_allclose(
        modes.overdamped_eigenvalues[:, 1], -zeta[k] * w[k] + root, rtol=1e-10
    )
    np.testing.assert_allclose(modes.overdamped_omega, w[k], rtol=1e-10)
    np.testing.assert_allclose(modes.overdamped_damping, zeta[k], rtol=1e-10)
    assert np.all(modes.overdamped_damping >= 1.0)


def test_underdamped_modes_are_the_closed_form_ones(chain):
    modes, w, zeta = chain
    k = modes.mode - 1
    np.testing.assert_array_equal(np.sort(modes.mode), np.flatnonzero(zeta < 1) + 1)
    np.testing.assert_allclose(modes.omega, w[k], rtol=1e-10)
    np.testing.assert_allclose(modes.damping, zeta[k], rtol=1e-10)
    np.testing.assert_allclose(modes.undamped_omega, w, rtol=1e-10)


def test_overdamped_shapes_are_the_undamped_shapes(chain):
    # classical damping: both eigenvectors of an overdamped couple are the undamped shape
    modes, _, _ = chain
    for col, j in enumerate(modes.overdamped_mode):
        exact = _chain_shape(j)
        assert modal.mac(modes.overdamped_shapes[:, col], exact)[0, 0] == pytest.approx(
            1, abs=1e-10
        )
        assert modal.mac(modes.real_shapes[:, j - 1], exact)[0, 0] == pytest.approx(1, abs=1e-10)


def test_classical_damping_mixes_no_modes(chain):
    # each eigenvector is exactly one undamped mode: participation 1 (modal.pairing, rule 2)
    modes, _, _ = chain
    np.testing.assert_allclose(modes.participation, 1.0, atol=1e-10)
    np.testing.assert_allclose(modes.overdamped_participation, 1.0, atol=1e-10)


def test_every_eigenvalue_is_used_once(chain):
    modes, _, _ = chain
    used = np.r_[
        modes.vibration_eigenvalues,
        modes.vibration_eigenvalues.conj(),
        modes.overdamped_eigenvalues.ravel(),
    ]
    np.testing.assert_allclose(
        np.sort_complex(used), np.sort_complex(modes.eigenvalues), rtol=1e-12
    )
    table = modes.to_pandas()
    assert list(table["mode"]) == list(range(1, N_CHAIN + 1))


@pytest.mark.parametrize("c", [200.0, 81.0, 5000.0])  # ζ = 2.5, 1.0125, 62.5
def test_pair_formula_on_a_textbook_overdamped_oscillator(c):
    # m ẍ + c ẋ + k x = 0: ω = √(k/m), ζ = c / (2√(km)); its roots from numpy.roots
    m, k = 2.0, 800.0
    roots = np.roots([m, c, k])
    assert np.all(np.isreal(roots))
    w, z = modal.pair_frequency_and_damping(roots[0].real, roots[1].real)
    assert w == pytest.approx(np.sqrt(k / m), rel=1e-12)
    assert z == pytest.approx(c / (2 * np.sqrt(k * m)), rel=1e-12)


# --- a column meshed finely: Rayleigh damping overdamps its high modes --------------------------


@pytest.fixture(scope="module")
def col40(tmp_path_factory):
    heights = [round(0.05 * (i + 1), 4) for i in range(40)]
    path = column_toml(tmp_path_factory.mktemp("col40"), heights, [20.0] * 40, name="col40")
    return modal.analyse(multimass.column(path))


def test_40_node_full_contact_is_rayleigh_in_every_mode(col40):
    # full contact is classically damped: mode j has ω_j of the undamped problem (solved here
    # by the symmetric eigensolver, independently of Eq 24) and ζ_j = a0/(2ω_j) + a1 ω_j/2
    s = col40.structure
    w = np.sqrt(sla.eigh(s.K, s.M, eigvals_only=True))
    a0, a1 = s.rayleigh
    zeta = a0 / (2 * w) + a1 * w / 2
    table = col40.full_contact.to_pandas()
    assert (table["kind"] == "overdamped").sum() == (zeta > 1).sum() >= 20
    np.testing.assert_array_equal(table["kind"] == "overdamped", zeta > 1)
    np.testing.assert_allclose(2 * np.pi * table["freq_hz"], w, rtol=1e-8)
    np.testing.assert_allclose(table["damping"], zeta, rtol=1e-8)


def test_40_node_rocking_phase_keeps_its_rocking_pair_and_lists_every_mode(col40):
    rk = col40.rocking
    lam = col40.rocking_eigenvalues
    assert lam[0] > 0 > lam[1]
    assert lam[0] == pytest.approx(col40.structure.p_l, rel=1e-3)  # paper 001, Eq 6
    assert list(rk.to_pandas()["mode"]) == list(range(1, 41))
    assert rk.overdamped_mode.size >= 20 and np.all(rk.overdamped_damping >= 1)
    assert np.all(rk.overdamped_eigenvalues < 0)
    used = np.r_[
        rk.vibration_eigenvalues,
        rk.vibration_eigenvalues.conj(),
        rk.overdamped_eigenvalues.ravel(),
        lam,
    ]
    np.testing.assert_allclose(np.sort_complex(used), np.sort_complex(rk.eigenvalues), rtol=1e-12)


def test_40_node_high_modes_barely_feel_rocking(col40):
    # invariant: the high modes' rocking components are small, so uplift changes their ω and ζ
    # very little (paper 001, Section 4.2, "the 3rd mode ... remains nearly identical")
    fc, rk = col40.full_contact.to_pandas(), col40.rocking.to_pandas()
    high = fc["mode"] >= 14
    np.testing.assert_array_equal(fc["kind"][high], rk["kind"][high])
    np.testing.assert_allclose(rk["freq_hz"][high], fc["freq_hz"][high], rtol=1e-3)
    np.testing.assert_allclose(rk["damping"][high], fc["damping"][high], rtol=1e-3)


def test_one_node_column_overdamped_while_rocking(tmp_path):
    # ζ_1 = 0.5 in full contact; uplift stiffens the mode ~2.8x, the same damper then overdamps it.
    # Reference: the quartic det(Λ² M_L + Λ C_L + K_L) = 0 written by hand (paper 001, Eqs 19–21)
    p = column_toml(tmp_path, [1.0], [200.0], name="sdof", **{"zeta_1 = 0.005": "zeta_1 = 0.5"})
    res = modal.analyse(p)
    m, H, k, g, B, J0 = 200.0, 1.0, 5.0e8, 9.81, 0.305, 10.0  # the file's numbers
    c = 2 * 0.5 * np.sqrt(k * m)  # ζ_1 = 0.5 at ω_1 = √(k/m)
    J = m * (H**2 + B**2) + J0
    roots = np.roots(
        [
            m * J - (m * H) ** 2,
            c * J,
            k * J + g * m * m * H,
            -g * m * H * c,
            -g * m * (H * k + g * m),
        ]
    ).real
    pos = roots[roots > 0]
    assert pos.size == 1
    neg = np.sort(roots[roots < 0])
    partner = neg[np.argmin(np.abs(neg + pos[0]))]  # the rocking couple ±≈p_l
    vib = np.sort(neg[neg != partner])
    np.testing.assert_allclose(res.rocking_eigenvalues, [pos[0], partner], rtol=1e-10)
    assert res.rocking.omega.size == 0 and res.rocking.overdamped_mode.tolist() == [1]
    np.testing.assert_allclose(res.rocking.overdamped_eigenvalues[0], vib, rtol=1e-10)
    zeta = -vib.sum() / (2 * np.sqrt(vib.prod()))
    assert res.rocking.overdamped_damping[0] == pytest.approx(zeta, rel=1e-10)
    assert res.full_contact.damping[0] == pytest.approx(0.5, rel=1e-12)
