"""Verdicts on successive refinements of the Moreau–Jean simulation: detection of
non-convergence (paper 002, Sections 6.1 and 6.3, Figs 10–11 and 16–19).

A study runs one block at successive refinements (time step or mesh) and
compares scalar measures between neighbouring levels: the first post-impact
peak, the first ten post-impact peaks, the rest time and the whole angle
history (angles in degrees, as paper 002 reports them; the measure's name ends
with its unit). A
measure is "converged" when its last difference is within tolerance,
"converging" when it is not yet but the differences shrink at least as fast
as an order-1/2 method would (half the scheme's first order), and "not
converged" when they do not decrease, or more slowly — the loss of
convergence paper 002 reports for flexible beams is flagged, not silently
plotted. The rest time is "undetermined" when the two finest runs are still
rocking at t_end; a study's status is its worst determined verdict, or
"failed" when one of its runs failed (its series stops early: nothing to
compare).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from multimass.impact_models import housner_eta

from .model import load_block
from .result import NSCDResult

__all__ = [
    "Verdict",
    "Study",
    "judge",
    "compare_runs",
    "housner_first_peak",
    "TOLERANCES",
    "MIN_ORDER",
    "N_PEAKS_COMPARED",
]

#: smallest observed order for "converging": d_last ≤ d_prev · ratio^(−MIN_ORDER)
MIN_ORDER = 0.5
#: default tolerances of the measures (deg, deg, s, deg)
TOLERANCES = {"first_peak_deg": 0.02, "peaks_deg": 0.05, "rest_time_s": 0.05, "history_deg": 0.5}
_UNITS = {"first_peak_deg": "deg", "peaks_deg": "deg", "rest_time_s": "s", "history_deg": "deg"}
N_PEAKS_COMPARED = 10


def housner_first_peak(block, theta0: float) -> float:
    """Exact first post-impact peak (rad) of a rigid block with Housner's restitution.

    Energy from rest at θ0 to the impact, ω⁺ = η_H ω⁻ (paper 004, Eq 9), then
    energy to the next rest: ``cos(α − θ1) = cos α + η_H² (cos(α − |θ0|) − cos α)``.
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
        return {
            "measure": self.measure,
            "unit": self.unit,
            "levels": list(self.levels),
            "values": list(self.values),
            "differences": inf,
            "tolerance": self.tolerance,
            "status": self.status,
            "reason": self.reason,
            "observed_order": list(self.observed_order),
        }


def judge(
    measure: str, levels, values, differences, tolerance: float, ratio: float | None = None
) -> Verdict:
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
    q_max = ratio**-MIN_ORDER if ratio is not None and ratio > 1 else 1.0
    if d and d[-1] <= tolerance:
        status, reason = "converged", f"last difference {d[-1]:.3g} within tolerance {tolerance:g}"
    elif len(d) < 2:
        status, reason = "not converged", "one refinement above tolerance: no decrease shown"
    elif q <= q_max and q < 1.0:
        status, reason = "converging", f"differences shrink (ratio {q:.2f}) but exceed tolerance"
    elif q < 1.0:
        status, reason = (
            "not converged",
            f"differences shrink too slowly (ratio {q:.2f} > {q_max:.2f})",
        )
    else:
        status, reason = "not converged", f"differences do not decrease (ratio {q:.2f})"
    order = ()
    if ratio is not None and ratio > 1:
        order = tuple(
            math.log(d[k] / d[k + 1]) / math.log(ratio)
            if 0 < d[k + 1] < math.inf and 0 < d[k] < math.inf
            else None
            for k in range(len(d) - 1)
        )
    return Verdict(
        measure,
        _UNITS.get(measure, ""),
        tuple(levels),
        tuple(values),
        tuple(d),
        tolerance,
        status,
        reason,
        order,
    )


def _history_difference(a: NSCDResult, b: NSCDResult) -> float:
    """max |θ_a(t) − θ_b(t)| (deg) on the coarser record's times, over the common span."""
    t = a.t if a.t.size <= b.t.size else b.t
    t = t[t <= min(a.t[-1], b.t[-1])]
    return float(
        np.degrees(np.max(np.abs(np.interp(t, a.t, a.theta) - np.interp(t, b.t, b.theta))))
    )


def _post_impact_peaks_deg(r: NSCDResult) -> np.ndarray:
    """The peaks after the release (deg): those of the half-cycles that follow an impact."""
    return np.degrees(r.peaks[1:])


def _first_peak_deg(r: NSCDResult) -> float | None:
    return None if r.first_peak is None else math.degrees(r.first_peak)


def _peaks_difference(a: NSCDResult, b: NSCDResult) -> float:
    """Largest difference (deg) of the first `N_PEAKS_COMPARED` peaks after the release."""
    pa, pb = _post_impact_peaks_deg(a), _post_impact_peaks_deg(b)
    k = min(N_PEAKS_COMPARED, len(pa), len(pb))
    if k == 0:
        return 0.0 if len(pa) == len(pb) else math.inf
    return float(np.max(np.abs(pa[:k] - pb[:k])))


def _scalar_difference(x, y) -> float:
    if x is None and y is None:
        return 0.0
    if x is None or y is None:  # one still rocking, the other at rest: not comparable
        return math.inf
    return abs(x - y)


def compare_runs(
    levels, runs: list[NSCDResult], ratio: float | None = None, tolerances: dict | None = None
) -> list[Verdict]:
    """Verdicts of the four measures along runs ordered coarse → fine."""
    tol = {**TOLERANCES, **(tolerances or {})}
    pairs = list(zip(runs[:-1], runs[1:]))
    rest = judge(
        "rest_time_s",
        levels,
        [r.rest_time for r in runs],
        [_scalar_difference(a.rest_time, b.rest_time) for a, b in pairs],
        tol["rest_time_s"],
        ratio,
    )
    if len(runs) >= 2 and runs[-1].rest_time is None and runs[-2].rest_time is None:
        rest = replace(
            rest,
            status="undetermined",
            reason="still rocking at t_end at the two finest levels; extend t_end",
        )
    return [
        judge(
            "first_peak_deg",
            levels,
            [_first_peak_deg(r) for r in runs],
            [_scalar_difference(_first_peak_deg(a), _first_peak_deg(b)) for a, b in pairs],
            tol["first_peak_deg"],
            ratio,
        ),
        judge(
            "peaks_deg",
            levels,
            [len(r.peaks) - 1 for r in runs],
            [_peaks_difference(a, b) for a, b in pairs],
            tol["peaks_deg"],
            ratio,
        ),
        rest,
        judge(
            "history_deg",
            levels,
            [None] * len(runs),
            [_history_difference(a, b) for a, b in pairs],
            tol["history_deg"],
            ratio,
        ),
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
        """The worst verdict over the measures ("undetermined" ones are left out), or
        "failed" when a run failed (its series stops early: nothing to compare)."""
        if any(r.outcome == "failed" for r in self.runs):
            return "failed"
        order = ("not converged", "converging", "converged")
        return min(
            (v.status for v in self.verdicts if v.status in order),
            key=order.index,
            default="undetermined",
        )

    @property
    def warnings(self) -> tuple[str, ...]:
        """The runs' warnings, each prefixed by its level, and runs that failed."""
        out = []
        for lev, r in zip(self.levels, self.runs):
            label = f"dt = {lev:g} s" if self.kind == "dt" else f"{lev} elements"
            if r.outcome == "failed":
                out.append(f"{label}: the run failed: {r.message}")
            out += [f"{label}: {w}" for w in r.warnings]
        return tuple(out)

    def to_dict(self) -> dict:
        return {
            "kind": self.kind,
            "block": self.block,
            "levels": list(self.levels),
            "status": self.status,
            "warnings": list(self.warnings),
            "settings": self.settings,
            "verdicts": [v.to_dict() for v in self.verdicts],
            "runs": [r.summary() for r in self.runs],
        }
