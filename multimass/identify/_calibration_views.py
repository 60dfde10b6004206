"""Simulations seen as the traces record them, and how far they are (`calibrate`'s metrics).

A *view* is a `Response` whose series is the run recorded at the trace's own times
(anti-alias filtered, on the trace's clock, with the fitted biases added), so that
`multimass.analysis.trace_metrics.compare_trace` (with ``t_offset = 0``) and
`multimass.analysis.plots.plot_overlay` use it as they would any simulation.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd

from ..analysis.trace_metrics import compare_trace
from ..inputs.traces import Trace
from ._calibration_peaks import crossings, measured_peaks, model_peaks

__all__ = ["view", "window_trace", "channel_metrics", "feature_errors"]


def view(case, rec, nuis: dict, biases: dict):
    """The run `rec` of `case` as its trace records it (a `Response` on the trace's clock)."""
    t = case.t
    tm = t - nuis["tau"]
    cols = {"t": t}
    for ch, col in case.columns.items():
        if col in cols:
            continue
        values = rec.at(col, tm)
        if col == "theta":
            values = values + nuis["bias"]
        elif col != "ag":
            values = values + biases.get(ch, 0.0)
        cols[col] = values
    if "theta" not in cols:
        cols["theta"] = rec.at("theta", tm) + nuis["bias"]
    return dataclasses.replace(rec.response, series=pd.DataFrame(cols))


def window_trace(case) -> Trace:
    """The trace cut to the window fitted in stage 2."""
    tr = case.trace
    return Trace(
        time=case.t[case.idx],
        channels={k: np.asarray(x)[case.idx] for k, x in tr.channels.items()},
        units=dict(tr.units),
        source=tr.source,
        time_units=tr.time_units,
        g=tr.g,
        specimen=tr.specimen,
    )


def channel_metrics(case, response, st, spans=("window", "trace")) -> dict:
    """span → channel → `ChannelMetrics` (`compare_trace` over the window and the trace)."""
    out = {}
    for span in spans:
        trace = window_trace(case) if span == "window" else case.trace
        out[span] = compare_trace(trace, response, st, t_offset=0.0)
    return out


def feature_errors(case, rec, tau: float) -> dict:
    """Peak and impact-time errors of a run over the trace's large half-cycles.

    Peaks as `multimass.identify._calibration_peaks` finds them on both sides:
    ``peak_error`` (rad, simulated − measured peak of half-cycles 1 … K−1: the release
    is fitted); ``impact_time_error`` (s, simulated − measured time of the impacts
    ending the large half-cycles; None where the simulation has none); their RMS.
    """
    k = len(case.large)
    floor = case.segments.band
    p_sim = model_peaks(case, rec, k, floor)
    p_meas = np.maximum(measured_peaks(case), floor)
    side = int(np.sign(case.theta0)) if case.free else 0
    t_sim = [t + tau for t in crossings(rec.response.events, side)]
    t_meas = [h.t_stop for h in case.large if h.ends == "impact"]
    j0 = case.first_impact
    dt = [(t_sim[j0 + i] - tm) if j0 + i < len(t_sim) else None for i, tm in enumerate(t_meas)]
    pe = (p_sim - p_meas)[1:] if k > 1 else np.zeros(0)
    finite = np.array([d for d in dt if d is not None], dtype=float)
    return {
        "peaks_measured": p_meas.tolist(),
        "peaks_simulated": p_sim.tolist(),
        "peak_error": pe.tolist(),
        "rms_peak_error": float(np.sqrt(np.mean(pe**2))) if pe.size else 0.0,
        "impact_times_measured": t_meas,
        "impact_time_error": dt,
        "rms_impact_time_error": float(np.sqrt(np.mean(finite**2))) if finite.size else None,
        "missing_impacts": int(sum(d is None for d in dt)),
    }
