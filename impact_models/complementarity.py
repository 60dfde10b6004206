"""Lemke's complementary pivoting algorithm for the linear complementarity problem.

The LCP (paper 000, Section 2.2; Cottle & Dantzig 1968, Lemke 1965) asks for
vectors ``w`` and ``z`` with

    w = M z + q,   w ≥ 0,   z ≥ 0,   wᵀz = 0.

`lemke` runs Lemke's method with the covering vector ``d = 1`` and the
**lexicographic** minimum-ratio rule, which keeps every tableau row
lexicographically positive and therefore cannot cycle on degenerate problems
(ties in the ratio test, zero entries in ``q``). For P-matrices (in particular
symmetric positive definite ones) the solution exists, is unique, and is found;
for copositive-plus matrices (e.g. positive semidefinite ones) a ray
termination proves that the LCP has no solution, and `lemke` raises `LCPError`.

Why not a library: SciPy has no LCP solver, and the small PyPI packages
(``lemkelcp``) have no anti-cycling rule; Siconos is a heavy C++ dependency.
The impact problems here have a handful of contacts, so a dense tableau in
NumPy is exact enough and fast.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multimass.errors import SolverError

__all__ = ["LCPError", "LCPSolution", "lemke"]


class LCPError(SolverError):
    """An LCP (or the impact problem that builds it) is ill-posed or has no solution.

    The message names the argument, the value and the fix; a ray termination
    of Lemke's method says so.
    """


@dataclass(frozen=True)
class LCPSolution:
    """Solution of ``w = M z + q, w ≥ 0, z ≥ 0, wᵀz = 0``.

    Attributes
    ----------
    z, w : ndarray, shape (n,)
        The complementary pair (``w`` recomputed as ``M z + q``).
    basis : tuple of str
        Basic variable of each row at termination, e.g. ``("z0", "w1")``.
    pivots : int
        Number of complementary pivots taken (0 when ``q ≥ 0``).
    """

    z: np.ndarray
    w: np.ndarray
    basis: tuple[str, ...]
    pivots: int


def _validate(M, q) -> tuple[np.ndarray, np.ndarray]:
    M = np.atleast_2d(np.asarray(M, dtype=float))
    q = np.atleast_1d(np.asarray(q, dtype=float))
    n = q.shape[0]
    if q.ndim != 1:
        raise LCPError(f"`q` has shape {q.shape}: expected a vector of length n")
    if M.shape != (n, n):
        raise LCPError(
            f"`M` has shape {M.shape} but `q` has length {n}: expected an ({n}, {n}) matrix"
        )
    if not (np.all(np.isfinite(M)) and np.all(np.isfinite(q))):
        raise LCPError("`M` or `q` holds NaN or inf: pass finite numbers")
    return M, q


def _lexmin_row(T: np.ndarray, rows: np.ndarray, col: np.ndarray, n: int, tol: float) -> int:
    """Row of `rows` with the lexicographically smallest (q̄, B⁻¹)ᵢ / colᵢ."""
    ratios = np.column_stack([T[rows, -1], T[rows, :n]]) / col[rows, None]
    cand = np.arange(rows.size)
    for k in range(ratios.shape[1]):
        vals = ratios[cand, k]
        lo = vals.min()
        cand = cand[vals <= lo + tol * max(1.0, abs(lo))]
        if cand.size == 1:
            break
    return int(rows[cand[0]])


def _pivot(T: np.ndarray, r: int, c: int) -> None:
    T[r] /= T[r, c]
    others = np.arange(T.shape[0]) != r
    T[others] -= np.outer(T[others, c], T[r])


def _names(basis: np.ndarray, n: int) -> tuple[str, ...]:
    def name(j):
        if j < n:
            return f"w{j + 1}"
        if j < 2 * n:
            return f"z{j - n + 1}"
        return "z0"

    return tuple(name(int(j)) for j in basis)


def _refine(M: np.ndarray, q: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Re-solve M_αα z_α = −q_α on the support α of z for full accuracy."""
    alpha = np.flatnonzero(z > 0.0)
    if alpha.size == 0:
        return z
    try:
        za = np.linalg.solve(M[np.ix_(alpha, alpha)], -q[alpha])
    except np.linalg.LinAlgError:
        return z
    scale = max(np.abs(z).max(), 1e-300)
    if np.any(za < -1e-9 * scale) or np.abs(za - z[alpha]).max() > 1e-6 * scale:
        return z  # singular-ish block: keep the tableau values
    zr = z.copy()
    zr[alpha] = np.maximum(za, 0.0)
    return zr


def _checked(M, q, z, basis, count, tol) -> LCPSolution:
    """The solution, after checking w ≥ 0 and wᵀz = 0 to round-off."""
    w = M @ z + q
    scale = np.abs(q).max() + np.abs(M).max() * np.abs(z).max()
    bad = max(-w.min(), np.abs(w * z).max() / max(np.abs(z).max(), 1e-300))
    if bad > 1e3 * tol * scale:
        raise LCPError(
            f"Lemke's method ended with a violated complementarity of "
            f"{bad:.3g} (scale {scale:.3g}): `M` is too ill-conditioned for "
            "the pivot tolerance; rescale the problem or raise `tol`"
        )
    return LCPSolution(z, w, basis, count)


def lemke(M, q, *, max_pivots: int | None = None, tol: float = 1e-9) -> LCPSolution:
    """Solve the LCP ``w = M z + q, w ≥ 0, z ≥ 0, wᵀz = 0`` by Lemke's method.

    Parameters
    ----------
    M : array_like, shape (n, n)
        LCP matrix (need not be symmetric).
    q : array_like, shape (n,)
    max_pivots : int, optional
        Pivot limit; default ``50 (n + 1)²``.
    tol : float
        Pivot and tie tolerance on the internally scaled problem
        (``max |M| = 1``, ``max |q| = 1``).

    Returns
    -------
    LCPSolution

    Raises
    ------
    LCPError
        Bad shapes or non-finite input; ray termination (no pivot row for the
        entering column — for copositive-plus ``M`` this proves the LCP has no
        solution); the pivot limit reached.

    Examples
    --------
    >>> sol = lemke([[2.0, 1.0], [1.0, 2.0]], [-5.0, -6.0])
    >>> sol.z.round(12).tolist(), sol.w.round(12).tolist()
    ([1.333333333333, 2.333333333333], [0.0, 0.0])
    """
    M, q = _validate(M, q)
    n = q.size
    if n == 0 or np.all(q >= 0.0):
        return LCPSolution(np.zeros(n), q.copy(), _names(np.arange(n), n), 0)
    m_scale = max(np.abs(M).max(), 1e-300)
    q_scale = np.abs(q).max()
    Ms, qs = M / m_scale, q / q_scale
    # tableau columns: w (n) | z (n) | z0 | q̄ ;  I w − M z − d z0 = q  (d = 1)
    T = np.hstack([np.eye(n), -Ms, -np.ones((n, 1)), qs[:, None]])
    basis = np.arange(n)
    z0 = 2 * n
    # first pivot: z0 enters at the lexicographic minimum of (q, I)ᵢ / dᵢ
    r = _lexmin_row(T, np.arange(n), np.ones(n), n, tol)
    _pivot(T, r, z0)
    leaving, basis[r] = basis[r], z0
    limit = 50 * (n + 1) ** 2 if max_pivots is None else int(max_pivots)
    for count in range(1, limit + 1):
        entering = leaving + n if leaving < n else leaving - n  # complement
        col = T[:, entering]
        rows = np.flatnonzero(col > tol)
        if rows.size == 0:
            raise LCPError(
                f"Lemke's method ended on a ray after {count} pivots (entering "
                f"{_names(np.array([entering]), n)[0]}): the LCP with this `M` and `q` "
                "has no solution when M is copositive-plus (e.g. positive semidefinite); "
                "check that the contact problem is feasible"
            )
        ratio = T[rows, -1] / col[rows]
        at_z0 = basis[rows] == z0
        if np.any(at_z0) and ratio[at_z0][0] <= ratio.min() + tol * max(1.0, abs(ratio.min())):
            r = int(rows[at_z0][0])  # z0 ties for leaving: let it, the method ends here
        else:
            r = _lexmin_row(T, rows, col, n, tol)
        _pivot(T, r, entering)
        leaving, basis[r] = basis[r], entering
        if leaving == z0:
            z = np.zeros(n)
            zmask = (basis >= n) & (basis < 2 * n)
            z[basis[zmask] - n] = np.maximum(T[zmask, -1], 0.0)
            z = _refine(Ms, qs, z) * (q_scale / m_scale)
            return _checked(M, q, z, _names(basis, n), count, tol)
    raise LCPError(
        f"`max_pivots` = {limit} reached without a solution: raise the limit, "
        "or check the LCP (Lemke's method terminates on P- and PSD matrices)"
    )
