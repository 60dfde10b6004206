"""Poisson-LCP impacts for the multi-mass engine (paper 000, Eqs 1–12, applied to paper 001's model).

At the end of a half-cycle (θ = 0) the base is a planar rigid body carrying
the elastic column; as in paper 001 it does not slide (both corners stick,
so the base centre has no horizontal velocity, and the horizontal motion of
the nodes relative to it is u̇). In the generalised velocities
v = [u̇ (N), ẏ, θ̇] of the base centre's height y and the rocking angle θ
(clockwise, paper 001 Fig 1), the kinetic energy at θ = 0 is

    T = ½ Σ m_i [(u̇_i + H_i θ̇)² + (ẏ − u_i θ̇)²] + ½ m0 [(h0 θ̇)² + ẏ²] + ½ J0 θ̇²,

so the mass matrix has blocks M (u̇u̇), MH (u̇θ̇), m_t (ẏẏ), −Σmu (ẏθ̇) and
Σm(H² + u²) + m0h0² + J0 (θ̇θ̇); it is positive definite when J0 + m0h0² > 0
(J0 = 10 kg m² for paper 001's specimens). The corner at body abscissa
c = ±B has normal velocity ẏ − c θ̇. Before the impact the structure rotates
about its pivot s (ẏ = sBθ̇); both corners are contacts of the LCP (the
pivot closed, the other approaching) with Poisson's ε_P.

The outcome decides the next phase: new pivot closed and the old one
separating → a new half-cycle about the new pivot; both closed → full
contact; a corner separating after expansion (bouncing, flight) is outside
what the multi-mass engine models and is reported as such. Unlike the
classical model (paper 001, Eq 11) the elastic velocities change at impact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from multimass.errors import InputError

from .models import ImpactModel, Transition, full_contact_velocities
from .poisson import poisson_impact
from .sources import FixedRestitution

__all__ = ["PoissonLCP", "base_mass_matrix"]


def base_mass_matrix(structure, u) -> np.ndarray:
    """Mass matrix over [u̇ (N), ẏ, θ̇] at θ = 0 (see the module docstring)."""
    m, H = np.asarray(structure.m, float), np.asarray(structure.H, float)
    n = m.size
    M = np.zeros((n + 2, n + 2))
    M[:n, :n] = np.diag(m)
    M[:n, n + 1] = M[n + 1, :n] = m * H
    M[n, n] = m.sum() + structure.m0
    M[n, n + 1] = M[n + 1, n] = -(m @ u)
    M[n + 1, n + 1] = m @ (H * H + u * u) + structure.m0 * structure.h0**2 + structure.J0
    return M


@dataclass(frozen=True)
class PoissonLCP(ImpactModel):
    """Impact at θ = 0 solved as compression and expansion LCPs with Poisson's law.

    Attributes
    ----------
    eps_p : float
        Poisson's coefficient of restitution ε_P ∈ [0, 1]. The multi-mass
        engine has no flight phase, so ε_P > 0 runs until the LCP predicts a
        bounce, which ends the run with status "failed" and says why.
    """

    restitution: object = FixedRestitution(1.0)  # not used: the LCP decides
    eps_p: float = 0.0
    name: str = "LCP"
    resolves_impact = True

    def __post_init__(self):
        if not (
            isinstance(self.eps_p, (int, float))
            and math.isfinite(self.eps_p)
            and 0.0 <= self.eps_p <= 1.0
        ):
            raise InputError(f"`eps_p` = {self.eps_p!r}: Poisson's coefficient must lie in [0, 1]")

    def rebound(self, thetadot, udot, r):  # pragma: no cover - replaced by impact_at_zero
        raise NotImplementedError("PoissonLCP resolves the impact in impact_at_zero")

    def impact_at_zero(
        self, structure, side_old: int, u, udot, thetadot: float, thetadot_min: float
    ) -> Transition:
        """The transition at θ = 0 by the Poisson LCP (paper 000, Eqs 6 and 11)."""
        n = np.asarray(structure.m).size
        B = structure.B
        M = base_mass_matrix(structure, np.asarray(u, float))
        v = np.concatenate([udot, [side_old * B * thetadot, thetadot]])
        W_N = np.zeros((n + 2, 2))
        for k, c in enumerate((side_old * B, -side_old * B)):  # old pivot, impacting corner
            W_N[n, k], W_N[n + 1, k] = 1.0, -c  # ġ_N = ẏ − c θ̇
        res = poisson_impact(M, W_N, None, v, self.eps_p)
        old, new = (st[1] for st in res.states)
        up = res.u_plus
        detail = f"LCP: old pivot {old}, new corner {new}; energy lost {res.energy_loss:.4g} J"
        if new == "separating":
            return Transition(None, up[:n], float(up[-1]), "flight", None, detail)
        if old == "closed" or abs(up[-1]) <= thetadot_min:
            ud = full_contact_velocities(np.asarray(structure.H), up[:n], up[-1])
            return Transition(0, ud, 0.0, "full_contact", None, detail)
        return Transition(-side_old, up[:n], float(up[-1]), "impact", None, detail)
