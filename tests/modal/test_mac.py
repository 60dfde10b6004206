"""MAC properties (Ewins 2000; paper 001, Section 4.2)."""

import numpy as np
import pytest

from modal import ModalError, mac


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
