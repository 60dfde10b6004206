"""Beam bases for blocks rocking on a flexible floor (paper 002, Section 6)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from ._fields import check_keys, number, show, table, text
from .column import G_DEFAULT
from .errors import SpecimenError
from .ranges import BEAM_RIGID_E, check

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
        Young's modulus (Pa), in [1e6, 1e24]: paper 002's convention E = 1e24 Pa
        (Section 6.1) makes a rigid base; above diamond's 1.05e12 Pa a value is
        that convention, not a material.
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


def _mode_numbers(source: str, value, n_elements: int) -> tuple[int, int]:
    """Two increasing 1-based mode numbers within the mesh's 3 n_elements modes.

    A simply supported mesh of n frame elements has 3 (n + 1) degrees of freedom
    (axial, transverse, rotation per node) less 3 fixed at the supports.
    """
    field = "damping.modes"
    n_modes = 3 * n_elements
    ok = (
        isinstance(value, (list, tuple))
        and len(value) == 2
        and all(isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= n_modes for v in value)
    )
    if not ok or value[0] >= value[1]:
        raise SpecimenError(
            f"{source}: `{field}` = {show(value)}: give two increasing 1-based mode numbers "
            f"within the {n_modes} modes of the {n_elements}-element mesh, e.g. [1, 3] "
            "(paper 002, Section 6)"
        )
    return int(value[0]), int(value[1])


#: Most beam elements. Paper 002 converges by 12; the beam's highest mode, which the
#: Moreau–Jean step must follow, grows as n², and its dense A⁻¹ as n²: 1000 elements
#: are ~7000 x paper 002's 12-element highest frequency and a 3000 x 3000 matrix.
MAX_ELEMENTS = 1000


def _n_elements(source: str, value) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or not 3 <= value <= MAX_ELEMENTS:
        raise SpecimenError(
            f"{source}: `mesh.n_elements` = {show(value)}: give an integer in 3..{MAX_ELEMENTS} "
            "(paper 002 uses 3, 6 and 12)"
        )
    return int(value)


def beam_from_mapping(data: Mapping, source: str) -> BeamSpecimen:
    """Validate a parsed beam TOML mapping (``kind = "beam"``) and build the specimen.

    Values must be physically plausible (`specimens.ranges`). Young's modulus may
    lie anywhere from soft rubber (1e6 Pa) up to paper 002's rigid-base convention
    E = 1e24 Pa (Section 6.1; `specimens.ranges.BEAM_RIGID_E`): above diamond's
    1.05e12 Pa a beam is that convention, a numerically rigid floor.

    Raises
    ------
    SpecimenError
        On a missing or unknown key or a value out of range or implausible.
    """
    check_keys(source, "", data, _TOP_REQUIRED, _TOP_OPTIONAL)
    geo = table(source, data, "geometry")
    check_keys(source, "geometry", geo, {"span_m", "section_width_m", "section_height_m"})
    mat = table(source, data, "material")
    check_keys(source, "material", mat, {"youngs_modulus_Pa", "poisson_ratio", "density_kg_per_m3"})
    con = table(source, data, "contact")
    check_keys(source, "contact", con, {"friction_coefficient"})
    damp = table(source, data, "damping")
    check_keys(source, "damping", damp, {"ratios", "modes"})
    mesh = table(source, data, "mesh")
    check_keys(source, "mesh", mesh, {"n_elements"})

    n_elements = _n_elements(source, mesh["n_elements"])
    ratios = damp["ratios"]
    if not isinstance(ratios, (list, tuple)) or len(ratios) != 2:
        raise SpecimenError(
            f"{source}: `damping.ratios` = {show(ratios)}: give two fractions of "
            "critical damping, e.g. [0.05, 0.2]"
        )
    zetas = tuple(
        number(
            source,
            f"damping.ratios[{i}]",
            z,
            low=0.0,
            high=1.0,
            high_open=True,
            what="fractions of critical damping, e.g. 0.05 for 5 %",
        )
        for i, z in enumerate(ratios)
    )
    return BeamSpecimen(
        name=text(source, "name", data["name"], required=True),
        description=text(source, "description", data.get("description", "")),
        source=text(source, "source", data.get("source", "")),
        **_geometry(source, geo),
        E=check(
            source,
            "material.youngs_modulus_Pa",
            mat["youngs_modulus_Pa"],
            "youngs_modulus",
            high=BEAM_RIGID_E,
            why="from soft rubber (~1e6 Pa) up to paper 002's rigid-base "
            "convention 1e24 Pa (Section 6.1)",
        ),
        nu=number(
            source,
            "material.poisson_ratio",
            mat["poisson_ratio"],
            low=-1.0,
            high=0.5,
            low_open=True,
            high_open=True,
            what="Poisson's ratio",
        ),
        rho=check(source, "material.density_kg_per_m3", mat["density_kg_per_m3"], "density"),
        mu=check(source, "contact.friction_coefficient", con["friction_coefficient"], "friction"),
        damping_ratios=zetas,
        damping_modes=_mode_numbers(source, damp["modes"], n_elements),
        n_elements=n_elements,
        g=check(source, "gravity_m_per_s2", data.get("gravity_m_per_s2", G_DEFAULT), "gravity"),
    )


def _geometry(source: str, geo: Mapping) -> dict:
    """Span and section; the section is shallower than the span (a beam, not a block)."""
    span = check(source, "geometry.span_m", geo["span_m"], "length")
    width = check(source, "geometry.section_width_m", geo["section_width_m"], "section")
    height = check(source, "geometry.section_height_m", geo["section_height_m"], "section")
    if height >= span:
        raise SpecimenError(
            f"{source}: `geometry.section_height_m` = {height!r} m is not less than the span "
            f"`geometry.span_m` = {span!r} m: an Euler–Bernoulli beam is shallow against its "
            "span; check the units (both in m)"
        )
    return {"span": span, "section_width": width, "section_height": height}
