"""The ``multimass`` command line: a thin layer over the public functions.

Each sub-command lives in its own module ``*_cmd.py`` of this package and
exposes ``register(subparsers)``, which adds its parser and sets ``func``;
modules are found by name, so adding a command touches no other file.
Errors a user can fix (subclasses of ValueError) print one clear line and
exit with status 2; every result can be printed as JSON.
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys

__all__ = ["main", "build_parser", "command_modules"]


def command_modules() -> list[str]:
    """Names of the sub-command modules (``*_cmd``), sorted."""
    return sorted(m.name for m in pkgutil.iter_modules(__path__) if m.name.endswith("_cmd"))


def build_parser() -> argparse.ArgumentParser:
    """The full argument parser with every sub-command registered."""
    parser = argparse.ArgumentParser(
        prog="multimass",
        description="Rocking structures: modal analysis, time histories, overturning maps.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in command_modules():
        importlib.import_module(f"{__name__}.{name}").register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``multimass`` console script."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except ValueError as exc:  # the packages' own errors all derive from ValueError
        print(f"multimass {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into e.g. `head`: not an error of ours
        sys.stderr.close()
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
