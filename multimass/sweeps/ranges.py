"""Inclusive ranges written START:STOP:COUNT (CLI) or given as sequences (API)."""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError

__all__ = ["parse_range", "check_values"]


def check_values(
    name: str, values, *, positive: bool = False, nonnegative: bool = False
) -> np.ndarray:
    """A non-empty, finite, strictly increasing 1-D array of sweep values."""
    try:
        a = np.atleast_1d(np.asarray(values, dtype=float))
    except (TypeError, ValueError):
        raise InputError(
            f"`{name}` = {values!r}: expected numbers (a sequence of floats)"
        ) from None
    shown = "[" + ", ".join(f"{x:g}" for x in a.ravel()[:8]) + (", …]" if a.size > 8 else "]")
    if a.ndim != 1 or a.size == 0:
        raise InputError(f"`{name}` is empty; give at least one value")
    if not np.all(np.isfinite(a)):
        raise InputError(f"`{name}` holds non-finite values: {shown}")
    if positive and np.any(a <= 0):
        raise InputError(f"`{name}` = {shown}: every value must be > 0")
    if nonnegative and np.any(a < 0):
        raise InputError(f"`{name}` = {shown}: every value must be ≥ 0")
    if a.size > 1 and np.any(np.diff(a) <= 0):
        raise InputError(f"`{name}` = {shown}: values must increase strictly")
    return a


def parse_range(text: str, name: str, convert=float) -> np.ndarray:
    """ "START:STOP:COUNT" → an inclusive linspace; a single value → one value.

    `convert` turns each of START and STOP into a number (e.g. to parse "0.4g").
    """
    parts = str(text).split(":")
    try:
        if len(parts) == 1:
            return np.array([convert(parts[0])])
        if len(parts) != 3:
            raise ValueError
        start, stop, count = convert(parts[0]), convert(parts[1]), int(parts[2])
    except InputError:  # the converter's own message names the value and the fix
        raise
    except (ValueError, TypeError):
        raise InputError(
            f"`{name}` = {text!r}: write START:STOP:COUNT (an inclusive range of "
            "COUNT values) or one value, e.g. 0.5:5:46"
        ) from None
    if count < 1:
        raise InputError(
            f"`{name}` = {text!r}: the range is empty (COUNT = {count}); COUNT must be ≥ 1"
        )
    if not (math.isfinite(start) and math.isfinite(stop)):
        raise InputError(f"`{name}` = {text!r}: START and STOP must be finite")
    if stop < start or (stop == start and count > 1):
        raise InputError(
            f"`{name}` = {text!r}: STOP must be greater than START (the range is inverted or empty)"
        )
    return np.linspace(start, stop, count)
