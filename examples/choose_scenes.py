"""Choose and verify the model of every example scene; print the README's Markdown table.

For each scene in examples/scenes/ this runs ``multimass.choose(scene, verify=True)``:
the a-priori criteria pick a rung of the model ladder, the next richer rung is run
on the same scene and the difference is measured against the scene's tolerance.

Run:  python examples/choose_scenes.py            (about 10 s with the compiled backend)
      python examples/choose_scenes.py --scipy-times   (adds the time saved on the SciPy
                                                    reference backend: 1-2 minutes)
The same for one scene from the shell:  multimass choose examples/scenes/X.toml --verify
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import multimass
from multimass.scenes import Scene, format_answer, ladder

SCENES = Path(__file__).resolve().parent / "scenes"


def fmt_diff(choice) -> str:
    tol = choice.tolerance
    if choice.difference is None:
        return f"– / {tol.describe()}"
    if tol.unit == "verdict":
        d = "differ" if choice.difference else "agree"
        return f"verdicts {d}"
    d = (
        f"{100 * choice.difference:.3g} %"
        if tol.relative
        else f"{choice.difference:.3g} {tol.unit}"
    )
    return f"{d} / {tol.describe()}"


def verdict(choice) -> str:
    if choice.adequate is None:
        return "cheaper model NOT adequate" if choice.verified_against else "only model"
    return "adequate" if choice.adequate else "NOT adequate"


def rejected(choice) -> str:
    """Cheaper models the verification measured and found NOT adequate."""
    out = [
        f"{c.model}: {fmt_cmp(c, choice.tolerance)}"
        for c in choice.comparisons
        if not c.adequate and choice.ladder.index(c.model) < choice.ladder.index(choice.model)
    ]
    return "; ".join(out) or "–"


def fmt_cmp(c, tol) -> str:
    if tol.unit == "verdict":
        return f"{'overturns' if c.answer else 'stands'} vs {'overturns' if c.reference_answer else 'stands'}"
    if not math.isfinite(c.difference):
        return "inf"
    return f"{100 * c.difference:.3g} %" if tol.relative else f"{c.difference:.3g} {tol.unit}"


def scipy_saving(scene, choice) -> str:
    """Time saved by the choice with the SciPy reference backend (reruns the two rungs)."""
    if choice.verified_against is None or choice.adequate is None:
        return "–"
    rungs = {r.name: r for r in ladder(scene)}
    a = rungs[choice.model].answer(scene, "scipy")
    b = rungs[choice.verified_against].answer(scene, "scipy")
    return f"{b.wall_time_s - a.wall_time_s:.2f}"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--scipy-times",
        action="store_true",
        help="also time the chosen and the richer model on the SciPy backend",
    )
    parser.add_argument("scenes", nargs="*", type=Path, help="scene files (default: all examples)")
    args = parser.parse_args(argv)
    files = args.scenes or sorted(SCENES.glob("*.toml"))
    head = [
        "scene",
        "question",
        "chosen model (a priori)",
        "its answer",
        "compared with",
        "its answer",
        "difference / tolerance",
        "verdict",
        "cheaper models NOT adequate",
        "time saved (s)",
    ]
    if args.scipy_times:
        head.append("time saved, SciPy (s)")
    rows = []
    start = time.perf_counter()
    for path in files:
        scene = Scene.from_toml(path)
        c = multimass.choose(scene, verify=True)
        q = scene.question.kind + (
            f" @{scene.question.sensor or 'node ' + str(scene.node)}" if scene.node else ""
        )
        model = c.model if c.model == c.a_priori_model else f"{c.model} ({c.a_priori_model})"
        row = [
            f"`{path.name}`",
            q,
            model,
            format_answer(c.answer, c.unit),
            c.verified_against or "–",
            format_answer(c.verified_answer, c.unit) if c.verified_answer is not None else "–",
            fmt_diff(c),
            verdict(c),
            rejected(c),
            f"{c.time_saved_s:.3f}",
        ]
        if args.scipy_times:
            row.append(scipy_saving(scene, c))
        rows.append(row)
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for row in rows:
        print("| " + " | ".join(row) + " |")
    print(f"\n{len(rows)} scenes in {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
