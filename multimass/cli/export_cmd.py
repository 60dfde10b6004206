"""``multimass export``: write a specimen's model for another engine (OpenSeesPy)."""

from __future__ import annotations

import json
from pathlib import Path

from ..errors import InputError
from ..export import PHASES, opensees
from ..inputs.records import read_record
from . import _types as types

__all__ = ["register", "run"]


def register(sub) -> None:
    p = sub.add_parser(
        "export",
        help="write a specimen's model as a standalone OpenSeesPy script",
        description="Write a standalone OpenSeesPy script of a specimen in one phase: "
        + "; ".join(f"{k}: {v}" for k, v in PHASES.items())
        + ". `python model.py` builds, runs and writes theta.out, disp.out, accel.out; "
        "`build(ops)` adds the model to a larger one.",
    )
    p.add_argument(
        "specimen",
        metavar="SPECIMEN",
        help="bundled specimen name (see `multimass specimens`) or TOML file "
        "(e.g. one written by `multimass calibrate --out`)",
    )
    p.add_argument("--to", choices=("opensees",), default="opensees", help="target engine")
    p.add_argument("--phase", choices=tuple(PHASES), default="full-contact", help="model phase")
    p.add_argument("--out", type=Path, required=True, help="the script to write, e.g. model.py")
    p.add_argument("--record", type=Path, default=None, help="ground motion: .AT2 or `t a` file")
    p.add_argument("--units", default=None, help="units of a two-column record: g, m/s2, ...")
    p.add_argument("--scale", type=types.positive, default=1.0, help="scale factor of the record")
    p.add_argument(
        "--release",
        type=types.finite,
        default=None,
        metavar="THETA0",
        help="rocking: release from rest at θ0 (rad)",
    )
    p.add_argument("--t-end", type=types.positive, default=None, help="end time (s)")
    p.add_argument("--dt", type=types.positive, default=None, help="analysis step (s)")
    p.add_argument(
        "--output-dt", type=types.positive, default=1e-3, help="recorders' step (s), default 1e-3"
    )
    p.add_argument(
        "--contact-damping",
        type=types.positive,
        default=None,
        metavar="ZETA_C",
        help="rocking: damping ratio of the contact springs (default 0.01 for a block, 0.1 for a column)",
    )
    p.add_argument("--json", action="store_true", help="print what was written as JSON")
    p.set_defaults(func=run)


def run(args) -> int:
    if args.record is None and (args.units is not None or args.scale != 1.0):
        raise InputError("--units and --scale apply to a record: give --record FILE too")
    record = None
    if args.record is not None:
        record = read_record(args.record, units=args.units, scale=args.scale)
    text = opensees(
        args.specimen,
        args.phase,
        record,
        out=args.out,
        t_end=args.t_end,
        dt=args.dt,
        output_dt=args.output_dt,
        release=args.release,
        contact_damping=args.contact_damping,
    )
    info = {
        "specimen": str(args.specimen),
        "phase": args.phase,
        "out": str(args.out),
        "lines": text.count("\n"),
        "record": None if record is None else record.describe(),
    }
    if args.json:
        print(json.dumps(info, default=str))
    else:
        print(
            f"wrote {args.out} ({info['lines']} lines): {args.specimen}, {args.phase}; "
            f"run it with `python {args.out}`"
        )
    return 0
