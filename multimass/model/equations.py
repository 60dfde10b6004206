"""The equations of the multi-mass rocking structure, each written once (paper 001, Sec 2).

Every function is one equation of paper 001, or one named term of one, as an
expression of per-node values and of sums over the nodes that its caller has
formed: ``cud`` and ``ku`` are the rows of C u̇ and K u, ``smu`` = 1ᵀMu,
``umu`` = uᵀMu, ``h_m_ud`` = HᵀMu̇, ... No function calls another or takes a
cosine: the caller passes ``c`` = cos θ and ``sn`` = sin θ (one exception,
`free_rocking_peak`, the energy balance of a rigid block's free swing, takes sines of
α on scalars). So the same source

* runs as NumPy on arrays — over the nodes of one state (the solve_ivp
  right-hand sides of `multimass.model._phase`, the structure-level API of
  `multimass.model.eom` and `multimass.model.kinematics`), or over rows × nodes of a
  recorded history (`multimass.model.eom.state_accelerations`, the recorder);
* and compiles unchanged with numba on scalars inside the loops of the
  compiled path (`multimass.engines.fast._maths` registers every function of
  ``__all__`` with `numba.extending.register_jitable`).

The two paths therefore evaluate one source of the physics; the tests compare
their drivers and sums (`tests/multimass/engines/test_fast.py`), and the equations
themselves against the Lagrangian derivation (`multimass.model.symbolic`), the
paper-000 contact engine and the energy ledger. The Gaussian impact force
(Eqs 14–17) lives with its model in `multimass.impact_models.gaussian_force`.

Notation: ``side`` s = +1 for the right pivot, −1 for the left (paper 001's
upper / lower sign; ∓ = −s), 0 in full contact.
"""

from __future__ import annotations

import math

__all__ = [
    "full_contact_acceleration",
    "pivot_arm",
    "rocking_forcing_u",
    "lever_arm",
    "rocking_inertia",
    "rocking_forcing_theta",
    "rocking_theta_acceleration",
    "rocking_u_acceleration",
    "total_acceleration",
    "kinetic_energy",
    "gravitational_energy",
    "ground_power",
    "impact_power",
    "pivot_momentum",
    "overturning_moment",
    "restoring_moment",
    "uplift_margin",
    "free_rocking_peak",
]


def full_contact_acceleration(cud, ku, m, ag):
    """ü of a node in full contact: M ü + C u̇ + K u = −M 1 ü_g with M diagonal."""
    return -(cud + ku) / m - ag  # paper 001, Eq 3


def pivot_arm(side, B, m, u):
    """M(±B1 − u) per node: the mass times its lever about the pivot (Eqs 4–5)."""
    return m * (side * B - u)


def rocking_forcing_u(arm, thetadot, cud, ku, m, ag, c, sn, g):
    """Row of Eq 4 with the inertia M ü + M H θ̈ on the left, all else on the right.

    b_u = −M(±B1 − u) θ̇² − C u̇ − K u − M 1 (ü_g cos θ − g sin θ); `arm` is `pivot_arm`.
    """
    return -arm * thetadot * thetadot - cud - ku - m * (ag * c - g * sn)  # paper 001, Eq 4


def lever_arm(side, B, m_t, smu):
    """ℓ = ±1ᵀM(B1 ∓ u) ± m0 B = ±B m_t − 1ᵀMu: the weights' lever in Eq 5's ü_g and g terms."""
    return side * B * m_t - smu


def rocking_inertia(J_p, umu, side, B, smu):
    """A_θθ = J_p + uᵀMu ∓ 2B 1ᵀMu, the coefficient of θ̈ in Eq 5."""
    return J_p + umu - 2.0 * side * B * smu


def rocking_forcing_theta(thetadot, ud_arm, B, F_i, ag, static_moment, lever, c, sn, g):
    """Eq 5 with the inertia HᵀM ü + A_θθ θ̈ on the left, all else on the right.

    b_θ = 2θ̇ u̇ᵀM(±B1 − u) − 2B F_i − ü_g (h cos θ + ℓ sin θ) − g (−h sin θ + ℓ cos θ)
    with h = HᵀM1 + m0 h0 (`static_moment`), ℓ = `lever_arm` and
    ``ud_arm`` = u̇ᵀM(±B1 − u).
    """
    return (
        2.0 * thetadot * ud_arm
        - 2.0 * B * F_i
        - ag * (static_moment * c + lever * sn)
        - g * (-static_moment * sn + lever * c)
    )  # paper 001, Eq 5


def rocking_theta_acceleration(b_theta, h_bu, a_tt, h_m_h):
    """θ̈ of Eqs 4–5 by the Schur complement of the diagonal M (solved, not inverted).

    θ̈ = (b_θ − Hᵀb_u) / (A_θθ − HᵀMH); the pivot
    A_θθ − HᵀMH = Σ m (u − sB)² + m0 (B² + h0²) + J0 is positive.
    """
    return (b_theta - h_bu) / (a_tt - h_m_h)


def rocking_u_acceleration(b_u, m, H, thetaddot):
    """ü of Eq 4 once θ̈ is known: M⁻¹ b_u − H θ̈."""
    return b_u / m - H * thetaddot


def total_acceleration(side, B, g, u, uddot, H, thetaddot, thetadot, ag, c, sn):
    """Total lateral acceleration of a node in the direction of u.

    a = ü + H θ̈ + (±B − u) θ̇² + ü_g cos θ − g sin θ; in full contact
    (side 0, θ = θ̇ = θ̈ = 0) it is ü + ü_g.
    """
    return (
        uddot + H * thetaddot + (side * B - u) * thetadot * thetadot + ag * c - g * sn
    )  # paper 001, Eq 7


def kinetic_energy(ud_m_ud, h_m_ud, a_tt, thetadot):
    """T = ½ q̇ᵀ A q̇ with A the mass matrix of Eqs 4–5: ½u̇ᵀMu̇ + θ̇ HᵀMu̇ + ½ A_θθ θ̇²."""
    return 0.5 * ud_m_ud + thetadot * h_m_ud + 0.5 * a_tt * thetadot * thetadot


def gravitational_energy(g, static_moment, lever, c, sn):
    """V_g − V_g(rest) = g (h (cos θ − 1) + ℓ sin θ), the potential whose gradient is Eq 5's g term."""
    return g * (static_moment * (c - 1.0) + lever * sn)


def ground_power(ag, m_ud, thetadot, static_moment, lever, c, sn):
    """Power of the effective ground forces −ü_g Σ m Ẋ (Ẋ: horizontal relative velocities).

    Σ m Ẋ = 1ᵀMu̇ cos θ + θ̇ (h cos θ + ℓ sin θ); in full contact (θ = θ̇ = 0)
    it is 1ᵀMu̇. Its time integral is the ledger's ground work.
    """
    return -ag * (m_ud * c + thetadot * (static_moment * c + lever * sn))


def impact_power(B, F_i, thetadot):
    """Rate of work of the impact force's moment 2B F_i (Eq 5): the ledger's W_F integrand."""
    return 2.0 * B * F_i * thetadot


def pivot_momentum(h_m_ud, thetadot, J_p, m_t, B, umu):
    """Angular momentum at θ = 0 about the impending pivot, in the sense of θ.

    L_p = HᵀMu̇ + θ̇ (J_p − 2 m_t B² + uᵀMu): the same for either pivot. It is
    paper 001's L_p^r at the end of a half-cycle and L'_p before an impact
    (Sec 2.3–2.4), and L_p^fc in full contact (θ̇ = 0).
    """
    return h_m_ud + thetadot * (J_p - 2.0 * m_t * B * B + umu)


def overturning_moment(h_m_acc, m0_h0, ag):
    """M_o^fc = HᵀM(ü + 1 ü_g) + m0 h0 ü_g: the moment of the full-contact inertia forces.

    ``h_m_acc`` = HᵀM(ü + 1 ü_g) with ü of Eq 3 (`full_contact_acceleration`).
    """
    return h_m_acc + m0_h0 * ag


def restoring_moment(side, g, m_t, B, smu):
    """M_res^fc about pivot `side`: g (m_t B ∓ 1ᵀMu)."""
    return g * (m_t * B - side * smu)


def uplift_margin(side, M_o, M_res, L, m_ref, l_ref):
    """Both uplift conditions about pivot `side` as one value, positive once they hold.

    ∓M_o^fc > M_res^fc and ±L_p^fc > 0, each scaled by its reference
    (`m_ref` a moment, `l_ref` an angular momentum); the smaller decides.
    """
    return min((-side * M_o - M_res) / m_ref, side * L / l_ref)  # paper 001, Eq 8


def free_rocking_peak(alpha, q):
    """``|θ|`` at the end of a free swing of a rigid block that holds the fraction `q` of
    the overturning barrier, q = E / (m g R (1 − cos α)), E its energy above rest.

    With no ground motion a rigid block's energy is conserved between impacts, and
    impacts only remove it (Housner 1963; the energy barrier of paper 004). A swing
    moving away from θ = 0 (or at its turning point) therefore peaks where all of E
    is potential energy, m g R [cos(α − ``|θ|``) − cos α] = E:
    ``|θ|`` = α − arccos(cos α + E / (m g R)), written with 1 − cos x = 2 sin²(x / 2)
    as α − 2 arcsin(sin(α / 2) √(1 − q)) (no cancellation for a slender block); every
    later swing holds less energy and peaks lower. `q` is clipped to [0, 1]
    (θ = 0 … α). Scalars (`multimass.engines._run.PhaseLoop.run`, the compiled block kernel,
    `multimass.engines._newmark_events.Run.energy_stop`).
    """
    q = min(max(q, 0.0), 1.0)
    return alpha - 2.0 * math.asin(math.sin(0.5 * alpha) * math.sqrt(1.0 - q))
