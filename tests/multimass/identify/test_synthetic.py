"""Synthetic traces with a known truth (multimass.identify.synthetic).

Each test recovers something the simulator was given: the samples written, the truth
kept apart, the noise, bias and clock offset asked for, the restitution each impact
used, and the ground motion of a table test.
"""

import json
import math

import numpy as np
import pytest

import multimass
from multimass import FreeRelease, G, InputError, SineWave, read_trace
from multimass.identify import read_truth, synthetic_trace, truth_path
from multimass.result import json_ready

THETA0 = 0.11  # rad: S1's free-vibration test (paper 001, Section 4.3, Fig 6)
T_END = 5.0  # s: the bundled synthetic trace lasts 10 s; half keeps these fast


def _s1(impact="DD2", **kw):
    return synthetic_trace("S1", FreeRelease(theta0=THETA0), impact, kw.pop("t_end", T_END), **kw)


@pytest.fixture(scope="module")
def dd2():
    return _s1("DD2", seed=11)


@pytest.fixture(scope="module")
def cim():
    return _s1("CIM", seed=11)


@pytest.fixture(scope="module")
def quiet():
    """The DD2 test of `dd2` (same seed: same draws, same run) without noise or bias."""
    return _s1("DD2", seed=11, noise=0.0, bias=0.0)


# ---------------------------------------------------------------------------- the files
def test_written_trace_reads_back_into_the_same_samples(dd2, tmp_path):
    csv, side = dd2.write(tmp_path / "sub" / "s1_dd2.csv")
    assert side == tmp_path / "sub" / "s1_dd2.truth.json" == truth_path(csv)
    back = read_trace(csv)
    np.testing.assert_array_equal(back.time, dd2.trace.time)
    assert back.names == dd2.trace.names == ("theta", "a_A1", "a_A2", "a_A3", "a_A4")
    for name in back.names:
        np.testing.assert_array_equal(back.channels[name], dd2.trace.channels[name])
    assert back.specimen == "S1" and back.ag is None
    assert dict(back.units) == {"theta": "rad", **{f"a_A{k}": "g" for k in range(1, 5)}}


def test_the_truth_is_beside_the_trace_never_in_it(dd2, tmp_path):
    import hashlib

    csv, side = dd2.write(tmp_path / "s1.csv")
    text = csv.read_text()
    lines = text.splitlines()
    # one comment line, the specimen's name; then the header and numbers only
    assert [line for line in lines if line.startswith("#")] == ["# specimen: S1"]
    assert lines[1] == "t [s],theta [rad],a_A1 [g],a_A2 [g],a_A3 [g],a_A4 [g]"
    assert all(set(line) <= set("0123456789.,-e+") for line in lines[2:])
    truth = read_truth(csv)
    assert truth == read_truth(side)
    assert truth["trace_file"] == "s1.csv"
    assert truth["trace_sha256"] == hashlib.sha256(text.encode()).hexdigest()
    expected = json.loads(json.dumps(json_ready(dd2.truth)))
    assert {k: v for k, v in truth.items() if not k.startswith("trace_")} == expected
    json.dumps(truth, allow_nan=False)  # no NaN anywhere
    assert truth["specimen"] == "S1" and truth["seed"] == 11
    assert truth["impact"]["name"] == "DD2" and truth["impact"]["C_p"] == 1750.0  # Table 2
    assert truth["excitation"] == {
        "kind": "free_release",
        "theta0": THETA0,
        "u0": None,
        "duration": 0.0,
    }


def test_read_truth_refuses_other_files(tmp_path):
    other = tmp_path / "x.truth.json"
    other.write_text('{"format": "something else"}')
    with pytest.raises(InputError, match=r"not a truth file of multimass.identify"):
        read_truth(other)
    with pytest.raises(InputError, match=r"no such file"):
        read_truth(tmp_path / "missing.csv")
    (tmp_path / "bad.truth.json").write_text("{")
    with pytest.raises(InputError, match=r"bad.truth.json: not JSON"):
        read_truth(tmp_path / "bad.truth.json")


# ---------------------------------------------------------------------------- noise, bias, offset
def test_noise_has_the_requested_spread(dd2):
    truth = dd2.truth
    n = dd2.trace.time.size
    for name in dd2.trace.names:
        peak = truth["peak"][name]
        noise = dd2.trace.channels[name] - dd2.clean.channels[name] - truth["bias"]["values"][name]
        sigma = truth["noise"]["std"][name]
        assert sigma == pytest.approx(0.02 * peak, rel=1e-12)
        # the sample standard deviation of n normal values: relative spread 1/sqrt(2n) = 2.2 %
        assert np.std(noise) == pytest.approx(sigma, rel=0.1)
        assert abs(np.mean(noise)) < 4 * sigma / math.sqrt(n)
        lag1 = np.corrcoef(noise[:-1], noise[1:])[0, 1]  # white: no correlation
        assert abs(lag1) < 4 / math.sqrt(n)


def test_bias_is_a_constant_within_the_requested_bound(dd2):
    truth = dd2.truth
    assert truth["bias"]["fraction_of_peak"] == 0.005
    values = truth["bias"]["values"]
    assert len(set(np.sign(list(values.values())))) == 2  # drawn, not one sign for all
    n = dd2.trace.time.size
    for name, b in values.items():
        assert abs(b) <= 0.005 * truth["peak"][name]
        offset = dd2.trace.channels[name] - dd2.clean.channels[name]
        assert np.mean(offset) == pytest.approx(b, abs=4 * truth["noise"]["std"][name] / n**0.5)


def test_bias_given_per_channel(quiet):
    given = {"theta": 1e-3, "a_A4": -0.05}
    syn = _s1("DD2", seed=11, noise=0.0, bias=given)
    assert syn.truth["bias"]["values"] == {
        "theta": 1e-3,
        "a_A1": 0.0,
        "a_A2": 0.0,
        "a_A3": 0.0,
        "a_A4": -0.05,
    }
    assert syn.truth["bias"]["fraction_of_peak"] is None
    for name, b in syn.truth["bias"]["values"].items():
        diff = syn.trace.channels[name] - quiet.clean.channels[name]
        np.testing.assert_allclose(diff, b, atol=1e-9 * quiet.truth["peak"][name])


def test_without_noise_or_bias_the_trace_is_the_clean_record(quiet, dd2):
    for name in quiet.trace.names:
        np.testing.assert_allclose(
            quiet.trace.channels[name], quiet.clean.channels[name], rtol=1e-9, atol=1e-12
        )
        np.testing.assert_array_equal(quiet.clean.channels[name], dd2.clean.channels[name])


def _zero_crossings(t, theta):
    """Times where θ changes sign, by linear interpolation between samples."""
    k = np.flatnonzero(np.sign(theta[:-1]) * np.sign(theta[1:]) < 0)
    return t[k] - theta[k] * (t[k + 1] - t[k]) / (theta[k + 1] - theta[k])


def test_clock_offset(quiet):
    truth, trace = quiet.truth, quiet.trace
    offset = truth["t_offset"]
    assert offset == 0.012 and trace.time[0] == 0.0 and np.all(np.diff(trace.time) > 0)
    # before the release (trace time < offset) the column is held still at θ0 (up to the
    # zero-phase filter's pre-ringing of the release, 5e-5 of θ0)
    held = trace.time < offset - 0.005
    assert held.sum() == 2
    np.testing.assert_allclose(trace.channels["theta"][held], THETA0, rtol=1e-4)
    # impacts: θ crosses zero at the truth's times on the trace's clock (t = t_model + offset)
    large = [i for i in truth["impacts"] if i["theta_before"] > 0.01]
    assert len(large) >= 6
    crossings = _zero_crossings(trace.time, trace.channels["theta"])
    for imp in large:
        assert imp["t"] == pytest.approx(imp["t_model"] + offset, abs=1e-12)
        assert np.min(np.abs(crossings - imp["t"])) < 5e-4  # a tenth of a sample
    # the trace is the simulation, seen on a clock shifted by the offset
    resp = quiet.response
    theta_model = np.interp(trace.time - offset, resp.t, resp.theta)
    after = trace.time > offset + 0.1
    assert np.max(np.abs(trace.channels["theta"][after] - theta_model[after])) < 2e-3 * THETA0


def test_compare_finds_the_run_at_the_true_offset(quiet, tmp_path):
    # the written trace feeds multimass.compare_trace: at the truth's offset the
    # simulation it came from matches its θ to 2e-4 (the filter smooths the impacts)
    csv, _ = quiet.write(tmp_path / "quiet.csv")
    trace = read_trace(csv)
    right = multimass.compare_trace(trace, quiet.response, "S1", t_offset=0.012)["theta"]
    wrong = multimass.compare_trace(trace, quiet.response, "S1", t_offset=0.0)["theta"]
    assert right.nrmse < 2e-4 < 0.02 < wrong.nrmse


def test_negative_offset_starts_recording_after_the_release():
    syn = _s1("CIM", seed=2, noise=0.0, bias=0.0, t_offset=-0.2, t_end=1.0)
    resp = syn.response
    assert syn.trace.time[0] == 0.0 and syn.trace.time[-1] == pytest.approx(0.8, abs=1e-12)
    expected = np.interp(0.2, resp.t, resp.theta)
    assert syn.trace.channels["theta"][0] == pytest.approx(expected, rel=1e-5)


# ---------------------------------------------------------------------------- restitution
def _impact_events(syn):
    lo = syn.truth["t_offset"] * -1.0
    hi = syn.trace.time[-1] - syn.truth["t_offset"]
    return [e for e in syn.response.events if e.kind == "impact" and lo <= e.time <= hi]


@pytest.mark.parametrize("name", ["dd2", "cim"])
def test_truth_r_values_are_the_ones_the_run_used(name, request):
    syn = request.getfixturevalue(name)
    impacts, events = syn.truth["impacts"], _impact_events(syn)
    assert len(impacts) == len(events) >= 10
    tables = syn.response.options["restitution"]  # the DrawnRestitution of the run
    assert tables["kind"] == "DrawnRestitution"
    for imp, e in zip(impacts, events):
        assert imp["t_model"] == e.time
        assert imp["corner"] == ("right" if e.phase_after > 0 else "left")
        assert imp["r"] == e.restitution and imp["r"] in tables[imp["corner"]]
    means = {c: np.mean([i["r"] for i in impacts if i["corner"] == c]) for c in ("right", "left")}
    assert syn.truth["r_mean_right"] == pytest.approx(means["right"], rel=1e-12)
    assert syn.truth["r_mean_left"] == pytest.approx(means["left"], rel=1e-12)


def test_classical_impacts_apply_r_in_draw_order(cim):
    # paper 001, Eq 11: θ̇⁺ = r θ̇⁻; the classical model draws once per impact into a new
    # half-cycle, so impact i takes entry i of its corner's table
    tables = cim.response.options["restitution"]
    for i, (imp, e) in enumerate(zip(cim.truth["impacts"], _impact_events(cim))):
        assert imp["r"] == tables[imp["corner"]][i]
        assert e.thetadot_plus == pytest.approx(imp["r"] * e.thetadot_minus, rel=1e-12)


def test_r_is_drawn_around_the_corner_means(dd2):
    # paper 001, Table 1, S1: r_er = 0.93, r_el = 0.87, σ_r = 0.025
    tables = dd2.response.options["restitution"]
    for corner, mean in (("right", 0.93), ("left", 0.87)):
        drawn = np.array(tables[corner])
        assert drawn.size >= 256 and np.all((drawn > 0) & (drawn <= 1))
        assert np.mean(drawn) == pytest.approx(mean, abs=4 * 0.025 / drawn.size**0.5)
        assert np.std(drawn) == pytest.approx(0.025, rel=0.15)
    law = dd2.truth["restitution"]
    assert law["means"] == {"right": 0.93, "left": 0.87} and law["spread"] == 0.025


def test_no_spread_gives_the_means():
    syn = _s1("CIM", seed=3, restitution_spread=0.0, restitution_means=(0.95, 0.9), t_end=2.0)
    assert {(i["corner"], i["r"]) for i in syn.truth["impacts"]} == {("right", 0.95), ("left", 0.9)}
    assert syn.truth["sigma_r"] == 0.0


# ---------------------------------------------------------------------------- reproducibility
def test_same_seed_same_trace(dd2):
    again = _s1("DD2", seed=11)
    for name in dd2.trace.names:
        np.testing.assert_array_equal(again.trace.channels[name], dd2.trace.channels[name])
    assert json.dumps(json_ready(again.truth)) == json.dumps(json_ready(dd2.truth))
    other = _s1("DD2", seed=12)
    assert not np.array_equal(other.trace.channels["a_A4"], dd2.trace.channels["a_A4"])
    assert [i["r"] for i in other.truth["impacts"]] != [i["r"] for i in dd2.truth["impacts"]]


# ---------------------------------------------------------------------------- channels
def test_table_motion_is_recorded_as_ag():
    # a single sine wave ü_g = A sin(ω t), 0 ≤ t ≤ 2π/ω, slow enough (2.4 Hz) to pass unchanged
    amp, omega = 0.3 * G, 15.0
    syn = synthetic_trace(
        "S1", SineWave(amplitude=amp, omega=omega), "DD2", 2.0, seed=5, noise=0.0, bias=0.0
    )
    assert syn.trace.names[-1] == "ag" and syn.trace.units["ag"] == "g"
    t = syn.trace.time - syn.truth["t_offset"]
    exact = np.where((t >= 0) & (t <= 2 * np.pi / omega), amp * np.sin(omega * t), 0.0)
    away = (np.abs(t) > 0.05) & (np.abs(t - 2 * np.pi / omega) > 0.05)  # from the two kinks
    assert np.max(np.abs(syn.trace.ag - exact)[away]) < 1e-3 * amp
    assert syn.truth["excitation"]["kind"] == "sine_wave"
    assert syn.truth["channels"]["ag"] == "ag"


def test_sensors_by_name_or_node(quiet):
    syn = _s1("DD2", seed=11, noise=0.0, bias=0.0, sensors=["A4", 3])
    assert syn.trace.names == ("theta", "a_A4", "a3")
    np.testing.assert_array_equal(syn.clean.channels["a3"], quiet.clean.channels["a_A2"])  # node 3
    np.testing.assert_array_equal(syn.clean.channels["a_A4"], quiet.clean.channels["a_A4"])


def test_a_rigid_block_records_theta_only():
    block = multimass.rigid_block("B6M")
    syn = synthetic_trace(
        block,
        FreeRelease(theta0=0.5 * block.alpha_cg),
        "CIM",
        1.5,
        seed=1,
        restitution_means=(0.9, 0.88),
        restitution_spread=0.02,
    )
    assert syn.trace.names == ("theta",) and syn.trace.specimen == "B6M"
    assert len(syn.truth["impacts"]) >= 5


# ---------------------------------------------------------------------------- bad input
BAD = [
    (dict(seed=-1), r"`seed` = -1: must be ≥ 0"),
    (dict(seed=1.5), r"`seed` = 1.5: expected a whole number"),
    (dict(noise=-0.1), r"`noise` = -0.1"),
    (dict(noise=True), r"`noise` = True"),
    (dict(bias="x"), r"`bias` = 'x'"),
    (
        dict(bias={"a_A9": 0.1}),
        r"`bias`: unknown channel 'a_A9'; the trace's channels are theta, a_A1",
    ),
    (dict(t_offset=math.nan), r"`t_offset` = nan"),
    (dict(t_offset=-5.0), r"`t_offset` = -5.0"),
    (dict(fs=0), r"`fs` = 0"),
    (
        dict(fs=20.0),
        r"`oversample` = 40: the response is simulated at 800 Hz.*raise oversample to at least 66",
    ),
    (dict(oversample=2), r"`oversample` = 2: must be in 4..1000"),
    (dict(sensors=["A9"]), r"`sensors`: 'S1' has no sensor 'A9' \(its sensors: A1, A2, A3, A4\)"),
    (dict(sensors=[0]), r"`sensors\[...\]` = 0: must be in 1..5"),
    (dict(sensors=["A2", "a2"]), r"`sensors`: 'a2' is given twice"),
    (dict(sensors="A2"), r"`sensors` = 'A2': give a list of sensor names"),
    (dict(restitution_means=(1.2, 0.8)), r"`restitution_means\[0\]` = 1.2"),
    (dict(restitution_means=0.9), r"`restitution_means` = 0.9: give the pair"),
    (dict(restitution_spread=-0.01), r"`restitution_spread` = -0.01"),
    (dict(impact="LCP"), r"`impact` = 'LCP' draws no coefficient of restitution"),
    (dict(impact="CIM", C_p=1000.0), r"`C_p` = 1000.0: applies to the Dirac-delta models"),
    (dict(C_p=-1.0), r"`C_p` = -1.0"),
    (dict(restitution="mean"), r"`restitution` is set by synthetic_trace; give the restitution"),
    (dict(output_dt=0.01), r"`output_dt` is set by synthetic_trace; remove it"),
    (dict(passband=0.6), r"`passband` = 0.6"),
    (dict(damping=0.01), r"`damping` = 0.01: give the pair \(zeta_1, zeta_2\)"),
    (dict(damping=(0.01, -0.02)), r"`damping\[1\]` = -0.02"),
    (dict(damping=(1.0, 0.02)), r"`damping\[0\]` = 1.0"),
    (dict(t_end=0.0), r"`t_end` = 0.0"),
]


def test_a_sampling_rate_whose_output_cannot_be_held_is_refused_before_the_run():
    """fs = 1e7 Hz (× oversample 40: a response of 4e9 rows) ran silent until memory ran
    out; its size is estimated from the arguments (rows × columns × 8 bytes) and refused
    at once, naming fs, its value and the fix. 100 kHz over 1 s (4e6 rows × 54 columns of
    S1 would be 1.6 GiB) is refused too, 2 kHz is accepted."""
    release = FreeRelease(theta0=THETA0)
    with pytest.raises(InputError) as err:
        synthetic_trace("S1", release, "DD2", 10.0, seed=1, fs=1e7)
    msg = str(err.value)
    assert msg.startswith("`fs` = 1e+07: the output would hold 4e+09 rows × 54 columns")
    assert "1.57 TiB" in msg and "lower `fs`" in msg and "oversample (at least 4)" in msg
    with pytest.raises(InputError, match=r"`fs` = 100000: .* 4e\+06 rows"):
        synthetic_trace("S1", release, "DD2", 1.0, seed=1, fs=1e5, t_offset=0.0)
    from multimass.identify._synthetic_setup import settings

    ok = settings(multimass.column("S1"), release, 1.0, 1, 2e3, 0.02, 0.0, 0.0, None, 0.4, 40)
    assert ok.fs_in == 8e4


@pytest.mark.parametrize("kwargs, message", BAD)
def test_bad_arguments_are_named(kwargs, message):
    args = dict(seed=1, t_end=1.0) | kwargs
    impact = args.pop("impact", "DD2")
    with pytest.raises(InputError, match=message):
        synthetic_trace("S1", FreeRelease(theta0=THETA0), impact, args.pop("t_end"), **args)


def test_damping_replaces_the_columns_rayleigh_ratios():
    """The modal damping of the simulated column is the (ζ1, ζ2) given: checked on its
    matrices (mass-normalised modes of (K, M), ζ_k = φ_kᵀ C φ_k / (2 ω_k)), and the
    truth records it."""
    import scipy.linalg as sla

    from multimass.identify._synthetic_setup import with_damping

    st = with_damping(multimass.from_specimen("S1"), (0.012, 0.03))
    w2, phi = sla.eigh(st.K, st.M)
    zeta = [phi[:, k] @ st.C @ phi[:, k] / (2.0 * math.sqrt(w2[k])) for k in (0, 1)]
    np.testing.assert_allclose(zeta, [0.012, 0.03], rtol=1e-9)
    syn = _s1("DD2", seed=2, t_end=1.0, damping=(0.012, 0.03))
    assert syn.truth["damping"] == {"zeta_1": 0.012, "zeta_2": 0.03}
    # the specimen file's ratios (paper 001 Table 1, S1: 0.5 %, 1.5 %) when none is given
    plain = _s1("DD2", seed=2, t_end=1.0)
    assert plain.truth["damping"] == {"zeta_1": 0.005, "zeta_2": 0.015}
    assert syn.trace.specimen == "S1"
    with pytest.raises(InputError, match=r"`damping` = \(0.01, 0.02\): 'B6M' is a rigid block"):
        synthetic_trace("B6M", FreeRelease(theta0=0.05), "CIM", 1.0, seed=1,
                        restitution_means=(0.9, 0.9), restitution_spread=0.0,
                        damping=(0.01, 0.02))  # fmt: skip


def test_a_block_needs_its_restitution_means():
    with pytest.raises(InputError, match=r"'B6M' has no corner means of restitution; give"):
        synthetic_trace("B6M", FreeRelease(theta0=0.05), "CIM", 1.0, seed=1)
    with pytest.raises(InputError, match=r"`sensors` = \[1\]: 'B6M' is a rigid block"):
        synthetic_trace("B6M", FreeRelease(theta0=0.05), "CIM", 1.0, seed=1, sensors=[1])


def test_a_test_that_overturns_is_refused():
    block = multimass.rigid_block("B6M")
    with pytest.raises(InputError, match=r"B6M overturned at t = .*lower the excitation"):
        synthetic_trace(
            block,
            SineWave(amplitude=0.5 * G, omega=1.5 * block.p),  # paper 004's kind of pulse
            "CIM",
            3.0,
            seed=1,
            restitution_means=(0.95, 0.95),
            restitution_spread=0.0,
        )


def test_write_needs_a_csv_name(dd2, tmp_path):
    with pytest.raises(InputError, match=r"give a file name ending in .csv"):
        dd2.write(tmp_path / "trace.txt")
