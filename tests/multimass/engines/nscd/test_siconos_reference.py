"""The Moreau–Jean engine against Siconos, an engine this toolkit did not write.

Reference: ``../shared/data/reference/siconos_LZB_2018_consistent.ref`` — the output of
the Siconos tutorial ``RockingBlockED_Lsodar_LZBimpact`` (event-driven, LSODAR, output
every 0.01 s; provenance in that folder's ``SOURCES_rocking.md``): a block 1.0 m wide and
0.5 m tall, 1 kg, released from θ = π/3 on one corner at rest, **frictionless** contact.
Without friction the corner slides while the block turns (the file's x and v_x stay at
their initial values: no horizontal force), so its first swing is not the pivoting rock
of papers 001/004; our engine reproduces it with ``mu=0`` (paper 002, Coulomb's law with
a zero coefficient). Only the swing before the first impact (t < 0.5875 s) is compared:
Siconos' LZB multiple-impact law then differs from paper 002's Newton law.

The other two Siconos files are not used: their contact geometry (0.2 × 0.1) does not
match their inertia (1.0 × 0.5), so the block starts in free flight
(``SOURCES_rocking.md``).

Moreau–Jean time stepping is first order here (velocity-level Signorini conditions), so
the test checks that order and Richardson-extrapolates two step sizes: measured, the
dt = 1e-3 s run is 2.0e-3 rad from Siconos, dt = 5e-4 s 9.8e-4 rad, and their
extrapolation 2θ_{h/2} − θ_h 6.7e-6 rad.
"""

import math

import numpy as np
import pytest

from multimass import nscd, specimens

#: Siconos' first impact: the duplicated event row of the reference file.
T_FIRST_IMPACT = 0.587477975

BLOCK = """kind = "block"
name = "SICONOS"
description = "The Siconos tutorial's rocking block (1.0 m wide, 0.5 m tall, 1 kg)."
source = "siconos-tutorials RockingBlock, 16735dd"
gravity_m_per_s2 = 9.81
[geometry]
width_m = 1.0
height_m = 0.5
depth_m = 0.001
[mass]
mass_kg = 1.0
[restitution]
k = 0.8
"""


def _siconos_rows(folder):
    """The reference file's data rows (after the ``#`` comments and the ``rows cols`` line)."""
    lines = (folder / "siconos_LZB_2018_consistent.ref").read_text().splitlines()
    lines = [x for x in lines if not x.startswith("#")]
    rows, cols = map(int, lines[0].split())
    d = np.array([[float(v) for v in x.split()] for x in lines[1:] if x.strip()])
    assert d.shape[1] == cols and len(d) >= rows
    return d


@pytest.fixture(scope="module")
def siconos(reference_data):
    """(t, θ, θ̇) of the Siconos run before its first impact."""
    d = _siconos_rows(reference_data)
    keep = d[:, 0] < T_FIRST_IMPACT - 1e-3
    return d[keep, 0], d[keep, 3], d[keep, 6]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Our frictionless runs at dt = 1e-3, 5e-4 and 2.5e-4 s on a rigid 3 m base."""
    folder = tmp_path_factory.mktemp("siconos")
    (folder / "block.toml").write_text(BLOCK)
    beam = specimens.loader._bundled()["beam_mudric2024"].read_text()
    beam = beam.replace("span_m = 0.30", "span_m = 3.0")  # room for a 1 m block; E = 1e24
    (folder / "beam.toml").write_text(beam)
    return {
        dt: nscd.simulate(
            folder / "block.toml",
            folder / "beam.toml",
            theta0=math.pi / 3,
            dt=dt,
            t_end=0.6,
            mu=0.0,
            theta_method=0.5,
            record_every=1,
            progress=False,
        )
        for dt in (1e-3, 5e-4, 2.5e-4)
    }


def _at(run, t, field):
    return np.interp(t, run.t, getattr(run, field))


def test_first_order_then_extrapolated_to_siconos(siconos, runs):
    t, th_ref, w_ref = siconos
    err = {dt: np.max(np.abs(_at(r, t, "theta") - th_ref)) for dt, r in runs.items()}
    # First order: halving dt halves the error (measured ratios 1.99, 2.00).
    assert 1.8 < err[1e-3] / err[5e-4] < 2.2
    assert 1.8 < err[5e-4] / err[2.5e-4] < 2.2
    # Richardson: the first-order term cancels; what is left shrinks by ~4 (second order).
    rich1 = 2 * _at(runs[5e-4], t, "theta") - _at(runs[1e-3], t, "theta")
    rich2 = 2 * _at(runs[2.5e-4], t, "theta") - _at(runs[5e-4], t, "theta")
    e1, e2 = np.max(np.abs(rich1 - th_ref)), np.max(np.abs(rich2 - th_ref))
    assert e1 < 2e-5 and e2 < 5e-6  # measured 6.7e-6 and 1.7e-6 rad
    assert e1 / e2 > 3.0
    w2 = 2 * _at(runs[2.5e-4], t, "thetadot") - _at(runs[5e-4], t, "thetadot")
    assert np.max(np.abs(w2 - w_ref)) < 1e-4 * np.max(np.abs(w_ref))


def test_first_impact_time_and_speed(runs, reference_data):
    d = _siconos_rows(reference_data)
    row = d[np.flatnonzero(np.isclose(d[:, 0], T_FIRST_IMPACT, atol=1e-8))[0]]
    impacts = {dt: next(e for e in r.events if e.kind == "impact") for dt, r in runs.items()}
    for dt, e in impacts.items():
        assert abs(e.time - row[0]) <= dt  # located to the step
    # Speed before impact, Richardson-extrapolated: Siconos -4.13076 rad/s.
    w = 2 * impacts[2.5e-4].thetadot_minus - impacts[5e-4].thetadot_minus
    assert abs(w - row[6]) < 5e-4 * abs(row[6])
