"""The maths of `multimass.identify.modes`: one segment's modes, two ways.

A segment is a stretch of a trace's sensor accelerations Y (n samples × S sensors)
over which the column's motion is one linear phase: one rocking half-cycle (the
uplifted system, paper 001 Eq 4 linearised, Eqs 19–21) or one stretch of full contact
(Eq 3). In it each sensor records

    y_s(t) = P_s(t) + Σ_k Re(A_sk exp(λ_k t)) + noise,   λ_k = −ζ_k ω_k + i ω_k √(1 − ζ_k²),

the free decay of the vibration modes k (frequency ω_k, damping ζ_k shared by all
sensors, complex amplitude A_sk: the operational shape) on top of P_s, the *rigid-body
part*: while the column rocks, a sensor at height H_s records H_s θ̈ + B θ̇² − g sin θ
of the rocking itself (paper 001, Eq 7), the "step function" of paper 001 Section 4.3
(θ̈ ≈ ∓p² (α − |θ|) flips sign at each impact and changes slowly within a half-cycle).
Within one half-cycle it is smooth: over the free half-cycles of S1 (up to ±0.37 s
about the peak, rocking-mode p = 2.5 rad/s) θ̈ ∝ cosh(p t) departs from a parabola by
under 3 % of its value, ~0.1 m/s² at the top sensor, a quarter of that sensor's noise in
the synthetic traces. So P_s is taken as a polynomial of low degree in t (`DEGREE`),
fitted per sensor and per segment together with the modes: degree 2 in a half-cycle,
degree 0 (the sensor's bias) in full contact. This needs no model of the rocking (no
B, α or heights). The alternative, H_s θ̈ from the measured θ, was rejected: the
uplifted modes move θ themselves (the rocking part v_r of their compound shapes,
paper 001 Section 4.2), so θ̈ would have to be low-passed below them first, which
smears its step at every impact, and differentiating twice multiplies the θ noise
(2 mrad) by (2π f)². How much the degree matters, measured on six synthetic S1 traces
(DD2 and CIM, seeds 1–3): with the fit, degrees 0–4 move the uplifted f1 by under
0.03 % (the modes, 20–46 Hz, are far above the slow rigid part); with the FFT, the
half-cycle f1 scatters by 0.39–0.51 % r.m.s. whatever the degree. Degree 2 is kept for
the reason above.

`fit_segment` — the parametric method: nonlinear least squares in (f_k, ζ_k) with the
amplitudes and the polynomial solved linearly at every step (variable projection,
Golub & Pereyra 1973), all sensors at once, each weighted by the inverse of its
residual noise. `fft_segment` — the frequency-domain method of paper 001 Section 4.2:
the polynomial removed, the zero-padded spectrum of each sensor, the peak of their
noise-weighted power sum in a band around each mode, the shape read off the complex
spectra at the peak, the damping from the half-power width of the peak, inverted for
the rectangular window of the segment's length (`_zeta_from_width`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import optimize

__all__ = [
    "SegmentModes", "fit_segment", "fft_segment", "search_bands", "rigid_basis", "DEGREE",
    "ZETA_MAX",
]  # fmt: skip

_TWO_PI = 2.0 * np.pi
_NFFT_MIN = 4096  # zero padding: a 0.05 Hz grid at 200 Hz, refined by a parabola
#: Upper bound of a fitted damping ratio.
ZETA_MAX = 0.5
#: Degree of the rigid-body polynomial per phase (module docstring).
DEGREE = {"rocking": 2, "full_contact": 0}


@dataclass(frozen=True, eq=False)
class SegmentModes:
    """The modes found in one segment.

    Attributes
    ----------
    freq_hz, damping : ndarray, shape (K,)
        NaN where a mode was not found.
    amplitudes : ndarray, complex, shape (S, K)
        A_sk: y_s ≈ Re(A_sk exp(λ_k t)), t from the segment's first sample (m/s²).
    energy : ndarray, shape (K,)
        Each mode's share of the segment's samples in units of the noise: Σ over
        sensors and samples of (its fitted part / the sensor's noise)².
    noise : ndarray, shape (S,)
        Residual standard deviation of each sensor (m/s²).
    n : int
        Samples used.
    rho1 : ndarray, shape (S,)
        Lag-1 autocorrelation of each sensor's residual: near 0 when what is left is
        white noise, near 1 when a slow misfit is (`fit_segment` only; NaN otherwise).
    rms : ndarray, shape (S,)
        Standard deviation of each sensor's samples about the polynomial (m/s²).
    """

    freq_hz: np.ndarray
    damping: np.ndarray
    amplitudes: np.ndarray
    energy: np.ndarray
    noise: np.ndarray
    n: int
    rho1: np.ndarray | None = None
    rms: np.ndarray | None = None


def rigid_basis(n: int, degree: int) -> np.ndarray:
    """Legendre polynomials 0..`degree` on n samples spread over [−1, 1], shape (n, degree+1)."""
    x = np.linspace(-1.0, 1.0, n)
    return np.polynomial.legendre.legvander(x, degree)


def _mode_basis(t: np.ndarray, freq_hz: np.ndarray, zeta: np.ndarray) -> np.ndarray:
    """Columns exp(−ζωt) cos(ω_d t), exp(−ζωt) sin(ω_d t) per mode, shape (n, 2K)."""
    w = _TWO_PI * np.asarray(freq_hz)
    z = np.asarray(zeta)
    decay = np.exp(-np.outer(t, z * w))
    phase = np.outer(t, w * np.sqrt(np.clip(1.0 - z * z, 0.0, None)))
    out = np.empty((t.size, 2 * w.size))
    out[:, 0::2] = decay * np.cos(phase)
    out[:, 1::2] = decay * np.sin(phase)
    return out


def _solve(basis: np.ndarray, Y: np.ndarray):
    """Least-squares coefficients of every column of Y on `basis` and the residual."""
    coef, *_ = np.linalg.lstsq(basis, Y, rcond=None)
    return coef, Y - basis @ coef


def _modes_of(coef: np.ndarray, K: int) -> np.ndarray:
    """Complex amplitudes A (S, K) from the cos/sin coefficients: a cos + b sin = Re((a − ib) e^{iωt})."""
    return (coef[0 : 2 * K : 2] - 1j * coef[1 : 2 * K : 2]).T


def _energy(t, f, z, coef, K, noise) -> np.ndarray:
    basis = _mode_basis(t, f, z)
    out = np.empty(K)
    for k in range(K):
        part = basis[:, 2 * k : 2 * k + 2] @ coef[2 * k : 2 * k + 2]
        out[k] = float(np.sum((part / noise) ** 2))
    return out


def _least_squares(t, Yw, poly, x0, bounds, scale) -> np.ndarray:
    """(f, ζ) minimising the residual of `Yw` on the modes and `poly` (variable projection)."""
    K = x0.size // 2

    def residual(p):
        basis = np.hstack([_mode_basis(t, p[:K], p[K:]), poly])
        return _solve(basis, Yw)[1].ravel()

    return optimize.least_squares(residual, x0, bounds=bounds, x_scale=scale, method="trf").x


def fit_segment(t: np.ndarray, Y: np.ndarray, f0, z0, degree: int, f_bounds=None) -> SegmentModes:
    """Damped sinusoids with common (f, ζ) and a polynomial per sensor, by least squares.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Times (s) from the segment's first sample.
    Y : ndarray, shape (n, S)
        Sensor accelerations.
    f0, z0 : array_like, shape (K,)
        Initial frequencies (Hz) and damping ratios.
    degree : int
        Degree of the rigid-body polynomial.
    f_bounds : (array_like, array_like), optional
        Bounds of each frequency (Hz); default 0.5 f0 to 1.5 f0.

    Returns
    -------
    SegmentModes
    """
    f0, z0 = np.asarray(f0, dtype=float), np.clip(np.asarray(z0, dtype=float), 1e-4, 0.3)
    K = f0.size
    poly = rigid_basis(t.size, degree)
    lo, hi = (0.5 * f0, 1.5 * f0) if f_bounds is None else map(np.asarray, f_bounds)
    f0 = np.clip(f0, lo * 1.0001, hi * 0.9999)
    scale = np.concatenate([f0, np.full(K, 0.01)])
    weights = 1.0 / np.maximum(np.std(Y - poly @ _solve(poly, Y)[0], axis=0), 1e-300)
    x = np.concatenate([f0, z0])
    bounds = (np.concatenate([lo, np.zeros(K)]), np.concatenate([hi, np.full(K, ZETA_MAX)]))
    for _ in range(2):  # a second pass with each sensor weighted by its residual noise
        x = _least_squares(t, Y * weights, poly, x, bounds, scale)
        basis = np.hstack([_mode_basis(t, x[:K], x[K:]), poly])
        coef, res = _solve(basis, Y)
        dof = max(t.size - basis.shape[1], 1)
        noise = np.maximum(np.sqrt(np.sum(res**2, axis=0) / dof), 1e-300)
        weights = 1.0 / noise
    f, z = x[:K], x[K:]
    rho1 = np.sum(res[1:] * res[:-1], axis=0) / np.maximum(np.sum(res * res, axis=0), 1e-300)
    rms = np.std(Y - poly @ _solve(poly, Y)[0], axis=0)
    return SegmentModes(
        f, z, _modes_of(coef, K), _energy(t, f, z, coef, K, noise), noise, int(t.size), rho1, rms
    )


def search_bands(model_hz, fs: float) -> list[tuple[float, float]]:
    """Where to look for each mode: ±35 % of its model frequency, not past the midpoints
    to its neighbours, nor above 0.45 fs."""
    f = np.asarray(model_hz, dtype=float)
    out = []
    for k, fk in enumerate(f):
        lo = 0.65 * fk if k == 0 else max(0.65 * fk, 0.5 * (f[k - 1] + fk))
        hi = 1.35 * fk if k == f.size - 1 else min(1.35 * fk, 0.5 * (fk + f[k + 1]))
        out.append((lo, min(hi, 0.45 * fs)))
    return out


def _parabola(y: np.ndarray, i: int) -> tuple[float, float]:
    """Vertex (offset in bins, value) of the parabola through y[i-1], y[i], y[i+1]."""
    if i <= 0 or i >= y.size - 1:
        return 0.0, float(y[i])
    a, b, c = y[i - 1], y[i], y[i + 1]
    den = a - 2.0 * b + c
    if den >= 0.0:
        return 0.0, float(b)
    d = 0.5 * (a - c) / den
    return float(d), float(b - 0.25 * (a - c) * d)


def _half_power(power: np.ndarray, i: int, df: float, peak: float) -> float:
    """Width (Hz) of the peak at bin i where the power falls to half `peak` (linear)."""
    half = 0.5 * peak
    j = i
    while j > 0 and power[j] > half:
        j -= 1
    k = i
    while k < power.size - 1 and power[k] > half:
        k += 1
    if power[j] > half or power[k] > half:
        return np.nan
    left = j + (half - power[j]) / (power[j + 1] - power[j])
    right = k - 1 + (power[k - 1] - half) / (power[k - 1] - power[k])
    return float((right - left) * df)


def _width(sigma: float, T: float) -> float:
    """Half-power width (Hz) of ``|∫_0^T exp(−(σ + iΔω) t) dt|²`` over Δω: the peak of a
    decaying sinusoid seen through a rectangular window of length T."""
    if sigma * T < 1e-9:
        p0 = T * T
        power = lambda dw: 4.0 * np.sin(0.5 * dw * T) ** 2 / (dw * dw)
    else:
        e = np.exp(-sigma * T)
        p0 = (1.0 - e) ** 2 / sigma**2
        power = lambda dw: (1.0 - 2.0 * e * np.cos(dw * T) + e * e) / (sigma**2 + dw * dw)
    hi = max(np.pi / T, 2.0 * sigma)  # below the window's first zero, above the Lorentzian's
    dw = optimize.brentq(lambda x: power(x) - 0.5 * p0, 1e-12, hi * 1.0001)
    return dw / np.pi


def _zeta_from_width(width: float, T: float, f: float) -> float:
    """ζ whose decay seen through a window of length T gives a peak `width` Hz wide.

    The half-power width of a damped sinusoid's spectrum over T seconds grows from the
    window's own (0.886 / T for ζ = 0) towards the Lorentzian's 2ζf; inverted here
    (monotone in ζ). A width below the window's own gives ζ = 0."""
    if not np.isfinite(width):
        return np.nan
    if width <= _width(0.0, T):
        return 0.0
    w = _TWO_PI * f
    g = lambda z: _width(z * w, T) - width
    top = ZETA_MAX
    if g(top) < 0.0:
        return top
    return float(optimize.brentq(g, 0.0, top, xtol=1e-6))


def fft_segment(t: np.ndarray, Y: np.ndarray, bands, degree: int, fs: float) -> SegmentModes:
    """Peaks of the summed, noise-weighted power spectra of the detrended sensors.

    Parameters
    ----------
    t, Y, degree :
        As `fit_segment`.
    bands : sequence of (float, float)
        Search band (Hz) of each mode (`search_bands`).
    fs : float
        Sampling rate (Hz).

    Returns
    -------
    SegmentModes
        NaN frequency for a mode whose band holds no interior peak.
    """
    n = t.size
    poly = rigid_basis(n, degree)
    _, R = _solve(poly, Y)
    nfft = max(_NFFT_MIN, 1 << int(np.ceil(np.log2(8 * n))))
    spec = np.fft.rfft(R, n=nfft, axis=0)  # (n_f, S); rectangular window
    freq = np.fft.rfftfreq(nfft, 1.0 / fs)
    df = freq[1]
    # noise of each sensor: the spectrum above every band (the anti-alias stopband side)
    top = max(b[1] for b in bands)
    quiet = freq > max(top * 1.1, 0.46 * fs)
    if np.count_nonzero(quiet) > 8:
        noise = np.sqrt(np.mean(np.abs(spec[quiet]) ** 2, axis=0) / n)
    else:
        noise = np.std(R, axis=0)
    noise = np.maximum(noise, 1e-300)
    power = np.sum(np.abs(spec / noise) ** 2, axis=1)
    K = len(bands)
    f = np.full(K, np.nan)
    z = np.full(K, np.nan)
    amp = np.zeros((Y.shape[1], K), complex)
    energy = np.zeros(K)
    for k, (lo, hi) in enumerate(bands):
        inside = np.flatnonzero((freq >= lo) & (freq <= hi))
        if inside.size < 3:
            continue
        i = int(inside[np.argmax(power[inside])])
        if i in (inside[0], inside[-1]):  # the band's edge: no peak inside it
            continue
        d, peak = _parabola(power, i)
        f[k] = freq[i] + d * df
        width = _half_power(power, i, df, peak)
        z[k] = _zeta_from_width(width, n / fs, f[k])
        # a damped sinusoid's transform at its peak is ≈ A × (effective length): rescale
        w = np.exp(-2j * np.pi * f[k] * t)
        amp[:, k] = 2.0 * (w @ R) / n
        energy[k] = float(np.sum(np.abs(spec[i] / noise) ** 2)) * 2.0 / n
    return SegmentModes(f, z, amp, energy, noise, int(n))
