"""Rigid prismatic block specimens (paper 004, Table 1; paper 002, Table 1)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

from ._fields import check_keys, number, show, table, text
from .column import G_DEFAULT
from .errors import SpecimenError
from .ranges import RANGES, check, fmt

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
#: The plausible range (`specimens.ranges`) of each reference value.
_REF_QUANTITY = {
    "alpha_rad": "angle_rad",
    "R_m": "length",
    "p_rad_per_s": "frequency_parameter",
    "eta_H": "restitution",
    "eta_M": "restitution",
    "s_m": "length",
    "theta0_deg": "angle_deg",
    "first_peak_deg": "angle_deg",
    "experimental_first_peak_deg": "angle_deg",
    "rest_time_s": "time_s",
}
_REF_KEYS = {
    "alpha_rad": "alpha",
    "R_m": "R",
    "p_rad_per_s": "p",
    "eta_H": "eta_H",
    "eta_M": "eta_M",
    "s_m": "s",
    "theta0_deg": "theta0_deg",
    "first_peak_deg": "first_peak_deg",
    "experimental_first_peak_deg": "experimental_first_peak_deg",
    "rest_time_s": "rest_time_s",
}


def block_from_mapping(data: Mapping, source: str) -> BlockSpecimen:
    """Validate a parsed block TOML mapping (``kind = "block"``) and build the specimen.

    Lengths, mass, gravity and the block's mean density mass / (b h depth) must be
    physically plausible (`specimens.ranges`): a dimension in mm or a mass in g
    is refused with the likely fix.

    Raises
    ------
    SpecimenError
        On a missing or unknown key or a value out of range or implausible.
    """
    check_keys(source, "", data, _TOP_REQUIRED, _TOP_OPTIONAL)
    geo = table(source, data, "geometry")
    check_keys(source, "geometry", geo, {"width_m", "height_m"}, {"depth_m"})
    mass = table(source, data, "mass")
    check_keys(source, "mass", mass, {"mass_kg"})
    rest = table(source, data, "restitution")
    check_keys(source, "restitution", rest, {"k"}, {"k_size_average"})
    ref = data.get("reference", {})
    if not isinstance(ref, Mapping):
        raise SpecimenError(
            f"{source}: `reference` = {show(ref)}: expected a table; write it as [reference]"
        )
    check_keys(source, "reference", ref, set(), set(_REF_KEYS) | {"source"})

    b = check(source, "geometry.width_m", geo["width_m"], "length")
    h = check(source, "geometry.height_m", geo["height_m"], "length")
    depth = check(source, "geometry.depth_m", geo["depth_m"], "length") if "depth_m" in geo else b
    m = check(source, "mass.mass_kg", mass["mass_kg"], "mass")
    _check_density(source, m, b, h, depth, "depth_m" in geo)
    k_avg = rest.get("k_size_average")
    return BlockSpecimen(
        name=text(source, "name", data["name"], required=True),
        description=text(source, "description", data.get("description", "")),
        source=text(source, "source", data.get("source", "")),
        b=b,
        h=h,
        depth=depth,
        mass=m,
        k=number(
            source,
            "restitution.k",
            rest["k"],
            low=0.0,
            high=1.0,
            what="k = b̄/(b/2) locates the contact impulse (paper 004, Eq 10)",
        ),
        k_size_average=None
        if k_avg is None
        else number(source, "restitution.k_size_average", k_avg, low=0.0, high=1.0),
        g=check(source, "gravity_m_per_s2", data.get("gravity_m_per_s2", G_DEFAULT), "gravity"),
        reference=BlockReference(
            source=text(source, "reference.source", ref.get("source", "")),
            **{
                attr: check(
                    source,
                    f"reference.{key}",
                    ref[key],
                    _REF_QUANTITY[key],
                    low_open=_REF_QUANTITY[key] != "angle_deg",
                )
                for key, attr in _REF_KEYS.items()
                if key in ref
            },
        ),
    )


def _check_density(
    source: str, mass: float, b: float, h: float, depth: float, depth_given: bool
) -> None:
    """The block's mean density mass / (b h depth) must be that of a real material."""
    rng = RANGES["density"]
    rho = mass / (b * h * depth)
    if rng.low <= rho <= rng.high:
        return
    fix = (
        "check `mass.mass_kg` (kg, not g) and the dimensions (m, not mm)"
        if depth_given
        else "give `geometry.depth_m`, the out-of-plane length (it defaults to the width b), or "
        "check `mass.mass_kg` (kg, not g) and the dimensions (m, not mm)"
    )
    raise SpecimenError(
        f"{source}: `mass.mass_kg` = {mass!r}: implausible mean density mass / (b h depth) = "
        f"{rho:.4g} kg/m^3 (b = {b:g} m, h = {h:g} m, depth = {depth:g} m); real blocks lie in "
        f"[{fmt(rng.low)}, {fmt(rng.high)}] kg/m^3 ({rng.why}); {fix}"
    )
