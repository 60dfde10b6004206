"""``multimass modal``: modal analysis and report of one or more specimens."""

from __future__ import annotations

import json
import re
from pathlib import Path

from ..errors import InputError

__all__ = ["register"]


def register(sub) -> None:
    p = sub.add_parser(
        "modal",
        help="full-contact and uplifted modes, damping, MAC; Markdown report and figures",
        description="Foss state-space modal analysis of full contact and rocking (paper 001, "
        "Sections 3 and 4.2), with a report against the published values.",
    )
    p.add_argument(
        "specimens",
        nargs="+",
        metavar="SPECIMEN",
        help="bundled specimen name (see `multimass specimens`) or TOML file",
    )
    p.add_argument(
        "--out",
        type=Path,
        default=None,
        help="folder for the reports and figures (default: modal_report unless --json)",
    )
    p.add_argument(
        "--json", action="store_true", help="print a JSON array, one object per specimen"
    )
    p.add_argument(
        "--measured",
        type=Path,
        default=None,
        metavar="CSV",
        help="measured mode shapes (nodes x modes) for MAC; one specimen only",
    )
    p.add_argument(
        "--shape-nodes",
        default=None,
        metavar="LIST",
        help="comma-separated 1-based nodes for shapes (default: 2..N)",
    )
    p.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    p.set_defaults(func=run)


def _nodes(text: str | None):
    """Parse ``--shape-nodes 2,3,4``: integers separated by commas, nothing else."""
    if text is None:
        return None
    items = [x.strip() for x in text.split(",")]
    if not all(re.fullmatch(r"[0-9]+", x) for x in items):
        raise InputError(
            f"`--shape-nodes` = {text!r}: give comma-separated integer node numbers, e.g. 2,3,4,5"
        )
    return tuple(int(x) for x in items)


def _ranges(modes) -> str:
    """1, 3, 4, 5 -> "1, 3–5"."""
    out, run = [], []
    for j in list(modes) + [None]:
        if run and (j is None or j != run[-1] + 1):
            out.append(str(run[0]) if len(run) == 1 else f"{run[0]}–{run[-1]}")
            run = []
        if j is not None:
            run.append(j)
    return ", ".join(out)


def _first_modes(phase: dict, k: int = 3) -> str:
    """Frequencies of modes 1..k by mode number; an overdamped one is marked."""
    freq = dict(zip(phase["mode"], phase["freq_hz"]))
    od = dict(zip(phase["overdamped"]["mode"], phase["overdamped"]["freq_hz"]))
    return ", ".join(
        f"{freq[j]:.2f}" if j in freq else f"{od[j]:.2f} (overdamped)"
        for j in range(1, k + 1)
        if j in freq or j in od
    )


def _line(info: dict) -> str:
    text = (
        f"{info['specimen']}: full contact {_first_modes(info['full_contact'])} Hz; "
        f"uplifted {_first_modes(info['rocking'])} Hz; "
        f"rocking ±{info['rocking']['rocking_eigenvalues'][0]:.4f} rad/s"
    )
    od = [
        f"{name} {_ranges(info[key]['overdamped']['mode'])}"
        for name, key in (("full contact", "full_contact"), ("uplifted", "rocking"))
        if info[key]["overdamped"]["mode"]
    ]
    return text + (f"; overdamped modes: {'; '.join(od)}" if od else "")


def run(args) -> int:
    import multimass.modal as modal
    from multimass.modal.measured import read_measured_shapes
    from multimass.modal.report import summary, write_report
    from multimass.modal.validate import validate_shape_nodes, validate_structure

    if args.measured is not None and len(args.specimens) != 1:
        raise InputError(
            f"`--measured` was given with {len(args.specimens)} specimens; "
            "measured shapes belong to one specimen: run them one at a time"
        )
    measured = read_measured_shapes(args.measured) if args.measured is not None else None
    out = args.out if args.out is not None or args.json else Path("modal_report")
    results = []
    for name in args.specimens:
        structure = validate_structure(name)
        default = modal.default_shape_nodes(structure.n)
        nodes = validate_shape_nodes(
            _nodes(args.shape_nodes),
            structure.n,
            default,
            "--shape-nodes",
            "--shape-nodes " + ",".join(map(str, default[:3])),
        )
        analysis = modal.analyse(structure, nodes)
        if out is not None:
            info = write_report(analysis, out, measured, figures=not args.no_figures)
        else:
            info = summary(analysis, measured)
        results.append(info)
    if args.json:
        print(json.dumps(results, indent=2))
    else:
        for info in results:
            print(_line(info))
        print(f"reports written to {out}/")
    return 0
