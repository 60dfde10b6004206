"""Derived quantities of the multi-mass structure (paper 001, Section 2 and Table 1)."""

import dataclasses

import numpy as np
import pytest

import multimass
from multimass import InputError, specimens
from multimass.model.damping import rayleigh_damping
from multimass.model.structure_checks import MAX_FREQ_HZ
from multimass.specimens import SpecimenError
from tests.conftest import REPO, column_toml


@pytest.mark.parametrize(
    "name, J_p, H_cg, alpha_cg, p_l",
    [
        ("S1", 298, 0.84, 0.35, 2.51),  # paper 001, Table 1
        ("S3", 413, 1.02, 0.29, 2.35),  # paper 001, Table 1
    ],
)
def test_derived_parameters_agree_with_table_1(name, J_p, H_cg, alpha_cg, p_l):
    s = multimass.column(name)
    assert abs(s.J_p - J_p) <= 1.0
    assert abs(s.H_cg - H_cg) <= 0.01
    assert abs(s.alpha_cg - alpha_cg) <= 0.01
    assert abs(s.p_l - p_l) <= 0.01


def test_s2_published_values_disagree_with_its_own_inputs():
    # DESIGN.md: S2's H and M give J_p ≈ 495 and H_cg ≈ 1.165, not Table 1's 509 and 1.18
    s = multimass.column("S2")
    assert s.J_p == pytest.approx(495.0, abs=0.5)
    assert s.H_cg == pytest.approx(1.165, abs=0.001)
    assert abs(s.J_p - 509) > 1.0


def test_derived_quantities_by_hand():
    # paper 001, after Eq 5: J_p = R0ᵀ M R0 + m0 B² + J0; Eq 6: p_l = sqrt(1ᵀMH g / J_p)
    s = multimass.column("S1")
    H, m, B = np.array(s.H), np.array(s.m), 0.305
    J_p = sum(mi * (hi**2 + B**2) for mi, hi in zip(m, H)) + 10.0
    assert s.J_p == pytest.approx(J_p, rel=1e-14)
    assert s.m_t == pytest.approx(226.1, rel=1e-14)
    assert s.R0 == pytest.approx(np.sqrt(H**2 + B**2))
    assert s.p_l == pytest.approx(np.sqrt(9.81 * (m @ H) / J_p), rel=1e-14)
    assert s.alpha_cg == pytest.approx(np.arctan(B / ((m @ H) / 226.1)), rel=1e-14)


def test_rayleigh_damping_reproduces_zeta_at_modes_1_and_2():
    s = multimass.column("S1")
    w2, phi = np.linalg.eig(np.linalg.solve(s.M, s.K))
    order = np.argsort(w2)
    for k, zeta in zip(order[:2], (0.005, 0.015)):  # paper 001, Table 1, S1
        v = phi[:, k].real
        c = v @ s.C @ v
        m = v @ s.M @ v
        assert c / (2.0 * np.sqrt(w2[k].real) * m) == pytest.approx(zeta, rel=1e-10)


def test_rayleigh_single_dof_gives_exact_zeta():
    M, K = np.array([[2.0]]), np.array([[800.0]])
    C, (a0, a1) = rayleigh_damping(M, K, 0.03, 0.5)
    assert C[0, 0] / (2.0 * np.sqrt(800.0 * 2.0)) == pytest.approx(0.03, rel=1e-14)
    assert a0 == 0.0


def test_one_node_column_is_the_sdof_oscillator(tmp_path):
    p = column_toml(tmp_path, [1.2], [150.0], name="sdof")
    s = multimass.column(p)
    assert s.n == 1
    assert s.K[0, 0] == pytest.approx(5.0e8)  # the horizontal spring alone
    assert s.full_contact_omega[0] == pytest.approx(np.sqrt(5.0e8 / 150.0))
    assert s.J_p == pytest.approx(150.0 * (1.2**2 + 0.305**2) + 10.0)


def test_e_s_override():
    base = multimass.column("S1")
    stiff = multimass.column("S1", E_s=210e9)
    assert stiff.full_contact_omega[0] > base.full_contact_omega[0]
    with pytest.raises(InputError, match="E_s"):
        multimass.column("S1", E_s=-1.0)


def test_rigid_block_is_housner():
    # paper 004, after Eq 2: I_A = (4/3) m R², p = sqrt(3 g / (4 R))
    blk = multimass.rigid_block("B6M")
    spec = specimens.load("B6M")
    assert blk.n == 0 and blk.is_rigid
    assert blk.J_p == pytest.approx(4.0 / 3.0 * spec.mass * spec.R**2, rel=1e-14)
    assert blk.p == pytest.approx(np.sqrt(3 * 9.81 / (4 * spec.R)), rel=1e-14)
    assert blk.alpha_cg == pytest.approx(np.arctan(spec.b / spec.h), rel=1e-14)
    assert multimass.from_specimen("B6M").J_p == blk.J_p
    with pytest.raises(InputError, match="block"):
        multimass.rigid_block("S1")


# ---------------------------------------------------------------------------- arguments
@pytest.mark.parametrize(
    "build, value, fragment",
    [
        (
            multimass.column,
            None,
            r"`specimen` = None: give a bundled name.*`column` needs a column",
        ),
        (multimass.column, 3.5, r"`specimen` = 3.5"),
        (multimass.column, b"S1", r"`specimen` = b'S1'"),
        (
            multimass.column,
            "B6M",
            r"`specimen` = 'B6M' is a 'block' specimen; `column` needs a column",
        ),
        (multimass.rigid_block, None, r"`specimen` = None.*`rigid_block` needs a block"),
        (multimass.rigid_block, "S1", r"'S1' is a 'column' specimen; `rigid_block` needs a block"),
        (multimass.from_specimen, 123, r"`specimen` = 123: give a column or block specimen"),
        (multimass.from_specimen, None, r"`specimen` = None"),
        (multimass.from_specimen, "beam_mudric2024", r"is a beam: a flexible base for a block"),
    ],
)
def test_bad_specimen_argument_is_named(build, value, fragment):
    with pytest.raises(InputError, match=fragment):
        build(value)


@pytest.mark.parametrize(
    "E_s, fragment",
    [
        (200, r"`E_s` = 200: implausible Young's modulus.*did you type GPa\? write 200e9"),
        (1e300, r"`E_s` = 1e\+300"),
        (True, r"`E_s` = True: expected a number"),
        ("210e9", r"`E_s` = '210e9': expected a number"),
        (float("nan"), r"`E_s` = nan"),
    ],
)
def test_e_s_override_is_validated(E_s, fragment):
    with pytest.raises(InputError, match=fragment):
        multimass.column("S1", E_s=E_s)


# ---------------------------------------------------------------------------- every known specimen builds
def _specimens_in_use(tmp_path):
    """Bundled columns and blocks, the example S1_soft, and the specimens the tests build."""
    out = [n for n in specimens.available() if specimens.load(n).kind != "beam"]
    out.append(REPO / "examples" / "data" / "S1_soft.toml")
    out.append(column_toml(tmp_path, [1.2], [150.0], name="sdof"))  # test_structure
    out.append(column_toml(tmp_path, [1.0], [200.0], name="sdof_modal"))  # tests/modal
    for scale in (100.0, 1000.0):  # test_simulate
        out.append(
            column_toml(
                tmp_path,
                [0.2, 1.0],
                [50.0, 100.0],
                name=f"stiff{scale:g}",
                **{
                    "youngs_modulus_Pa = 200e9": f"youngs_modulus_Pa = {200e9 * scale:g}",
                    "rotational_spring_Nm_per_rad = 2.0e6": f"rotational_spring_Nm_per_rad = {2e6 * scale:g}",
                    "horizontal_spring_N_per_m = 5.0e8": "horizontal_spring_N_per_m = 5e9",
                },
            )
        )
    s1 = specimens.load("S1")
    for factor in (1e4, 1e-2):  # test_choose (x 1e4) and benchmarks (x 1e4); S1 / 100
        out.append(
            dataclasses.replace(
                s1, E_s=s1.E_s * factor, K_rot=s1.K_rot * factor, K_fp=s1.K_fp * factor
            )
        )
    return out


def test_every_specimen_in_use_still_builds(tmp_path):
    for spec in _specimens_in_use(tmp_path):
        st = multimass.from_specimen(spec)
        assert np.isfinite([st.J_p, st.H_cg, st.p_l, st.p]).all()


# ---------------------------------------------------------------------------- structure-level checks
def _sdof(**fields):
    """A one-node column: K is the horizontal spring alone, ω² = K_fp / m (closed form)."""
    base = dataclasses.replace(specimens.load("S1"), heights=(1.2,), masses=(150.0,), sensors=())
    return dataclasses.replace(base, **fields)


def test_drift_under_1g_bound_at_the_height():
    # closed form for one node: g / ω1² = g m / K_fp; the limit H_N = 1.2 m gives K* = g m / H
    k_star = 9.81 * 150.0 / 1.2
    multimass.column(_sdof(K_fp=1.001 * k_star))
    with pytest.raises(
        SpecimenError,
        match=r"static drift under a lateral 1 g, g/ω1² = 1.2\d* m, "
        r"exceeds 1 x the height 1.2 m.*most flexible part is "
        r"`stiffness.horizontal_spring_N_per_m` = 1225",
    ):
        multimass.column(_sdof(K_fp=0.999 * k_star))


def test_highest_frequency_bound():
    # closed form for one node: f = sqrt(K_fp / m) / 2π; the 1e6 Hz ceiling at m = 0.01 kg
    m = 0.01
    k_star = m * (2 * np.pi * MAX_FREQ_HZ) ** 2
    multimass.column(_sdof(masses=(m,), K_fp=0.999 * k_star))
    with pytest.raises(
        SpecimenError,
        match=r"highest full-contact frequency 1e\+06 Hz > 1e6 Hz.*"
        r"stiffest part is `stiffness.horizontal_spring_N_per_m`",
    ):
        multimass.column(_sdof(masses=(m,), K_fp=1.001 * k_star))


def test_soft_column_names_the_bending_stiffness():
    # S1 with E_s = 1e7 Pa (inside the material range): g/ω1² is metres, the bending term dominates
    with pytest.raises(
        SpecimenError,
        match=r"most flexible part is `stiffness.youngs_modulus_Pa` = "
        r"1e\+07 Pa \(steel is 200e9\) with `stiffness.second_moment_m4`"
        r" = 1.833e-06 m\^4",
    ):
        multimass.column(dataclasses.replace(specimens.load("S1"), E_s=1e7))


def _modal_damping(spec, zeta_1, zeta_2):
    """ζ at every full-contact mode of Rayleigh damping fitted to ζ_1, ζ_2, computed apart from
    the code's fit: numpy.linalg.eig of M⁻¹K and a 2x2 solve of ζ_k = a0/(2ω_k) + a1 ω_k/2."""
    s1 = multimass.column(dataclasses.replace(spec, zeta_1=0.005, zeta_2=0.015))
    w = np.sort(np.sqrt(np.linalg.eig(np.linalg.solve(s1.M, s1.K))[0].real))
    a0, a1 = np.linalg.solve(
        [[1 / (2 * w[0]), w[0] / 2], [1 / (2 * w[1]), w[1] / 2]], [zeta_1, zeta_2]
    )
    return a0 / (2 * w) + a1 * w / 2, w


@pytest.mark.parametrize(
    "zeta_1, zeta_2, negative",
    [
        (0.05, 0.001, True),
        (0.02, 0.002, True),  # zeta_2 / zeta_1 < f1 / f2 = 0.184 (S1)
        (0.005, 0.015, False),
        (0.1, 0.1, False),
    ],
)  # S1's own (paper 001, Table 1); equal
def test_negative_rayleigh_damping_is_refused(zeta_1, zeta_2, negative):
    spec = dataclasses.replace(specimens.load("S1"), zeta_1=zeta_1, zeta_2=zeta_2)
    zeta, _ = _modal_damping(spec, zeta_1, zeta_2)
    assert (zeta.min() < 0) == negative
    if negative:
        k = int(np.argmin(zeta)) + 1
        with pytest.raises(
            SpecimenError,
            match=rf"gives ζ = .* < 0 at full-contact mode {k} .*make "
            r"zeta_2 / zeta_1 >= f1 / f2 = 0.184",
        ):
            multimass.column(spec)
    else:
        st = multimass.column(spec)
        v = np.linalg.eigh(st.C)[0]
        assert v.min() >= -1e-12 * abs(v).max()  # C positive semi-definite


def test_two_node_column_has_no_mode_to_go_negative():
    # with N = 2 Rayleigh damping is exactly ζ_1, ζ_2 at the only two modes, whatever their ratio
    spec = dataclasses.replace(
        specimens.load("S1"),
        heights=(0.5, 1.5),
        masses=(100.0, 50.0),
        sensors=(),
        zeta_1=0.1,
        zeta_2=0.001,
    )
    st = multimass.column(spec)
    zeta, _ = _modal_damping(spec, 0.1, 0.001)
    assert zeta == pytest.approx([0.1, 0.001], rel=1e-9) and st.n == 2


@pytest.mark.parametrize(
    "fields, fragment",
    [
        (dict(B=float("nan")), r"B = nan \(a finite number > 0\)"),
        (dict(K_fp=-1.0), r"K_fp = -1.0"),
        (dict(E_s="200e9"), r"E_s = '200e9'"),
        (dict(zeta_1=1.5), r"zeta_1 = 1.5 \(a finite number >= 0, < 1\)"),
        (dict(heights=(0.06, 0.49)), r"heights/masses"),
        (dict(masses=(77.3, -6.2, 88.2, 8.2, 46.2)), r"masses \(> 0\)"),
        (dict(heights=tuple(np.linspace(0.01, 2.0, 201)), masses=(1.0,) * 201), r"1..200 nodes"),
    ],
)
def test_objects_built_with_replace_are_checked(fields, fragment):
    with pytest.raises(SpecimenError, match=fragment):
        multimass.column(dataclasses.replace(specimens.load("S1"), **fields))


def test_rigid_block_object_is_checked():
    with pytest.raises(SpecimenError, match=r"`mass` = nan"):
        multimass.rigid_block(dataclasses.replace(specimens.load("B6M"), mass=float("nan")))


def test_matrices_are_finite_and_spd_for_the_bundled_columns():
    for name in ("S1", "S2", "S3"):
        st = multimass.column(name)
        for A in (st.K, st.M):
            assert np.isfinite(A).all() and np.array_equal(A, A.T)
            assert np.linalg.eigvalsh(A).min() > 0
        assert np.linalg.eigvalsh(st.C).min() > 0  # ζ > 0 at every mode of S1–S3


@pytest.mark.parametrize(
    "heights, masses",
    [
        ([0.06, 0.49, 0.93, 1.43, 1.93], [77300, 6200, 88200, 8200, 46200]),  # S1's masses in g
        ([6, 49, 93, 143, 193], [77.3, 6.2, 88.2, 8.2, 46.2]),  # S1's heights in cm
    ],
    ids=["masses in g", "heights in cm"],
)
def test_slips_that_pass_each_range_are_caught_by_the_frequency(tmp_path, heights, masses):
    # each value is a plausible mass or length on its own; together S1 becomes a column whose
    # 1-g drift is metres (paper 001, Table 1 values x 1000 or heights x 100)
    path = column_toml(tmp_path, heights, masses, name="slip")
    with pytest.raises(
        SpecimenError,
        match=r"slip.toml: full-contact first frequency .* exceeds 1 x "
        r"the height.*`mass.nodal_kg` \(kg\)",
    ):
        multimass.column(path)


def test_a_specimen_is_built_once_and_shared_read_only():
    # `column` of the same specimen returns one structure; its arrays cannot be
    # changed under another caller's feet
    a, b = multimass.column("S1"), multimass.column(specimens.load("S1"))
    assert a is b
    with pytest.raises(ValueError, match="read-only"):
        a.K[0, 0] = 0.0
    # a modulus given explicitly is a structure of its own (E_s 210 GPa: DESIGN.md)
    c = multimass.column("S1", E_s=210e9)
    assert c is not a and not np.allclose(c.K, a.K)
    assert c.K.flags.writeable


def test_what_is_derived_from_a_shared_structure_is_kept_on_it():
    from multimass.model.structure import derived_once

    calls = []
    build = lambda st: calls.append(st) or np.linalg.eigvalsh(st.K)  # noqa: E731
    shared = multimass.column("S1")
    first = derived_once(shared, "test_eigs", build)
    assert derived_once(shared, "test_eigs", build) is first and len(calls) == 1
    own = multimass.column("S1", E_s=210e9)  # writeable arrays: may change, so not kept
    derived_once(own, "test_eigs", build), derived_once(own, "test_eigs", build)
    assert len(calls) == 3
