"""A scene: what stands where, what shakes it, what the user wants to know, how exactly.

A `Scene` is built in Python or read from a TOML file (`Scene.from_toml`)::

    name = "S1 under paper 001's pulse"
    [structure]
    specimen = "S1"              # bundled name, or a TOML path (relative to this file)
    # beam = "beam_mudric2024"   # a block standing on a beam (free release only)
    # E_Pa = 3.0e9 | E_over_Ebar = 1e4   # the beam's Young's modulus (default: the beam's)
    [excitation]
    kind = "cosine_pulse"        # free_release | sine_wave | cosine_wave | cosine_pulse | ricker
                                 # | mp_pulse | record
    omega_rad_per_s = 15.0
    amplitude = "0.4g"
    [question]
    kind = "peak_rotation"       # | overturning | peak_acceleration | uplifted_frequencies
    [tolerance]
    relative = 0.05              # or absolute_rad / absolute_deg / absolute_m_per_s2
                                 # / absolute_g / absolute_hz
    [simulation]                 # optional
    t_end_s = 6.0
    impact = "DD2"               # restitution, max_step_s, nscd_dt_s, nscd_elements

Units: SI, and each TOML key names its unit. Unknown keys are errors. Excitation keys:
free_release: theta0_rad or theta0_deg, [u0_m]; sine_wave, cosine_wave, cosine_pulse
(paper 001's pulse): amplitude ("0.4g", "3.9 m/s2"), omega_rad_per_s; ricker: the same and
[t0_s]; mp_pulse (Mavroeidis & Papageorgiou 2003): amplitude_m_per_s, fp_hz, [gamma],
[nu_rad], [t0_s]; record: path (relative to the scene file), units (two-column files), [scale].

Questions and their answers:

``peak_rotation``
    Largest ``|θ|`` (rad) over the half-cycles after `after_impacts` impacts
    (default 1 for a free release — its first peak is the release angle
    itself — else 0). An overturned structure answers π/2.
``overturning``
    True if the structure overturns before t_end. Verdicts must agree, so the
    scene has no [tolerance] table.
``peak_acceleration``
    Largest absolute total lateral acceleration (m/s², paper 001 Eq 7) at a column
    node (`node`, 1-based, or `sensor`, a name of the specimen's [sensors]).
``uplifted_frequencies``
    The first `n_modes` (default 2) uplifted vibration frequencies (Hz) of the
    Foss analysis (paper 001, Eqs 24–25); compared mode by mode, worst taken.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import multimass.specimens as specimens

from ..inputs.excitations import Excitation, FreeRelease
from ..simulation import DEFAULTS
from .question import IMPACTS, QUESTIONS, Question, Tolerance
from .toml_scene import scene_arguments
from .validate import validate_scene

__all__ = ["Scene", "Question", "Tolerance", "QUESTIONS", "IMPACTS"]


@dataclass(frozen=True, eq=False)
class Scene:
    """A structure, an excitation, a question and a tolerance (module docstring).

    Attributes
    ----------
    name : str
    specimen : str, path or specimen object
        A column (S1, S2, S3, a TOML path) or a block (B4M, B6M, ...).
    excitation : Excitation
        `FreeRelease`, `SineWave`, `CosineWave`, `CosinePulse`, `Ricker`, `MPPulse` or a
        `Record`.
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
        validate_scene(self)

    @cached_property
    def spec(self):
        """The loaded specimen (column or block)."""
        return self.specimen if hasattr(self.specimen, "kind") else specimens.load(self.specimen)

    @cached_property
    def beam_spec(self):
        """The loaded beam specimen, or None (rigid ground)."""
        if self.beam is None:
            return None
        return self.beam if hasattr(self.beam, "kind") else specimens.load(self.beam)

    @property
    def kind(self) -> str:
        """ "column", "block" (rigid ground) or "block_on_beam"."""
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
    def from_toml(cls, path) -> Scene:
        """Read and validate a scene file (module docstring); paths resolve against its folder.

        A missing, empty, binary or non-UTF-8 file, a directory or bad TOML syntax is an
        `InputError` naming the path (`multimass.scenes.toml_scene.scene_from_file`).
        """
        return cls(**scene_arguments(path))

    def describe(self) -> dict:
        """A JSON-ready description of the scene."""
        spec = self.spec
        exc = (
            self.excitation.describe()
            if hasattr(self.excitation, "describe")
            else repr(self.excitation)
        )
        return {
            "name": self.name,
            "specimen": spec.name,
            "kind": self.kind,
            "beam": None if self.beam_spec is None else self.beam_spec.name,
            "E_Pa": self.E,
            "excitation": exc,
            "question": self.question.kind,
            "node": self.node,
            "n_modes": self.question.n_modes
            if self.question.kind == "uplifted_frequencies"
            else None,
            "after_impacts": self.after_impacts if self.question.kind == "peak_rotation" else None,
            "tolerance": self.tol.to_dict(),
            "t_end_s": self.duration,
            "impact": self.impact_model,
            "restitution": self.restitution_value,
            "max_step_s": self.solver_max_step,
            "source": self.source or None,
        }
