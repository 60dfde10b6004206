"""Output folders of the commands, checked before anything is computed.

A run that fails to write its results after an hour of computing has lost the
hour: every command that writes files calls `output_folder` first.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from ..errors import InputError

__all__ = ["output_folder"]


def output_folder(path, flag: str = "--out") -> Path | None:
    """Create the folder `path` (with parents) and check that files can be written in it.

    Parameters
    ----------
    path : str, Path or None
        None: no output (returned as is).
    flag : str
        The flag or argument named in messages.

    Raises
    ------
    InputError
        If `path` is an existing file, cannot be created, or is not writable.
    """
    if path is None:
        return None
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise InputError(
            f"`{flag}` = {str(path)!r} is an existing file; give a folder "
            "(it is created if missing)"
        )
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=path, prefix=".multimass-write-test-"):
            pass
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise InputError(
            f"`{flag}` = {str(path)!r}: cannot write there ({reason}); give a "
            "folder you can write to"
        ) from None
    if not os.access(path, os.W_OK):
        raise InputError(
            f"`{flag}` = {str(path)!r}: the folder is not writable; give a folder you can write to"
        )
    return path
