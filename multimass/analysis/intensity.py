"""Intensity measures of a sampled ground acceleration: PGA, PGV, PGD, Arias, Sa(T, ζ).

Every measure treats the record as the **piecewise-linear** function through its samples
(the interpolation the engines use, `multimass.inputs.records.Record`), starting from rest at
``t[0]``, with no baseline correction; each is computed *exactly* for that function:

* PGV and PGD integrate the straight lines exactly (trapezoid for v; the cubic term
  ``h²(2a_i + a_{i+1})/6`` for d) and include the extrema that fall between samples;
* Arias intensity ``I_a = π/(2g) ∫ a² dt`` (Arias 1970) integrates the squared lines
  exactly, ``h (a_i² + a_i a_{i+1} + a_{i+1}²)/3`` per step;
* the pseudo-spectral acceleration ``Sa = ω² max|u|`` of the damped oscillator
  ``ü + 2ζωu̇ + ω²u = -a_g(t)`` uses the exact recurrence of Nigam & Jennings (1969),
  vectorised over the periods (numpy arrays over periods, a loop over the time steps).
  Between two samples the peak is located by cubic Hermite interpolation of (u, u̇) and
  evaluated by the exact recurrence over the partial step, so the peak is not limited to
  the sample instants.

Non-uniform steps are handled exactly: the recurrence coefficients are built for each
distinct step (at most 64 of them are tabulated; beyond that they are computed step
by step; `multimass.model._nigam_jennings`).

Units: the measures come in the units of ``ag`` (and of ``t``): PGV in [ag]·s, PGD in
[ag]·s², Sa in [ag]; Arias in [ag]²·s / [g], i.e. m/s when ``ag`` is in m/s² and
``g = 9.81``.

References
----------
N. C. Nigam and P. C. Jennings (1969), Calculation of response spectra from
strong-motion earthquake records, Bull. Seismol. Soc. Am. 59(2), 909–922.
A. Arias (1970), A measure of earthquake intensity, in R. J. Hansen (ed.), Seismic
Design for Nuclear Power Plants, MIT Press, 438–483.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError
from ..model._nigam_jennings import peak_displacement as _peak_displacement
from ..model._nigam_jennings import quadratic_roots as _quadratic_roots

__all__ = [
    "IMS",
    "pga",
    "pgv",
    "pgd",
    "arias_intensity",
    "ground_motion",
    "spectral_acceleration",
    "intensity_measure",
    "scale_to",
]

#: Names accepted by `intensity_measure` and `scale_to`.
IMS = ("pga", "pgv", "pgd", "arias", "sa")

#: Standard gravity (m/s²), the same value as `multimass.inputs.units.G` (DESIGN.md: g = 9.81).
_G = 9.81


# ------------------------------------------------------------------------ validation
def _samples(t, ag) -> tuple[np.ndarray, np.ndarray]:
    """Return `t` and `ag` as float arrays after checking them (the record contract)."""
    t = np.asarray(t, dtype=float)
    ag = np.asarray(ag, dtype=float)
    if t.ndim != 1 or ag.ndim != 1 or t.size != ag.size:
        raise InputError(
            f"`t` and `ag` must be 1-D arrays of the same length; got shapes {t.shape} and "
            f"{ag.shape}. Pass the record's time and acceleration columns."
        )
    if t.size < 2:
        raise InputError(f"a record needs at least 2 samples; got {t.size}.")
    for name, x in (("t", t), ("ag", ag)):
        bad = np.flatnonzero(~np.isfinite(x))
        if bad.size:
            raise InputError(
                f"`{name}` has {bad.size} non-finite value(s) (first at index {bad[0]}: "
                f"{x[bad[0]]}); clean or drop those samples before computing intensities."
            )
    dt = np.diff(t)
    bad = np.flatnonzero(dt <= 0)
    if bad.size:
        i = bad[0]
        raise InputError(
            f"`t` must increase strictly; t[{i}] = {t[i]} is followed by t[{i + 1}] = "
            f"{t[i + 1]}. Sort the samples and remove duplicate times."
        )
    return t, ag


def _periods(periods) -> np.ndarray:
    T = np.atleast_1d(np.asarray(periods, dtype=float))
    if T.ndim != 1 or T.size == 0:
        raise InputError(f"`periods` must be a number or a 1-D array; got shape {T.shape}.")
    bad = np.flatnonzero(~np.isfinite(T) | (T <= 0))
    if bad.size:
        raise InputError(
            f"`periods` must be finite and > 0 (s); periods[{bad[0]}] = {T[bad[0]]}. "
            "For the peak ground acceleration use `pga`."
        )
    return T


def _damping(damping) -> float:
    z = float(damping)
    if not (math.isfinite(z) and 0.0 <= z < 1.0):
        raise InputError(
            f"`damping` is the ratio of critical damping and must lie in [0, 1); got "
            f"{damping!r}. Pass 0.05 for 5 %, not 5."
        )
    return z


# --------------------------------------------------------------- ground motion (v, d)
def ground_motion(t, ag) -> tuple[np.ndarray, np.ndarray]:
    """Ground velocity and displacement at the samples, integrated exactly.

    Parameters
    ----------
    t, ag : array_like
        Sample times and ground accelerations (piecewise-linear between samples).

    Returns
    -------
    v, d : ndarray
        Velocity ``v_{i+1} = v_i + h (a_i + a_{i+1})/2`` and displacement
        ``d_{i+1} = d_i + h v_i + h² (2a_i + a_{i+1})/6``, from rest at ``t[0]``.
    """
    t, a = _samples(t, ag)
    return _integrate(t, a)


def _integrate(t, a):
    h = np.diff(t)
    v = np.concatenate(([0.0], np.cumsum(0.5 * h * (a[:-1] + a[1:]))))
    dd = h * v[:-1] + h * h * (2.0 * a[:-1] + a[1:]) / 6.0
    d = np.concatenate(([0.0], np.cumsum(dd)))
    return v, d


def pga(t, ag) -> float:
    """Peak ground acceleration ``max |a_g|`` (the peak of a piecewise-linear record is a
    sample), in the units of `ag`."""
    _, a = _samples(t, ag)
    return float(np.max(np.abs(a)))


def pgv(t, ag) -> float:
    """Peak ground velocity of the piecewise-linear record, from rest at ``t[0]``.

    Besides the samples, the extremum inside a step where ``a`` changes sign (v is a
    parabola there) is included, so the value is exact. Units: [ag]·s.
    """
    t, a = _samples(t, ag)
    v, _ = _integrate(t, a)
    peak = np.max(np.abs(v))
    a0, a1, h = a[:-1], a[1:], np.diff(t)
    cross = np.flatnonzero(a0 * a1 < 0)
    if cross.size:
        s = a0[cross] / (a0[cross] - a1[cross])  # where a = 0, in [0, 1]
        vs = v[cross] + 0.5 * a0[cross] * h[cross] * s
        peak = max(peak, np.max(np.abs(vs)))
    return float(peak)


def pgd(t, ag) -> float:
    """Peak ground displacement of the piecewise-linear record, from rest at ``t[0]``.

    Besides the samples, the extrema inside a step where v vanishes (d is a cubic there;
    the roots of the quadratic v are taken exactly) are included. Units: [ag]·s². No
    baseline correction is applied: a record that ends with a residual velocity drifts.
    """
    t, a = _samples(t, ag)
    v, d = _integrate(t, a)
    h = np.diff(t)
    a0, a1 = a[:-1], a[1:]
    # v(s) = v0 + a0 h s + (a1 - a0) h s²/2, s in [0, 1]  ->  c2 s² + c1 s + c0 = 0
    c2, c1, c0 = 0.5 * (a1 - a0) * h, a0 * h, v[:-1]
    peak = np.max(np.abs(d))
    for s in _quadratic_roots(c2, c1, c0):
        ok = (s > 0) & (s < 1)
        if np.any(ok):
            hs = h[ok] * s[ok]
            ds = (
                d[:-1][ok]
                + v[:-1][ok] * hs
                + a0[ok] * hs**2 / 2
                + (a1 - a0)[ok] * hs**3 / (6 * h[ok])
            )
            peak = max(peak, np.max(np.abs(ds)))
    return float(peak)


def arias_intensity(t, ag, g: float = _G) -> float:
    """Arias intensity ``I_a = π/(2g) ∫ a_g² dt`` (Arias 1970), exact for linear segments.

    Parameters
    ----------
    t, ag : array_like
        Sample times (s) and ground accelerations.
    g : float
        Gravity in the units of `ag`: 9.81 for m/s² (result in m/s); 1.0 when `ag` is in g
        (result in g·s; multiply by 9.81 for m/s).
    """
    t, a = _samples(t, ag)
    if not (math.isfinite(g) and g > 0):
        raise InputError(f"`g` must be > 0 in the units of `ag`; got {g!r}.")
    a0, a1, h = a[:-1], a[1:], np.diff(t)
    return float(math.pi / (2.0 * g) * np.sum(h * (a0 * a0 + a0 * a1 + a1 * a1) / 3.0))


def spectral_acceleration(
    t, ag, periods, damping: float = 0.05, *, min_period_ratio: float = 2.0
) -> np.ndarray:
    """Elastic pseudo-spectral acceleration ``Sa(T, ζ) = ω² max_t |u(t)|``.

    ``u`` solves ``ü + 2ζωu̇ + ω²u = -a_g(t)`` from rest, ``ω = 2π/T``, with `ag`
    interpolated linearly between samples. The response is computed exactly for that
    excitation by the Nigam & Jennings (1969) recurrence, vectorised over the periods;
    steps of different lengths are handled exactly (coefficients per distinct step).
    The peak includes the extrema between samples (Hermite-located, evaluated exactly);
    the response after the last sample (free vibration) is not included.

    Parameters
    ----------
    t : array_like, shape (n,)
        Sample times (s), strictly increasing; the step need not be uniform.
    ag : array_like, shape (n,)
        Ground acceleration, any units; Sa comes in the same units.
    periods : float or array_like
        Oscillator periods T (s), each > 0.
    damping : float
        Ratio of critical damping ζ in [0, 1) (0.05 = 5 %).
    min_period_ratio : float
        Resolution rule: every period must satisfy ``T ≥ min_period_ratio · max(dt)``.
        The default 2 is the record's Nyquist period: the recurrence is exact for the
        straight lines between samples at any T, but a record sampled at dt carries no
        ground motion at periods below 2·dt, so Sa there describes the interpolation, not
        the earthquake. Pass 0 to accept it anyway.

    Returns
    -------
    ndarray, shape (len(periods),)
        Sa at each period, in the units of `ag` (a float array even for one period).

    Raises
    ------
    multimass.errors.InputError
        Non-finite samples, `t` not increasing, a period ≤ 0, damping outside [0, 1), or a
        period shorter than the record resolves.

    References
    ----------
    N. C. Nigam and P. C. Jennings (1969), Bull. Seismol. Soc. Am. 59(2), 909–922.
    """
    t, a = _samples(t, ag)
    T = _periods(periods)
    z = _damping(damping)
    h = np.diff(t)
    hmax = float(np.max(h))
    if np.min(T) < min_period_ratio * hmax:
        raise InputError(
            f"period T = {np.min(T):g} s is shorter than the record resolves: its step is "
            f"dt = {hmax:g} s, so it carries ground motion only at T ≥ "
            f"{min_period_ratio:g}·dt = {min_period_ratio * hmax:g} s (the Nyquist period). "
            "The recurrence is exact for the straight lines between samples, but below that "
            "period Sa describes the interpolation, not the earthquake. Drop the shorter "
            "periods, use a record sampled more finely at its source, or pass "
            "min_period_ratio=0 to accept the interpolated answer."
        )
    w = 2.0 * np.pi / T
    return w * w * _peak_displacement(a, h, w, z)


# ------------------------------------------------------------------ dispatch and scale
def intensity_measure(
    t, ag, im: str, *, period=None, damping: float = 0.05, g: float = _G
) -> float:
    """One intensity measure by name: ``"pga"``, ``"pgv"``, ``"pgd"``, ``"arias"`` or
    ``"sa"`` (Sa needs `period`, in s; `damping` as in `spectral_acceleration`)."""
    key = str(im).lower()
    if key == "sa":
        if period is None or np.ndim(period) != 0:
            raise InputError(f"`im='sa'` needs one `period` (s), e.g. period=1.0; got {period!r}.")
        return float(spectral_acceleration(t, ag, [period], damping)[0])
    funcs = {"pga": pga, "pgv": pgv, "pgd": pgd}
    if key in funcs:
        return funcs[key](t, ag)
    if key == "arias":
        return arias_intensity(t, ag, g)
    raise InputError(f"`im` must be one of {', '.join(IMS)}; got {im!r}.")


def scale_to(
    t, ag, im: str, target: float, *, period=None, damping: float = 0.05, g: float = _G
) -> tuple[np.ndarray, float]:
    """Scale a record so that its intensity measure `im` equals `target`.

    Every measure is proportional to the scale factor except Arias intensity, which goes
    with its square; the factor is therefore ``target / im`` (``sqrt`` of it for Arias).

    Parameters
    ----------
    t, ag : array_like
        The record.
    im : str
        ``"pga"``, ``"pgv"``, ``"pgd"``, ``"arias"`` or ``"sa"`` (see `intensity_measure`).
    target : float
        The wanted value, > 0, in the units of that measure (see the module docstring).
    period, damping, g
        As in `intensity_measure`.

    Returns
    -------
    scaled : ndarray
        ``factor * ag``.
    factor : float
        The scale factor applied.
    """
    target_f = float(target)
    if not (math.isfinite(target_f) and target_f > 0):
        raise InputError(f"`target` must be finite and > 0; got {target!r}.")
    current = intensity_measure(t, ag, im, period=period, damping=damping, g=g)
    if current <= 0:
        raise InputError(
            f"the record's {im} is 0 (an all-zero record?), so no factor reaches {target_f:g}; "
            "check the record file."
        )
    ratio = target_f / current
    factor = math.sqrt(ratio) if str(im).lower() == "arias" else ratio
    return factor * np.asarray(ag, dtype=float), factor
