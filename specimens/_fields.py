"""Small validators for specimen tables: each returns the cleaned value or raises.

Every message names the source, the dotted field path, the value and the fix,
in the style of scipy's ``validate_*`` helpers.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from typing import Any

from .errors import SpecimenError

__all__ = [
    "show",
    "check_keys",
    "table",
    "number",
    "number_list",
    "text",
]


def show(value: Any, limit: int = 80) -> str:
    """repr(value), cut to `limit` characters with an ellipsis (a message stays one line)."""
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _fail(source: str, field: str, value: Any, fix: str) -> SpecimenError:
    return SpecimenError(f"{source}: `{field}` = {show(value)}: {fix}")


def check_keys(
    source: str, where: str, data: Mapping, required: set[str], optional: set[str] = frozenset()
) -> None:
    """Raise if `data` misses a required key or holds one not in the schema."""
    prefix = f"{where}." if where else ""
    missing = sorted(required - set(data), key=str)
    if missing:
        raise SpecimenError(
            f"{source}: missing key `{prefix}{missing[0]}`"
            + (f" (and {', '.join(prefix + m for m in missing[1:])})" if len(missing) > 1 else "")
            + f"; add it to the [{where or 'top level'}] table"
        )
    unknown = sorted(set(data) - required - set(optional), key=str)
    if unknown:
        allowed = ", ".join(sorted(required | set(optional)))
        raise SpecimenError(
            f"{source}: unknown key `{prefix}{unknown[0]!s}`; remove it or correct its "
            f"spelling (allowed in [{where or 'top level'}]: {allowed})"
        )


def table(source: str, data: Mapping, key: str) -> Mapping:
    """The sub-table `key` of `data`, which must be a TOML table."""
    value = data[key]
    if not isinstance(value, Mapping):
        raise _fail(source, key, value, f"expected a table; write it as [{key}]")
    return value


def _as_float(source: str, field: str, value: Any) -> float:
    # numbers.Real takes Python and NumPy numbers; bool (and numpy.bool_) is refused
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise _fail(source, field, value, "expected a number")
    try:
        x = float(value)
    except OverflowError:  # an integer beyond the float range, e.g. 10**400
        raise _fail(
            source, field, value, "expected a finite number (this one is beyond the float range)"
        ) from None
    if not math.isfinite(x):
        raise _fail(source, field, value, "expected a finite number")
    return x


def number(
    source: str,
    field: str,
    value: Any,
    *,
    low: float | None = None,
    high: float | None = None,
    low_open: bool = False,
    high_open: bool = False,
    what: str = "",
) -> float:
    """A finite number within optional bounds (closed unless `*_open`)."""
    x = _as_float(source, field, value)
    too_low = low is not None and (x <= low if low_open else x < low)
    too_high = high is not None and (x >= high if high_open else x > high)
    if too_low or too_high:
        lo = "" if low is None else ("(" if low_open else "[") + f"{low:g}"
        hi = "" if high is None else f"{high:g}" + (")" if high_open else "]")
        interval = f"{lo or '(-inf'}, {hi or 'inf)'}"
        raise _fail(source, field, value, f"must lie in {interval}" + (f"; {what}" if what else ""))
    return x


def number_list(
    source: str, field: str, value: Any, *, positive: bool = False, what: str = ""
) -> tuple[float, ...]:
    """A non-empty list of finite numbers, optionally all > 0."""
    if not isinstance(value, (list, tuple)) or not value:
        raise _fail(source, field, value, "expected a non-empty list of numbers, e.g. [0.5, 1.0]")
    out = []
    for i, v in enumerate(value):
        x = _as_float(source, f"{field}[{i}]", v)
        if positive and x <= 0.0:
            raise _fail(source, f"{field}[{i}]", v, "must be > 0" + (f"; {what}" if what else ""))
        out.append(x)
    return tuple(out)


def text(source: str, field: str, value: Any, *, required: bool = False) -> str:
    """A string; non-blank if `required`."""
    if not isinstance(value, str):
        raise _fail(source, field, value, "expected a string in quotes")
    if required and not value.strip():
        raise _fail(source, field, value, "expected a non-empty string in quotes")
    return value
