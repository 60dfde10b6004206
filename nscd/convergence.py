"""Convergence studies of the Moreau–Jean simulation and detection of
non-convergence (paper 002, Sections 6.1 and 6.3, Figs 10–11 and 16–19).

A study runs one block at successive refinements (time step or mesh) and
compares scalar measures between neighbouring levels: the first post-impact
peak, the first ten peaks, the rest time and the whole angle history. A
measure is "converged" when its last difference is within tolerance,
"converging" when it is not yet but the differences shrink at least as fast
as an order-1/2 method would (half the scheme's first order), and "not
converged" when they do not decrease, or more slowly — the loss of
convergence paper 002 reports for flexible beams is flagged, not silently
plotted. The rest time is "undetermined" when the two finest runs are still
rocking at t_end; a study's status is its worst determined verdict.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from impact_models import housner_eta

from multimass.errors import InputError

from .model import flexible_modulus, load_block
from .simulate import NSCDResult, simulate

__all__ = ["Verdict", "Study", "FirstPeakStudy", "judge", "compare_runs", "housner_first_peak",
           "dt_study", "mesh_study", "first_peak_study", "flexibility_study", "TOLERANCES",
           "MIN_ORDER"]

#: smallest observed order for "converging": d_last ≤ d_prev · ratio^(−MIN_ORDER)
MIN_ORDER = 0.5
#: default tolerances of the measures (deg, deg, s, deg)
TOLERANCES = {"first_peak_deg": 0.02, "peaks_deg": 0.05, "rest_time_s": 0.05, "history_deg": 0.5}
_UNITS = {"first_peak_deg": "deg", "peaks_deg": "deg", "rest_time_s": "s", "history_deg": "deg"}
N_PEAKS_COMPARED = 10


def housner_first_peak(block, theta0: float) -> float:
    """Exact first post-impact peak (rad) of a rigid block with Housner's restitution.

    Energy from rest at θ0 to the impact, ω⁺ = η_H ω⁻ (paper 004, Eq 9), then
    energy to the next rest: cos(α − θ1) = cos α + η_H² (cos(α − |θ0|) − cos α).
    """
    blk = load_block(block)
    a, th0 = blk.alpha, abs(theta0)
    eta = housner_eta(a)
    return a - math.acos(math.cos(a) + eta**2 * (math.cos(a - th0) - math.cos(a)))


@dataclass(frozen=True)
class Verdict:
    """Successive differences of one measure along a refinement and the verdict."""

    measure: str
    unit: str
    levels: tuple
    values: tuple
    differences: tuple[float, ...]
    tolerance: float
    status: str
    reason: str = ""
    observed_order: tuple = ()

    def to_dict(self) -> dict:
        inf = [None if not math.isfinite(d) else d for d in self.differences]
        return {"measure": self.measure, "unit": self.unit, "levels": list(self.levels),
                "values": list(self.values), "differences": inf, "tolerance": self.tolerance,
                "status": self.status, "reason": self.reason,
                "observed_order": list(self.observed_order)}


def judge(measure: str, levels, values, differences, tolerance: float,
          ratio: float | None = None) -> Verdict:
    """Verdict on successive differences d_k between refinement levels k and k+1.

    "converged" if the last difference ≤ `tolerance`; otherwise "converging"
    if the last two differences shrink at least as an order-`MIN_ORDER`
    method's would, d_last ≤ d_prev · ratio^(−1/2) (0.71 for halving, 0.32
    for a decade; any decrease if `ratio` is None); else "not converged":
    the differences do not decrease, or too slowly to trust the finest level
    (also with a single difference above tolerance: nothing shows a
    decrease). `ratio` (> 1) is the refinement ratio; the observed order is
    p = log(d_k / d_(k+1)) / log(ratio).
    """
    d = [float(x) for x in differences]
    q = d[-1] / d[-2] if len(d) >= 2 and d[-2] > 0 else math.inf
    q_max = ratio ** -MIN_ORDER if ratio is not None and ratio > 1 else 1.0
    if d and d[-1] <= tolerance:
        status, reason = "converged", f"last difference {d[-1]:.3g} within tolerance {tolerance:g}"
    elif len(d) < 2:
        status, reason = "not converged", "one refinement above tolerance: no decrease shown"
    elif q <= q_max and q < 1.0:
        status, reason = "converging", f"differences shrink (ratio {q:.2f}) but exceed tolerance"
    elif q < 1.0:
        status, reason = "not converged", f"differences shrink too slowly (ratio {q:.2f} > {q_max:.2f})"
    else:
        status, reason = "not converged", f"differences do not decrease (ratio {q:.2f})"
    order = ()
    if ratio is not None and ratio > 1:
        order = tuple(math.log(d[k] / d[k + 1]) / math.log(ratio)
                      if 0 < d[k + 1] < math.inf and 0 < d[k] < math.inf else None
                      for k in range(len(d) - 1))
    return Verdict(measure, _UNITS.get(measure, ""), tuple(levels), tuple(values), tuple(d),
                   tolerance, status, reason, order)


def _history_difference(a: NSCDResult, b: NSCDResult) -> float:
    """max |θ_a(t) − θ_b(t)| (deg) on the coarser record's times, over the common span."""
    t = a.t if a.t.size <= b.t.size else b.t
    t = t[t <= min(a.t[-1], b.t[-1])]
    return float(np.degrees(np.max(np.abs(np.interp(t, a.t, a.theta) - np.interp(t, b.t, b.theta)))))


def _peaks_difference(a: NSCDResult, b: NSCDResult) -> float:
    k = min(N_PEAKS_COMPARED, len(a.peaks_deg), len(b.peaks_deg))
    if k == 0:
        return 0.0 if len(a.peaks_deg) == len(b.peaks_deg) else math.inf
    return float(np.max(np.abs(np.subtract(a.peaks_deg[:k], b.peaks_deg[:k]))))


def _scalar_difference(x, y) -> float:
    if x is None and y is None:
        return 0.0
    if x is None or y is None:     # one still rocking, the other at rest: not comparable
        return math.inf
    return abs(x - y)


def compare_runs(levels, runs: list[NSCDResult], ratio: float | None = None,
                 tolerances: dict | None = None) -> list[Verdict]:
    """Verdicts of the four measures along runs ordered coarse → fine."""
    tol = {**TOLERANCES, **(tolerances or {})}
    pairs = list(zip(runs[:-1], runs[1:]))
    rest = judge("rest_time_s", levels, [r.rest_time_s for r in runs],
                 [_scalar_difference(a.rest_time_s, b.rest_time_s) for a, b in pairs],
                 tol["rest_time_s"], ratio)
    if len(runs) >= 2 and runs[-1].rest_time_s is None and runs[-2].rest_time_s is None:
        rest = replace(rest, status="undetermined",
                       reason="still rocking at t_end at the two finest levels; extend t_end")
    return [
        judge("first_peak_deg", levels, [r.first_peak_deg for r in runs],
              [_scalar_difference(a.first_peak_deg, b.first_peak_deg) for a, b in pairs],
              tol["first_peak_deg"], ratio),
        judge("peaks_deg", levels, [len(r.peaks_deg) for r in runs],
              [_peaks_difference(a, b) for a, b in pairs], tol["peaks_deg"], ratio),
        rest,
        judge("history_deg", levels, [None] * len(runs),
              [_history_difference(a, b) for a, b in pairs], tol["history_deg"], ratio),
    ]


@dataclass(frozen=True)
class Study:
    """Runs of one block along one refinement (dt or mesh), with verdicts."""

    kind: str
    block: str
    levels: tuple
    runs: tuple[NSCDResult, ...]
    verdicts: tuple[Verdict, ...]
    settings: dict = field(default_factory=dict)

    @property
    def status(self) -> str:
        """The worst verdict over the measures ("undetermined" ones are left out)."""
        order = ("not converged", "converging", "converged")
        return min((v.status for v in self.verdicts if v.status in order), key=order.index,
                   default="undetermined")

    def to_dict(self) -> dict:
        return {"kind": self.kind, "block": self.block, "levels": list(self.levels),
                "status": self.status, "settings": self.settings,
                "verdicts": [v.to_dict() for v in self.verdicts],
                "runs": [r.summary() for r in self.runs]}


def _theta0(block, theta0):
    blk = load_block(block)
    if theta0 is not None:
        return float(theta0)
    if blk.reference.theta0_deg is None:
        raise InputError(f"`theta0` is required: block {blk.name!r} has no reference "
                         "theta0_deg; give the release angle in rad")
    return math.radians(blk.reference.theta0_deg)


def _study(kind, block, levels, ratio, run, label, progress, settings) -> Study:
    """Run `run(level)` for each level (reported through `progress`) and compare the runs."""
    runs = []
    for level in levels:
        runs.append(run(level))
        if progress:
            progress(f"{label(level)} done ({runs[-1].wall_time_s:.1f} s)")
    return Study(kind, load_block(block).name, tuple(levels), tuple(runs),
                 tuple(compare_runs(levels, runs, ratio)),
                 {"E_Pa": runs[0].params["E_Pa"], **settings})


def dt_study(block, dts=(1e-3, 1e-4, 1e-5, 1e-6), *, E=None, n_elements=6, t_end=4.0,
             theta0=None, progress=None, **kw) -> Study:
    """Time-step refinement (paper 002, Fig 10; dt from 1e-3 to 1e-6 s)."""
    th0 = _theta0(block, theta0)
    dts = sorted(dts, reverse=True)
    return _study("dt", block, dts, dts[0] / dts[1] if len(dts) > 1 else None,
                  lambda dt: simulate(block, theta0=th0, dt=dt, t_end=t_end, E=E,
                                      n_elements=n_elements, **kw),
                  lambda dt: f"dt = {dt:g} s", progress,
                  {"n_elements": n_elements, "t_end_s": t_end, "theta0_deg": math.degrees(th0)})


def mesh_study(block, meshes=(3, 6, 12), *, dt=1e-5, E=None, t_end=4.0, theta0=None,
               progress=None, **kw) -> Study:
    """Mesh refinement (paper 002, Fig 11: 3, 6 and 12 elements)."""
    th0 = _theta0(block, theta0)
    meshes = sorted(meshes)
    return _study("mesh", block, meshes, meshes[1] / meshes[0] if len(meshes) > 1 else None,
                  lambda n: simulate(block, theta0=th0, dt=dt, t_end=t_end, E=E, n_elements=n,
                                     **kw),
                  lambda n: f"{n} elements", progress,
                  {"dt_s": dt, "t_end_s": t_end, "theta0_deg": math.degrees(th0)})


@dataclass(frozen=True)
class FirstPeakStudy:
    """First post-impact peak against the exact Housner value as dt → 0."""

    blocks: tuple[str, ...]
    dts: tuple[float, ...]
    exact_deg: dict
    paper_deg: dict
    peaks_deg: dict
    errors_deg: dict
    fitted_order: dict
    successive_order: dict

    def to_dict(self) -> dict:
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in self.__dict__.items()}


def first_peak_study(blocks=("B4M", "B6M", "B8M"), dts=None, *, t_end=2.0, E=None,
                     n_elements=6, progress=None) -> FirstPeakStudy:
    """First peak of each block for dt → 0 against the exact rigid-block value.

    The observed order is the least-squares slope of log|error| against
    log dt (the error of one impact in an event-capturing scheme depends on
    where the impact falls inside a step, so successive ratios scatter);
    successive orders between decades are given too.
    """
    dts = tuple(sorted(dts or (1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6, 1e-6),
                       reverse=True))
    names, exact, paper, peaks, errors, fit, succ = [], {}, {}, {}, {}, {}, {}
    for block in blocks:
        blk = load_block(block)
        th0 = _theta0(blk, None)
        ex = math.degrees(housner_first_peak(blk, th0))
        vals = []
        for dt in dts:
            r = simulate(blk, theta0=th0, dt=dt, t_end=t_end, E=E, n_elements=n_elements)
            vals.append(r.first_peak_deg)
            if progress:
                progress(f"{blk.name} dt = {dt:g} s: first peak {r.first_peak_deg:.4f}°")
        err = [abs(v - ex) for v in vals]
        names.append(blk.name)
        exact[blk.name], paper[blk.name] = ex, blk.reference.first_peak_deg
        peaks[blk.name], errors[blk.name] = vals, err
        ok = [(math.log(d), math.log(e)) for d, e in zip(dts, err) if e > 0]
        fit[blk.name] = float(np.polyfit(*zip(*ok), 1)[0]) if len(ok) >= 2 else None
        decades = [i for i, d in enumerate(dts) if abs(math.log10(d) - round(math.log10(d))) < 1e-9]
        succ[blk.name] = [math.log10(err[i] / err[j]) / math.log10(dts[i] / dts[j])
                          if err[i] > 0 and err[j] > 0 else None
                          for i, j in zip(decades[:-1], decades[1:])]
    return FirstPeakStudy(tuple(names), dts, exact, paper, peaks, errors, fit, succ)


def flexibility_study(block, exponents=(8, 6, 4, 2, 0), *, meshes=(6, 12, 24),
                      dts=(1e-4, 1e-5, 1e-6), base_dt=1e-5, base_mesh=6, t_end=4.0,
                      theta0=None, progress=None, **kw) -> dict:
    """Flexibility sweep E = Ē·10ⁿ with mesh and time-step sensitivity (paper 002, Figs 16–19).

    Ē gives a midspan deflection of L/2500 under the block's weight. For each
    n, a mesh study (at `base_dt`) and a dt study (at `base_mesh`) are run;
    the run at (base_dt, base_mesh) is shared. A rigid-base run (the beam
    specimen's E) is included for comparison.

    Returns
    -------
    dict
        ``{"E_bar": Ē, "rigid": NSCDResult, "base": {n: NSCDResult},
        "mesh": {n: Study}, "dt": {n: Study}, ...}``; "base" is the run at
        (`base_dt`, `base_mesh`).
    """
    th0 = _theta0(block, theta0)
    name = load_block(block).name
    Ebar = flexible_modulus(block)
    out = {"E_bar": Ebar, "block": name, "theta0": th0, "exponents": tuple(exponents),
           "rigid": simulate(block, theta0=th0, dt=base_dt, t_end=t_end, n_elements=base_mesh, **kw),
           "base": {}, "mesh": {}, "dt": {}}
    for n in exponents:
        E = Ebar * 10.0**n
        cache = {}

        def run(dt, m):
            if (dt, m) not in cache:
                cache[dt, m] = simulate(block, theta0=th0, dt=dt, t_end=t_end, E=E,
                                        n_elements=m, **kw)
                if progress:
                    progress(f"n = {n}: dt = {dt:g} s, {m} elements ({cache[dt, m].wall_time_s:.1f} s)")
            return cache[dt, m]

        ms, ds = sorted(set(meshes) | {base_mesh}), sorted(set(dts) | {base_dt}, reverse=True)
        mesh_runs = [run(base_dt, m) for m in ms]
        dt_runs = [run(dt, base_mesh) for dt in ds]
        out["base"][n] = run(base_dt, base_mesh)
        settings = {"E_Pa": E, "exponent": n, "t_end_s": t_end, "theta0_deg": math.degrees(th0)}
        out["mesh"][n] = Study("mesh", name, tuple(ms), tuple(mesh_runs),
                               tuple(compare_runs(ms, mesh_runs, ms[1] / ms[0])),
                               {**settings, "dt_s": base_dt})
        out["dt"][n] = Study("dt", name, tuple(ds), tuple(dt_runs),
                             tuple(compare_runs(ds, dt_runs, ds[0] / ds[1])),
                             {**settings, "n_elements": base_mesh})
    return out
