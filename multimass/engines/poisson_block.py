"""Rigid rocking block with Poisson impacts as LCPs (paper 000, Section 3).

The block is 2b wide and 2h tall (paper 000 writes 2H for the height), mass m,
I_G = m R²/3 with R = √(b² + h²) the half-diagonal (paper 000, after Eq 13).
Generalised coordinates q = (x, y, φ): x the horizontal displacement of the
centre of mass relative to the ground, y its height above the ground (y = h at
rest), and φ the rotation, **counter-clockwise positive as in paper 000**.
Contact 0 is the left corner (paper 000's point '1'), contact 1 the right
corner (point '2'). At φ = 0 the matrices are those of Eq 13, with one
resultant tangential direction for the two corners.

Sign conventions: the toolkit's θ (paper 001, Fig 1: θ > 0 rocks about the
right pivot) is θ = −φ. A positive ground acceleration (ground moving to +x)
tips the block about its left corner, φ > 0, θ < 0.

Phases (full contact, rocking on either corner, free flight) are the closed
contact sets of `multimass.engines.contact_dynamics`; every impact is resolved by
`impact_models.poisson_impact`. In the result contract's words
(`multimass.result`): phase 0 is full contact, +1 rocking on the right corner
(contact 1 only: φ < 0, θ > 0), −1 on the left corner (contact 0 only), None in
flight; reaching ``|φ|`` = π/2 is an event "overturn" and the outcome "overturned".
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..validation import number, positive
from ._contact_checks import ground_excitation
from .contact_dynamics import ContactResponse, ContactView, simulate_contacts

__all__ = ["PoissonBlock", "BlockResponse", "simulate_block", "housner_theta"]


@dataclass(frozen=True)
class PoissonBlock:
    """A rigid rectangular block 2b × 2h on a rigid base (paper 000, Fig 2a).

    Parameters
    ----------
    b : float
        Half-width (m).
    h : float
        Half-height (m); paper 000's H.
    mass : float
        Mass (kg).
    g : float
        Gravitational acceleration (m/s²).
    """

    b: float
    h: float
    mass: float = 1.0
    g: float = 9.81

    def __post_init__(self):
        for name in ("b", "h", "mass", "g"):
            object.__setattr__(self, name, positive(name, getattr(self, name)))
        try:
            derived = dict(
                alpha=self.alpha,
                R=self.R,
                I_G=self.I_G,
                p=self.p,
                weight=self.mass * self.g,
                R_squared=self.R**2,
            )
            bad = [k for k, v in derived.items() if not (math.isfinite(v) and v > 0.0)]
        except (OverflowError, ZeroDivisionError):
            bad = ["quantities"]
        if bad:
            raise InputError(
                f"PoissonBlock(b={self.b!r}, h={self.h!r}, mass={self.mass!r}, "
                f"g={self.g!r}): derived {', '.join(bad)} not finite and "
                "positive; give SI values of ordinary size (m, kg, m/s²)"
            )

    @classmethod
    def from_slenderness(cls, h_over_b: float, width: float = 1.0, **kw) -> PoissonBlock:
        """Block of base width 2b = `width` and H/b = `h_over_b` (paper 000, Sec 3.3)."""
        b = positive("width", width) / 2.0
        return cls(b=b, h=positive("h_over_b", h_over_b) * b, **kw)

    @property
    def alpha(self) -> float:
        """Slenderness α = atan(b/h) (rad)."""
        return math.atan2(self.b, self.h)

    @property
    def R(self) -> float:
        """Half-diagonal (m)."""
        return math.hypot(self.b, self.h)

    @property
    def I_G(self) -> float:
        """Moment of inertia about the centre of mass, m R²/3 (kg m²)."""
        return self.mass * self.R**2 / 3.0  # paper 000, after Eq 13

    @property
    def p(self) -> float:
        """Frequency parameter p = √(3g / 4R) (rad/s) (paper 000, Sec 3.3)."""
        return math.sqrt(3.0 * self.g / (4.0 * self.R))

    def mass_matrix(self) -> np.ndarray:
        """M of paper 000, Eq 13."""
        return np.diag([self.mass, self.mass, self.I_G])

    def impact_matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(M, W_N, W_T) at φ = 0 with both corners closed (paper 000, Eq 13)."""
        b, h = self.b, self.h
        W_N = np.array([[0.0, 0.0], [1.0, 1.0], [-b, b]])  # paper 000, Eq 13
        W_T = np.array([[1.0], [0.0], [h]])  # paper 000, Eq 13
        return self.mass_matrix(), W_N, W_T

    def rocking_state(self, phi: float, dphi: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """(q, q̇) of the block rotated by φ about the corner that stays down.

        φ > 0 pivots on the left corner, φ < 0 on the right; for φ = 0 the pivot
        is chosen by the sign of φ̇ (φ̇ = 0: full contact).
        """
        s = -np.sign(phi) if phi != 0.0 else -np.sign(dphi)
        c, sn = math.cos(phi), math.sin(phi)
        x = s * self.b - (s * self.b * c + self.h * sn)
        y = -s * self.b * sn + self.h * c
        return np.array([x, y, phi]), dphi * np.array([-y, x - s * self.b, 1.0])


class _BlockModel:
    """`contact_dynamics` model of the block under a horizontal ground acceleration."""

    n, k = 3, 2
    rotation = 2  # q[2] = φ, counter-clockwise: θ = −φ
    pivots = (0, 1)  # contact 0 the left corner, contact 1 the right one

    def __init__(self, block: PoissonBlock, ag, quiet_after: float = np.inf):
        self.bl, self.ag, self.quiet_after = block, ag, quiet_after
        self._M = block.mass_matrix()
        self.events = (("overturn", lambda t, q, v: abs(q[2]) - 0.5 * math.pi),)

    def mass(self, q):
        return self._M

    def forces(self, t, q, v):
        m = self.bl.mass
        return np.array([-m * self.ag(t), -m * self.bl.g, 0.0])

    def contacts(self, q, v):
        b, h = self.bl.b, self.bl.h
        c, sn, w = math.cos(q[2]), math.sin(q[2]), v[2]
        s = np.array([-1.0, 1.0])
        g = q[1] + s * b * sn - h * c
        WN = np.array([[0.0, 0.0], [1.0, 1.0], s * b * c + h * sn])
        WT = np.array([[1.0, 1.0], [0.0, 0.0], -s * b * sn + h * c])
        return g, WN, WT, (-s * b * sn + h * c) * w * w, (-s * b * c - h * sn) * w * w

    def energy(self, q, v):
        bl = self.bl
        T = 0.5 * (bl.mass * (v[0] ** 2 + v[1] ** 2) + bl.I_G * v[2] ** 2)
        return T + bl.mass * bl.g * (q[1] - bl.h)

    def powers(self, t, q, v):
        return -self.bl.mass * self.ag(t) * v[0], 0.0


@dataclass(frozen=True, eq=False)
class BlockResponse(ContactView):
    """Response of `simulate_block`: the contact response with the block's views.

    A `multimass.result.Result` (engine "contact") through
    `multimass.engines.contact_dynamics.ContactView`; ``series`` names the block's
    coordinates x, y (centre of mass, m) and φ (counter-clockwise, rad).

    Attributes
    ----------
    block : PoissonBlock
    eps_p : float
    raw : ContactResponse
    """

    block: PoissonBlock
    eps_p: float
    raw: ContactResponse

    COORDINATES = ("x", "y", "phi")
    x = property(lambda self: self.coordinate("x"), doc="Centre of mass, horizontal (m).")
    y = property(lambda self: self.coordinate("y"), doc="Centre of mass height (m; h at rest).")
    phi = property(lambda self: self.coordinate("phi"), doc="Rotation, counter-clockwise (rad).")

    def _summary_extra(self) -> dict:
        bl = self.block
        return self.raw._summary_extra() | {
            "model": "poisson_block",
            "eps_p": self.eps_p,
            "b": bl.b,
            "h": bl.h,
            "mass": bl.mass,
            "alpha": bl.alpha,
        }


def simulate_block(
    block: PoissonBlock,
    eps_p: float,
    t_end: float,
    *,
    phi0: float = 0.0,
    dphi0: float = 0.0,
    ag=None,
    dt_out: float | None = 0.01,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    zeno_velocity: float | None = None,
    max_events: int = 20_000,
    locked_dt: float = 0.002,
    mu: float | None = None,
) -> BlockResponse:
    """Event-driven response of the block with Poisson impacts (paper 000, Sec 3.3).

    Parameters
    ----------
    block : PoissonBlock
    eps_p : float
        Poisson's coefficient of restitution ε_P ∈ [0, 1].
    t_end : float
        End time (s).
    phi0, dphi0 : float
        Initial rotation (rad, counter-clockwise, ``|φ0| < π/2``) and rate (rad/s);
        the block starts on the corner that stays down
        (`PoissonBlock.rocking_state`; at φ0 = 0 the corner the spin pivots
        on). The energy ledger starts from this state. A block started upright
        with a spin rocks on its pivot (the other corner separates); a spin
        towards the other corner from φ0 ≈ 0 is an impact at t = 0.
    ag : callable, optional
        Horizontal ground acceleration ag(t) (m/s²); attributes
        ``breakpoints`` (times of kinks) and ``duration`` (ag = 0 after it)
        are honoured. Default: none.
    dt_out : float or None
        Sampling interval (s).
    rtol, atol : float
        Integration tolerances.
    zeno_velocity : float, optional
        Approach speed below which an impact ends an accumulation of impacts
        (bounces, or rocking cycles shrinking to zero) by keeping all touching
        corners closed (an event "rest", ``detail`` "zeno_rest"); default 1e-4 √(g R).
    max_events : int
    locked_dt : float
        In full contact the contact forces are scanned for uplift on this grid (s).
    mu : float, optional
        Friction coefficient of the corners. Paper 000's corners stick, however
        large the tangential force; the run reports the largest friction demand
        ``|T/N|`` (``BlockResponse.friction``) and, when `mu` is given and the
        demand exceeds it, status "inaccurate" with a warning: the block would
        slide. A rigid block needs ``|T/N| = |a_g|/g`` in full contact, h/b at the
        impacts of a stocky block (h/b < 1/√2, paper 000 Eqs 14–15) and
        3 sin α cos α / (4 − 3 sin²α) at those of a slender one (Eqs 17–18);
        while it rocks, the centripetal acceleration of a squat block loads the
        pivot sideways as it unloads it (`multimass.engines._contact_checks`).

    Returns
    -------
    BlockResponse
        ``status`` is the status of ``outcome`` ("completed", "overturned";
        "max_events" fails) when the checks pass, else "inaccurate"; see
        ``checks``, ``warnings``. "failed": the solvers could not go on (e.g. a
        corner that would have to slide), the history up to there is kept and
        ``message`` says why.
    """
    if not isinstance(block, PoissonBlock):
        raise InputError(f"`block` = {block!r}: expected a PoissonBlock")
    phi0, dphi0 = number("phi0", phi0), number("dphi0", dphi0)
    if not abs(phi0) < 0.5 * math.pi:
        raise InputError(f"`phi0` = {phi0!r}: the initial rotation must lie in (−π/2, π/2)")
    ag, quiet, bps = ground_excitation(ag)
    eps_p = number("eps_p", eps_p)
    q0, v0 = block.rocking_state(phi0, dphi0)
    zv = 1e-4 * math.sqrt(block.g * block.R) if zeno_velocity is None else zeno_velocity
    raw = simulate_contacts(
        _BlockModel(block, ag, quiet),
        q0,
        v0,
        t_end,
        eps_p,
        dt_out=dt_out,
        rtol=rtol,
        atol=atol,
        gap_tol=1e-9 * block.R,
        zeno_velocity=zv,
        max_events=max_events,
        locked_dt=locked_dt,
        breakpoints=bps,
        mu=mu,
    )
    return BlockResponse(block, eps_p, raw)


def housner_theta(
    block: PoissonBlock,
    ag,
    t_start: float,
    theta0: float,
    t_grid,
    eta: float | None = None,
    side: int | None = None,
) -> np.ndarray:
    """θ(t) of the same block under Housner's classical model, the reference for Fig 5.

    θ̈ = −p²[sin(α sgnθ − θ) + (ag/g) cos(α sgnθ − θ)], θ̇⁺ = η θ̇⁻ at θ = 0
    (paper 004, Eqs 1–2; η defaults to η_H, Eq 9), in the toolkit's convention
    (θ = −φ, θ > 0 on the right pivot), integrated with solve_ivp (DOP853, rtol
    1e-12) independently of the LCP machinery. Starts at `t_start` from θ0 at rest
    on the pivot `side` (default sgn θ0). Returns θ on `t_grid` (0 before t_start).
    """
    from scipy.integrate import solve_ivp

    from multimass.impact_models import housner_eta

    a, p, g = block.alpha, block.p, block.g
    eta = housner_eta(a) if eta is None else eta
    s = side if side is not None else np.sign(theta0)
    t, y, out = t_start, np.array([theta0, 0.0]), np.zeros_like(t_grid)
    t_end = t_grid[-1]
    while t < t_end:

        def rhs(t, y, s=s):  # paper 004, Eq 1
            return [y[1], -p * p * (math.sin(a * s - y[0]) + ag(t) / g * math.cos(a * s - y[0]))]

        def cross(t, y):
            return y[0]

        cross.terminal, cross.direction = True, -s
        sol = solve_ivp(
            rhs,
            (t, t_end),
            y,
            method="DOP853",
            rtol=1e-12,
            atol=1e-14,
            events=cross,
            dense_output=True,
        )
        sel = (t_grid >= t) & (t_grid <= sol.t[-1])
        out[sel] = sol.sol(t_grid[sel])[0]
        t, y = sol.t[-1], sol.y[:, -1].copy()
        y[0], y[1], s = 0.0, eta * y[1], -s  # paper 004, Eq 2
    return out
