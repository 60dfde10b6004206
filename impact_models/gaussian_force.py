"""The Gaussian Dirac-delta impact force of paper 001 (Eqs 14–17), each equation once.

Plain functions of scalars (or NumPy arrays where noted) that run as Python
and compile unchanged with numba: `multimass.impact_models.models.DiracDelta`,
the solve_ivp path (`multimass.model._phase`, `multimass.engines._events`) and the compiled
path (`multimass.engines.fast._maths`, which registers every function of ``__all__``
with `numba.extending.register_jitable`) all call these. ``side`` is the
current pivot (+1 right, −1 left); the force acts at the impending one, −side.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "impact_force",
    "impact_width",
    "activation_angle",
    "activation_margin",
    "deactivation_angle",
    "deactivation_margin",
]

_SQRT_PI = math.sqrt(math.pi)
_SQRT_2 = math.sqrt(2.0)


def impact_force(theta, side, E_ini, r, n, B):
    """F_i = ±E_ini (1 − r²)/(B n √π) exp(−θ²/n²), opposing the approach to θ = 0.

    ± is the impending pivot (−side), which makes the moment 2B F_i in Eq 5
    brake the motion. `theta` may be an array.
    """
    amplitude = -side * E_ini * (1.0 - r * r) / (B * n * _SQRT_PI)
    return amplitude * np.exp(-(theta * theta) / (n * n))  # paper 001, Eq 14


def impact_width(E_ini, r, B, m_t, g, C_p, thetadot_i, n_min):
    """Width parameter n = E_ini (1 − r²)/(B √π (m_t g/2 + C_p ``|θ̇_i|``)), at least `n_min`."""
    peak = 0.5 * m_t * g + C_p * abs(thetadot_i)  # bound on the peak force / (B √π)
    return max(E_ini * (1.0 - r * r) / (B * _SQRT_PI * peak), n_min)  # paper 001, Eq 15


def activation_angle(z, n):
    """``|θ_i|`` = z n/√2 with z = 2.576, the 99.5 % interval of the Gaussian."""
    return z * n / _SQRT_2  # paper 001, Eq 16


def activation_margin(theta, theta_i, side, L, l_ref, thetadot, thetadot_min):
    """The three activation conditions as one value, negative once all hold.

    ±θ > ±θ_i (``|θ|`` below ``|θ_i|``), ±L'_p > 0 and ±θ̇ > θ̇_min with ± the
    impending pivot −side; L scaled by `l_ref`, θ̇ by θ̇_min. The angle enters signed
    (side·θ, positive on the current pivot), so the margin changes sign when θ passes
    θ_i even if a step jumps over the whole window −θ_i … θ_i (S2, r → 1: θ_i ≈ 2e-4
    rad against ~2e-3 rad per step); with ``|θ|`` such an impact lost no energy.
    """
    side_imp = -side
    return max(
        side * theta / theta_i - 1.0,
        -side_imp * L / l_ref,
        (thetadot_min - side_imp * thetadot) / thetadot_min,
    )  # paper 001, Eq 16


def deactivation_angle(release, theta_i):
    """``|θ|`` beyond which a force moving away from impact is dropped: 1.1 ``|θ_i|`` (`release` = 1.1)."""
    return release * abs(theta_i)  # paper 001, Eq 17


def deactivation_margin(side, theta, limit):
    """±θ − limit: positive once the structure has moved back past `deactivation_angle`."""
    return side * theta - limit
