"""Rocking side by side: the toolkit's rigid-contact models and the exported OpenSees model.

`compare_rocking` runs one structure under one excitation in both engines — this
toolkit's `simulate` with impact models such as CIM and DD2 (rigid contact, a
restitution law at θ = 0), and the OpenSees rocking model of `opensees` (contact
springs) — and measures both histories the same way: impact times (θ changes sign),
the peak of each half-cycle, and the energy lost between consecutive peaks.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from tempfile import TemporaryDirectory

import numpy as np

from ..errors import InputError
from ..impact_models.restitution import housner_eta
from ..inputs.excitations import FreeRelease
from ..inputs.records import Record
from ..model.equations import free_rocking_peak
from ..model.structure import Structure, from_specimen
from ..simulation import simulate
from ._runtime import import_opensees
from .opensees import opensees

__all__ = [
    "EngineRun",
    "SideBySide",
    "compare_rocking",
    "impact_times",
    "half_cycle_peaks",
    "rocking_energy",
    "housner_peaks",
]

#: ``|θ|`` below this (rad) is not rocking: the OpenSees contact springs let the base turn
#: by about m_t g / (k_n B) ~ 1e-6 rad in full contact.
THETA_MIN = 1e-4


@dataclass(frozen=True, eq=False)
class EngineRun:
    """One engine's run: θ(t) and what is measured on it the same way for every engine."""

    engine: str
    t: np.ndarray
    theta: np.ndarray
    wall_time_s: float
    impacts: np.ndarray
    peaks: np.ndarray
    peak_times: np.ndarray
    energy_lost: np.ndarray


@dataclass(frozen=True, eq=False)
class SideBySide:
    """The runs of one comparison, keyed by engine name, and the Housner reference."""

    name: str
    structure: Structure
    runs: dict = field(default_factory=dict)
    housner: np.ndarray | None = None

    def summary(self) -> dict:
        """Plain numbers: peaks (rad), impact times (s), energy lost (J), run times (s)."""
        out = {"name": self.name, "engines": {}}
        for key, run in self.runs.items():
            out["engines"][key] = {
                "wall_time_s": run.wall_time_s,
                "impact_times_s": run.impacts.tolist(),
                "peaks_rad": run.peaks.tolist(),
                "peak_times_s": run.peak_times.tolist(),
                "energy_lost_J": run.energy_lost.tolist(),
            }
        if self.housner is not None:
            out["housner_peaks_rad"] = self.housner.tolist()
        return out


def impact_times(t, theta, theta_min: float = THETA_MIN) -> np.ndarray:
    """Times (s) at which θ changes sign between two half-cycles that rock (``|θ| > theta_min``).

    Linear interpolation between the samples around each sign change.
    """
    t, theta = np.asarray(t, float), np.asarray(theta, float)
    keep = np.abs(theta) > theta_min
    idx = np.flatnonzero(keep)
    out = []
    for a, b in zip(idx[:-1], idx[1:]):
        if np.sign(theta[a]) != np.sign(theta[b]):
            k = a + int(np.flatnonzero(np.sign(theta[a : b + 1]) != np.sign(theta[a]))[0]) - 1
            t0, t1, y0, y1 = t[k], t[k + 1], theta[k], theta[k + 1]
            out.append(t0 if y1 == y0 else t0 + (t1 - t0) * y0 / (y0 - y1))
    return np.asarray(out)


def half_cycle_peaks(t, theta, theta_min: float = THETA_MIN) -> tuple[np.ndarray, np.ndarray]:
    """(peaks, times): the largest ``|θ|`` (rad) of each half-cycle between impacts, and when.

    A last half-cycle that the series cuts off while ``|θ|`` still grows (its largest value
    is the last sample) has no peak yet and is left out.
    """
    t, theta = np.asarray(t, float), np.asarray(theta, float)
    cuts = np.searchsorted(t, impact_times(t, theta, theta_min))
    peaks, times = [], []
    for a, b in zip(np.r_[0, cuts], np.r_[cuts, t.size]):
        if b > a:
            k = a + int(np.argmax(np.abs(theta[a:b])))
            if b == t.size and k == b - 1 and b - a > 1:
                continue  # cut off before its peak
            if abs(theta[k]) > theta_min:
                peaks.append(abs(theta[k]))
                times.append(t[k])
    return np.asarray(peaks), np.asarray(times)


def rocking_energy(s: Structure, theta) -> np.ndarray:
    """Gravitational energy (J) of the structure, taken as rigid, tilted by ``|θ|`` on a pivot.

    ``m_t g (R_cg cos(α_cg − |θ|) − H_cg)``: at a peak (θ̇ = 0) the whole rocking energy.
    """
    th = np.abs(np.asarray(theta, float))
    return s.m_t * s.g * (s.R_cg * np.cos(s.alpha_cg - th) - s.H_cg)


def housner_peaks(s: Structure, theta0: float, n: int) -> np.ndarray:
    """Peaks of a rigid block's free rocking with Housner's r = 1 − 1.5 sin²α per impact.

    Each impact keeps r² of the kinetic energy (paper 004, Eq 9 for r), so consecutive
    peaks satisfy E(θ_k+1) = r² E(θ_k) with `rocking_energy` E.
    """
    r = housner_eta(s.alpha_cg)
    out = [abs(theta0)]
    for _ in range(n - 1):
        e = r**2 * float(rocking_energy(s, out[-1]))
        # the swing that E reaches: m g R [cos(α − φ) − cos α] = E
        out.append(
            free_rocking_peak(s.alpha_cg, e / (s.m_t * s.g * s.R_cg * (1 - math.cos(s.alpha_cg))))
        )
    return np.asarray(out)


def _measured(engine, s, t, theta, wall, theta_min) -> EngineRun:
    peaks, times = half_cycle_peaks(t, theta, theta_min)
    energy = rocking_energy(s, peaks)
    return EngineRun(
        engine,
        np.asarray(t, float),
        np.asarray(theta, float),
        wall,
        impact_times(t, theta, theta_min),
        peaks,
        times,
        energy[:-1] - energy[1:],
    )


def _run_opensees(s, excitation, t_end, contact_damping, output_dt) -> tuple:
    ops = import_opensees()
    record = excitation if isinstance(excitation, Record) else None
    release = excitation.theta0 if isinstance(excitation, FreeRelease) else None
    with TemporaryDirectory() as tmp:
        path = Path(tmp) / "model.py"
        opensees(
            s,
            "rocking",
            record,
            out=path,
            t_end=t_end,
            release=release or None,
            contact_damping=contact_damping,
            output_dt=output_dt,
        )
        namespace: dict = {"__name__": "exported_model"}
        exec(compile(path.read_text(), str(path), "exec"), namespace)  # the script, not main
        start = time.perf_counter()
        ops.wipe()
        ops.model("basic", "-ndm", 2, "-ndf", 3)
        namespace["build"](ops)
        namespace["start"](ops)
        series = namespace["ground_motion"](ops)
        namespace["recorders"](ops, tmp, series)
        status = namespace["run"](ops)
        ops.wipe()
        wall = time.perf_counter() - start
        namespace["write_theta"](tmp)
        t, theta = np.loadtxt(Path(tmp) / "theta.out", ndmin=2).T
    if status != 0:
        raise InputError(f"the OpenSees rocking model of {s.name} failed before t = {t[-1]:.4g} s")
    return t, theta, wall


def compare_rocking(
    specimen,
    excitation,
    t_end: float,
    *,
    impacts=("CIM", "DD2"),
    contact_damping: float | None = None,
    output_dt: float = 1e-3,
    theta_min: float = THETA_MIN,
) -> SideBySide:
    """Run a structure in both engines and measure both the same way.

    Parameters
    ----------
    specimen : Structure, specimen, bundled name or TOML path
    excitation : FreeRelease or Record
        A free release from θ0 (no initial deformation) or a ground motion.
    t_end : float
        End time (s) of both runs.
    impacts : sequence of str
        Impact models of the toolkit's runs (`simulate`'s ``impact``).
    contact_damping : float, optional
        ζ_c of the OpenSees contact springs (default: `opensees`'s, by kind).

    Returns
    -------
    SideBySide
        With one `EngineRun` per impact model and ``"OpenSees"``; for a rigid block
        released freely, Housner's peaks too.
    """
    s = specimen if isinstance(specimen, Structure) else from_specimen(specimen)
    if not isinstance(excitation, (FreeRelease, Record)):
        raise InputError(
            f"`excitation` is a {type(excitation).__name__}: give a FreeRelease (θ0) or a "
            "Record; the OpenSees model is exported with a record or a release only"
        )
    if isinstance(excitation, FreeRelease) and excitation.u0 not in (None, 0.0):
        raise InputError("`excitation`: the OpenSees model is released undeformed; use u0=None")
    runs = {}
    for impact in impacts:
        start = time.perf_counter()
        r = simulate(s, excitation, impact=impact, t_end=t_end, output_dt=output_dt, progress=False)
        wall = time.perf_counter() - start
        runs[impact] = _measured(impact, s, r.series["t"], r.series["theta"], wall, theta_min)
    t, theta, wall = _run_opensees(s, excitation, t_end, contact_damping, output_dt)
    runs["OpenSees"] = _measured("OpenSees", s, t, theta, wall, theta_min)
    housner = None
    if s.is_rigid and isinstance(excitation, FreeRelease):
        housner = housner_peaks(s, excitation.theta0, max(len(r.peaks) for r in runs.values()))
    return SideBySide(s.name, s, runs, housner)
