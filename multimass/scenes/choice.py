"""`choose`: the cheapest model whose answer stays within the tolerance of the next richer one.

1. The ladder of the scene (`ladder.ladder`), cheapest first.
2. A-priori verdicts (`criteria.assess`): the first rung that passes every
   criterion is the a-priori choice (the top rung always passes).
3. Its answer.
4. With ``verify=True``, the measured walk:

   * up: compare the rung with the next richer one; while the difference exceeds
     the tolerance, the rung is *not adequate* — say so and move up;
   * down (only if the a-priori choice was adequate, or is the top rung): compare
     the next cheaper rungs, one by one, with the same reference (the a-priori
     choice's next richer rung, or the top rung); while one is within the
     tolerance, the a-priori criteria were conservative — move down. Comparing
     with one fixed reference keeps small steps from adding up.

   Every comparison is kept (`Choice.comparisons`).

``time_saved_s``: wall time of the next richer model minus the chosen one's — measured
with ``verify``, else from `estimate_cost` (flagged ``time_saved_estimated``).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

from ..errors import InputError
from ..model.structure import column
from .criteria import assess
from .rungs import BACKENDS, Rung, RungAnswer, ladder
from .scene import Scene, Tolerance

__all__ = ["Choice", "Comparison", "choose", "estimate_cost", "format_answer"]


@dataclass(frozen=True)
class Comparison:
    """A cheaper rung's answer measured against a richer one's."""

    model: str
    answer: object
    reference: str
    reference_answer: object
    difference: float
    adequate: bool
    model_time_s: float
    reference_time_s: float

    def to_dict(self) -> dict:
        return {
            "model": self.model,
            "answer": _jsonable(self.answer),
            "reference": self.reference,
            "reference_answer": _jsonable(self.reference_answer),
            "difference": _jsonable(self.difference),
            "adequate": self.adequate,
            "model_time_s": self.model_time_s,
            "reference_time_s": self.reference_time_s,
        }


@dataclass(frozen=True)
class Choice:
    """The outcome of `choose`.

    Attributes
    ----------
    scene : str
    model, label : str
        The chosen rung and its description.
    reason : str
        Why: the a-priori checks and, with verify, the measured differences.
    answer : float, bool or tuple of float
        The chosen model's answer, in `unit`.
    unit : str
    verified_against : str or None
        The rung it was measured against: the next richer one; for the top rung,
        the next cheaper one (showing why the cheaper one was not enough); None
        without verify.
    verified_answer : object or None
    difference : float or None
        ``|answer − verified_answer|`` (absolute, or relative to the richer answer).
    tolerance : Tolerance
    adequate : bool or None
        True if the chosen model is within the tolerance of the next richer one;
        None if not measured (no verify, or the top rung).
    time_saved_s : float
    time_saved_estimated : bool
    a_priori_model : str
    ladder : tuple of str
    verdicts : tuple of Verdict
    criteria : dict
        The indicators behind the verdicts (ω₁/p_l, κ, ε, n_c, δ/L, ...).
    comparisons : tuple of Comparison
    wall_time_s : float
        The chosen model's own time.
    """

    scene: str
    model: str
    label: str
    reason: str
    answer: object
    unit: str
    verified_against: str | None
    verified_answer: object
    difference: float | None
    tolerance: Tolerance
    adequate: bool | None
    time_saved_s: float
    time_saved_estimated: bool
    a_priori_model: str
    ladder: tuple
    verdicts: tuple
    criteria: dict
    comparisons: tuple
    wall_time_s: float

    def to_dict(self) -> dict:
        """JSON-ready dict (SI units; infinities as null)."""
        return {
            "scene": self.scene,
            "model": self.model,
            "label": self.label,
            "reason": self.reason,
            "answer": _jsonable(self.answer),
            "unit": self.unit,
            "verified_against": self.verified_against,
            "verified_answer": _jsonable(self.verified_answer),
            "difference": _jsonable(self.difference),
            "tolerance": self.tolerance.to_dict(),
            "adequate": self.adequate,
            "time_saved_s": self.time_saved_s,
            "time_saved_estimated": self.time_saved_estimated,
            "a_priori_model": self.a_priori_model,
            "ladder": list(self.ladder),
            "verdicts": [v.to_dict() for v in self.verdicts],
            "criteria": _jsonable(self.criteria),
            "comparisons": [c.to_dict() for c in self.comparisons],
            "wall_time_s": self.wall_time_s,
        }

    def to_json(self, **kw) -> str:
        return json.dumps(self.to_dict(), **kw)


def format_answer(value, unit: str) -> str:
    """An answer for display: radians also in degrees, m/s² also in g."""
    if unit == "verdict":
        return "overturns" if value else "does not overturn"
    if unit == "Hz":
        return ", ".join(f"{f:.3f}" for f in value) + " Hz"
    if unit == "rad":
        return f"{value:.5f} rad ({math.degrees(value):.3f}°)"
    return f"{value:.4g} m/s² ({value / 9.81:.3f} g)"


def _jsonable(x):
    if isinstance(x, dict):
        return {k: _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, (bool, int, str)) or x is None:
        return x
    try:
        v = float(x)
    except (TypeError, ValueError):
        return str(x)
    return v if math.isfinite(v) else None


def estimate_cost(rung: Rung, scene) -> float:
    """A rough a-priori wall time of a rung (s), for ``time_saved_s`` without verify.

    Columns: explicit Runge–Kutta steps ≈ t_end · max(1 / max_step, ω_max / 4) (the
    step cap, or the stability limit of the fastest kept mode) at ~10 µs a step;
    uplifted frequencies: a modal analysis, ~1 ms;
    blocks on beams: t_end / dt steps at ~3.5 µs (paper 002's kernel on this
    toolkit, benchmarks/nscd_cost.py). Order-of-magnitude only.
    """
    if scene.question.kind == "uplifted_frequencies":
        return 1e-3 + 1e-5 * rung.dofs**3  # two dense eigenproblems of size ~2(n+1)
    if rung.n_modes is not None:
        w = column(scene.spec).full_contact_omega
        w_max = float(w[rung.n_modes - 1]) if rung.n_modes else 0.0
        return scene.duration * max(1.0 / scene.solver_max_step, w_max / 4.0) * 10e-6
    if rung.name == "nscd":
        return scene.duration / scene.nscd_dt * 3.5e-6
    return scene.duration / scene.solver_max_step * 10e-6


def _describe_checks(rungs, verdicts, upto: int) -> str:
    parts = []
    for r, v in zip(rungs[: upto + 1], verdicts[: upto + 1]):
        if v.checks and v.checks[0][0] == "top of the ladder":
            parts.append(f"{r.name}: the richest model")
        else:
            parts.append(f"{r.name} {'passes' if v.passes else 'fails'} ({v.reason()})")
    return "a priori: " + "; ".join(parts)


def choose(scene, verify: bool = False, *, backend: str = "auto") -> Choice:
    """Pick the cheapest adequate model of `scene` (module docstring).

    Parameters
    ----------
    scene : Scene or path
        A scene, or the path of a scene TOML file.
    verify : bool
        Also run the neighbouring rung(s) and measure the difference.
    backend : {"auto", "compiled", "scipy"}
        Backend of `multimass.simulate` for the column and rigid-block rungs
        ("auto": the compiled one when available). It changes the timings, not
        the answers (beyond the solvers' tolerances).

    Returns
    -------
    Choice

    Raises
    ------
    InputError
        For a bad scene.
    SolverError
        If a model's simulation fails.
    """
    if not isinstance(scene, Scene):
        if isinstance(scene, (str, bytes)) or hasattr(scene, "__fspath__"):
            scene = Scene.from_toml(scene)
        else:
            raise InputError(f"`scene` = {scene!r}: give a multimass.Scene or a scene TOML path")
    if backend not in BACKENDS:
        raise InputError(f"`backend` = {backend!r}: use one of {', '.join(BACKENDS)}")
    runs = _Runs(scene, ladder(scene), backend)
    rungs = runs.rungs
    verdicts, indicators, budget = assess(scene, rungs)
    i0 = next(i for i, v in enumerate(verdicts) if v.passes)
    reason = _describe_checks(rungs, verdicts, i0)
    i, ref = i0, None
    if verify:
        i, ref, notes = _walk(i0, [r.name for r in rungs], runs.compare, scene.tol)
        reason += ". verified: " + "; ".join(notes)
    chosen = runs.answer(i)
    against, ref_answer, diff, adequate, saved, estimated = _outcome(runs, i, ref, verify)
    if budget is not None:
        indicators = {**indicators, "budget": budget}
    return Choice(
        scene=scene.name,
        model=rungs[i].name,
        label=rungs[i].label,
        reason=reason,
        answer=chosen.value,
        unit=chosen.unit,
        verified_against=against,
        verified_answer=ref_answer,
        difference=diff,
        tolerance=scene.tol,
        adequate=adequate,
        time_saved_s=float(saved),
        time_saved_estimated=estimated,
        a_priori_model=rungs[i0].name,
        ladder=tuple(r.name for r in rungs),
        verdicts=tuple(verdicts),
        criteria=indicators,
        comparisons=tuple(runs.comps[k] for k in sorted(runs.comps)),
        wall_time_s=chosen.wall_time_s,
    )


class _Runs:
    """The answers of the rungs run so far (each runs once) and their comparisons."""

    def __init__(self, scene, rungs, backend):
        self.scene, self.rungs, self.backend = scene, rungs, backend
        self.answers: dict[int, RungAnswer] = {}
        self.comps: dict[tuple[int, int], Comparison] = {}

    def answer(self, i: int) -> RungAnswer:
        if i not in self.answers:
            self.answers[i] = self.rungs[i].answer(self.scene, self.backend)
        return self.answers[i]

    def compare(self, i: int, j: int) -> Comparison:
        """Rung i against the richer rung j."""
        a, b = self.answer(i), self.answer(j)
        d = self.scene.tol.difference(a.value, b.value)
        self.comps[(i, j)] = Comparison(
            self.rungs[i].name,
            a.value,
            self.rungs[j].name,
            b.value,
            d,
            self.scene.tol.allows(d),
            a.wall_time_s,
            b.wall_time_s,
        )
        return self.comps[(i, j)]


def _outcome(runs: _Runs, i: int, ref: int | None, verify: bool):
    """(verified_against, its answer, difference, adequate, time saved, estimated?)."""
    if ref is not None and ref > i:
        c = runs.comps[(i, ref)]
        saved = runs.answers[ref].wall_time_s - runs.answers[i].wall_time_s
        return c.reference, c.reference_answer, c.difference, c.adequate, saved, False
    if ref is not None and (i - 1, i) in runs.comps:  # the top rung: why the cheaper failed
        c = runs.comps[(i - 1, i)]
        return c.model, c.answer, c.difference, None, 0.0, False
    top = len(runs.rungs) - 1
    if i < top and not verify:
        saved = estimate_cost(runs.rungs[i + 1], runs.scene) - estimate_cost(
            runs.rungs[i], runs.scene
        )
        return None, None, None, None, saved, True
    return None, None, None, None, 0.0, False


def _walk(i0: int, names, compare, tol) -> tuple[int, int | None, list[str]]:
    """The measured walk of `choose`: up while not adequate, then down against one reference.

    Returns the chosen rung, the rung it was measured against (None if it is the
    only rung) and the notes for the reason.
    """
    i, top, notes = i0, len(names) - 1, []
    while i < top:
        c = compare(i, i + 1)
        if c.adequate:
            break
        notes.append(f"{c.model} NOT adequate: {_diff(c, tol)} against {c.reference}")
        i += 1
    if i > i0:  # moved up: (i - 1, i) already failed
        ref = i + 1 if i < top else i
    else:  # check the cheaper rungs against one reference
        ref = i + 1 if i < top else i
        while i > 0:
            c = compare(i - 1, ref)
            if not c.adequate:
                notes.append(
                    f"{c.model} (cheaper) confirmed not adequate: {_diff(c, tol)} "
                    f"against {c.reference}"
                )
                break
            notes.append(
                f"{c.model} (cheaper) measured adequate: {_diff(c, tol)} against "
                f"{c.reference}; the a-priori criteria were conservative"
            )
            i -= 1
    if top == 0:
        notes.append(f"chosen {names[i]}: the only model of this scene's ladder")
    elif ref == i:
        notes.append(f"chosen {names[i]}: the richest model")
    else:
        c = compare(i, ref)
        notes.append(f"chosen {names[i]}: {_diff(c, tol)} against {names[ref]} (adequate)")
    return i, (ref if top > 0 else None), notes


def _diff(c: Comparison, tol: Tolerance) -> str:
    if tol.unit == "verdict":
        return f"verdict {c.answer} vs {c.reference_answer}"
    d = (
        "inf"
        if not math.isfinite(c.difference)
        else (f"{100 * c.difference:.3g} %" if tol.relative else f"{c.difference:.3g} {tol.unit}")
    )
    return f"difference {d} {'≤' if c.adequate else '>'} {tol.describe()}"
