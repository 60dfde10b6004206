"""The rocking structure: matrices and geometry built from a specimen.

Conventions (paper 001, Fig 1), stated once here and tested:

* ``u`` — small elastic lateral displacements of nodes 1..N, positive towards
  the right pivot, measured in the column's own frame.
* ``θ`` — rigid base rotation; θ > 0 rocks about the **right** pivot (the
  column leans towards +u), θ < 0 about the left pivot.
* The pivots lie at ±B from the centre line; node 0 (the base, mass m0,
  rotary inertia J0) is rigid and does not deform.
"""

from __future__ import annotations

import math
import numbers
import os
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from multimass.specimens import BlockSpecimen, ColumnSpecimen, SpecimenError, available
from multimass.specimens import load as load_specimen
from multimass.specimens.ranges import check as plausible

from ..errors import InputError
from .damping import rayleigh_damping
from .structure_checks import (
    check_damping,
    check_derived,
    check_fields,
    check_frequencies,
    full_contact,
)

__all__ = ["Structure", "column", "rigid_block", "from_specimen", "derived_once"]


@dataclass(frozen=True, eq=False)
class Structure:
    """A multi-mass rocking structure (paper 001, Section 2.1).

    Build it with `column` (from a specimen) rather than directly.

    Attributes
    ----------
    name : str
    H : ndarray, shape (N,)
        Heights of elastic nodes 1..N (m).
    m : ndarray, shape (N,)
        Their lumped masses, diag(M) (kg).
    m0, J0 : float
        Base mass (kg) and rotary inertia (kg m²), node 0.
    h0 : float
        Height of node 0's mass above the pivots (0 in paper 001).
    B : float
        Half the distance between the pivots (m).
    g : float
        Gravitational acceleration (m/s²).
    K : ndarray, shape (N, N)
        Condensed full-contact stiffness (paper 001, Eq 2).
    C : ndarray, shape (N, N)
        Rayleigh damping matrix.
    rayleigh : tuple of float
        (a0, a1) with C = a0 M + a1 K.
    K_s : ndarray, shape (2N, 2N)
        Uncondensed stiffness over [u; Ω] (paper 001, Eq 1).
    specimen : object or None
        The specimen it was built from (restitution data, reference values).
    """

    name: str
    H: np.ndarray
    m: np.ndarray
    m0: float
    J0: float
    B: float
    g: float
    K: np.ndarray
    C: np.ndarray
    rayleigh: tuple[float, float] = (0.0, 0.0)
    K_s: np.ndarray | None = None
    h0: float = 0.0
    specimen: object | None = field(default=None, repr=False)

    @property
    def n(self) -> int:
        """N, the number of elastic nodes."""
        return self.H.size

    @cached_property
    def M(self) -> np.ndarray:
        """Diagonal mass matrix of nodes 1..N."""
        return np.diag(self.m)

    @cached_property
    def m_t(self) -> float:
        """Total mass m_t = m0 + Σ m_i (kg)."""
        return float(self.m0 + self.m.sum())

    @cached_property
    def static_moment(self) -> float:
        """First moment of mass about the base, 1ᵀ M H + m0 h0 (kg m)."""
        return float(self.m @ self.H + self.m0 * self.h0)

    @cached_property
    def R0(self) -> np.ndarray:
        """Radial distances from a pivot to nodes 1..N at rest (m)."""
        return np.hypot(self.H, self.B)

    @cached_property
    def J_p(self) -> float:
        """Mass moment of inertia about a pivot (paper 001, after Eq 5).

        J_p = R0ᵀ M R0 + m0 (B² + h0²) + J0.
        """
        return float(self.m @ self.R0**2 + self.m0 * (self.B**2 + self.h0**2) + self.J0)

    @cached_property
    def H_cg(self) -> float:
        """Height of the centre of gravity (m)."""
        return self.static_moment / self.m_t

    @cached_property
    def alpha_cg(self) -> float:
        """Slenderness with respect to the centre of gravity, atan(B / H_cg) (rad)."""
        return float(np.arctan2(self.B, self.H_cg))

    @cached_property
    def p_l(self) -> float:
        """Modified frequency parameter p_l = sqrt(1ᵀ M H g / J_p) (paper 001, Eq 6)."""
        return float(np.sqrt(self.static_moment * self.g / self.J_p))  # paper 001, Eq 6

    @cached_property
    def R_cg(self) -> float:
        """Distance from a pivot to the centre of gravity at rest (m)."""
        return float(np.hypot(self.B, self.H_cg))

    @cached_property
    def p(self) -> float:
        """Frequency parameter sqrt(m_t g R_cg / J_p) (rad/s).

        For a uniform rigid block this is Housner's p = sqrt(3 g / (4 R))
        (paper 004, after Eq 6); compare `p_l`, its linearised counterpart.
        """
        return float(np.sqrt(self.m_t * self.g * self.R_cg / self.J_p))

    @property
    def is_rigid(self) -> bool:
        """True for a rigid body (no elastic nodes)."""
        return self.n == 0

    @cached_property
    def full_contact_omega(self) -> np.ndarray:
        """Undamped full-contact circular frequencies (rad/s), ascending."""
        if self.n == 0:
            return np.empty(0)
        import scipy.linalg as sla  # here: a rigid block's runs need no SciPy

        return np.sqrt(sla.eigh(self.K, self.M, eigvals_only=True))

    def derived(self) -> dict[str, float]:
        """The derived parameters of Table 1 (paper 001) as a dict, SI units."""
        return {
            "m_t": self.m_t,
            "J_p": self.J_p,
            "H_cg": self.H_cg,
            "alpha_cg": self.alpha_cg,
            "p_l": self.p_l,
        }


def _cut(value, limit: int = 80) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _kind_hint(cls) -> str:
    """'column (kind = "column"; S1, S2, S3)': the kind and its bundled specimens."""
    names = [n for n in available() if isinstance(load_specimen(n), cls)]
    return f'{cls.kind} (kind = "{cls.kind}"; {", ".join(names)})'


def _specimen(specimen, cls, builder: str):
    """(specimen object of type `cls`, where) from an object, a bundled name or a path."""
    if isinstance(specimen, cls):
        return specimen, f"specimen {specimen.name!r}"
    if isinstance(specimen, (str, os.PathLike)) and not isinstance(specimen, bytes):
        spec = load_specimen(specimen)
        where = str(specimen)
    elif hasattr(specimen, "kind") and hasattr(specimen, "name"):
        spec, where = specimen, f"specimen {getattr(specimen, 'name', '?')!r}"
    else:
        raise InputError(
            f"`specimen` = {_cut(specimen)}: give a bundled name, the path of a "
            f"specimen TOML file or a loaded specimen (specimens.load); `{builder}` "
            f"needs a {_kind_hint(cls)}"
        )
    if not isinstance(spec, cls):
        raise InputError(
            f"`specimen` = {_cut(getattr(spec, 'name', spec))} is a "
            f"{getattr(spec, 'kind', type(spec).__name__)!r} specimen; `{builder}` "
            f"needs a {_kind_hint(cls)}"
        )
    return spec, where


def column(specimen: ColumnSpecimen | str, *, E_s: float | None = None) -> Structure:
    """Build the multi-mass structure of a column specimen.

    Parameters
    ----------
    specimen : ColumnSpecimen, str or path
        A loaded specimen, a bundled name (``"S1"``) or a TOML path.
    E_s : float, optional
        Override of the specimen's Young's modulus (Pa), e.g. for sensitivity
        studies (DESIGN.md: 210 GPa brings S1's full-contact pair within 0.2 %).

    Returns
    -------
    Structure
        With condensed K (paper 001, Eq 2) and Rayleigh C fitted to ζ_n1, ζ_n2
        at the first two full-contact modes.

    Raises
    ------
    InputError
        If `specimen` is not a column specimen, a name or a path, or `E_s` is
        not a plausible Young's modulus.
    SpecimenError
        If the file is invalid, or the assembled model is not usable: K not
        finite and positive definite; a first frequency whose 1-g static drift
        g/ω1² exceeds `MAX_DRIFT_1G` x the height; a highest frequency above
        `MAX_FREQ_HZ`; Rayleigh damping < 0 at some mode. The message names
        the input to fix.
    """
    spec, where = _specimen(specimen, ColumnSpecimen, "column")
    if E_s is None:
        try:
            hash(spec)
        except TypeError:  # a specimen built by hand with a list in it: built each call
            return _column(spec, where, None)
        return _column_once(spec, where)
    return _column(spec, where, E_s)


#: Structures of specimens as given (no E_s), built once per process: 1 ms of a 12 ms
#: compiled run of S1. Specimens are frozen and hashable; the arrays of a structure every
#: caller shares are read-only.
_BUILT: dict[ColumnSpecimen, Structure] = {}
_BUILT_MAX = 32


def derived_once(st: Structure, name: str, build):
    """``build(st)``, kept on `st` if it is a shared structure (its arrays read-only, as
    `column` returns for a specimen as given), else computed each call (a structure built
    by hand may have its arrays changed in place)."""
    if st.K.flags.writeable:
        return build(st)
    kept = st.__dict__.setdefault("_derived", {})
    if name not in kept:
        kept[name] = build(st)
    return kept[name]


def _column_once(spec: ColumnSpecimen, where: str) -> Structure:
    """`column` of `spec` from `_BUILT`, built there (with `where` for its messages) if new."""
    st = _BUILT.get(spec)
    if st is None:
        st = _column(spec, where, None)
        for name in ("H", "m", "K", "C", "K_s"):
            getattr(st, name).setflags(write=False)
        if len(_BUILT) >= _BUILT_MAX:
            _BUILT.pop(next(iter(_BUILT)))
        _BUILT[spec] = st
    return st


def _column(spec: ColumnSpecimen, where: str, E_s: float | None) -> Structure:
    """The structure of column specimen `spec`, with E_s overriding its modulus if given."""
    check_fields(spec, where)
    E = spec.E_s
    if E_s is not None:
        try:
            E = plausible(where, "E_s", E_s, "youngs_modulus")
        except SpecimenError as err:
            raise InputError(str(err)) from None
    Ks, K, omega = full_contact(spec, E, where)
    check_frequencies(spec, E, omega, where)
    m = np.asarray(spec.masses, dtype=float)
    C, coeffs = rayleigh_damping(np.diag(m), K, spec.zeta_1, spec.zeta_2)
    check_damping(spec, omega, coeffs, C, where)
    return check_derived(
        Structure(
            name=spec.name,
            H=np.asarray(spec.heights, dtype=float),
            m=m,
            m0=spec.m0,
            J0=spec.J0,
            B=spec.B,
            g=spec.g,
            K=K,
            C=C,
            rayleigh=coeffs,
            K_s=Ks,
            specimen=spec,
        ),
        where,
    )


def rigid_block(specimen: BlockSpecimen | str) -> Structure:
    """Build a rigid block as a structure with no elastic nodes.

    The block's mass sits in node 0 at its centre of gravity: m0 = m,
    h0 = h/2, J0 = m (b² + h²)/12 (about the centre of gravity), B = b/2.
    Then J_p = (4/3) m R² and the rocking equation reduces to Housner's
    (paper 004, Eqs 1–2).

    Raises
    ------
    InputError
        If `specimen` is not a block specimen, a name or a path.
    SpecimenError
        If the file is invalid or the block's values are not finite and positive.
    """
    spec, where = _specimen(specimen, BlockSpecimen, "rigid_block")
    for name in ("b", "h", "mass", "g"):
        x = getattr(spec, name)
        if isinstance(x, bool) or not isinstance(x, numbers.Real) or not 0 < x < math.inf:
            raise SpecimenError(f"{where}: `{name}` = {_cut(x)}: must be a finite number > 0")
    empty = np.zeros((0, 0))
    return check_derived(
        Structure(
            name=spec.name,
            H=np.zeros(0),
            m=np.zeros(0),
            m0=spec.mass,
            J0=spec.mass * (spec.b**2 + spec.h**2) / 12.0,
            B=0.5 * spec.b,
            g=spec.g,
            K=empty,
            C=empty,
            h0=0.5 * spec.h,
            specimen=spec,
        ),
        where,
    )


def from_specimen(specimen) -> Structure:
    """Build the structure of any specimen: a column or a rigid block.

    Parameters
    ----------
    specimen : specimen object, bundled name or TOML path

    Raises
    ------
    InputError
        If `specimen` is none of these, or a beam (a base for `nscd`, not a structure).
    SpecimenError
        As `column` and `rigid_block`.
    """
    if isinstance(specimen, (str, os.PathLike)) and not isinstance(specimen, bytes):
        spec = load_specimen(specimen)
    else:
        spec = specimen
    if isinstance(spec, ColumnSpecimen):
        return column(spec)
    if isinstance(spec, BlockSpecimen):
        return rigid_block(spec)
    if getattr(spec, "kind", None) == "beam":
        raise InputError(
            f"`specimen` = {spec.name!r} is a beam: a flexible base for a block "
            "(nscd.simulate(block, beam=...), `multimass nscd BLOCK --beam ...`), "
            "not a rocking structure; give a column or a block"
        )
    raise InputError(
        f"`specimen` = {_cut(specimen)}: give a column or block specimen, a "
        f"bundled name ({', '.join(available())}) or the path of a specimen TOML file"
    )
