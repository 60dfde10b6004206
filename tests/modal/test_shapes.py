"""The scale and sign rule of mode shapes (modal.shapes), by hand and on S1–S3."""

import numpy as np
import pytest

from multimass import modal
from multimass.modal.shapes import align_to_full_contact, normalise


def test_normalise_by_hand():
    # rule 1: unit norm at the shape nodes; rule 2: largest component positive
    v = np.array([[3.0], [-4.0], [0.0]])
    np.testing.assert_allclose(normalise(v, np.arange(3), 3), [[-0.6], [0.8], [0.0]], rtol=1e-15)
    # a complex eigenvector (1 + j)(3, −4): phase removed, the same real shape results
    out = normalise((1 + 1j) * v, np.arange(3), 3)
    np.testing.assert_allclose(out, [[-0.6], [0.8], [0.0]], rtol=1e-15, atol=1e-16)
    # shape nodes only: rows 0-1 scale the whole vector, the rocking row keeps the scale
    z = np.array([[3.0], [4.0], [10.0]])
    np.testing.assert_allclose(normalise(z, np.arange(2), 2), [[0.6], [0.8], [2.0]], rtol=1e-15)


def test_normalise_falls_back_to_all_nodes_when_the_shape_nodes_do_not_move():
    v = np.array([[0.0], [0.0], [5.0]])
    np.testing.assert_allclose(normalise(v, np.array([0, 1]), 3), [[0.0], [0.0], [1.0]])
    assert np.all(np.isfinite(normalise(v, np.array([0, 1]), 3)))


def test_align_by_hand():
    # v_n = (1, 0); uplifted mode: v_t = (−1, 0), v_r = 0 -> v_t opposes v_n: flipped
    h = np.array([1.0, 2.0])
    v_n = np.array([[1.0], [0.0]])
    z = np.array([[-1.0], [0.0], [0.0]])
    np.testing.assert_allclose(
        align_to_full_contact(z, np.array([0]), v_n, np.arange(2), h), [[1.0], [0.0], [0.0]]
    )
    # v_t = (0, 1) is unrelated to v_n (MAC 0) but v_c = v_t + H v_r = (−1, −1) is closer
    # (MAC 0.5) and opposes v_n: the whole mode is flipped, v_r too
    z = np.array([[0.0], [1.0], [-1.0]])
    out = align_to_full_contact(z, np.array([0]), v_n, np.arange(2), h)
    np.testing.assert_allclose(out, -z)
    # unrelated shapes (both MAC < 0.01) keep their sign
    z = np.array([[0.0], [1.0], [0.0]])
    np.testing.assert_allclose(align_to_full_contact(z, np.array([0]), v_n, np.arange(2), h), z)


@pytest.mark.parametrize("name", ["S1", "S2", "S3"])
def test_sign_convention(name):
    # modal.shapes, rule 2: a full-contact shape's largest component is positive;
    # rule 3: the uplifted shape closer to v_n (larger MAC of v_t, v_c) correlates positively
    res = modal.analyse(name)
    vn, vt, vc = res.full_contact_shapes(), res.elastic_shapes(), res.compound_shapes()
    big = vn[np.argmax(np.abs(vn), axis=0), np.arange(vn.shape[1])]
    assert np.all(big > 0)
    m_t, m_c = np.diag(res.mac_full_vs_elastic()), np.diag(res.mac_full_vs_compound())
    for j in range(vn.shape[1]):
        closer = vt[:, j] if m_t[j] >= m_c[j] else vc[:, j]
        assert max(m_t[j], m_c[j]) < 0.01 or vn[:, j] @ closer > 0, j
    # the complex (damped) uplifted shapes follow the same rule
    vt_c = res.elastic_shapes(complex_=True)
    for col, j in enumerate(res.rocking.mode - 1):
        if m_t[j] >= m_c[j] and m_t[j] > 0.5:
            assert np.real(vn[:, j] @ vt_c[:, col]) > 0


def test_s2_mode_3_is_drawn_the_same_way_up():
    # the reviewer's case: MAC(v_n3, v_t3) = 0.99 yet v_n3 was drawn mirrored against v_t3
    res = modal.analyse("S2")
    assert res.mac_full_vs_elastic()[2, 2] > 0.99
    assert res.full_contact_shapes()[:, 2] @ res.elastic_shapes()[:, 2] > 0.99
