"""How far a simulation is from a recorded trace, channel by channel (paper 001, Section 4.3).

`compare_trace` gives `ChannelMetrics` per channel of a `multimass.inputs.traces.Trace`;
`align` puts the measured and simulated signals on the trace's time grid.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..errors import InputError
from ..inputs.traces import Trace, _kind
from ..model.structure import Structure, from_specimen

__all__ = ["ChannelMetrics", "compare_trace", "align", "channel_columns"]


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
        (``"theta"``, ``"ag"`` or ``"a<node>"``).
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
        ``max |meas|`` and ``max |sim|`` on the trace's samples in the overlap.
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
    return structure if isinstance(structure, Structure) else from_specimen(structure)


def _check_trace(trace) -> None:
    if not isinstance(trace, Trace):
        raise InputError(
            f"`trace` = {trace!r:.60}: give a Trace, e.g. multimass.inputs.traces.read_trace('test.csv')"
        )


def _check_response(response) -> pd.DataFrame:
    """The recorded series of a simulation result; InputError for anything else."""
    df = getattr(response, "series", None)
    if not isinstance(df, pd.DataFrame) or "t" not in df.columns:
        raise InputError(
            f"`response` = {response!r:.60}: give the result of multimass.simulate "
            "(a Response with a recorded series)"
        )
    if df.empty or len(df) < 2:
        raise InputError(
            "`response` has no recorded series: simulate with `output_dt` set "
            "(e.g. the default 1e-3 s)"
        )
    return df


def _check_offset(t_offset) -> float:
    if (
        isinstance(t_offset, bool)
        or not isinstance(t_offset, numbers.Real)
        or not math.isfinite(t_offset)
    ):
        raise InputError(
            f"`t_offset` = {t_offset!r:.60}: give the trace time of the "
            "simulation's t = 0 in s (a finite number, e.g. trace.time[0])"
        )
    return float(t_offset)


def channel_columns(trace: Trace, structure) -> dict[str, str]:
    """The `Response.series` column matching each trace channel.

    ``theta`` → ``"theta"``; ``ag`` (the table's acceleration) → ``"ag"`` (the
    simulated ground acceleration); ``a_<sensor>`` → ``"a<node>"`` with the node of
    the specimen's named sensor; ``a<k>`` / ``a_node<k>`` → ``"a<k>"``.

    Raises
    ------
    InputError
        Naming the column: an unknown sensor, a node outside 1..N, or an
        acceleration channel for a rigid block (only θ can be compared).
    """
    _check_trace(trace)
    st = _structure(structure)
    out = {}
    for name in trace.channels:
        kind = _kind(name)
        if kind[0] in ("theta", "ag"):
            out[name] = kind[0]
            continue
        where = f"{trace.source}, column `{name}`"
        if st.n == 0:
            raise InputError(
                f"{where}: {st.name!r} is a rigid block without elastic nodes, so only "
                "`theta` can be compared (and the table's `ag`); remove the acceleration column"
            )
        node = kind[1]
        if kind[0] == "sensor":
            try:
                node = st.specimen.sensor_node(kind[1])
            except ValueError as err:
                raise InputError(
                    f"{where}: {err}; or name the node instead: a<k> or a_node<k> (k = 1..{st.n})"
                ) from None
        if not 1 <= node <= st.n:
            raise InputError(
                f"{where}: node {node} does not exist; {st.name!r} has nodes 1..{st.n}"
            )
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
    _check_trace(trace)
    df = _check_response(response)
    t_offset = _check_offset(t_offset)
    if not isinstance(name, str) or name not in trace.channels:
        raise InputError(
            f"`name` = {name!r:.60}: not a channel of {trace.source}; channels: "
            f"{', '.join(trace.channels)}"
        )
    column = channel_columns(trace, structure)[name]
    if column not in df.columns:
        raise InputError(
            f"`response` has no column {column!r} for channel `{name}`: was it "
            f"simulated with `structure` ({_structure(structure).name!r})?"
        )
    tau = df["t"].to_numpy(dtype=float) + t_offset
    tol = 1e-9 * max(1.0, abs(tau[-1]))
    mask = (trace.time >= tau[0] - tol) & (trace.time <= tau[-1] + tol)
    if np.count_nonzero(mask) < 2:
        raise InputError(
            f"{trace.source}: fewer than 2 samples of the trace ([{trace.time[0]:g}, "
            f"{trace.time[-1]:g}] s) fall in the simulation's span ([{tau[0]:g}, "
            f"{tau[-1]:g}] s on the trace's clock, `t_offset` = {t_offset:g} s); "
            f"check `t_offset` and the simulation's `t_end`"
        )
    t = trace.time[mask]
    sim = _interp(tau, df[column].to_numpy(dtype=float), np.clip(t, tau[0], tau[-1]))
    return t, np.asarray(trace.channels[name][mask]), sim


def _rms(t: np.ndarray, e: np.ndarray) -> float:
    """sqrt( (1/T) ∫ e² dt ), trapezoidal rule."""
    e2 = e * e
    return math.sqrt(float(np.sum(0.5 * (e2[1:] + e2[:-1]) * np.diff(t))) / float(t[-1] - t[0]))


def compare_trace(
    trace: Trace, response, structure, *, t_offset: float = 0.0
) -> dict[str, ChannelMetrics]:
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
        `trace` not a Trace, `response` not a simulation result with a recorded
        series, `t_offset` not a finite number; an unknown sensor or node, an
        acceleration channel for a rigid block, or fewer than 2 trace samples
        inside the simulated span.
    SpecimenError
        If `structure` names an invalid specimen file.
    """
    _check_trace(trace)
    _check_response(response)
    _check_offset(t_offset)
    columns = channel_columns(trace, structure)
    out = {}
    for name in trace.channels:
        t, meas, sim = align(trace, response, structure, name, t_offset=t_offset)
        rms_err, rms_meas = _rms(t, sim - meas), _rms(t, meas)
        i_m, i_s = int(np.argmax(np.abs(meas))), int(np.argmax(np.abs(sim)))
        p_m, p_s = float(abs(meas[i_m])), float(abs(sim[i_s]))
        out[name] = ChannelMetrics(
            channel=name,
            column=columns[name],
            units=trace.si_units(name),
            t_start=float(t[0]),
            t_end=float(t[-1]),
            n_samples=int(t.size),
            rms_error=rms_err,
            rms_measured=rms_meas,
            nrmse=rms_err / rms_meas if rms_meas > 0.0 else None,
            peak_measured=p_m,
            peak_simulated=p_s,
            peak_error=p_s - p_m,
            peak_error_rel=(p_s - p_m) / p_m if p_m > 0.0 else None,
            t_peak_measured=float(t[i_m]),
            t_peak_simulated=float(t[i_s]),
            peak_time_shift_s=float(t[i_s] - t[i_m]),
        )
    return out
