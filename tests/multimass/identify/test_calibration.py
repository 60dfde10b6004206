"""`multimass.identify.calibrate`: calibration of a column model against test traces,
on synthetic S1 traces whose truth is known (`synthetic_trace`).

Kept short: 2.6 s of a 0.11 rad free release of S1 (paper 001 Section 4.3, Fig 6), DD2
(Table 2), 200 Hz, 2 % noise — five large half-cycles. The full 10 s measurements on
S1–S3 are in benchmarks/calibration.py.
"""

import json
import math
import re
from types import SimpleNamespace

import numpy as np
import pytest
from scipy import stats

import multimass
from multimass import FreeRelease
from multimass.errors import InputError
from multimass.identify import synthetic_trace
from multimass.identify._calibration_model import Simulator
from multimass.identify._calibration_params import parameter_set
from multimass.identify._calibration_result import _not_reproduced, _parameters, misfit
from multimass.identify._calibration_setup import cases
from multimass.identify._calibration_stages import align_releases
from multimass.identify._misfit import MISFIT_P, NOISE_TOL, theta_misfit
from multimass.identify.calibration import FITTABLE, STATUSES, Calibration, calibrate
from multimass.identify.calibration_report import markdown, write_report
from multimass.inputs.traces import Trace, parse_trace
from multimass.model.structure import from_specimen

THETA0 = 0.11  # rad: paper 001 Section 4.3's large free-vibration test of S1
T_END = 2.6  # s: five impacts of S1 released from 0.11 rad
CP = 1750.0  # kg m/rad/s: paper 001 Table 2, DD2


def window_means(cal, truth, label):
    """The drawn restitution of the impacts in the fitted window, averaged per corner."""
    drawn = [i["r"] for i in truth["impacts"]]
    out = {}
    for corner in ("right", "left"):
        rs = [drawn[i["index"]] for i in cal.nuisance[label]["impacts"] if i["corner"] == corner]
        out[corner] = float(np.mean(rs))
    return out


@pytest.fixture(scope="module")
def syn():
    return synthetic_trace("S1", FreeRelease(theta0=THETA0), "DD2", T_END, seed=11)


@pytest.fixture(scope="module")
def dd2(syn):
    # start 20 % off: the means 20 % low, C_p 20 % high
    start = {"r_er": 0.8 * 0.93, "r_el": 0.8 * 0.87, "cp": 1.2 * CP}
    return calibrate(syn.trace, impact="DD2", fit="r_er,r_el,cp", start=start, progress=False)


@pytest.fixture(scope="module")
def cim(syn):
    return calibrate(syn.trace, "S1", "CIM", fit=("r_er", "r_el"), progress=False)


def test_recovers_the_truth_of_a_dd2_trace(dd2, syn):
    truth = syn.truth
    assert isinstance(dd2, Calibration) and dd2.status == "converged", dd2.message
    label = next(iter(dd2.nuisance))
    drawn = window_means(dd2, truth, label)
    for name, corner in (("r_er", "right"), ("r_el", "left")):
        p = dd2.parameters[name]
        # the mean of the impacts the trace shows, to 0.005
        assert abs(p["value"] - drawn[corner]) < 0.005
        # the corner mean itself, within the std a corner mean of n impacts has
        assert abs(p["value"] - truth["restitution"]["means"][corner]) < 3.0 * p["std"]
        assert p["constrained"] and p["bound_hit"] is None and p["start"] < 0.8
    cp = dd2.parameters["cp"]
    assert abs(cp["value"] - CP) < 0.1 * CP
    assert abs(cp["value"] - CP) < 3.0 * cp["std"] + 1.0
    nu = dd2.nuisance[label]
    assert nu["kind"] == "free"
    assert abs(nu["t_offset"] - truth["t_offset"]) < 2e-3
    assert abs(nu["theta0"] - THETA0) < 1e-3
    # every impact of the window: its fitted r is the drawn one
    fitted = [i["r"] for i in nu["impacts"]]
    assert (
        np.max(
            np.abs(np.subtract(fitted, [truth["impacts"][i["index"]]["r"] for i in nu["impacts"]]))
        )
        < 0.01
    )
    # residuals at the noise: whitened scales near the noise level (2 % of each peak)
    for key, r in dd2.residuals.items():
        ch = key.split(":")[1]
        assert 0.8 < r["scale"] / truth["noise"]["std"][ch] < 1.3
        assert abs(r["rho1"]) < 0.2


def test_metrics_before_and_after(dd2):
    label = next(iter(dd2.nuisance))
    before = dd2.metrics["before"][label]["trace"]
    after = dd2.metrics["after"][label]["trace"]
    fit = dd2.metrics["fit"][label]["window"]
    assert set(before) == set(after) == set(fit) == {"theta", "a_A1", "a_A2", "a_A3", "a_A4"}
    assert after["theta"].rms_error < 0.5 * before["theta"].rms_error
    for m in fit.values():  # with each impact's restitution: the noise, 2 % of the peak
        assert m.nrmse < 0.2
    fb, fa = dd2.features["before"][label], dd2.features["after"][label]
    assert fa["rms_peak_error"] < 0.5 * fb["rms_peak_error"]
    assert fa["rms_impact_time_error"] < fb["rms_impact_time_error"]
    assert dd2.features["fit"][label]["missing_impacts"] == 0
    assert dd2.features["fit"][label]["rms_impact_time_error"] < 0.01


def test_a_free_release_runs_no_check_of_a_table_motion(dd2):
    assert set(dd2.stages) == {"1", "2"}


def test_cim_on_a_dd2_trace_reports_its_misfit(cim, dd2, tmp_path):
    # paper 001 Section 4.3: the classical impact over-predicts the vibration at impact
    assert cim.status in ("misfit", "ill-posed")
    label = next(iter(cim.nuisance))
    worst = max(r["rho1"] for r in cim.residuals.values())
    assert worst > 0.5
    for ch in ("a_A2", "a_A4"):
        assert (
            cim.metrics["fit"][label]["window"][ch].rms_error
            > 1.5 * dd2.metrics["fit"][label]["window"][ch].rms_error
        )
    files = write_report(cim, tmp_path)
    assert (tmp_path / f"{label}_residuals.png").is_file()
    assert cim.status in (tmp_path / "calibration.md").read_text()
    assert {p.suffix for p in files} == {".png", ".md", ".json", ".toml"}


def test_a_fit_that_does_not_reproduce_the_trace_estimates_nothing(cim):
    # CIM cannot follow a DD2 trace (paper 001 Section 4.3): the fit fails restitution's
    # test (θ against the trace's noise, χ²; each accelerometer against its residuals
    # before the first impact, F), and no parameter is reported as estimated
    assert max(r["misfit"] or 0.0 for r in cim.residuals.values()) > 1.0
    assert cim.status == "ill-posed" and "does not reproduce the trace" in cim.message
    for name in ("r_er", "r_el"):
        p = cim.provenance[name]
        assert p["status"] == "ill-posed" and "does not reproduce the trace" in p["reason"]
        assert p["interval_kind"] == "explored range" and p["std"] is None
        assert not cim.parameters[name]["constrained"]
    data = json.loads(cim.to_json())
    assert data["provenance"]["r_er"]["status"] == "ill-posed"
    assert any("does not reproduce the trace" in w for w in data["warnings"])
    text = cim.specimen_text()
    mean_right = next(line for line in text.splitlines() if line.startswith("mean_right"))
    assert "ILL-POSED" in mean_right and "best fit, not an estimate" in mean_right
    assert "does not reproduce the trace" in "\n".join(markdown(cim).splitlines())


def test_a_fit_that_reproduces_the_trace_is_estimated(dd2):
    tested = [r["misfit"] for r in dd2.residuals.values()]
    assert len(tested) == 5 and all(r is not None and r <= 1.0 for r in tested), tested
    for name in ("r_er", "r_el", "cp"):
        assert dd2.provenance[name]["status"] == "estimated"
    assert not any("does not reproduce" in w for w in dd2.warnings)


def _fake_problem(theta, accel, noise, fs=200.0, t_impact=0.5):
    """A stage-2 problem's stand-in for `misfit`: one trace, residuals given."""
    t = np.arange(theta.size) / fs
    case = SimpleNamespace(
        label="a", t=t, idx=slice(0, t.size),
        segments=SimpleNamespace(noise=noise, fs=fs, impacts=[SimpleNamespace(t=t_impact)]),
    )  # fmt: skip
    raw = {("a", "theta"): (theta, 0.0), ("a", "a_A1"): (accel, 0.0)}
    return SimpleNamespace(cases=[case], raw=lambda x: raw)


def test_the_misfit_test_of_calibrate_is_restitutions():
    rng = np.random.default_rng(5)
    sigma, n = 1e-3, 600  # 200 Hz: the first impact at 0.5 s, 87 samples before its reach

    def tested(theta, accel):
        return misfit(_fake_problem(theta, accel, sigma), None)

    white = tested(rng.normal(0, sigma, n), rng.normal(0, 0.3, n))
    assert set(white) == {("a", "theta"), ("a", "a_A1")}
    assert max(white.values()) <= 1.0  # white noise at the trace's level passes
    # θ against the trace's noise: the χ² limit of its count (closed form, `theta_misfit`)
    theta = rng.normal(0, sigma, n)
    theta[100:] += 2 * sigma
    ratio, limit = theta_misfit(theta, sigma)
    assert limit == pytest.approx(stats.chi2.ppf(1 - MISFIT_P, n) / n * (1 + NOISE_TOL))
    assert tested(theta, rng.normal(0, 0.3, n))[("a", "theta")] == pytest.approx(ratio / limit)
    assert ratio / limit > 1.0
    # noise 25 % above the trace's estimate, the same before and after the first impact:
    # its residuals before it are the reference (F), and the fit passes
    assert tested(rng.normal(0, 1.25 * sigma, n), rng.normal(0, 0.3, n))[("a", "theta")] <= 1.0
    # a release the fit does not reproduce fails, whatever follows
    theta = rng.normal(0, sigma, n)
    theta[:50] += 5 * sigma
    assert tested(theta, rng.normal(0, 0.3, n))[("a", "theta")] > 1.0
    # an accelerometer whose residuals grow after the first impact (less the filter's
    # reach) fails against its own residuals before it
    accel = rng.normal(0, 0.3, n)
    accel[100:] *= 3.0
    loud = tested(rng.normal(0, sigma, n), accel)
    assert loud[("a", "theta")] <= 1.0 and loud[("a", "a_A1")] > 1.0


def test_the_model_floor_is_added_to_cp_and_to_the_damping_ratios():
    # 1.5 % (`MODEL_REL_FLOOR`: measured with restitution for C_p and ζ, checked with
    # calibrate for ζ on the coverage draws of seeds 1 and 2), added in quadrature to
    # the covariance's relative std of each log-fitted parameter; restitution means keep
    # the covariance's std (not log-fitted)
    values = {"r_er": 0.9, "cp": 1500.0, "zeta1": 0.004, "zeta2": 0.015}
    rel = {"r_er": 0.003, "cp": 0.004, "zeta1": 0.01, "zeta2": 0.03}  # the covariance's
    floors = {"r_er": 0.0, "cp": 0.015, "zeta1": 0.015, "zeta2": 0.015}
    pset = SimpleNamespace(
        fit=list(values), start=dict(values),
        bounds={"r_er": (0.5, 1.0), "cp": (100.0, 1e5), "zeta1": (1e-4, 0.2), "zeta2": (1e-4, 0.2)},
    )  # fmt: skip
    x = np.array([0.9, *np.log([1500.0, 0.004, 0.015])])
    cov = np.diag([rel["r_er"] ** 2, *(rel[n] ** 2 for n in ("cp", "zeta1", "zeta2"))])
    out, _ = _parameters(pset, None, x, cov, {})
    assert out["r_er"]["std"] == pytest.approx(0.003)
    for name in ("cp", "zeta1", "zeta2"):
        v = values[name]
        assert out[name]["std"] == pytest.approx(v * math.hypot(rel[name], floors[name]))


def test_a_damping_ratio_whose_mode_the_traces_do_not_show_is_not_constrained():
    # `unseen_damping`'s reasons (the rule restitution uses too): ζ2 not constrained, its
    # value and std kept; ζ1 and C_p, well fixed by the covariance, untouched
    values = {"cp": 1500.0, "zeta1": 0.004, "zeta2": 0.015}
    bounds = {"cp": (100.0, 1e5), "zeta1": (1e-4, 0.2), "zeta2": (1e-4, 0.2)}
    pset = SimpleNamespace(fit=list(values), start=dict(values), bounds=bounds)
    x, cov = np.log(list(values.values())), np.diag([0.004, 0.01, 0.03]) ** 2
    why = {"zeta2": "ζ2 is the damping of mode 2, which the traces do not show"}
    out, flagged = _parameters(pset, None, x, cov, {}, None, why)
    assert not flagged["zeta2"]["constrained"] and why["zeta2"] in flagged["zeta2"]["reason"]
    assert flagged["zeta1"]["constrained"] and flagged["cp"]["constrained"]
    assert out["zeta2"]["value"] == pytest.approx(0.015)
    same, _ = _parameters(pset, None, x, cov, {})  # without it: constrained
    assert same["zeta2"]["constrained"] and same["zeta2"]["std"] == out["zeta2"]["std"]


def test_the_misfit_test_makes_every_fitted_parameter_not_constrained():
    flagged = {
        "r_er": {"bound_hit": None, "constrained": True, "reason": ""},
        "cp": {"bound_hit": "lower", "constrained": False, "reason": "on its lower bound"},
    }
    _not_reproduced(flagged, {("a", "theta"): 0.9})  # passes: nothing changes
    assert flagged["r_er"]["constrained"] and flagged["r_er"]["reason"] == ""
    _not_reproduced(flagged, {("a", "theta"): 0.9, ("a", "a_A1"): 3.0})
    assert not flagged["r_er"]["constrained"] and not flagged["cp"]["constrained"]
    assert "a:a_A1's residual mean square 3 ×" in flagged["r_er"]["reason"]
    assert flagged["cp"]["reason"].startswith("on its lower bound; the fit does not")


def test_the_release_is_aligned_before_the_first_stage():
    # released 0.21 s into a trace whose hold is noisy: the first guess of the clock is
    # the trace's first sample (seed 2), stage 1's bounds ±0.2 s about it; restitution's
    # alignment finds the synthetic truth
    syn = synthetic_trace("S1", FreeRelease(theta0=0.07), "DD2", 2.6, seed=2, t_offset=0.21,
                          noise=0.015)  # fmt: skip
    st = from_specimen("S1")
    cs = cases([syn.trace], st, (), None, 0.01)
    assert abs(cs[0].tau - 0.21) > 0.2  # the guess alone is out of reach
    aligned = align_releases(
        Simulator(st, "DD2", 10, {}), parameter_set(None, "DD2", st.specimen), cs
    )
    assert aligned[0].tau == pytest.approx(syn.truth["t_offset"], abs=1e-3)
    assert aligned[0].theta0 == pytest.approx(0.07, abs=1e-3)


def test_json_table_and_specimen_round_trip(dd2, tmp_path):
    data = json.loads(dd2.to_json())
    assert data["status"] == "converged" and data["impact"] == "DD2"
    assert set(data["parameters"]) == {"r_er", "r_el", "cp"}
    for p in data["parameters"].values():
        assert {"value", "std", "start", "bound_hit", "constrained"} <= set(p)
    table = dd2.to_pandas()
    assert list(table.index) == ["r_er", "r_el", "cp"] and "std" in table
    path = dd2.write_specimen(tmp_path / "S1_fit.toml", name="S1-fit")
    spec = multimass.specimens.load(path)
    assert spec.name == "S1-fit"
    assert spec.r_right == pytest.approx(dd2.values["r_er"], abs=1e-6)
    assert spec.r_left == pytest.approx(dd2.values["r_el"], abs=1e-6)
    assert (spec.zeta_1, spec.zeta_2) == (0.005, 0.015)  # not fitted: kept
    assert "C_p = " in path.read_text()
    assert "Status: converged" in markdown(dd2)


def test_two_traces_fitted_jointly():
    a = synthetic_trace("S1", FreeRelease(theta0=0.11), "DD2", 1.8, seed=21)
    b = synthetic_trace("S1", FreeRelease(theta0=-0.09), "DD2", 1.8, seed=22)
    cal = calibrate([a.trace, b.trace], fit=("r_er", "r_el"), progress=False)
    assert cal.status == "converged", cal.message
    assert len(cal.nuisance) == 2
    (la, na), (lb, nb) = cal.nuisance.items()
    assert la != lb
    assert na["theta0"] == pytest.approx(0.11, abs=1e-3)
    assert nb["theta0"] == pytest.approx(-0.09, abs=1e-3)
    drawn = {"right": [], "left": []}
    for syn, label in ((a, la), (b, lb)):
        for i in cal.nuisance[label]["impacts"]:
            drawn[i["corner"]].append(syn.truth["impacts"][i["index"]]["r"])
    assert abs(cal.values["r_er"] - np.mean(drawn["right"])) < 0.005
    assert abs(cal.values["r_el"] - np.mean(drawn["left"])) < 0.005


def test_unconstrained_parameter_is_flagged(syn):
    # ζ2 from θ alone: mode 2 barely moves the base rotation
    cal = calibrate(syn.trace, "S1", "DD2", fit=("r_er", "r_el", "zeta2"), channels=(),
                    progress=False)  # fmt: skip
    z = cal.parameters["zeta2"]
    assert cal.status == "ill-posed" and not z["constrained"] and z["reason"]
    assert "zeta2" in cal.message
    assert not math.isfinite(z["std"]) or z["std"] > 0.25 * z["value"]
    # what it reports is the range the fit explored (the fit's bounds), not a 95 % interval
    p = cal.provenance["zeta2"]
    assert p["status"] == "ill-posed" and p["interval_kind"] == "explored range"
    assert p["std"] is None and p["value_kind"] == "best fit, not an estimate"
    lo, hi = p["interval"]
    assert lo <= p["value"] <= hi and hi / lo > 2.0
    text = cal.specimen_text()
    zeta_2 = next(line for line in text.splitlines() if line.startswith("zeta_2"))
    assert "ILL-POSED" in zeta_2 and "best fit, not an estimate" in zeta_2
    assert re.search(r"ill-posed \(best fits, not estimates\): [^;]*zeta2", text)


# ---------------------------------------------------------------------------- bad input
def _trace_text(syn, columns=None, ag=None):
    tr = syn.trace
    names = columns or tr.names
    head = "# specimen: S1\nt [s]," + ",".join(f"{n} [{tr.units[n]}]" for n in names)
    cols = [tr.time] + [tr.to_written_units(n, tr.channels[n]) for n in names]
    if ag is not None:
        head += f",ag [{ag[0]}]"
        cols.append(ag[1])
    rows = "\n".join(",".join(f"{x:.9g}" for x in row) for row in np.column_stack(cols))
    return head + "\n" + rows + "\n"


def test_unknown_fit_name(syn):
    with pytest.raises(InputError, match="'r_right'.*r_er, r_el, cp, zeta1, zeta2"):
        calibrate(syn.trace, fit=("r_right",))
    assert set(FITTABLE) == {"r_er", "r_el", "cp", "zeta1", "zeta2"}
    assert {"converged", "misfit", "ill-posed", "failed"} == set(STATUSES)


def test_cp_with_cim(syn):
    with pytest.raises(InputError, match="'cp'.*CIM"):
        calibrate(syn.trace, impact="CIM", fit="r_er,cp")


def test_missing_sensors(syn):
    trace = parse_trace(_trace_text(syn, ["theta", "a_A2"]), source="two_channels.csv")
    with pytest.raises(InputError, match=r"two_channels.csv.*A1, A3, A4.*\[sensors\]"):
        calibrate(trace, fit="r_er")


def test_nan_samples(syn, tmp_path):
    text = _trace_text(syn).splitlines()
    cells = text[40].split(",")
    cells[1] = "nan"  # θ
    text[40] = ",".join(cells)
    path = tmp_path / "nan.csv"
    path.write_text("\n".join(text) + "\n")
    with pytest.raises(InputError, match="nan.csv, line 41, column `theta`.*not a finite"):
        calibrate(path, fit="r_er")


def test_table_acceleration_in_the_wrong_unit(syn):
    t = syn.trace.time
    pulse = 0.5 * 9.81 * np.sin(15.0 * t) * (t < 0.42)  # m/s2 written under a g header
    trace = parse_trace(_trace_text(syn, ag=("g", pulse)), source="table.csv")
    with pytest.raises(InputError, match=r"table.csv, column `ag`.*4.9 g.*m/s2 under a `g`"):
        calibrate(trace, fit="r_er")
    trace = parse_trace(_trace_text(syn, ag=("m/s2", pulse / 9.81)), source="table.csv")
    with pytest.raises(InputError, match=r"table.csv, column `ag`.*in g under an `m/s2`"):
        calibrate(trace, fit="r_er")


def test_a_trace_without_rocking():
    rng = np.random.default_rng(0)
    t = np.arange(400) / 200.0
    chans = {"theta": 1e-4 * rng.standard_normal(t.size)}
    chans |= {f"a_A{k}": 0.01 * rng.standard_normal(t.size) for k in range(1, 5)}
    trace = Trace(time=t, channels=chans, units={k: ("rad" if k == "theta" else "m/s2") for k in chans},
                  source="still.csv", specimen="S1")  # fmt: skip
    with pytest.raises(InputError, match="still.csv: no rocking"):
        calibrate(trace, fit="r_er")


def test_options_the_calibration_sets(syn):
    with pytest.raises(InputError, match="`C_p` is set by calibrate"):
        calibrate(syn.trace, fit="r_er", C_p=1000.0)
    with pytest.raises(InputError, match="`start` gives 'cp'"):
        calibrate(syn.trace, impact="CIM", fit="r_er", start={"cp": 1000.0})
    with pytest.raises(InputError, match="`impact` = 'LCP'"):
        calibrate(syn.trace, impact="LCP", fit="r_er")


def test_a_trace_with_table_motion():
    # paper 001 Section 4.4: the cosine pulse of Fig 9 (ω = 15 rad/s, A = 0.4 g) on S1
    from multimass.inputs.excitations import CosinePulse

    syn = synthetic_trace("S1", CosinePulse(amplitude=0.4 * 9.81, omega=15.0), "DD2", 2.0, seed=5)
    cal = calibrate(syn.trace, fit=("r_er", "r_el"), progress=False)
    nu = next(iter(cal.nuisance.values()))
    assert nu["kind"] == "table" and nu["theta0"] is None and nu["t_offset"] == 0.0
    # the check of the table motion's noise ran (`_calibration_input`); a free release
    # has none (`test_a_free_release_runs_no_check_of_a_table_motion`)
    assert len(cal.stages["input"]["draws"]) == 5
    assert cal.status in STATUSES and len(nu["impacts"]) >= 3
    # the excitation is the recorded (filtered, noisy) table motion: within a few hundredths
    for i in nu["impacts"]:
        assert abs(i["r"] - syn.truth["impacts"][i["index"]]["r"]) < 0.05
