"""A recorded trace cut into rocking half-cycles, impacts and full-contact stretches.

Paper 001 analysed its tests half-cycle by half-cycle (Sections 4.2–4.3): the
restitution of each impact from the peaks around it, the operational shapes from the
accelerations inside each half-cycle. `segment_trace` finds those pieces from the
base rotation θ alone, with rules that hold on noisy records:

1. **Noise and smoothing.** θ is low-passed zero-phase (4th-order Butterworth, forward
   and backward, cut-off `cutoff_hz`, default 20 Hz: rocking itself is slower, its
   kinks at impacts are kept to a few ms); the noise σ is the robust spread
   (1.4826 × median absolute deviation) of the raw minus the smoothed signal, scaled by
   the share of white noise the filter passes.
2. **Quiet band.** A sample is quiet when the smoothed ``|θ − b|`` is within
   ``h = max(k σ_s, theta_floor)``, σ_s the noise left after smoothing and ``k = 4``;
   the bias b is the median θ over the quiet runs of the first pass that last
   `min_rest` (0 without any).
3. **Excursions.** A rocking excursion is a maximal run of samples outside the band
   on one side, at least 20 ms long (shorter ones are noise). Between two
   excursions the quiet gap is a *crossing* if it is shorter than `min_rest`
   (default 0.1 s): an **impact** when the sign changes (the corner
   of the new side is hit: θ > 0 after it is rocking about the right pivot, "right"
   corner), a bounce and uplift on the same side otherwise; a longer gap is **full
   contact**. A free release is a first excursion that starts at the first sample.
4. **Impact time**: the zero crossing of the smoothed θ − b inside the gap (linear
   between samples). **Peak**: the vertex of a least-squares parabola through the
   raw samples where the smoothed ``|θ − b|`` exceeds 60 % of its maximum (at least
   5), so noise averages out instead of biasing the maximum high. This is the peak
   of the rocking motion: the uplifted vibration that rides on θ (the compound modes
   move θ too, by a few mrad in S1 at 20 Hz) averages out as well, so small peaks
   read lower than the maximum of θ itself. A free release's peak is the median of
   the samples held near the release angle.

An excursion whose peak is below `theta_min` (paper 001, Section 4.3: 0.01 rad) is
kept but flagged `small`; identification steps decide what to do with it.

>>> from multimass import FreeRelease
>>> from multimass.identify import synthetic_trace
>>> syn = synthetic_trace("S1", FreeRelease(theta0=0.11), "DD2", 3.0, seed=2)
>>> seg = segment_trace(syn.trace)
>>> seg.half_cycles[0].begins, seg.impacts[0].corner
('release', 'left')
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import signal

from .. import validation as v
from ..errors import InputError
from ..inputs.traces import Trace
from ..modal.errors import ModalError
from ..modal.measured_frf import sampling_rate

__all__ = ["HalfCycle", "ImpactMark", "Segments", "segment_trace", "require_trace", "THETA_MIN"]

#: Paper 001, Section 4.3: half-cycles below this peak (rad) take the corner means.
THETA_MIN = 0.01
_K_BAND = 4.0  # the quiet band is this many smoothed-noise standard deviations
_PEAK_SHARE = 0.6  # the parabola through the samples above this share of the peak
_MIN_EXCURSION = 0.02  # s: shorter runs outside the band are noise
_CUTOFF_SHARE = 0.45  # θ's low-pass stays below this share of the sampling rate


@dataclass(frozen=True)
class HalfCycle:
    """One rocking excursion of a trace, on one side.

    Attributes
    ----------
    start, stop : int
        Sample index range [start, stop) of the trace: from the last quiet sample
        before it (or 0) to the first quiet sample after it (or the end).
    t_start, t_stop : float
        Trace times (s) of its start (the release, the impact or uplift that began it)
        and of its end (the next impact or return to full contact, or the last sample).
    sign : int
        +1 for θ > 0 (rocking about the right pivot), −1 for θ < 0.
    peak : float
        Its peak ``|θ − b|`` (rad), b the trace's θ bias; for a free release the
        release angle.
    t_peak : float
        Time of the peak (s).
    begins : str
        "release", "impact", "uplift" (from full contact, or a bounce on the same
        side), or "start" (rocking when the trace starts).
    ends : str
        "impact", "full_contact" or "end" (the trace ends).
    small : bool
        Its peak is below `Segments.theta_min`.
    """

    start: int
    stop: int
    t_start: float
    t_stop: float
    sign: int
    peak: float
    t_peak: float
    begins: str
    ends: str
    small: bool


@dataclass(frozen=True)
class ImpactMark:
    """An impact found in a trace: the half-cycle before it ends at `t`, the next begins.

    Attributes
    ----------
    t : float
        Trace time (s): the zero crossing of θ − b.
    corner : str
        The corner it lands on: "right" (θ > 0 after it) or "left".
    before, after : int
        Indices into `Segments.half_cycles`.
    """

    t: float
    corner: str
    before: int
    after: int


@dataclass(frozen=True, eq=False)
class Segments:
    """What `segment_trace` found in a trace.

    Attributes
    ----------
    trace : Trace
    half_cycles : tuple of HalfCycle
        In time order.
    impacts : tuple of ImpactMark
        In time order; one between every two consecutive half-cycles of opposite sign
        that no full contact separates.
    full_contact : tuple of (int, int)
        Index ranges [start, stop) of quiet stretches of at least `min_rest`.
    noise : float
        The θ channel's white-noise standard deviation (rad), estimated.
    bias : float
        θ while at rest on the base (rad), estimated (0 without full contact).
    band : float
        Half-width of the quiet band (rad).
    fs : float
        Sampling rate (Hz).
    theta_min : float
        Half-cycles below this peak (rad) are `small`.
    smooth : ndarray
        The smoothed θ − bias.
    """

    trace: Trace
    half_cycles: tuple
    impacts: tuple
    full_contact: tuple
    noise: float
    bias: float
    band: float
    fs: float
    theta_min: float
    smooth: np.ndarray

    @property
    def free_release(self) -> bool:
        """True if the trace starts held at a release angle (a free-vibration test)."""
        return bool(self.half_cycles) and self.half_cycles[0].begins == "release"

    def to_pandas(self) -> pd.DataFrame:
        """One row per half-cycle (times in s, peaks in rad)."""
        rows = [vars(h) for h in self.half_cycles]
        cols = list(HalfCycle.__dataclass_fields__)
        return pd.DataFrame(rows, columns=cols)


def require_trace(trace) -> Trace:
    """`trace` if it is a `Trace`, else the InputError every trace tool gives."""
    if not isinstance(trace, Trace):
        raise InputError(
            f"`trace` = {type(trace).__name__}: give a multimass.inputs.traces.Trace "
            "(read one with multimass.read_trace)"
        )
    return trace


def _theta(trace: Trace) -> np.ndarray:
    th = require_trace(trace).channels.get("theta")
    if th is None:
        raise InputError(
            f"{trace.source}: no `theta` column; the half-cycles and impacts are found from "
            "the base rotation θ: add a column `theta [rad]` (or `[deg]`)"
        )
    return np.asarray(th, dtype=float)


def segment_trace(
    trace: Trace,
    *,
    theta_min: float = THETA_MIN,
    cutoff_hz: float = 20.0,
    min_rest: float = 0.1,
    theta_floor: float = 1e-5,
) -> Segments:
    """Cut a trace into rocking half-cycles, impacts and full-contact stretches.

    Parameters
    ----------
    trace : Trace
        A recorded trace with a θ channel, uniformly sampled.
    theta_min : float, optional
        Half-cycles with a lower peak (rad) are flagged `small` (default 0.01, paper
        001 Section 4.3).
    cutoff_hz : float, optional
        Cut-off of the zero-phase low-pass applied to θ (Hz; below 0.45 × the
        sampling rate, so the default 20 needs a trace sampled at 45 Hz or more).
    min_rest : float, optional
        Shortest quiet stretch (s) counted as full contact (default 0.1).
    theta_floor : float, optional
        Smallest half-width of the quiet band (rad), for noiseless traces.

    Returns
    -------
    Segments

    Raises
    ------
    InputError
        No θ channel, non-uniform sampling, a sampling rate too low for `cutoff_hz`, too
        few samples, or an argument out of range (named).
    """
    th = _theta(trace)
    theta_min = v.positive("theta_min", theta_min, "rad")
    min_rest = v.positive("min_rest", min_rest, "s")
    theta_floor = v.positive("theta_floor", theta_floor, "rad")
    try:
        fs = sampling_rate(trace.time)
    except ModalError as err:
        raise InputError(f"{trace.source}: {err}") from None
    cutoff_hz = v.positive("cutoff_hz", cutoff_hz, "Hz")
    if cutoff_hz > _CUTOFF_SHARE * fs:  # the trace is too slow for θ's low-pass
        raise InputError(
            f"{trace.source}: sampled at {fs:.4g} Hz, too slow to cut θ into half-cycles: "
            f"θ is low-passed at cutoff_hz = {cutoff_hz:g} Hz, which must stay below "
            f"{_CUTOFF_SHARE:g} × the sampling rate = {_CUTOFF_SHARE * fs:.3g} Hz; record at "
            f"{math.ceil(cutoff_hz / _CUTOFF_SHARE)} Hz or more (or, in Python, give "
            "segment_trace a lower cutoff_hz)"
        )
    if th.size < 32:
        raise InputError(
            f"{trace.source}: {th.size} samples; segmenting needs at least 32 (a longer record)"
        )
    sos = signal.butter(4, cutoff_hz, fs=fs, output="sos")
    smooth = signal.sosfiltfilt(sos, th)
    resid = th - smooth
    share = np.sqrt(max(1.0 - 2.0 * cutoff_hz / fs, 0.05))  # white noise the filter removes
    noise = 1.4826 * float(np.median(np.abs(resid - np.median(resid)))) / share
    band = max(_K_BAND * noise * np.sqrt(2.0 * cutoff_hz / fs), theta_floor)
    n_rest = max(int(round(min_rest * fs)), 2)
    bias = 0.0
    quiet = _runs(np.abs(smooth) <= band)
    rests = [(a, b) for a, b in quiet if b - a >= n_rest]
    if rests:
        bias = float(np.median(np.concatenate([th[a:b] for a, b in rests])))
    x = smooth - bias
    side = np.where(x > band, 1, np.where(x < -band, -1, 0))
    n_min = max(3, int(round(_MIN_EXCURSION * fs)))
    for a, b in _runs(side != 0, values=side):
        if b - a < n_min:  # noise poking out of the band (e.g. at the ends)
            side[a:b] = 0
    runs = [(a, b, int(side[a])) for a, b in _runs(side != 0, values=side)]
    half, impacts, contact = _assemble(trace.time, th - bias, x, runs, n_rest, theta_min, band)
    return Segments(
        trace, tuple(half), tuple(impacts), tuple(contact), noise, bias, band, fs, theta_min, x
    )


def _runs(mask: np.ndarray, values: np.ndarray | None = None) -> list[tuple[int, int]]:
    """Maximal runs [a, b) where `mask` holds (and `values`, if given, stays the same)."""
    key = mask.astype(np.int64) if values is None else np.where(mask, values, 0)
    edges = np.flatnonzero(np.diff(key)) + 1
    starts = np.concatenate([[0], edges])
    stops = np.concatenate([edges, [key.size]])
    return [(int(a), int(b)) for a, b in zip(starts, stops) if mask[a]]


def _crossing(t: np.ndarray, x: np.ndarray, a: int, b: int) -> float:
    """Time where x changes sign between samples a and b (the last change; linear)."""
    seg = x[a : b + 1]
    k = np.flatnonzero(np.sign(seg[:-1]) != np.sign(seg[1:]))
    if k.size == 0:
        return float(0.5 * (t[a] + t[b]))
    i = a + int(k[-1])
    return float(t[i] + (t[i + 1] - t[i]) * x[i] / (x[i] - x[i + 1]))


def _peak(t: np.ndarray, raw: np.ndarray, x: np.ndarray, a: int, b: int, sign: int):
    """(peak |θ|, time): the vertex of a parabola through the samples near the maximum."""
    y = sign * x[a:b]
    k = a + int(np.argmax(y))
    near = np.flatnonzero(y >= _PEAK_SHARE * y.max()) + a
    lo, hi = int(near.min()), int(near.max()) + 1
    while hi - lo < 5 and (lo > a or hi < b):
        lo, hi = max(lo - 1, a), min(hi + 1, b)
    tt = t[lo:hi] - t[k]
    if tt.size >= 5:
        c2, c1, c0 = np.polyfit(tt, sign * raw[lo:hi], 2)
        if c2 < 0.0:
            tv = -c1 / (2.0 * c2)
            if tt[0] <= tv <= tt[-1]:
                return float(c0 - c1 * c1 / (4.0 * c2)), float(t[k] + tv)
    return float(sign * raw[k]), float(t[k])


def _assemble(t, raw, x, runs, n_rest: int, theta_min: float, band: float):
    """Half-cycles, impacts and full-contact ranges from the excursion runs."""
    half, impacts, contact = [], [], []
    n = t.size
    if not runs:
        return half, impacts, [(0, n)] if n >= n_rest else []
    if runs[0][0] >= n_rest:
        contact.append((0, runs[0][0]))
    starts = []  # (begins, t_start, start index) per run
    ends = []
    for j, (a, b, sgn) in enumerate(runs):
        if j == 0:
            if a == 0:
                # held at its release angle before it lets go: the largest angle comes
                # early, or (a noisy hold, whose largest sample is noise) the first samples
                # sit within the quiet band's width of the run's upper tenth; a trace that
                # starts mid-swing starts well below it
                y = sgn * x[a:b]
                top = int(np.argmax(y))
                head = float(np.median(y[: min(10, y.size)]))
                held = head >= float(np.quantile(y, 0.9)) - band
                begins = "release" if top <= 0.15 * (b - a) or held else "start"
                starts.append((begins, float(t[0]), 0))
            else:
                starts.append(("uplift", float(t[a - 1]), a - 1))
            continue
        pa, pb, psgn = runs[j - 1]
        gap = a - pb
        if gap >= n_rest:
            ends.append(("full_contact", float(t[pb]), pb + 1))
            contact.append((pb, a))
            starts.append(("uplift", float(t[a - 1]), a - 1))
        elif psgn != sgn:
            tc = _crossing(t, x, pb - 1, a)
            ends.append(("impact", tc, a))
            starts.append(("impact", tc, pb - 1))
        else:
            ends.append(("full_contact", float(t[pb]), pb + 1))
            starts.append(("uplift", float(t[a - 1]), a - 1))
    last_b = runs[-1][1]
    if n - last_b >= n_rest:
        ends.append(("full_contact", float(t[last_b]), last_b + 1))
        contact.append((last_b, n))
    else:
        ends.append(("end", float(t[-1]), n))
    for j, (a, b, sgn) in enumerate(runs):
        begins, t0, i0 = starts[j]
        kind, t1, i1 = ends[j]
        if begins == "release":  # held still, then slow to leave: the samples near the top
            y = sgn * x[a:b]
            held = np.flatnonzero(y >= y.max() - 0.5 * band)
            top = raw[a : a + max(3, (int(held.max()) + 1) // 2)]
            peak, t_peak = float(sgn * np.median(top)), float(t[0])
        else:
            peak, t_peak = _peak(t, raw, x, a, b, sgn)
        half.append(
            HalfCycle(i0, min(i1, n), t0, t1, sgn, peak, t_peak, begins, kind, peak < theta_min)
        )
        if begins == "impact":
            impacts.append(ImpactMark(t0, "right" if sgn > 0 else "left", j - 1, j))
    return half, impacts, contact
