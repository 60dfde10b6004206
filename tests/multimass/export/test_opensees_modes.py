"""Exported OpenSees models vs `multimass.modal`: eigenvalues in full contact and uplifted.

The reference is the toolkit's own linear systems (paper 001 Eq 3 and Eqs 19-20,
`multimass.modal`): the OpenSees models keep the rotations that multimass condenses
out and carry the uplifted gravity terms as springs, so agreement to 1e-6 checks both
the condensation and the representation of the gravity terms.
"""

import numpy as np
import pytest
import scipy.linalg as sla

import multimass
from multimass import modal
from multimass.export import opensees
from tests.conftest import column_toml

from .conftest import fresh, load_script

EIGEN_RTOL = 1e-6  # the agreement promised: relative, every mode


def _columns(tmp_path):
    eight = column_toml(
        tmp_path,
        [0.06, 0.3, 0.55, 0.8, 1.05, 1.3, 1.6, 1.93],
        [70.0, 6.0, 30.0, 8.0, 60.0, 8.0, 6.0, 40.0],
        name="C8",
    )
    return ["S1", "S2", "S3", eight]


def _opensees_eigenvalues(ops, tmp_path, specimen, phase):
    path = tmp_path / f"{phase}.py"
    opensees(specimen, phase, out=path)
    return np.array(fresh(ops, load_script(path)).eigenvalues(ops))


def test_eigenvalues_agree_with_modal(ops, tmp_path):
    for specimen in _columns(tmp_path):
        s = multimass.column(specimen)
        res = modal.analyse(s)
        # full contact: omega^2 of modes 1..N (modal.analyse, undamped)
        got = _opensees_eigenvalues(ops, tmp_path, specimen, "full-contact")
        want = res.full_contact.undamped_omega**2
        np.testing.assert_allclose(got, want, rtol=EIGEN_RTOL, err_msg=f"{s.name} full contact")
        # uplifted: the rocking mode (negative, from the linearised Eqs 19-20) and modes 1..N
        got = _opensees_eigenvalues(ops, tmp_path, specimen, "uplifted")
        system = modal.rocking(s)
        rocking = sla.eigh(system.K, system.M, eigvals_only=True)[0]
        want = np.concatenate([[rocking], res.rocking.undamped_omega**2])
        np.testing.assert_allclose(got, want, rtol=EIGEN_RTOL, err_msg=f"{s.name} uplifted")
        assert got[0] < 0 < got[1]


def test_uplifted_rocking_eigenvalue_near_p_l(ops, tmp_path):
    """An independent bound: a stiff column rocks almost rigidly, λ_rock → -p_l²
    (paper 001, Eq 6); with E_s and K_rot x 1000 the OpenSees eigenvalue is within 0.1 % of it."""
    stiff = column_toml(
        tmp_path,
        [0.06, 0.49, 0.93, 1.43, 1.93],
        [77.3, 6.2, 88.2, 8.2, 46.2],
        name="stiff",
        **{"200e9": "2e14", "2.0e6": "2.0e9"},
    )
    got = _opensees_eigenvalues(ops, tmp_path, stiff, "uplifted")[0]
    p_l = multimass.column(stiff).p_l
    assert got == pytest.approx(-(p_l**2), rel=1e-3)


def test_two_models_share_one_domain(ops, tmp_path):
    """`build(ops)` drops the model into a larger one: S1 and S2 built side by side in one
    domain (S2's tags offset) have the union of their eigenvalues, each within 1e-6."""
    models = []
    for name, offset in (("S1", 0), ("S2", 10000)):
        path = tmp_path / f"{name}.py"
        opensees(name, "uplifted", out=path, offset=offset)
        models.append(load_script(path))
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for module in models:
        module.build(ops)
    models[0].analysis(ops)
    got = np.sort(ops.eigen("-fullGenLapack", 12))
    want = []
    for name in ("S1", "S2"):
        system = modal.rocking(multimass.column(name))
        want.append(sla.eigh(system.K, system.M, eigvals_only=True))
    np.testing.assert_allclose(got, np.sort(np.concatenate(want)), rtol=EIGEN_RTOL)
