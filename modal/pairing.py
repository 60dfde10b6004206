"""Which state-space eigenvalues form which mode (paper 001, Eqs 24–25).

Eq 24 gives 2n eigenvalues. Paper 001 reads them as complex-conjugate couples
(the vibration modes) plus, while rocking, one real couple ±p_l (the rocking
mode). A heavily damped vibration mode is *overdamped* instead: its couple is
two real negative eigenvalues λ1,2 = −ζω ± ω√(ζ² − 1). Rayleigh damping grows
with frequency, so the high modes of a finely meshed column are overdamped;
that is physics, not an error, and the modes are reported as such.

The pairing rule, stated once:

1. Complex couples pair by conjugacy (LAPACK returns them as exact conjugates).
2. Each eigenvector z is compared with the undamped modes Φ of the same phase
   (K Φ = M Φ Ω², Φᵀ M Φ = I) through its modal participation
   ``w_k = |φ_kᵀ M z|² / Σ_j |φ_jᵀ M z|²``, so Σ_k w_k = 1.
3. Each complex couple takes one undamped mode, by the assignment that
   maximises the total participation (`scipy.optimize.linear_sum_assignment`).
4. The real eigenvalues go two by two to the undamped modes left over, by the
   assignment that maximises the total participation with two places per mode,
   so every left-over mode receives exactly two. While rocking, the undamped
   rocking mode (the one negative eigenvalue of K_L) is kept for the real
   eigenvalues; the two it receives are the rocking couple, one positive and
   one negative.

In a classically damped system (full contact, Rayleigh C) both eigenvectors
of an overdamped mode *are* its undamped shape, so the rule is exact there;
while rocking (C_L is not classical) it is the nearest-shape rule.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from .errors import ModalError

__all__ = ["ModePairing", "participation", "pair_modes"]

#: |Re Λ| / |Λ| below which an eigenvalue counts as undamped, not growing (round-off of eig)
_UNDAMPED_NOISE = 1e-10


@dataclass(frozen=True, eq=False)
class ModePairing:
    """Eigenvalue indices of each mode of one phase.

    Attributes
    ----------
    under : ndarray of int, shape (k,)
        Index of the Im Λ > 0 member of each complex couple.
    under_mode : ndarray of int, shape (k,)
        The undamped mode (column of Φ) each complex couple belongs to.
    over : ndarray of int, shape (m, 2)
        Indices of the two real eigenvalues of each overdamped mode, the more
        negative first.
    over_mode : ndarray of int, shape (m,)
        The undamped mode each overdamped couple belongs to.
    rocking : ndarray of int, shape (2,) or None
        The rocking couple, positive eigenvalue first (rocking phase only).
    under_weight, over_weight : ndarray, shape (k,) and (m,)
        Participation w of the assigned undamped mode in each couple's
        eigenvector(s) (the smaller of the two for a real couple): 1 for a
        classically damped system, lower where damping mixes the modes.
    """

    under: np.ndarray
    under_mode: np.ndarray
    over: np.ndarray
    over_mode: np.ndarray
    rocking: np.ndarray | None
    under_weight: np.ndarray
    over_weight: np.ndarray


def participation(Phi: np.ndarray, M: np.ndarray, Z: np.ndarray) -> np.ndarray:
    """Modal participation w[k, j] of undamped mode k in eigenvector j (rule 2 above).

    Parameters
    ----------
    Phi : ndarray, shape (n, n)
        M-orthonormal undamped modes (columns).
    M : ndarray, shape (n, n)
    Z : ndarray, shape (n, p)
        Eigenvectors (columns), real or complex, any scale.

    Returns
    -------
    ndarray, shape (n, p)
        Non-negative; each column sums to 1.
    """
    q = np.abs(Phi.T @ (M @ Z)) ** 2
    return q / q.sum(axis=0)


def _assign(weights: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """Column (from `cols`) given to each row, maximising the total weight."""
    r, c = linear_sum_assignment(weights[np.ix_(cols, rows)].T, maximize=True)
    out = np.empty(rows.size, dtype=int)
    out[r] = cols[c]
    return out


def _conjugate_couples(lam: np.ndarray, phase: str) -> tuple[np.ndarray, np.ndarray]:
    """Indices of the Im > 0 eigenvalues and of the real ones; checks the couples."""
    up, down = np.flatnonzero(lam.imag > 0.0), np.flatnonzero(lam.imag < 0.0)
    if up.size != down.size or not np.allclose(
        np.sort_complex(lam[up]), np.sort_complex(lam[down].conj()), rtol=1e-10
    ):
        raise ModalError(
            f"the {phase} system has complex eigenvalues without their conjugates; "
            "its matrices must be real"
        )
    return up, np.flatnonzero(lam.imag == 0.0)


def pair_modes(
    lam: np.ndarray,
    Z: np.ndarray,
    M: np.ndarray,
    Phi: np.ndarray,
    rocking_mode: int | None,
    phase: str,
) -> ModePairing:
    """Pair the eigenvalues of Eq 24 into modes by the rule of the module docstring.

    Parameters
    ----------
    lam : ndarray, shape (2n,), complex
    Z : ndarray, shape (n, 2n), complex
        Displacement part of each state eigenvector.
    M : ndarray, shape (n, n)
    Phi : ndarray, shape (n, n)
        M-orthonormal undamped modes.
    rocking_mode : int or None
        Column of Φ that is the undamped rocking mode (rocking phase), else None.
    phase : str
        For messages.

    Returns
    -------
    ModePairing

    Raises
    ------
    ModalError
        If the eigenvalues cannot form these modes (no rocking couple, or a
        vibration mode that grows instead of decaying).
    """
    n = Phi.shape[1]
    up, real = _conjugate_couples(lam, phase)
    W = participation(Phi, M, Z)
    vib_cols = np.array([k for k in range(n) if k != rocking_mode], dtype=int)
    if rocking_mode is not None and real.size < 2:
        raise ModalError(
            f"the {phase} system has no real eigenvalue couple for the rocking "
            "mode (expected ≈ ±p_l)"
        )
    under_mode = _assign(W, up, vib_cols) if up.size else np.empty(0, dtype=int)
    left = np.setdiff1d(np.arange(n), under_mode)
    if 2 * left.size != real.size:  # cannot happen for real matrices: 2n = 2k + #real
        raise ModalError(
            f"the {phase} system has {real.size} real eigenvalues for "
            f"{left.size} modes; expected two per mode"
        )
    slot = np.repeat(np.arange(left.size), 2)  # two places per left-over mode
    W_slots = np.zeros((slot.size, W.shape[1]))
    W_slots[:, real] = W[left[slot]][:, real]
    got = _assign(W_slots, real, np.arange(slot.size))
    couples = {int(left[s]): [] for s in range(left.size)}
    for i, s in zip(real, got):
        couples[int(left[slot[s]])].append(int(i))
    rocking = None
    if rocking_mode is not None:
        rocking = np.array(sorted(couples.pop(rocking_mode), key=lambda i: -lam[i].real))
    over_mode = np.array(sorted(couples), dtype=int)
    over = np.array(
        [sorted(couples[k], key=lambda i: lam[i].real) for k in over_mode], dtype=int
    ).reshape(-1, 2)
    pairing = ModePairing(
        under=up,
        under_mode=under_mode,
        over=over,
        over_mode=over_mode,
        rocking=rocking,
        under_weight=W[under_mode, up],
        over_weight=np.min(W[over_mode[:, None], over], axis=1, initial=1.0),
    )
    _check_signs(lam, pairing, phase)
    return pairing


def _check_signs(lam: np.ndarray, p: ModePairing, phase: str) -> None:
    """Vibration modes decay; the rocking couple is one positive, one negative eigenvalue."""
    vib = np.concatenate([p.under, p.over.ravel()])
    grows = lam[vib].real > _UNDAMPED_NOISE * np.abs(lam[vib])  # an undamped mode has Re ≈ 0
    if np.any(grows) or np.any(lam[vib] == 0.0):
        bad = ", ".join(f"{x:.6g}" for x in lam[vib][grows | (lam[vib] == 0.0)])
        raise ModalError(
            f"the {phase} system has vibration eigenvalues that do not decay ({bad} "
            "rad/s): the structure is unstable (or has a zero-frequency mode) beyond "
            "its rocking mode; check the stiffness and damping of the specimen"
        )
    if p.rocking is not None and not lam[p.rocking[0]].real > 0.0 > lam[p.rocking[1]].real:
        pair = ", ".join(f"{x.real:.6g}" for x in lam[p.rocking])
        raise ModalError(
            f"the {phase} system's rocking couple is {pair} rad/s, not ±p_l: "
            "the rocking mode could not be identified"
        )
