"""Measured frequency responses: the H1 estimator over full-contact segments of a trace.

H1(f) = S_xy(f) / S_xx(f), the cross-spectral density of the input x = ü_g and an
output y (a sensor's total acceleration) over the input's auto-spectral density,
both Welch averages (`scipy.signal.csd`, `scipy.signal.welch`); the ordinary
coherence γ²(f) = ``|S_xy|²`` / (S_xx S_yy) says how much of the output is linear in the
input (Bendat & Piersol, *Random Data*, 4th ed., Chapters 6 and 9). Noise on the
output that is uncorrelated with ü_g does not bias H1 (it lowers γ²); noise on the
input biases ``|H1|`` low.

The estimate is compared with the model's `multimass.modal.frf` of the full-contact
phase: only while the structure sits on its base is it the linear system of paper
001, Eq 3. `full_contact_segments` finds those stretches of a trace from θ; the
rule is stated there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import signal

from .errors import ModalError

__all__ = [
    "MeasuredFRF",
    "h1_estimate",
    "full_contact_segments",
    "full_contact_h1",
    "sampling_rate",
    "THETA_MAX",
    "MIN_PERIODS",
]

#: Default ``|θ|`` (rad) below which a trace sample counts as full contact (≈ 0.011°).
THETA_MAX = 2e-4
#: Default shortest full-contact segment, in periods of the first full-contact mode.
MIN_PERIODS = 10.0
_JITTER = 1e-3  # largest relative deviation of a time step from the mean step


@dataclass(frozen=True, eq=False)
class MeasuredFRF:
    """An H1 estimate; unpacks as ``freq_hz, H, coherence = h1_estimate(...)``.

    Attributes
    ----------
    freq_hz : ndarray, shape (n_freq,)
        Frequencies (Hz), 0 to the Nyquist frequency in steps of ``fs / nperseg``.
    H : ndarray, complex, shape (n_outputs, n_freq)
        H1 = S_xy / S_xx per output (output unit per input unit; m/s² per m/s²
        for accelerations). NaN where the input has no power.
    coherence : ndarray, shape (n_outputs, n_freq)
        Ordinary coherence γ² in [0, 1].
    outputs : tuple of str
        A name per row of `H`.
    segments : tuple of (int, int)
        Index ranges [start, stop) of the samples averaged.
    fs : float
        Sampling rate (Hz).
    nperseg : int
        Welch window length (samples); the frequency step is ``fs / nperseg``.
    n_averages : int
        Welch windows averaged over all segments (50 % overlap).
    skipped : tuple of (int, int)
        Full-contact segments found but shorter than `nperseg`, so not used
        (`full_contact_h1` only).
    t0 : float
        Time (s) of sample 0, so that sample i is at ``t0 + i / fs``.
    theta_max, min_periods : float or None
        The rule that found the segments (`full_contact_h1`; None when the
        segments were given).
    """

    freq_hz: np.ndarray
    H: np.ndarray
    coherence: np.ndarray
    outputs: tuple[str, ...]
    segments: tuple[tuple[int, int], ...]
    fs: float
    nperseg: int
    n_averages: int
    skipped: tuple[tuple[int, int], ...] = ()
    t0: float = 0.0
    theta_max: float | None = None
    min_periods: float | None = None

    def __iter__(self):
        return iter((self.freq_hz, self.H, self.coherence))

    def segment_times(self, which: str = "segments") -> tuple[tuple[float, float], ...]:
        """(first, last) sample time (s) of each range of ``segments`` (or ``skipped``)."""
        ranges = self.segments if which == "segments" else self.skipped
        return tuple((self.t0 + a / self.fs, self.t0 + (b - 1) / self.fs) for a, b in ranges)

    def random_error(self) -> np.ndarray:
        """Normalised random error of ``|H1|`` (also the s.d. of its phase in rad).

        ε = √(1 − γ²) / (``|γ|`` √(2 n_d)) with n_d = `n_averages` (Bendat & Piersol,
        *Random Data*, 4th ed., Chapter 9); shape (n_outputs, n_freq). Welch
        windows overlapping by 50 % are not independent, so the true error is a
        little larger.
        """
        g2 = np.clip(self.coherence, 1e-12, 1.0)
        return np.sqrt(1.0 - g2) / (np.sqrt(g2) * np.sqrt(2.0 * self.n_averages))

    def to_pandas(self) -> pd.DataFrame:
        """One row per frequency: ``freq_hz``, then ``|H|``, ``phase_deg`` and
        ``coherence`` of each output (columns ``<output> |H|`` etc.)."""
        cols = {"freq_hz": self.freq_hz}
        for name, h, c in zip(self.outputs, self.H, self.coherence):
            cols[f"{name} |H|"] = np.abs(h)
            cols[f"{name} phase_deg"] = np.degrees(np.angle(h))
            cols[f"{name} coherence"] = c
        return pd.DataFrame(cols)


def sampling_rate(t) -> float:
    """The sampling rate (Hz) of uniformly sampled times `t`.

    Raises
    ------
    ModalError
        If `t` is not a 1-D array of at least 2 finite, increasing times, or if a
        time step differs from the mean step by more than 0.1 %.
    """
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 2 or not np.all(np.isfinite(t)):
        raise ModalError(
            f"`t`: give a 1-D array of at least 2 finite sample times (s), got shape {t.shape}"
        )
    dt = np.diff(t)
    mean = (t[-1] - t[0]) / (t.size - 1)
    if not np.all(dt > 0.0):
        k = int(np.flatnonzero(dt <= 0.0)[0]) + 1
        raise ModalError(
            f"`t`: t[{k}] = {t[k]!r} s does not increase; sort the samples and remove repeats"
        )
    worst = int(np.argmax(np.abs(dt - mean)))
    if abs(dt[worst] - mean) > _JITTER * mean:
        raise ModalError(
            f"`t`: the sampling is not uniform (step {dt[worst]:.6g} s at t = {t[worst]:.6g} s, "
            f"mean step {mean:.6g} s); spectral estimates need uniform samples: resample "
            "every channel onto one uniform grid first, e.g. np.interp(t_new, t, y)"
        )
    return 1.0 / mean


def _outputs(acc, n: int, outputs) -> tuple[np.ndarray, tuple[str, ...]]:
    y = np.asarray(acc, dtype=float)
    y = y[None, :] if y.ndim == 1 else y
    if y.ndim != 2 or y.shape[1] != n:
        raise ModalError(
            f"`acc` has shape {np.shape(acc)}: give one row of {n} samples per output "
            f"(shape (n_outputs, {n})), as many samples as `t`"
        )
    if not np.all(np.isfinite(y)):
        raise ModalError("`acc` holds NaN or infinite samples; remove or repair them first")
    names = tuple(f"y{k + 1}" for k in range(y.shape[0])) if outputs is None else tuple(outputs)
    if len(names) != y.shape[0]:
        raise ModalError(
            f"`outputs` = {list(names)!r}: give one name per row of `acc` ({y.shape[0]})"
        )
    return y, names


def _segments(segments, n: int) -> tuple[tuple[int, int], ...]:
    if segments is None:
        return ((0, n),)
    out = []
    for seg in segments:
        try:
            i0, i1 = (int(i) for i in seg)
        except (TypeError, ValueError):
            raise ModalError(
                f"`segments` holds {seg!r}: give index ranges (start, stop), e.g. [(0, 4000)]"
            ) from None
        if not 0 <= i0 < i1 <= n:
            raise ModalError(
                f"`segments` holds ({i0}, {i1}): a range needs 0 <= start < stop <= {n} "
                "(the number of samples)"
            )
        out.append((i0, i1))
    if not out:
        raise ModalError("`segments` is empty: give at least one index range (start, stop)")
    return tuple(out)


def _check_nperseg(nperseg) -> int:
    if isinstance(nperseg, bool) or not isinstance(nperseg, (int, np.integer)) or nperseg < 8:
        raise ModalError(f"`nperseg` = {nperseg!r}: give an integer ≥ 8 (samples per window)")
    return int(nperseg)


def _nperseg(nperseg, lengths: list[int]) -> int:
    if nperseg is None:  # a power of two; at least ~7 windows over the whole record
        cap = min(min(lengths), sum(lengths) // 4)
        return int(2 ** np.floor(np.log2(max(cap, 8))))
    return _check_nperseg(nperseg)


def _calm_runs(theta: np.ndarray, theta_max: float) -> list[tuple[int, int]]:
    """Maximal index ranges [start, stop) where ``|θ|`` ≤ `theta_max`."""
    calm = np.concatenate([[0], (np.abs(theta) <= theta_max).astype(np.int8), [0]])
    edges = np.flatnonzero(np.diff(calm))
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2])]


def h1_estimate(
    t, ag, acc, *, segments=None, nperseg=None, window="hann", outputs=None
) -> MeasuredFRF:
    """H1 estimate of the frequency response from ü_g to each output, with coherence.

    Welch spectral densities (windows of `nperseg` samples overlapping by half,
    mean removed per window) are computed in each segment and averaged over all
    segments, weighted by their number of windows; then H1 = S_xy / S_xx and
    γ² = ``|S_xy|²`` / (S_xx S_yy).

    Parameters
    ----------
    t : array_like, shape (n,)
        Sample times (s), uniformly spaced (0.1 % jitter allowed).
    ag : array_like, shape (n,)
        Ground (table) acceleration ü_g, the input.
    acc : array_like, shape (n,) or (n_outputs, n)
        The outputs, e.g. total accelerations of sensors (same unit as `ag` for a
        dimensionless H).
    segments : sequence of (int, int), optional
        Index ranges [start, stop) to average over, e.g. the full-contact segments of
        `full_contact_segments`; default the whole record.
    nperseg : int, optional
        Welch window length (samples). Default: the largest power of two not above
        the shortest segment and a quarter of all samples. The frequency step is
        ``fs / nperseg``: to resolve a mode of frequency f and damping ζ it must be
        well below its half-power bandwidth 2ζf.
    window : str or tuple, optional
        Window of `scipy.signal.get_window` (default ``"hann"``).
    outputs : sequence of str, optional
        A name per output (default ``y1``, ``y2``, ...).

    Returns
    -------
    MeasuredFRF
        Unpacks as ``freq_hz, H, coherence``.

    Raises
    ------
    ModalError
        Naming the argument: non-uniform or non-finite samples, mismatched
        shapes, a segment shorter than `nperseg`, no input power.
    """
    fs = sampling_rate(t)
    n = np.asarray(t).size
    x = np.asarray(ag, dtype=float)
    if x.shape != (n,) or not np.all(np.isfinite(x)):
        raise ModalError(
            f"`ag` has shape {x.shape}: give {n} finite samples of the ground acceleration, "
            "one per time"
        )
    y, names = _outputs(acc, n, outputs)
    segs = _segments(segments, n)
    nper = _nperseg(nperseg, [i1 - i0 for i0, i1 in segs])
    short = [s for s in segs if s[1] - s[0] < nper]
    if short:
        raise ModalError(
            f"`segments`: {short[0]} has {short[0][1] - short[0][0]} samples, fewer than "
            f"`nperseg` = {nper}; lower `nperseg` or leave the short segments out"
        )
    try:
        win = signal.get_window(window, nper)
    except (ValueError, TypeError) as err:
        raise ModalError(
            f"`window` = {window!r}: not a window of scipy.signal.get_window ({err}); "
            "e.g. 'hann' or ('tukey', 0.25)"
        ) from None
    over = nper // 2
    kw = dict(fs=fs, window=win, nperseg=nper, noverlap=over, detrend="constant")
    sxx, sxy, syy, total = 0.0, 0.0, 0.0, 0
    for i0, i1 in segs:
        k = 1 + (i1 - i0 - nper) // (nper - over)  # windows Welch averages here
        f, pxx = signal.welch(x[i0:i1], **kw)
        _, pxy = signal.csd(x[None, i0:i1], y[:, i0:i1], **kw)
        _, pyy = signal.welch(y[:, i0:i1], **kw)
        sxx, sxy, syy, total = sxx + k * pxx, sxy + k * pxy, syy + k * pyy, total + k
    if not np.any(sxx > 0.0):
        raise ModalError(
            "`ag` is constant over the segments: no table motion to estimate a response "
            "from; give a trace recorded while the table moves"
        )
    with np.errstate(invalid="ignore", divide="ignore"):
        H = np.where(sxx > 0.0, sxy / np.where(sxx > 0.0, sxx, 1.0), np.nan)
        coh = np.where(sxx * syy > 0.0, np.abs(sxy) ** 2 / (sxx * syy), 0.0)
    return MeasuredFRF(
        freq_hz=f,
        H=H,
        coherence=np.clip(coh, 0.0, 1.0),
        outputs=names,
        segments=segs,
        fs=fs,
        nperseg=nper,
        n_averages=total,
        t0=float(np.asarray(t, dtype=float)[0]),
    )


def full_contact_segments(
    t, theta, f1_hz: float, *, theta_max: float = THETA_MAX, min_periods: float = MIN_PERIODS
) -> tuple[tuple[int, int], ...]:
    """Index ranges [start, stop) of a trace where the structure stays in full contact.

    The rule: a segment is a maximal run of consecutive samples with ``|θ|`` ≤
    `theta_max` that lasts at least `min_periods` periods of the first
    full-contact mode (k samples last k / fs seconds; at least
    ``min_periods / f1_hz``). The run's length keeps out the instants when θ
    crosses zero between two rocking half-cycles. The vibration the last impact
    leaves behind at the start of a segment is, for random table motion,
    uncorrelated with the table motion of that segment: it enters H1 as output
    noise (lower coherence, no bias).

    Parameters
    ----------
    t, theta : array_like, shape (n,)
        Sample times (s, uniform) and base rotation (rad).
    f1_hz : float
        Frequency of the first full-contact mode (Hz), e.g.
        ``modal.analyse(s).full_contact.freq_hz[0]``.
    theta_max : float, optional
        ``|θ|`` (rad) below which a sample counts as full contact (default
        `THETA_MAX` = 2e-4 rad, about 0.011°); above the noise of the θ channel.
    min_periods : float, optional
        Shortest segment, in periods of the first mode (default `MIN_PERIODS`).

    Returns
    -------
    tuple of (int, int)
        Possibly empty.
    """
    fs = sampling_rate(t)
    th = np.asarray(theta, dtype=float)
    n = np.asarray(t).size
    if th.shape != (n,) or not np.all(np.isfinite(th)):
        raise ModalError(
            f"`theta` has shape {th.shape}: give {n} finite samples (rad), one per time"
        )
    for name, value in (("theta_max", theta_max), ("min_periods", min_periods), ("f1_hz", f1_hz)):
        number = isinstance(value, (int, float, np.integer, np.floating))
        if isinstance(value, bool) or not number or not np.isfinite(value) or value <= 0:
            raise ModalError(f"`{name}` = {value!r}: give a finite number > 0")
    need = min_periods / f1_hz * fs * (1 - 1e-12)
    return tuple((a, b) for a, b in _calm_runs(th, theta_max) if b - a >= need)


def full_contact_h1(
    t,
    ag,
    acc,
    theta,
    f1_hz: float,
    *,
    theta_max: float = THETA_MAX,
    min_periods: float = MIN_PERIODS,
    nperseg=None,
    window="hann",
    outputs=None,
) -> MeasuredFRF:
    """`h1_estimate` over the `full_contact_segments` of a trace given as arrays.

    Segments shorter than `nperseg` (when it is given) are not used; they are
    listed in the result's ``skipped``.

    Parameters
    ----------
    t, ag, acc, nperseg, window, outputs :
        As in `h1_estimate`.
    theta, f1_hz, theta_max, min_periods :
        As in `full_contact_segments`.

    Raises
    ------
    ModalError
        When no segment is long enough (naming the longest calm stretch and the
        fix), or the sampling rate is below 4 `f1_hz`; and as `h1_estimate`.
    """
    segs = full_contact_segments(t, theta, f1_hz, theta_max=theta_max, min_periods=min_periods)
    fs = sampling_rate(t)
    if fs < 4.0 * f1_hz:
        raise ModalError(
            f"sampled at {fs:.4g} Hz, too slow for the first full-contact mode "
            f"({f1_hz:.4g} Hz): its peak needs a Nyquist frequency well above it; record "
            f"at {8 * f1_hz:.0f} Hz or more"
        )
    if not segs:
        runs = _calm_runs(np.asarray(theta, dtype=float), theta_max)
        longest = max((b - a for a, b in runs), default=0) / fs
        raise ModalError(
            f"no full-contact segment: |theta| stays at or below `theta_max` = {theta_max:g} rad "
            f"for at most {longest:.3g} s, and a segment needs {min_periods:g} periods of the "
            f"first mode ({min_periods / f1_hz:.3g} s); raise `theta_max` (--theta-max) above "
            "the noise of theta, or record a stretch of low-amplitude table motion"
        )
    keep, skipped = segs, ()
    if nperseg is not None:
        nper = _check_nperseg(nperseg)
        keep = tuple(s for s in segs if s[1] - s[0] >= nper)
        skipped = tuple(s for s in segs if s[1] - s[0] < nper)
        if not keep:
            longest = max(b - a for a, b in segs)
            raise ModalError(
                f"`nperseg` = {nper}: every full-contact segment is shorter (longest "
                f"{longest} samples); lower `nperseg` to at most {longest}"
            )
    est = h1_estimate(t, ag, acc, segments=keep, nperseg=nperseg, window=window, outputs=outputs)
    rule = dict(skipped=skipped, theta_max=float(theta_max), min_periods=float(min_periods))
    return MeasuredFRF(**{**est.__dict__, **rule})
