"""Find, read and validate specimen files, bundled or the user's own."""

from __future__ import annotations

import tomllib
from collections.abc import Callable, Mapping
from importlib import resources
from pathlib import Path

from .beam import beam_from_mapping
from .block import block_from_mapping
from .column import column_from_mapping
from .errors import SpecimenError

__all__ = ["load", "available", "from_mapping", "register_kind"]

_DATA = "data"

#: kind name -> builder(mapping, source) -> specimen
_KINDS: dict[str, Callable[[Mapping, str], object]] = {
    "column": column_from_mapping,
    "block": block_from_mapping,
    "beam": beam_from_mapping,
}


def register_kind(kind: str, builder: Callable[[Mapping, str], object]) -> None:
    """Make `load` understand files with ``kind = "<kind>"``."""
    _KINDS[kind] = builder


def _bundled() -> dict[str, Path]:
    root = resources.files(__package__) / _DATA
    return {Path(p.name).stem: Path(str(p)) for p in root.iterdir() if p.name.endswith(".toml")}


def available() -> list[str]:
    """Names of the specimens shipped with the package, sorted."""
    return sorted(_bundled())


def from_mapping(data: Mapping, source: str = "<mapping>"):
    """Validate an already-parsed specimen mapping and build its specimen object."""
    if "kind" not in data:
        raise SpecimenError(f"{source}: missing key `kind`; add e.g. kind = \"column\" at the top")
    kind = data["kind"]
    if kind not in _KINDS:
        raise SpecimenError(f"{source}: `kind` = {kind!r}: unknown kind; use one of "
                            + ", ".join(repr(k) for k in sorted(_KINDS)))
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
    if isinstance(name_or_path, (str, Path)) and not str(name_or_path).strip():
        raise SpecimenError("specimen name is empty; give a bundled name "
                            f"({', '.join(available())}) or a TOML file path")
    path = Path(name_or_path)
    bundled = {k.lower(): v for k, v in _bundled().items()}
    if isinstance(name_or_path, str) and name_or_path.lower() in bundled and not path.exists():
        path = bundled[name_or_path.lower()]
    elif not path.exists():
        raise SpecimenError(
            f"specimen {str(name_or_path)!r}: no such bundled specimen or file; use one of "
            f"{', '.join(available())} or the path of a TOML file")
    if path.is_dir():
        raise SpecimenError(f"specimen {str(path)!r} is a directory; give a TOML file")
    try:
        with path.open("rb") as fh:
            data = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise SpecimenError(f"{path}: not a valid TOML file ({exc}); check its syntax") from exc
    except UnicodeDecodeError as exc:
        raise SpecimenError(f"{path}: not a text TOML file ({exc})") from exc
    return from_mapping(data, str(path))
