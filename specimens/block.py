"""Rigid prismatic block specimens (paper 004, Table 1; paper 002, Table 1)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

from ._fields import check_keys, number, table, text
from .column import G_DEFAULT
from .errors import SpecimenError

__all__ = ["BlockSpecimen", "BlockReference", "block_from_mapping"]


@dataclass(frozen=True)
class BlockReference:
    """Published values for a block (all optional, SI units unless named).

    Attributes
    ----------
    alpha, R, p, eta_H, eta_M : float or None
        Paper 004 Table 1: slenderness (rad), semi-diagonal (m), frequency
        parameter (rad/s), Housner's and the modified restitution.
    s : float or None
        Paper 002 Table 1: semi-diagonal (m).
    theta0_deg, first_peak_deg, experimental_first_peak_deg, rest_time_s : float or None
        Paper 002 Section 6.2 free rocking: initial angle, simulated and
        measured first post-impact peak (magnitudes, degrees), time to rest.
    """

    alpha: float | None = None
    R: float | None = None
    p: float | None = None
    eta_H: float | None = None
    eta_M: float | None = None
    s: float | None = None
    theta0_deg: float | None = None
    first_peak_deg: float | None = None
    experimental_first_peak_deg: float | None = None
    rest_time_s: float | None = None
    source: str = ""


@dataclass(frozen=True)
class BlockSpecimen:
    """A rigid prismatic block rocking on a rigid base (paper 004, Eqs 1–2).

    Attributes
    ----------
    name, description, source : str
    b, h, depth : float
        Width, height and depth (m); depth = b unless given.
    mass : float
        Mass (kg).
    k : float
        Block-specific restitution parameter of paper 004 Eq 10 (the position
        of the contact impulse, k = b̄ / (b/2)), in [0, 1].
    k_size_average : float or None
        Paper 004's average k for blocks of this width (0.8608 for b = 0.045 m,
        0.7306 for b = 0.06 m), used in its Table 1.
    g : float
        Gravitational acceleration (m/s²).
    reference : BlockReference
    """

    name: str
    b: float
    h: float
    depth: float
    mass: float
    k: float
    k_size_average: float | None = None
    g: float = G_DEFAULT
    description: str = ""
    source: str = ""
    reference: BlockReference = field(default_factory=BlockReference)

    kind = "block"

    @property
    def alpha(self) -> float:
        """Slenderness α = atan(b / h) (rad); DESIGN.md on paper 004's typo."""
        return math.atan2(self.b, self.h)

    @property
    def R(self) -> float:
        """Semi-diagonal R = ½ sqrt(b² + h²) (m)."""
        return 0.5 * math.hypot(self.b, self.h)

    @property
    def p(self) -> float:
        """Frequency parameter p = sqrt(3 g / (4 R)) (rad/s), paper 004 after Eq 6."""
        return math.sqrt(3.0 * self.g / (4.0 * self.R))


_TOP_REQUIRED = {"kind", "name", "geometry", "mass", "restitution"}
_TOP_OPTIONAL = {"description", "source", "gravity_m_per_s2", "reference"}
_REF_KEYS = {"alpha_rad": "alpha", "R_m": "R", "p_rad_per_s": "p", "eta_H": "eta_H",
             "eta_M": "eta_M", "s_m": "s", "theta0_deg": "theta0_deg",
             "first_peak_deg": "first_peak_deg",
             "experimental_first_peak_deg": "experimental_first_peak_deg",
             "rest_time_s": "rest_time_s"}


def block_from_mapping(data: Mapping, source: str) -> BlockSpecimen:
    """Validate a parsed block TOML mapping (``kind = "block"``) and build the specimen.

    Raises
    ------
    SpecimenError
        On a missing or unknown key or a value out of range.
    """
    check_keys(source, "", data, _TOP_REQUIRED, _TOP_OPTIONAL)
    geo = table(source, data, "geometry")
    check_keys(source, "geometry", geo, {"width_m", "height_m"}, {"depth_m"})
    mass = table(source, data, "mass")
    check_keys(source, "mass", mass, {"mass_kg"})
    rest = table(source, data, "restitution")
    check_keys(source, "restitution", rest, {"k"}, {"k_size_average"})

    def pos(tbl, key, where, what):
        return number(source, f"{where}.{key}", tbl[key], low=0.0, low_open=True, what=what)

    b = pos(geo, "width_m", "geometry", "the block width b in m")
    ref = data.get("reference", {})
    if not isinstance(ref, Mapping):
        raise SpecimenError(f"{source}: `reference` = {ref!r}: expected a table; write it as [reference]")
    check_keys(source, "reference", ref, set(), set(_REF_KEYS) | {"source"})
    k_avg = rest.get("k_size_average")
    return BlockSpecimen(
        name=text(source, "name", data["name"]),
        description=text(source, "description", data.get("description", "")),
        source=text(source, "source", data.get("source", "")),
        b=b,
        h=pos(geo, "height_m", "geometry", "the block height h in m"),
        depth=pos(geo, "depth_m", "geometry", "the depth in m (omit it for depth = b)") if "depth_m" in geo else b,
        mass=pos(mass, "mass_kg", "mass", "the block mass in kg"),
        k=number(source, "restitution.k", rest["k"], low=0.0, high=1.0,
                 what="k = b̄/(b/2) locates the contact impulse (paper 004, Eq 10)"),
        k_size_average=None if k_avg is None else number(
            source, "restitution.k_size_average", k_avg, low=0.0, high=1.0),
        g=number(source, "gravity_m_per_s2", data.get("gravity_m_per_s2", G_DEFAULT),
                 low=0.0, low_open=True, what="gravitational acceleration in m/s^2"),
        reference=BlockReference(
            source=text(source, "reference.source", ref.get("source", "")),
            **{attr: number(source, f"reference.{key}", ref[key])
               for key, attr in _REF_KEYS.items() if key in ref}),
    )
