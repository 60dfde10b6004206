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
import re
import sys
import time

__all__ = ["main", "build_parser", "command_modules", "attach_negative_values"]


def command_modules() -> list[str]:
    """Names of the sub-command modules (``*_cmd``), sorted."""
    return sorted(m.name for m in pkgutil.iter_modules(__path__) if m.name.endswith("_cmd"))


class _Parser(argparse.ArgumentParser):
    """argparse, with a mistake reported in one line (no usage dump) and exit status 2."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see `{self.prog} --help`)\n")


def build_parser() -> argparse.ArgumentParser:
    """The full argument parser with every sub-command registered."""
    parser = _Parser(
        prog="multimass",
        description="Rocking structures: modal analysis, time histories, overturning maps.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in command_modules():
        importlib.import_module(f"{__name__}.{name}").register(sub)
    return parser


# a value that starts with a minus sign: a number, a range START:STOP:COUNT or a list
_NEGATIVE_VALUE = re.compile(r"^-(\d|\.\d)[\w.:+,-]*$")


def attach_negative_values(argv: list[str]) -> list[str]:
    """``--flag -1:10:6`` → ``--flag=-1:10:6``.

    argparse takes a token that starts with '-' for an option unless it is a plain
    negative number, so a negative range (``--omega-p -1:10:6``) was refused with
    "expected one argument" instead of reaching the range's own check, which says
    what is wrong with it.
    """
    out: list[str] = []
    for token in argv:
        if out and _NEGATIVE_VALUE.match(token) and out[-1].startswith("--") and "=" not in out[-1]:
            out[-1] = f"{out[-1]}={token}"
        else:
            out.append(token)
    return out


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``multimass`` console script."""
    started = time.perf_counter()  # the command's start: the commands' wall times count from it
    parser = build_parser()
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        args = parser.parse_args(attach_negative_values(argv))
    except SystemExit as done:  # --help, or a mistake argparse reported in one line
        return int(done.code or 0) if not isinstance(done.code, str) else 2
    args.started = started
    try:
        return int(args.func(args) or 0)
    except ValueError as exc:  # the packages' own errors all derive from ValueError
        print(f"multimass {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except MemoryError:
        print(
            f"multimass {args.command}: error: out of memory; reduce the size of the run "
            "(end time, output step, grid, elements)",
            file=sys.stderr,
        )
        return 2
    except BrokenPipeError:  # output piped into e.g. `head`: not an error of ours
        sys.stderr.close()
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
