"""The Mavroeidis–Papageorgiou near-fault pulse: velocity, acceleration, displacement.

Mavroeidis, G.P. and Papageorgiou, A.S. (2003), "A mathematical representation of
near-fault ground motions", Bull. Seismol. Soc. Am. 93(3), 1099–1131 (M&P 2003).
The model is the ground *velocity* of a near-fault pulse, a harmonic carrier under a
raised-cosine envelope::

    v(t) = A/2 [1 + cos(2π f_p τ / γ)] cos(2π f_p τ + ν),   τ = t − t0,
    for |τ| ≤ γ / (2 f_p), else 0,

with A the amplitude (m/s), f_p the prevailing frequency (Hz), γ > 1 the oscillatory
character (the number of half-cycles grows with γ), ν the phase (rad) and t0 the time
of the envelope's peak (s). The acceleration is its exact derivative and the
displacement its exact integral (written here with ψ = 2π f_p τ/γ, φ = 2π f_p τ + ν)::

    a(t) = −(A π f_p / γ) [sin ψ cos φ + γ (1 + cos ψ) sin φ],
    d(t) = A/(4π f_p) [sin φ + γ/(2(γ+1)) sin(φ + ψ) + γ/(2(γ−1)) sin(φ − ψ)] − d(t0 − γ/(2f_p)).

Each function takes floats and uses `math` only, so `multimass.engines.fast._maths` compiles
`mp_acceleration` unchanged (numba ``register_jitable``) for the compiled kernels and
`multimass.inputs.excitations.MPPulse` calls the same source on the solve_ivp path. The
functions hold inside the pulse's window; the caller returns zero outside it.
"""

from __future__ import annotations

import math

__all__ = ["mp_velocity", "mp_acceleration", "mp_displacement_raw"]

_TWO_PI = 2.0 * math.pi


def mp_velocity(t, amplitude, fp, gamma, nu, t0):
    """Ground velocity v(t) of the M&P pulse inside its window (m/s); M&P 2003's model."""
    tau = t - t0
    return (
        0.5
        * amplitude
        * (1.0 + math.cos(_TWO_PI * fp * tau / gamma))
        * math.cos(_TWO_PI * fp * tau + nu)
    )


def mp_acceleration(t, amplitude, fp, gamma, nu, t0):
    """Ground acceleration a(t) = dv/dt of the M&P pulse inside its window (m/s²)."""
    tau = t - t0
    psi = _TWO_PI * fp * tau / gamma
    phi = _TWO_PI * fp * tau + nu
    return -(amplitude * math.pi * fp / gamma) * (  # d/dt of M&P 2003's velocity
        math.sin(psi) * math.cos(phi) + gamma * (1.0 + math.cos(psi)) * math.sin(phi)
    )


def mp_displacement_raw(t, amplitude, fp, gamma, nu, t0):
    """An antiderivative of the M&P velocity (m); subtract its value at the pulse's start.

    Valid for γ ≠ 1 (M&P 2003 take γ > 1).
    """
    tau = t - t0
    psi = _TWO_PI * fp * tau / gamma
    phi = _TWO_PI * fp * tau + nu
    return (amplitude / (2.0 * _TWO_PI * fp)) * (  # ∫ of M&P 2003's velocity
        math.sin(phi)
        + gamma / (2.0 * (gamma + 1.0)) * math.sin(phi + psi)
        + gamma / (2.0 * (gamma - 1.0)) * math.sin(phi - psi)
    )
