"""Foss state-space eigen-solution of non-classically damped systems (paper 001, Eqs 22–25)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from .errors import ModalError
from .linearisation import LinearSystem

__all__ = [
    "StateSpaceModes",
    "state_matrix",
    "foss",
    "frequency_and_damping",
    "pair_frequency_and_damping",
    "check_system",
]


def state_matrix(system: LinearSystem) -> np.ndarray:
    """The first-order matrix A of paper 001, Eq 24.

    A = [[0, I], [−M⁻¹K, −M⁻¹C]], with M⁻¹ applied by an LU solve.
    """
    n = system.n
    lu = sla.lu_factor(system.M)
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -sla.lu_solve(lu, system.K)  # paper 001, Eq 24
    A[n:, n:] = -sla.lu_solve(lu, system.C)
    return A


def frequency_and_damping(eigenvalues: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``ω_k = |Λ_k|`` and ``ζ_k = −Re Λ_k / |Λ_k|`` (paper 001, Eq 25), for complex couples."""
    lam = np.asarray(eigenvalues, dtype=complex)
    omega = np.abs(lam)  # paper 001, Eq 25
    with np.errstate(invalid="ignore", divide="ignore"):
        zeta = np.where(omega > 0.0, -lam.real / np.where(omega > 0, omega, 1.0), 0.0)
    return omega, zeta


def pair_frequency_and_damping(lam_1, lam_2) -> tuple[np.ndarray, np.ndarray]:
    """ω = √(λ1 λ2) and ζ = −(λ1 + λ2) / (2ω) of a couple of real eigenvalues.

    The two roots of λ² + 2ζωλ + ω² = 0 have product ω² and sum −2ζω, so for a
    complex couple (Λ, Λ̄) these formulas are Eq 25's (``Λ Λ̄ = |Λ|²``,
    ``Λ + Λ̄ = 2 Re Λ``); for two real negative roots they give an overdamped mode's
    ω and ζ ≥ 1 (λ1,2 = −ζω ± ω√(ζ² − 1)).

    Parameters
    ----------
    lam_1, lam_2 : array_like of float
        The two real eigenvalues of each couple (same sign, non-zero).

    Returns
    -------
    omega, zeta : ndarray
    """
    l1, l2 = np.asarray(lam_1, dtype=float), np.asarray(lam_2, dtype=float)
    omega = np.sqrt(l1 * l2)  # extends paper 001, Eq 25 to real couples
    return omega, -(l1 + l2) / (2.0 * omega)


def check_system(system) -> None:
    """Refuse a linear system Eq 24 cannot solve: the message names the matrix and the fix.

    Raises
    ------
    ModalError
        If `system` is not a `LinearSystem`, its M, C, K are not square
        matrices of one size with finite entries, or M is not symmetric
        positive definite.
    """
    if not isinstance(system, LinearSystem):
        raise ModalError(
            f"`system` is a {type(system).__name__}: give a modal.LinearSystem "
            "(from modal.full_contact, modal.rocking or modal.linearise)"
        )
    n = None
    for name in ("M", "C", "K"):
        a = np.asarray(getattr(system, name))
        if a.ndim != 2 or a.shape[0] != a.shape[1] or a.shape[0] == 0 or a.dtype.kind not in "iuf":
            raise ModalError(
                f"`system.{name}` has shape {a.shape} and dtype {a.dtype}: give a "
                "square real matrix"
            )
        if n is not None and a.shape[0] != n:
            raise ModalError(
                f"`system.{name}` is {a.shape[0]}x{a.shape[0]} but `system.M` is "
                f"{n}x{n}: M, C and K must have one size"
            )
        n = a.shape[0]
        if not np.all(np.isfinite(a)):
            raise ModalError(f"`system.{name}` holds non-finite entries; give finite numbers")
    M = np.asarray(system.M, dtype=float)
    if not np.allclose(M, M.T, rtol=1e-12, atol=0.0):
        raise ModalError("`system.M` is not symmetric: a mass matrix must be")
    try:
        sla.cholesky(M)
    except sla.LinAlgError:
        raise ModalError(
            "`system.M` is not positive definite: every coordinate needs mass (or inertia)"
        ) from None


@dataclass(frozen=True, eq=False)
class StateSpaceModes:
    """All 2n eigenpairs of Eq 24.

    Attributes
    ----------
    eigenvalues : ndarray, shape (2n,), complex
        Λ, in the order returned by the solver.
    eigenvectors : ndarray, shape (n, 2n), complex
        The displacement half v of each state eigenvector [v; Λ v].
    """

    eigenvalues: np.ndarray
    eigenvectors: np.ndarray


def foss(system: LinearSystem) -> StateSpaceModes:
    """Solve the state-space eigenproblem of paper 001, Eq 24.

    Parameters
    ----------
    system : LinearSystem

    Returns
    -------
    StateSpaceModes

    Raises
    ------
    ModalError
        If the system is malformed (see `check_system`) or the solver returns
        non-finite values.
    """
    check_system(system)
    lam, V = sla.eig(state_matrix(system))
    if not (np.all(np.isfinite(lam)) and np.all(np.isfinite(V))):
        raise ModalError(f"eigen-solution of the {system.phase} system is not finite")
    return StateSpaceModes(eigenvalues=lam, eigenvectors=V[: system.n, :])
