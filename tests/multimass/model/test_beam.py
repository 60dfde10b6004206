"""Column stiffness and static condensation (paper 001, Eqs 1–2)."""

import numpy as np
import pytest

from multimass.model.beam import beam_element_stiffness, column_stiffness, condense


def cantilever_flexibility(H, EI, K_fp, K_rot):
    """Flexibility of a cantilever on base springs, from beam theory (independent of Eq 2).

    Unit load at node j: the horizontal spring translates every node by 1/K_fp;
    the base moment (H_j - H_1) rotates the rotational spring, giving a rigid
    rotation; the beam clamped at node 1 deflects a²(3b − a)/(6EI) at a ≤ b.
    """
    x = np.asarray(H) - H[0]
    F = np.empty((x.size, x.size))
    for i, a in enumerate(x):
        for j, b in enumerate(x):
            lo, hi = min(a, b), max(a, b)
            F[i, j] = 1.0 / K_fp + a * b / K_rot + lo**2 * (3.0 * hi - lo) / (6.0 * EI)
    return F


@pytest.mark.parametrize(
    "H",
    [
        [0.06, 0.49, 0.93, 1.43, 1.93],  # paper 001, Table 1, S1
        [0.5, 1.0],
        [0.1, 0.7, 0.8, 2.5],
    ],
)
def test_condensed_stiffness_inverts_the_flexibility_matrix(H):
    EI, K_fp, K_rot = 200e9 * 183.3e-8, 5e8, 2e6  # paper 001, Table 1 footnote
    K = condense(column_stiffness(H, EI, K_fp, K_rot))
    F = cantilever_flexibility(H, EI, K_fp, K_rot)
    np.testing.assert_allclose(K @ F, np.eye(len(H)), atol=1e-9)


def test_one_node_is_the_horizontal_spring():
    # hand algebra: with one node the rotation is uncoupled, K = K_fp
    K = condense(column_stiffness([0.3], 1.0, 7.0e5, 3.0e4))
    assert K.shape == (1, 1)
    assert K[0, 0] == pytest.approx(7.0e5, rel=1e-14)


def test_two_nodes_by_hand():
    # hand algebra: flexibility of node 2 is 1/K_fp + L²/K_rot + L³/(3EI), node 1 1/K_fp
    EI, K_fp, K_rot, L = 3.0e5, 4.0e6, 2.0e5, 0.8
    F = np.array([[1 / K_fp, 1 / K_fp], [1 / K_fp, 1 / K_fp + L**2 / K_rot + L**3 / (3 * EI)]])
    K = condense(column_stiffness([0.2, 0.2 + L], EI, K_fp, K_rot))
    np.testing.assert_allclose(K, np.linalg.inv(F), rtol=1e-11)


def test_element_stiffness_is_symmetric_with_two_rigid_body_modes():
    k = beam_element_stiffness(2.0, 0.7)
    np.testing.assert_allclose(k, k.T)
    translation = np.array([1.0, 0.0, 1.0, 0.0])
    rotation = np.array([0.0, 1.0, 0.7, 1.0])  # small rigid rotation about end a
    np.testing.assert_allclose(k @ translation, 0.0, atol=1e-12)
    np.testing.assert_allclose(k @ rotation, 0.0, atol=1e-12)


def test_condensed_stiffness_is_symmetric_positive_definite():
    K = condense(column_stiffness([0.06, 0.49, 0.93, 1.43, 1.93], 366600.0, 5e8, 2e6))
    np.testing.assert_array_equal(K, K.T)
    assert np.all(np.linalg.eigvalsh(K) > 0)
