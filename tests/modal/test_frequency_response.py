"""State-space models (python-control) and frequency responses of the linearised phases.

References: the Foss eigenvalues of paper 001, Eq 24 (`multimass.modal.eigen`); the
second-order form M z̈ + C ż + K z = −r ü_g solved at each frequency, an independent
route to the same FRF (no first-order matrices); closed forms at f = 0 (full contact:
the column moves with the table, a = ü_g) and near each mode (a lightly damped
mode's peak lies within about ζ² of its frequency).
"""

import numpy as np
import pytest

import multimass
from multimass.modal import ModalError, foss, full_contact, rocking
from multimass.modal.frequency_response import frf, state_space

control = pytest.importorskip("control")


@pytest.fixture(scope="module")
def s1():
    return multimass.column("S1")


@pytest.mark.parametrize("phase, system", [("full_contact", full_contact), ("rocking", rocking)])
def test_poles_are_the_foss_eigenvalues(s1, phase, system):
    sys = state_space(s1, phase)
    poles = np.sort_complex(control.poles(sys))
    lam = np.sort_complex(foss(system(s1)).eigenvalues)
    assert poles.shape == lam.shape
    np.testing.assert_allclose(poles, lam, rtol=1e-10, atol=1e-10 * np.abs(lam).max())


def _second_order(s1, phase, f):
    """Total accelerations (and θ) per unit ü_g from M z̈ + C ż + K z = −r ü_g at each f."""
    L = full_contact(s1) if phase == "full_contact" else rocking(s1)
    N, out = s1.n, []
    for fk in f:
        w = 2 * np.pi * fk
        Z = np.linalg.solve(-(w**2) * L.M + 1j * w * L.C + L.K, -L.r)
        a = -(w**2) * Z[:N] + 1.0
        if phase == "rocking":
            a = a - (w**2) * s1.H * Z[N] - s1.g * Z[N]
            a = np.append(a, Z[N])
        out.append(a)
    return np.array(out).T


@pytest.mark.parametrize("phase", ["full_contact", "rocking"])
def test_frf_equals_the_second_order_solution_and_python_control(s1, phase):
    f = np.array([0.3, 2.0, 7.5, 20.0, 45.0, 120.0])
    H = frf(s1, f, phase)
    np.testing.assert_allclose(H, _second_order(s1, phase, f), rtol=1e-9, atol=1e-12)
    sys = state_space(s1, phase)
    H_control = np.array([control.evalfr(sys, 2j * np.pi * fk) for fk in f])[..., 0].T
    np.testing.assert_allclose(H, H_control, rtol=1e-9, atol=1e-12)
    names = [f"a{i}" for i in range(1, s1.n + 1)] + (["theta"] if phase == "rocking" else [])
    assert sys.output_labels == names and sys.input_labels == ["ag"]


def test_full_contact_moves_with_the_table_at_zero_frequency(s1):
    np.testing.assert_allclose(frf(s1, [0.0])[:, 0], np.ones(s1.n), atol=1e-12)


def test_frf_peaks_sit_at_the_full_contact_modes(s1):
    modes = multimass.modal.analyse(s1).full_contact
    top = s1.n  # the top sensor
    for f_k, z_k in list(zip(modes.freq_hz, modes.damping))[:2]:
        f = np.linspace(0.8 * f_k, 1.2 * f_k, 40001)
        amp = np.abs(frf(s1, f, sensors=[top])[0])
        peak = f[np.argmax(amp)]
        # a single mode's transmissibility peaks at ω_n (1 − ζ² + O(ζ⁴)); the other modes
        # move it a little more: allow 2 ζ² and the grid step
        assert abs(peak / f_k - 1.0) < 2 * z_k**2 + 2 * (f[1] - f[0]) / f_k, (f_k, peak)


def test_sensors_select_outputs(s1):
    sys = state_space(s1, "rocking", sensors=[1, s1.n])
    assert sys.output_labels == ["a1", f"a{s1.n}", "theta"]
    np.testing.assert_allclose(
        frf(s1, [5.0], "rocking", sensors=[s1.n]), frf(s1, [5.0], "rocking")[[s1.n - 1, s1.n]]
    )


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(phase="uplift"), "use 'full_contact' or 'rocking'"),
        (dict(sensors=[0]), "node numbers run from 1"),
        (dict(sensors=["top"]), "give a list of node numbers"),
    ],
)
def test_bad_arguments_are_named(s1, kwargs, words):
    with pytest.raises(ModalError, match=words):
        state_space(s1, **kwargs)


def test_a_rigid_block_has_no_state_space_model():
    with pytest.raises(ModalError, match="no elastic nodes"):
        state_space(multimass.rigid_block("B6M"))
    with pytest.raises(ModalError, match="frequencies"):
        frf(multimass.column("S1"), [-1.0])
