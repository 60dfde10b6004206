"""The Nigam–Jennings (1969) recurrence: exact response of damped oscillators to a
piecewise-linear ground acceleration, for many frequencies at once.

The solver behind `multimass.analysis.intensity.spectral_acceleration`. For
``ü + 2ζωu̇ + ω²u = -a_g(t)`` with ``a_g`` linear over a step h,

    [u, u̇]_{i+1} = A(ω, ζ, h) [u, u̇]_i + B(ω, ζ, h) [a_i, a_{i+1}]

exactly (N. C. Nigam and P. C. Jennings 1969, Bull. Seismol. Soc. Am. 59(2), 909–922).
The state is an array over the frequencies; the loop runs over the time steps. Peaks
between samples are located by cubic Hermite interpolation of (u, u̇), polished by Newton
on the exact u̇ = 0, and evaluated by the recurrence over the partial step.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "coefficients",
    "free_vibration",
    "nj_coefficients",
    "peak_displacement",
    "quadratic_roots",
]

#: Steps whose lengths agree to this relative tolerance share their coefficients.
_DT_RTOL = 1e-9
#: Most distinct step lengths tabulated before the coefficients are built step by step.
_MAX_TABLE = 64
#: Rows of (u, u̇) buffered before the between-sample peaks are searched.
_BLOCK = 2048
#: Newton iterations that polish the time of a peak between two samples.
_NEWTON = 2
#: Below this ωh the coefficients come from a power series (`_series_coefficients`).
_SMALL = 0.05
#: Terms of that series: 0.05^16/16! ≈ 7e-35, far below rounding.
_SERIES_TERMS = 16


def quadratic_roots(c2, c1, c0):
    """Both real roots of ``c2 s² + c1 s + c0`` elementwise (nan where none), stably."""
    with np.errstate(invalid="ignore", divide="ignore"):
        disc = c1 * c1 - 4.0 * c2 * c0
        sq = np.sqrt(np.where(disc >= 0, disc, np.nan))
        q = -0.5 * (c1 + np.copysign(sq, c1))
        lin = np.abs(c2) <= 1e-14 * (np.abs(c1) + np.abs(c0))
        r1 = np.where(lin, -c0 / c1, q / c2)
        r2 = np.where(lin, np.nan, c0 / q)
    return r1, r2


def free_vibration(w, z, h):
    """Exact map of the free oscillator ``ü + 2ζωu̇ + ω²u = 0`` (ζ ≥ 0) over a step `h`.

    ``[u, u̇](h) = [[a11, a12], [a21, a22]] [u, u̇](0)``; returns a11, a12, a21, a22.
    Underdamped (ζ < 1): the A of Nigam & Jennings 1969, BSSA 59(2), on scalars or
    arrays. Critically or overdamped (ζ ≥ 1; scalars only): with the roots
    λ1,2 = −ω(ζ ∓ √(ζ² − 1)), a12 = (e^{λ1 h} − e^{λ2 h})/(λ1 − λ2) formed as
    e^{λ1 h}(1 − e^{−(λ1 − λ2)h})/(λ1 − λ2) (no overflow; h e^{−ωh} at ζ = 1), and
    a11 = e^{λ2 h} − λ2 a12, a21 = −ω² a12, a22 = e^{λ1 h} + λ2 a12. No term cancels
    as h → 0. Plain arithmetic: `multimass.engines.fast` compiles it unchanged.
    """
    if z < 1.0:
        r = math.sqrt(1.0 - z * z)
        wd = w * r
        e = np.exp(-z * w * h)
        s, c = np.sin(wd * h), np.cos(wd * h)
        return e * (z / r * s + c), e * s / wd, -w / r * e * s, e * (c - z / r * s)
    r = math.sqrt(z * z - 1.0)
    lam1, lam2 = -w * (z - r), -w * (z + r)
    delta = lam1 - lam2  # 2ωr ≥ 0
    e1, e2 = np.exp(lam1 * h), np.exp(lam2 * h)
    x = delta * h
    if x == 0.0:  # ζ = 1 (or h = 0)
        a12 = e1 * h
    else:
        a12 = e1 * (-np.expm1(-x)) / delta
    return e2 - lam2 * a12, a12, -w * w * a12, e1 + lam2 * a12


def nj_coefficients(w, z, h):
    """Exact one-step maps of ``ü + 2ζωu̇ + ω²u = -a`` for a linear `a` over a step `h`.

    ``[u, u̇]_{i+1} = A [u, u̇]_i + B [a_i, a_{i+1}]``; returns a11, a12, a21, a22, b11,
    b12, b21, b22 broadcast over `w` and `h` (Nigam & Jennings 1969, BSSA 59(2); checked
    against the matrix exponential of the augmented system in the tests). Use
    `coefficients`, which also covers ωh → 0.
    """
    a11, a12, a21, a22 = free_vibration(w, z, h)
    r = math.sqrt(1.0 - z * z)
    wd = w * r
    e = np.exp(-z * w * h)
    s, c = np.sin(wd * h), np.cos(wd * h)
    k1 = (2.0 * z * z - 1.0) / (w * w * h)
    k2 = 2.0 * z / (w**3 * h)
    cs = c - z / r * s
    ws = wd * s + z * w * c
    b11 = e * ((k1 + z / w) * s / wd + (k2 + 1.0 / w**2) * c) - k2
    b12 = -e * (k1 * s / wd + k2 * c) - 1.0 / w**2 + k2
    b21 = e * ((k1 + z / w) * cs - (k2 + 1.0 / w**2) * ws) + 1.0 / (w * w * h)
    b22 = -e * (k1 * cs - k2 * ws) - 1.0 / (w * w * h)
    return a11, a12, a21, a22, b11, b12, b21, b22


def coefficients(w, z, h):
    """`nj_coefficients`, with a series where ωh < `_SMALL` (the closed forms hold 1/h terms
    that cancel there: relative error ~1e-6 at ωh = 1e-3, ~4e-2 at ωh = 1e-5)."""
    w, h = np.asarray(w, dtype=float), np.asarray(h, dtype=float)
    with np.errstate(all="ignore"):  # h = 0 divides; the series covers it
        out = nj_coefficients(w, z, h)
    small = np.asarray(w * h < _SMALL)
    if not small.any():
        return out
    series = _series_coefficients(w, z, h)
    with np.errstate(all="ignore"):
        return tuple(np.where(small, s_, o_) for o_, s_ in zip(out, series))


def _series_coefficients(w, z, h):
    """The same map by power series in H = ωh, in the dimensionless state (u, u̇/ω).

    With A = [[0, 1], [-1, -2ζ]] and forcing f = a/ω² linear in σ = τ/H:
    E = Σ A^j H^j/j!, Γ0 = Σ A^j H^{j+1}/(j+1)!, Γ1 = Σ A^j H^{j+1}/(j+2)!, and
    x(H) = E x0 - (Γ0 - Γ1) e2 f0 - Γ1 e2 f1 (e2 = [0, 1]).
    """
    H = np.asarray(w * h, dtype=float)
    A = np.array([[0.0, 1.0], [-1.0, -2.0 * z]])
    E = np.zeros((2, 2) + H.shape)
    G0 = np.zeros_like(E)
    G1 = np.zeros_like(E)
    Aj = np.eye(2)
    Hj = np.ones_like(H)  # H^j / j!
    for j in range(_SERIES_TERMS):
        E += _outer(Aj, Hj)
        G0 += _outer(Aj, Hj * H / (j + 1))
        G1 += _outer(Aj, Hj * H / ((j + 1) * (j + 2)))
        Aj = Aj @ A
        Hj = Hj * H / (j + 1)
    w2 = w * w
    d0 = G0 - G1
    return (
        E[0, 0],
        E[0, 1] / w,
        w * E[1, 0],
        E[1, 1] + 0.0 * w,
        -d0[0, 1] / w2,
        -G1[0, 1] / w2,
        -d0[1, 1] / w,
        -G1[1, 1] / w,
    )


def _outer(M, x):
    """M (2×2) times every element of x: shape (2, 2) + x.shape."""
    return M.reshape((2, 2) + (1,) * x.ndim) * x


def _step_tables(h, w, z):
    """Coefficients per step: (index per step, table over distinct steps) or (None, None)."""
    ref = np.max(h)
    keys = np.round(h / (ref * _DT_RTOL)).astype(np.int64)
    uniq, index = np.unique(keys, return_inverse=True)
    if uniq.size > _MAX_TABLE:
        return None, None
    hs = np.array([h[index == j].mean() for j in range(uniq.size)])
    table = np.stack(np.broadcast_arrays(*coefficients(w[None, :], z, hs[:, None])), axis=1)
    return index, table  # table shape (n_distinct, 8, n_periods)


def peak_displacement(a, h, w, z):
    """``max |u|`` over the record for every ω (the time loop; arrays over the periods)."""
    index, table = _step_tables(h, w, z)
    n, m = a.size, w.size
    u, v = np.zeros(m), np.zeros(m)
    peak = np.zeros(m)
    U = np.zeros((min(_BLOCK, n - 1) + 1, m))
    V = np.zeros_like(U)
    start = 0  # sample index of row 0 of the buffer
    row = 0
    for i in range(n - 1):
        if table is not None:
            a11, a12, a21, a22, b11, b12, b21, b22 = table[index[i]]
        else:
            a11, a12, a21, a22, b11, b12, b21, b22 = coefficients(w, z, h[i])
        u, v = (
            a11 * u + a12 * v + b11 * a[i] + b12 * a[i + 1],
            a21 * u + a22 * v + b21 * a[i] + b22 * a[i + 1],
        )
        row += 1
        U[row], V[row] = u, v
        if row == U.shape[0] - 1 or i == n - 2:
            peak = _fold_block(peak, U[: row + 1], V[: row + 1], a, h, start, w, z)
            U[0], V[0] = U[row], V[row]
            start, row = i + 1, 0
    return peak


def _fold_block(peak, U, V, a, h, start, w, z):
    """Update the running peak with a block of samples and the extrema between them."""
    stop = start + U.shape[0]
    peak = np.maximum(peak, np.max(np.abs(U), axis=0))
    hb = h[start : stop - 1, None]
    a0, a1 = a[start : stop - 1], a[start + 1 : stop]
    mid = _peak_between_cols(U[:-1], V[:-1], U[1:], V[1:], a0, a1, hb, w, z)
    return np.maximum(peak, mid)


def _peak_between_cols(u0, v0, u1, v1, a0, a1, h, w, z):
    """Per period, the largest ``|u|`` at the extrema (u̇ = 0) that fall between samples."""
    out = np.zeros(w.size)
    hh = np.broadcast_to(h, u0.shape)
    c1 = hh * v0
    c2 = 3.0 * (u1 - u0) - hh * (2.0 * v0 + v1)
    c3 = 2.0 * (u0 - u1) + hh * (v0 + v1)
    r1, r2 = quadratic_roots(3.0 * c3, 2.0 * c2, c1)  # p'(s) = 0
    cand = np.where((r1 > 0) & (r1 < 1), r1, np.where((r2 > 0) & (r2 < 1), r2, np.nan))
    ok = (v0 * v1 < 0) & np.isfinite(cand)
    if not np.any(ok):
        return out
    rows, cols = np.nonzero(ok)
    s = cand[ok]
    aa0, aa1 = a0[rows], a1[rows]
    hk, wk, uk, vk = hh[ok], w[cols], u0[ok], v0[ok]
    for _ in range(_NEWTON):  # polish the Hermite guess on the exact u̇(s) = 0
        u_s, v_s, a_s = _partial_step(uk, vk, aa0, aa1, s, hk, wk, z)
        acc = -a_s - 2.0 * z * wk * v_s - wk * wk * u_s
        with np.errstate(divide="ignore", invalid="ignore"):
            s_new = s - v_s / (acc * hk)
        s = np.where(np.isfinite(s_new), np.clip(s_new, 0.0, 1.0), s)
    u_s, _, _ = _partial_step(uk, vk, aa0, aa1, s, hk, wk, z)
    np.maximum.at(out, cols, np.abs(u_s))
    return out


def _partial_step(u0, v0, a0, a1, s, h, w, z):
    """Exact (u, u̇, a_g) at the fraction `s` of a step, by the recurrence over s·h."""
    a_s = a0 + (a1 - a0) * s
    a11, a12, a21, a22, b11, b12, b21, b22 = coefficients(w, z, s * h)
    u_s = a11 * u0 + a12 * v0 + b11 * a0 + b12 * a_s
    v_s = a21 * u0 + a22 * v0 + b21 * a0 + b22 * a_s
    return u_s, v_s, a_s
