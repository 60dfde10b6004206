"""Modal Assurance Criterion (Ewins, Modal Testing, 2000; paper 001, Section 4.2)."""

from __future__ import annotations

import numpy as np

from .errors import ModalError

__all__ = ["mac"]


def _as_shapes(phi, name: str) -> np.ndarray:
    try:
        a = np.asarray(phi)
    except ValueError:  # ragged nested lists
        raise ModalError(
            f"`{name}` is ragged: give shapes as an (n_locations, n_modes) array, "
            "every mode with the same locations"
        ) from None
    if a.dtype.kind not in "iufc":
        raise ModalError(f"`{name}` holds {a.dtype} values: give real or complex numbers")
    if a.ndim == 1:
        a = a[:, None]
    if a.ndim != 2 or a.shape[0] == 0 or a.shape[1] == 0:
        raise ModalError(
            f"`{name}` has shape {np.shape(phi)}: give shapes as "
            "(n_locations, n_modes) or one shape as (n_locations,)"
        )
    if not np.all(np.isfinite(a)):
        raise ModalError(f"`{name}` holds non-finite values")
    if np.any(np.linalg.norm(a, axis=0) == 0.0):
        raise ModalError(f"`{name}` holds an all-zero shape; MAC is undefined for it")
    return a


def mac(phi_a, phi_b=None) -> np.ndarray:
    """MAC matrix between two sets of (possibly complex) mode shapes.

    ``MAC_jk = |φ_aj^H φ_bk|² / ((φ_aj^H φ_aj)(φ_bk^H φ_bk))``.

    Parameters
    ----------
    phi_a : array_like, shape (n_locations, n_modes_a) or (n_locations,)
    phi_b : array_like, shape (n_locations, n_modes_b) or (n_locations,), optional
        Defaults to `phi_a` (the auto-MAC).

    Returns
    -------
    ndarray, shape (n_modes_a, n_modes_b)
        Real values in [0, 1]; invariant to the scale (and phase) of each shape.
    """
    a = _as_shapes(phi_a, "phi_a")
    b = a if phi_b is None else _as_shapes(phi_b, "phi_b")
    if a.shape[0] != b.shape[0]:
        raise ModalError(
            f"`phi_a` has {a.shape[0]} locations but `phi_b` has {b.shape[0]}; "
            "MAC compares shapes at the same locations"
        )
    cross = np.abs(a.conj().T @ b) ** 2
    na = np.real(np.sum(a.conj() * a, axis=0))
    nb = np.real(np.sum(b.conj() * b, axis=0))
    return np.clip(cross / np.outer(na, nb), 0.0, 1.0)
