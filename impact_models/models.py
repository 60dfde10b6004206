"""Impact models: the classical instantaneous impact and the Gaussian Dirac-delta force.

An impact model has two duties (DESIGN.md): (1) a force acting while rocking
near θ = 0 (none for the classical model; the Gaussian F_i of paper 001,
Eqs 14–17, for the Dirac-delta model), and (2) the transition map at θ = 0:
given the state at the end of a half-cycle, the next phase and the
post-transition velocities (paper 001, Eqs 9–12).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from multimass.errors import InputError

from .gaussian_force import activation_angle, deactivation_angle, impact_width
from .sources import Restitution

__all__ = [
    "Transition",
    "ImpactModel",
    "Classical",
    "DiracDelta",
    "next_phase_is_rocking",
    "classical_rebound",
    "full_contact_velocities",
]


@dataclass(frozen=True)
class Transition:
    """Outcome of the transition map at θ = 0.

    Attributes
    ----------
    phase : int
        Next phase: +1 / −1 rocking about the right / left pivot, 0 full contact.
    udot : ndarray
        Elastic velocities after the transition.
    thetadot : float
        Rocking velocity after the transition.
    kind : str
        "impact" (a new half-cycle) or "full_contact".
    restitution : float or None
        The coefficient applied (classical impacts only).
    detail : str
        What decided the transition (e.g. the LCP's contact states).
    """

    phase: int | None
    udot: np.ndarray
    thetadot: float
    kind: str
    restitution: float | None = None
    detail: str = ""


def next_phase_is_rocking(
    side_new: int, L_new: float, thetadot: float, thetadot_min: float
) -> bool:
    """Paper 001, Eq 9: ±L_p^r ≥ 0 and ±θ̇⁻ > θ̇_min (± = the new pivot)."""
    return side_new * L_new >= 0.0 and side_new * thetadot > thetadot_min  # paper 001, Eq 9


def classical_rebound(thetadot: float, r: float) -> float:
    """θ̇⁺ = r θ̇⁻ of the classical impact (paper 001, Eq 11; the elastic velocities are kept)."""
    return r * thetadot  # paper 001, Eq 11


def full_contact_velocities(H, udot, thetadot):
    """u̇⁺ = u̇⁻ + H θ̇⁻ of a drop to full contact (θ̇⁺ = 0): the vertical momentum is
    lost, each node's horizontal momentum kept."""
    return udot + H * thetadot  # paper 001, Eq 10


@dataclass(frozen=True)
class ImpactModel:
    """Base class: Eq 9 chooses the next phase, Eq 10 drops to full contact,
    and subclasses give the rebound of a new half-cycle (`rebound`)."""

    restitution: Restitution
    name: str = "impact"
    has_force = False

    def rebound(self, thetadot: float, udot: np.ndarray, r: float) -> tuple[float, np.ndarray]:
        """Velocities (θ̇⁺, u̇⁺) of a new half-cycle."""
        raise NotImplementedError

    def at_zero(
        self,
        H: np.ndarray,
        side_old: int,
        L_new: float,
        udot: np.ndarray,
        thetadot: float,
        r: float,
        thetadot_min: float,
    ) -> Transition:
        """The transition map at the end of a half-cycle (θ = 0).

        Parameters
        ----------
        H : ndarray
            Node heights.
        side_old : int
            The pivot of the half-cycle that ends.
        L_new : float
            Angular momentum about the impending pivot (paper 001, Eq 9).
        udot, thetadot : pre-transition velocities.
        r : float
            Restitution for this corner.
        thetadot_min : float
            θ̇_min of Eq 9 (rad/s).
        """
        side_new = -side_old
        if next_phase_is_rocking(side_new, L_new, thetadot, thetadot_min):
            td, ud = self.rebound(thetadot, udot, r)
            return Transition(
                side_new, ud, td, "impact", r if self.uses_restitution_at_zero else None
            )
        return Transition(0, full_contact_velocities(H, udot, thetadot), 0.0, "full_contact")

    uses_restitution_at_zero = False


@dataclass(frozen=True)
class Classical(ImpactModel):
    """Classical impact model, CIM (paper 001, Eq 11): θ̇⁺ = r θ̇⁻, u̇⁺ = u̇⁻."""

    name: str = "CIM"
    uses_restitution_at_zero = True

    def rebound(self, thetadot, udot, r):
        return classical_rebound(thetadot, r), udot.copy()


@dataclass(frozen=True)
class DiracDelta(ImpactModel):
    """Gaussian Dirac-delta impact force (paper 001, Eqs 14–17).

    Attributes
    ----------
    restitution : Restitution
        r of the impending corner, fixed when the force activates.
    C_p : float
        Proportionality between ``|θ̇_i|`` and the peak force (kg m/rad/s; Table 2).
    n_min : float
        Lower bound of the width parameter n (paper 001: 1e-4).
    z : float
        Activation angle in standard deviations (2.576: 99.5 %, Eq 16).
    release : float
        Deactivation at `release` × θ_i when moving away (1.1, Eq 17).
    """

    C_p: float = 1750.0
    n_min: float = 1e-4
    z: float = 2.576
    release: float = 1.1
    name: str = "DD"
    has_force = True

    def __post_init__(self):
        for key in ("C_p", "n_min", "z"):
            v = getattr(self, key)
            if not (math.isfinite(v) and v > 0.0):
                raise InputError(f"`{key}` = {v!r}: must be a positive number")
        if not (math.isfinite(self.release) and self.release >= 1.0):
            raise InputError(f"`release` = {self.release!r}: must be ≥ 1 (paper 001 uses 1.1)")

    def rebound(self, thetadot, udot, r):
        """Velocities after the transition at θ = 0: unchanged, ``θ̇⁺ = θ̇⁻, u̇⁺ = u̇⁻``
        (the force has already dissipated the impact's energy; `r` is not used here)."""
        return thetadot, udot.copy()  # paper 001, Eq 12

    def width(
        self, E_ini: float, r: float, B: float, m_t: float, g: float, thetadot_i: float
    ) -> float:
        """Width parameter n (`gaussian_force.impact_width`, Eq 15) with this model's C_p, n_min."""
        return impact_width(E_ini, r, B, m_t, g, self.C_p, thetadot_i, self.n_min)

    def threshold(self, n: float) -> float:
        """``|θ_i|`` = 2.576 n/√2 (`gaussian_force.activation_angle`, Eq 16) with this model's z."""
        return activation_angle(self.z, n)

    def release_angle(self, theta_i: float) -> float:
        """``|θ|`` at which a force moving away from impact is dropped (`deactivation_angle`, Eq 17)."""
        return deactivation_angle(self.release, theta_i)
