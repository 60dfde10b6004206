"""``method="auto"`` of the sweeps: the exponential method where it wins, DOP853 elsewhere.

References: the stiffness ratio S = min(2 ms, max_step) · ρ / 3.4 with ρ the spectral
radius of the full-contact state matrix (`multimass.cost`), recomputed here with numpy
from the structure's matrices; the work-precision table of the module docstring
(benchmarks/exponential_rocking.py) places S1 (S ≈ 2) where DOP853 wins and the 20-node
column (S ≈ 88) where the exponential method is 4-20 times faster.
"""

import math

import numpy as np
import pytest

import multimass
from multimass import FreeRelease, G
from multimass.bench.scaling import uniform_column
from multimass.sweeps.method_choice import AUTO, STIFF, choose_method, stiffness, sweep_method
from multimass.sweeps.spectra import pulse_spectrum


def _rho(st) -> float:
    """Largest |λ| of [[0, I], [−M⁻¹K, −M⁻¹C]], by numpy here."""
    n = st.n
    m = np.asarray(st.m, float)
    A = np.block(
        [
            [np.zeros((n, n)), np.eye(n)],
            [-np.asarray(st.K, float).reshape(n, n) / m[:, None],
             -np.asarray(st.C, float).reshape(n, n) / m[:, None]],
        ]
    )  # fmt: skip
    return float(np.abs(np.linalg.eigvals(A)).max())


def test_stiffness_is_the_exponential_step_over_dop853s_stable_step():
    st = multimass.column("S1")
    assert stiffness(st) == pytest.approx(2e-3 * _rho(st) / 3.4, rel=1e-9)
    assert stiffness(st, max_step=1e-3) == pytest.approx(1e-3 * _rho(st) / 3.4, rel=1e-9)
    assert math.isnan(stiffness(multimass.rigid_block("B6M")))


def test_auto_keeps_dop853_on_s1_because_it_is_not_stiff():
    c = choose_method(
        multimass.column("S1"), FreeRelease(0.1), 2.0, "DD2", None, {"backend": "compiled"}
    )
    assert c.method == "DOP853" and c.measured == {}  # decided without a sample run
    assert c.stiffness < STIFF and "not stiff" in c.reason and "S = 1.9" in c.reason


def test_auto_picks_exponential_on_a_20_node_column_faster_and_as_accurate():
    st = uniform_column(20)
    assert stiffness(st) > STIFF
    c = choose_method(st, FreeRelease(0.11), 1.0, "DD2", None, {"backend": "compiled"})
    assert c.method == "exponential", c.reason
    assert "faster" in c.reason and "agrees with DOP853" in c.reason
    exp, dop = c.measured["exponential"], c.measured["DOP853"]
    assert exp["wall_time_s"] < dop["wall_time_s"]
    apart = exp["against_DOP853"]
    assert apart["same_impacts"] and apart["n_impacts"] >= 1
    assert apart["theta"] <= 10 * 1e-8 * apart["theta_max"]  # FLOOR × rtol (default 1e-8)


def test_auto_keeps_dop853_where_the_exponential_run_is_less_accurate(monkeypatch):
    # the same 20-node column, its exponential sample run made to miss its last impact
    import dataclasses

    from multimass.sweeps import method_choice

    real = method_choice.simulate_outcome

    def lossy(*args, **kw):
        r = real(*args, **kw)
        if kw["method"] != "exponential":
            return r
        last = max(i for i, e in enumerate(r.events) if e.kind == "impact")
        return dataclasses.replace(r, events=r.events[:last] + r.events[last + 1 :])

    monkeypatch.setattr(method_choice, "simulate_outcome", lossy)
    options = {"backend": "compiled"}
    c = choose_method(uniform_column(20), FreeRelease(0.11), 1.0, "DD2", None, options)
    assert c.method == "DOP853" and "less accurate" in c.reason
    assert c.measured["exponential"]["against_reference"]["same_impacts"] is False


def test_a_spectrum_with_auto_reports_its_choice():
    sp = pulse_spectrum("S1", "cosine", 15.0, 0.3 * G, t_free=0.5, executor="serial", method="auto")
    assert sp.options["method"] == "DOP853"
    assert sp.options["method_choice"]["method"] == "DOP853"
    assert "not stiff" in sp.summary()["options"]["method_choice"]["reason"]


def test_a_column_sweep_on_the_compiled_path_chooses_by_default():
    s1, block = multimass.column("S1"), multimass.rigid_block("B6M")
    compiled = {"backend": "compiled", "impact": "DD5"}
    assert sweep_method(s1, compiled) == compiled | {"method": AUTO}
    for st, options in [
        (s1, compiled | {"method": "DOP853"}),  # a method asked for stays
        (s1, {"backend": "scipy"}),  # solve_ivp: no exponential method
        (block, {"backend": "compiled"}),  # a rigid block: DOP853
    ]:
        assert sweep_method(st, options) == options


def test_a_stiff_columns_spectrum_takes_the_exponential_method_by_default():
    # the 20-node column (S ≈ 88): its sample run each way decides, as with method="auto"
    sp = pulse_spectrum(
        uniform_column(20), "cosine", 15.0, 0.4 * G, impact="DD2", t_free=0.5, executor="serial"
    )
    assert sp.options["method"] == "exponential", sp.options["method_choice"]["reason"]
    assert "agrees with DOP853" in sp.options["method_choice"]["reason"]
    asked = pulse_spectrum(
        uniform_column(20), "cosine", 15.0, 0.4 * G, impact="DD2", t_free=0.5,
        executor="serial", method="DOP853",
    )  # fmt: skip
    assert asked.options["method"] == "DOP853" and "method_choice" not in asked.options
    assert sp.table.theta_max[0] == pytest.approx(asked.table.theta_max[0], rel=1e-7)


def test_the_sample_runs_show_a_bar_only_if_the_sweep_may(monkeypatch):
    from multimass.sweeps import method_choice

    seen, real = [], method_choice.simulate_outcome

    def recorded(*args, **kw):
        seen.append(kw["progress"])
        return real(*args, **kw)

    monkeypatch.setattr(method_choice, "simulate_outcome", recorded)
    st, run = uniform_column(20), (FreeRelease(0.11), 0.2, "DD2", None, {"backend": "compiled"})
    choose_method(st, *run, progress=False)  # a sweep run with progress=False (--no-progress)
    assert seen and set(seen) == {False}
    seen.clear()
    choose_method(st, *run)  # else: a bar if a sample run is long (simulate's own rule)
    assert seen and set(seen) == {None}
