"""Stage 2's fitted windows (`multimass.identify._calibration_setup`): they stop the
anti-alias filter's reach before the impact that ends their last large half-cycle, so
that no part of that impact's filtered spike is fitted."""

from types import SimpleNamespace

import numpy as np
import pytest

from multimass import FreeRelease
from multimass.identify import synthetic_trace
from multimass.identify._calibration_setup import cases, window_end
from multimass.identify._calibration_stages import REACH
from multimass.identify._restitution_fit import EDGE
from multimass.model.structure import from_specimen


def _half(t_start, t_stop, ends):
    return SimpleNamespace(t_start=t_start, t_stop=t_stop, ends=ends)


def test_stage_two_stops_restitutions_margin_before_an_impact():
    # the margin `restitution` keeps before an impact (`EDGE`, 13 trace samples)
    assert REACH == EDGE == 13


def test_a_window_ending_at_an_impact_stops_reach_samples_before_it():
    assert window_end(_half(0.2, 0.8, "impact"), 200.0, 13) == pytest.approx(0.8 - 13 / 200.0)
    assert window_end(_half(0.2, 0.8, "impact"), 1000.0, 13) == pytest.approx(0.8 - 0.013)
    assert window_end(_half(0.2, 0.8, "impact"), 200.0) == 0.8  # no reach: at the impact


def test_a_window_ending_otherwise_keeps_its_end():
    assert window_end(_half(0.2, 0.8, "full_contact"), 200.0, 13) == 0.8
    assert window_end(_half(0.2, 0.8, "end"), 200.0, 13) == 0.8


def test_a_half_cycle_shorter_than_the_reach_ends_where_it_starts():
    assert window_end(_half(0.75, 0.8, "impact"), 200.0, 13) == 0.75


@pytest.fixture(scope="module")
def case():
    syn = synthetic_trace("S1", FreeRelease(theta0=0.11), "DD2", 2.6, seed=11)
    return cases([syn.trace], from_specimen("S1"), (), None, 0.01)[0]


def test_stage_two_windows_stop_before_the_impact_ending_them(case):
    t = case.t
    assert len(case.large) >= 3 and case.large[-1].ends == "impact"
    for k in (2, len(case.large), len(case.large) + 4):  # also the whole run of them
        c = case.upto(k, REACH)
        last = case.large[min(k, len(case.large)) - 1]
        t1 = last.t_stop - REACH / case.fs
        assert c.window == (case.window[0], pytest.approx(t1))
        assert t[c.idx][-1] <= t1 < t[c.idx.stop]  # every sample up to t1, none after
        assert np.count_nonzero((t > t1) & (t <= last.t_stop)) >= REACH - 1
        # without a reach: up to the impact
        assert case.upto(k).window[1] == last.t_stop
