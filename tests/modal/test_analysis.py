"""Paper 001 Section 4.2 findings, reproduced from the literal Table 1 inputs."""

import numpy as np
import pytest

import multimass
from multimass import modal
from multimass.modal import ModalError
from multimass.modal.analysis import nodal_points
from tests.conftest import column_toml


@pytest.fixture(scope="module")
def s1():
    return modal.analyse("S1")


def _within_pct(value, ref, pct):
    return abs(value - ref) <= pct / 100.0 * ref


def test_s1_full_contact_within_3_percent_of_paper(s1):
    # paper 001, Section 4.2: 7.6 and 41.4 Hz
    assert _within_pct(s1.full_contact.freq_hz[0], 7.6, 3)
    assert _within_pct(s1.full_contact.freq_hz[1], 41.4, 3)


def test_s1_uplifted_within_3_percent_of_paper(s1):
    # paper 001, Section 4.2: 20.7 and 46.9 Hz
    assert _within_pct(s1.rocking.freq_hz[0], 20.7, 3)
    assert _within_pct(s1.rocking.freq_hz[1], 46.9, 3)


def test_s1_rocking_pair_is_plus_minus_p_l(s1):
    lam = s1.rocking_eigenvalues
    assert lam[0] > 0 > lam[1]
    p_l = s1.structure.p_l
    assert _within_pct(lam[0], p_l, 0.5) and _within_pct(-lam[1], p_l, 0.5)
    assert _within_pct(lam[0], 2.51, 0.5)  # paper 001, Table 1: p_l = 2.51 rad/s


@pytest.mark.parametrize("name", ["S1", "S2", "S3"])
def test_rocking_pair_tracks_p_l_for_every_specimen(name):
    res = modal.analyse(name)
    assert _within_pct(res.rocking_eigenvalues[0], res.structure.p_l, 0.5)


def test_s1_uplifted_mode_1_is_about_three_times_full_contact(s1):
    # paper 001, Section 4.2: "a threefold increase in frequency ... from 7.6 Hz to 20.7 Hz"
    ratio = s1.rocking.freq_hz[0] / s1.full_contact.freq_hz[0]
    assert 2.5 <= ratio <= 3.5


@pytest.mark.parametrize("name", ["S1", "S2", "S3"])
def test_mode_3_barely_changes(name):
    # paper 001, Section 4.2: "the 3rd mode eigenvector remains nearly identical"
    res = modal.analyse(name)
    assert _within_pct(res.rocking.freq_hz[2], res.full_contact.freq_hz[2], 1.0)
    assert res.mac_full_vs_compound()[2, 2] > 0.99


def test_s1_uplifted_damping_increases_for_modes_1_and_2(s1):
    # paper 001, Section 4.2: "A similar increase is observed for the modal damping"
    assert np.all(s1.rocking.damping[:2] > s1.full_contact.damping[:2])


def test_s1_compound_mode_1_changes_sign_near_1_3_m(s1):
    # paper 001, Section 4.2: "A nodal point is now observed at H ≈ 1.3 m"
    points = nodal_points(s1.heights, s1.compound_shapes()[:, 0])
    assert points.size == 1
    assert 1.2 <= points[0] <= 1.4
    # while the elastic part alone keeps one sign, like the full-contact shape
    assert nodal_points(s1.heights, s1.elastic_shapes()[:, 0]).size == 0
    assert s1.mac_full_vs_elastic()[0, 0] > 0.99


def test_rocking_mode_is_nearly_rigid(s1):
    # paper 001, Section 4.2: "the rocking mode eigenvector represents a rigid body action"
    shape = s1.rocking_shape
    assert shape[-1] == 1.0
    assert np.max(np.abs(shape[:-1])) < 1e-3 * s1.structure.H[-1]


def test_normalisation(s1):
    # modal.shapes, rule 1: unit Euclidean norm of the elastic part over the shape nodes
    for vt in (s1.full_contact_shapes(), s1.elastic_shapes()):
        np.testing.assert_allclose(np.linalg.norm(vt, axis=0), 1.0, rtol=1e-12)
    vt_c = s1.elastic_shapes(complex_=True)
    np.testing.assert_allclose(np.linalg.norm(vt_c, axis=0), 1.0, rtol=1e-12)
    assert s1.compound_shapes(complex_=True).dtype.kind == "c"


def test_complex_and_real_shapes_are_close(s1):
    # paper 001, Section 4.2: undamped eigenvectors "do not differ significantly" from complex ones
    m = modal.mac(s1.compound_shapes(True)[:, :3], s1.compound_shapes(False)[:, :3])
    assert np.all(np.diag(m) > 0.99)


def test_one_node_structure_has_one_vibration_mode(tmp_path):
    p = column_toml(tmp_path, [1.0], [200.0], name="sdof")
    res = modal.analyse(multimass.column(p))
    assert res.full_contact.omega.size == 1 and res.rocking.omega.size == 1
    assert res.shape_nodes == (1,)
    # hand algebra, 2-DOF rocking system: det(K_L − λ M_L) = 0 with
    # M_L = [[m, mH], [mH, J]], K_L = [[k, −gm], [−gm, −gmH]]
    m, H, k, g, J = 200.0, 1.0, 5e8, 9.81, 200.0 * (1.0 + 0.305**2) + 10.0
    a = m * J - (m * H) ** 2
    b = -(k * J) + g * m * H * m - 2 * g * m * m * H
    c = -k * g * m * H - (g * m) ** 2
    lam = np.sort(np.roots([a, b, c]).real)
    assert res.rocking.undamped_omega[0] == pytest.approx(np.sqrt(lam[1]), rel=1e-10)
    assert res.rocking_eigenvalues[0] == pytest.approx(np.sqrt(-lam[0]), rel=1e-3)


def test_bad_shape_nodes():
    with pytest.raises(ModalError, match="shape_nodes"):
        modal.analyse("S1", shape_nodes=[0, 2])


def test_mac_measured_phase_is_checked(s1):
    with pytest.raises(ModalError, match="`phase` = 'uplifted'"):
        s1.mac_measured(s1.compound_shapes(), phase="uplifted")


# --- heavy damping: an uplifted mode becomes overdamped ------------------------------------------


@pytest.fixture(scope="module")
def zeta09(tmp_path_factory):
    p = column_toml(
        tmp_path_factory.mktemp("z09"),
        [0.06, 0.49, 0.93, 1.43, 1.93],
        [77.3, 6.2, 88.2, 8.2, 46.2],
        name="z09",
        **{"zeta_1 = 0.005": "zeta_1 = 0.9", "zeta_2 = 0.015": "zeta_2 = 0.9"},
    )
    return modal.analyse(p)


def test_heavy_damping_is_classified_not_an_error(zeta09):
    s = zeta09.structure
    fc, rk = zeta09.full_contact.to_pandas(), zeta09.rocking.to_pandas()
    # full contact is Rayleigh: ζ_j = a0/(2ω_j) + a1 ω_j/2 with ζ_1 = ζ_2 = 0.9 (the file)
    a0, a1 = s.rayleigh
    w = zeta09.full_contact.undamped_omega
    np.testing.assert_allclose(fc["damping"], a0 / (2 * w) + a1 * w / 2, rtol=1e-9)
    assert list(fc["kind"]) == ["underdamped"] * 2 + ["overdamped"] * 3
    # uplift adds coupling and stiffness: the first mode is overdamped while rocking
    assert rk["kind"][0] == "overdamped" and rk["damping"][0] > 1
    assert list(rk["mode"]) == [1, 2, 3, 4, 5]
    lam = zeta09.rocking_eigenvalues
    assert lam[0] > 0 > lam[1] and lam[0] == pytest.approx(s.p_l, rel=1e-3)  # Eq 6
    # damping this heavy mixes uplifted modes 1 and 2: flagged, not hidden
    assert np.all(rk["participation"][:2] < 0.9) and np.all(rk["participation"][2:] > 0.98)
    from multimass.modal.report import markdown, summary

    md = markdown(zeta09, summary(zeta09))
    assert "**Mixed modes:**" in md and "uplifted mode 1 (45 %)" in md
    # every overdamped couple solves the quadratic eigenproblem of Eqs 19–21
    from multimass.modal import rocking

    sys = rocking(s)
    for l in zeta09.rocking.overdamped_eigenvalues.ravel():
        Q = l**2 * sys.M + l * sys.C + sys.K
        assert np.linalg.svd(Q, compute_uv=False)[-1] <= 1e-12 * np.linalg.norm(Q)
