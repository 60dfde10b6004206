"""Validators of user arguments: each returns the cleaned value or raises `InputError`.

In the style of scipy's ``validate_*`` helpers: the message names the argument in
backticks, shows the value and says what to give instead. Numbers are strict: a
bool, a string such as ``'10'`` or a non-finite value is refused, never coerced, and
an integer argument refuses 2.5 instead of truncating it.

>>> positive("t_end", 10)
10.0
>>> integer("repeats", 3, low=1)
3
"""

from __future__ import annotations

import math
import numbers
from typing import Any

from .errors import InputError

__all__ = ["number", "positive", "integer", "choice"]


def _is_real(value: Any) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def number(
    name: str,
    value: Any,
    *,
    low: float | None = None,
    high: float | None = None,
    low_open: bool = False,
    high_open: bool = False,
    allow_inf: bool = False,
    what: str = "",
) -> float:
    """A real number (not a bool or a string) within optional bounds, as a float.

    Parameters
    ----------
    name : str
        The argument's name, shown in the message (e.g. ``"t_end"`` or ``"--t-end"``).
    value : object
    low, high : float, optional
        Bounds, closed unless `low_open` / `high_open`.
    allow_inf : bool
        Accept ±inf (NaN is never accepted).
    what : str
        What the number is, with its unit (e.g. ``"an end time in s"``).

    Raises
    ------
    InputError
    """
    about = f" ({what})" if what else ""
    if not _is_real(value):
        raise InputError(f"`{name}` = {value!r}: expected a number{about}")
    try:
        x = float(value)
    except OverflowError:  # an int beyond the float range, e.g. 10**400
        x = math.inf
    if math.isnan(x) or (math.isinf(x) and not allow_inf):
        kind = "a number, not NaN" if allow_inf else "a finite number"
        raise InputError(f"`{name}` = {value!r}: expected {kind}{about}")
    too_low = low is not None and (x <= low if low_open else x < low)
    too_high = high is not None and (x >= high if high_open else x > high)
    if too_low or too_high:
        lo = "(-inf" if low is None else ("(" if low_open else "[") + f"{low:g}"
        hi = "inf)" if high is None else f"{high:g}" + (")" if high_open else "]")
        raise InputError(f"`{name}` = {value!r}: must lie in {lo}, {hi}{about}")
    return x


def positive(name: str, value: Any, what: str = "", *, allow_inf: bool = False) -> float:
    """A number > 0 (see `number`)."""
    return number(name, value, low=0.0, low_open=True, allow_inf=allow_inf, what=what)


def integer(
    name: str, value: Any, *, low: int | None = None, high: int | None = None, what: str = ""
) -> int:
    """An integer (int or numpy integer; not a bool, a float or a string) within bounds."""
    about = f" ({what})" if what else ""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise InputError(f"`{name}` = {value!r}: expected a whole number{about}")
    n = int(value)
    if (low is not None and n < low) or (high is not None and n > high):
        bounds = f"≥ {low}" if high is None else f"≤ {high}" if low is None else f"in {low}..{high}"
        raise InputError(f"`{name}` = {value!r}: must be {bounds}{about}")
    return n


def choice(name: str, value: Any, options) -> str:
    """One of `options` (strings), exactly."""
    options = tuple(options)
    if not isinstance(value, str) or value not in options:
        raise InputError(f"`{name}` = {value!r}: use one of {', '.join(map(repr, options))}")
    return value
