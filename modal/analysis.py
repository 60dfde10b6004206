"""Modal analysis of a rocking structure in full contact and while rocking (paper 001, Section 3).

Every vibration mode of a phase is reported: underdamped modes (a complex
couple Λ, Λ̄; ω and ζ by Eq 25) and overdamped ones (two real negative
eigenvalues; ω = √(λ1 λ2), ζ = −(λ1 + λ2)/(2ω) ≥ 1). Modes are numbered by
the undamped mode they belong to (`modal.pairing` states the rule), so "mode
j" is the same mode in the frequency tables, the shapes and the MAC. Shapes
follow one scale and sign rule, stated in `modal.shapes`. The shape nodes
default to nodes 2..N, as in paper 001 Fig 4 (node 1 is the foundation); for
N = 1 they are node 1.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import pandas as pd
import scipy.linalg as sla

from multimass.model.structure import Structure

from .assurance import mac
from .eigen import foss, frequency_and_damping, pair_frequency_and_damping
from .errors import ModalError
from .linearisation import LinearSystem, full_contact, rocking
from .pairing import pair_modes
from .shapes import align_to_full_contact, normalise
from .validate import validate_shape_nodes, validate_structure

__all__ = [
    "PhaseModes",
    "ModalAnalysis",
    "analyse",
    "phase_modes",
    "default_shape_nodes",
    "nodal_points",
]

_TWO_PI = 2.0 * np.pi


@dataclass(frozen=True, eq=False)
class PhaseModes:
    """Vibration modes of one phase: underdamped ones and overdamped ones.

    Attributes
    ----------
    phase : str
    eigenvalues : ndarray, complex
        All state-space eigenvalues Λ (paper 001, Eq 24), for plotting.
    vibration_eigenvalues : ndarray, complex, shape (k,)
        The underdamped modes' Λ with Im Λ > 0, ascending in ``|Λ|``.
    omega, damping : ndarray, shape (k,)
        Their ``ω = |Λ|`` (rad/s) and ``ζ = −Re Λ / |Λ|`` (paper 001, Eq 25).
    undamped_omega : ndarray, shape (N,)
        Frequencies of the undamped system (rad/s), ascending: mode j is
        ``undamped_omega[j - 1]``.
    shapes : ndarray, complex, shape (n_dofs, k)
        Damped (complex) eigenvectors of the underdamped modes, normalised.
    real_shapes : ndarray, shape (n_dofs, N)
        Undamped (real) eigenvectors, normalised, modes 1..N.
    mode : ndarray of int, shape (k,)
        Mode number (1-based, undamped order) of each underdamped mode.
    overdamped_mode : ndarray of int, shape (m,)
        Mode numbers of the overdamped modes, ascending.
    overdamped_eigenvalues : ndarray, shape (m, 2)
        Their two real eigenvalues λ1 < λ2 < 0 (rad/s).
    overdamped_omega, overdamped_damping : ndarray, shape (m,)
        ω = √(λ1 λ2) (rad/s) and ζ = −(λ1 + λ2)/(2ω) ≥ 1.
    overdamped_shapes : ndarray, shape (n_dofs, m)
        Real eigenvector of each overdamped mode's slower eigenvalue λ2 (it
        dominates the free decay; in a classically damped system both
        eigenvalues share it), normalised.
    participation, overdamped_participation : ndarray, shape (k,) and (m,)
        How much of each mode's eigenvector is the undamped mode it is
        numbered after (`modal.pairing`): 1 when damping is classical, lower
        where damping mixes modes (then the numbering is the best assignment).
    """

    phase: str
    eigenvalues: np.ndarray
    vibration_eigenvalues: np.ndarray
    omega: np.ndarray
    damping: np.ndarray
    undamped_omega: np.ndarray
    shapes: np.ndarray
    real_shapes: np.ndarray
    mode: np.ndarray
    overdamped_mode: np.ndarray
    overdamped_eigenvalues: np.ndarray
    overdamped_omega: np.ndarray
    overdamped_damping: np.ndarray
    overdamped_shapes: np.ndarray
    participation: np.ndarray
    overdamped_participation: np.ndarray

    @property
    def freq_hz(self) -> np.ndarray:
        """Underdamped-mode frequencies ω / 2π (Hz), ascending."""
        return self.omega / _TWO_PI

    @property
    def overdamped_freq_hz(self) -> np.ndarray:
        """Overdamped-mode frequencies √(λ1 λ2) / 2π (Hz)."""
        return self.overdamped_omega / _TWO_PI

    def to_pandas(self) -> pd.DataFrame:
        """One row per mode 1..N: ``mode``, ``kind`` ("underdamped" or "overdamped"),
        ``freq_hz``, ``damping``, ``participation``, ``undamped_freq_hz``."""
        kind = ["underdamped"] * self.mode.size + ["overdamped"] * self.overdamped_mode.size
        df = pd.DataFrame(
            {
                "mode": np.concatenate([self.mode, self.overdamped_mode]),
                "kind": kind,
                "freq_hz": np.concatenate([self.freq_hz, self.overdamped_freq_hz]),
                "damping": np.concatenate([self.damping, self.overdamped_damping]),
                "participation": np.concatenate(
                    [self.participation, self.overdamped_participation]
                ),
            }
        )
        df = df.sort_values("mode", ignore_index=True)
        df["undamped_freq_hz"] = self.undamped_omega[df["mode"].to_numpy() - 1] / _TWO_PI
        return df


def default_shape_nodes(n: int) -> tuple[int, ...]:
    """Nodes used for shapes: 2..N as in paper 001 Fig 4, or (1,) when N = 1."""
    return tuple(range(2, n + 1)) if n >= 2 else (1,)


def _undamped(system: LinearSystem) -> tuple[np.ndarray, np.ndarray]:
    """Undamped eigenvalues ω² (ascending) and M-orthonormal modes; checks their signs."""
    w2, Phi = sla.eigh(system.K, system.M)
    n_neg = int(np.count_nonzero(w2 <= 0.0))
    if system.phase == "rocking" and n_neg != 1:
        raise ModalError(
            "the undamped rocking system should have exactly one unstable (rocking) "
            f"mode; found {n_neg} non-positive eigenvalues "
            f"({', '.join(f'{x:.6g}' for x in w2[w2 <= 0.0])} rad²/s²): check the "
            "column's stiffness against its weight"
        )
    if system.phase != "rocking" and n_neg:
        raise ModalError(
            f"the {system.phase} stiffness is not positive definite (eigenvalues "
            f"{', '.join(f'{x:.6g}' for x in w2[w2 <= 0.0])} rad²/s²)"
        )
    return w2, Phi


def phase_modes(system: LinearSystem, shape_idx: np.ndarray) -> tuple[PhaseModes, dict]:
    """Damped (Foss) and undamped modes of one linear system, paired into modes.

    Returns the modes and, for the rocking phase, a dict with the rocking
    couple's eigenvalues and the undamped rocking eigenvector (empty in full
    contact).
    """
    ss = foss(system)
    lam, V = ss.eigenvalues, ss.eigenvectors
    w2, Phi = _undamped(system)
    rocking_col = 0 if system.phase == "rocking" else None  # ω² < 0 sorts first
    pairing = pair_modes(lam, V, system.M, Phi, rocking_col, system.phase)
    shift = 1 if rocking_col is None else 0  # column of Φ -> mode number
    n_el = system.n - (rocking_col is not None)
    extra: dict = {}
    if rocking_col is not None:
        extra["rocking_eigenvalues"] = lam[pairing.rocking].real
        extra["rocking_shape_real"] = Phi[:, 0] / Phi[-1, 0]
    order = np.argsort(np.abs(lam[pairing.under]), kind="stable")
    under, under_mode = pairing.under[order], pairing.under_mode[order]
    omega, zeta = frequency_and_damping(lam[under])
    l1, l2 = lam[pairing.over[:, 0]].real, lam[pairing.over[:, 1]].real
    o_omega, o_zeta = pair_frequency_and_damping(l1, l2)
    vib = slice(1, None) if rocking_col is not None else slice(None)
    modes = PhaseModes(
        phase=system.phase,
        eigenvalues=lam,
        vibration_eigenvalues=lam[under],
        omega=omega,
        damping=zeta,
        undamped_omega=np.sqrt(w2[vib]),
        shapes=normalise(V[:, under], shape_idx, n_el),
        real_shapes=normalise(Phi[:, vib], shape_idx, n_el),
        mode=under_mode + shift,
        overdamped_mode=pairing.over_mode + shift,
        overdamped_eigenvalues=np.column_stack([l1, l2]),
        overdamped_omega=o_omega,
        overdamped_damping=o_zeta,
        overdamped_shapes=normalise(V[:, pairing.over[:, 1]], shape_idx, n_el).real,
        participation=pairing.under_weight[order],
        overdamped_participation=pairing.over_weight,
    )
    return modes, extra


def _aligned(rk: PhaseModes, fc: PhaseModes, idx: np.ndarray, heights: np.ndarray) -> PhaseModes:
    """The rocking-phase modes with the uplifted sign rule of `modal.shapes` applied."""
    v_n = fc.real_shapes[idx]
    N = v_n.shape[1]
    return dataclasses.replace(
        rk,
        shapes=align_to_full_contact(rk.shapes, rk.mode - 1, v_n, idx, heights),
        real_shapes=align_to_full_contact(rk.real_shapes, np.arange(N), v_n, idx, heights),
        overdamped_shapes=align_to_full_contact(
            rk.overdamped_shapes, rk.overdamped_mode - 1, v_n, idx, heights
        ),
    )


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
        """v_n at the shape nodes, shape (n_shape_nodes, N), modes 1..N.

        Undamped (real) shapes; with ``complex_=True`` the damped eigenvectors
        of the underdamped modes instead, one column per entry of
        ``full_contact.mode``. The same holds for the uplifted shapes below.
        """
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
        if phase not in ("rocking", "full_contact"):
            raise ModalError(f"`phase` = {phase!r}: use 'rocking' or 'full_contact'")
        model = self.compound_shapes() if phase == "rocking" else self.full_contact_shapes()
        return mac(measured, model)


def analyse(structure: Structure | str, shape_nodes=None) -> ModalAnalysis:
    """Modal analysis of full contact and rocking phases (paper 001, Section 3).

    Parameters
    ----------
    structure : Structure, str or path
        A column structure, or a specimen name/TOML path (built with
        `multimass.from_specimen`). A rigid block has no vibration modes and
        is refused.
    shape_nodes : sequence of int, optional
        Distinct 1-based nodes at which to report shapes (default:
        `default_shape_nodes`). Integers only: a string such as "2,3", a
        float or a bool is refused, not converted.

    Returns
    -------
    ModalAnalysis

    Raises
    ------
    ModalError
        If an argument is not as described (the message names it and the fix)
        or the structure's modes cannot be formed.
    """
    s = validate_structure(structure)
    nodes = validate_shape_nodes(shape_nodes, s.n, default_shape_nodes(s.n))
    idx = np.asarray(nodes) - 1
    fc, _ = phase_modes(full_contact(s), idx)
    rk, extra = phase_modes(rocking(s), idx)
    rk = _aligned(rk, fc, idx, s.H[idx])
    return ModalAnalysis(
        structure=s,
        shape_nodes=nodes,
        full_contact=fc,
        rocking=rk,
        rocking_eigenvalues=extra["rocking_eigenvalues"],
        rocking_shape=extra["rocking_shape_real"],
    )


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
