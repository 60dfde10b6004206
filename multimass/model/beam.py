"""Column stiffness: Euler–Bernoulli elements, base springs and static condensation.

Degrees of freedom of nodes 1..N are ordered ``[u_1..u_N, Ω_1..Ω_N]`` as in
paper 001, Eq 1. Node 0 (the base) is fixed: the springs K_fp (horizontal)
and K_rot (rotational) tie node 1 to it.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError

__all__ = ["beam_element_stiffness", "column_stiffness", "condense"]


def beam_element_stiffness(EI: float, length: float) -> np.ndarray:
    """Bending stiffness of an inextensible Euler–Bernoulli beam element.

    Parameters
    ----------
    EI : float
        Bending stiffness E_s I_s (N m²).
    length : float
        Element length (m).

    Returns
    -------
    ndarray, shape (4, 4)
        Stiffness over ``[u_a, Ω_a, u_b, Ω_b]`` (end translations, end rotations).
    """
    L = float(length)
    if L <= 0.0:
        raise InputError(f"`length` = {L!r}: a beam element needs a positive length")
    return (
        EI
        / L**3
        * np.array(
            [
                [12.0, 6.0 * L, -12.0, 6.0 * L],
                [6.0 * L, 4.0 * L * L, -6.0 * L, 2.0 * L * L],
                [-12.0, -6.0 * L, 12.0, -6.0 * L],
                [6.0 * L, 2.0 * L * L, -6.0 * L, 4.0 * L * L],
            ]
        )
    )


def column_stiffness(heights, EI: float, K_fp: float, K_rot: float) -> np.ndarray:
    """Full-contact stiffness K_s of the column (paper 001, Eq 1).

    Beam elements join nodes i and i+1 (i = 1..N-1); zero-length springs
    K_fp (on u_1) and K_rot (on Ω_1) join node 1 to the fixed node 0.

    Returns
    -------
    ndarray, shape (2N, 2N)
        ``[[K_tt, K_tr], [K_rt, K_rr]]`` over ``[u; Ω]``.
    """
    H = np.asarray(heights, dtype=float)
    n = H.size
    Ks = np.zeros((2 * n, 2 * n))
    Ks[0, 0] += K_fp
    Ks[n, n] += K_rot
    for e in range(n - 1):
        dofs = [e, n + e, e + 1, n + e + 1]
        Ks[np.ix_(dofs, dofs)] += beam_element_stiffness(EI, H[e + 1] - H[e])
    return Ks


def condense(Ks: np.ndarray) -> np.ndarray:
    """Condensed lateral stiffness K = K_tt − K_tr K_rr⁻¹ K_rt (paper 001, Eq 2).

    The rotations carry no inertia, so the condensation is exact. K_rr is
    solved by Cholesky, not inverted.
    """
    import scipy.linalg as sla  # here: a rigid block's runs need no SciPy

    n = Ks.shape[0] // 2
    Ktt, Ktr, Krr = Ks[:n, :n], Ks[:n, n:], Ks[n:, n:]
    K = Ktt - Ktr @ sla.cho_solve(sla.cho_factor(Krr), Ktr.T)  # paper 001, Eq 2
    return 0.5 * (K + K.T)
