"""Find, read and validate specimen files, bundled or the user's own."""

from __future__ import annotations

import functools
import os
import tomllib
from collections.abc import Callable, Mapping
from importlib import resources
from pathlib import Path

from ._fields import show
from .beam import beam_from_mapping
from .block import block_from_mapping
from .column import column_from_mapping
from .errors import SpecimenError

__all__ = ["load", "available", "from_mapping", "register_kind"]

_DATA = "data"

#: Specimens read in this process, by (resolved path, modification time, size): a file
#: is parsed and validated once until it changes (a run by name re-read it each call,
#: 1.1 ms of a 12 ms compiled run). Specimens are frozen dataclasses of scalars and
#: tuples, so sharing one is safe.
_LOADED: dict[tuple, object] = {}
_LOADED_MAX = 64

#: kind name -> builder(mapping, source) -> specimen
_KINDS: dict[str, Callable[[Mapping, str], object]] = {
    "column": column_from_mapping,
    "block": block_from_mapping,
    "beam": beam_from_mapping,
}


def register_kind(kind: str, builder: Callable[[Mapping, str], object]) -> None:
    """Make `load` understand files with ``kind = "<kind>"``."""
    _KINDS[kind] = builder


@functools.cache
def _bundled() -> dict[str, Path]:
    """Name -> file of the bundled specimens (package data: listed once per process)."""
    root = resources.files(__package__) / _DATA
    return {Path(p.name).stem: Path(str(p)) for p in root.iterdir() if p.name.endswith(".toml")}


def available() -> list[str]:
    """Names of the specimens shipped with the package, sorted."""
    return sorted(_bundled())


def from_mapping(data: Mapping, source: str = "<mapping>"):
    """Validate an already-parsed specimen mapping and build its specimen object.

    Parameters
    ----------
    data : mapping
        A parsed specimen TOML document (``kind``, ``name`` and the tables of its kind).
    source : str, optional
        Where it came from, used in error messages.

    Raises
    ------
    SpecimenError
        If `data` is not a mapping, or its ``kind`` or any field is invalid.
    """
    if not isinstance(data, Mapping):
        raise SpecimenError(
            f"{source}: expected a mapping of specimen fields (a parsed TOML "
            f"document), got {type(data).__name__} {show(data)}"
        )
    if "kind" not in data:
        raise SpecimenError(f'{source}: missing key `kind`; add e.g. kind = "column" at the top')
    kind = data["kind"]
    if not isinstance(kind, str) or kind not in _KINDS:
        raise SpecimenError(
            f"{source}: `kind` = {show(kind)}: unknown kind; use one of "
            + ", ".join(repr(k) for k in sorted(_KINDS))
        )
    return _KINDS[kind](data, source)


def load(name_or_path: str | Path):
    """Load a specimen by bundled name (``"S1"``) or from a TOML file path.

    Parameters
    ----------
    name_or_path : str or pathlib.Path
        A bundled name (see `available`, case-insensitive) or the path of a
        TOML file of the same format.

    Returns
    -------
    specimen
        A frozen dataclass, e.g. `ColumnSpecimen`, whose type follows the
        file's ``kind``.

    Raises
    ------
    SpecimenError
        If the name is unknown, the file is missing or not TOML, or its
        contents are invalid (the message names the field and the fix).
    """
    path = _locate(name_or_path)
    try:
        stat = path.stat()
        key = (str(path.resolve()), stat.st_mtime_ns, stat.st_size)
        if key in _LOADED:
            return _LOADED[key]
        with path.open("rb") as fh:
            data = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise SpecimenError(f"{path}: not a valid TOML file ({exc}); check its syntax") from exc
    except UnicodeDecodeError as exc:
        raise SpecimenError(
            f"{path}: not a UTF-8 text file ({exc}); give a specimen TOML file saved as UTF-8"
        ) from exc
    except OSError as exc:
        raise SpecimenError(
            f"{path}: cannot be read ({exc.strerror or exc}); give a readable specimen TOML file"
        ) from exc
    specimen = from_mapping(data, str(path))
    if len(_LOADED) >= _LOADED_MAX:
        _LOADED.pop(next(iter(_LOADED)))
    _LOADED[key] = specimen
    return specimen


def _locate(name_or_path) -> Path:
    """The file of a bundled name or a path; SpecimenError if there is none."""
    names = ", ".join(available())  # for the messages
    if isinstance(name_or_path, bytes) or not isinstance(name_or_path, (str, os.PathLike)):
        raise SpecimenError(
            f"`specimen` = {show(name_or_path)}: give a bundled name ({names}), "
            "the path of a specimen TOML file, or a loaded specimen"
        )
    text = os.fspath(name_or_path)
    if not isinstance(text, str) or not text.strip() or "\0" in text:
        raise SpecimenError(
            f"`specimen` = {show(text)}: not a usable name; give a bundled "
            f"name ({names}) or a TOML file path"
        )
    path = Path(text)
    bundled = {k.lower(): v for k, v in _bundled().items()}
    if isinstance(name_or_path, str) and text.lower() in bundled and not path.exists():
        return bundled[text.lower()]
    if not path.exists():
        raise SpecimenError(
            f"specimen {text!r}: no such bundled specimen or file; use one of "
            f"{names} or the path of a TOML file"
        )
    if path.is_dir():
        raise SpecimenError(
            f"specimen {text!r} is a directory; give a specimen TOML file "
            "(e.g. specimens/data/S1.toml)"
        )
    return path
