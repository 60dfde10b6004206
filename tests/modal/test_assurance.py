"""MAC properties (Ewins 2000; paper 001, Section 4.2)."""

import numpy as np
import pytest

from multimass.modal import ModalError, mac


@pytest.fixture
def shapes():
    return np.random.default_rng(7).normal(size=(6, 4))


def test_one_on_itself(shapes):
    np.testing.assert_allclose(np.diag(mac(shapes)), 1.0, rtol=1e-14)


def test_scale_invariance(shapes):
    scaled = shapes * np.array([3.0, -0.2, 1e4, -7.0])
    np.testing.assert_allclose(mac(shapes, scaled), mac(shapes), rtol=1e-12)


def test_complex_phase_invariance(shapes):
    rotated = shapes * np.exp(1j * np.array([0.3, 1.2, -2.0, 3.0]))
    np.testing.assert_allclose(mac(rotated, shapes), mac(shapes), rtol=1e-12)


def test_symmetry_and_range():
    rng = np.random.default_rng(11)
    a, b = rng.normal(size=(5, 3)), rng.normal(size=(5, 4))
    m = mac(a, b)
    assert m.shape == (3, 4)
    np.testing.assert_allclose(mac(b, a), m.T, rtol=1e-14)
    assert np.all((m >= 0) & (m <= 1))


def test_orthogonal_shapes_give_zero():
    q, _ = np.linalg.qr(np.random.default_rng(3).normal(size=(5, 5)))
    np.testing.assert_allclose(mac(q), np.eye(5), atol=1e-14)


def test_single_vectors():
    np.testing.assert_allclose(mac([1.0, 2.0, 3.0], [2.0, 4.0, 6.0]), [[1.0]], rtol=1e-14)


def test_mismatched_locations_raise():
    with pytest.raises(ModalError, match="locations"):
        mac(np.ones((4, 2)), np.ones((5, 2)))


def test_zero_shape_raises():
    with pytest.raises(ModalError, match="all-zero"):
        mac(np.zeros(3))


# --- complex shapes: MAC_jk = |φ_jᴴ ψ_k|² / ((φ_jᴴ φ_j)(ψ_kᴴ ψ_k)) needs the conjugate ---
# Components with different phases, so that φᵀψ (no conjugate) differs from φᴴψ.


def test_complex_shape_against_itself_times_a_complex_scalar_is_one():
    phi = np.array([1.0, 1.0j, 2.0 - 1.0j])
    # by hand: φᴴφ = 1 + 1 + 5 = 7, while φᵀφ = 1 − 1 + (3 − 4j) = 3 − 4j (|.| = 5)
    np.testing.assert_allclose(mac(phi, (0.3 - 2.0j) * phi), [[1.0]], rtol=1e-14)


def test_complex_shapes_with_a_hand_computed_mac():
    phi = np.array([1.0 + 1.0j, 2.0, 1.0j])
    psi = np.array([1.0, 1.0j, 1.0])
    # by hand: φᴴψ = (1 − j)·1 + 2·j + (−j)·1 = 1, so |φᴴψ|² = 1;
    # φᴴφ = 2 + 4 + 1 = 7, ψᴴψ = 3: MAC = 1/21 (without the conjugate it would be 17/21)
    np.testing.assert_allclose(mac(phi, psi), [[1.0 / 21.0]], rtol=1e-14)
    np.testing.assert_allclose(mac(psi, phi), [[1.0 / 21.0]], rtol=1e-14)


def test_complex_orthogonal_shapes_give_zero():
    # [1, j] and [j, 1]: φᴴψ = j − j = 0 (without the conjugate, φᵀψ = 2j and MAC would be 1)
    m = mac(np.array([[1.0, 1.0j], [1.0j, 1.0]]).T)
    np.testing.assert_allclose(m, np.eye(2), atol=1e-15)


@pytest.mark.parametrize(
    "bad, fragment",
    [
        (np.array(["a", "b"]), "<U1"),
        ([[1.0, 2.0], [3.0]], "ragged"),
        (np.array([True, False]), "bool"),
    ],
)
def test_non_numeric_shapes_raise(bad, fragment):
    with pytest.raises(ModalError, match=fragment):
        mac(bad)
