"""Acceleration units: conversion to m/s² and parsing of strings such as ``"0.4g"``.

The engine works in SI units (m/s²). Records and command-line amplitudes come in
other units; they are converted here, once, at the edge. Units are never guessed:
a missing or unknown unit is an error that lists the accepted spellings.

>>> to_mps2(0.5, "g")
4.905
>>> parse_acceleration("350gal")
3.5
"""

from __future__ import annotations

import math
import re

import numpy as np

from ..errors import InputError

__all__ = ["G", "UNITS", "canonical_units", "to_mps2", "parse_acceleration"]

#: Standard gravity used to convert records given in g (m/s²); DESIGN.md: g = 9.81.
G = 9.81

# canonical name -> factor to m/s² (the factor for "g" is applied with the `g` argument)
_FACTORS = {"g": None, "m/s2": 1.0, "cm/s2": 0.01, "mm/s2": 0.001}

# accepted spelling (lower case, no blanks) -> canonical name
_ALIASES = {
    "g": "g",
    "m/s2": "m/s2",
    "m/s^2": "m/s2",
    "m/s²": "m/s2",
    "mps2": "m/s2",
    "m/s/s": "m/s2",
    "m/sec2": "m/s2",
    "m/sec/sec": "m/s2",
    "cm/s2": "cm/s2",
    "cm/s^2": "cm/s2",
    "cm/s²": "cm/s2",
    "gal": "cm/s2",
    "cm/s/s": "cm/s2",
    "cm/sec2": "cm/s2",
    "cm/sec/sec": "cm/s2",
    "mm/s2": "mm/s2",
    "mm/s^2": "mm/s2",
    "mm/s²": "mm/s2",
    "mm/s/s": "mm/s2",
}

#: The canonical unit names accepted everywhere (aliases are listed in `canonical_units`).
UNITS = tuple(_FACTORS)

_ACCEPTED = "g, m/s2 (or m/s^2, mps2), cm/s2 (or cm/s^2, gal), mm/s2 (or mm/s^2)"

# a signed decimal number, optionally with exponent, then the rest (the unit)
_NUMBER_UNIT = re.compile(r"^\s*([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*(.*?)\s*$")


def canonical_units(units: str, *, argument: str = "units") -> str:
    """The canonical name of an acceleration unit: ``"g"``, ``"m/s2"``, ``"cm/s2"`` or ``"mm/s2"``.

    Spelling is case-insensitive and blanks are ignored (``"M/S^2"``, ``"Gal"``).

    Raises
    ------
    InputError
        If `units` is missing or not one of the accepted spellings.
    """
    if units is None:
        raise InputError(
            f"`{argument}` is missing: give the units explicitly "
            f"(they are never guessed); accepted: {_ACCEPTED}"
        )
    if not isinstance(units, str):
        raise InputError(f"`{argument}` = {units!r}: expected a string; accepted: {_ACCEPTED}")
    key = "".join(units.split()).lower()
    if key not in _ALIASES:
        raise InputError(
            f"`{argument}` = {units!r}: unknown acceleration unit; accepted: {_ACCEPTED}"
        )
    return _ALIASES[key]


def to_mps2(value, units: str, *, g: float = G):
    """Convert an acceleration (a number or an array) from `units` to m/s².

    Parameters
    ----------
    value : float or array_like
        Acceleration in `units`.
    units : str
        ``"g"``, ``"m/s2"`` (``"m/s^2"``, ``"mps2"``), ``"cm/s2"`` (``"gal"``) or
        ``"mm/s2"``; case-insensitive.
    g : float, optional
        Acceleration of gravity used for ``"g"`` (default `G` = 9.81 m/s²).

    Returns
    -------
    float or ndarray
        The acceleration in m/s² (a float for a scalar input).
    """
    name = canonical_units(units)
    factor = g if name == "g" else _FACTORS[name]
    if np.ndim(value) == 0:
        return float(value) * factor
    return np.asarray(value, dtype=float) * factor


def parse_acceleration(
    text, default_units: str | None = None, *, g: float = G, argument: str = "acceleration"
) -> float:
    """Parse an acceleration such as ``"0.4g"``, ``"3.5m/s2"`` or ``"350gal"`` into m/s².

    Parameters
    ----------
    text : str or float
        A number followed by a unit (blanks allowed between them). A bare number
        (or a float) takes `default_units`.
    default_units : str, optional
        Units of a bare number. Without it a bare number is an error.
    g : float, optional
        Acceleration of gravity used for ``"g"`` (default 9.81 m/s²).
    argument : str, optional
        Name of the argument shown in error messages (e.g. ``"--amp"``).

    Returns
    -------
    float
        The acceleration in m/s² (finite; the sign is kept).

    Raises
    ------
    InputError
        For text that is not a number with an accepted unit.
    """
    if isinstance(text, bool):
        raise InputError(f"`{argument}` = {text!r}: expected a number with units, e.g. 0.4g")
    if isinstance(text, (int, float)):
        number, unit = float(text), ""
    elif isinstance(text, str):
        match = _NUMBER_UNIT.match(text)
        if match is None:
            raise InputError(
                f"`{argument}` = {text!r}: expected a number followed by a unit, "
                f"e.g. 0.4g, 3.5m/s2 or 350gal; accepted units: {_ACCEPTED}"
            )
        number, unit = float(match.group(1)), match.group(2)
    else:
        raise InputError(f"`{argument}` = {text!r}: expected a string such as '0.4g'")
    if not math.isfinite(number):
        raise InputError(f"`{argument}` = {text!r}: expected a finite number")
    if not unit:
        if default_units is None:
            raise InputError(
                f"`{argument}` = {text!r}: a bare number has no units; "
                f"write e.g. {number:g}g or {number:g}m/s2"
            )
        unit = default_units
    try:
        name = canonical_units(unit, argument=argument)
    except InputError:
        raise InputError(
            f"`{argument}` = {text!r}: unknown unit {unit!r}; accepted: {_ACCEPTED}"
        ) from None
    return to_mps2(number, name, g=g)
