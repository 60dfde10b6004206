"""Each segment's modes, then one estimate per mode (`multimass.identify.modes`, steps 3–5).

A mode counts in a segment when its energy there (`SegmentModes.energy`) is at least
`MIN_ENERGY` noise variances — fits to pure white noise reach 35 with the
least-squares fit and 90 with the FFT peaks (4 sensors, 60–1000 samples, 30 draws
each) — and, with the fit, when its frequency is not stuck on its search band's edge.
Segments are combined with weights equal to the mode's energy in them; the spread is
the weighted standard deviation. Shapes: each segment's complex amplitudes are turned
to their principal real direction (the rotation e^{−iφ} that puts the most of the
vector on the real axis), scaled to unit norm and signed to correlate positively with
the model's shape of the same mode, then averaged with the same weights.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ..modal import mac
from . import _modes_fit as fitting

__all__ = ["MIN_ENERGY", "estimate", "combine"]

#: A mode counts in a segment when its energy is at least this many noise variances.
MIN_ENERGY = 100.0
_COLUMNS = [
    "segment", "start", "stop", "t_start", "t_stop", "half_cycle", "mode",
    "freq_hz", "damping", "energy", "found",
]  # fmt: skip


def _at_bounds(est: fitting.SegmentModes, lo, hi) -> fitting.SegmentModes:
    """A fitted frequency stuck on its band's edge (or ζ on its bound) is no peak: NaN."""
    f = est.freq_hz.copy()
    edge = (f <= lo * 1.001) | (f >= hi * 0.999) | (est.damping >= 0.99 * fitting.ZETA_MAX)
    f[edge] = np.nan
    return fitting.SegmentModes(
        f, est.damping, est.amplitudes, est.energy, est.noise, est.n, est.rho1, est.rms
    )


def estimate(t_all, Y, ranges, numbers, f_m, z_m, method: str, degree: int, fs: float):
    """Each range's modes; (list of SegmentModes, table with one row per range and mode)."""
    bands = fitting.search_bands(f_m, fs)
    lo, hi = np.array(bands).T
    rows, fits = [], []
    for k, (i0, i1, hc) in enumerate(ranges):
        t = t_all[i0:i1] - t_all[i0]
        est = fitting.fft_segment(t, Y[i0:i1], bands, degree, fs)
        if method == "fit":
            f0 = np.where(np.isfinite(est.freq_hz), est.freq_hz, f_m)
            est = _at_bounds(fitting.fit_segment(t, Y[i0:i1], f0, z_m, degree, (lo, hi)), lo, hi)
        fits.append(est)
        for j, f, z, e in zip(numbers, est.freq_hz, est.damping, est.energy):
            found = bool(np.isfinite(f) and e >= MIN_ENERGY)
            rows.append((k, i0, i1, t_all[i0], t_all[i1 - 1], hc, int(j), f, z, e, found))
    return fits, pd.DataFrame(rows, columns=_COLUMNS)


def _real(vec: np.ndarray, ref: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(real shape, complex shape) of complex amplitudes: the principal real direction,
    unit norm, signed to correlate positively with `ref`; the complex one turned alike."""
    _, _, vt = np.linalg.svd(np.column_stack([vec.real, vec.imag]), full_matrices=False)
    c = vec * np.exp(-1j * math.atan2(vt[0, 1], vt[0, 0]))
    c = c / np.linalg.norm(c)
    r = c.real / np.linalg.norm(c.real)
    if float(r @ ref) < 0.0:
        r, c = -r, -c
    return r, c


def _weighted(x: np.ndarray, w: np.ndarray) -> tuple[float, float]:
    mean = float(np.sum(w * x) / np.sum(w))
    return mean, float(np.sqrt(max(np.sum(w * (x - mean) ** 2) / np.sum(w), 0.0)))


def _one_mode(k: int, ok: pd.DataFrame, fits, ref: np.ndarray) -> dict:
    w = ok["energy"].to_numpy()
    f, f_sd = _weighted(ok["freq_hz"].to_numpy(), w)
    z, z_sd = _weighted(ok["damping"].to_numpy(), w)
    real, cplx = np.zeros(ref.size), np.zeros(ref.size, complex)
    for seg_k, wk in zip(ok["segment"], w):
        r, c = _real(fits[seg_k].amplitudes[:, k], ref)
        real, cplx = real + wk * r, cplx + wk * c
    return dict(
        freq_hz=f, damping=z, freq_spread_hz=f_sd, damping_spread=z_sd, n_segments=len(ok),
        shape=real / np.linalg.norm(real), complex_shape=cplx / np.linalg.norm(cplx),
    )  # fmt: skip


def combine(numbers, f_m, z_m, fits, table: pd.DataFrame, model_all: np.ndarray):
    """One estimate per mode found (ascending frequency) and the modes not found.

    Returns
    -------
    (dict of arrays, dict)
        The fields of `IdentifiedModes` but ``phase``, ``not_identified``,
        ``segments`` and ``skipped``; mode number → why it was found in no segment.
    """
    S = model_all.shape[0]
    found, missing = [], {}
    for k, j in enumerate(numbers):
        ok = table[(table["mode"] == j) & table["found"]]
        if ok.empty:
            best = table.loc[table["mode"] == j, "energy"].max()
            missing[int(j)] = (
                f"found in none of {table['segment'].nunique()} segment(s): its energy reaches "
                f"{best:.3g} noise variances, below {MIN_ENERGY:g}"
            )
            continue
        found.append((k, _one_mode(k, ok, fits, model_all[:, j - 1])))
    found.sort(key=lambda kv: kv[1]["freq_hz"])
    idx = np.array([k for k, _ in found], dtype=int)
    pick = lambda key: np.array([m[key] for _, m in found], dtype=float)
    shapes = np.column_stack([m["shape"] for _, m in found]) if found else np.zeros((S, 0))
    cshapes = (
        np.column_stack([m["complex_shape"] for _, m in found])
        if found
        else np.zeros((S, 0), complex)
    )
    mode = np.asarray(numbers, dtype=int)[idx]
    model = model_all[:, mode - 1]
    model = model / np.linalg.norm(model, axis=0)  # unit norm, as `shapes`
    fields = dict(
        mode=mode,
        freq_hz=pick("freq_hz"),
        damping=pick("damping"),
        freq_spread_hz=pick("freq_spread_hz"),
        damping_spread=pick("damping_spread"),
        n_segments=pick("n_segments").astype(int),
        shapes=shapes,
        complex_shapes=cshapes,
        model_freq_hz=np.asarray(f_m, dtype=float)[idx],
        model_damping=np.asarray(z_m, dtype=float)[idx],
        model_shapes=model,
        mac=np.array([mac(shapes[:, i], model[:, i])[0, 0] for i in range(idx.size)]),
        mac_matrix=mac(shapes, model_all) if found else np.zeros((0, model_all.shape[1])),
    )
    return fields, missing
