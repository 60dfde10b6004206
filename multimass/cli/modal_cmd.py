"""``multimass modal``: modal analysis and report of one or more specimens."""

from __future__ import annotations

import json
from pathlib import Path

from ..errors import InputError

__all__ = ["register"]


def register(sub) -> None:
    p = sub.add_parser(
        "modal", help="full-contact and uplifted modes, damping, MAC; Markdown report and figures",
        description="Foss state-space modal analysis of full contact and rocking (paper 001, "
                    "Sections 3 and 4.2), with a report against the published values.")
    p.add_argument("specimens", nargs="+", metavar="SPECIMEN",
                   help="bundled specimen name (see `multimass specimens`) or TOML file")
    p.add_argument("--out", type=Path, default=None,
                   help="folder for the reports and figures (default: modal_report unless --json)")
    p.add_argument("--json", action="store_true",
                   help="print a JSON array, one object per specimen")
    p.add_argument("--measured", type=Path, default=None, metavar="CSV",
                   help="measured mode shapes (nodes x modes) for MAC; one specimen only")
    p.add_argument("--shape-nodes", default=None, metavar="LIST",
                   help="comma-separated 1-based nodes for shapes (default: 2..N)")
    p.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    p.set_defaults(func=run)


def _nodes(text: str | None):
    if text is None:
        return None
    try:
        return tuple(int(x) for x in text.split(",") if x.strip())
    except ValueError:
        raise InputError(f"`--shape-nodes` = {text!r}: give comma-separated node numbers, e.g. 2,3,4,5") from None


def run(args) -> int:
    import modal
    from modal.measured import read_measured_shapes
    from modal.report import summary, write_report

    if args.measured is not None and len(args.specimens) != 1:
        raise InputError(f"`--measured` was given with {len(args.specimens)} specimens; "
                         "measured shapes belong to one specimen: run them one at a time")
    measured = read_measured_shapes(args.measured) if args.measured is not None else None
    out = args.out if args.out is not None or args.json else Path("modal_report")
    results = []
    for name in args.specimens:
        analysis = modal.analyse(name, _nodes(args.shape_nodes))
        if out is not None:
            info = write_report(analysis, out, measured, figures=not args.no_figures)
        else:
            info = summary(analysis, measured)
        results.append(info)
    if args.json:
        print(json.dumps(results, indent=2))
    else:
        for info in results:
            fu = ", ".join(f"{f:.2f}" for f in info["rocking"]["freq_hz"][:3])
            fn = ", ".join(f"{f:.2f}" for f in info["full_contact"]["freq_hz"][:3])
            print(f"{info['specimen']}: full contact {fn} Hz; uplifted {fu} Hz; "
                  f"rocking ±{info['rocking']['rocking_eigenvalues'][0]:.4f} rad/s")
        print(f"reports written to {out}/")
    return 0
