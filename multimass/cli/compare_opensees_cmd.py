"""``multimass compare-opensees``: one rocking run in both engines, overlaid and measured."""

from __future__ import annotations

import json
from pathlib import Path

from ..errors import InputError
from ..export.side_by_side import compare_rocking
from ..export.side_by_side_plots import plot_side_by_side
from ..inputs.excitations import FreeRelease
from ..inputs.records import read_record
from . import _types as types

__all__ = ["register", "run"]


def register(sub) -> None:
    p = sub.add_parser(
        "compare-opensees",
        help="run a specimen in multimass (CIM, DD2) and in its exported OpenSees rocking "
        "model; overlay θ(t), impacts, peaks, energy lost, run times",
        description="Runs the toolkit's rigid-contact models and the OpenSees rocking model "
        "(compression-only contact springs, `multimass export --phase rocking`) for a free "
        "release or a record, and writes a figure and a JSON of both engines' impact times, "
        "half-cycle peaks, energy lost per impact and run times. For a rigid block released "
        "freely, Housner's decay (r = 1 - 1.5 sin^2 alpha per impact) is drawn too.",
    )
    p.add_argument("specimen", metavar="SPECIMEN", help="bundled specimen name or TOML file")
    g = p.add_argument_group("excitation (one of)")
    g.add_argument(
        "--release",
        type=types.finite,
        default=None,
        metavar="THETA0",
        help="free release from θ0 (rad)",
    )
    g.add_argument("--record", type=Path, default=None, help="ground motion: .AT2 or `t a` file")
    g.add_argument("--units", default=None, help="units of a two-column record: g, m/s2, ...")
    g.add_argument("--scale", type=types.positive, default=1.0, help="scale factor of the record")
    p.add_argument("--t-end", type=types.positive, default=4.0, help="end time (s), default 4")
    p.add_argument(
        "--impact",
        default="CIM,DD2",
        help="comma-separated impact models of the toolkit's runs (default CIM,DD2)",
    )
    p.add_argument(
        "--contact-damping",
        type=types.positive,
        default=None,
        metavar="ZETA_C",
        help="damping ratio of the OpenSees contact springs (default 0.01 for a block, 0.1 for a column)",
    )
    p.add_argument(
        "--out",
        type=Path,
        default=Path("compare_opensees"),
        help="folder for <name>.png and <name>.json (default compare_opensees)",
    )
    p.add_argument("--name", default=None, help="file stem (default SPECIMEN_release or _record)")
    p.add_argument("--json", action="store_true", help="print the numbers as JSON")
    p.set_defaults(func=run)


def run(args) -> int:
    if (args.release is None) == (args.record is None):
        raise InputError("give one excitation: --release THETA0 or --record FILE")
    if args.out.exists() and not args.out.is_dir():
        raise InputError(f"--out {args.out}: is a file; give a folder")
    if args.record is not None:
        excitation = read_record(args.record, units=args.units, scale=args.scale)
    else:
        excitation = FreeRelease(theta0=args.release)
    impacts = tuple(m.strip() for m in args.impact.split(",") if m.strip())
    result = compare_rocking(
        args.specimen,
        excitation,
        args.t_end,
        impacts=impacts,
        contact_damping=args.contact_damping,
    )
    stem = args.name or f"{result.name}_{'release' if args.record is None else 'record'}"
    args.out.mkdir(parents=True, exist_ok=True)
    plot_side_by_side(result, args.out / f"{stem}.png")
    summary = result.summary()
    (args.out / f"{stem}.json").write_text(json.dumps(summary, indent=1))
    if args.json:
        print(json.dumps(summary))
    else:
        for engine, row in summary["engines"].items():
            peaks = ", ".join(f"{p:.4f}" for p in row["peaks_rad"][:6])
            print(
                f"{engine:>9}: {row['wall_time_s']:.3g} s, {len(row['impact_times_s'])} impacts, "
                f"peaks {peaks} rad"
            )
        print(f"wrote {args.out / (stem + '.png')} and {stem}.json")
    return 0
