"""The modes of full contact that `._contact_kernel.contact_phase` advances exactly.

`ContactModes.of` decides whether a structure's full-contact phase can be solved
in closed form — classical damping (Φᵀ C Φ diagonal, as Rayleigh damping is), no
negative damping — and lays out the modes; otherwise it gives the reason, and the
compiled path integrates Eq 3 with its Runge–Kutta pair as before.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...model.structure import derived_once

__all__ = ["ContactModes", "CLASSICAL_RTOL", "CHECKS_PER_PERIOD"]

#: Largest off-diagonal of Φᵀ C Φ, relative to its largest diagonal term, still taken as
#: classical damping (a Rayleigh C built in floating point sits near 1e-15).
CLASSICAL_RTOL = 1e-9
#: Event checks per period of the stiffest underdamped mode. The uplift margin holds that
#: mode's velocity, so it can be positive for a small part of its period: with 4 checks
#: the closed form missed uplifts that DOP853 at rtol 1e-12 finds (a 3-node column at
#: 5.656 s; S1 under El Centro × 1.5: 249 events against 225), with 8 still one case;
#: with 16 every case tried agrees (`tests/multimass/engines/test_fast_contact.py`). Overdamped
#: modes do not oscillate: their free part changes sign at most once.
CHECKS_PER_PERIOD = 16


@dataclass(frozen=True, eq=False)
class ContactModes:
    """Mass-normalised modes of full contact (paper 001, Eq 3) for the exact phase.

    Attributes
    ----------
    phi : ndarray (n, n)
        Mode shapes in columns, Φᵀ M Φ = I.
    w, z, gam : ndarray (n,)
        Circular frequencies (rad/s), damping ratios (any ≥ 0: many-node columns
        with Rayleigh damping have overdamped top modes) and participation factors
        Φᵀ M 1.
    h_max : float
        Longest interval between two event checks (s): 2π/ω of the stiffest
        underdamped mode (of any mode if none is) over `CHECKS_PER_PERIOD`.
    screen : ndarray (3, n)
        Rows a, b, c with which paper 001's Eq 8 reads, in modes, M_o^fc =
        a·q + b·q̇ + m0 h0 ü_g and L_p^fc = c·q̇ (M_res^fc = g (m_t B ∓ Γ·q)):
        a = −Φᵀ Kᵀ H, b = −Φᵀ Cᵀ H (as M(ü + 1 ü_g) = −C u̇ − K u), c = Φᵀ M H. The
        kernel uses them only to skip event checks far from uplift; the events
        themselves are the compiled `event_value`.
    """

    phi: np.ndarray
    w: np.ndarray
    z: np.ndarray
    gam: np.ndarray
    h_max: float
    screen: np.ndarray

    @classmethod
    def of(cls, st) -> ContactModes | str:
        """The modes of `st`'s full contact, or why its full contact has no exact solution here."""
        return derived_once(st, "contact_modes", cls._of)

    @classmethod
    def _of(cls, st) -> ContactModes | str:
        if st.n == 0:
            return "a rigid body has no elastic full-contact phase"
        m = np.asarray(st.m, dtype=float)
        K = np.asarray(st.K, dtype=float).reshape(st.n, st.n)
        C = np.asarray(st.C, dtype=float).reshape(st.n, st.n)
        if np.abs(K - K.T).max() > CLASSICAL_RTOL * np.abs(K).max():
            return "its full-contact stiffness matrix is not symmetric"
        import scipy.linalg  # here: a rigid block's runs need no SciPy

        lam, phi = scipy.linalg.eigh(K, np.diag(m))
        if not np.all(lam > 0.0):
            return "its full-contact stiffness is not positive definite"
        w = np.sqrt(lam)
        c = phi.T @ C @ phi
        diag = np.diag(c).copy()
        off = np.abs(c - np.diag(diag)).max()
        if off > CLASSICAL_RTOL * np.abs(diag).max():
            return (
                f"its damping is not classical (Φᵀ C Φ has off-diagonal terms "
                f"{off / np.abs(diag).max():.2g} of its diagonal)"
            )
        z = diag / (2.0 * w)
        if np.any(z < 0.0):
            i = int(np.argmin(z))
            return (
                f"its mode {i + 1} ({w[i] / (2 * math.pi):.4g} Hz) has negative damping "
                f"(ζ = {z[i]:.3g})"
            )
        oscillating = w[z < 1.0] if np.any(z < 1.0) else w
        return cls(
            phi=np.ascontiguousarray(phi),
            w=w,
            z=z,
            gam=phi.T @ m,
            h_max=float(2.0 * math.pi / oscillating.max() / CHECKS_PER_PERIOD),
            screen=np.ascontiguousarray(
                np.stack([-(phi.T @ K.T @ st.H), -(phi.T @ C.T @ st.H), phi.T @ (m * st.H)])
            ),
        )
