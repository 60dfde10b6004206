"""Error measures and failure detection of the benchmarks (benchmarks/work_precision.py,
benchmarks/failures.py, benchmarks/results.py) on hand-made runs."""

import math

import numpy as np
import pytest

from multimass.bench.failures import detect
from multimass.bench.results import RunResult, _crossings, sampled_peaks
from multimass.bench.work_precision import compare, window_end

KINDS = ("uplift", "impact", "full_contact", "overturn")


def _run(events, peaks, peak_times, status="completed", energy=1.0, chatter=0):
    return RunResult(
        status,
        "",
        tuple(events),
        tuple(peaks),
        tuple(peak_times),
        energy,
        10.0,
        1e-9,
        chatter,
        100,
        0.1,
    )


REF = _run(
    [("uplift", 0.1), ("impact", 0.5), ("impact", 0.9), ("impact", 1.2)],
    [0.2, 0.1, 0.05, 0.02],
    [0.3, 0.7, 1.05, 1.4],
    energy=2.0,
)


def test_window_moves_to_the_middle_of_the_gap():
    # reference transitions at 0.5 and 0.9: a nominal 0.6 moves to their midpoint 0.7
    assert window_end(REF, KINDS, 0.6, 2.0) == pytest.approx(0.7)
    # after the last transition (1.2) the window ends midway to t_end (2.0)
    assert window_end(REF, KINDS, 1.5, 2.0) == pytest.approx(1.6)


def test_matched_events_give_the_largest_differences():
    run = _run(
        [("uplift", 0.1), ("impact", 0.5003), ("impact", 0.8999), ("impact", 1.3)],
        [0.2, 0.1001, 0.0498, 0.5],
        [0.3, 0.7, 1.05, 1.4],
        energy=2.5,
    )
    e = compare(run, REF, KINDS, 1.0)  # up to t = 1.0: 3 events, the 2 peaks at 0.3 and 0.7 s
    assert e["events_match"] and e["n_events"] == e["n_events_ref"] == 3
    assert e["event_time_error_s"] == pytest.approx(3e-4)  # |0.5003 − 0.5|
    assert e["peak_error_rad"] == pytest.approx(1e-4)  # |0.1001 − 0.1|
    assert e["energy_error"] == pytest.approx(0.5 / 10.0)  # |2.5 − 2.0| / scale 10


def test_a_missed_impact_makes_the_errors_infinite_and_is_detected():
    run = _run([("uplift", 0.1), ("impact", 0.5)], [0.2, 0.1, 0.05], [0.3, 0.7, 1.05])
    e = compare(run, REF, KINDS, 1.0)
    assert e["events_match"] is False and e["n_events"] == 2 and e["n_events_ref"] == 3
    assert math.isinf(e["event_time_error_s"]) and math.isinf(e["peak_error_rad"])
    row = dict(e, status="completed", chatter=0, chatter_ref=0, balance_error=1e-9, t_compare=1.0)
    assert [k for k, _ in detect(row)] == ["missed_impacts"]


def test_detectors():
    base = dict(
        status="completed",
        events_match=True,
        chatter=0,
        chatter_ref=0,
        balance_error=1e-9,
        t_compare=1.0,
        n_events=3,
        n_events_ref=3,
    )
    assert detect(base) == []
    assert [k for k, _ in detect(base | {"chatter": 3, "chatter_ref": 1})] == ["chattering"]
    assert [k for k, _ in detect(base | {"balance_error": 2e-3})] == ["energy_drift"]
    failed = detect(base | {"status": "failed", "message": "boom"})
    assert failed == [("solver_failed", "boom")]


def test_a_failed_run_has_no_errors():
    e = compare(_run([], [], [], status="failed"), REF, KINDS, 1.0)
    assert e["events_match"] is None and math.isnan(e["peak_error_rad"])


def test_sampled_peaks_of_a_sine():
    # closed form: θ = 0.1 sin(2π t) has |θ| peaks 0.1 at t = 0.25 + k/2
    t = np.arange(0.0, 2.0 + 1e-12, 1e-3)
    peaks, times = sampled_peaks(t, 0.1 * np.sin(2 * np.pi * t))
    assert len(peaks) == 4
    np.testing.assert_allclose(peaks, 0.1, rtol=1e-9)
    np.testing.assert_allclose(times, [0.25, 0.75, 1.25, 1.75], atol=1e-6)


def test_crossings_of_a_sine():
    # closed form: sin(2π t) changes sign at t = k/2
    t = np.linspace(0.0, 1.7, 1701)
    np.testing.assert_allclose(_crossings(t, np.sin(2 * np.pi * t)), [0.5, 1.0, 1.5], atol=1e-6)
