"""`NSCDResult` on the toolkit's one result contract (`multimass.result`):
status and outcome sets, event kinds, peaks in radians with the release angle first, the
series and ledger names, JSON with degrees only beside radians.

Independent references: the release angle is the given θ0; the first peak after the
impact is paper 002's 7.76° for B6M from 11.268° (Section 6.2); a θ-method with θ < 1/2
diverges on the stiff rigid base (the failed run of `test_simulate`)."""

import json
import math

import numpy as np
import pandas as pd
import pytest

from multimass.engines import nscd
from multimass.result import EVENT_KINDS, LEDGER_NAMES, OUTCOMES, STATUSES, Event, Result

TH0 = math.radians(11.268)  # paper 002, Section 6.2: B6M's release angle


@pytest.fixture(scope="module")
def res():
    return nscd.simulate("B6M", theta0=TH0, dt=1e-4, t_end=1.0, progress=False)


def test_status_outcome_and_engine(res):
    assert isinstance(res, Result) and res.engine == "nscd"
    assert res.status in STATUSES and res.outcome in OUTCOMES
    assert res.status == res.outcome == "completed" and res.warnings == ()
    assert all(set(c) >= {"value", "limit", "passed"} for c in res.checks.values())


def test_events_start_with_the_release_and_list_the_impacts(res):
    assert all(isinstance(e, Event) for e in res.events)
    assert {e.kind for e in res.events} <= EVENT_KINDS
    first = res.events[0]
    assert (first.kind, first.time, first.theta) == ("release", 0.0, TH0)
    assert first.phase_before == first.phase_after == 1  # θ0 > 0: on the right corner
    times = [e.time for e in res.events]
    assert times == sorted(times)
    assert res.n_impacts == len(res.impact_times) >= 2
    # the first impact rocks the block from its right corner onto its left one
    imp = next(e for e in res.events if e.kind == "impact")
    assert (imp.phase_before, imp.phase_after) == (1, -1)
    assert imp.thetadot_minus < imp.thetadot_plus < 0.0 and imp.energy_change < 0.0
    assert res.events_frame().shape[0] == len(res.events)


def test_peaks_in_radians_with_the_release_angle_first(res):
    assert isinstance(res.peaks, np.ndarray) and len(res.peak_times) == len(res.peaks) >= 3
    assert res.peaks[0] == abs(TH0) and res.peak_times[0] == 0.0
    assert res.first_peak == res.peaks[1]
    assert math.degrees(res.first_peak) == pytest.approx(7.76, abs=0.03)  # paper 002, 6.2
    assert np.all(np.diff(res.peaks) < 0.0)  # free rocking loses energy at every impact
    assert res.theta_max == res.peaks[0]
    assert np.max(np.abs(res.theta)) <= res.theta_max


def test_series_and_ledger(res):
    assert isinstance(res.series, pd.DataFrame)
    assert list(res.series.columns) == [
        "t",
        "theta",
        "thetadot",
        "X",
        "Y",
        "v_mid",
        "energy",
        "n_contacts",
    ]
    np.testing.assert_array_equal(res.series["theta"].to_numpy(), res.theta)
    np.testing.assert_array_equal(res.series["thetadot"].to_numpy(), res.thetadot)
    assert list(res.ledger.columns) == ["t", "energy"]
    assert set(res.ledger.columns) <= set(LEDGER_NAMES)
    np.testing.assert_array_equal(res.ledger["energy"].to_numpy(), res.energy)


def test_json_radians_with_degrees_beside(res):
    d = json.loads(res.to_json(allow_nan=False))
    assert d["engine"] == "nscd" and d["status"] == res.status
    assert d["peaks"] == pytest.approx(res.peaks.tolist())
    assert d["peaks_deg"] == pytest.approx(np.degrees(res.peaks).tolist())
    assert d["peak_times"] == pytest.approx(res.peak_times.tolist())
    assert d["first_peak"] == res.first_peak
    assert d["first_peak_deg"] == pytest.approx(math.degrees(res.first_peak))
    assert d["theta0"] == TH0 and d["theta0_deg"] == pytest.approx(11.268, abs=1e-12)
    assert d["n_impacts"] == res.n_impacts and d["rest_time"] is None
    # degrees only in keys ending _deg, each beside its radians
    for k in (k for k in d if "deg" in k):
        assert k.endswith("_deg") and k[: -len("_deg")] in d


def test_a_failed_run_ends_with_a_failed_event():
    res = nscd.simulate("B6M", theta0=0.1, dt=1e-4, t_end=0.05, theta_method=0.0)
    assert res.status == res.outcome == "failed" and res.status in STATUSES
    last = res.events[-1]
    assert last.kind == "failed" and last.time == pytest.approx(res.n_steps * 1e-4)
    assert "diverged" in last.detail
    json.loads(res.to_json(allow_nan=False))


def test_a_block_released_upright_stays_at_rest():
    res = nscd.simulate("B6M", theta0=0.0, dt=1e-4, t_end=0.05, progress=False)
    assert res.peaks.tolist() == [0.0] and res.peak_times.tolist() == [0.0]
    assert res.first_peak is None and res.n_impacts == 0
    assert [e.kind for e in res.events] == ["release"] and res.events[0].phase_after == 0
