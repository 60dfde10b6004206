"""Opening a user's text file: one reader, so every file argument fails the same clear way.

`read_text` returns the text of a UTF-8 file or raises `InputError` naming the path,
what is wrong with it (missing, a directory, unreadable, empty, binary, not UTF-8) and
what to give instead. The record, trace and scene readers call it before parsing.

>>> read_text("no/such.csv", what="a trace CSV file")
Traceback (most recent call last):
...
multimass.errors.InputError: `path` = 'no/such.csv': no such file; give a trace CSV file
"""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import InputError

__all__ = ["as_path", "read_text"]

#: Names of files listed when a directory is given instead of a file.
_LISTED = 5


def _cut(value, limit: int = 80) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 1] + "…"


def as_path(value, *, what: str, argument: str = "path") -> Path:
    """`value` as a Path, if it is a non-empty str or os.PathLike; else InputError."""
    if isinstance(value, bytes) or not isinstance(value, (str, os.PathLike)):
        raise InputError(
            f"`{argument}` = {_cut(value)}: give the path of {what} (a str or pathlib.Path)"
        )
    text = os.fspath(value)
    if not isinstance(text, str) or not text.strip() or "\0" in text:
        raise InputError(f"`{argument}` = {_cut(text)}: not a usable path; give the path of {what}")
    return Path(text)


def _files_in(folder: Path, suffixes: tuple[str, ...]) -> str:
    try:
        names = sorted(
            p.name
            for p in folder.iterdir()
            if p.is_file() and (not suffixes or p.suffix.lower() in suffixes)
        )
    except OSError:
        return ""
    if not names:
        return ""
    more = f", … ({len(names)} in all)" if len(names) > _LISTED else ""
    return f" (files there: {', '.join(names[:_LISTED])}{more})"


def read_text(path, *, what: str, argument: str = "path", suffixes: tuple[str, ...] = ()) -> str:
    """The text of a UTF-8 file (a leading byte-order mark is dropped).

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    what : str
        What the file should be, for messages ("a record file: two columns `t a`").
    argument : str, optional
        The argument's name, for messages.
    suffixes : tuple of str, optional
        Lower-case suffixes (".csv") of the files to suggest when `path` is a directory.

    Returns
    -------
    str

    Raises
    ------
    InputError
        If `path` is not a path, does not exist, is a directory, cannot be read,
        is empty, holds NUL bytes (a binary file) or is not UTF-8 text.
    """
    p = as_path(path, what=what, argument=argument)
    where = f"`{argument}` = {str(p)!r}"
    if p.is_dir():
        raise InputError(f"{where} is a directory; give {what} inside it{_files_in(p, suffixes)}")
    try:
        data = p.read_bytes()
    except FileNotFoundError:
        raise InputError(f"{where}: no such file; give {what}") from None
    except OSError as exc:
        raise InputError(
            f"{where}: cannot be read ({exc.strerror or exc}); give a readable file: {what}"
        ) from None
    if not data.strip():
        raise InputError(f"{where}: the file is empty; give {what}")
    nul = data.find(b"\0")
    if nul >= 0:
        raise InputError(
            f"{where}: a binary file (NUL byte at offset {nul}), not text; give {what}"
        )
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise InputError(
            f"{where}: not UTF-8 text (byte 0x{data[exc.start]:02x} on line {line}); "
            f"save it as UTF-8 (or plain ASCII) and give {what}"
        ) from None
