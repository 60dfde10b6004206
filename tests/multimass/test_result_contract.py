"""Every engine returns a result on one contract (`multimass.result`).

One small case per engine — the solve_ivp path, the compiled path, Newmark through
`simulate`, `simulate_outcome`, `newmark_block` (paper 004), the paper-000 contact
engine's block and oscillator, Moreau–Jean (paper 002) — each a free release from
θ0 = 0.1 rad (0.05 rad for the column) or 2.5 u_cr for the oscillator, and the
same checks: the fields, the status and outcome sets, event kinds, peaks in
radians with the release angle first, the ledger's names, the series, JSON.

Independent references: the release angle is the given θ0; a free rocking
block's first peaks can only decrease (no energy input, restitution ≤ 1); every
θ sample lies within the largest peak (θ_max is a maximum of |θ|).
"""

import json
import math

import numpy as np
import pandas as pd
import pytest

import multimass
from multimass import FreeRelease, SineWave, simulate, simulate_outcome
from multimass.engines import nscd
from multimass.engines.flexible_oscillator import FlexibleOscillator, simulate_oscillator
from multimass.engines.newmark import newmark_block
from multimass.engines.poisson_block import PoissonBlock, simulate_block
from multimass.result import EVENT_KINDS, LEDGER_NAMES, OUTCOMES, STATUSES, Event, Result

TH0 = 0.1  # rad, the release angle of the blocks


def _simulate_scipy():
    return simulate("B6M", FreeRelease(theta0=TH0), "CIM", 3.0), TH0


def _simulate_compiled():
    return simulate("S1", FreeRelease(theta0=0.05), "DD2", 1.0, backend="compiled"), 0.05


def _simulate_newmark():
    return simulate("B6M", FreeRelease(theta0=TH0), "CIM", 3.0, integrator="newmark"), TH0


def _simulate_outcome():
    return simulate_outcome("B6M", FreeRelease(theta0=TH0), "CIM", 3.0), TH0


def _newmark_block():
    st = multimass.from_specimen("B6M")
    return newmark_block(st, lambda t: 0.0, 3.0, restitution=0.9, theta0=TH0), TH0


def _poisson_block():
    return simulate_block(PoissonBlock.from_slenderness(3.0), 0.0, 2.0, phi0=-TH0), TH0


def _oscillator():
    osc = FlexibleOscillator.from_frequency(
        2.0, m=1000.0, m_c=200.0, m_b=300.0, h=2.0, b=0.3, zeta=0.02
    )
    return simulate_oscillator(osc, 0.0, 2.0, u0=2.5 * osc.u_cr), None


def _nscd():
    return nscd.simulate("B6M", theta0=TH0, dt=1e-4, t_end=1.0, progress=False), TH0


ENGINES = {
    "simulate-scipy": _simulate_scipy,
    "simulate-compiled": _simulate_compiled,
    "simulate-newmark": _simulate_newmark,
    "simulate_outcome": _simulate_outcome,
    "newmark_block": _newmark_block,
    "poisson_block": _poisson_block,
    "flexible_oscillator": _oscillator,
    "nscd": _nscd,
}


@pytest.fixture(scope="module", params=list(ENGINES))
def case(request):
    res, theta0 = ENGINES[request.param]()
    return request.param, res, theta0


def test_the_shared_fields(case):
    name, res, _ = case
    assert isinstance(res, Result), name
    assert res.status in STATUSES and res.outcome in OUTCOMES
    assert isinstance(res.message, str) and isinstance(res.warnings, tuple)
    for check in res.checks.values():
        assert set(check) >= {"value", "limit", "passed"}
    assert isinstance(res.engine, str) and res.engine
    assert res.status == "completed", (name, res.message, res.warnings)  # free rocking, at rest


def test_events_are_one_type_with_one_set_of_kinds(case):
    name, res, theta0 = case
    assert res.events, name
    assert all(isinstance(e, Event) for e in res.events)
    assert {e.kind for e in res.events} <= EVENT_KINDS
    times = [e.time for e in res.events]
    assert times == sorted(times)
    if theta0 is not None:
        first = res.events[0]
        assert first.kind == "release" and first.time == 0.0
        assert first.theta == pytest.approx(theta0, abs=1e-12)
        assert res.n_impacts >= 1  # a free release of a slender block rocks through θ = 0


def test_peaks_are_in_radians_with_the_release_angle_first(case):
    name, res, theta0 = case
    peaks = np.asarray(res.peaks)
    assert peaks.size >= 2 and len(res.peak_times) == peaks.size
    assert np.all(peaks >= 0.0) and np.all(peaks < math.pi / 2)
    assert res.theta_max == pytest.approx(peaks.max())
    if theta0 is not None:
        assert peaks[0] == pytest.approx(theta0, rel=1e-9)
        assert res.peak_times[0] == pytest.approx(0.0, abs=1e-9)
        # free rocking with restitution ≤ 1 loses energy at every impact
        assert np.all(np.diff(peaks[:3]) < 0.0), peaks[:3]
    if len(res.theta):
        assert np.max(np.abs(res.theta)) <= res.theta_max * (1 + 1e-6) + 1e-12


def test_series_and_ledger_have_the_shared_names(case):
    name, res, _ = case
    assert isinstance(res.series, pd.DataFrame)
    assert {"t", "theta", "thetadot"} <= set(res.series.columns)
    assert isinstance(res.ledger, pd.DataFrame)
    assert {"t", "energy"} <= set(res.ledger.columns) <= set(LEDGER_NAMES)
    np.testing.assert_array_equal(res.t, res.series["t"].to_numpy())
    np.testing.assert_array_equal(res.theta, res.series["theta"].to_numpy())
    if name != "simulate_outcome":  # the lean result holds no samples
        assert len(res.t) > 10 and np.all(np.diff(res.t) >= 0.0)
        led = res.ledger
        assert np.all(np.isfinite(led["energy"].to_numpy()))
        if "balance_error" in led:
            scale = max(abs(led["energy"].iloc[0]), 1e-300)
            assert np.max(np.abs(led["balance_error"].to_numpy())) / scale < 1e-3


def test_json_holds_radians_and_degrees_beside_them(case):
    name, res, _ = case
    d = json.loads(res.to_json(allow_nan=False))
    assert d["status"] == res.status and d["outcome"] == res.outcome
    assert d["engine"] == res.engine
    assert d["peaks"] == pytest.approx(list(map(float, res.peaks)))
    assert d["peaks_deg"] == pytest.approx([math.degrees(p) for p in res.peaks])
    assert d["theta_max_deg"] == pytest.approx(math.degrees(d["theta_max"]))
    assert not [k for k in d if "deg" in k and not k.endswith("_deg")], name


# --------------------------------------------------------------------- ending at an overturn
def _b6m_sine():
    """B6M under a sine of 3 g tan α at 10 rad/s: it overturns in its first swing (0.35 s)."""
    st = multimass.from_specimen("B6M")
    return st, SineWave(amplitude=3.0 * st.g * math.tan(st.alpha_cg), omega=10.0)


def _overturn_simulate(**kw):
    st, exc = _b6m_sine()
    return simulate(st, exc, "CIM", 2.0, restitution=0.9, **kw), exc


def _overturn_newmark_block():
    st, exc = _b6m_sine()
    return newmark_block(st, exc, 2.0, restitution=0.9), exc


def _overturn_poisson_block():
    block = PoissonBlock.from_slenderness(4.0, width=0.4)
    exc = SineWave(amplitude=1.2 * block.g, omega=2.0 * block.p)
    return simulate_block(block, 0.0, 10.0, ag=exc), exc


OVERTURNING = {
    "simulate-scipy": lambda: _overturn_simulate(),
    "simulate-scipy-events-only": lambda: _overturn_simulate(output_dt=None),
    "simulate-compiled": lambda: _overturn_simulate(backend="compiled"),
    "simulate-newmark": lambda: _overturn_simulate(integrator="newmark"),
    "newmark_block": _overturn_newmark_block,
    "poisson_block": _overturn_poisson_block,
}


@pytest.mark.parametrize("name", list(OVERTURNING))
def test_an_overturned_series_ends_at_the_overturn(name):
    """Every engine that records a series stops it at the overturn event: its last row is
    the overturning instant (|θ| = π/2, the default overturning angle, with the event's
    θ̇), and no row — no frozen state, no ground motion — is made up after it."""
    res, exc = OVERTURNING[name]()
    assert res.status == "overturned", (name, res.message)
    over = res.events[-1]
    assert over.kind == "overturn"
    df = res.series
    assert df["t"].iloc[-1] == pytest.approx(over.time, abs=1e-12), name
    assert abs(df["theta"].iloc[-1]) == pytest.approx(math.pi / 2, abs=1e-9)
    assert df["thetadot"].iloc[-1] == pytest.approx(over.thetadot_minus, rel=1e-9)
    if "ag" in df:  # the ground motion at the overturn, from the excitation itself
        assert df["ag"].iloc[-1] == pytest.approx(exc(over.time), rel=1e-9, abs=1e-12)


def test_a_table_given_as_columns_is_a_dataframe_when_read():
    # a Response may hold its series as columns (name -> array): read, it is the same
    # table pandas builds from them; `with_fields` changes fields without reading it
    from multimass.response import Response
    from multimass.result import with_fields

    cols = {"t": np.array([0.0, 0.5]), "theta": np.array([0.1, -0.05])}
    r = Response("x", "completed", "", cols, [], np.array([0.1]), np.array([0.0]), 1.0, 0.0, 0.0)
    changed = with_fields(r, status="inaccurate", warnings=("w",))
    assert (changed.status, changed.warnings, r.status) == ("inaccurate", ("w",), "completed")
    assert isinstance(changed.series, pd.DataFrame)
    pd.testing.assert_frame_equal(changed.series, pd.DataFrame(cols))
    np.testing.assert_array_equal(r.theta, cols["theta"])
    with pytest.raises(TypeError, match="no field colour"):
        with_fields(r, colour="red")
