"""The linear part of the rocking phase that `._exp_kernel` advances exactly.

While a column rocks (paper 001, Eqs 4–5) its first-order system y' = f(t, y) over the
mechanical state x = [u, θ, u̇, θ̇] is split as x' = L x + N(t, y): L is the Jacobian
of f at rest (u = θ = u̇ = θ̇ = 0, ü_g = 0), N = f − L x what is left (the
constant restoring moment, the ground motion, sin θ and cos θ beyond linear, the
θ̇² and θ̇ u̇ terms, the change of the mass matrix with u, the Dirac-delta force).
L is the state matrix of the uplifted modal analysis (paper 001, Eqs 19–21,
`multimass.modal.linearisation.rocking`: [[0, I], [−M_L⁻¹K_L, −M_L⁻¹C_L]]) plus the
derivative of the inverse mass matrix times the constant restoring moment, a
non-stiff term that Eqs 19–21 leave out; it is formed here by central differences of
the solve_ivp path's right-hand side (`multimass.model._phase.rocking_rhs`, the equations
the compiled kernels compile), so there is no second copy of the equations. It is the
same for both pivots (only the constant load changes sign).

`RockingModes.of` diagonalises L = V Λ V⁻¹ (complex; the column's elastic modes as
damped pairs, the rocking pair ±p real) and keeps one eigenvalue of each conjugate
pair with weight 2, so that x = Σ_j w_j Re(V_j z_j) with z = V⁻¹ x.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...model._phase import Model, rocking_rhs

__all__ = ["RockingModes", "MAX_CONDITION", "JACOBIAN_STEP"]

#: Largest condition number of the eigenvector matrix accepted: beyond it the round-off
#: of x = V z would approach the tolerances asked of the integrator. The bundled columns
#: sit near 1e4 (V's columns of unit length; u in m beside u̇ in m/s).
MAX_CONDITION = 1e9
#: Perturbation of the central differences that form L, per unit of each coordinate
#: (m, rad, m/s, rad/s): f is linear in u and u̇ up to terms of relative size 1e-5, and
#: the rounding of f (``|f|`` ~ 10 at rest) adds ~1e-10 to entries of order 1 … 1e7.
JACOBIAN_STEP = 1e-5


def _jacobian(st) -> np.ndarray:
    """∂f/∂x of the rocking phase about the right pivot at rest, by central differences
    of `multimass.model._phase.rocking_rhs` (ü_g = 0, no impact force)."""
    n = st.n
    nm, ny = 2 * n + 2, 2 * n + 5
    f = rocking_rhs(Model.of(st), 1, lambda t: 0.0, None)
    L = np.empty((nm, nm))
    for j in range(nm):
        y = np.zeros(ny)
        y[j] = JACOBIAN_STEP
        plus = f(0.0, y)
        y[j] = -JACOBIAN_STEP
        L[:, j] = (plus[:nm] - f(0.0, y)[:nm]) / (2.0 * JACOBIAN_STEP)
    return L


@dataclass(frozen=True, eq=False)
class RockingModes:
    """The linear part L of the rocking phase and its eigen-decomposition.

    Attributes
    ----------
    L : ndarray (2N+2, 2N+2)
        ∂f/∂x at rest over x = [u, θ, u̇, θ̇] (the module docstring).
    lam : complex ndarray (k,)
        Eigenvalues of L, one of each conjugate pair (rad/s).
    V : complex ndarray (2N+2, k)
        Their eigenvectors, in columns.
    W : complex ndarray (k, 2N+2)
        The matching rows of V⁻¹.
    wt : ndarray (k,)
        2 for a complex pair, 1 for a real eigenvalue: x = Σ_j wt_j Re(V_j (W x)_j).
    condition : float
        Condition number of the full eigenvector matrix.
    """

    L: np.ndarray
    lam: np.ndarray
    V: np.ndarray
    W: np.ndarray
    wt: np.ndarray
    condition: float

    @classmethod
    def of(cls, st) -> RockingModes | str:
        """The modes of `st`'s rocking phase, or why its linear part cannot be diagonalised
        (kept for the last few structures: a sweep builds one per run)."""
        if st.n == 0:
            return "a rigid block has no elastic modes to advance exactly"
        key = tuple(np.asarray(a, dtype=float).tobytes() for a in (st.m, st.H, st.K, st.C)) + (
            float(st.J_p), float(st.m0), float(st.h0), float(st.B), float(st.g),
        )  # fmt: skip
        got = _KEPT.get(key)
        if got is None:
            got = _KEPT[key] = cls._of(st)
            while len(_KEPT) > _KEEP:
                _KEPT.pop(next(iter(_KEPT)))
        return got

    @classmethod
    def _of(cls, st) -> RockingModes | str:
        if st.n == 0:
            return "a rigid block has no elastic modes to advance exactly"
        L = _jacobian(st)
        if not np.all(np.isfinite(L)):
            return "its linearised rocking system is not finite"
        lam, V = np.linalg.eig(L)
        cond = float(np.linalg.cond(V))
        if not (np.all(np.isfinite(lam)) and cond < MAX_CONDITION):
            return (
                f"its linearised rocking system is (nearly) defective: the eigenvector "
                f"matrix has condition number {cond:.3g}"
            )
        Winv = np.linalg.inv(V)
        keep = lam.imag >= 0.0  # numpy returns conjugate pairs of a real matrix exactly
        if np.count_nonzero(lam.imag > 0.0) != np.count_nonzero(lam.imag < 0.0):
            return "its linearised rocking system has unpaired complex eigenvalues"
        wt = np.where(lam.imag[keep] > 0.0, 2.0, 1.0)
        return cls(
            L=np.ascontiguousarray(L),
            lam=np.ascontiguousarray(lam[keep]),
            V=np.ascontiguousarray(V[:, keep]),
            W=np.ascontiguousarray(Winv[keep, :]),
            wt=wt,
            condition=cond,
        )

    @property
    def arrays(self) -> tuple:
        """(L, lam, V, W, wt), as `._exp_kernel.exp_phase` takes them."""
        return self.L, self.lam, self.V, self.W, self.wt


_KEEP = 16
_KEPT: dict = {}
