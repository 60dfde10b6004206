"""Scale and sign of mode shapes: one rule for the API, the JSON, the Markdown and the figures.

1. **Scale.** Each eigenvector z = [u; θ] is divided by the Euclidean norm of
   its elastic part u over the shape nodes, which then has unit norm (paper
   001, Section 4.2: "scaled to Euclidean norm of unity"). The rocking part v_r
   keeps the same scale, so the compound shape v_c = v_t + H v_r is in the
   units of v_t. (Should u vanish at every shape node, its norm over all
   nodes is used instead.)
2. **Full-contact shapes v_n**: the largest-magnitude component at the shape
   nodes is made real and positive.
3. **Uplifted shapes** (rocking-phase vibration mode j, real or complex,
   under- or overdamped): first rule 2, then the sign (×−1) that makes the
   one of v_t and v_c that is closer to v_nj (larger MAC) correlate positively
   with v_nj: Re(v_njᵀ x) > 0. Compared shapes are then drawn the same way
   up. If both MAC values are below `UNRELATED_MAC` the shapes are unrelated
   and rule 2 stands.
4. **The rocking mode** is scaled to θ = 1.

Figures draw these arrays as stored: nothing is flipped at plotting time.
"""

from __future__ import annotations

import numpy as np

from .assurance import mac

__all__ = ["UNRELATED_MAC", "normalise", "align_to_full_contact"]

#: Below this MAC an uplifted shape is not compared with v_n for its sign (rule 3).
UNRELATED_MAC = 0.01


def normalise(v: np.ndarray, idx: np.ndarray, n_elastic: int) -> np.ndarray:
    """Scale eigenvectors by rules 1 and 2 of the module docstring.

    Parameters
    ----------
    v : ndarray, shape (n_dofs, k), real or complex
        Eigenvectors over [u_1..u_N] or [u_1..u_N, θ].
    idx : ndarray of int
        0-based rows of the shape nodes.
    n_elastic : int
        N, the number of elastic rows (u) at the top of `v`.

    Returns
    -------
    ndarray
        Same shape; real if `v` is real.
    """
    vt = v[idx]
    norm = np.linalg.norm(vt, axis=0)
    weak = norm <= 1e-12 * np.linalg.norm(v[:n_elastic], axis=0)
    norm = np.where(weak, np.linalg.norm(v[:n_elastic], axis=0), norm)
    big = vt[np.argmax(np.abs(vt), axis=0), np.arange(v.shape[1])]
    big = np.where(big == 0.0, 1.0, big)  # u = 0 at every shape node: no sign to fix
    out = v / (norm * (big / np.abs(big)))
    return out.real if np.isrealobj(v) else out


def _mac(a: np.ndarray, b: np.ndarray) -> float:
    """`modal.mac` of two shapes, 0 when one of them is zero."""
    return float(mac(a, b)[0, 0]) if np.any(a) and np.any(b) else 0.0


def align_to_full_contact(
    shapes: np.ndarray, modes: np.ndarray, v_n: np.ndarray, idx: np.ndarray, heights: np.ndarray
) -> np.ndarray:
    """Apply rule 3: flip uplifted shapes whose closer partner opposes v_n.

    Parameters
    ----------
    shapes : ndarray, shape (N + 1, k)
        Rocking-phase eigenvectors [u; θ] after `normalise`.
    modes : ndarray of int, shape (k,)
        0-based vibration-mode number of each column (its column of `v_n`).
    v_n : ndarray, shape (n_shape_nodes, N)
        Full-contact shapes at the shape nodes.
    idx : ndarray of int
        0-based rows of the shape nodes.
    heights : ndarray, shape (n_shape_nodes,)

    Returns
    -------
    ndarray
        `shapes` with some columns multiplied by −1.
    """
    out = shapes.copy()
    for col, j in enumerate(modes):
        ref, vt = v_n[:, j], shapes[idx, col]
        vc = vt + heights * shapes[-1, col]
        m_t, m_c = _mac(ref, vt), _mac(ref, vc)
        if max(m_t, m_c) < UNRELATED_MAC:
            continue
        closer = vt if m_t >= m_c else vc
        if np.real(ref @ closer) < 0.0:
            out[:, col] = -shapes[:, col]
    return out
