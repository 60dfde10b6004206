"""``multimass specimens``: list the bundled specimens."""

from __future__ import annotations

import json

import specimens

__all__ = ["register"]


def register(sub) -> None:
    p = sub.add_parser("specimens", help="list the bundled specimens")
    p.add_argument("--json", action="store_true", help="print a JSON array")
    p.set_defaults(func=run)


def run(args) -> int:
    rows = []
    for name in specimens.available():
        spec = specimens.load(name)
        rows.append({"name": name, "kind": spec.kind, "source": spec.source,
                     "description": spec.description})
    if args.json:
        print(json.dumps(rows, indent=2))
    else:
        width = max(len(r["name"]) for r in rows)
        for r in rows:
            print(f"{r['name']:<{width}}  {r['kind']:<7} {r['source']:<22} {r['description']}")
    return 0
