"""A scene: what stands where, what shakes it, what the user wants to know, how exactly.

A `Scene` is built in Python or read from a TOML file (`Scene.from_toml`)::

    name = "S1 under paper 001's pulse"
    [structure]
    specimen = "S1"              # bundled name, or a TOML path (relative to this file)
    # beam = "beam_mudric2024"   # a block standing on a beam (free release only)
    # E_Pa = 3.0e9 | E_over_Ebar = 1e4   # the beam's Young's modulus (default: the beam's)
    [excitation]
    kind = "cosine_pulse"        # free_release | sine_wave | cosine_wave | cosine_pulse | ricker | record
    omega_rad_per_s = 15.0
    amplitude = "0.4g"
    [question]
    kind = "peak_rotation"       # | overturning | peak_acceleration | uplifted_frequencies
    [tolerance]
    relative = 0.05              # or absolute_rad / absolute_deg / absolute_m_per_s2 / absolute_g / absolute_hz
    [simulation]                 # optional
    t_end_s = 6.0
    impact = "DD2"               # restitution, max_step_s, nscd_dt_s, nscd_elements

Units: SI, and each TOML key names its unit. Unknown keys are errors. Excitation keys:
free_release: theta0_rad or theta0_deg, [u0_m]; sine_wave, cosine_wave, cosine_pulse
(paper 001's pulse): amplitude ("0.4g", "3.9 m/s2"), omega_rad_per_s; ricker: the same and
[t0_s]; record: path (relative to the scene file), units (two-column files), [scale].

Questions and their answers:

``peak_rotation``
    Largest |θ| (rad) over the half-cycles after `after_impacts` impacts
    (default 1 for a free release — its first peak is the release angle
    itself — else 0). An overturned structure answers π/2.
``overturning``
    True if the structure overturns before t_end. Verdicts must agree, so the
    scene has no [tolerance] table.
``peak_acceleration``
    Largest |total lateral acceleration| (m/s², paper 001 Eq 7) at a column
    node (`node`, 1-based, or `sensor`, a name of the specimen's [sensors]).
``uplifted_frequencies``
    The first `n_modes` (default 2) uplifted vibration frequencies (Hz) of the
    Foss analysis (paper 001, Eqs 24–25); compared mode by mode, worst taken.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

from ..errors import InputError
from ..excitations import Excitation, FreeRelease

__all__ = ["Scene", "Question", "Tolerance", "QUESTIONS", "IMPACTS"]

QUESTIONS = ("peak_rotation", "overturning", "peak_acceleration", "uplifted_frequencies")
IMPACTS = ("CIM", "DD", "DD1", "DD2", "DD3", "DD4", "DD5")
#: unit of each question's answer
ANSWER_UNITS = {"peak_rotation": "rad", "overturning": "verdict", "peak_acceleration": "m/s2",
                "uplifted_frequencies": "Hz"}
#: absolute-tolerance keys: (unit of the answer they apply to, factor to SI)
_ABS_KEYS = {"absolute_rad": ("rad", 1.0), "absolute_deg": ("rad", math.pi / 180.0),
             "absolute_m_per_s2": ("m/s2", 1.0), "absolute_g": ("m/s2", None),
             "absolute_hz": ("Hz", 1.0)}


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
    unknown = sorted(set(data) - allowed - set(required))   # a misspelt key first: clearer
    if unknown:
        raise InputError(f"{where}: unknown key `{prefix}{unknown[0]}`; remove it or correct its "
                         f"spelling (allowed in [{table or 'top level'}]: "
                         f"{', '.join(sorted(allowed | set(required)))})")
    for key in sorted(required):
        if key not in data:
            raise InputError(f"{where}: missing key `{prefix}{key}`; add it to "
                             f"[{table or 'top level'}]")


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
                raise InputError("question: a peak_acceleration question needs exactly one of "
                                 "`question.node` (1-based node number) or `question.sensor` "
                                 "(a name from the specimen's [sensors] table)")
            if self.node is not None:
                _integer(w, "question.node", self.node, 1, "a 1-based node number")
            elif not isinstance(self.sensor, str) or not self.sensor:
                raise _fail(w, "question.sensor", self.sensor, "give a sensor name, e.g. \"A2\"")
        elif self.node is not None or self.sensor is not None:
            raise InputError(f"question: `question.node`/`question.sensor` apply only to "
                             f"peak_acceleration, not to {self.kind}; remove them")
        _integer(w, "question.n_modes", self.n_modes, 1, "the number of uplifted frequencies")
        if self.after_impacts is not None:
            if self.kind != "peak_rotation":
                raise InputError(f"question: `question.after_impacts` applies only to "
                                 f"peak_rotation, not to {self.kind}; remove it")
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
        True: |a − b| / |b| ≤ value, b the richer model's answer.
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
        _number("tolerance", "tolerance.value", self.value, low=0.0, low_open=True,
                what="a positive tolerance")
        if self.relative and self.unit != "1":
            raise _fail("tolerance", "tolerance.unit", self.unit, "a relative tolerance has unit \"1\"")
        if not self.relative and self.unit not in ("rad", "m/s2", "Hz"):
            raise _fail("tolerance", "tolerance.unit", self.unit, "use rad, m/s2 or Hz")

    @classmethod
    def verdict(cls) -> "Tolerance":
        """The overturning tolerance: verdicts must agree (difference 0 or 1)."""
        return cls(0.0, relative=False, unit="verdict")

    def difference(self, cheap, rich) -> float:
        """|cheap − rich| (absolute) or |cheap − rich| / |rich| (relative); worst mode for tuples."""
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
        return {"value": self.value, "relative": self.relative, "unit": self.unit,
                "text": self.describe()}


@dataclass(frozen=True, eq=False)
class Scene:
    """A structure, an excitation, a question and a tolerance (module docstring).

    Attributes
    ----------
    name : str
    specimen : str, path or specimen object
        A column (S1, S2, S3, a TOML path) or a block (B4M, B6M, ...).
    excitation : Excitation
        `FreeRelease`, `SineWave`, `CosineWave`, `CosinePulse`, `Ricker` or a `Record`.
    question : Question
    tolerance : Tolerance
        Ignored (and may be None) for overturning, whose verdicts must agree.
    beam : str, path or BeamSpecimen, optional
        A block standing on this beam (paper 002); free release only.
    E : float, optional
        The beam's Young's modulus (Pa); default the beam's own.
    t_end : float, optional
        Duration (s); default 6 s for a released column, 2 s for a released
        block, else the excitation's duration + 3 s.
    impact : str, optional
        Impact model (default DD2 for columns, CIM for blocks).
    restitution : str or float, optional
        Override of the impact model's restitution (default: the specimen's
        Table 2 data for columns, Housner's η for blocks — the rigid limit of
        the plastic NSCD impact, paper 002 Section 6.2).
    max_step : float, optional
        Largest solver step of `multimass.simulate` (s). Default: its own 5 ms
        for a free release, 1 ms under ground motion — small rocking under a
        record is sensitive (paper 001 §4.4): with 5 ms, S1 under El Centro ×1.1
        lands on one of two branches (0.0042 or 0.0129 rad) depending on round-off
        details of the model, with 1 ms every model of the ladder finds 0.0042.
    nscd_dt, nscd_elements :
        Time step (s, default 1e-5) and elements (default the beam's) of the
        block-on-beam model.
    description, source : str
    """

    name: str
    specimen: object
    excitation: Excitation
    question: Question
    tolerance: Tolerance | None
    beam: object = None
    E: float | None = None
    t_end: float | None = None
    impact: str | None = None
    restitution: object = None
    max_step: float | None = None
    nscd_dt: float = 1e-5
    nscd_elements: int | None = None
    description: str = ""
    source: str = field(default="", repr=False)

    def __post_init__(self):
        from .validate import validate_scene

        validate_scene(self)

    @cached_property
    def spec(self):
        """The loaded specimen (column or block)."""
        import specimens

        return self.specimen if hasattr(self.specimen, "kind") else specimens.load(self.specimen)

    @cached_property
    def beam_spec(self):
        """The loaded beam specimen, or None (rigid ground)."""
        import specimens

        if self.beam is None:
            return None
        return self.beam if hasattr(self.beam, "kind") else specimens.load(self.beam)

    @property
    def kind(self) -> str:
        """"column", "block" (rigid ground) or "block_on_beam"."""
        if self.spec.kind == "column":
            return "column"
        return "block" if self.beam is None else "block_on_beam"

    @property
    def is_release(self) -> bool:
        return isinstance(self.excitation, FreeRelease)

    @property
    def impact_model(self) -> str:
        return self.impact or ("DD2" if self.kind == "column" else "CIM")

    @property
    def restitution_value(self):
        if self.restitution is not None:
            return self.restitution
        return None if self.kind == "column" else "housner"

    @property
    def solver_max_step(self) -> float:
        """max_step of `multimass.simulate` (s): the scene's, else 5 ms released, 1 ms forced."""
        from ..simulate import DEFAULTS

        if self.max_step is not None:
            return float(self.max_step)
        return DEFAULTS["max_step"] if self.is_release else 1e-3

    @property
    def duration(self) -> float:
        """End time of the simulations (s)."""
        if self.t_end is not None:
            return float(self.t_end)
        if self.is_release:
            return 6.0 if self.kind == "column" else 2.0
        return float(self.excitation.duration) + 3.0

    @property
    def after_impacts(self) -> int:
        q = self.question.after_impacts
        return q if q is not None else (1 if self.is_release else 0)

    @property
    def node(self) -> int | None:
        """The 1-based column node a peak_acceleration question asks about."""
        q = self.question
        if q.kind != "peak_acceleration":
            return None
        return q.node if q.node is not None else self.spec.sensor_node(q.sensor)

    @property
    def tol(self) -> Tolerance:
        return Tolerance.verdict() if self.question.kind == "overturning" else self.tolerance

    @classmethod
    def from_toml(cls, path) -> "Scene":
        """Read and validate a scene file (module docstring); paths resolve against its folder.

        A missing, empty, binary or non-UTF-8 file, a directory or bad TOML syntax is an
        `InputError` naming the path (`multimass.scenes.toml_scene.scene_from_file`).
        """
        from .toml_scene import scene_from_file

        return scene_from_file(path)

    def describe(self) -> dict:
        """A JSON-ready description of the scene."""
        spec = self.spec
        exc = self.excitation.describe() if hasattr(self.excitation, "describe") else repr(self.excitation)
        return {"name": self.name, "specimen": spec.name, "kind": self.kind,
                "beam": None if self.beam_spec is None else self.beam_spec.name,
                "E_Pa": self.E, "excitation": exc, "question": self.question.kind,
                "node": self.node, "n_modes": self.question.n_modes if
                self.question.kind == "uplifted_frequencies" else None,
                "after_impacts": self.after_impacts if self.question.kind == "peak_rotation" else None,
                "tolerance": self.tol.to_dict(), "t_end_s": self.duration,
                "impact": self.impact_model, "restitution": self.restitution_value,
                "max_step_s": self.solver_max_step,
                "source": self.source or None}

