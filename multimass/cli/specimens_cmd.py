"""``multimass specimens``: list the bundled specimens (and the user's own files).

The table stays readable whatever the lengths of its cells: the name, kind and source
columns have capped widths and a long cell wraps onto continuation lines inside its
own column; the description takes the rest of the terminal's width.
"""

from __future__ import annotations

import json
import shutil
import textwrap
from itertools import zip_longest

import multimass.specimens as specimens

__all__ = ["register", "run", "format_table"]

HEADER = {"name": "name", "kind": "kind", "source": "source", "description": "description"}
#: Largest widths of the name and source columns (longer cells wrap).
NAME_WIDTH, SOURCE_WIDTH = 24, 28
#: Narrowest description column, and the width used when the terminal's is unknown.
MIN_DESCRIPTION, DEFAULT_WIDTH = 24, 100
GAP = "  "


def register(sub) -> None:
    p = sub.add_parser("specimens", help="list the bundled specimens (and your own files)")
    p.add_argument(
        "files",
        nargs="*",
        metavar="FILE",
        help="your own specimen TOML files, listed after the bundled ones",
    )
    p.add_argument("--json", action="store_true", help="print a JSON array")
    p.set_defaults(func=run)


def _wrap(text: str, width: int) -> list[str]:
    """Lines of at most `width` characters; a word longer than `width` is split."""
    lines = textwrap.wrap(
        " ".join(str(text).split()), width, break_long_words=True, break_on_hyphens=False
    )
    return lines or [""]


def format_table(rows: list[dict], width: int = DEFAULT_WIDTH) -> list[str]:
    """The lines of a table of `rows` (dicts with name, kind, source, description).

    Every line is at most `width` characters long, unless `width` is below the
    narrowest table (the fixed columns plus `MIN_DESCRIPTION`).
    """
    table = [HEADER, *rows]
    widths = {
        "name": min(NAME_WIDTH, max(len(r["name"]) for r in table)),
        "kind": max(len(r["kind"]) for r in table),
        "source": min(SOURCE_WIDTH, max(len(r["source"]) for r in table)),
    }
    fixed = sum(widths.values()) + len(GAP) * 3
    widths["description"] = max(MIN_DESCRIPTION, width - fixed)
    lines = []
    for r in table:
        cells = [_wrap(r[key], widths[key]) for key in HEADER]
        for parts in zip_longest(*cells, fillvalue=""):
            line = GAP.join(f"{part:<{widths[key]}}" for part, key in zip(parts, HEADER))
            lines.append(line.rstrip())
    return lines


def _row(name: str, spec) -> dict:
    return {"name": name, "kind": spec.kind, "source": spec.source, "description": spec.description}


def run(args) -> int:
    rows = [_row(name, specimens.load(name)) for name in specimens.available()]
    rows += [_row(path, specimens.load(path)) for path in args.files]
    if args.json:
        print(json.dumps(rows, indent=2))
    else:
        width = shutil.get_terminal_size((DEFAULT_WIDTH, 24)).columns
        print("\n".join(format_table(rows, width)))
    return 0
