"""Cheaper models of a multi-mass column that keep what rocking needs.

A column of N elastic nodes (paper 001, Section 2.1) is reduced to a structure
with fewer degrees of freedom. Every reduction keeps, to round-off, the
rigid-body properties that govern rocking — the total mass m_t, the height of
the centre of gravity H_cg (so the static moment and α_cg) and the moment of
inertia about a pivot J_p (so p_l, paper 001 Eq 6) — by putting whatever mass,
first and second moment the elastic nodes do not carry into the rigid base
node 0 (m0, h0, J0; `multimass.Structure` allows h0 > 0).

`rigid_equivalent` (N = 0)
    The column as one rigid body: m0 = m_t at h0 = H_cg and
    J0 = J_p − m_t (B² + H_cg²). Its rocking equation is Housner's with J_p.

`modal_reduction` (1 ≤ n ≤ N) and `sdof` (n = 1)
    The first n full-contact modes of the column, realised as an n-node
    column. Let φ_j (j ≤ n) be the mass-normalised modes with frequencies ω_j,
    L = [φ_jᵀ M 1] and L_θ = [φ_jᵀ M H] their participation in translation and
    in rotation about the base. Paper 001's rocking equations (Eqs 4–5, 7, 9–11
    and the Dirac-delta force, Eqs 14–17) involve the elastic displacements
    only through M u, 1ᵀ M u, Hᵀ M u, uᵀ M u, C and K; in modal coordinates
    q = Φᵀ M u these are q, L·q, L_θ·q, qᵀq, diag(2ζ_j ω_j) and diag(ω_j²).
    So any n-node column with ::

        Σ m'_k = |L|²,   Σ m'_k h'_k = L·L_θ,   Σ m'_k h'_k² = |L_θ|²,
        K' = M'^½ Q Ω² Qᵀ M'^½  (Q orthogonal with Qᵀ M'^½ 1 = L, Qᵀ M'^½ h' = L_θ),

    and C' = a0 M' + a1 K' (the column's Rayleigh coefficients), plus the base
    node that restores m_t, H_cg and J_p, moves *exactly* as the column's
    Galerkin projection onto its first n modes, nonlinear rocking terms
    included. The nodes are generalised coordinates: here n equal masses
    ``|L|²/n`` at heights μ + σ z_k (μ, σ the mean and spread the moments fix, z_k
    evenly spaced with unit variance); for n ≥ 4 a height may fall below the
    base. Elastic displacements at the column's own nodes are recovered as
    u ≈ Φ_n q = R u' (`Reduced.recovery`). For n = 1 this is the classical
    equivalent SDOF oscillator of mode 1 (effective modal mass
    m* = (φ₁ᵀ M 1)² and height h* = φ₁ᵀ M H / φ₁ᵀ M 1 with mass-normalised φ₁;
    e.g. Chopra, *Dynamics of Structures*, Section 13.1), with R = Γ₁ φ₁.
    The base mass ``m_t − |L|²`` is ≥ 0 and J0' ≥ J0 ≥ 0 by Cauchy–Schwarz, so
    the reduction always exists.

Built to match: m_t, H_cg, J_p, ω₁..ω_n and their damping ratios, and the
participations L, L_θ of modes 1..n. Whether the reduced model answers a
question as the full one does is what `multimass.choose` verifies.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from ..errors import InputError
from ..model.structure import Structure

__all__ = ["Reduced", "rigid_equivalent", "sdof", "modal_reduction", "modes"]


@dataclass(frozen=True, eq=False)
class Reduced:
    """A reduced structure and how to read the original nodes from it.

    Attributes
    ----------
    structure : Structure
        The cheaper model (n elastic nodes, n = 0 for the rigid equivalent).
    recovery : ndarray, shape (N, n)
        Elastic displacements of the original nodes 1..N per unit displacement
        of the reduced nodes, u ≈ R u'. The identity for the full column.
    original : Structure
        The column it was reduced from.
    """

    structure: Structure
    recovery: np.ndarray
    original: Structure


def _check_column(st, what: str) -> None:
    if not isinstance(st, Structure):
        raise InputError(
            f"`structure` = {st!r}: give a multimass.Structure (e.g. multimass.column('S1'))"
        )
    if st.n == 0:
        raise InputError(
            f"`structure` = {st.name!r} is already rigid (N = 0): `{what}` needs "
            "a column with elastic nodes"
        )


def _with_base(st: Structure, name: str, H, m, K) -> Structure:
    """A structure with elastic nodes (H, m, K) whose base restores st's m_t, H_cg, J_p."""
    H, m = np.asarray(H, dtype=float), np.asarray(m, dtype=float)
    m0 = st.m_t - float(m.sum())
    first = st.static_moment - float(m @ H)
    tiny = 1e-12 * st.m_t
    if m0 < -tiny:
        raise InputError(
            f"reduction of {st.name!r}: the elastic nodes carry {m.sum():.6g} kg, "
            f"more than m_t = {st.m_t:.6g} kg"
        )
    if m0 > tiny:
        h0 = first / m0
    else:  # all the mass is elastic: the first moment must already match
        m0, h0 = 0.0, 0.0
    J0 = st.J_p - float(m @ (H**2 + st.B**2)) - m0 * (st.B**2 + h0**2)
    if J0 < -1e-9 * st.J_p:
        raise InputError(
            f"reduction of {st.name!r}: the kept nodes have more rotary inertia "
            f"than J_p (J0 would be {J0:.6g} kg m²)"
        )
    a0, a1 = st.rayleigh
    C = a0 * np.diag(m) + a1 * K if m.size else np.zeros((0, 0))
    return Structure(
        name=name,
        H=H,
        m=m,
        m0=m0,
        J0=max(J0, 0.0),
        B=st.B,
        g=st.g,
        K=K,
        C=C,
        rayleigh=(a0, a1),
        h0=h0,
        specimen=st.specimen,
    )


def rigid_equivalent(structure: Structure) -> Reduced:
    """The column as one rigid body with the same m_t, H_cg and J_p.

    Parameters
    ----------
    structure : Structure
        A column (N ≥ 1).

    Returns
    -------
    Reduced
        Structure with n = 0 (m0 = m_t at h0 = H_cg, J0 = J_p − m_t(B² + H_cg²)),
        named ``"<name>-rigid"``; recovery of shape (N, 0). The specimen is
        kept, so impact models find its restitution data.
    """
    _check_column(structure, "rigid_equivalent")
    st = _with_base(
        structure, f"{structure.name}-rigid", np.zeros(0), np.zeros(0), np.zeros((0, 0))
    )
    return Reduced(st, np.zeros((structure.n, 0)), structure)


def modes(structure: Structure) -> tuple[np.ndarray, np.ndarray]:
    """Full-contact ω (rad/s, ascending) and mass-normalised modes Φ (φ_jᵀ M 1 ≥ 0)."""
    w2, V = sla.eigh(structure.K, structure.M)
    sign = np.where(V.T @ structure.m < 0.0, -1.0, 1.0)
    return np.sqrt(w2), V * sign


def _orthonormal_completion(A: np.ndarray) -> np.ndarray:
    """An orthogonal n×n matrix whose first columns span A's columns, as QR does (R_ii > 0)."""
    Q, R = np.linalg.qr(A, mode="complete")
    d = np.sign(np.diag(R))
    d[d == 0] = 1.0
    Q[:, : d.size] *= d
    return Q


def _heights(n: int, mu: float, sigma: float) -> np.ndarray:
    if n == 1:
        return np.array([mu])
    z = np.linspace(-1.0, 1.0, n)
    return mu + sigma * z / np.sqrt(np.mean(z**2))


def modal_reduction(structure: Structure, n: int) -> Reduced:
    """The column's first n full-contact modes as an n-node column (module docstring).

    Parameters
    ----------
    structure : Structure
        A column with N ≥ n elastic nodes.
    n : int
        Number of modes (and nodes) kept, 1 ≤ n ≤ N.

    Returns
    -------
    Reduced
        Named ``"<name>-sdof"`` (n = 1) or ``"<name>-m<n>"``.
    """
    _check_column(structure, "modal_reduction")
    st = structure
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 1 <= n <= st.n:
        raise InputError(f"`n` = {n!r}: give the number of modes to keep, an integer in 1..{st.n}")
    n = int(n)
    omega, Phi = modes(st)
    Phi = Phi[:, :n]
    L, Lt = Phi.T @ st.m, Phi.T @ (st.m * st.H)  # participations φᵀM1, φᵀMH
    total = float(L @ L)
    mu = float(L @ Lt) / total
    sigma = float(np.sqrt(max(float(Lt @ Lt) / total - mu**2, 0.0)))
    h = _heights(n, mu, sigma)
    m = np.full(n, total / n)
    sq = np.sqrt(m)
    if n == 1:
        Q = np.array([[1.0]])  # Qᵀ √m* = L: L = √m* (L > 0)
    else:
        Wa = _orthonormal_completion(np.column_stack([sq, sq * h]))
        Wt = _orthonormal_completion(np.column_stack([L, Lt]))
        Q = Wa @ Wt.T  # Qᵀ [√m, √m h] = [L, L_θ]
    K = (sq[:, None] * Q) @ np.diag(omega[:n] ** 2) @ (Q.T * sq[None, :])  # M'^½ Q Ω² Qᵀ M'^½
    K = 0.5 * (K + K.T)
    name = f"{st.name}-sdof" if n == 1 else f"{st.name}-m{n}"
    reduced = _with_base(st, name, h, m, K)
    R = Phi @ (Q.T * sq[None, :])  # u ≈ Φ q, q = Qᵀ M'^½ u'
    return Reduced(reduced, R, st)


def sdof(structure: Structure) -> Reduced:
    """The equivalent SDOF oscillator of mode 1: `modal_reduction` with n = 1."""
    return modal_reduction(structure, 1)
