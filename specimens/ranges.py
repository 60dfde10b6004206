"""Plausible ranges of specimen inputs, so that a unit slip is refused at load time.

A specimen file holds SI values. A value typed in another unit (a Young's modulus
in GPa, a second moment of area in cm⁴, a height in mm, a mass in g) is still a
finite positive number, passes a sign check, and then makes a model that is wrong by
orders of magnitude: it overflows, or runs for hours, or quietly answers for another
structure. Each quantity here has a range that every real structure of this toolkit
lies in by a wide margin, and the reason for its bounds; a value outside is refused
with its field, its value, the range and the likely fix ("did you type GPa? write
200e9").

The ranges are wide on purpose (they catch slips of 10³ and more, not unusual
designs); the bundled specimens lie far inside them. Structure-level checks that need
the assembled matrices (the first and the highest full-contact frequency, positive
definiteness, Rayleigh damping that stays positive) are made by `multimass.column`.

>>> from multimass.specimens.ranges import RANGES
>>> RANGES["youngs_modulus"].low, RANGES["youngs_modulus"].high
(1000000.0, 1000000000000000.0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from ._fields import number, show
from .errors import SpecimenError

__all__ = ["Range", "RANGES", "check", "fmt", "written", "BEAM_RIGID_E", "SECTION_FACTOR"]


@dataclass(frozen=True)
class Range:
    """A closed plausible interval of one physical quantity.

    Attributes
    ----------
    what : str
        The quantity, as a message names it ("Young's modulus").
    low, high : float
        Bounds, in `unit`.
    unit : str
        SI unit of the field.
    why : str
        The reason for the bounds, quoted in messages.
    slips : tuple of (float, str)
        Unit slips to suggest: (factor, unit typed). A value ``x`` outside the
        range whose ``x * factor`` lies inside it gets "did you type <unit>?
        write <x * factor>".
    """

    what: str
    low: float
    high: float
    unit: str
    why: str
    slips: tuple[tuple[float, str], ...] = ()
    typical: str = ""
    common: tuple[float, float] | None = None

    def hint(self, x: float) -> str:
        """The likely fix for an out-of-range `x`."""
        lo, hi = self.common or (self.low, self.high)
        for factor, typed in self.slips:
            y = x * factor
            if lo < y <= hi:
                return f"did you type {typed}? write {written(x, factor)}"
        return f"give it in {self.unit or 'plain numbers'}" + (
            f" ({self.typical})" if self.typical else ""
        )


def written(x: float, factor: float) -> str:
    """x * factor as a user would type it: 200 GPa -> "200e9", 1930 mm -> "1.93"."""
    y = x * factor
    k = round(math.log10(factor))
    if not 1e-3 <= abs(y) < 1e4 and math.isclose(10.0**k, factor):
        return f"{x:g}e{k}"
    return f"{y:.6g}"


_LENGTH_SLIPS = ((1e-3, "mm"), (1e-2, "cm"))

#: Plausible ranges by quantity; the text of `why` is the justification.
RANGES: dict[str, Range] = {
    "length": Range(
        "length",
        1e-3,
        1e3,
        "m",
        "rocking structures run from laboratory blocks (paper 004: b = 45 mm) to the "
        "tallest towers (< 1 km); below 1 mm a dimension is a typing slip",
        _LENGTH_SLIPS + ((1e3, "km"),),
        "S1 is 1.93 m tall",
    ),
    "mass": Range(
        "mass",
        1e-3,
        1e9,
        "kg",
        "from a gram to the heaviest buildings (~5e8 kg); paper 004's lightest block "
        "is 0.544 kg, S1's lightest node 6.2 kg",
        ((1e-3, "g"), (1e3, "t")),
        "S1's top node is 46.2 kg",
    ),
    "base_mass": Range(
        "base mass",
        0.0,
        1e9,
        "kg",
        "0 (paper 001) up to the heaviest buildings (~5e8 kg)",
        ((1e-3, "g"),),
    ),
    "base_inertia": Range(
        "base rotary inertia",
        0.0,
        1e15,
        "kg m^2",
        "0 up to the largest mass (1e9 kg) at the largest size (1e3 m) squared",
        ((1e-4, "kg cm^2"), (1e-6, "kg mm^2")),
    ),
    "youngs_modulus": Range(
        "Young's modulus",
        1e6,
        1e15,
        "Pa",
        "structural materials run from soft rubber (~1e6 Pa) to diamond (1.05e12 Pa); "
        "the bound is 1000 x diamond because stiffened copies of a real column are how "
        "the rigid limit is studied (S1 x 1000 against the rigid body, in the verification guide)",
        ((1e9, "GPa"), (1e6, "MPa"), (1e3, "kPa")),
        "steel is 200e9, concrete 30e9",
        common=(1e6, 1.2e12),
    ),
    "translational_spring": Range(
        "spring stiffness",
        1.0,
        1e15,
        "N/m",
        "below 1 N/m a spring cannot hold a 1 kg mass under 1 g within 10 m; above "
        "1e15 N/m (2e6 x S1's K_fp) it is rigid for any mass in range and its "
        "frequency makes the time step absurd",
        ((1e3, "kN/m"), (1e6, "kN/mm or MN/m")),
        "S1's K_fp is 5.0e8",
    ),
    "rotational_spring": Range(
        "rotational spring stiffness",
        1.0,
        1e15,
        "N m/rad",
        "below 1 N m/rad a spring cannot hold a 1 kg mass at 1 m; above 1e15 N m/rad "
        "(5e8 x S1's K_rot) it is rigid for any mass in range",
        ((1e3, "kN m/rad"), (1e6, "MN m/rad")),
        "S1's K_rot is 2.0e6",
    ),
    "gravity": Range(
        "gravitational acceleration",
        1.6,
        1e4,
        "m/s^2",
        "from the Moon (1.62 m/s^2) to a geotechnical centrifuge (~1000 g); Earth is 9.81",
        ((9.81, "g"),),
        "Earth: 9.81",
    ),
    "density": Range(
        "density",
        10.0,
        2.5e4,
        "kg/m^3",
        "from rigid foams (~30 kg/m^3) to osmium (22 590 kg/m^3)",
        ((1e3, "g/cm^3"),),
        "aluminium is 2700",
    ),
    "section": Range(
        "section dimension",
        1e-5,
        1e2,
        "m",
        "from a 10 um foil to a 100 m deep girder; paper 002's beam is 1.71 mm thick",
        _LENGTH_SLIPS,
    ),
    "friction": Range(
        "friction coefficient",
        0.0,
        10.0,
        "",
        "dry friction coefficients of real surfaces stay below ~2; up to 10 means 'no sliding'",
    ),
    "restitution": Range(
        "coefficient of restitution",
        0.0,
        1.0,
        "",
        "a coefficient of restitution lies in (0, 1]",
        ((1e-2, "%"),),
    ),
    "restitution_sigma": Range(
        "standard deviation of the restitution",
        0.0,
        0.5,
        "",
        "a coefficient in (0, 1] cannot have a standard deviation above 0.5",
        ((1e-2, "%"),),
    ),
    "frequency_hz": Range(
        "frequency",
        1e-3,
        1e6,
        "Hz",
        "a period of 1000 s to 1 us: no rocking structure vibrates outside",
        (),
    ),
    "angle_rad": Range(
        "angle",
        0.0,
        math.pi / 2,
        "rad",
        "a slenderness lies in (0, pi/2)",
        ((math.pi / 180, "degrees"),),
    ),
    "angle_deg": Range(
        "angle", -90.0, 90.0, "deg", "a rocking angle lies in (-90, 90) degrees", ()
    ),
    "frequency_parameter": Range(
        "frequency parameter",
        1e-3,
        1e4,
        "rad/s",
        "sqrt(g/R) over the ranges of g and of lengths stays below 1e4 rad/s",
        (),
    ),
    "moment_of_inertia": Range(
        "moment of inertia",
        1e-9,
        1e21,
        "kg m^2",
        "the smallest mass at the smallest size squared up to the largest",
        (),
    ),
    "time_s": Range("time", 0.0, 1e6, "s", "a free-rocking test lasts seconds to minutes", ()),
}

#: Paper 002, Section 6.1: E = 1e24 Pa makes the beam a rigid base. A beam's Young's
#: modulus may take any value up to it (above diamond it is that convention).
BEAM_RIGID_E = 1e24

#: A section of second moment I fits in the footprint 2B x 2B only if
#: I <= (2B)(2B)^3/12 = 4 B^4 / 3 (the full square section is the largest).
SECTION_FACTOR = 4.0 / 3.0


def fmt(x: float) -> str:
    """A number as a user types it: 1e6, not 1e+06."""
    return f"{x:g}".replace("e+0", "e").replace("e+", "e").replace("e-0", "e-")


def check(
    source: str,
    field: str,
    value: Any,
    quantity: str,
    *,
    low: float | None = None,
    high: float | None = None,
    low_open: bool = False,
    why: str | None = None,
) -> float:
    """A finite number in the plausible range of `quantity` (a key of `RANGES`).

    Parameters
    ----------
    source, field : str
        The file and the dotted field, for the message.
    value : object
        The value found.
    quantity : str
        Key of `RANGES`.
    low, high : float, optional
        Override the range's bounds (e.g. a beam's Young's modulus up to
        `BEAM_RIGID_E`).
    low_open : bool
        Refuse the lower bound itself (e.g. a length of 0).
    why : str, optional
        The reason for overridden bounds (default: the range's own).

    Returns
    -------
    float

    Raises
    ------
    SpecimenError
        Naming the field, the value, the range, its reason and the likely fix.
    """
    rng = RANGES[quantity]
    lo = rng.low if low is None else low
    hi = rng.high if high is None else high
    x = number(source, field, value)
    if (x <= lo if low_open else x < lo) or x > hi:
        unit = f" {rng.unit}" if rng.unit else ""
        raise SpecimenError(
            f"{source}: `{field}` = {show(value)}: implausible {rng.what} {fmt(x)}{unit}; "
            f"it must lie in {'(' if low_open else '['}{fmt(lo)}, {fmt(hi)}]{unit} ({why or rng.why}); "
            f"{rng.hint(x) if x > 0 else 'it must be positive'}"
        )
    return x
