"""Rocking side by side: the measurements, checked on closed forms, and the command."""

import json
import math

import numpy as np
import pytest

import multimass
from multimass.cli import main
from multimass.export.side_by_side import (
    half_cycle_peaks,
    housner_peaks,
    impact_times,
    rocking_energy,
)


def test_impacts_and_peaks_of_a_decaying_cosine():
    """θ = A e^{-t} cos(2π t): zero crossings at t = 1/4 + k/2 (closed form), half-cycle
    peaks near A e^{-k/2} at t ≈ k/2."""
    t = np.linspace(0.0, 3.0, 30001)
    theta = 0.1 * np.exp(-t) * np.cos(2 * np.pi * t)
    np.testing.assert_allclose(impact_times(t, theta), 0.25 + 0.5 * np.arange(6), atol=1e-6)
    peaks, times = half_cycle_peaks(t, theta)
    # seven peaks: the seventh at tan(2πt) = −1/(2π), t = 3 − 0.0253, before the series ends
    assert peaks.size == 7 and peaks[0] == pytest.approx(0.1)
    np.testing.assert_allclose(times[1:6], 0.5 * np.arange(1, 6), atol=0.03)
    assert times[6] == pytest.approx(3 - math.atan(1 / (2 * math.pi)) / (2 * math.pi), abs=1e-3)
    # cut at t = 2.9, while |θ| still grows towards the seventh peak: that one is left out
    cut = t <= 2.9
    p6, _ = half_cycle_peaks(t[cut], theta[cut])
    np.testing.assert_allclose(p6, peaks[:6])
    # a bump below the threshold is no impact
    assert impact_times(t, 1e-5 * np.sin(20 * t)).size == 0


def test_rocking_energy_closed_form():
    """Uniform block: E(θ) = m g R (cos(α − θ) − cos α) (paper 004, Housner)."""
    s = multimass.rigid_block("B6M")
    spec = s.specimen
    R, alpha = math.hypot(spec.b, spec.h) / 2, math.atan(spec.b / spec.h)
    want = spec.mass * spec.g * R * (math.cos(alpha - 0.05) - math.cos(alpha))
    assert float(rocking_energy(s, -0.05)) == pytest.approx(want, rel=1e-12)
    assert float(rocking_energy(s, 0.0)) == pytest.approx(0.0, abs=1e-15)


def test_housner_peaks_keep_r_squared_of_the_energy():
    s = multimass.rigid_block("B6M")
    peaks = housner_peaks(s, 0.1, 5)
    r = 1 - 1.5 * math.sin(s.alpha_cg) ** 2  # paper 004, Eq 9
    ratios = rocking_energy(s, peaks[1:]) / rocking_energy(s, peaks[:-1])
    np.testing.assert_allclose(ratios, r**2, rtol=1e-10)


def test_command_block_release_follows_housner(ops, tmp_path, capsys):
    """B6M released from 0.1 rad in OpenSees (default ζ_c = 0.01) against Housner's decay:
    each of its first four peaks within 5 % (measured: within 3 %)."""
    argv = ["compare-opensees", "B6M", "--release", "0.1", "--t-end", "1.2"]
    argv += ["--impact", "CIM", "--out", str(tmp_path), "--json"]
    assert main(argv) == 0
    summary = json.loads(capsys.readouterr().out)
    assert (tmp_path / "B6M_release.png").stat().st_size > 0
    got = np.array(summary["engines"]["OpenSees"]["peaks_rad"][:4])
    want = np.array(summary["housner_peaks_rad"][:4])
    np.testing.assert_allclose(got, want, rtol=0.05)
    for engine in ("CIM", "OpenSees"):
        row = summary["engines"][engine]
        assert row["wall_time_s"] > 0 and len(row["impact_times_s"]) >= 3


def test_command_bad_excitation(tmp_path, capsys):
    assert main(["compare-opensees", "S1", "--out", str(tmp_path)]) == 2
    assert "give one excitation" in capsys.readouterr().err
