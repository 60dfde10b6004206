"""Synthetic shake-table records of a linear full-contact response, for the FRF tests.

The ground acceleration is band-limited noise on a fine grid (`over` × the recorded
rate); the response of `multimass.modal.state_space` to it, taken as the piecewise-
linear input through those samples, is computed exactly (first-order hold, as
`scipy.signal.lsim` with ``interp=True``, but one `scipy.signal.lfilter` per mode
instead of a Python loop: tests/modal/test_measured_frf.py checks the two agree).
Recording every `over`-th sample keeps what the model's FRF says up to the factor
sinc²(f / (over · fs)) of the hold (≤ 0.1 % below 60 Hz for fs = 200 Hz, over = 10).
"""

from __future__ import annotations

import numpy as np
import scipy.signal as sig


def foh_response(system, u: np.ndarray, h: float) -> np.ndarray:
    """Outputs (n_outputs, n) of a diagonalisable `system` (A, B, C, D; one input), at rest
    at t = 0, driven by the piecewise-linear input through the samples `u` (step `h`)."""
    A, B, C, D = (np.asarray(m, dtype=float) for m in (system.A, system.B, system.C, system.D))
    lam, V = np.linalg.eig(A)
    b = np.linalg.solve(V, B[:, 0])
    e = np.exp(lam * h)
    e1 = (e - 1.0) / lam  # ∫_0^h e^{λ(h−s)} ds
    e2 = (e - 1.0 - lam * h) / (lam**2 * h)  # ∫_0^h e^{λ(h−s)} s/h ds
    z = np.empty((lam.size, u.size), dtype=complex)
    for k in range(lam.size):  # z[n] = e z[n−1] + b (e1 − e2) u[n−1] + b e2 u[n], z[0] = 0
        num = [b[k] * e2[k], b[k] * (e1[k] - e2[k])]
        z[k], _ = sig.lfilter(num, [1.0, -e[k]], u, zi=[-num[0] * u[0]])
    return (C @ V @ z).real + D @ u[None, :]


def band_noise(n: int, fs: float, band=(1.0, 60.0), rng=None) -> np.ndarray:
    """`n` samples of Gaussian noise band-passed to `band` (Hz), unit standard deviation."""
    rng = np.random.default_rng(rng)
    sos = sig.butter(6, band, btype="band", fs=fs, output="sos")
    u = sig.sosfilt(sos, rng.standard_normal(n))
    return u / u.std()


def full_contact_record(
    structure, duration: float, *, fs=200.0, over=10, sensors=None, noise=0.02, seed=1
):
    """(t, ag, acc): a linear full-contact response to band-limited table motion, recorded
    at `fs` with white output noise of `noise` × each channel's standard deviation."""
    from multimass.modal import state_space

    rng = np.random.default_rng(seed)
    n = int(round(duration * fs)) * over
    u = band_noise(n, fs * over, rng=rng)
    y = foh_response(state_space(structure, "full_contact", sensors), u, 1.0 / (fs * over))
    t, ag, acc = np.arange(n // over) / fs, u[::over], y[:, ::over]
    acc = acc + noise * acc.std(axis=1, keepdims=True) * rng.standard_normal(acc.shape)
    return t, ag, acc


def with_rocking(t, ag, acc, spans, *, amplitude=0.01, seed=2):
    """θ (rad) for the record, and `acc` spoiled inside `spans` ((t0, t1) s): there θ swings
    at `amplitude` (rocking) and the accelerations are noise unrelated to ü_g; elsewhere θ is
    a sensor's noise of 2e-5 rad."""
    rng = np.random.default_rng(seed)
    theta = 2e-5 * rng.standard_normal(t.size)
    acc = acc.copy()
    for a, b in spans:
        inside = (t >= a) & (t < b)
        theta[inside] = amplitude * np.cos(2 * np.pi * 1.3 * (t[inside] - a))
        acc[:, inside] = 3.0 * acc.std() * rng.standard_normal((acc.shape[0], inside.sum()))
    return theta, acc


def write_trace(path, t, theta, ag, acc, names) -> None:
    """A trace CSV: t [s], theta [rad], ag [m/s2] and one `<name> [m/s2]` column per row of acc."""
    header = ",".join(["t [s]", "theta [rad]", "ag [m/s2]", *(f"{k} [m/s2]" for k in names)])
    data = np.column_stack([t, theta, ag, *acc])
    rows = "\n".join(",".join(f"{x:.9g}" for x in row) for row in data)
    path.write_text(header + "\n" + rows + "\n", encoding="utf-8")
