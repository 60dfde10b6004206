"""Foss state-space eigen-solution of non-classically damped systems (paper 001, Eqs 22–25)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from .errors import ModalError
from .linearise import LinearSystem

__all__ = ["StateSpaceModes", "state_matrix", "foss", "frequency_and_damping"]


def state_matrix(system: LinearSystem) -> np.ndarray:
    """The first-order matrix A of paper 001, Eq 24.

    A = [[0, I], [−M⁻¹K, −M⁻¹C]], with M⁻¹ applied by an LU solve.
    """
    n = system.n
    lu = sla.lu_factor(system.M)
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -sla.lu_solve(lu, system.K)   # paper 001, Eq 24
    A[n:, n:] = -sla.lu_solve(lu, system.C)
    return A


def frequency_and_damping(eigenvalues: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """ω_k = |Λ_k| and ζ_k = −Re Λ_k / |Λ_k| (paper 001, Eq 25)."""
    lam = np.asarray(eigenvalues, dtype=complex)
    omega = np.abs(lam)                        # paper 001, Eq 25
    with np.errstate(invalid="ignore", divide="ignore"):
        zeta = np.where(omega > 0.0, -lam.real / np.where(omega > 0, omega, 1.0), 0.0)
    return omega, zeta


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
        If M is singular or the solver returns non-finite values.
    """
    try:
        A = state_matrix(system)
    except (sla.LinAlgError, ValueError) as exc:
        raise ModalError(f"mass matrix of the {system.phase} system is singular ({exc})") from exc
    lam, V = sla.eig(A)
    if not (np.all(np.isfinite(lam)) and np.all(np.isfinite(V))):
        raise ModalError(f"eigen-solution of the {system.phase} system is not finite")
    return StateSpaceModes(eigenvalues=lam, eigenvectors=V[: system.n, :])
