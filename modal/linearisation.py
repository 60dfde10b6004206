"""Linearised equations of motion about the rest state (paper 001, Eqs 19–21).

``M_L z̈ + C_L ż + K_L z = −F_L`` with z = [u; θ] while rocking. In full
contact θ ≡ 0 is a constraint, so z = u and the system is Eq 3's (M, C, K).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multimass.model.structure import Structure

from .errors import ModalError

__all__ = ["LinearSystem", "full_contact", "rocking", "linearise"]


@dataclass(frozen=True, eq=False)
class LinearSystem:
    """A linear second-order system M z̈ + C ż + K z = −(r ü_g + f0).

    Attributes
    ----------
    phase : {"full_contact", "rocking"}
    M, C, K : ndarray, shape (n, n)
        Mass, damping and stiffness over `dofs`.
    r : ndarray, shape (n,)
        Influence vector of the ground acceleration ü_g.
    f0 : ndarray, shape (n,)
        Constant load (the restoring moment ±m_t g B while rocking, for θ > 0).
    dofs : tuple of str
        Names of the coordinates, ``("u1", ..., "uN")`` or with ``"theta"`` last.
    """

    phase: str
    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    r: np.ndarray
    f0: np.ndarray
    dofs: tuple[str, ...]

    @property
    def n(self) -> int:
        """Number of coordinates."""
        return self.M.shape[0]


def _u_names(n: int) -> tuple[str, ...]:
    return tuple(f"u{i + 1}" for i in range(n))


def _check_structure(structure) -> None:
    if not isinstance(structure, Structure):
        raise ModalError(
            f"`structure` is a {type(structure).__name__}: give a multimass "
            "Structure, e.g. multimass.column('S1') or multimass.column('my.toml')"
        )


def full_contact(structure: Structure) -> LinearSystem:
    """The full-contact system, paper 001 Eq 3: M ü + C u̇ + K u = −M 1 ü_g."""
    _check_structure(structure)
    if structure.n == 0:
        raise ModalError(
            f"structure {structure.name!r} has no elastic nodes: a rigid "
            "body has no full-contact vibration modes"
        )
    M = structure.M
    return LinearSystem(
        "full_contact",
        M.copy(),
        structure.C.copy(),
        structure.K.copy(),
        r=M @ np.ones(structure.n),
        f0=np.zeros(structure.n),
        dofs=_u_names(structure.n),
    )


def rocking(structure: Structure, side: int = +1) -> LinearSystem:
    """The rocking system linearised about θ = 0 (paper 001, Eqs 19–20).

    Parameters
    ----------
    structure : Structure
    side : {+1, -1}
        +1 rocking about the right pivot, −1 about the left; only the constant
        load ±m_t g B depends on it.

    Returns
    -------
    LinearSystem
        Over z = [u; θ]:
        M_L = [[M, M H], [Hᵀ M, J_p]], C_L = [[C, 0], [0, 0]],
        K_L = [[K, −g M 1], [−g 1ᵀ M, −g (Hᵀ M 1 + m0 h0)]].
    """
    _check_structure(structure)
    if isinstance(side, bool) or side not in (1, -1):
        raise ModalError(f"`side` = {side!r}: use +1 (right pivot) or -1 (left pivot)")
    s, n, g = structure, structure.n, structure.g
    MH = s.m * s.H
    ML = np.zeros((n + 1, n + 1))
    ML[:n, :n] = s.M  # paper 001, Eq 19: M ü + M H θ̈
    ML[:n, n] = MH
    ML[n, :n] = MH  # paper 001, Eq 20: Hᵀ M ü + J_p θ̈
    ML[n, n] = s.J_p
    CL = np.zeros((n + 1, n + 1))
    CL[:n, :n] = s.C  # paper 001, Eq 19: C u̇
    KL = np.zeros((n + 1, n + 1))
    KL[:n, :n] = s.K  # paper 001, Eq 19: K u − M 1 g θ
    KL[:n, n] = -g * s.m
    KL[n, :n] = -g * s.m  # paper 001, Eq 20: g(−uᵀ M 1 − Hᵀ M 1 θ)
    KL[n, n] = -g * s.static_moment
    r = np.append(s.m, s.static_moment)  # M 1 ü_g and m_t H_cg ü_g
    f0 = np.zeros(n + 1)
    f0[n] = side * s.m_t * g * s.B  # paper 001, Eq 20: ± m_t g B
    return LinearSystem("rocking", ML, CL, KL, r=r, f0=f0, dofs=_u_names(n) + ("theta",))


def linearise(structure: Structure, phase: str) -> LinearSystem:
    """The linear system of `phase` ("full_contact" or "rocking")."""
    if phase == "full_contact":
        return full_contact(structure)
    if phase == "rocking":
        return rocking(structure)
    raise ModalError(f"`phase` = {phase!r}: use 'full_contact' or 'rocking'")
