"""Frictional contact at the velocity level: transformation matrices, Delassus
blocks, the single-contact solution and Gauss–Seidel over simultaneous
contacts (paper 002, Eqs 35–58), written for numba.
"""

from __future__ import annotations

from numba import njit

__all__ = ["block_q", "beam_q", "delassus_block", "solve_single", "gauss_seidel"]


@njit(cache=True)
def block_q(Q, cpsi, spsi, rx, ry):
    """Fill Q_k (2 × 3), block velocity → vertex velocity in the local frame (paper 002, Eq 50).

    (rx, ry) = d − G is the vertex relative to the centre of gravity, so that
    s cos λ_d = −ry and s sin λ_d = rx (Eqs 45, 47).
    """
    Q[0, 0], Q[0, 1], Q[0, 2] = cpsi, spsi, -ry * cpsi + rx * spsi  # s cos(λ − ψ)
    Q[1, 0], Q[1, 1], Q[1, 2] = -spsi, cpsi, ry * spsi + rx * cpsi  # s sin(λ − ψ)


@njit(cache=True)
def beam_q(Q, cpsi, spsi, N):
    """Fill Q_e (2 × 6), element velocities → beam-point velocity in the local frame (Eq 55)."""
    for a in (0, 3):  # axial: N_u1, N_u2
        Q[0, a], Q[1, a] = cpsi * N[a], -spsi * N[a]
    for a in (1, 2, 4, 5):  # transverse: N_v1..N_v4
        Q[0, a], Q[1, a] = spsi * N[a], cpsi * N[a]


@njit(cache=True)
def delassus_block(W, Qk_h, Qe_h, e_h, Qk_j, Qe_j, e_j, inv_mass, inv_inertia, Ainv, edof):
    """Fill W^{hj} = Q^h B Q^{jT} (2 × 2), Q = [Q_k | −Q_e] (paper 002, Eqs 43, 44, 58)."""
    minv = (inv_mass, inv_mass, inv_inertia)
    for r in range(2):
        for c in range(2):
            acc = 0.0
            for k in range(3):
                acc += Qk_h[r, k] * minv[k] * Qk_j[c, k]
            for a in range(6):
                ia = edof[e_h, a]
                if ia < 0:
                    continue
                for b in range(6):
                    ib = edof[e_j, b]
                    if ib >= 0:
                        acc += Qe_h[r, a] * Ainv[ia, ib] * Qe_j[c, b]
            W[r, c] = acc


@njit(cache=True)
def solve_single(Wnn, Wnt, Wtn, Wtt, Un, Ut, mu):
    """Impulse (P_n, P_t) = Δt R of one contact with U = Ū + W P (paper 002, Eq 41).

    Velocity Signorini 0 ≤ U_n ⊥ P_n ≥ 0 (Eq 36) and Coulomb ``|P_t| ≤ μ P_n``,
    P_t = −μ P_n sign(U_t) when sliding (Eqs 37–38). `Un` already holds the
    restitution shift e U_n⁻. Tried in order: open, sticking (U = 0),
    sliding (the direction consistent with the sign of U_t).

    Returns
    -------
    Pn, Pt : float
    sliding : bool
    """
    if Un >= 0.0:
        return 0.0, 0.0, False  # open: U_n ≥ 0 with P = 0
    det = Wnn * Wtt - Wnt * Wtn
    if det > 0.0:  # sticking: U = 0
        Pn = (-Un * Wtt + Ut * Wnt) / det
        Pt = (-Ut * Wnn + Un * Wtn) / det
        if Pn >= 0.0 and abs(Pt) <= mu * Pn:
            return Pn, Pt, False
        first = 1.0 if Pt < 0.0 else -1.0  # slide against the stick force
    else:
        first = 1.0 if Ut > 0.0 else -1.0
    for k in range(2):
        s = first if k == 0 else -first  # s = sign of the sliding velocity
        den = Wnn - s * mu * Wnt
        if den <= 0.0:
            continue
        Pn = -Un / den  # U_n = 0
        Pt = -s * mu * Pn  # paper 002, Eq 38
        Ut_new = Ut + Wtn * Pn + Wtt * Pt
        if s * Ut_new >= 0.0:
            return Pn, Pt, True
    den = max(Wnn - first * mu * Wnt, Wnn)
    Pn = -Un / den
    return Pn, -first * mu * Pn, True


@njit(cache=True)
def gauss_seidel(W, Ubar, P, sliding, nc, mu, tol, max_iter, p_scale):
    """Gauss–Seidel over simultaneous contacts (paper 002, Eq 44), in place on P.

    Parameters
    ----------
    W : ndarray (≥nc, ≥nc, 2, 2)
        Delassus blocks W^{hj}.
    Ubar : ndarray (≥nc, 2)
        Free local velocities, normal components shifted by e U_n⁻.
    P : ndarray (≥nc, 2)
        Starting impulses (warm start), overwritten with the solution.
    sliding : ndarray of bool (≥nc,)
        Overwritten: whether each contact slides.
    nc : int
        Number of contacts (the leading entries of the arrays).
    tol, max_iter : float, int
        Stop when no impulse changes by more than ``tol · max(|P|, p_scale)``.
    p_scale : float
        Impulse scale of the problem (weight × Δt) used as a floor.

    Returns
    -------
    iterations : int
    converged : bool
    residual : float
        The largest change of an impulse in the last sweep, relative to
        ``max(|P|, p_scale)``: ≤ tol when converged.
    """
    residual = 0.0
    for it in range(1, max_iter + 1):
        change, size = 0.0, p_scale
        for h in range(nc):
            un, ut = Ubar[h, 0], Ubar[h, 1]
            for j in range(nc):
                if j != h:
                    un += W[h, j, 0, 0] * P[j, 0] + W[h, j, 0, 1] * P[j, 1]
                    ut += W[h, j, 1, 0] * P[j, 0] + W[h, j, 1, 1] * P[j, 1]
            pn, pt, sl = solve_single(
                W[h, h, 0, 0], W[h, h, 0, 1], W[h, h, 1, 0], W[h, h, 1, 1], un, ut, mu
            )
            change = max(change, abs(pn - P[h, 0]), abs(pt - P[h, 1]))
            size = max(size, abs(pn), abs(pt))
            P[h, 0], P[h, 1] = pn, pt
            sliding[h] = sl
        residual = change / size
        if nc == 1 or change <= tol * size:
            return it, True, residual
    return max_iter, False, residual
