"""Step kernel of paper 004's Newmark integrator for a rigid rocking block.

`advance` integrates one rocking flight (no impacts, no uplift) on a fixed time grid:
Newmark's trapezoidal rule (paper 004, Eqs 3–4) with Newton–Raphson on the discrete
equation of motion (paper 004, Eqs 5–6) and an analytic tangent. It stops at the first
step whose end has crossed θ = 0, at overturning, at a requested check point, at the
end of the grid, or on a Newton failure; the caller (`multimass.engines.newmark`) locates the
events and applies the transition maps.

The function is plain Python with `math` only, so the *same source* is the readable
reference and, compiled with ``numba.njit(cache=True)`` by `compiled_advance`, the fast
path; ``tests/multimass/engines/test_newmark.py`` compares the two.

Equation of motion on side ``s`` (+1: right pivot, θ ≥ 0; −1: left pivot, θ ≤ 0),
paper 004 Eqs 1–2 divided by I_A, with p² = m g R / I_A::

    θ̈ = f(θ, ü_g) = −p² [ s sin(α − sθ) + (ü_g / g) cos(α − sθ) ]

Newton unknown. Eq 5 is solved for the end acceleration a = θ̈_{n+1} instead of θ_{n+1}:
by Eq 4, θ_{n+1} = θ_n + Δt θ̇_n + Δt²/4 (θ̈_n + a) is affine in a, and Newton's method
is invariant under an affine change of unknown, so the iterates are those of Newton on
Eq 5 in θ_{n+1}; the a-form stays well conditioned for the short steps that follow an
impact (no 4/Δt² cancellation).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["advance", "compiled_advance", "rhs", "END", "CROSS", "OVERTURN", "CHECK", "FAIL"]

# return codes of `advance`
END = 0  # reached the last grid point
CROSS = 1  # the step to grid point k crossed θ = 0 (k not written)
OVERTURN = 2  # |θ_k| ≥ overturn angle (k written)
CHECK = 3  # reached the check point k_check (k written)
FAIL = 4  # Newton did not converge in the step to k (k not written)


def rhs_and_tangent(theta: float, side: int, ag: float, p2: float, alpha: float, g: float):
    """θ̈ on `side` at angle θ and ground acceleration ü_g, and its tangent ∂θ̈/∂θ."""
    s = float(side)
    phi = alpha - s * theta
    sn = math.sin(phi)
    cs = math.cos(phi)
    agn = ag / g
    return -p2 * (s * sn + agn * cs), p2 * (cs - s * agn * sn)  # paper 004, Eqs 1–2


def rhs(theta: float, side: int, ag: float, p2: float, alpha: float, g: float) -> float:
    """θ̈ on `side` at angle θ and ground acceleration ü_g (`rhs_and_tangent`)."""
    return rhs_and_tangent(theta, side, ag, p2, alpha, g)[0]


def advance(
    t_grid,
    ag_grid,
    k,
    k_last,
    t_a,
    th,
    thd,
    thdd,
    side,
    p2,
    alpha,
    g,
    tol,
    max_iter,
    overturn,
    k_check,
    out,
    stats_i,
    stats_f,
):
    """Newmark steps from the state at `t_a` to grid points k, k+1, …, k_last.

    Parameters
    ----------
    t_grid, ag_grid : ndarray (float64)
        Grid times and ü_g at them (m/s²).
    k, k_last : int
        First grid point to reach (t_grid[k] > t_a) and last grid point.
    t_a, th, thd, thdd : float
        Start time and state θ, θ̇, θ̈ there (t_a may lie between grid points).
    side : int
        +1 right pivot, −1 left pivot.
    p2, alpha, g : float
        p², the slenderness α (rad) and g (m/s²).
    tol, max_iter : float, int
        Newton stops when the θ correction is ≤ tol (rad); at most max_iter iterations.
    overturn : float
        Return OVERTURN once |θ| ≥ overturn (rad).
    k_check : int
        Return CHECK after writing this grid point (−1: never).
    out : ndarray (3, N+1)
        θ, θ̇, θ̈ at the grid points, written in place.
    stats_i : ndarray (int64, 3)
        [Newmark steps, Newton iterations, max iterations in one step], updated.
    stats_f : ndarray (float64, 2)
        [largest s·θ of the current half-cycle (refined inside steps), θ at the end of
        a step that crossed θ = 0], updated.

    Returns
    -------
    code, k : int, int
        Return code and the grid point it refers to.
    """
    s = float(side)
    while k <= k_last:
        h = t_grid[k] - t_a
        q = 0.25 * h * h
        a = thdd  # predictor: θ̈_{n+1} = θ̈_n
        th1 = th + h * thd + q * (thdd + a)  # paper 004, Eq 4 solved for θ_{n+1}
        it = 0
        converged = False
        while it < max_iter:
            it += 1
            f, df = rhs_and_tangent(th1, side, ag_grid[k], p2, alpha, g)
            d = (f - a) / (1.0 - q * df)  # Newton on paper 004, Eq 5 / Eq 6
            a += d
            th1 += q * d
            if abs(q * d) <= tol:
                converged = True
                break
        stats_i[0] += 1
        stats_i[1] += it
        if it > stats_i[2]:
            stats_i[2] = it
        if not converged or not math.isfinite(th1) or not math.isfinite(a):
            return FAIL, k
        if s * th1 <= 0.0:
            stats_f[1] = th1
            return CROSS, k
        thd1 = thd + 0.5 * h * (thdd + a)  # paper 004, Eq 3 (with Eq 4)
        # half-cycle peak: θ̇ changes sign inside the step; Newmark's constant average
        # acceleration makes θ quadratic there, with its extremum at τ = −θ̇_n / ā
        abar = 0.5 * (thdd + a)
        if s * thd > 0.0 and s * thd1 <= 0.0 and abar != 0.0:
            pk = s * (th - 0.5 * thd * thd / abar)
            if pk > stats_f[0]:
                stats_f[0] = pk
        if s * th1 > stats_f[0]:
            stats_f[0] = s * th1
        out[0, k] = th1
        out[1, k] = thd1
        out[2, k] = a
        th = th1
        thd = thd1
        thdd = a
        t_a = t_grid[k]
        if abs(th1) >= overturn:
            return OVERTURN, k
        if k == k_check:
            return CHECK, k
        k += 1
    return END, k_last


_COMPILED = None


def compiled_advance():
    """`advance` compiled with ``numba.njit(cache=True)`` (compiled once per process)."""
    global _COMPILED
    if _COMPILED is None:
        import numba
        from numba.extending import register_jitable

        register_jitable(inline="always")(rhs_and_tangent)  # compiled from the same source
        _COMPILED = numba.njit(cache=True)(advance)
    return _COMPILED


def _warm_up() -> None:
    """Compile the numba kernel on a two-point grid (used by benchmarks)."""
    out = np.zeros((3, 2))
    compiled_advance()(
        np.array([0.0, 1e-3]),
        np.zeros(2),
        1,
        1,
        0.0,
        0.1,
        0.0,
        0.0,
        1,
        70.0,
        0.2,
        9.81,
        1e-9,
        50,
        1.5,
        -1,
        out,
        np.zeros(3, dtype=np.int64),
        np.zeros(2),
    )
