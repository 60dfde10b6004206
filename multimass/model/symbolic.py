"""Symbolic rocking-phase equations from the Lagrangian (an independent check of Eqs 4–5).

The equations of the rocking phase are derived here from first principles with
plain sympy (positions → T, V, Rayleigh D → Lagrange's equations), without
transcribing paper 001's Eqs 4–5, so that tests can compare them with the
hand-coded `multimass.model.eom.rocking_system`.

Kinematics (paper 001, Fig 1 conventions)
-----------------------------------------
Ground-fixed x to the right, y up; the ground moves by x_g(t). At rest the base
centre is at the origin and the pivots at (±B, 0). In the body frame node i
(1..N) sits at (u_i, H_i) (u_i: elastic displacement perpendicular to the
column axis, positive towards the right pivot) and node 0 at (0, h0). Rocking
about the pivot P = (s B, 0), s = ±1, by θ (θ > 0 for s = +1, θ < 0 for s = −1)
maps a body point p to

    r(p) = (x_g, 0) + P + R(θ) (p − P),   R(θ) = [[cos θ, sin θ], [−sin θ, cos θ]],

i.e. a clockwise rotation for θ > 0, so for u = 0 and small θ a node at height
H moves by ≈ +H θ in x (towards the right pivot for θ > 0).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np
import sympy as sp

from ..errors import InputError

__all__ = ["SymbolicRocking", "derive_rocking", "rocking_system_symbolic"]


@dataclass(frozen=True, eq=False)
class SymbolicRocking:
    """Rocking-phase equations derived from the Lagrangian, A(q) q̈ = b(q, q̇, ü_g, F_i).

    ``q = [u_1, …, u_N, θ]``. With d = u − s B 1 (s = ±1 the pivot side) the
    derivation gives::

        A = [[M,     M H                              ],
             [Hᵀ M,  J0 + m0 (B² + h0²) + Σ m_i (H_i² + d_i²)]]

        b_u = M d θ̇² − C u̇ − K u − M 1 (ü_g cos θ − g sin θ)
        b_θ = −2 θ̇ u̇ᵀ M d − 2 B F_i
              − ü_g (Hᵀ M 1 cos θ + m0 h0 cos θ − dᵀ M 1 sin θ + s m0 B sin θ)
              − g (−Hᵀ M 1 sin θ − m0 h0 sin θ − dᵀ M 1 cos θ + s m0 B cos θ)

    (the sympy expressions in `mass_matrix` and `forcing` are the reference;
    this display is their simplified form).

    Attributes
    ----------
    n, side : int
        Number of elastic nodes and pivot side (+1 right, −1 left).
    q, qdot : tuple of sympy.Symbol
        Coordinates [u_1..u_N, θ] and their rates.
    params : dict[str, object]
        Parameter symbols: ``H``, ``m`` (tuples), ``m0``, ``h0``, ``J0``, ``B``,
        ``g``, ``K``, ``C`` (symmetric sympy matrices), ``ag``, ``F_i``.
    mass_matrix : sympy.Matrix, shape (N+1, N+1)
    forcing : sympy.Matrix, shape (N+1, 1)
    positions : dict[str, sympy.Matrix]
        Absolute positions (relative to the moving ground, x_g omitted) of
        ``"node0"``, ``"node1"``…, the pivot ``"P"`` and the impending pivot ``"P'"``.
    """

    n: int
    side: int
    q: tuple
    qdot: tuple
    params: dict
    mass_matrix: sp.Matrix
    forcing: sp.Matrix
    positions: dict


def _sym_matrix(name: str, n: int) -> sp.Matrix:
    return sp.Matrix(n, n, lambda i, j: sp.Symbol(f"{name}_{min(i, j) + 1}{max(i, j) + 1}"))


def _place(point, pivot, c, s, xg):
    """Absolute position of body point `point` rocking about `pivot` (see module doc)."""
    R = sp.Matrix([[c, s], [-s, c]])
    return sp.Matrix([xg, 0]) + pivot + R * (point - pivot)


def _lagrange(L, D, force, r_force, qf, t):
    """d/dt ∂L/∂q̇_k − ∂L/∂q_k + ∂D/∂q̇_k − Q_k, with Q_k = F · ∂r_F/∂q_k (virtual work)."""
    eqs = []
    for qk in qf:
        qdk = sp.diff(qk, t)
        Qk = (force.T * sp.diff(r_force, qk))[0]
        eqs.append(sp.diff(sp.diff(L, qdk), t) - sp.diff(L, qk) + sp.diff(D, qdk) - Qk)
    return eqs


def _to_state_symbols(eqs, qf, xg, ag, t, n):
    """Replace q(t), q̇, q̈ by plain symbols and ẍ_g by ü_g; check that x_g has gone."""
    q = sp.symbols(f"u1:{n + 1}", real=True) + (sp.Symbol("theta", real=True),)
    qd = sp.symbols(f"ud1:{n + 1}", real=True) + (sp.Symbol("thetad", real=True),)
    qdd = sp.symbols(f"udd1:{n + 1}", real=True) + (sp.Symbol("thetadd", real=True),)
    subs = [(sp.diff(xg, t, 2), ag)]  # highest derivatives first
    subs += [(sp.diff(f, t, 2), v) for f, v in zip(qf, qdd)]
    subs += [(sp.diff(f, t), v) for f, v in zip(qf, qd)]
    subs += list(zip(qf, q))
    th = q[-1]
    out = []
    for e in eqs:
        e = sp.expand(sp.expand(e).subs(subs))
        e = sp.expand(e.subs(sp.sin(th) ** 2, 1 - sp.cos(th) ** 2))  # sin² + cos² = 1
        if e.has(xg):
            raise RuntimeError(f"x_g or its rate survives in a Lagrange equation: {e}")
        out.append(e)
    return sp.Matrix(out), q, qd, qdd


@cache
def derive_rocking(n: int, side: int) -> SymbolicRocking:
    """Derive the rocking equations of an N-node structure with Lagrange's equations.

    T = Σ ½ m_i ``|ṙ_i|²`` + ½ m0 ``|ṙ_0|²`` + ½ J0 θ̇² (absolute velocities, ẋ_g included),
    V = Σ m_i g y_i + m0 g y_0 + ½ uᵀ K u, D = ½ u̇ᵀ C u̇, and the impact force
    F_i as a generalised force by virtual work (see `rocking_system_symbolic`).
    The ground enters only through ẍ_g = ü_g: terms in ẋ_g cancel (checked).

    Parameters
    ----------
    n : int
        Number of elastic nodes (0 for a rigid block).
    side : {+1, -1}
        Pivot: +1 right, −1 left.

    Returns
    -------
    SymbolicRocking
    """
    if side not in (1, -1):
        raise InputError(f"`side` = {side!r}: use +1 (right pivot) or -1 (left pivot)")
    if not (isinstance(n, int) and n >= 0):
        raise InputError(f"`n` = {n!r}: the number of elastic nodes must be an int >= 0")
    t = sp.Symbol("t")
    H = sp.symbols(f"H1:{n + 1}", real=True)
    m = sp.symbols(f"m1:{n + 1}", positive=True)
    m0, h0, J0, B, g, ag, F_i = sp.symbols("m0 h0 J0 B g ag F_i", real=True)
    K, C = _sym_matrix("K", n), _sym_matrix("C", n)
    uf = [sp.Function(f"u{i + 1}")(t) for i in range(n)]
    thf, xg = sp.Function("theta")(t), sp.Function("x_g")(t)
    c, s = sp.cos(thf), sp.sin(thf)
    P = sp.Matrix([side * B, 0])
    r = [_place(sp.Matrix([uf[i], H[i]]), P, c, s, xg) for i in range(n)]
    r0 = _place(sp.Matrix([0, h0]), P, c, s, xg)
    rP2 = _place(sp.Matrix([-side * B, 0]), P, c, s, xg)  # impending pivot P'
    vel2 = lambda p: sum(sp.diff(p, t).applyfunc(lambda e: e**2))  # noqa: E731
    T = (sum(m[i] * vel2(r[i]) for i in range(n)) + m0 * vel2(r0) + J0 * sp.diff(thf, t) ** 2) / 2
    uvec = sp.Matrix(uf)
    V = sum(m[i] * g * r[i][1] for i in range(n)) + m0 * g * r0[1]
    V += (uvec.T * K * uvec)[0] / 2 if n else 0
    D = (sp.diff(uvec, t).T * C * sp.diff(uvec, t))[0] / 2 if n else sp.Integer(0)
    # impact force on P' along −s n̂, n̂ = R(θ)(0, 1) the foundation's normal, so that
    # Eq 5's convention (+F_i (2B) on its left-hand side) holds; see rocking_system_symbolic
    force = -side * F_i * sp.Matrix([s, c])
    qf = uf + [thf]
    eq, q, qd, qdd = _to_state_symbols(_lagrange(T - V, D, force, rP2, qf, t), qf, xg, ag, t, n)
    A = eq.jacobian(qdd).applyfunc(sp.expand)
    b = (-eq.subs({v: 0 for v in qdd})).applyfunc(sp.expand)
    if A.free_symbols & set(qdd):
        raise RuntimeError("Lagrange's equations are not linear in the accelerations")
    pos = {"node0": r0, "P": P, "P'": rP2} | {f"node{i + 1}": r[i] for i in range(n)}
    pos = {k: sp.Matrix(v).subs(list(zip(qf, q))).subs(xg, 0) for k, v in pos.items()}
    params = {
        "H": H,
        "m": m,
        "m0": m0,
        "h0": h0,
        "J0": J0,
        "B": B,
        "g": g,
        "K": K,
        "C": C,
        "ag": ag,
        "F_i": F_i,
    }
    return SymbolicRocking(
        n=n, side=side, q=q, qdot=qd, params=params, mass_matrix=A, forcing=b, positions=pos
    )


def _upper(Mat: sp.Matrix) -> list:
    n = Mat.shape[0]
    return [Mat[i, j] for i in range(n) for j in range(i, n)]


@cache
def _lambdified(n: int, side: int):
    d = derive_rocking(n, side)
    p = d.params
    args = (
        list(d.q)
        + list(d.qdot)
        + list(p["H"])
        + list(p["m"])
        + [p["m0"], p["h0"], p["J0"], p["B"], p["g"]]
        + _upper(p["K"])
        + _upper(p["C"])
        + [p["ag"], p["F_i"]]
    )
    return sp.lambdify(args, [d.mass_matrix, d.forcing], modules="numpy")


def rocking_system_symbolic(
    structure, side: int, u, theta: float, udot, thetadot: float, ag: float, F_i: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """A and b of A [ü; θ̈] = b from the symbolic Lagrangian, evaluated numerically.

    Same signature as `multimass.model.eom.rocking_system`. The impact force F_i is
    applied at the impending pivot P' along −s n̂ (n̂ the foundation's normal
    R(θ)(0, 1), s the side); its virtual work gives the generalised forces
    Q_u = 0 and Q_θ = −2 B F_i, the convention of paper 001's Eq 5 (+F_i (2B)
    on its left-hand side). A contact force pushing P' off the ground is
    therefore F_i = −s ``|F|``.

    Parameters
    ----------
    structure : multimass.Structure
        Uses H, m, m0, h0, J0, B, g, K, C (K and C are symmetrised).
    side : {+1, -1}
    u, udot : array_like, shape (N,)
    theta, thetadot, ag, F_i : float

    Returns
    -------
    A : ndarray, shape (N+1, N+1)
    b : ndarray, shape (N+1,)
    """
    st = structure
    n = st.H.size
    f = _lambdified(n, int(side))
    K = 0.5 * (np.asarray(st.K) + np.asarray(st.K).T) if n else np.zeros((0, 0))
    C = 0.5 * (np.asarray(st.C) + np.asarray(st.C).T) if n else np.zeros((0, 0))
    iu = np.triu_indices(n)
    args = [
        *np.asarray(u, float),
        float(theta),
        *np.asarray(udot, float),
        float(thetadot),
        *st.H,
        *st.m,
        st.m0,
        st.h0,
        st.J0,
        st.B,
        st.g,
        *K[iu],
        *C[iu],
        float(ag),
        float(F_i),
    ]
    A, b = f(*args)
    return np.array(A, dtype=float).reshape(n + 1, n + 1), np.array(b, dtype=float).reshape(n + 1)
