"""Beam bases for blocks rocking on a flexible floor (paper 002, Section 6)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from ._fields import check_keys, number, table, text
from .column import G_DEFAULT
from .errors import SpecimenError

__all__ = ["BeamSpecimen", "beam_from_mapping"]


@dataclass(frozen=True)
class BeamSpecimen:
    """A simply supported Euler–Bernoulli beam with a rectangular section.

    The beam carries a rocking block (paper 002, Figs 1–2): a pin at x = 0
    and a roller at x = `span`; axial and bending deformation; Rayleigh
    damping fitted to two of its modes. SI units throughout.

    Attributes
    ----------
    name, description, source : str
    span : float
        Span L between the supports (m).
    section_width, section_height : float
        Width and height of the rectangular section (m).
    E : float
        Young's modulus (Pa); a very large value (1e24) makes a rigid base.
    nu : float
        Poisson's ratio (kept for completeness; Euler–Bernoulli elements do
        not use it).
    rho : float
        Density (kg/m³).
    mu : float
        Coulomb friction coefficient between block and beam.
    damping_ratios : tuple of float
        Fractions of critical damping (ζ_a, ζ_b) of the two fitted modes.
    damping_modes : tuple of int
        The 1-based numbers of those modes, in increasing frequency.
    n_elements : int
        Default number of finite elements along the span.
    g : float
        Gravitational acceleration (m/s²).
    """

    name: str
    span: float
    section_width: float
    section_height: float
    E: float
    nu: float
    rho: float
    mu: float
    damping_ratios: tuple[float, float]
    damping_modes: tuple[int, int]
    n_elements: int
    g: float = G_DEFAULT
    description: str = ""
    source: str = ""

    kind = "beam"

    @property
    def area(self) -> float:
        """Cross-section area A = width × height (m²)."""
        return self.section_width * self.section_height

    @property
    def second_moment(self) -> float:
        """Second moment of area I = width × height³ / 12 (m⁴)."""
        return self.section_width * self.section_height**3 / 12.0

    @property
    def mass_per_length(self) -> float:
        """Mass per unit length m = ρ A (kg/m)."""
        return self.rho * self.area


_TOP_REQUIRED = {"kind", "name", "geometry", "material", "contact", "damping", "mesh"}
_TOP_OPTIONAL = {"description", "source", "gravity_m_per_s2"}


def _mode_numbers(source: str, value) -> tuple[int, int]:
    field = "damping.modes"
    ok = (isinstance(value, list) and len(value) == 2
          and all(isinstance(v, int) and not isinstance(v, bool) and v >= 1 for v in value))
    if not ok or value[0] >= value[1]:
        raise SpecimenError(
            f"{source}: `{field}` = {value!r}: give two increasing 1-based mode numbers, "
            "e.g. [1, 3] (paper 002, Section 6)")
    return int(value[0]), int(value[1])


def _n_elements(source: str, value) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 3:
        raise SpecimenError(
            f"{source}: `mesh.n_elements` = {value!r}: give an integer >= 3 "
            "(paper 002 uses 3, 6 and 12)")
    return int(value)


def beam_from_mapping(data: Mapping, source: str) -> BeamSpecimen:
    """Validate a parsed beam TOML mapping (``kind = "beam"``) and build the specimen.

    Raises
    ------
    SpecimenError
        On a missing or unknown key or a value out of range.
    """
    check_keys(source, "", data, _TOP_REQUIRED, _TOP_OPTIONAL)
    geo = table(source, data, "geometry")
    check_keys(source, "geometry", geo, {"span_m", "section_width_m", "section_height_m"})
    mat = table(source, data, "material")
    check_keys(source, "material", mat,
               {"youngs_modulus_Pa", "poisson_ratio", "density_kg_per_m3"})
    con = table(source, data, "contact")
    check_keys(source, "contact", con, {"friction_coefficient"})
    damp = table(source, data, "damping")
    check_keys(source, "damping", damp, {"ratios", "modes"})
    mesh = table(source, data, "mesh")
    check_keys(source, "mesh", mesh, {"n_elements"})

    def pos(tbl, key, where, what):
        return number(source, f"{where}.{key}", tbl[key], low=0.0, low_open=True, what=what)

    ratios = damp["ratios"]
    if not isinstance(ratios, list) or len(ratios) != 2:
        raise SpecimenError(f"{source}: `damping.ratios` = {ratios!r}: give two fractions of "
                            "critical damping, e.g. [0.05, 0.2]")
    zetas = tuple(number(source, f"damping.ratios[{i}]", z, low=0.0, high=1.0, high_open=True,
                         what="fractions of critical damping, e.g. 0.05 for 5 %")
                  for i, z in enumerate(ratios))
    return BeamSpecimen(
        name=text(source, "name", data["name"]),
        description=text(source, "description", data.get("description", "")),
        source=text(source, "source", data.get("source", "")),
        span=pos(geo, "span_m", "geometry", "the distance between the supports in m"),
        section_width=pos(geo, "section_width_m", "geometry", "the section width in m"),
        section_height=pos(geo, "section_height_m", "geometry", "the section height in m"),
        E=pos(mat, "youngs_modulus_Pa", "material", "Young's modulus in Pa (1e24 for a rigid base)"),
        nu=number(source, "material.poisson_ratio", mat["poisson_ratio"], low=-1.0, high=0.5,
                  low_open=True, high_open=True, what="Poisson's ratio"),
        rho=pos(mat, "density_kg_per_m3", "material", "the density in kg/m^3"),
        mu=number(source, "contact.friction_coefficient", con["friction_coefficient"], low=0.0,
                  what="the Coulomb friction coefficient between block and beam"),
        damping_ratios=zetas,
        damping_modes=_mode_numbers(source, damp["modes"]),
        n_elements=_n_elements(source, mesh["n_elements"]),
        g=number(source, "gravity_m_per_s2", data.get("gravity_m_per_s2", G_DEFAULT),
                 low=0.0, low_open=True, what="gravitational acceleration in m/s^2"),
    )
