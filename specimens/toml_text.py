"""Specimen files written back: a specimen's TOML text with some tables replaced.

Identification and calibration (`multimass.identify`) end in new values for a few
tables of a specimen — ``[restitution]``, ``[damping]``, ``[impact]`` — and write a
specimen file that `load` reads: the original file's text, comments included, with
those tables replaced (or appended) and a comment saying where the values came from.

>>> text = '''kind = "column"
... [damping]
... zeta_1 = 0.005
... zeta_2 = 0.015
... '''
>>> print(replace_tables(text, {"damping": {"zeta_1": 0.006, "zeta_2": 0.02}}, note="fitted"))
kind = "column"
# fitted
[damping]
zeta_1 = 0.006
zeta_2 = 0.02
<BLANKLINE>
"""

from __future__ import annotations

import math
import re
import tomllib
from collections.abc import Mapping

from .errors import SpecimenError
from .loader import from_mapping

__all__ = ["format_table", "replace_tables", "specimen_text"]

_HEADER = re.compile(r"^\s*\[\s*([A-Za-z0-9_.\-]+)\s*\]\s*(#.*)?$")


def _value(key: str, value) -> str:
    """A TOML value: a finite number, a string, a bool or a list of them."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise SpecimenError(f"`{key}` = {value!r}: a specimen file holds finite numbers only")
        return repr(value)
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_value(key, v) for v in value) + "]"
    try:  # numpy scalars
        return _value(key, value.item())
    except AttributeError:
        raise SpecimenError(
            f"`{key}` = {value!r:.60}: give a number, a string or a list of them"
        ) from None


def format_table(name: str, values: Mapping, comments: Mapping | None = None) -> str:
    """The text of a TOML table ``[name]`` with one ``key = value`` line per entry.

    Parameters
    ----------
    name : str
        The table's name.
    values : mapping
        Key → number, string, bool or list.
    comments : mapping, optional
        Key → a comment written after its value.
    """
    comments = comments or {}
    lines = [f"[{name}]"]
    for key, value in values.items():
        line = f"{key} = {_value(key, value)}"
        if key in comments:
            line += f"   # {comments[key]}"
        lines.append(line)
    return "\n".join(lines) + "\n"


def replace_tables(text: str, tables: Mapping, *, note: str = "", comments=None) -> str:
    """`text` with each table of `tables` replaced (in place) or appended.

    Parameters
    ----------
    text : str
        A specimen's TOML text.
    tables : mapping
        Table name → mapping of its new entries (the whole table: keys not given are
        dropped).
    note : str, optional
        A comment line written above each replaced table.
    comments : mapping, optional
        Table name → {key: comment}.

    Returns
    -------
    str
        The new text; it parses as TOML (checked).
    """
    comments = comments or {}
    lines = text.splitlines()
    out: list[str] = []
    done = set()
    skipping = False
    for line in lines:
        m = _HEADER.match(line)
        if m:
            skipping = m.group(1) in tables
            if skipping:
                name = m.group(1)
                if note:
                    out.append(f"# {note}")
                out.extend(format_table(name, tables[name], comments.get(name)).splitlines())
                out.append("")
                done.add(name)
                continue
        if not skipping:
            out.append(line)
    for name, values in tables.items():
        if name not in done:
            if out and out[-1].strip():
                out.append("")
            if note:
                out.append(f"# {note}")
            out.extend(format_table(name, values, comments.get(name)).splitlines())
    new = "\n".join(out).rstrip("\n") + "\n"
    try:
        tomllib.loads(new)
    except tomllib.TOMLDecodeError as exc:  # pragma: no cover - our own formatting
        raise SpecimenError(f"the rewritten specimen is not TOML ({exc})") from exc
    return new


def specimen_text(
    specimen, tables: Mapping, *, note: str = "", comments=None, name=None, path=None
) -> str:
    """The TOML text of a specimen's file with `tables` replaced, checked by loading.

    Parameters
    ----------
    specimen : specimen object
        A loaded specimen, e.g. ``specimens.load("S1")``.
    tables, note, comments
        As in `replace_tables`.
    name : str, optional
        A new ``name`` for the specimen.
    path : str or Path, optional
        The specimen's file; default the bundled file of its name.

    Raises
    ------
    SpecimenError
        If there is no file to start from, or the new values do not make a valid
        specimen (the message names the field).
    """
    from .loader import _locate

    label = getattr(specimen, "name", "?")
    try:
        path = _locate(path if path is not None else label)
    except SpecimenError:
        raise SpecimenError(
            f"specimen {label!r}: its TOML file is unknown; give the file it was loaded "
            "from (path=...)"
        ) from None
    text = path.read_text(encoding="utf-8")
    if name is not None:
        text = re.sub(
            r'^(\s*name\s*=\s*)"[^"]*"', lambda m: m.group(1) + _value("name", name), text,
            count=1, flags=re.M,
        )  # fmt: skip
    new = replace_tables(text, tables, note=note, comments=comments)
    from_mapping(tomllib.loads(new), f"{path.name} with new {', '.join(tables)}")
    return new
