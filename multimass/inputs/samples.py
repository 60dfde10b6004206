"""Checks of sampled signals — ground-motion records and test traces — before they are used.

Each check returns the cleaned value or raises `InputError` naming the source, the
sample (or the line of the file) and the fix. Numbers are strict: bool, str or None
are refused, never coerced, and an integer beyond the float range is refused, not
raised as OverflowError.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from ..errors import InputError
from .units import UNITS, canonical_units, to_mps2

__all__ = [
    "DT_RTOL",
    "DT_MIN",
    "DT_MAX",
    "T_MAX",
    "float_array",
    "finite_float",
    "where",
    "check_samples",
    "check_span",
    "check_scale",
    "check_peak",
    "PEAK_G",
    "scaled_to_mps2",
    "units_of",
]

#: Relative tolerance on the time step: ``|Δt_k − dt| ≤ DT_RTOL · dt`` for every step.
DT_RTOL = 1e-6

#: Plausible time step (s). Accelerographs sample at 50–1000 Hz (dt 0.001–0.02 s; the
#: bundled El Centro 0.02 s); a step above 1 s cannot carry earthquake motion (0.1–25 Hz)
#: and is usually a time column in ms, one below 1 µs is not a recording (and 1/dt must
#: stay a float for the interpolation).
DT_MIN, DT_MAX = 1e-6, 1.0
#: Latest plausible sample time (s): a day; records last seconds to minutes.
T_MAX = 86_400.0

#: Plausible peak of a record's values before `scale` (g). Above: beyond any recorded
#: earthquake (the largest recorded peak ground acceleration is about 4 g: 2008
#: Iwate-Miyagi, station IWTH25; the bundled records peak at 0.35-0.99 g). Below: a
#: thousandth of the gentlest motion that can rock a bundled structure (uplift needs about
#: g tan α, 0.1 g and more), and at the noise of a strong-motion accelerograph. Either is
#: almost surely a unit slip (m/s² read as g multiplies the peak by 9.81).
PEAK_G = (1e-4, 5.0)
_COMMON_G = (0.01, 2.0)  # peaks of the motions records are run for: where a slip lands


def float_array(source: str, name: str, value) -> np.ndarray:
    """`value` as a float array if it holds real numbers only (no bool, str or None).

    ``np.asarray(["10"], dtype=float)`` would silently read the string; here a
    non-numeric entry is refused, naming the argument.
    """
    if isinstance(value, (str, bytes)):
        raise InputError(f"{source}: `{name}` = {value!r:.60}: expected an array of numbers")
    try:
        raw = np.asarray(value)
    except (ValueError, TypeError):  # ragged nested sequences
        raise InputError(
            f"{source}: `{name}` is not a rectangular array of numbers; give "
            f"a 1-D sequence of floats"
        ) from None
    if raw.dtype.kind not in "iuf":
        raise InputError(
            f"{source}: `{name}` holds {raw.dtype.name!r} values (e.g. "
            f"{raw.ravel()[:1].tolist()!r:.60}); give real numbers only (no bool, "
            f"str or None)"
        )
    return raw.astype(float)


def where(source: str, lines, k: int) -> str:
    """'file, line L' for sample k when line numbers are known, else 'file, sample k'."""
    return f"{source}, line {lines[k]}" if lines is not None else f"{source}, sample {k}"


def check_samples(time: np.ndarray, accel: np.ndarray, source: str, lines=None) -> float:
    """Validate a record's samples; return its time step dt (s)."""
    if time.ndim != 1 or accel.ndim != 1 or time.size != accel.size:
        raise InputError(
            f"{source}: `time` (shape {time.shape}) and `accel` (shape "
            f"{accel.shape}) must be 1-D arrays of the same length"
        )
    if time.size < 2:
        raise InputError(
            f"{source}: {time.size} sample(s); a record needs at least 2 "
            f"samples `t a` to define a time step"
        )
    for label, values in (("time", time), ("acceleration", accel)):
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            k = int(bad[0])
            raise InputError(
                f"{where(source, lines, k)}: {label} = {float(values[k])!r} is not a "
                f"finite number; fix or remove the sample"
            )
    with np.errstate(over="ignore", invalid="ignore"):
        jumps = np.diff(accel)
    bad = np.flatnonzero(~np.isfinite(jumps))
    if bad.size:
        k = int(bad[0]) + 1
        raise InputError(
            f"{where(source, lines, k)}: acceleration jumps from {float(accel[k - 1])!r} "
            f"to {float(accel[k])!r}, beyond the float range, so ü_g between the two "
            f"samples is not a number; check the values and their units"
        )
    if time[0] < 0.0:
        raise InputError(
            f"{where(source, lines, 0)}: `time` starts at {float(time[0])!r} s < 0; "
            f"shift the time column so that it starts at 0 or later"
        )
    steps = np.diff(time)
    bad = np.flatnonzero(steps <= 0.0)
    if bad.size:
        k = int(bad[0]) + 1
        raise InputError(
            f"{where(source, lines, k)}: `time` = {float(time[k])!r} s does not increase "
            f"(previous sample at {float(time[k - 1])!r} s); times must be strictly "
            f"increasing: sort the samples or remove duplicates"
        )
    ref = float(np.sort(steps)[(steps.size - 1) // 2])  # the lower median: an actual step
    check_span(source, time, ref)
    bad = np.flatnonzero(np.abs(steps - ref) > DT_RTOL * ref)
    if bad.size:
        k = int(bad[0]) + 1
        raise InputError(
            f"{where(source, lines, k)}: non-uniform time step: `time` = "
            f"{float(time[k])!r} s is {float(steps[k - 1])!r} s after the previous sample, the "
            f"usual step is {ref!r} s; a record needs a uniform step (relative "
            f"tolerance {DT_RTOL:g}): resample it onto a uniform grid first"
        )
    return float((time[-1] - time[0]) / (time.size - 1))


def finite_float(value) -> float | None:
    """float(value) for a finite real number (not bool); None for anything else.

    An integer beyond the float range (10**400) is None, not an OverflowError.
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        return None
    try:
        x = float(value)
    except OverflowError:
        return None
    return x if math.isfinite(x) else None


def check_span(source: str, time: np.ndarray, dt: float) -> None:
    """A plausible time step and a record shorter than a day (`DT_MIN`, `DT_MAX`, `T_MAX`)."""
    if not DT_MIN <= dt <= DT_MAX:
        hint = (
            "; is the time column in ms? divide it by 1000"
            if DT_MIN <= dt / 1000 <= DT_MAX
            else "; give times in s"
        )
        raise InputError(
            f"{source}: time step {dt!r} s is implausible for a ground-motion record "
            f"(accelerographs sample every 0.001–0.02 s; accepted {DT_MIN:g}–{DT_MAX:g} "
            f"s){hint}"
        )
    if time[-1] > T_MAX:
        raise InputError(
            f"{source}: last sample at t = {float(time[-1])!r} s, later than a day "
            f"({T_MAX:g} s); give times in s from the record's start"
        )


def check_scale(source: str, scale) -> float:
    if isinstance(scale, (bool, np.bool_)) or not isinstance(scale, numbers.Real):
        raise InputError(f"{source}: `scale` = {scale!r:.60}: expected a number > 0")
    x = finite_float(scale)
    if x is None or x <= 0.0:
        raise InputError(
            f"{source}: `scale` = {scale!r:.60}: must be a finite number > 0 (a "
            f"factor on the record's amplitude; to reverse the record's sign, "
            f"mirror the response instead)"
        )
    return x


def check_peak(source: str, time, values, units: str) -> None:
    """InputError if the largest ``|values|`` (in `units`, before any scale) lies outside
    `PEAK_G`, naming the sample, the peak, the likely unit slip and the fix.

    A peak meant to be that large or small (a synthetic input) is given through the
    record's `scale`: write the values at an earthquake's amplitude and scale them.
    """
    given, units = units, canonical_units(units)
    values = np.asarray(values, dtype=float)
    if values.size == 0 or not np.all(np.isfinite(values)):
        return  # check_samples names those
    k = int(np.argmax(np.abs(values)))
    peak = abs(float(values[k]))
    peak_g = float(to_mps2(peak, units)) / float(to_mps2(1.0, "g"))
    low, high = PEAK_G
    if low <= peak_g <= high or peak == 0.0:  # all zero: no motion, not a unit slip
        return
    where_ = f"{source}, sample {k} (t = {float(time[k]):g} s)"
    if peak_g > high:
        what = (
            f"beyond any recorded earthquake (the largest recorded peaks are about 4 g; "
            f"accepted up to {high:g} g)"
        )
    else:
        what = f"below {low:g} g, too weak to rock any structure (accepted from {low:g} g)"
    slips = [
        (abs(math.log(float(to_mps2(1.0, u)) / float(to_mps2(1.0, units)))), u)
        for u in UNITS
        if u != units
        and _COMMON_G[0] <= float(to_mps2(peak, u)) / float(to_mps2(1.0, "g")) <= _COMMON_G[1]
    ]
    guesses = [
        f"{u} read as {units} (peak {float(to_mps2(peak, u)) / float(to_mps2(1.0, 'g')):.3g} g)"
        for _, u in sorted(slips)[:2]
    ]
    if len(guesses) == 1:
        fix = f"give `units` = {slips[0][1]!r} (--units {slips[0][1]})"
    else:
        fix = "give the unit the values are in as `units` (--units)"
    hint = f"likely {' or '.join(guesses)}: {fix}" if guesses else "check the values' unit"
    in_g = "" if units == "g" else f" = {peak_g:.3g} g"
    raise InputError(
        f"{where_}: `units` = {given!r}: peak {peak:g} {given}{in_g}, {what}; "
        f"{hint}. A peak meant to be this {'large' if peak_g > high else 'small'} (a "
        "synthetic input): write the values at an earthquake's amplitude and give the "
        "factor as `scale` (--scale)"
    )


def scaled_to_mps2(source: str, values: np.ndarray, units: str, scale: float) -> np.ndarray:
    """values in `units` times `scale`, in m/s²; InputError if a product leaves the float range."""
    with np.errstate(over="ignore", invalid="ignore"):
        out = to_mps2(values, units) * scale
    bad = np.flatnonzero(~np.isfinite(out) & np.isfinite(values))
    if bad.size:
        k = int(bad[0])
        raise InputError(
            f"{source}, sample {k}: {float(values[k])!r} {units} x `scale` = {scale!r} "
            f"is beyond the float range; check the scale factor and the units"
        )
    return out


def units_of(source: str, units) -> str:
    try:
        return canonical_units(units)
    except InputError as err:
        raise InputError(f"{source}: {err}") from None
