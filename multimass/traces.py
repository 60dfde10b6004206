"""Recorded test traces (θ and accelerations) and their comparison with simulations.

A trace is a CSV file with a header row naming each column and its unit in brackets::

    # optional comment lines start with '#'
    t [s],theta [deg],a_A2 [g],a_A4 [m/s2]
    0.000,2.8648,0.0012,0.013
    ...

* time: ``t`` or ``time``, in ``s`` or ``ms``; strictly increasing, any spacing
  (unlike a ground-motion record, a trace need not be uniformly sampled);
* ``theta``: base rotation in ``rad`` or ``deg`` (paper 001 Fig 1: θ > 0 rocks
  about the right pivot);
* ``a_<sensor>`` (e.g. ``a_A2``, a named sensor of the specimen), ``a<k>`` or
  ``a_node<k>`` (1-based node k): total lateral acceleration (paper 001 Eq 7) in
  ``g``, ``m/s2``, ``cm/s2`` (``gal``) or ``mm/s2``.

Names are case-insensitive. Units are never guessed: a column without a unit is an
error. Values are converted to SI (s, rad, m/s²) on reading.

`compare_trace` measures, per channel, how far a simulation is from the trace (see
`ChannelMetrics`); `align` gives the two signals on the trace's time grid.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType

import numpy as np

from .errors import InputError
from .excitations import FreeRelease
from .units import G, canonical_units, to_mps2

__all__ = ["Trace", "ChannelMetrics", "read_trace", "compare_trace", "align",
           "channel_columns", "ACCEPTED_COLUMNS"]

#: What a header may contain (shown in error messages).
ACCEPTED_COLUMNS = ("`t [s]` or `time [s]` (s or ms); `theta [rad]` (rad or deg); "
                    "`a_<sensor> [g]` (e.g. a_A2), `a<k>` or `a_node<k>` (1-based node k) "
                    "in g, m/s2, cm/s2 (gal) or mm/s2")

_TIME_UNITS = {"s": 1.0, "sec": 1.0, "ms": 1e-3}
_ANGLE_UNITS = {"rad": 1.0, "radian": 1.0, "radians": 1.0,
                "deg": math.pi / 180.0, "degree": math.pi / 180.0, "degrees": math.pi / 180.0}
_HEADER_CELL = re.compile(r"^\s*([^\[\]()]*?)\s*(?:[\[(]\s*([^\[\]()]*?)\s*[\])])?\s*$")
_NODE = re.compile(r"^a(?:_node)?(\d+)$", re.IGNORECASE)
_SENSOR = re.compile(r"^a_(\w+)$", re.IGNORECASE)


def _kind(name: str):
    """("time",), ("theta",), ("node", k), ("sensor", label), or None if unknown."""
    low = name.lower()
    if low in ("t", "time"):
        return ("time",)
    if low == "theta":
        return ("theta",)
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
            raise InputError(f"{where}: column `{name}` has no unit (units are never guessed): "
                             f"write it as `{name} [{si}]`; accepted units: {accepted}")
        if unit.lower() not in table:
            raise InputError(f"{where}: column `{name}` has unit {unit!r}; accepted: {accepted}")
        return table[unit.lower()]
    if not unit:
        raise InputError(f"{where}: column `{name}` has no unit (units are never guessed): "
                         f"write it as `{name} [g]`; accepted units: g, m/s2, cm/s2 (gal), mm/s2")
    try:
        return to_mps2(1.0, canonical_units(unit, argument=name), g=g)
    except InputError as err:
        raise InputError(f"{where}: column {err}") from None


# ---------------------------------------------------------------------------- the trace
def _where(source: str, lines, k: int) -> str:
    return f"{source}, line {lines[k]}" if lines is not None else f"{source}, sample {k}"


def _check(time, channels, source, lines=None) -> None:
    """Validate samples: ≥ 2 rows, finite values, strictly increasing time."""
    if time.ndim != 1 or time.size < 2:
        raise InputError(f"{source}: {time.size} sample(s); a trace needs at least 2 rows")
    for name, values in (("time", time), *channels.items()):
        if values.shape != time.shape:
            raise InputError(f"{source}: column `{name}` has shape {values.shape}, the time "
                             f"column {time.shape}: give one value per time")
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            k = int(bad[0])
            raise InputError(f"{_where(source, lines, k)}, column `{name}`: value "
                             f"{float(values[k])!r} is not a finite number; fix or remove the row")
    bad = np.flatnonzero(np.diff(time) <= 0.0)
    if bad.size:
        k = int(bad[0]) + 1
        raise InputError(f"{_where(source, lines, k)}, column `time`: t = {float(time[k])!r} s "
                         f"does not increase (previous row t = {float(time[k - 1])!r} s); times "
                         f"must be strictly increasing: sort the rows or remove duplicates")


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
    """

    time: np.ndarray
    channels: dict
    units: dict
    source: str = "arrays"
    time_units: str = "s"
    g: float = G
    _factors: dict = field(default=None, init=False, repr=False)

    def __post_init__(self):
        time = np.array(self.time, dtype=float)
        chans = {str(k): np.array(v, dtype=float) for k, v in dict(self.channels).items()}
        units = {str(k): str(v) for k, v in dict(self.units).items()}
        if not chans:
            raise InputError(f"{self.source}: no channel; accepted columns: {ACCEPTED_COLUMNS}")
        if str(self.time_units).lower() not in _TIME_UNITS:
            raise InputError(f"{self.source}: `time_units` = {self.time_units!r}; accepted: s, ms")
        factors = {}
        for name in chans:
            kind = _kind(name)
            if kind is None or kind[0] == "time":
                raise InputError(f"{self.source}: unknown channel `{name}`; accepted columns: "
                                 f"{ACCEPTED_COLUMNS}")
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
    def duration(self) -> float:
        """Last minus first sample time (s)."""
        return float(self.time[-1] - self.time[0])

    def si_units(self, name: str) -> str:
        """``"rad"`` for θ, ``"m/s2"`` for an acceleration channel."""
        return "rad" if _kind(name)[0] == "theta" else "m/s2"

    def to_written_units(self, name: str, values):
        """Convert SI `values` of channel `name` back to the unit it was written in."""
        return np.asarray(values, dtype=float) / self._factors[name]

    def free_release(self) -> FreeRelease:
        """The free release matching the trace: θ0 = θ at the first sample, at rest."""
        theta = next((v for k, v in self.channels.items() if _kind(k)[0] == "theta"), None)
        if theta is None:
            raise InputError(f"{self.source}: no `theta` column, so the release angle is unknown; "
                             f"give the excitation (e.g. FreeRelease(theta0=...)) explicitly")
        return FreeRelease(theta0=float(theta[0]))


def read_trace(path, *, g: float = G) -> Trace:
    """Read a recorded trace from a CSV file with units in the header.

    Parameters
    ----------
    path : str or Path
        CSV file: optional ``#`` comment lines, a header row such as
        ``t [s],theta [deg],a_A2 [g],a_A4 [m/s2]``, then one row of numbers per
        sample (see the module docstring for the accepted names and units).
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
        strictly increasing.
    """
    path = Path(path)
    source = str(path)
    with open(path, encoding="utf-8", errors="replace") as f:
        rows = [(n, line.strip()) for n, line in enumerate(f.read().splitlines(), start=1)]
    rows = [(n, line) for n, line in rows if line and not line.startswith("#")]
    if not rows:
        raise InputError(f"{source}: empty file; expected a header such as "
                         f"`t [s],theta [rad],a_A2 [g]` and rows of numbers")
    header_line, header = rows[0]
    names, factors, written = _parse_header(header, f"{source}, line {header_line}", g)
    values, linenos = [], []
    for n, line in rows[1:]:
        cells = [c.strip() for c in line.split(",")]
        if len(cells) != len(names):
            raise InputError(f"{source}, line {n}: {len(cells)} cell(s) but the header has "
                             f"{len(names)} columns ({', '.join(names)})")
        row = []
        for name, cell in zip(names, cells):
            try:
                row.append(float(cell))
            except ValueError:
                raise InputError(f"{source}, line {n}, column `{name}`: cannot read {cell!r} "
                                 f"as a number; fix the value or comment the row out with #") from None
        values.append(row)
        linenos.append(n)
    data = np.array(values, dtype=float).reshape(len(values), len(names)) * np.array(factors)
    i_time = next(i for i, name in enumerate(names) if _kind(name)[0] == "time")
    chans = {name: data[:, i] for i, name in enumerate(names) if i != i_time}
    _check(data[:, i_time], chans, source, linenos)
    return Trace(time=data[:, i_time], channels=chans,
                 units={k: written[k] for k in chans}, source=source,
                 time_units=written[names[i_time]], g=g)


def _parse_header(header: str, where: str, g: float):
    """(names, SI factors, written units) of a header row."""
    names, factors, written = [], [], {}
    for col, cell in enumerate(header.split(","), start=1):
        m = _HEADER_CELL.match(cell)
        name, unit = (m.group(1), m.group(2)) if m else (cell.strip(), None)
        if not name:
            raise InputError(f"{where}: column {col} has no name; accepted columns: "
                             f"{ACCEPTED_COLUMNS}")
        kind = _kind(name)
        if kind is None:
            raise InputError(f"{where}: unknown column `{name}` (column {col}); accepted "
                             f"columns: {ACCEPTED_COLUMNS}")
        if name.lower() in (n.lower() for n in names):
            raise InputError(f"{where}: column `{name}` appears twice; keep one")
        factors.append(_si_factor(name, kind, unit, where, g))
        names.append(name)
        written[name] = unit
    times = [n for n in names if _kind(n)[0] == "time"]
    if len(times) != 1:
        raise InputError(f"{where}: {'no' if not times else 'more than one'} time column "
                         f"(`t [s]` or `time [s]`); give exactly one")
    if len(names) < 2:
        raise InputError(f"{where}: no channel column besides time; accepted columns: "
                         f"{ACCEPTED_COLUMNS}")
    return names, factors, written


# ---------------------------------------------------------------------------- comparison
@dataclass(frozen=True)
class ChannelMetrics:
    """How far a simulated channel is from the measured one (SI units).

    Every quantity is evaluated on the trace's own samples inside the overlap of
    the two time spans, with the simulation interpolated linearly onto them
    (across an event the simulation's pre-event values are used before it and its
    post-event values from it on). Time-weighted means use the trapezoidal rule,
    so a non-uniformly sampled trace is weighted by time, not by sample count.

    Attributes
    ----------
    channel, column : str
        Trace channel (e.g. ``"a_A2"``) and the `Response.series` column it maps to
        (``"theta"`` or ``"a<node>"``).
    units : str
        SI units of the values below: ``"rad"`` or ``"m/s2"``.
    t_start, t_end : float
        Overlap on the trace's clock (s).
    n_samples : int
        Trace samples in the overlap.
    rms_error : float
        sqrt( (1/T) ∫ (sim − meas)² dt ) over the overlap of length T.
    rms_measured : float
        sqrt( (1/T) ∫ meas² dt ).
    nrmse : float or None
        rms_error / rms_measured (None if the measured signal is identically 0).
    peak_measured, peak_simulated : float
        max |meas| and max |sim| on the trace's samples in the overlap.
    peak_error : float
        peak_simulated − peak_measured (signed: > 0 when the simulation over-predicts).
    peak_error_rel : float or None
        peak_error / peak_measured (None if peak_measured is 0).
    t_peak_measured, t_peak_simulated : float
        Times of those peaks (first occurrence), s.
    peak_time_shift_s : float
        t_peak_simulated − t_peak_measured (> 0: the simulated peak comes later);
        resolved to the trace's sampling step.
    """

    channel: str
    column: str
    units: str
    t_start: float
    t_end: float
    n_samples: int
    rms_error: float
    rms_measured: float
    nrmse: float | None
    peak_measured: float
    peak_simulated: float
    peak_error: float
    peak_error_rel: float | None
    t_peak_measured: float
    t_peak_simulated: float
    peak_time_shift_s: float

    def to_dict(self) -> dict:
        """JSON-ready dict of the fields."""
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


def _structure(structure):
    from .structure import Structure, from_specimen

    return structure if isinstance(structure, Structure) else from_specimen(structure)


def channel_columns(trace: Trace, structure) -> dict[str, str]:
    """The `Response.series` column matching each trace channel.

    ``theta`` → ``"theta"``; ``a_<sensor>`` → ``"a<node>"`` with the node of the
    specimen's named sensor; ``a<k>`` / ``a_node<k>`` → ``"a<k>"``.

    Raises
    ------
    InputError
        Naming the column: an unknown sensor, a node outside 1..N, or an
        acceleration channel for a rigid block (only θ can be compared).
    """
    st = _structure(structure)
    out = {}
    for name in trace.channels:
        kind = _kind(name)
        if kind[0] == "theta":
            out[name] = "theta"
            continue
        where = f"{trace.source}, column `{name}`"
        if st.n == 0:
            raise InputError(f"{where}: {st.name!r} is a rigid block without elastic nodes, so "
                             f"only `theta` can be compared; remove the acceleration column")
        node = kind[1]
        if kind[0] == "sensor":
            try:
                node = st.specimen.sensor_node(kind[1])
            except ValueError as err:
                raise InputError(f"{where}: {err}; or name the node instead: a<k> or "
                                 f"a_node<k> (k = 1..{st.n})") from None
        if not 1 <= node <= st.n:
            raise InputError(f"{where}: node {node} does not exist; {st.name!r} has nodes "
                             f"1..{st.n}")
        out[name] = f"a{node}"
    return out


def _interp(t: np.ndarray, y: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Linear interpolation of samples (t, y) whose t may repeat at events.

    For x inside (t_k, t_k+1) the interval's two samples are used, so a jump
    recorded as two samples at one time is never smeared; at a repeated time
    the later (post-event) sample is returned.
    """
    i = np.clip(np.searchsorted(t, x, side="right"), 1, t.size - 1)
    t0, t1 = t[i - 1], t[i]
    span = t1 - t0
    w = np.where(span > 0.0, (x - t0) / np.where(span > 0.0, span, 1.0), 1.0)
    return y[i - 1] + w * (y[i] - y[i - 1])


def align(trace: Trace, response, structure, name: str, *, t_offset: float = 0.0):
    """Measured and simulated channel `name` on the trace's samples in the overlap.

    Parameters
    ----------
    trace : Trace
    response : Response
        A simulation with a recorded series (``output_dt`` not None).
    structure : Structure, specimen or str
        The simulated structure (maps sensor names to nodes).
    name : str
        A channel of `trace`.
    t_offset : float, optional
        Trace time of the simulation's t = 0 (s): simulation time τ is compared
        with trace time τ + t_offset. For a release from the trace's first sample
        use ``trace.time[0]``.

    Returns
    -------
    t, measured, simulated : ndarray
        Trace times (s) in the overlap and both signals there, in SI units.
    """
    if name not in trace.channels:
        raise InputError(f"`name` = {name!r}: not a channel of {trace.source}; channels: "
                         f"{', '.join(trace.channels)}")
    column = channel_columns(trace, structure)[name]
    df = response.series
    if df.empty or len(df) < 2:
        raise InputError("`response` has no recorded series: simulate with `output_dt` set "
                         "(e.g. the default 1e-3 s)")
    tau = df["t"].to_numpy(dtype=float) + float(t_offset)
    tol = 1e-9 * max(1.0, abs(tau[-1]))
    mask = (trace.time >= tau[0] - tol) & (trace.time <= tau[-1] + tol)
    if np.count_nonzero(mask) < 2:
        raise InputError(f"{trace.source}: fewer than 2 samples of the trace ([{trace.time[0]:g}, "
                         f"{trace.time[-1]:g}] s) fall in the simulation's span ([{tau[0]:g}, "
                         f"{tau[-1]:g}] s on the trace's clock, `t_offset` = {t_offset:g} s); "
                         f"check `t_offset` and the simulation's `t_end`")
    t = trace.time[mask]
    sim = _interp(tau, df[column].to_numpy(dtype=float), np.clip(t, tau[0], tau[-1]))
    return t, np.asarray(trace.channels[name][mask]), sim


def _rms(t: np.ndarray, e: np.ndarray) -> float:
    """sqrt( (1/T) ∫ e² dt ), trapezoidal rule."""
    e2 = e * e
    return math.sqrt(float(np.sum(0.5 * (e2[1:] + e2[:-1]) * np.diff(t))) / float(t[-1] - t[0]))


def compare_trace(trace: Trace, response, structure, *,
                  t_offset: float = 0.0) -> dict[str, ChannelMetrics]:
    """Error metrics of a simulation against every channel of a recorded trace.

    Parameters
    ----------
    trace : Trace
        From `read_trace`.
    response : Response
        From `multimass.simulate`, with a recorded series.
    structure : Structure, specimen or str
        The simulated structure: maps ``a_<sensor>`` channels to nodes.
    t_offset : float, optional
        Trace time of the simulation's t = 0 (s); see `align`.

    Returns
    -------
    dict of str to ChannelMetrics
        One entry per trace channel, in column order (SI units; see
        `ChannelMetrics` for the definitions).

    Raises
    ------
    InputError
        An unknown sensor or node, an acceleration channel for a rigid block, an
        empty series, or fewer than 2 trace samples inside the simulated span.
    """
    columns = channel_columns(trace, structure)
    out = {}
    for name in trace.channels:
        t, meas, sim = align(trace, response, structure, name, t_offset=t_offset)
        rms_err, rms_meas = _rms(t, sim - meas), _rms(t, meas)
        i_m, i_s = int(np.argmax(np.abs(meas))), int(np.argmax(np.abs(sim)))
        p_m, p_s = float(abs(meas[i_m])), float(abs(sim[i_s]))
        out[name] = ChannelMetrics(
            channel=name, column=columns[name], units=trace.si_units(name),
            t_start=float(t[0]), t_end=float(t[-1]), n_samples=int(t.size),
            rms_error=rms_err, rms_measured=rms_meas,
            nrmse=rms_err / rms_meas if rms_meas > 0.0 else None,
            peak_measured=p_m, peak_simulated=p_s, peak_error=p_s - p_m,
            peak_error_rel=(p_s - p_m) / p_m if p_m > 0.0 else None,
            t_peak_measured=float(t[i_m]), t_peak_simulated=float(t[i_s]),
            peak_time_shift_s=float(t[i_s] - t[i_m]))
    return out
