"""A readable pure-NumPy Moreau–Jean step, the reference for the compiled kernel.

It follows paper 002 literally with whole-system matrices: B (Eq 33), the
force vector F (Eq 32), the free velocity v̄ (Eq 34), Q as rows over all
degrees of freedom (Eq 58), W = Q B Qᵀ (Eq 43), the quintic of Eq 62 solved
with ``numpy.roots`` on every element (global minimum of Eq 60), and
Gauss–Seidel (Eq 44). It is slow (tens of µs per step) and meant for tests.
"""

from __future__ import annotations

import math

import numpy as np

from .fe_beam import shape_functions
from .model import System

__all__ = ["closest_point_roots", "reference_step", "reference_run"]


def _element_rho(sys: System, qe: np.ndarray, e: int) -> np.ndarray:
    idx = sys.beam.edof[e]
    return np.where(idx >= 0, qe[np.maximum(idx, 0)], 0.0)


def closest_point_roots(sys: System, qe: np.ndarray, d: np.ndarray) -> tuple[int, float]:
    """Nearest beam point to vertex d over all elements via `numpy.roots` (paper 002, Eqs 59–62)."""
    Le = sys.beam.Le
    best = (np.inf, 0, 0.0)
    for e in range(sys.beam.n_elements):
        r = _element_rho(sys, qe, e)
        # v(s) as a polynomial in s (highest power first), paper 002, Eq 59
        basis = np.array(
            [
                [2 / Le**3, -3 / Le**2, 0, 1],
                [1 / Le**2, -2 / Le, 1, 0],
                [-2 / Le**3, 3 / Le**2, 0, 0],
                [1 / Le**2, -1 / Le, 0, 0],
            ]
        )
        v = r[1] * basis[0] + r[2] * basis[1] + r[4] * basis[2] + r[5] * basis[3]
        x1 = sys.beam.x_nodes[e]
        g = np.polyadd(np.polymul(np.polysub(v, [d[1]]), np.polyder(v)), [1.0, x1 - d[0]])  # Eq 62
        roots = np.roots(np.trim_zeros(g, "f")) if np.any(g) else np.array([])
        cand = [s.real for s in roots if abs(s.imag) < 1e-9 * Le and 0.0 <= s.real <= Le]
        for s in cand + [0.0, Le]:
            f = math.hypot(d[0] - x1 - s, d[1] - np.polyval(v, s))  # Eq 60
            if f < best[0]:
                best = (f, e, float(s))
    return best[1], best[2]


def _contact_row(sys: System, qk, qe, j):
    """Q (2 × (3 + n)) of vertex j, its gap, or None if the vertex is off the span."""
    c, s = math.cos(qk[2]), math.sin(qk[2])
    r = np.array([[c, -s], [s, c]]) @ sys.verts[j]
    d = qk[:2] + r
    if not 0.0 <= d[0] <= sys.beam.L:
        return None
    e, sb = closest_point_roots(sys, qe, d)
    N = shape_functions(sb, sys.beam.Le)
    rho = _element_rho(sys, qe, e)
    v = N[1] * rho[1] + N[2] * rho[2] + N[4] * rho[4] + N[5] * rho[5]
    Le, xi = sys.beam.Le, sb / sys.beam.Le
    dN = np.array(
        [6 * (-xi + xi**2) / Le, 1 - 4 * xi + 3 * xi**2, 6 * (xi - xi**2) / Le, -2 * xi + 3 * xi**2]
    )
    slope = dN @ rho[[1, 2, 4, 5]]
    psi = math.atan(slope) + math.pi / 2  # Eq 63
    T = np.array([[math.cos(psi), math.sin(psi)], [-math.sin(psi), math.cos(psi)]])  # Eq 48
    gap = T[0] @ (d - np.array([sys.beam.x_nodes[e] + sb, v]))
    S = np.array([[1.0, 0.0, -r[1]], [0.0, 1.0, r[0]]])  # Eq 45
    Nmat = np.array([[N[0], 0, 0, N[3], 0, 0], [0, N[1], N[2], 0, N[4], N[5]]])  # Eq 52
    Q = np.zeros((2, 3 + sys.beam.n_dof))
    Q[:, :3] = T @ S  # Eq 50
    Qe = T @ Nmat  # Eq 55
    for a, i in enumerate(sys.beam.edof[e]):
        if i >= 0:
            Q[:, 3 + i] -= Qe[:, a]  # Eq 58
    return Q, gap


def _single(W, U, mu):
    """Open, sticking or sliding solution of U + W P with Signorini–Coulomb (Eqs 36–38)."""
    if U[0] >= 0.0:
        return np.zeros(2), False
    P = np.linalg.solve(W, -U)
    if P[0] >= 0.0 and abs(P[1]) <= mu * P[0]:
        return P, False
    first = 1.0 if P[1] < 0 else -1.0
    for s in (first, -first):
        den = W[0, 0] - s * mu * W[0, 1]
        if den <= 0:
            continue
        pn = -U[0] / den
        P = np.array([pn, -s * mu * pn])
        if s * (U[1] + W[1] @ P) >= 0:
            return P, True
    pn = -U[0] / max(W[0, 0] - first * mu * W[0, 1], W[0, 0])
    return np.array([pn, -first * mu * pn]), True


def reference_step(
    sys: System,
    q: np.ndarray,
    v: np.ndarray,
    P_prev: dict,
    gs_tol: float = 1e-8,
    gs_max_iter: int = 5000,
):
    """One step of paper 002, Eqs 27–44 on the whole state q = [q_k; q_e], v = q̇.

    `P_prev` maps vertex → impulse of the previous step (warm start) and is
    updated. Returns (q_new, v_new).
    """
    bm, dt, th = sys.beam, sys.dt, sys.theta_method
    n = bm.n_dof
    A = bm.M + dt * th * bm.C + (dt * th) ** 2 * bm.K  # Eq 26
    B = np.zeros((3 + n, 3 + n))  # Eq 33
    B[:3, :3] = np.diag([1 / sys.mass, 1 / sys.mass, 1 / sys.inertia])
    B[3:, 3:] = np.linalg.inv(A)
    qe, ve = q[3:], v[3:]
    F = np.concatenate([sys.Fk, -bm.K @ (dt * th * ve + qe) - bm.C @ ve + bm.p_self])  # Eq 32
    vbar = v + dt * B @ F  # Eq 34
    qbar = q + dt * (th * vbar + (1 - th) * v)
    rows, ids, Um = [], [], []
    for j in range(4):
        got = _contact_row(sys, qbar[:3], qbar[3:], j)
        if got is not None and got[1] <= 0.0:
            rows.append(got[0])
            ids.append(j)
            Um.append(got[0][0] @ v)
    P = np.array([P_prev.get(j, np.zeros(2)) for j in ids]).reshape(-1, 2)
    Ubar = np.array([Q @ vbar for Q in rows]).reshape(-1, 2)  # Eq 42
    Ubar[:, 0] += sys.restitution * np.minimum(Um, 0.0)
    W = [[Qh @ B @ Qj.T for Qj in rows] for Qh in rows]  # Eq 43
    scale = abs(sys.Fk[1]) * dt
    for _ in range(gs_max_iter):  # Eq 44
        change, size = 0.0, scale
        for h in range(len(rows)):
            U = Ubar[h] + sum(W[h][j] @ P[j] for j in range(len(rows)) if j != h)
            new, _ = _single(W[h][h], U, sys.mu)
            change = max(change, np.max(np.abs(new - P[h])))
            size = max(size, np.max(np.abs(new)))
            P[h] = new
        if len(rows) <= 1 or change <= gs_tol * size:
            break
    v_new = vbar + B @ sum((Q.T @ p for Q, p in zip(rows, P)), np.zeros(3 + n))  # Eq 34
    P_prev.clear()
    P_prev.update({j: p.copy() for j, p in zip(ids, P) if p[0] > 0.0})
    q_new = q + dt * (th * v_new + (1 - th) * v)  # Eq 28
    return q_new, v_new


def reference_run(sys: System, n_steps: int, **gs):
    """`n_steps` reference steps from the system's initial state; returns (q, v)."""
    q = np.concatenate([sys.qk0, sys.qe0])
    v = np.zeros_like(q)
    P_prev: dict = {}
    for _ in range(n_steps):
        q, v = reference_step(sys, q, v, P_prev, **gs)
    return q, v
