"""Multi-mass rocking column specimens (paper 001, Section 2.1 and Table 1)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from ._fields import check_keys, number, number_list, show, table, text
from .errors import SpecimenError
from .ranges import SECTION_FACTOR, check, fmt, written

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
        raise SpecimenError(
            f"specimen {self.name!r} has no sensor {name!r}; known sensors: "
            + (", ".join(k for k, _ in self.sensors) or "none (add a [sensors] table)")
        )

    @property
    def n_nodes(self) -> int:
        """N, the number of elastic nodes."""
        return len(self.heights)


_TOP_REQUIRED = {"kind", "name", "geometry", "mass", "stiffness", "damping", "restitution"}
_TOP_OPTIONAL = {"description", "source", "gravity_m_per_s2", "reference", "sensors"}

#: Largest number of nodes N. Paper 001's columns have 5; a lumped column needs a node
#: per mode of interest. S1 lumped into 200 even nodes has its highest mode at 6.6e5 Hz,
#: near the frequency ceiling of `multimass.column` (1e6 Hz), and dense (2N x 2N)
#: matrices of 160 000 entries: more nodes only cost time.
MAX_NODES = 200

#: Smallest distance between consecutive nodes, as a fraction of the top node's height:
#: closer nodes are one node for a lumped model, and the element stiffness ∝ 1/L³ then
#: drowns the rest of the matrix in round-off (a 10 000-element mesh is still allowed).
MIN_SPACING = 1e-4


def column_from_mapping(data: Mapping, source: str) -> ColumnSpecimen:
    """Validate a parsed column TOML mapping and build the specimen.

    Every value must also be physically plausible (`specimens.ranges`): a length,
    a mass, a modulus or a spring typed in another unit is refused here, with
    the likely fix; the frequencies are checked by `multimass.column`.

    Parameters
    ----------
    data : mapping
        The parsed TOML document (``kind = "column"``).
    source : str
        Where it came from, used in error messages.

    Raises
    ------
    SpecimenError
        On a missing or unknown key, a value of the wrong type, out of range
        or implausible, or inconsistent lengths or ordering.
    """
    check_keys(source, "", data, _TOP_REQUIRED, _TOP_OPTIONAL)
    geo = table(source, data, "geometry")
    check_keys(source, "geometry", geo, {"heights_m", "half_width_m"})
    mass = table(source, data, "mass")
    check_keys(source, "mass", mass, {"nodal_kg", "base_kg", "base_inertia_kgm2"})
    stiff = table(source, data, "stiffness")
    check_keys(
        source,
        "stiffness",
        stiff,
        {
            "youngs_modulus_Pa",
            "second_moment_m4",
            "rotational_spring_Nm_per_rad",
            "horizontal_spring_N_per_m",
        },
    )
    damp = table(source, data, "damping")
    check_keys(source, "damping", damp, {"zeta_1", "zeta_2"})
    rest = table(source, data, "restitution")
    check_keys(source, "restitution", rest, {"mean_right", "mean_left", "sigma"}, {"empirical"})

    heights = _heights(source, geo["heights_m"])
    B = check(source, "geometry.half_width_m", geo["half_width_m"], "length")
    return ColumnSpecimen(
        name=text(source, "name", data["name"], required=True),
        description=text(source, "description", data.get("description", "")),
        source=text(source, "source", data.get("source", "")),
        heights=heights,
        B=B,
        **_masses(source, mass, len(heights)),
        **_stiffness(source, stiff, B),
        **_damping(source, damp),
        **_restitution(source, rest),
        g=check(source, "gravity_m_per_s2", data.get("gravity_m_per_s2", G_DEFAULT), "gravity"),
        reference=_reference(data.get("reference", {}), source),
        sensors=_sensors(data.get("sensors", {}), source, len(heights)),
    )


def _heights(source: str, value) -> tuple[float, ...]:
    """H: 1..MAX_NODES plausible heights, strictly increasing, not closer than MIN_SPACING."""
    field = "geometry.heights_m"
    heights = number_list(
        source,
        field,
        value,
        positive=True,
        what="node heights are measured upwards from the base (node 0)",
    )
    if len(heights) > MAX_NODES:
        raise SpecimenError(
            f"{source}: `{field}` has {len(heights)} nodes; at most {MAX_NODES} "
            "are accepted (see specimens.column.MAX_NODES): lump the column "
            "into fewer nodes"
        )
    for i, raw in enumerate(value):  # the values as typed, for the message
        check(source, f"{field}[{i}]", raw, "length")
    for i in range(1, len(heights)):
        if heights[i] <= heights[i - 1]:
            raise SpecimenError(
                f"{source}: `{field}[{i}]` = {heights[i]!r}: heights must increase "
                f"strictly from node 1 to node N (previous is {heights[i - 1]!r}); list nodes bottom to top"
            )
        if heights[i] - heights[i - 1] < MIN_SPACING * heights[-1]:
            raise SpecimenError(
                f"{source}: `{field}[{i}]` = {heights[i]!r} is only {heights[i] - heights[i - 1]:.3g} m "
                f"above node {i} ({heights[i - 1]!r} m), less than {MIN_SPACING:g} x the column's "
                "height: merge the two nodes (add their masses)"
            )
    return heights


def _masses(source: str, mass: Mapping, n: int) -> dict:
    field = "mass.nodal_kg"
    masses = number_list(
        source, field, mass["nodal_kg"], positive=True, what="give each node's lumped mass in kg"
    )
    if len(masses) != n:
        raise SpecimenError(
            f"{source}: `{field}` has {len(masses)} entries but `geometry.heights_m` has "
            f"{n}; give one mass per node height"
        )
    for i, raw in enumerate(mass["nodal_kg"]):
        check(source, f"{field}[{i}]", raw, "mass")
    return {
        "masses": masses,
        "m0": check(source, "mass.base_kg", mass["base_kg"], "base_mass"),
        "J0": check(source, "mass.base_inertia_kgm2", mass["base_inertia_kgm2"], "base_inertia"),
    }


def _stiffness(source: str, stiff: Mapping, B: float) -> dict:
    """E_s, I_s (within the footprint 2B x 2B), K_rot, K_fp."""
    field = "stiffness.second_moment_m4"
    I_s = number(
        source,
        field,
        stiff["second_moment_m4"],
        low=0.0,
        low_open=True,
        what="second moment of area in m^4",
    )
    I_max = SECTION_FACTOR * B**4
    if I_s > I_max:
        hint = next(
            (
                f"did you type {u}? write {written(I_s, f)}"
                for u, f in (("cm^4", 1e-8), ("mm^4", 1e-12))
                if I_s * f <= I_max
            ),
            "give it in m^4",
        )
        raise SpecimenError(
            f"{source}: `{field}` = {show(stiff['second_moment_m4'])}: implausible second moment of "
            f"area {fmt(I_s)} m^4: a section that fits in the column's footprint 2B x 2B "
            f"(B = `geometry.half_width_m` = {B:g} m) has I <= (2B)^4/12 = {I_max:.4g} m^4; {hint}"
        )
    return {
        "E_s": check(
            source, "stiffness.youngs_modulus_Pa", stiff["youngs_modulus_Pa"], "youngs_modulus"
        ),
        "I_s": I_s,
        "K_rot": check(
            source,
            "stiffness.rotational_spring_Nm_per_rad",
            stiff["rotational_spring_Nm_per_rad"],
            "rotational_spring",
        ),
        "K_fp": check(
            source,
            "stiffness.horizontal_spring_N_per_m",
            stiff["horizontal_spring_N_per_m"],
            "translational_spring",
        ),
    }


def _damping(source: str, damp: Mapping) -> dict:
    return {
        f"zeta_{k}": number(
            source,
            f"damping.zeta_{k}",
            damp[f"zeta_{k}"],
            low=0.0,
            high=1.0,
            high_open=True,
            what=f"a fraction of critical damping, e.g. "
            f"{0.005 if k == 1 else 0.015} for {0.5 if k == 1 else 1.5} %",
        )
        for k in (1, 2)
    }


def _restitution(source: str, rest: Mapping) -> dict:
    def unit_interval(key):
        return number(
            source,
            f"restitution.{key}",
            rest[key],
            low=0.0,
            high=1.0,
            low_open=True,
            what="a coefficient of restitution",
        )

    empirical = ()
    if "empirical" in rest and rest["empirical"] != []:
        empirical = number_list(source, "restitution.empirical", rest["empirical"])
        for i, r in enumerate(empirical):
            if not 0.0 < r <= 1.0:
                raise SpecimenError(
                    f"{source}: `restitution.empirical[{i}]` = {r!r}: a coefficient of "
                    "restitution must lie in (0, 1]"
                )
    return {
        "r_right": unit_interval("mean_right"),
        "r_left": unit_interval("mean_left"),
        "sigma_r": check(source, "restitution.sigma", rest["sigma"], "restitution_sigma"),
        "r_empirical": empirical,
    }


def _sensors(data, source: str, n: int) -> tuple[tuple[str, int], ...]:
    if not isinstance(data, Mapping):
        raise SpecimenError(
            f"{source}: `sensors` = {show(data)}: expected a table; write it as [sensors]"
        )
    out = []
    for name, node in data.items():
        if isinstance(node, bool) or not isinstance(node, int) or not 1 <= node <= n:
            raise SpecimenError(
                f"{source}: `sensors.{name}` = {show(node)}: give the 1-based node "
                f"number (1..{n}) the sensor sits at"
            )
        out.append((str(name), int(node)))
    return tuple(out)


def _reference(data, source: str) -> ColumnReference:
    if not isinstance(data, Mapping):
        raise SpecimenError(
            f"{source}: `reference` = {show(data)}: expected a table; write it as [reference]"
        )
    quantities = {
        "J_p_kgm2": "moment_of_inertia",
        "H_cg_m": "length",
        "alpha_cg_rad": "angle_rad",
        "p_l_rad_per_s": "frequency_parameter",
    }
    check_keys(
        source,
        "reference",
        data,
        set(),
        {*quantities, "full_contact_freq_hz", "rocking_freq_hz", "source"},
    )

    def opt(key):
        return (
            check(source, f"reference.{key}", data[key], quantities[key], low_open=True)
            if key in data
            else None
        )

    def opt_list(key):
        values = number_list(source, f"reference.{key}", data[key]) if key in data else ()
        return tuple(
            check(source, f"reference.{key}[{i}]", v, "frequency_hz") for i, v in enumerate(values)
        )

    return ColumnReference(
        J_p=opt("J_p_kgm2"),
        H_cg=opt("H_cg_m"),
        alpha_cg=opt("alpha_cg_rad"),
        p_l=opt("p_l_rad_per_s"),
        full_contact_freq_hz=opt_list("full_contact_freq_hz"),
        rocking_freq_hz=opt_list("rocking_freq_hz"),
        source=text(source, "reference.source", data.get("source", "")),
    )
