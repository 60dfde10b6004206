"""Modal analysis of a rocking structure in full contact and while rocking (paper 001, Section 3).

Normalisation of shapes (documented once, used everywhere): each eigenvector
z = [u; θ] is scaled so that its elastic part over the *shape nodes* has unit
Euclidean norm and its largest-magnitude elastic component is real and
positive. The rocking part v_r keeps the same scale, so the compound shape
v_c = v_t + H v_r (Section 4.2) is in the same units as v_t. The shape nodes
default to nodes 2..N, as in paper 001 Fig 4 (node 1 is the foundation); for
N = 1 they are node 1. The rocking mode is scaled to θ = 1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from multimass import Structure, column

from .errors import ModalError
from .foss import foss, frequency_and_damping
from .linearise import LinearSystem, full_contact, rocking
from .mac import mac

__all__ = ["PhaseModes", "ModalAnalysis", "analyse", "phase_modes", "default_shape_nodes", "nodal_points"]

_TWO_PI = 2.0 * np.pi


@dataclass(frozen=True, eq=False)
class PhaseModes:
    """Vibration modes of one phase, ascending in frequency.

    Attributes
    ----------
    phase : str
    eigenvalues : ndarray, complex
        All state-space eigenvalues Λ (paper 001, Eq 24), for plotting.
    vibration_eigenvalues : ndarray, complex, shape (k,)
        The vibration modes' Λ with Im Λ > 0, ascending in |Λ|.
    omega, damping : ndarray, shape (k,)
        ω = |Λ| (rad/s) and ζ = −Re Λ / |Λ| (paper 001, Eq 25).
    undamped_omega : ndarray, shape (k,)
        Frequencies of the undamped system (rad/s).
    shapes : ndarray, complex, shape (n_dofs, k)
        Damped (complex) eigenvectors over the system's dofs, normalised.
    real_shapes : ndarray, shape (n_dofs, k)
        Undamped (real) eigenvectors, normalised.
    """

    phase: str
    eigenvalues: np.ndarray
    vibration_eigenvalues: np.ndarray
    omega: np.ndarray
    damping: np.ndarray
    undamped_omega: np.ndarray
    shapes: np.ndarray
    real_shapes: np.ndarray

    @property
    def freq_hz(self) -> np.ndarray:
        """Damped-mode frequencies ω / 2π (Hz)."""
        return self.omega / _TWO_PI


def default_shape_nodes(n: int) -> tuple[int, ...]:
    """Nodes used for shapes: 2..N as in paper 001 Fig 4, or (1,) when N = 1."""
    return tuple(range(2, n + 1)) if n >= 2 else (1,)


def _normalise(v: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """Scale eigenvector(s) v (n_dofs, k) by the rule in the module docstring."""
    vt = v[idx]
    big = vt[np.argmax(np.abs(vt), axis=0), np.arange(v.shape[1])]
    phase = big / np.abs(big)
    scale = np.linalg.norm(vt, axis=0) * phase
    out = v / scale
    return out.real if np.isrealobj(v) else out


def _split_rocking_pair(lam: np.ndarray, system: LinearSystem) -> tuple[np.ndarray, np.ndarray]:
    """Indices of the real rocking pair and of the vibration eigenvalues (Im > 0)."""
    order = np.argsort(np.abs(lam.imag))
    pair = order[:2]
    mag = np.abs(lam[pair])
    if not (np.all(np.abs(lam[pair].imag) <= 1e-8 * np.maximum(mag, 1.0))
            and lam[pair].real.prod() < 0.0):
        raise ModalError(f"the {system.phase} system has no real ± eigenvalue pair: "
                         f"{lam[pair]} (expected ≈ ±p_l)")
    pair = pair[np.argsort(-lam[pair].real)]
    return pair, order[2:]


def phase_modes(system: LinearSystem, shape_idx: np.ndarray) -> tuple[PhaseModes, dict]:
    """Damped (Foss) and undamped modes of one linear system.

    Returns the vibration modes and, for the rocking phase, a dict with the
    rocking pair's eigenvalues and eigenvectors (empty in full contact).
    """
    ss = foss(system)
    lam, V = ss.eigenvalues, ss.eigenvectors
    extra: dict = {}
    if system.phase == "rocking":
        pair, rest = _split_rocking_pair(lam, system)
        extra["rocking_eigenvalues"] = lam[pair].real
        extra["rocking_shape"] = (V[:, pair[0]] / V[-1, pair[0]]).real
    else:
        rest = np.arange(lam.size)
    vib = rest[lam[rest].imag > 0.0]
    vib = vib[np.argsort(np.abs(lam[vib]))]
    if 2 * vib.size != rest.size:
        raise ModalError(f"the {system.phase} system has overdamped or unpaired modes: "
                         f"{lam[rest]}")
    omega, zeta = frequency_and_damping(lam[vib])

    w2, Vr = sla.eigh(system.K, system.M)      # undamped, real eigenvectors
    keep = w2 > 0.0
    if system.phase == "rocking":
        if np.count_nonzero(~keep) != 1:
            raise ModalError("the undamped rocking system should have exactly one unstable "
                             f"(rocking) mode, found eigenvalues {w2[~keep]}")
        extra["rocking_shape_real"] = Vr[:, ~keep][:, 0] / Vr[-1, ~keep][0]
    modes = PhaseModes(
        phase=system.phase, eigenvalues=lam, vibration_eigenvalues=lam[vib], omega=omega,
        damping=zeta, undamped_omega=np.sqrt(w2[keep]),
        shapes=_normalise(V[:, vib], shape_idx), real_shapes=_normalise(Vr[:, keep], shape_idx))
    return modes, extra


@dataclass(frozen=True, eq=False)
class ModalAnalysis:
    """Modes of a structure in full contact and while rocking (paper 001, Sections 3, 4.2).

    Attributes
    ----------
    structure : Structure
    shape_nodes : tuple of int
        1-based node numbers at which shapes are given.
    full_contact, rocking : PhaseModes
    rocking_eigenvalues : ndarray, shape (2,)
        The real pair of the rocking mode, (+, −); compare with ±p_l.
    rocking_shape : ndarray, shape (N+1,)
        Undamped rocking-mode eigenvector [u; θ] scaled to θ = 1.
    """

    structure: Structure
    shape_nodes: tuple[int, ...]
    full_contact: PhaseModes
    rocking: PhaseModes
    rocking_eigenvalues: np.ndarray
    rocking_shape: np.ndarray

    @property
    def _idx(self) -> np.ndarray:
        return np.asarray(self.shape_nodes) - 1

    @property
    def heights(self) -> np.ndarray:
        """Heights of the shape nodes (m)."""
        return self.structure.H[self._idx]

    def full_contact_shapes(self, complex_: bool = False) -> np.ndarray:
        """v_n at the shape nodes, shape (n_shape_nodes, N)."""
        src = self.full_contact.shapes if complex_ else self.full_contact.real_shapes
        return src[self._idx]

    def elastic_shapes(self, complex_: bool = False) -> np.ndarray:
        """v_t, the elastic part of the uplifted vibration modes at the shape nodes."""
        src = self.rocking.shapes if complex_ else self.rocking.real_shapes
        return src[self._idx]

    def rocking_parts(self, complex_: bool = False) -> np.ndarray:
        """v_r, the rocking component of each uplifted vibration mode, shape (N,)."""
        src = self.rocking.shapes if complex_ else self.rocking.real_shapes
        return src[-1]

    def compound_shapes(self, complex_: bool = False) -> np.ndarray:
        """v_c = v_t + H v_r at the shape nodes (paper 001, Section 4.2)."""
        return self.elastic_shapes(complex_) + np.outer(self.heights, self.rocking_parts(complex_))

    def mac_full_vs_compound(self) -> np.ndarray:
        """MAC matrix, full-contact shapes (rows) vs uplifted compound shapes (columns)."""
        return mac(self.full_contact_shapes(), self.compound_shapes())

    def mac_full_vs_elastic(self) -> np.ndarray:
        """MAC matrix, full-contact shapes (rows) vs uplifted elastic parts (columns)."""
        return mac(self.full_contact_shapes(), self.elastic_shapes())

    def mac_measured(self, measured: np.ndarray, phase: str = "rocking") -> np.ndarray:
        """MAC of measured shapes (rows) against the compound (rocking) or
        full-contact (full_contact) shapes of this analysis (columns).

        `measured` has shape (n_shape_nodes, n_measured_modes).
        """
        model = self.compound_shapes() if phase == "rocking" else self.full_contact_shapes()
        return mac(measured, model)


def analyse(structure: Structure | str, shape_nodes=None) -> ModalAnalysis:
    """Modal analysis of full contact and rocking phases (paper 001, Section 3).

    Parameters
    ----------
    structure : Structure or str
        A structure, or a specimen name/path (built with `multimass.column`).
    shape_nodes : sequence of int, optional
        1-based nodes at which to report shapes (default: `default_shape_nodes`).

    Returns
    -------
    ModalAnalysis
    """
    s = structure if isinstance(structure, Structure) else column(structure)
    nodes = default_shape_nodes(s.n) if shape_nodes is None else tuple(int(i) for i in shape_nodes)
    if not nodes or any(not 1 <= i <= s.n for i in nodes) or len(set(nodes)) != len(nodes):
        raise ModalError(f"`shape_nodes` = {shape_nodes!r}: give distinct node numbers in 1..{s.n}")
    idx = np.asarray(nodes) - 1
    fc, _ = phase_modes(full_contact(s), idx)
    rk, extra = phase_modes(rocking(s), idx)
    return ModalAnalysis(structure=s, shape_nodes=nodes, full_contact=fc, rocking=rk,
                         rocking_eigenvalues=extra["rocking_eigenvalues"],
                         rocking_shape=extra["rocking_shape_real"])


def nodal_points(heights, shape) -> np.ndarray:
    """Heights where a real shape changes sign, by linear interpolation between nodes.

    Parameters
    ----------
    heights : array_like, shape (n,)
    shape : array_like, shape (n,)

    Returns
    -------
    ndarray
        The crossing heights, bottom to top (empty if the shape keeps its sign).
    """
    h = np.asarray(heights, dtype=float)
    v = np.asarray(shape, dtype=float)
    i = np.nonzero(np.sign(v[:-1]) * np.sign(v[1:]) < 0)[0]
    return h[i] + (h[i + 1] - h[i]) * v[i] / (v[i] - v[i + 1])
