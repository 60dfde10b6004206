"""Multi-mass rocking column specimens (paper 001, Section 2.1 and Table 1)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from ._fields import check_keys, number, number_list, table, text
from .errors import SpecimenError

__all__ = ["ColumnSpecimen", "ColumnReference", "column_from_mapping"]

#: Standard gravity used when a file gives none (DESIGN.md, conventions).
G_DEFAULT = 9.81


@dataclass(frozen=True)
class ColumnReference:
    """Published values for a column, kept beside the inputs for comparison.

    All optional; SI units (kg m², m, rad, rad/s, Hz).
    """

    J_p: float | None = None
    H_cg: float | None = None
    alpha_cg: float | None = None
    p_l: float | None = None
    full_contact_freq_hz: tuple[float, ...] = ()
    rocking_freq_hz: tuple[float, ...] = ()
    source: str = ""


@dataclass(frozen=True)
class ColumnSpecimen:
    """A multi-mass flexible rocking column (paper 001, Fig 1 and Table 1).

    Nodes 1..N sit at `heights` above the base; node 0 (the base, mass `m0`,
    rotary inertia `J0`) is rigid. Node 1 is tied to node 0 by a horizontal
    spring `K_fp` and a rotational spring `K_rot`; nodes 1..N are joined by
    Euler–Bernoulli beams of bending stiffness `E_s * I_s`. The pivots are
    at ±`B` from the centre line. SI units throughout.

    Attributes
    ----------
    name, description, source : str
    heights : tuple of float
        H, heights of nodes 1..N (m), strictly increasing, > 0.
    masses : tuple of float
        diag(M), lumped masses of nodes 1..N (kg).
    m0, J0 : float
        Base mass (kg) and base rotary inertia (kg m²).
    B : float
        Half the distance between the pivots (m).
    E_s, I_s : float
        Young's modulus (Pa) and second moment of area (m⁴) of the column.
    K_rot, K_fp : float
        Rotational (N m/rad) and horizontal (N/m) springs between nodes 0 and 1.
    zeta_1, zeta_2 : float
        Fractions of critical damping of full-contact modes 1 and 2 (Rayleigh).
    r_right, r_left : float
        Mean coefficients of restitution of impacts on the right and on the
        left corner (paper 001's r̄_er, r̄_el).
    sigma_r : float
        Standard deviation of the coefficient of restitution.
    r_empirical : tuple of float
        Impact-specific coefficients r_e, in impact order (may be empty).
    g : float
        Gravitational acceleration (m/s²).
    reference : ColumnReference
        Published values.
    sensors : tuple of (str, int)
        Named instruments and the 1-based node each sits at (e.g. ("A2", 3)).
    """

    name: str
    heights: tuple[float, ...]
    masses: tuple[float, ...]
    m0: float
    J0: float
    B: float
    E_s: float
    I_s: float
    K_rot: float
    K_fp: float
    zeta_1: float
    zeta_2: float
    r_right: float
    r_left: float
    sigma_r: float
    r_empirical: tuple[float, ...] = ()
    g: float = G_DEFAULT
    description: str = ""
    source: str = ""
    reference: ColumnReference = field(default_factory=ColumnReference)
    sensors: tuple[tuple[str, int], ...] = ()

    kind = "column"

    def sensor_node(self, name: str) -> int:
        """1-based node of the named sensor (e.g. "A2")."""
        for key, node in self.sensors:
            if key.lower() == name.lower():
                return node
        raise SpecimenError(f"specimen {self.name!r} has no sensor {name!r}; known sensors: "
                            + (", ".join(k for k, _ in self.sensors) or "none (add a [sensors] table)"))

    @property
    def n_nodes(self) -> int:
        """N, the number of elastic nodes."""
        return len(self.heights)


_TOP_REQUIRED = {"kind", "name", "geometry", "mass", "stiffness", "damping", "restitution"}
_TOP_OPTIONAL = {"description", "source", "gravity_m_per_s2", "reference", "sensors"}


def column_from_mapping(data: Mapping, source: str) -> ColumnSpecimen:
    """Validate a parsed column TOML mapping and build the specimen.

    Parameters
    ----------
    data : mapping
        The parsed TOML document (``kind = "column"``).
    source : str
        Where it came from, used in error messages.

    Raises
    ------
    SpecimenError
        On a missing or unknown key, a value of the wrong type or out of range,
        or inconsistent lengths or ordering.
    """
    check_keys(source, "", data, _TOP_REQUIRED, _TOP_OPTIONAL)
    geo = table(source, data, "geometry")
    check_keys(source, "geometry", geo, {"heights_m", "half_width_m"})
    mass = table(source, data, "mass")
    check_keys(source, "mass", mass, {"nodal_kg", "base_kg", "base_inertia_kgm2"})
    stiff = table(source, data, "stiffness")
    check_keys(source, "stiffness", stiff, {
        "youngs_modulus_Pa", "second_moment_m4",
        "rotational_spring_Nm_per_rad", "horizontal_spring_N_per_m"})
    damp = table(source, data, "damping")
    check_keys(source, "damping", damp, {"zeta_1", "zeta_2"})
    rest = table(source, data, "restitution")
    check_keys(source, "restitution", rest, {"mean_right", "mean_left", "sigma"}, {"empirical"})

    heights = number_list(source, "geometry.heights_m", geo["heights_m"], positive=True,
                          what="node heights are measured upwards from the base (node 0)")
    for i in range(1, len(heights)):
        if heights[i] <= heights[i - 1]:
            raise SpecimenError(
                f"{source}: `geometry.heights_m[{i}]` = {heights[i]!r}: heights must increase "
                f"strictly from node 1 to node N (previous is {heights[i - 1]!r}); list nodes bottom to top")
    masses = number_list(source, "mass.nodal_kg", mass["nodal_kg"], positive=True,
                         what="give each node's lumped mass in kg")
    if len(masses) != len(heights):
        raise SpecimenError(
            f"{source}: `mass.nodal_kg` has {len(masses)} entries but `geometry.heights_m` has "
            f"{len(heights)}; give one mass per node height")

    def positive(tbl, key, where, what):
        return number(source, f"{where}.{key}", tbl[key], low=0.0, low_open=True, what=what)

    def unit_interval(key, what):
        return number(source, f"restitution.{key}", rest[key], low=0.0, high=1.0,
                      low_open=True, what=what)

    empirical = ()
    if "empirical" in rest and rest["empirical"] != []:
        empirical = number_list(source, "restitution.empirical", rest["empirical"])
        for i, r in enumerate(empirical):
            if not 0.0 < r <= 1.0:
                raise SpecimenError(
                    f"{source}: `restitution.empirical[{i}]` = {r!r}: a coefficient of "
                    "restitution must lie in (0, 1]")

    zeta_1 = number(source, "damping.zeta_1", damp["zeta_1"], low=0.0, high=1.0,
                    high_open=True, what="a fraction of critical damping, e.g. 0.005 for 0.5 %")
    zeta_2 = number(source, "damping.zeta_2", damp["zeta_2"], low=0.0, high=1.0,
                    high_open=True, what="a fraction of critical damping, e.g. 0.015 for 1.5 %")

    return ColumnSpecimen(
        name=text(source, "name", data["name"]),
        description=text(source, "description", data.get("description", "")),
        source=text(source, "source", data.get("source", "")),
        heights=heights,
        masses=masses,
        m0=number(source, "mass.base_kg", mass["base_kg"], low=0.0,
                  what="the base mass m0 may be 0 but not negative"),
        J0=number(source, "mass.base_inertia_kgm2", mass["base_inertia_kgm2"], low=0.0,
                  what="the base rotary inertia J0 may be 0 but not negative"),
        B=positive(geo, "half_width_m", "geometry", "B is half the distance between the pivots"),
        E_s=positive(stiff, "youngs_modulus_Pa", "stiffness", "Young's modulus in Pa, e.g. 200e9"),
        I_s=positive(stiff, "second_moment_m4", "stiffness", "second moment of area in m^4"),
        K_rot=positive(stiff, "rotational_spring_Nm_per_rad", "stiffness", "spring stiffness in N m/rad"),
        K_fp=positive(stiff, "horizontal_spring_N_per_m", "stiffness", "spring stiffness in N/m"),
        zeta_1=zeta_1,
        zeta_2=zeta_2,
        r_right=unit_interval("mean_right", "a coefficient of restitution"),
        r_left=unit_interval("mean_left", "a coefficient of restitution"),
        sigma_r=number(source, "restitution.sigma", rest["sigma"], low=0.0,
                       what="a standard deviation, 0 for none"),
        r_empirical=empirical,
        g=number(source, "gravity_m_per_s2", data.get("gravity_m_per_s2", G_DEFAULT),
                 low=0.0, low_open=True, what="gravitational acceleration in m/s^2"),
        reference=_reference(data.get("reference", {}), source),
        sensors=_sensors(data.get("sensors", {}), source, len(heights)),
    )


def _sensors(data, source: str, n: int) -> tuple[tuple[str, int], ...]:
    if not isinstance(data, Mapping):
        raise SpecimenError(f"{source}: `sensors` = {data!r}: expected a table; write it as [sensors]")
    out = []
    for name, node in data.items():
        if isinstance(node, bool) or not isinstance(node, int) or not 1 <= node <= n:
            raise SpecimenError(f"{source}: `sensors.{name}` = {node!r}: give the 1-based node "
                                f"number (1..{n}) the sensor sits at")
        out.append((str(name), int(node)))
    return tuple(out)


def _reference(data, source: str) -> ColumnReference:
    if not isinstance(data, Mapping):
        raise SpecimenError(f"{source}: `reference` = {data!r}: expected a table; write it as [reference]")
    keys = {"J_p_kgm2", "H_cg_m", "alpha_cg_rad", "p_l_rad_per_s",
            "full_contact_freq_hz", "rocking_freq_hz", "source"}
    check_keys(source, "reference", data, set(), keys)

    def opt(key):
        return (number(source, f"reference.{key}", data[key], low=0.0, low_open=True)
                if key in data else None)

    def opt_list(key):
        return (number_list(source, f"reference.{key}", data[key], positive=True)
                if key in data else ())

    return ColumnReference(
        J_p=opt("J_p_kgm2"), H_cg=opt("H_cg_m"), alpha_cg=opt("alpha_cg_rad"),
        p_l=opt("p_l_rad_per_s"), full_contact_freq_hz=opt_list("full_contact_freq_hz"),
        rocking_freq_hz=opt_list("rocking_freq_hz"),
        source=text(source, "reference.source", data.get("source", "")))
