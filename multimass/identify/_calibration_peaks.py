"""Peaks of rocking half-cycles, measured and simulated alike (`multimass.identify.calibrate`).

A half-cycle's peak is the vertex of the least-squares parabola through |θ| over the
middle half of the half-cycle (from a quarter to three quarters of the time between
the impacts that bound it): the vibration that rides on θ (a few mrad at 20 Hz in
S1) and the sensor noise average out, and the measured and simulated peaks are the
same estimator of the same signal. On the trace the samples in that window are used;
on a simulation, 41 points of its recorded θ spread over its own window (its impact
times from its events), so the simulated peak moves continuously with the model's
parameters. (`segment_trace`'s peaks, a parabola over the samples above 60 % of the
maximum, jump when a sample crosses that threshold: on S2 their derivatives with
respect to a restitution mean changed sign and size from one step to the next.)
"""

from __future__ import annotations

import numpy as np

__all__ = ["measured_peaks", "model_peaks", "parabola_peak", "crossings"]

_WINDOW = (0.25, 0.75)  # the part of a half-cycle fitted, as fractions of its duration
_POINTS = 41


def parabola_peak(t: np.ndarray, y: np.ndarray) -> float:
    """The extremum of the LS parabola through (t, |y|), clipped to the window's span."""
    y = np.abs(np.asarray(y, dtype=float))
    if y.size < 3:
        return float(np.max(y)) if y.size else 0.0
    t = np.asarray(t, dtype=float)
    tc = 0.5 * (t[0] + t[-1])
    a, b, c = np.polyfit(t - tc, y, 2)
    if a >= 0.0:  # not a cap: the window's largest fitted value
        ends = np.polyval([a, b, c], [t[0] - tc, t[-1] - tc])
        return float(max(ends.max(), np.polyval([a, b, c], 0.0)))
    tv = np.clip(-b / (2.0 * a), t[0] - tc, t[-1] - tc)
    return float(np.polyval([a, b, c], tv))


def measured_peaks(case) -> np.ndarray:
    """Peaks (rad, from θ's bias) of the trace's large half-cycles; the release's is its
    held value (replaced by the fitted θ0 where it matters)."""
    cached = getattr(case, "_peaks", None)
    if cached is not None and cached.size == len(case.large):
        return cached
    theta = np.asarray(case.trace.channels["theta"], dtype=float) - case.segments.bias
    t = case.t
    out = []
    for h in case.large:
        if h.begins == "release":
            out.append(h.peak)
            continue
        lo, hi = (h.t_start + f * (h.t_stop - h.t_start) for f in _WINDOW)
        m = (t >= lo) & (t <= hi)
        out.append(parabola_peak(t[m], theta[m]) if np.count_nonzero(m) >= 3 else h.peak)
    peaks = np.array(out)
    object.__setattr__(case, "_peaks", peaks)
    return peaks


def crossings(events, side: int) -> list[float]:
    """Times the simulated rocking changes side, as a trace shows it: an impact onto the
    other pivot, or full contact followed by an uplift onto the other pivot (at the
    time of the full contact). Counting impact events alone, an impact that turned
    into full contact and uplift (S2 at 0.01–0.02 rad) dropped out of the list and
    every later half-cycle was matched with the wrong one.

    Parameters
    ----------
    events : list of Event
    side : int
        The rocking side at the start: sign(θ0) for a release, 0 from rest.
    """
    out, zero = [], None
    for e in events:
        if e.kind == "full_contact":
            zero = e.time
        elif e.kind in ("impact", "uplift"):
            new = int(np.sign(e.phase_after or 0))
            if new and side and new != side:
                out.append(e.time if e.kind == "impact" else (zero if zero is not None else e.time))
            if new:
                side = new
            zero = None
    return out


def model_peaks(case, rec, n: int, floor: float) -> np.ndarray:
    """The first `n` half-cycle peaks of a recorded run of `case` (the release first: its
    held θ0), each over its window between the simulated impacts that bound it. A
    half-cycle after the simulation's last impact (rocking that ended in full contact)
    gets its largest |θ|, the ones after it `floor`; every peak is at least `floor`."""
    side = int(np.sign(case.theta0)) if case.free else 0
    times = crossings(rec.response.events, side)
    j0 = case.first_impact
    out = np.full(n, floor)
    if n and case.free:
        out[0] = abs(float(rec.at("theta", np.array([-0.01]))[0]))
    for k in range(1, n):
        j = j0 + k  # half-cycle k runs from impact j − 1 to impact j
        if j - 1 >= len(times):
            break
        a = times[j - 1]
        if j < len(times):
            lo, hi = (a + f * (times[j] - a) for f in _WINDOW)
            tm = np.linspace(lo, hi, _POINTS)
            out[k] = parabola_peak(tm, rec.at("theta", tm))
        else:
            tm = np.linspace(a, min(a + 2.0, rec.span[1]), 4 * _POINTS)
            out[k] = float(np.max(np.abs(rec.at("theta", tm))))
            break
    return np.maximum(out, floor)
