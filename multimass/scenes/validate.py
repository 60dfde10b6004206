"""Checks of a `Scene` as a whole: each error names the field, the value and the fix."""

from __future__ import annotations

import math

from ..errors import InputError
from ..inputs.excitations import (
    CosinePulse,
    CosineWave,
    Excitation,
    FreeRelease,
    MPPulse,
    Ricker,
    SineWave,
)
from ..inputs.records import Record
from ..model.structure import column
from .question import IMPACTS, Tolerance

__all__ = ["validate_scene"]

EXCITATIONS = (FreeRelease, SineWave, CosineWave, CosinePulse, Ricker, MPPulse, Record)


def _where(scene) -> str:
    return scene.source or f"scene {scene.name!r}"


def _load(scene, attr: str, field: str, raw):
    try:
        return getattr(scene, attr)
    except ValueError as exc:  # SpecimenError: unknown name, bad file
        raise InputError(f"{_where(scene)}: `{field}` = {raw!r}: {exc}") from None


def _structure(scene, w: str):
    spec = _load(scene, "spec", "structure.specimen", scene.specimen)
    if spec.kind not in ("column", "block"):
        raise InputError(
            f"{w}: `structure.specimen` = {spec.name!r} is a {spec.kind!r} specimen; "
            "give a column (S1, S2, S3) or a block (B4M, B6M, ...); a beam goes in "
            "`structure.beam` under a block"
        )
    if scene.beam is None:
        if scene.E is not None:
            raise InputError(
                f"{w}: `structure.E` = {scene.E!r} without a beam; give "
                "`structure.beam` or remove E"
            )
        return spec
    if spec.kind != "block":
        raise InputError(
            f"{w}: `structure.beam` = {scene.beam!r}: only a block can stand on a "
            f"beam (paper 002), and {spec.name!r} is a column; remove the beam"
        )
    beam = _load(scene, "beam_spec", "structure.beam", scene.beam)
    if beam.kind != "beam":
        raise InputError(
            f"{w}: `structure.beam` = {beam.name!r} is a {beam.kind!r} specimen; give "
            "a beam, e.g. beam_mudric2024"
        )
    if scene.E is not None and not (
        isinstance(scene.E, (int, float)) and math.isfinite(scene.E) and scene.E > 0
    ):
        raise InputError(
            f"{w}: `structure.E` = {scene.E!r}: give the beam's Young's modulus in Pa (> 0)"
        )
    if spec.b >= beam.span:
        raise InputError(
            f"{w}: `structure.specimen` = {spec.name!r} is {spec.b:g} m wide, not "
            f"narrower than the span {beam.span:g} m of {beam.name!r}"
        )
    return spec


def _excitation(scene, spec, w: str):
    exc = scene.excitation
    if not isinstance(exc, EXCITATIONS) or not isinstance(exc, (Excitation, Record)):
        raise InputError(
            f"{w}: `excitation` = {exc!r}: give FreeRelease, SineWave, CosineWave, "
            "CosinePulse, Ricker, MPPulse or a Record (multimass.read_record)"
        )
    if scene.beam is not None and not isinstance(exc, FreeRelease):
        raise InputError(
            f"{w}: `excitation.kind` = {getattr(exc, 'kind', exc)!r}: a block on a "
            "beam is modelled in free rocking only (paper 002's NSCD model has no "
            'ground motion); release it with kind = "free_release" or remove the beam'
        )
    if isinstance(exc, FreeRelease):
        alpha = spec.alpha if spec.kind == "block" else _alpha_cg(spec)
        if exc.theta0 == 0.0 and exc.u0 is None:
            raise InputError(
                f"{w}: `excitation.theta0` = 0: a free release from rest at θ = 0 "
                "does not move; give a release angle, e.g. theta0_rad = 0.08"
            )
        if abs(exc.theta0) >= alpha:
            raise InputError(
                f"{w}: `excitation.theta0` = {exc.theta0!r} rad is beyond the "
                f"overturning angle {alpha:.4f} rad of {spec.name!r}; release it from "
                "a smaller angle"
            )
        if exc.u0 is not None and spec.kind != "column":
            raise InputError(
                f"{w}: `excitation.u0` = {exc.u0!r}: a rigid block has no elastic "
                "nodes to displace; remove u0"
            )


def _alpha_cg(spec) -> float:
    return column(spec).alpha_cg


def _question(scene, spec, w: str):
    q = scene.question
    if q.kind in ("peak_acceleration", "uplifted_frequencies") and spec.kind != "column":
        raise InputError(
            f"{w}: `question.kind` = {q.kind!r}: a rigid block has no elastic nodes "
            "or vibration modes; ask peak_rotation or overturning"
        )
    if q.kind == "peak_acceleration":
        n = len(spec.heights)
        if q.node is not None and q.node > n:
            raise InputError(f"{w}: `question.node` = {q.node!r}: {spec.name!r} has nodes 1..{n}")
        if q.sensor is not None:
            try:
                spec.sensor_node(q.sensor)
            except ValueError as exc:
                raise InputError(f"{w}: `question.sensor` = {q.sensor!r}: {exc}") from None
    if q.kind == "uplifted_frequencies" and q.n_modes > len(spec.heights):
        raise InputError(
            f"{w}: `question.n_modes` = {q.n_modes!r}: {spec.name!r} has only "
            f"{len(spec.heights)} vibration modes"
        )


def _tolerance(scene, w: str):
    q, tol = scene.question, scene.tolerance
    if q.kind == "overturning":
        if tol is not None and tol.unit != "verdict":
            raise InputError(
                f"{w}: `tolerance` = {tol.describe()!r}: an overturning question "
                "compares verdicts, which must agree; remove the [tolerance] table"
            )
        return
    if not isinstance(tol, Tolerance):
        raise InputError(
            f"{w}: `tolerance` = {tol!r}: a {q.kind} question needs a tolerance, "
            "e.g. [tolerance] relative = 0.05"
        )
    if not tol.relative and tol.unit != q.unit:
        raise InputError(
            f"{w}: `tolerance` = {tol.describe()!r}: the answer to {q.kind} is in "
            f"{q.unit}; give the tolerance in {q.unit} or as `relative`"
        )


def _options(scene, w: str):
    if scene.t_end is not None and not (
        isinstance(scene.t_end, (int, float)) and math.isfinite(scene.t_end) and scene.t_end > 0
    ):
        raise InputError(
            f"{w}: `simulation.t_end_s` = {scene.t_end!r}: give a positive duration in s"
        )
    if scene.impact is not None and (
        not isinstance(scene.impact, str) or scene.impact.upper() not in IMPACTS
    ):
        raise InputError(
            f"{w}: `simulation.impact` = {scene.impact!r}: use one of "
            f"{', '.join(IMPACTS)} (paper 001, Table 2)"
        )
    ms = scene.max_step
    if ms is not None and (
        isinstance(ms, bool) or not isinstance(ms, (int, float)) or not 0 < ms < math.inf
    ):
        raise InputError(
            f"{w}: `simulation.max_step_s` = {ms!r}: give the largest solver step "
            "in s (> 0), e.g. 1e-3"
        )
    r = scene.restitution
    if r is not None and (isinstance(r, bool) or not isinstance(r, (str, int, float))):
        raise InputError(
            f"{w}: `simulation.restitution` = {r!r}: give a name (housner, "
            "modified, mean, random, r_h) or a number in (0, 1]"
        )
    if not (isinstance(scene.nscd_dt, (int, float)) and 0 < scene.nscd_dt < 1e-2):
        raise InputError(
            f"{w}: `simulation.nscd_dt_s` = {scene.nscd_dt!r}: give the NSCD time "
            "step in s, in (0, 0.01) (paper 002 uses 1e-4 to 1e-6)"
        )
    n_el = scene.nscd_elements
    if n_el is not None and (isinstance(n_el, bool) or not isinstance(n_el, int) or n_el < 3):
        raise InputError(
            f"{w}: `simulation.nscd_elements` = {n_el!r}: give an integer >= 3 "
            "(paper 002 uses 3, 6 and 12)"
        )


def validate_scene(scene) -> None:
    """Raise `InputError` for the first inconsistent field of `scene`."""
    if not isinstance(scene.name, str) or not scene.name.strip():
        raise InputError(f"`name` = {scene.name!r}: give the scene a name")
    w = _where(scene)
    spec = _structure(scene, w)
    _excitation(scene, spec, w)
    _question(scene, spec, w)
    _tolerance(scene, w)
    _options(scene, w)
