"""Phases of `multimass.engines.contact_dynamics`: constrained dynamics, projections, Signorini choice.

A phase is a fixed set S of closed contacts, held at acceleration level with
sticking tangential directions (paper 000, Section 2.1): M q̈ = h + W_N λ_N +
W_T λ_T with g̈_N = 0 and g̈_T = 0 on S.
"""

from __future__ import annotations

import itertools

import numpy as np

from ..errors import SolverError
from ._contact_checks import tangential_groups

__all__ = ["_Phase", "_constraint_matrix", "_project", "_project_q", "_select", "_events", "_grid"]


def _independent(cols: list[np.ndarray], start: np.ndarray, rtol: float = 1e-9) -> list[int]:
    """Indices of `cols` that raise the rank of [start, chosen...] (greedy)."""
    keep, basis = [], start
    for i, c in enumerate(cols):
        trial = np.column_stack([basis, c]) if basis.size else c[:, None]
        if trial.shape[1] > trial.shape[0]:
            break
        s = np.linalg.svd(trial, compute_uv=False)
        if s[-1] > rtol * s[0]:
            keep.append(i)
            basis = trial
    return keep


def _constraint_matrix(WN, WT, S):
    """[W_N,S | independent W_T,S] and the indices of the tangential columns kept."""
    n = WN.shape[0]
    N = WN[:, list(S)] if S else np.zeros((n, 0))
    tk = [S[i] for i in _independent([WT[:, j] for j in S], N)] if S else []
    return np.column_stack([N, WT[:, tk]]) if S else N, tk


class _Phase:
    """Dynamics of one phase (fixed set S of closed contacts)."""

    def __init__(self, model, S: tuple[int, ...], q, v):
        self.model, self.S = model, S
        _, WN, WT, _, _ = model.contacts(q, v)
        _, self.tk = _constraint_matrix(WN, WT, S)
        self.groups = tangential_groups(WT, S, self.tk)

    def multipliers(self, t, q, v):
        """Accelerations, all multipliers (λ_N,S then λ_T), normal accelerations, gaps."""
        m = self.model
        M, h = m.mass(q), m.forces(t, q, v)
        g, WN, WT, wN, wT = m.contacts(q, v)
        S = list(self.S)
        W = np.column_stack([WN[:, S], WT[:, self.tk]])
        what = np.concatenate([wN[S], wT[self.tk]])
        if W.shape[1]:  # paper 000, Sec 2.1: M q̈ = h + W λ, g̈ = 0
            Mi = np.linalg.solve(M, np.column_stack([h, W]))
            G = W.T @ Mi[:, 1:]
            lam = np.linalg.solve(G, -(W.T @ Mi[:, 0]) - what)
            a = Mi[:, 0] + Mi[:, 1:] @ lam
        else:
            a, lam = np.linalg.solve(M, h), np.zeros(0)
        return a, lam, WN.T @ a + wN, g

    def solve(self, t, q, v):
        """Accelerations, normal contact forces of S and all normal accelerations."""
        a, lam, gdd, g = self.multipliers(t, q, v)
        return a, lam[: len(self.S)], gdd, g

    def force_map(self, q, v):
        """(L, c) with λ(t) = L h(t) + c (λ_N,S then λ_T) at a fixed state (locked phases)."""
        m = self.model
        M = m.mass(q)
        _, WN, WT, wN, wT = m.contacts(q, v)
        S = list(self.S)
        W = np.column_stack([WN[:, S], WT[:, self.tk]])
        MiW = np.linalg.solve(M, W)
        Gi = np.linalg.inv(W.T @ MiW)
        return -(Gi @ MiW.T), -(Gi @ np.concatenate([wN[S], wT[self.tk]]))

    def rhs(self, t, y):
        n = self.model.n
        q, v = y[:n], y[n : 2 * n]
        a = self.solve(t, q, v)[0]
        pg, pd = self.model.powers(t, q, v)
        return np.concatenate([v, a, [pg, pd]])


def _project_q(model, K, q, v) -> np.ndarray:
    """One Newton step of q onto g_N,K = 0 (minimal in the M metric)."""
    if not K:
        return q
    K = list(K)
    g, WN, _, _, _ = model.contacts(q, v)
    N = WN[:, K]
    MiN = np.linalg.solve(model.mass(q), N)
    return q - MiN @ np.linalg.solve(N.T @ MiN, g[K])


def _project(model, S, q, v) -> np.ndarray:
    """Remove integration drift: q onto g_N,S = 0, then q̇ onto Wᵀq̇ = 0."""
    if not S:
        return np.concatenate([q, v])
    q = _project_q(model, S, q, v)
    M = model.mass(q)
    g, WN, WT, _, _ = model.contacts(q, v)
    W, _ = _constraint_matrix(WN, WT, tuple(S))
    MiW = np.linalg.solve(M, W)
    v = v - MiW @ np.linalg.solve(W.T @ MiW, W.T @ v)
    return np.concatenate([q, v])


def _select(model, t, q, v, cands, ftol) -> tuple[int, ...]:
    """Largest subset of `cands` with λ_N ≥ 0 and g̈_N ≥ 0 on the rest (Signorini).

    When round-off leaves no subset exactly consistent (a grazing contact whose
    force or acceleration is zero to within ~1e-6 of the load scale), the subset
    with the smallest relative violation is taken; a larger violation raises.
    """
    cands = tuple(sorted(int(c) for c in cands))
    f_scale = ftol * 1e10
    best, best_viol = None, np.inf
    for size in range(len(cands), -1, -1):
        for S in itertools.combinations(cands, size):
            ph = _Phase(model, S, q, v)
            a, lam, gdd, _ = ph.solve(t, q, v)
            rest = [j for j in cands if j not in S]
            if np.all(lam >= -ftol) and np.all(gdd[rest] >= -ftol):
                return S
            a_scale = max(np.abs(a).max(), 1e-300)
            viol = max(
                np.max(-lam, initial=0.0) / f_scale, np.max(-gdd[rest], initial=0.0) / a_scale
            )
            if viol < best_viol:
                best, best_viol = S, viol
    if best_viol <= 1e-5:
        return best
    raise SolverError(
        f"t = {t:.9g}: no consistent set of closed contacts among {cands} "
        f"(smallest relative violation {best_viol:.3g}): a sticking contact "
        "would need a tensile force while opening it would let it penetrate; "
        "a real contact slides here, which the sticking model of paper 000 "
        "does not cover"
    )


def _events(model, ph: _Phase, k: int, y0, gap_eps: float):
    """Terminal events of a phase: λ_N,i → 0 for closed contacts, g_N,j → 0 for open ones.

    Each gap event is shifted to start at ≥ `gap_eps` above zero, so a contact
    that has just bounced off (g = 0, ġ > 0) is caught when it comes back
    within the first step.
    """
    n = model.n
    g0 = model.contacts(y0[:n], y0[n : 2 * n])[0]
    evs = []
    for j in range(k):
        if j in ph.S:
            i = ph.S.index(j)

            def f(t, y, i=i):
                return ph.solve(t, y[:n], y[n : 2 * n])[1][i]
        else:

            def f(t, y, j=j, off=gap_eps - min(g0[j], 0.0)):
                return model.contacts(y[:n], y[n : 2 * n])[0][j] + off

        f.terminal, f.direction = True, -1
        evs.append(f)
    for name, fn in getattr(model, "events", ()):

        def f(t, y, fn=fn):
            return fn(t, y[:n], y[n : 2 * n])

        f.terminal, f.direction, f.name = True, 0, name
        evs.append(f)
    return evs


def _grid(t0, t1, dt_out):
    if dt_out is None:
        return np.array([t0, t1])
    k0, k1 = int(np.floor(t0 / dt_out)) + 1, int(np.ceil(t1 / dt_out))
    inner = dt_out * np.arange(k0, k1)
    return np.concatenate([[t0], inner[(inner > t0) & (inner < t1)], [t1]])
