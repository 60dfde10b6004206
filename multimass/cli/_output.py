"""Output folders of the commands, checked before anything is computed.

A run that fails to write its results after an hour of computing has lost the
hour: every command that writes files calls `output_folder` (or, for one named file,
`output_file`) first.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from ..errors import InputError

__all__ = ["output_folder", "output_file", "write_csv"]

#: Seconds to write one row of a run's series as CSV (22–77 µs measured, 2026-11-28; B6M
#: and S1 series of 10⁵ rows): the estimate that decides whether a bar is shown.
_CSV_ROW_SECONDS = 80e-6
_CSV_CHUNK_ROWS = 50_000


def write_csv(table, path, progress: bool | None = None) -> None:
    """Write `table` (a DataFrame) to `path` as CSV without its index, in chunks, with a
    progress bar on stderr when it is estimated to take seconds (`multimass.progress`)."""
    from ..progress import Progress

    n = len(table)
    with Progress(
        n, f"writing {Path(path).name}", show=progress, estimate=n * _CSV_ROW_SECONDS, unit="rows"
    ) as bar:
        if not bar.shown:
            table.to_csv(path, index=False)
            return
        for start in range(0, max(n, 1), _CSV_CHUNK_ROWS):
            part = table.iloc[start : start + _CSV_CHUNK_ROWS]
            part.to_csv(path, index=False, mode="w" if start == 0 else "a", header=start == 0)
            bar.update(start + len(part))


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
    _check_writable(path, f"`{flag}` = {str(path)!r}")
    return path


def output_file(
    path, flag: str = "--out", *, suffix: str = ".csv", force: bool = False, companions=None
) -> Path:
    """Check that the file `path` (and its `companions`) may be written; create its folder.

    Parameters
    ----------
    path : str or Path
        The file to write; its name must end in `suffix`.
    flag : str
        The flag or argument named in messages.
    suffix : str
        The required ending of the file's name, e.g. ``".csv"``.
    force : bool
        Allow replacing existing files (the command's ``--force``).
    companions : callable, optional
        ``companions(path)``: the other files the command writes beside `path` (e.g. a
        sidecar), checked the same way; called once the name of `path` is checked.

    Returns
    -------
    Path

    Raises
    ------
    InputError
        If the name does not end in `suffix`, a file is a folder, exists (without
        `force`), or its folder cannot be created or is not writable.
    """
    path = Path(path)
    if path.suffix.lower() != suffix:
        raise InputError(f"`{flag}` = {str(path)!r}: give a file name ending in {suffix}")
    for p in (path, *(map(Path, companions(path)) if companions else ())):
        if p.is_dir():
            raise InputError(
                f"`{flag}` = {str(path)!r}: {str(p)!r} is a folder; give a file name "
                f"ending in {suffix}"
            )
        if p.exists() and not force:
            raise InputError(
                f"`{flag}` = {str(path)!r}: {str(p)!r} exists; give another name, or add "
                "--force to replace it"
            )
    if path.parent.exists() and not path.parent.is_dir():
        raise InputError(
            f"`{flag}` = {str(path)!r}: {str(path.parent)!r} is a file, not a folder; "
            "give a path in a folder"
        )
    _check_writable(path.parent, f"`{flag}` = {str(path)!r}: its folder {str(path.parent)!r}")
    return path


def _check_writable(folder: Path, what: str) -> None:
    """Create `folder` (with parents) and write a scratch file in it; `what` opens a message."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=folder, prefix=".multimass-write-test-"):
            pass
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise InputError(
            f"{what}: cannot write there ({reason}); give a folder you can write to"
        ) from None
    if not os.access(folder, os.W_OK):
        raise InputError(f"{what}: the folder is not writable; give a folder you can write to")
