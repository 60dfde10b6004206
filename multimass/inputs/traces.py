"""Recorded test traces (θ and accelerations) and their comparison with simulations.

A trace is a CSV file with a header row naming each column and its unit in brackets::

    # specimen: S1
    # other comment lines start with '#' too
    t [s],theta [deg],a_A2 [g],a_A4 [m/s2],ag [g]
    0.000,2.8648,0.0012,0.013,0.0003
    ...

* time: ``t`` or ``time``, in ``s`` or ``ms``; strictly increasing, any spacing
  (unlike a ground-motion record, a trace need not be uniformly sampled);
* ``theta``: base rotation in ``rad`` or ``deg`` (paper 001 Fig 1: θ > 0 rocks
  about the right pivot);
* ``a_<sensor>`` (e.g. ``a_A2``, a named sensor of the specimen), ``a<k>`` or
  ``a_node<k>`` (1-based node k): total lateral acceleration (paper 001 Eq 7) in
  ``g``, ``m/s2``, ``cm/s2`` (``gal``) or ``mm/s2``;
* ``ag`` (optional): the ground (shake-table) acceleration, in the same units as the
  ``a_...`` channels; `Trace.ag` is None without it.

A comment line ``# specimen: NAME`` names the specimen tested (`Trace.specimen`); other
comment lines are ignored.

Names are case-insensitive. Units are never guessed: a column without a unit is an
error. Values are converted to SI (s, rad, m/s²) on reading.

`read_trace` reads a file, `parse_trace` the same text from a string; `write_trace`
(and `format_trace`, its text) writes a `Trace` back in the units it was written in.
`multimass.analysis.trace_metrics.compare_trace` measures, per channel, how far a simulation
is from the trace.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType

import numpy as np

from ..errors import InputError
from ..validation import integer
from .excitations import FreeRelease
from .samples import finite_float, float_array
from .textfile import as_path, read_text
from .units import G, canonical_units, to_mps2

__all__ = ["Trace", "read_trace", "parse_trace", "format_trace", "write_trace", "ACCEPTED_COLUMNS"]

#: What a header may contain (shown in error messages).
ACCEPTED_COLUMNS = (
    "`t [s]` or `time [s]` (s or ms); `theta [rad]` (rad or deg); "
    "`a_<sensor> [g]` (e.g. a_A2), `a<k>` or `a_node<k>` (1-based node k) "
    "in g, m/s2, cm/s2 (gal) or mm/s2; `ag [g]` (ground or table acceleration, same units)"
)

_WHAT = "a trace CSV file with units in its header, e.g. `t [s],theta [deg],a_A2 [g]`"
_TIME_UNITS = {"s": 1.0, "sec": 1.0, "ms": 1e-3}
_ANGLE_UNITS = {
    "rad": 1.0,
    "radian": 1.0,
    "radians": 1.0,
    "deg": math.pi / 180.0,
    "degree": math.pi / 180.0,
    "degrees": math.pi / 180.0,
}
_HEADER_CELL = re.compile(r"^\s*([^\[\]()]*?)\s*(?:[\[(]\s*([^\[\]()]*?)\s*[\])])?\s*$")
_NODE = re.compile(r"^a(?:_node)?(\d+)$", re.IGNORECASE)
_SENSOR = re.compile(r"^a_(\w+)$", re.IGNORECASE)
_SPECIMEN = re.compile(r"^#\s*specimen\s*:(.*)$", re.IGNORECASE)


def _kind(name: str):
    """("time",), ("theta",), ("ag",), ("node", k), ("sensor", label), or None if unknown."""
    low = name.lower()
    if low in ("t", "time"):
        return ("time",)
    if low == "theta":
        return ("theta",)
    if low == "ag":
        return ("ag",)
    m = _NODE.match(name)
    if m:
        return ("node", int(m.group(1)))
    m = _SENSOR.match(name)
    return ("sensor", m.group(1)) if m else None


def _si_factor(name: str, kind, unit, where: str, g: float) -> float:
    """SI value = factor × written value, for a column `name` of `kind` in `unit`."""
    if kind[0] in ("time", "theta"):
        table, si = (_TIME_UNITS, "s") if kind[0] == "time" else (_ANGLE_UNITS, "rad")
        accepted = "s, ms" if kind[0] == "time" else "rad, deg"
        if not unit:
            raise InputError(
                f"{where}: column `{name}` has no unit (units are never guessed): "
                f"write it as `{name} [{si}]`; accepted units: {accepted}"
            )
        if unit.lower() not in table:
            raise InputError(f"{where}: column `{name}` has unit {unit!r}; accepted: {accepted}")
        return table[unit.lower()]
    if not unit:
        raise InputError(
            f"{where}: column `{name}` has no unit (units are never guessed): "
            f"write it as `{name} [g]`; accepted units: g, m/s2, cm/s2 (gal), mm/s2"
        )
    try:
        return to_mps2(1.0, canonical_units(unit, argument=name), g=g)
    except InputError as err:
        hint = (
            f"; `{name}` is the ground (table) acceleration: write it as `{name} [g]` "
            f"or `{name} [m/s2]`"
            if kind[0] == "ag"
            else ""
        )
        raise InputError(f"{where}: column {err}{hint}") from None


# ---------------------------------------------------------------------------- the trace
def _where(source: str, lines, k: int) -> str:
    return f"{source}, line {lines[k]}" if lines is not None else f"{source}, sample {k}"


def _check(time, channels, source, lines=None) -> None:
    """Validate samples: ≥ 2 rows, finite values, strictly increasing time."""
    if time.ndim != 1 or time.size < 2:
        raise InputError(f"{source}: {time.size} sample(s); a trace needs at least 2 rows")
    for name, values in (("time", time), *channels.items()):
        if values.shape != time.shape:
            raise InputError(
                f"{source}: column `{name}` has shape {values.shape}, the time "
                f"column {time.shape}: give one value per time"
            )
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            k = int(bad[0])
            raise InputError(
                f"{_where(source, lines, k)}, column `{name}`: value "
                f"{float(values[k])!r} is not a finite number; fix or remove the row"
            )
    bad = np.flatnonzero(np.diff(time) <= 0.0)
    if bad.size:
        k = int(bad[0]) + 1
        raise InputError(
            f"{_where(source, lines, k)}, column `time`: t = {float(time[k])!r} s "
            f"does not increase (previous row t = {float(time[k - 1])!r} s); times "
            f"must be strictly increasing: sort the rows or remove duplicates"
        )


def _specimen_name(name, source: str) -> str | None:
    """A specimen name: None, or a non-empty one-line string (stripped)."""
    if name is None:
        return None
    if not isinstance(name, str) or not name.strip() or "\n" in name or "\r" in name:
        raise InputError(
            f"{source}: `specimen` = {name!r:.60}: give the specimen's name as one "
            "line of text (e.g. 'S1'), or None"
        )
    return name.strip()


@dataclass(frozen=True, eq=False)
class Trace:
    """A recorded test trace in SI units (read it with `read_trace`).

    Attributes
    ----------
    time : ndarray
        Sample times (s), strictly increasing, any spacing.
    channels : mapping of str to ndarray
        Channel name as written in the header (``"theta"``, ``"a_A2"``, ``"a3"``)
        → values in SI: rad for ``theta``, m/s² for accelerations. Read-only.
    units : mapping of str to str
        The unit each channel was written in (e.g. ``{"theta": "deg"}``).
    source : str
        Where the samples came from (a file path or ``"arrays"``).
    time_units : str
        The unit the time column was written in.
    g : float
        Acceleration of gravity used to convert ``g`` (m/s²).
    specimen : str or None
        The specimen tested, from a ``# specimen: NAME`` comment line (None without one).
    """

    time: np.ndarray
    channels: dict
    units: dict
    source: str = "arrays"
    time_units: str = "s"
    g: float = G
    specimen: str | None = None
    _factors: dict = field(default=None, init=False, repr=False)

    def __post_init__(self):
        if not isinstance(self.source, str):
            raise InputError(f"Trace: `source` = {self.source!r:.60}: give a string")
        for label in ("channels", "units"):
            if not isinstance(getattr(self, label), Mapping):
                raise InputError(
                    f"{self.source}: `{label}` = {getattr(self, label)!r:.60}: give a "
                    f"mapping of channel name to {'values' if label == 'channels' else 'unit'}"
                )
        if not isinstance(self.time_units, str):
            raise InputError(
                f"{self.source}: `time_units` = {self.time_units!r:.60}; accepted: s, ms"
            )
        g = finite_float(self.g)
        if g is None or g <= 0.0:
            raise InputError(
                f"{self.source}: `g` = {self.g!r:.60}: give the acceleration of gravity "
                "in m/s^2 (a finite number > 0, e.g. 9.81)"
            )
        object.__setattr__(self, "g", g)
        object.__setattr__(self, "specimen", _specimen_name(self.specimen, self.source))
        time = float_array(self.source, "time", self.time).copy()
        chans = {
            str(k): float_array(self.source, f"channels[{k!r}]", v).copy()
            for k, v in self.channels.items()
        }
        units = {str(k): v for k, v in self.units.items()}
        bad = next((k for k, v in units.items() if not isinstance(v, str)), None)
        if bad is not None:
            raise InputError(
                f"{self.source}: `units[{bad!r}]` = {units[bad]!r:.60}: give the unit "
                "as a string, e.g. 'deg' or 'g'"
            )
        if not chans:
            raise InputError(f"{self.source}: no channel; accepted columns: {ACCEPTED_COLUMNS}")
        if str(self.time_units).lower() not in _TIME_UNITS:
            raise InputError(f"{self.source}: `time_units` = {self.time_units!r}; accepted: s, ms")
        factors = {}
        for name in chans:
            kind = _kind(name)
            if kind is None or kind[0] == "time":
                raise InputError(
                    f"{self.source}: unknown channel `{name}`; accepted columns: {ACCEPTED_COLUMNS}"
                )
            factors[name] = _si_factor(name, kind, units.get(name), self.source, self.g)
        _check(time, chans, self.source)
        for arr in (time, *chans.values()):
            arr.flags.writeable = False
        object.__setattr__(self, "time", time)
        object.__setattr__(self, "channels", MappingProxyType(chans))
        object.__setattr__(self, "units", MappingProxyType(units))
        object.__setattr__(self, "_factors", MappingProxyType(factors))

    @property
    def names(self) -> tuple[str, ...]:
        """Channel names, in column order."""
        return tuple(self.channels)

    @property
    def ag(self) -> np.ndarray | None:
        """The ground (table) acceleration channel ``ag`` (m/s²), or None without one."""
        return next((v for k, v in self.channels.items() if _kind(k)[0] == "ag"), None)

    @property
    def duration(self) -> float:
        """Last minus first sample time (s)."""
        return float(self.time[-1] - self.time[0])

    def si_units(self, name: str) -> str:
        """``"rad"`` for θ, ``"m/s2"`` for an acceleration channel (``ag`` included)."""
        return "rad" if _kind(name)[0] == "theta" else "m/s2"

    def to_written_units(self, name: str, values):
        """Convert SI `values` of channel `name` back to the unit it was written in."""
        return np.asarray(values, dtype=float) / self._factors[name]

    def free_release(self) -> FreeRelease:
        """The free release matching the trace: θ0 = θ at the first sample, at rest."""
        theta = next((v for k, v in self.channels.items() if _kind(k)[0] == "theta"), None)
        if theta is None:
            raise InputError(
                f"{self.source}: no `theta` column, so the release angle is unknown; "
                f"give the excitation (e.g. FreeRelease(theta0=...)) explicitly"
            )
        return FreeRelease(theta0=float(theta[0]))


def _gravity(g) -> float:
    g_value = finite_float(g)
    if g_value is None or g_value <= 0.0:
        raise InputError(
            f"`g` = {g!r:.60}: give the acceleration of gravity in m/s^2 (a finite "
            "number > 0, e.g. 9.81)"
        )
    return g_value


def read_trace(path, *, g: float = G) -> Trace:
    """Read a recorded trace from a CSV file with units in the header.

    Parameters
    ----------
    path : str or Path
        CSV file: optional ``#`` comment lines (``# specimen: NAME`` names the
        specimen), a header row such as ``t [s],theta [deg],a_A2 [g],a_A4 [m/s2]``,
        then one row of numbers per sample (see the module docstring for the
        accepted names and units).
    g : float, optional
        Acceleration of gravity for values in ``g`` (default 9.81 m/s², DESIGN.md).

    Returns
    -------
    Trace
        Values in SI units (s, rad, m/s²).

    Raises
    ------
    InputError
        Naming the file, line and column: a missing or unknown unit, an unknown or
        repeated column, no time or no channel column, a row with the wrong number
        of cells, an unreadable or non-finite value, fewer than 2 rows, time not
        strictly increasing, an empty or repeated ``# specimen:`` line.
    """
    g = _gravity(g)
    source = str(as_path(path, what=_WHAT))
    text = read_text(path, what=_WHAT, suffixes=(".csv", ".txt"))
    return _parse(text, source, g, "empty file")


def parse_trace(text: str, *, source: str = "text", g: float = G) -> Trace:
    """A trace from the text of a trace CSV file (what `read_trace` reads from a file).

    Parameters
    ----------
    text : str
        The file's text (see the module docstring).
    source : str, optional
        Where the text came from, shown in error messages and kept as `Trace.source`.
    g : float, optional
        Acceleration of gravity for values in ``g`` (m/s²).

    Returns
    -------
    Trace

    Raises
    ------
    InputError
        As `read_trace`, naming `source` and the line.
    """
    if not isinstance(text, str):
        raise InputError(f"`text` = {text!r:.60}: give the text of a trace CSV file (a str)")
    if not isinstance(source, str):
        raise InputError(f"`source` = {source!r:.60}: give a string, e.g. the file's name")
    return _parse(text, source, _gravity(g), "empty text")


def _parse(text: str, source: str, g: float, empty: str) -> Trace:
    """The trace of the text of a CSV file (`read_trace`, `parse_trace`)."""
    lines = [(n, line.strip()) for n, line in enumerate(text.splitlines(), start=1)]
    rows = [(n, line) for n, line in lines if line and not line.startswith("#")]
    if not rows:
        raise InputError(
            f"{source}: {empty}; expected a header such as "
            f"`t [s],theta [rad],a_A2 [g]` and rows of numbers"
        )
    specimen = _specimen_line([(n, line) for n, line in lines if line.startswith("#")], source)
    header_line, header = rows[0]
    names, factors, written = _parse_header(header, f"{source}, line {header_line}", g)
    values, linenos = _parse_rows(rows[1:], names, source)
    with np.errstate(over="ignore"):  # a value x its unit beyond the float range: _check
        data = np.array(values, dtype=float).reshape(len(values), len(names)) * np.array(factors)
    i_time = next(i for i, name in enumerate(names) if _kind(name)[0] == "time")
    chans = {name: data[:, i] for i, name in enumerate(names) if i != i_time}
    _check(data[:, i_time], chans, source, linenos)
    return Trace(
        time=data[:, i_time],
        channels=chans,
        units={k: written[k] for k in chans},
        source=source,
        time_units=written[names[i_time]],
        g=g,
        specimen=specimen,
    )


def _specimen_line(comments, source: str) -> str | None:
    """The NAME of the comment line ``# specimen: NAME`` (None without one)."""
    found = None
    for n, line in comments:
        m = _SPECIMEN.match(line)
        if m is None:
            continue
        name = m.group(1).strip()
        if not name:
            raise InputError(
                f"{source}, line {n}: `# specimen:` without a name; write e.g. `# specimen: S1`"
            )
        if found is not None and name != found[1]:
            raise InputError(
                f"{source}, line {n}: a second `# specimen:` line ({name!r}; line "
                f"{found[0]} says {found[1]!r}); keep one"
            )
        found = found or (n, name)
    return None if found is None else found[1]


def format_trace(trace: Trace, *, digits: int = 10) -> str:
    """The text of `trace` as a trace CSV file, each channel in the unit it was written in.

    Parameters
    ----------
    trace : Trace
    digits : int, optional
        Significant digits of each value (1–17; default 10).

    Returns
    -------
    str
        A ``# specimen: NAME`` line if `trace.specimen` is set, the header row
        (e.g. ``t [s],theta [rad],a_A2 [g]``) and one row per sample: what
        `parse_trace` and `read_trace` read back (to `digits` significant digits).
    """
    if not isinstance(trace, Trace):
        raise InputError(f"`trace` = {trace!r:.60}: give a Trace (e.g. from read_trace)")
    digits = integer("digits", digits, low=1, high=17)
    head = [f"# specimen: {trace.specimen}"] if trace.specimen is not None else []
    time_name = f"t [{trace.time_units}]"
    head.append(",".join([time_name, *(f"{k} [{trace.units[k]}]" for k in trace.names)]))
    columns = [trace.time / _TIME_UNITS[trace.time_units.lower()]]
    columns += [trace.to_written_units(k, v) for k, v in trace.channels.items()]
    fmt = f"%.{digits}g"
    body = np.char.mod(fmt, np.column_stack(columns))
    return "\n".join([*head, *(",".join(row) for row in body)]) + "\n"


def write_trace(trace: Trace, path, *, digits: int = 10) -> Path:
    """Write `trace` as a trace CSV file (`format_trace`); return the path written.

    Parameters
    ----------
    trace : Trace
    path : str or Path
        The file to write (``.csv``); its folder must exist. An existing file is replaced.
    digits : int, optional
        Significant digits of each value (default 10).

    Raises
    ------
    InputError
        `path` not a usable ``.csv`` path or its folder missing; `trace` or `digits` invalid.
    """
    out = as_path(path, what="the trace CSV file to write")
    if out.suffix.lower() != ".csv":
        raise InputError(f"`path` = {str(out)!r}: give a file name ending in .csv")
    if not out.parent.is_dir():
        raise InputError(
            f"`path` = {str(out)!r}: the folder {str(out.parent)!r} does not exist; create it first"
        )
    out.write_text(format_trace(trace, digits=digits), encoding="utf-8")
    return out


def _parse_rows(rows, names: list[str], source: str) -> tuple[list[list[float]], list[int]]:
    """(values, line numbers) of the data rows: one number per header column."""
    values, linenos = [], []
    for n, line in rows:
        cells = [c.strip() for c in line.split(",")]
        if len(cells) != len(names):
            raise InputError(
                f"{source}, line {n}: {len(cells)} cell(s) but the header has "
                f"{len(names)} columns ({', '.join(names)})"
            )
        row = []
        for name, cell in zip(names, cells):
            try:
                row.append(float(cell))
            except ValueError:
                raise InputError(
                    f"{source}, line {n}, column `{name}`: cannot read {cell!r} "
                    f"as a number; fix the value or comment the row out with #"
                ) from None
        values.append(row)
        linenos.append(n)
    return values, linenos


def _parse_header(header: str, where: str, g: float):
    """(names, SI factors, written units) of a header row."""
    names, factors, written = [], [], {}
    for col, cell in enumerate(header.split(","), start=1):
        m = _HEADER_CELL.match(cell)
        name, unit = (m.group(1), m.group(2)) if m else (cell.strip(), None)
        if not name:
            raise InputError(
                f"{where}: column {col} has no name; accepted columns: {ACCEPTED_COLUMNS}"
            )
        kind = _kind(name)
        if kind is None:
            raise InputError(
                f"{where}: unknown column `{name}` (column {col}); accepted "
                f"columns: {ACCEPTED_COLUMNS}"
            )
        if name.lower() in (n.lower() for n in names):
            raise InputError(f"{where}: column `{name}` appears twice; keep one")
        factors.append(_si_factor(name, kind, unit, where, g))
        names.append(name)
        written[name] = unit
    times = [n for n in names if _kind(n)[0] == "time"]
    if len(times) != 1:
        raise InputError(
            f"{where}: {'no' if not times else 'more than one'} time column "
            f"(`t [s]` or `time [s]`); give exactly one"
        )
    if len(names) < 2:
        raise InputError(
            f"{where}: no channel column besides time; accepted columns: {ACCEPTED_COLUMNS}"
        )
    return names, factors, written
