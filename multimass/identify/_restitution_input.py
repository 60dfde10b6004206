"""Does the table motion's noise decide `multimass.identify.restitution`'s fit?

DOCSTRING TO BE WRITTEN FROM THE MEASUREMENTS.
"""

from __future__ import annotations

import time
from dataclasses import replace

from ._calibration_input import DRAWS, decides, noise_reason, renoised_runs
from ._restitution_fit import Track, reproduces

__all__ = ["input_check", "impact_reasons", "span_reason", "DRAWS"]


def input_check(track: Track, fitted: dict, progress=None) -> dict | None:
    """The fitted model run with the trace's ``ag`` re-noised (`renoised_runs`: `DRAWS`
    draws of the noise `_calibration_input.input_noise` reads from it) through the
    fit's own tests (`_restitution_fit.reproduces`); None for a free-vibration trace.

    Parameters
    ----------
    track : Track
        After `_restitution_fit.fit_impacts`.
    fitted : dict
        Its answer: trace impact index → `ImpactFit`.
    progress : callable, optional
        Called with the number of draws done.

    Returns
    -------
    dict or None
        ``noise`` (label → the ``ag`` noise's std, m/s²); ``impacts`` (trace impact index
        → per draw (channel, ratio) of the test over the two half-cycles that set its r,
        None where the run failed); ``span`` (per draw, the same over the whole span
        fitted); ``decided`` (trace impact index → bool: most draws fail its test);
        ``span_decided`` (bool); ``seconds``; ``simulations``.
    """
    if track.case.free or not fitted:
        return None
    wall, runs = time.perf_counter(), track.sim.n_runs

    def one(_k: int, cases: list):
        per, whole, _ = reproduces(replace(track, case=cases[0]), fitted)
        return per, whole

    noise, answers = renoised_runs([track.case], one, progress)
    impacts = {
        i: [None if a is None else (a[0][i][1], float(a[0][i][0])) for a in answers]
        for i in fitted
    }  # fmt: skip
    span = [None if a is None else (a[1][1], float(a[1][0])) for a in answers]
    return {
        "noise": noise,
        "impacts": impacts,
        "span": span,
        "decided": {i: decides(d) for i, d in impacts.items()},
        "span_decided": decides(span),
        "seconds": time.perf_counter() - wall,
        "simulations": track.sim.n_runs - runs,
    }


def impact_reasons(checked) -> dict:
    """Trace impact index → why its r is not estimated, for each impact whose test most
    re-noised draws fail; {} where none does (or `checked` is None)."""
    if not checked:
        return {}
    return {
        i: noise_reason(checked["noise"], checked["impacts"][i])
        for i, bad in checked["decided"].items()
        if bad
    }


def span_reason(checked) -> str:
    """Why every parameter estimated over the whole span is ill-posed, where most draws
    fail the test over it; "" where they do not (or `checked` is None)."""
    if not checked or not checked["span_decided"]:
        return ""
    return noise_reason(checked["noise"], checked["span"])
