"""Arguments of modal.analyse and friends: refused with a message naming the value and the fix."""

import numpy as np
import pytest

import multimass
from multimass import modal
from multimass.modal import ModalError


@pytest.fixture(scope="module")
def s1_structure():
    return multimass.column("S1")


@pytest.mark.parametrize(
    "nodes, fragment",
    [
        ("2,3", r"`shape_nodes` = '2,3' is a string"),
        (b"23", "is a string"),
        ([2.5], r"holds 2\.5 \(float\), not an integer"),
        ([2.0, 3.0], r"holds 2\.0 \(float\)"),
        (np.array([2.0, 3.0]), "float64"),
        ([True, 2], r"holds True \(bool\)"),
        ([np.True_, 2], "bool"),
        (["2", "3"], r"holds '2' \(str\)"),
        (2, r"\(int\) is not an ordered sequence"),
        ({2, 3}, r"\(set\) is not an ordered sequence"),
        ([], "is empty"),
        ([2, 9], r"node\(s\) \[9\] outside 1\.\.5"),
        ([3, 3], r"repeats node\(s\) \[3\]"),
    ],
)
def test_shape_nodes_are_refused_with_the_fix(s1_structure, nodes, fragment):
    with pytest.raises(ModalError, match=fragment) as err:
        modal.analyse(s1_structure, nodes)
    assert "give distinct integer node numbers in 1..5" in str(err.value)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize(
    "nodes", [(2, 3), [5, 2], np.array([2, 3, 4]), range(2, 6), [np.int64(3), 4]]
)
def test_integer_shape_nodes_are_accepted(s1_structure, nodes):
    res = modal.analyse(s1_structure, nodes)
    assert res.shape_nodes == tuple(int(i) for i in nodes)
    assert all(type(i) is int for i in res.shape_nodes)


@pytest.mark.parametrize("make", [lambda: multimass.rigid_block("B6M"), lambda: "B6M"])
def test_a_rigid_block_has_no_vibration_modes(make):
    with pytest.raises(ModalError, match=r"'B6M' is a rigid block.*kind = \"column\""):
        modal.analyse(make())


@pytest.mark.parametrize("bad", [3, None, 2.5, ["S1"]])
def test_structure_of_the_wrong_type(bad):
    with pytest.raises(ModalError, match=r"`structure` = .*give a Structure"):
        modal.analyse(bad)


def test_linearise_and_foss_refuse_wrong_types():
    with pytest.raises(ModalError, match="give a multimass Structure"):
        modal.rocking("S1")
    with pytest.raises(ModalError, match="side"):
        modal.rocking(multimass.column("S1"), side=True)
    with pytest.raises(ModalError, match="modal.LinearSystem"):
        modal.foss("S1")
    n = 2
    sys = modal.LinearSystem(
        "full_contact",
        np.diag([1.0, 0.0]),
        np.zeros((n, n)),
        np.eye(n),
        r=np.zeros(n),
        f0=np.zeros(n),
        dofs=("a", "b"),
    )
    with pytest.raises(ModalError, match="not positive definite"):
        modal.foss(sys)
    sys = modal.LinearSystem(
        "full_contact",
        np.eye(n),
        np.zeros((3, 3)),
        np.eye(n),
        r=np.zeros(n),
        f0=np.zeros(n),
        dofs=("a", "b"),
    )
    with pytest.raises(ModalError, match="one size"):
        modal.foss(sys)
