"""The question a scene asks and the tolerance of its answer (see `multimass.scenes.scene`).

Also the small validators of scene tables, shared by `scene`, `toml_scene` and
`validate`, so that none of them imports another in a circle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import InputError

__all__ = ["Question", "Tolerance", "QUESTIONS", "IMPACTS", "ANSWER_UNITS"]

QUESTIONS = ("peak_rotation", "overturning", "peak_acceleration", "uplifted_frequencies")
IMPACTS = ("CIM", "DD", "DD1", "DD2", "DD3", "DD4", "DD5")
#: unit of each question's answer
ANSWER_UNITS = {
    "peak_rotation": "rad",
    "overturning": "verdict",
    "peak_acceleration": "m/s2",
    "uplifted_frequencies": "Hz",
}
#: absolute-tolerance keys: (unit of the answer they apply to, factor to SI)
_ABS_KEYS = {
    "absolute_rad": ("rad", 1.0),
    "absolute_deg": ("rad", math.pi / 180.0),
    "absolute_m_per_s2": ("m/s2", 1.0),
    "absolute_g": ("m/s2", None),
    "absolute_hz": ("Hz", 1.0),
}


def _fail(where: str, field_: str, value, fix: str) -> InputError:
    return InputError(f"{where}: `{field_}` = {value!r}: {fix}")


def _number(where, field_, value, *, low=None, low_open=False, high=None, what="a number"):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise _fail(where, field_, value, f"expected {what}")
    x = float(value)
    if not math.isfinite(x):
        raise _fail(where, field_, value, f"expected a finite number ({what})")
    if low is not None and (x <= low if low_open else x < low):
        raise _fail(where, field_, value, f"must be {'>' if low_open else '>='} {low:g} ({what})")
    if high is not None and x > high:
        raise _fail(where, field_, value, f"must be <= {high:g} ({what})")
    return x


def _integer(where, field_, value, low: int, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        raise _fail(where, field_, value, f"expected an integer >= {low} ({what})")
    return int(value)


def _keys(where: str, table: str, data, allowed: set[str], required: set[str] = frozenset()):
    if not isinstance(data, dict):
        raise _fail(where, table, data, f"expected a table; write it as [{table}]")
    prefix = f"{table}." if table else ""
    unknown = sorted(set(data) - allowed - set(required))  # a misspelt key first: clearer
    if unknown:
        raise InputError(
            f"{where}: unknown key `{prefix}{unknown[0]}`; remove it or correct its "
            f"spelling (allowed in [{table or 'top level'}]: "
            f"{', '.join(sorted(allowed | set(required)))})"
        )
    for key in sorted(required):
        if key not in data:
            raise InputError(
                f"{where}: missing key `{prefix}{key}`; add it to [{table or 'top level'}]"
            )


@dataclass(frozen=True)
class Question:
    """What the user wants to know (see the module docstring).

    Attributes
    ----------
    kind : str
        One of `QUESTIONS`.
    node : int, optional
        1-based column node (peak_acceleration).
    sensor : str, optional
        A sensor name of the specimen's [sensors] table, instead of `node`.
    n_modes : int
        Number of uplifted frequencies (uplifted_frequencies; default 2).
    after_impacts : int, optional
        peak_rotation counts half-cycles after this many impacts (default: 1
        for a free release, else 0).
    """

    kind: str
    node: int | None = None
    sensor: str | None = None
    n_modes: int = 2
    after_impacts: int | None = None

    def __post_init__(self):
        w = "question"
        if self.kind not in QUESTIONS:
            raise _fail(w, "question.kind", self.kind, f"use one of {', '.join(QUESTIONS)}")
        if self.kind == "peak_acceleration":
            if (self.node is None) == (self.sensor is None):
                raise InputError(
                    "question: a peak_acceleration question needs exactly one of "
                    "`question.node` (1-based node number) or `question.sensor` "
                    "(a name from the specimen's [sensors] table)"
                )
            if self.node is not None:
                _integer(w, "question.node", self.node, 1, "a 1-based node number")
            elif not isinstance(self.sensor, str) or not self.sensor:
                raise _fail(w, "question.sensor", self.sensor, 'give a sensor name, e.g. "A2"')
        elif self.node is not None or self.sensor is not None:
            raise InputError(
                f"question: `question.node`/`question.sensor` apply only to "
                f"peak_acceleration, not to {self.kind}; remove them"
            )
        _integer(w, "question.n_modes", self.n_modes, 1, "the number of uplifted frequencies")
        if self.after_impacts is not None:
            if self.kind != "peak_rotation":
                raise InputError(
                    f"question: `question.after_impacts` applies only to "
                    f"peak_rotation, not to {self.kind}; remove it"
                )
            _integer(w, "question.after_impacts", self.after_impacts, 0, "a number of impacts")

    @property
    def unit(self) -> str:
        """Unit of the answer: "rad", "verdict", "m/s2" or "Hz"."""
        return ANSWER_UNITS[self.kind]


@dataclass(frozen=True)
class Tolerance:
    """How close a cheaper model's answer must be to the richer one's.

    Attributes
    ----------
    value : float
        A fraction (relative) or an amount in `unit` (absolute, SI).
    relative : bool
        True: ``|a − b| / |b| ≤ value``, b the richer model's answer.
    unit : str
        "1" for relative; else the answer's unit ("rad", "m/s2", "Hz").
        Overturning verdicts must agree: ``Tolerance.verdict()``.
    """

    value: float
    relative: bool = True
    unit: str = "1"

    def __post_init__(self):
        if self.unit == "verdict":
            return
        _number(
            "tolerance",
            "tolerance.value",
            self.value,
            low=0.0,
            low_open=True,
            what="a positive tolerance",
        )
        if self.relative and self.unit != "1":
            raise _fail(
                "tolerance", "tolerance.unit", self.unit, 'a relative tolerance has unit "1"'
            )
        if not self.relative and self.unit not in ("rad", "m/s2", "Hz"):
            raise _fail("tolerance", "tolerance.unit", self.unit, "use rad, m/s2 or Hz")

    @classmethod
    def verdict(cls) -> Tolerance:
        """The overturning tolerance: verdicts must agree (difference 0 or 1)."""
        return cls(0.0, relative=False, unit="verdict")

    def difference(self, cheap, rich) -> float:
        """``|cheap − rich|`` (absolute) or ``|cheap − rich| / |rich|`` (relative); worst mode for tuples."""
        if self.unit == "verdict":
            return 0.0 if bool(cheap) == bool(rich) else 1.0
        pairs = list(zip(cheap, rich)) if isinstance(cheap, (tuple, list)) else [(cheap, rich)]
        if isinstance(cheap, (tuple, list)) and len(cheap) != len(rich):
            return math.inf
        worst = 0.0
        for a, b in pairs:
            d = abs(float(a) - float(b))
            if self.relative:
                d = 0.0 if d == 0.0 else (d / abs(float(b)) if b != 0 else math.inf)
            worst = max(worst, d)
        return worst

    def allows(self, difference: float) -> bool:
        """True if `difference` is within this tolerance."""
        return difference <= self.value

    def describe(self) -> str:
        """E.g. "5 %", "0.002 rad", "verdicts agree"."""
        if self.unit == "verdict":
            return "verdicts agree"
        return f"{100 * self.value:g} %" if self.relative else f"{self.value:g} {self.unit}"

    def to_dict(self) -> dict:
        return {
            "value": self.value,
            "relative": self.relative,
            "unit": self.unit,
            "text": self.describe(),
        }
