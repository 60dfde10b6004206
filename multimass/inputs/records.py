"""Recorded ground motions: the `Record` excitation and readers for record files.

Two formats are read:

* two-column text files ``t a`` (`read_two_column`), separated by blanks or commas,
  with ``#`` comment lines; the units of ``a`` must be given explicitly (never guessed);
* PEER NGA ``.AT2`` files (`read_at2`): 4 header lines (the 3rd states the units, the
  4th NPTS and DT), then the values, usually 5 a line.

`read_record` dispatches on the suffix. Every bad file raises `InputError` naming the
file, the line or field, and the fix.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .excitations import Excitation
from .samples import (
    DT_RTOL,
    check_peak,
    check_samples,
    check_scale,
    float_array,
    scaled_to_mps2,
    units_of,
)
from .textfile import as_path, read_text
from .units import canonical_units, to_mps2

__all__ = ["Record", "read_two_column", "read_at2", "read_record"]


# ---------------------------------------------------------------------------- the record
@dataclass(frozen=True, eq=False)
class Record(Excitation):
    """A recorded accelerogram with a uniform time step (m/s², already scaled).

    ü_g is interpolated linearly between samples on the uniform grid
    ``time[0] + k dt`` and is zero before the first and after the last sample.

    Build it with `read_record`, `read_two_column`, `read_at2` or `Record.from_arrays`.
    Every way checks that the values as written (``accel / scale``, in `units`) peak
    within `multimass.inputs.samples.PEAK_G` (1e-4 to 5 g): outside, a unit slip is named
    (`multimass.inputs.samples.check_peak`); a larger or smaller synthetic motion is written at
    an earthquake's amplitude and given its factor as `scale`.

    Attributes
    ----------
    time : ndarray
        Sample times (s), strictly increasing with a uniform step, time[0] ≥ 0.
    accel : ndarray
        Accelerations in m/s², after unit conversion and scaling.
    dt : float
        Time step (s); computed from `time` when not given.
    name : str
    units : str
        Units of the source values, as given (e.g. ``"g"``).
    scale : float
        Factor applied to the source values (e.g. A_sc = 1.1, paper 001 Section 4.4).
    source : str
        Where the samples came from (a file path, or ``"arrays"``).
    """

    time: np.ndarray
    accel: np.ndarray
    dt: float | None = None
    name: str = "record"
    units: str = "m/s2"
    scale: float = 1.0
    source: str = "arrays"
    kind = "record"

    def __post_init__(self):
        for label in ("name", "units", "source"):
            if not isinstance(getattr(self, label), str):
                raise InputError(f"Record: `{label}` = {getattr(self, label)!r:.60}: give a string")
        time = float_array(self.source, "time", self.time).copy()
        accel = float_array(self.source, "accel", self.accel).copy()
        dt = check_samples(time, accel, self.source)
        if self.dt is not None and not (
            isinstance(self.dt, (int, float))
            and not isinstance(self.dt, bool)
            and abs(self.dt - dt) <= DT_RTOL * dt
        ):
            raise InputError(
                f"{self.source}: `dt` = {self.dt!r} s disagrees with the step of "
                f"`time` ({dt!r} s); omit `dt` or correct it"
            )
        check_scale(self.source, self.scale)
        # the values as the source wrote them (before `scale`) in a plausible unit
        check_peak(self.source, time, accel / (self.scale * to_mps2(1.0, self.units)), self.units)
        time.flags.writeable = False
        accel.flags.writeable = False
        object.__setattr__(self, "time", time)
        object.__setattr__(self, "accel", accel)
        object.__setattr__(self, "dt", dt)
        self._cache()

    def _cache(self) -> None:
        # one tuple read per call: (t_start, t_end, 1/dt, last interval index, samples)
        fast = (
            float(self.time[0]),
            float(self.time[-1]),
            1.0 / self.dt,
            self.time.size - 2,
            self.accel.tolist(),
        )
        object.__setattr__(self, "_fast", fast)

    @classmethod
    def from_arrays(
        cls,
        time,
        accel,
        units: str,
        scale: float = 1.0,
        name: str = "record",
        source: str = "arrays",
    ) -> Record:
        """A record from arrays of times (s) and accelerations in `units`, times `scale`."""
        if not isinstance(source, str):
            raise InputError(f"Record.from_arrays: `source` = {source!r:.60}: give a string")
        units_c = units_of(source, units)
        scale = check_scale(source, scale)
        time = float_array(source, "time", time)
        accel = float_array(source, "accel", accel)
        check_samples(time, accel, source)
        return cls(
            time=time,
            accel=scaled_to_mps2(source, accel, units_c, scale),
            name=name,
            units=units,
            scale=scale,
            source=source,
        )

    def scaled(self, factor: float) -> Record:
        """The same record scaled again by `factor` (scale factors multiply)."""
        factor = check_scale(self.source, factor)
        return Record(
            time=self.time,
            accel=self.accel * factor,
            dt=self.dt,
            name=self.name,
            units=self.units,
            scale=self.scale * factor,
            source=self.source,
        )

    # pickling: fields only; the interpolation cache is rebuilt
    def __getstate__(self):
        return {
            "time": self.time,
            "accel": self.accel,
            "dt": self.dt,
            "name": self.name,
            "units": self.units,
            "scale": self.scale,
            "source": self.source,
        }

    def __setstate__(self, state):
        for key, value in state.items():
            if isinstance(value, np.ndarray):
                value = value.copy()
                value.flags.writeable = False
            object.__setattr__(self, key, value)
        self._cache()

    def __eq__(self, other):
        if not isinstance(other, Record):
            return NotImplemented
        return (
            np.array_equal(self.time, other.time)
            and np.array_equal(self.accel, other.accel)
            and (self.dt, self.name, self.units, self.scale, self.source)
            == (other.dt, other.name, other.units, other.scale, other.source)
        )

    def __hash__(self):
        return hash((self.name, self.dt, self.time.size, self.accel.tobytes()))

    @property
    def duration(self) -> float:
        """Time of the last sample (s); ü_g ≡ 0 after it."""
        return self._fast[1]

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """First and last sample times: ü_g may jump from or to zero there."""
        t_start, t_end = self._fast[:2]
        return (t_start, t_end)

    @property
    def kinks(self) -> np.ndarray:
        """The sample times (s): ü_g is linear between samples, so its slope jumps at
        each. A Runge–Kutta step across one loses its order without its error estimate
        seeing it; the solve_ivp path stops at each (the compiled path ends its steps
        there)."""
        return self.time

    @property
    def npts(self) -> int:
        """Number of samples."""
        return self.time.size

    @property
    def pga(self) -> float:
        """Peak ground acceleration ``max |ü_g|`` (m/s²)."""
        return float(np.max(np.abs(self.accel)))

    def acceleration(self, t):
        """Ground acceleration ü_g(t) in m/s², linear between samples, 0 outside them.

        Parameters
        ----------
        t : float or array_like
            Time(s) in s.

        Returns
        -------
        float or ndarray
        """
        if isinstance(t, (float, int)):
            t_start, t_end, inv_dt, last, a = self._fast
            if t < t_start or t > t_end:
                return 0.0
            x = (t - t_start) * inv_dt  # index arithmetic on the uniform grid
            i = int(x)
            if i > last:
                i = last
            ai = a[i]
            return ai + (x - i) * (a[i + 1] - ai)
        arr = np.asarray(t, dtype=float)
        out = self._array(arr)
        return float(out) if arr.ndim == 0 else out

    __call__ = acceleration

    def _scalar(self, t: float) -> float:
        return self.acceleration(float(t))

    def _array(self, t: np.ndarray) -> np.ndarray:
        t_start, t_end, inv_dt, last, _ = self._fast
        x = (t - t_start) * inv_dt
        i = np.clip(np.floor(x), 0, last).astype(np.intp)
        a = self.accel
        with np.errstate(over="ignore", invalid="ignore"):  # far outside: masked below
            out = a[i] + (x - i) * (a[i + 1] - a[i])
        return np.where((t >= t_start) & (t <= t_end), out, 0.0)

    def describe(self) -> dict:
        return {
            "kind": self.kind,
            "name": self.name,
            "source": self.source,
            "units": self.units,
            "scale": self.scale,
            "dt": self.dt,
            "npts": self.npts,
            "t_start": self._fast[0],
            "duration": self.duration,
            "pga": self.pga,
        }


# ---------------------------------------------------------------------------- readers
_TWO_COLUMN = "a record file of two columns `t a` (time in s, acceleration)"
_AT2 = "a PEER .AT2 acceleration file"
_SUFFIXES = (".at2", ".dat", ".txt", ".csv")


def _read_lines(path, what: str) -> list[str]:
    """Lines of a UTF-8 text file; InputError if it is missing, a folder, empty or binary."""
    return read_text(path, what=what, suffixes=_SUFFIXES).splitlines()


def _name(source: str, name) -> None:
    if name is not None and not isinstance(name, str):
        raise InputError(
            f"{source}: `name` = {name!r}: give a string, or omit it to use the file's stem"
        )


def read_two_column(path, units: str, scale: float = 1.0, name: str | None = None) -> Record:
    """Read a two-column record ``t a`` (time in s, acceleration in `units`).

    Columns are separated by blanks and/or a comma; blank lines and lines starting
    with ``#`` are skipped.

    Parameters
    ----------
    path : str or Path
    units : str
        Units of the acceleration column: ``"g"``, ``"m/s2"``, ``"cm/s2"`` (``"gal"``),
        ``"mm/s2"``. Required: units are never guessed.
    scale : float, optional
        Factor (> 0) applied to the accelerations (e.g. 1.1).
    name : str, optional
        Defaults to the file's stem.

    Returns
    -------
    Record

    Raises
    ------
    InputError
        Naming the file and line: unknown units, unreadable numbers, a line without
        two columns, non-finite values, fewer than 2 samples, non-increasing or
        non-uniform time, a bad `scale`, a peak outside 1e-4–5 g before `scale` (the
        likely unit slip named).
    """
    path = as_path(path, what=_TWO_COLUMN)
    source = str(path)
    units_c = units_of(source, units)
    scale = check_scale(source, scale)
    _name(source, name)
    times, values, linenos = [], [], []
    for lineno, line in enumerate(_read_lines(path, _TWO_COLUMN), start=1):
        text = line.strip()
        if not text or text.startswith("#"):
            continue
        parts = text.replace(",", " ").split()
        if len(parts) != 2:
            raise InputError(
                f"{source}, line {lineno}: expected two columns `t a` (time in s, "
                f"acceleration in {units}), found {len(parts)}: {text!r}; "
                f"comment header lines out with #"
            )
        try:
            t, a = float(parts[0]), float(parts[1])
        except ValueError:
            raise InputError(
                f"{source}, line {lineno}: cannot read {text!r} as two numbers "
                f"`t a`; fix the value or comment the line out with #"
            ) from None
        times.append(t)
        values.append(a)
        linenos.append(lineno)
    time = np.array(times)
    accel = np.array(values)
    check_samples(time, accel, source, linenos)
    return Record(
        time=time,
        accel=scaled_to_mps2(source, accel, units_c, scale),
        name=name or path.stem,
        units=units,
        scale=scale,
        source=source,
    )


_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?"
_NPTS = re.compile(r"NPTS\s*[=:]?\s*(\d+)", re.IGNORECASE)
_DT = re.compile(rf"\bDT\s*[=:]?\s*({_NUM})", re.IGNORECASE)
_OLD_HEADER = re.compile(rf"^\s*(\d+)\s+({_NUM})\s+NPTS\s*,\s*DT", re.IGNORECASE)  # old NGA
_UNITS_OF = re.compile(r"UNITS\s+OF\s+(\S+)", re.IGNORECASE)


def _at2_header(source: str, lines: list[str]) -> tuple[str, int, float]:
    """(canonical units, NPTS, DT) from the 4 header lines of a PEER .AT2 file."""
    if len(lines) < 5:
        raise InputError(
            f"{source}: {len(lines)} line(s); a PEER .AT2 file has 4 header "
            f"lines followed by the values"
        )
    kind_line = lines[2]
    for other in ("VELOCITY", "DISPLACEMENT"):
        if other in kind_line.upper():
            raise InputError(
                f"{source}, line 3: {kind_line.strip()!r} is a {other.lower()} "
                f"record; give the acceleration file (.AT2)"
            )
    match = _UNITS_OF.search(kind_line)
    if match is None:
        raise InputError(
            f"{source}, line 3: cannot find the units in {kind_line.strip()!r}; "
            f"expected e.g. 'ACCELERATION TIME SERIES IN UNITS OF G'"
        )
    raw = match.group(1).rstrip(".,;")
    try:
        units = canonical_units(raw)
    except InputError:
        raise InputError(
            f"{source}, line 3: unknown units {raw!r} in the header; accepted: "
            f"G, CM/S/S (cm/s2), M/S/S (m/s2), MM/S/S (mm/s2)"
        ) from None
    line4 = lines[3]
    old = _OLD_HEADER.match(line4)
    npts_m, dt_m = _NPTS.search(line4), _DT.search(line4)
    if old is not None:
        npts_s, dt_s = old.group(1), old.group(2)
    elif npts_m is not None and dt_m is not None:
        npts_s, dt_s = npts_m.group(1), dt_m.group(1)
    else:
        raise InputError(
            f"{source}, line 4: cannot read NPTS and DT from {line4.strip()!r}; "
            f"expected e.g. 'NPTS=  2000, DT=   0.020 SEC'"
        )
    npts = int(npts_s)
    dt = float(dt_s.replace("D", "E").replace("d", "e"))
    if not math.isfinite(dt) or dt <= 0.0:
        raise InputError(f"{source}, line 4: `DT` = {dt_s}: must be a finite time step > 0 (s)")
    if npts < 2:
        raise InputError(f"{source}, line 4: `NPTS` = {npts}: a record needs at least 2 samples")
    return units, npts, dt


def read_at2(path, scale: float = 1.0, name: str | None = None) -> Record:
    """Read a PEER NGA ``.AT2`` acceleration file.

    Header: line 3 states the units (``... IN UNITS OF G``), line 4 NPTS and DT
    (``NPTS=  2000, DT=   0.020 SEC``, ``NPTS= 2000 DT= .0200 SEC`` or the old
    ``2000 0.0200 NPTS, DT``). Then the NPTS values, any number a line (usually 5).
    Sample k is at t = k·DT, k = 0 … NPTS−1.

    Parameters
    ----------
    path : str or Path
    scale : float, optional
        Factor (> 0) applied to the accelerations.
    name : str, optional
        Defaults to the file's stem.

    Returns
    -------
    Record
        ``units`` is the header's unit (e.g. ``"g"``), converted to m/s².

    Raises
    ------
    InputError
        Naming the file and line: missing or unreadable header fields, a velocity or
        displacement file, unreadable or non-finite values, NPTS disagreeing with the
        number of values, a bad `scale`, a peak outside 1e-4–5 g before `scale`.
    """
    path = as_path(path, what=_AT2)
    source = str(path)
    scale = check_scale(source, scale)
    _name(source, name)
    lines = _read_lines(path, _AT2)
    units, npts, dt = _at2_header(source, lines)
    values = []
    for lineno, line in enumerate(lines[4:], start=5):
        for token in line.split():
            try:
                x = float(token.replace("D", "E").replace("d", "e"))
            except ValueError:
                raise InputError(
                    f"{source}, line {lineno}: cannot read {token!r} as a number; "
                    f"fix the value (values are separated by blanks)"
                ) from None
            if not math.isfinite(x):
                raise InputError(
                    f"{source}, line {lineno}: value {token!r} is not finite; fix or remove it"
                )
            values.append(x)
    if len(values) != npts:
        raise InputError(
            f"{source}: `NPTS` = {npts} in the header (line 4) but {len(values)} "
            f"values follow; the file may be truncated or NPTS wrong: correct it"
        )
    time = dt * np.arange(npts)
    accel = scaled_to_mps2(source, np.array(values), units, scale)
    return Record(
        time=time, accel=accel, name=name or path.stem, units=units, scale=scale, source=source
    )


def read_record(
    path, units: str | None = None, scale: float = 1.0, name: str | None = None
) -> Record:
    """Read a record file: PEER ``.AT2`` by its suffix, otherwise two columns ``t a``.

    Parameters
    ----------
    path : str or Path
    units : str, optional
        Required for two-column files. For ``.AT2`` files the header gives the units;
        `units`, if given, must agree with it.
    scale : float, optional
        Factor (> 0) on the accelerations.
    name : str, optional
        Defaults to the file's stem.

    Returns
    -------
    Record
    """
    path = as_path(path, what=f"{_AT2} or {_TWO_COLUMN}")
    if path.suffix.lower() == ".at2":
        record = read_at2(path, scale=scale, name=name)
        if units is not None and units_of(str(path), units) != record.units:
            raise InputError(
                f"{path}: `units` = {units!r} but the .AT2 header says "
                f"{record.units!r}; omit `units` for .AT2 files"
            )
        return record
    return read_two_column(path, units, scale=scale, name=name)
