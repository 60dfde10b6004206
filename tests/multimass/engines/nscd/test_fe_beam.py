"""Frame-element beam of paper 002, Section 3.1, against closed-form beam theory."""

import math

import numpy as np
import pytest

from multimass.engines.nscd.fe_beam import build_beam, static_deflection
from multimass.errors import InputError

L, W, H, RHO = 0.30, 0.040, 0.00171, 2795.0  # paper 002, Section 6
A, I = W * H, W * H**3 / 12
E = 70e9


@pytest.mark.parametrize("n_el", [4, 6, 12])
def test_midspan_point_load(n_el):
    beam = build_beam(L, E, A, I, RHO, n_el, g=0.0)
    q = static_deflection(beam, beam.point_load(L / 2, 0.0, -10.0))
    # closed form: simply supported beam, central load P: delta = P L^3 / (48 E I)
    assert beam.deflection(q, L / 2) == pytest.approx(-10.0 * L**3 / (48 * E * I), rel=1e-10)


def test_self_weight_deflection():
    beam = build_beam(L, E, A, I, RHO, 6, g=9.81)
    q = static_deflection(beam, beam.p_self)
    # closed form: uniform load w = rho A g: delta = 5 w L^4 / (384 E I) (nodally exact for
    # Hermite elements with consistent loads)
    w = RHO * A * 9.81
    assert beam.deflection(q, L / 2) == pytest.approx(-5 * w * L**4 / (384 * E * I), rel=1e-10)


def test_bending_frequencies():
    beam = build_beam(L, E, A, I, RHO, 24)
    # closed form: simply supported Euler-Bernoulli beam, omega_k = (k pi / L)^2 sqrt(E I / m)
    exact = [(k * math.pi / L) ** 2 * math.sqrt(E * I / (RHO * A)) for k in (1, 2, 3)]
    assert beam.omega[:3] == pytest.approx(exact, rel=1e-4)


def test_axial_mode():
    beam = build_beam(L, E, A, I, RHO, 24)
    # closed form: pinned-free bar (roller end free axially), omega = (pi / 2L) sqrt(E / rho)
    w_ax = math.pi / (2 * L) * math.sqrt(E / RHO)
    assert np.min(np.abs(beam.omega / w_ax - 1.0)) < 1e-3


def test_rayleigh_ratios_at_modes_1_and_3():
    beam = build_beam(L, E, A, I, RHO, 6, damping_ratios=(0.05, 0.2), damping_modes=(1, 3))
    a0, a1 = beam.rayleigh
    zeta = a0 / (2 * beam.omega) + a1 * beam.omega / 2
    # paper 002, Section 6: 0.05 at the first and 0.2 at the third natural frequency
    assert zeta[0] == pytest.approx(0.05, rel=1e-10)
    assert zeta[2] == pytest.approx(0.2, rel=1e-10)
    assert np.allclose(beam.C, a0 * beam.M + a1 * beam.K)


def test_rigid_base_matrices_are_usable():
    beam = build_beam(L, 1e24, A, I, RHO, 6)  # paper 002, Section 6.1: rigid base
    assert np.all(np.isfinite(beam.omega)) and np.all(
        np.linalg.eigvalsh(beam.C) > -1e-6 * np.abs(beam.C).max()
    )


@pytest.mark.parametrize(
    "kw, fragment",
    [
        ({"n_elements": 2}, "`n_elements`"),
        ({"E": -1.0}, "`E`"),
        ({"damping_modes": (1, 40)}, "`damping_modes`"),
    ],
)
def test_bad_beam_input(kw, fragment):
    args = {"L": L, "E": E, "A": A, "I": I, "rho": RHO, "n_elements": 6, **kw}
    with pytest.raises(InputError, match=fragment):
        build_beam(**args)
