"""Rayleigh damping fitted to two full-contact modes (paper 001, Section 2.1)."""

from __future__ import annotations

import numpy as np

__all__ = ["rayleigh_coefficients", "rayleigh_damping"]


def rayleigh_coefficients(
    omega_1: float, omega_2: float, zeta_1: float, zeta_2: float
) -> tuple[float, float]:
    """Coefficients (a0, a1) of C = a0 M + a1 K giving ζ_1 at ω_1 and ζ_2 at ω_2.

    Solves ζ_k = a0 / (2 ω_k) + a1 ω_k / 2 for k = 1, 2.
    """
    d = omega_2**2 - omega_1**2
    a0 = 2.0 * omega_1 * omega_2 * (zeta_1 * omega_2 - zeta_2 * omega_1) / d
    a1 = 2.0 * (zeta_2 * omega_2 - zeta_1 * omega_1) / d
    return float(a0), float(a1)


def rayleigh_damping(
    M: np.ndarray, K: np.ndarray, zeta_1: float, zeta_2: float
) -> tuple[np.ndarray, tuple[float, float]]:
    """Rayleigh damping matrix fitted at the first two undamped modes of (K, M).

    With a single degree of freedom there is no second mode: the damping is
    then stiffness-proportional, C = (2 ζ_1 / ω_1) K, which gives exactly ζ_1
    (ζ_2 is not used).

    Returns
    -------
    C : ndarray
        Damping matrix.
    (a0, a1) : tuple of float
        Its mass and stiffness coefficients.
    """
    import scipy.linalg as sla  # here: a rigid block's runs need no SciPy

    omega = np.sqrt(sla.eigh(K, M, eigvals_only=True))
    if omega.size == 1:
        a0, a1 = 0.0, float(2.0 * zeta_1 / omega[0])
    else:
        a0, a1 = rayleigh_coefficients(omega[0], omega[1], zeta_1, zeta_2)
    return a0 * M + a1 * K, (a0, a1)
