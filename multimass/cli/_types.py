"""Argument types of the command line: strict numbers whose errors name the flag.

argparse calls these on the text of a flag; an `argparse.ArgumentTypeError` becomes
``multimass CMD: error: argument --seed: must be a whole number ≥ 0, got '-1'``,
which names the flag, the value and the rule before anything is computed.
"""

from __future__ import annotations

import argparse
import math

__all__ = [
    "finite",
    "positive",
    "positive_or_inf",
    "nonnegative",
    "whole",
    "count",
    "unit_interval",
]


def _float(text: str, rule: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be {rule}, got {text!r}") from None
    if math.isnan(x):
        raise argparse.ArgumentTypeError(f"must be {rule}, got {text!r}")
    return x


def finite(text: str) -> float:
    """A finite number."""
    x = _float(text, "a finite number")
    if not math.isfinite(x):
        raise argparse.ArgumentTypeError(f"must be a finite number, got {text!r}")
    return x


def positive(text: str) -> float:
    """A finite number > 0."""
    x = _float(text, "a finite number > 0")
    if not (math.isfinite(x) and x > 0.0):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text!r}")
    return x


def positive_or_inf(text: str) -> float:
    """A number > 0, inf allowed (e.g. no step cap)."""
    x = _float(text, "a number > 0 (or inf)")
    if not x > 0.0:
        raise argparse.ArgumentTypeError(f"must be a number > 0 (or inf), got {text!r}")
    return x


def nonnegative(text: str) -> float:
    """A finite number ≥ 0."""
    x = _float(text, "a finite number ≥ 0")
    if not (math.isfinite(x) and x >= 0.0):
        raise argparse.ArgumentTypeError(f"must be a finite number ≥ 0, got {text!r}")
    return x


def unit_interval(text: str) -> float:
    """A number in [0, 1]."""
    x = _float(text, "a number in [0, 1]")
    if not 0.0 <= x <= 1.0:
        raise argparse.ArgumentTypeError(f"must be a number in [0, 1], got {text!r}")
    return x


def _int(text: str, low: int) -> int:
    rule = f"a whole number ≥ {low}"
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be {rule}, got {text!r}") from None
    if n < low:
        raise argparse.ArgumentTypeError(f"must be {rule}, got {text!r}")
    return n


def whole(text: str) -> int:
    """A whole number ≥ 0 (e.g. a seed)."""
    return _int(text, 0)


def count(text: str) -> int:
    """A whole number ≥ 1 (e.g. repeats, workers)."""
    return _int(text, 1)
