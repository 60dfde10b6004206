"""``multimass choose``: the cheapest model a scene needs, optionally verified."""

from __future__ import annotations

import json
from pathlib import Path

__all__ = ["register"]


def register(sub) -> None:
    p = sub.add_parser(
        "choose",
        help="pick the cheapest adequate model of a scene (rigid, SDOF, column, NSCD)",
        description="Read a scene (structure, excitation, question, tolerance) and pick the "
        "cheapest model of the ladder rigid body -> SDOF -> n-node -> N-node column "
        "(or rigid block -> block on an FE beam) that the documented a-priori "
        "criteria accept; with --verify also run the next richer model and measure "
        "the difference (see multimass.scenes).",
    )
    p.add_argument(
        "scenes",
        nargs="+",
        type=Path,
        metavar="SCENE.toml",
        help="scene file(s), e.g. examples/scenes/s1_pulse_rotation.toml",
    )
    p.add_argument(
        "--verify",
        action="store_true",
        help="run the neighbouring model(s) and measure the difference",
    )
    p.add_argument(
        "--json",
        action="store_true",
        help="print JSON (one object, or an array for several scenes)",
    )
    p.add_argument(
        "--backend",
        choices=("auto", "compiled", "scipy"),
        default="auto",
        help="simulate() backend for columns and rigid blocks (default: compiled when available)",
    )
    p.set_defaults(func=run)


def _print(choice, scene) -> None:
    print(f"{scene.name} [{scene.source}]")
    print(
        f"  model: {choice.model} — {choice.label}"
        + (
            ""
            if choice.model == choice.a_priori_model
            else f" (a-priori choice: {choice.a_priori_model})"
        )
    )
    from multimass.scenes import format_answer

    print(f"  answer ({scene.question.kind}): {format_answer(choice.answer, choice.unit)}")
    if choice.verified_against is not None:
        tol = choice.tolerance
        diff = (
            "verdicts differ"
            if tol.unit == "verdict" and choice.difference
            else "verdicts agree"
            if tol.unit == "verdict"
            else f"difference {100 * choice.difference:.3g} %"
            if tol.relative
            else f"difference {choice.difference:.3g} {tol.unit}"
        )
        other = format_answer(choice.verified_answer, choice.unit)
        if choice.adequate is None:
            print(
                f"  the cheaper {choice.verified_against} answers {other}: {diff} "
                f"(tolerance {tol.describe()}): NOT adequate, so {choice.model} is needed"
            )
        else:
            print(
                f"  verified against {choice.verified_against}: {other}; {diff} "
                f"(tolerance {tol.describe()}): "
                f"{'adequate' if choice.adequate else 'NOT adequate'}"
            )
    saved = "estimated " if choice.time_saved_estimated else ""
    print(
        f"  time saved: {saved}{choice.time_saved_s:.3f} s (model ran in {choice.wall_time_s:.3f} s)"
    )
    print(f"  reason: {choice.reason}")


def run(args) -> int:
    from ..scenes import Scene, choose

    results = []
    for path in args.scenes:
        scene = Scene.from_toml(path)
        choice = choose(scene, verify=args.verify, backend=args.backend)
        if args.json:
            results.append(
                {**choice.to_dict(), "scene_file": str(path), "scene_description": scene.describe()}
            )
        else:
            _print(choice, scene)
    if args.json:
        print(json.dumps(results[0] if len(results) == 1 else results, indent=2))
    return 0
