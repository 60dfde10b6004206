"""The Mavroeidis–Papageorgiou pulse (M&P 2003, BSSA 93(3)): closed forms, validation, paths.

References: M&P 2003 (BSSA 93(3)) give the velocity; the acceleration and displacement
of `multimass.inputs.pulse_shapes` are its derivative and integral. The tests integrate the
acceleration and the velocity numerically (scipy.integrate.quad, adaptive Gauss–Kronrod,
an independent calculation) and compare with the closed forms, and run a small map on
the compiled path and on solve_ivp.
"""

import math
import pickle

import numpy as np
import pytest
from scipy.integrate import quad

import multimass
from multimass import InputError, MPPulse, MPShape
from multimass.engines.fast import encode
from multimass.engines.fast._maths import ground_acc

CASES = [
    dict(amplitude=0.6, fp=0.5, gamma=2.0, nu=0.0),
    dict(amplitude=0.8, fp=1.3, gamma=2.5, nu=1.1),  # a residual displacement
    dict(amplitude=0.3, fp=0.25, gamma=1.4, nu=-2.0, t0=4.0),  # starts later
    dict(amplitude=1.2, fp=2.0, gamma=3.2, nu=math.pi / 2),
]


def _velocity_closed_form(p, t):
    """M&P 2003's velocity, typed from the paper (not through multimass.inputs.pulse_shapes)."""
    tau = t - p.t0
    if abs(tau) > p.gamma / (2 * p.fp):
        return 0.0
    envelope = 0.5 * p.amplitude * (1 + math.cos(2 * math.pi * p.fp * tau / p.gamma))
    return envelope * math.cos(2 * math.pi * p.fp * tau + p.nu)


@pytest.mark.parametrize("case", CASES)
def test_acceleration_integrates_to_the_velocity_and_velocity_to_displacement(case):
    p = MPPulse(**case)
    times = np.linspace(p.start - 0.2, p.duration + 0.3, 23)
    for t in times:
        v_int, _ = quad(p.acceleration, 0.0, t, limit=400, epsabs=1e-13, epsrel=1e-12)
        d_int, _ = quad(p.velocity, 0.0, t, limit=400, epsabs=1e-13, epsrel=1e-12)
        assert p.velocity(t) == pytest.approx(_velocity_closed_form(p, t), abs=1e-14)
        assert v_int == pytest.approx(p.velocity(t), abs=1e-10 * p.amplitude), t
        assert d_int == pytest.approx(p.displacement(t), abs=1e-10 * p.amplitude), t


def test_residual_displacement_is_zero_for_integer_gamma_only():
    # closed form: sin(φ ± ψ) at τ = ±γ/(2 f_p) differ by 2π(γ ± 1)/… — equal for integer γ
    assert MPPulse(amplitude=0.5, fp=1.0, gamma=2.0, nu=0.7).displacement(10.0) == pytest.approx(
        0.0, abs=1e-15
    )
    d = MPPulse(amplitude=0.5, fp=1.0, gamma=2.5, nu=0.7).displacement(10.0)
    end, _ = quad(MPPulse(amplitude=0.5, fp=1.0, gamma=2.5, nu=0.7).velocity, 0, 2.5, limit=200)
    assert abs(d) > 1e-3 and d == pytest.approx(end, abs=1e-12)


@pytest.mark.parametrize("case", CASES)
def test_window_ends_and_breakpoints(case):
    p = MPPulse(**case)
    assert p.breakpoints == (p.start, p.duration)
    assert p.duration == pytest.approx(p.t0 + p.gamma / (2 * p.fp), rel=1e-15)
    for t in (p.start, p.duration):  # ü_g and v vanish at both ends: no jump
        assert abs(p.acceleration(t)) < 1e-12 * p.amplitude * p.fp
        assert abs(p.velocity(t)) < 1e-14
    assert p.acceleration(p.duration * (1 + 1e-9)) == 0.0
    assert p.acceleration(-1e-9) == 0.0
    arr = p.acceleration(np.array([p.start - 1, p.t0, p.duration + 1]))
    assert arr[0] == 0.0 and arr[2] == 0.0 and arr[1] == p.acceleration(p.t0)


@pytest.mark.parametrize("case", CASES)
def test_peak_acceleration_is_the_peak_of_a_fine_sampling(case):
    p = MPPulse(**case)
    t = np.linspace(p.start, p.duration, 400_001)
    v = np.array([_velocity_closed_form(p, x) for x in t])
    sampled = np.max(np.abs(np.gradient(v, t)))  # numerical derivative of the paper's v
    assert p.peak_acceleration == pytest.approx(sampled, rel=1e-6)
    assert p.peak_acceleration >= np.max(np.abs(p.acceleration(t)))


def test_shape_builds_the_pulse_of_a_given_peak_acceleration():
    shape = MPShape(gamma=2.5, nu=0.4)
    p = shape(amplitude=3.0, omega=4.0)
    assert p.fp == pytest.approx(4.0 / (2 * math.pi), rel=1e-15)
    assert p.peak_acceleration == pytest.approx(3.0, rel=1e-12)
    # independent of MPShape's own peak search: the paper's v, differentiated numerically
    t = np.linspace(p.start, p.duration, 400_001)
    v = np.array([_velocity_closed_form(p, x) for x in t])
    assert np.max(np.abs(np.gradient(v, t))) == pytest.approx(3.0, rel=1e-6)
    assert p.start == 0.0 and (p.gamma, p.nu) == (2.5, 0.4)
    assert (
        multimass.inputs.excitations.pulse("mp", amplitude=3.0, omega=4.0, gamma=2.5, nu=0.4) == p
    )


def test_compiled_ground_acceleration_is_the_same_source():
    rng = np.random.default_rng(5)
    for case in CASES:
        p = MPPulse(**case)
        kind, par, smp = encode(p)
        for t in rng.uniform(-0.5, p.duration + 0.5, 200):
            assert ground_acc(float(t), kind, par, smp) == p.acceleration(float(t))


def test_describe_and_pickle():
    p = MPPulse(amplitude=0.6, fp=0.5, gamma=2.0, nu=0.3)
    d = p.describe()
    assert d["kind"] == "mp_pulse" and d["fp"] == 0.5 and d["t0"] == 2.0
    assert d["peak_acceleration"] == pytest.approx(p.peak_acceleration)
    assert pickle.loads(pickle.dumps(p)) == p
    assert pickle.loads(pickle.dumps(MPShape(gamma=3.0))) == MPShape(gamma=3.0)


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(amplitude=-0.5, fp=1.0), ["amplitude", "-0.5", "nu + π"]),
        (dict(amplitude=60.0, fp=1.0), ["amplitude", "60", "m/s", "cm/s"]),
        (dict(amplitude=0.5, fp=6.28e2), ["fp", "628", "Hz", "rad/s"]),
        (dict(amplitude=0.5, fp=0.0), ["fp"]),
        (dict(amplitude=0.5, fp=1.0, gamma=1.0), ["gamma", "1 < γ ≤ 10"]),
        (dict(amplitude=0.5, fp=1.0, gamma=1e6), ["gamma", "1000000.0", "1 < γ ≤ 10", "gamma=2"]),
        (dict(amplitude=0.5, fp=1.0, nu=90.0), ["nu", "90", "rad", "1.5708"]),
        (dict(amplitude=0.5, fp=1.0, t0=0.2), ["t0", "0.2", ">= 1"]),
        (dict(amplitude=float("nan"), fp=1.0), ["amplitude"]),
    ],
)
def test_bad_input_is_named(kwargs, words):
    with pytest.raises(InputError) as err:
        MPPulse(**kwargs)
    for w in words:
        assert w in str(err.value), (w, str(err.value))


def test_positional_arguments_are_refused():
    with pytest.raises(InputError, match="keyword"):
        MPPulse(0.5, 1.0)


def test_a_column_runs_it_on_both_paths():
    p = MPShape(gamma=2.0, nu=0.0)(amplitude=0.6 * multimass.G, omega=12.0)  # S1: g tan α ≈ 0.36 g
    a = multimass.simulate_outcome("S1", p, t_end=4.0, impact="DD2", backend="compiled")
    b = multimass.simulate_outcome("S1", p, t_end=4.0, impact="DD2", backend="scipy")
    assert a.status == b.status == "completed" and a.n_impacts == b.n_impacts > 0
    assert a.theta_max == pytest.approx(b.theta_max, rel=1e-6)


def test_map_agrees_between_compiled_and_solve_ivp_in_every_cell():
    from multimass.sweeps.maps import overturning_map

    kw = dict(omega_p=np.linspace(1, 8, 6), amp=np.linspace(0.5, 6, 6), executor="serial")
    a = overturning_map("B6M", pulse=MPShape(gamma=2.5, nu=0.5), **kw)
    b = overturning_map("B6M", pulse=MPShape(gamma=2.5, nu=0.5), backend="scipy", **kw)
    assert a.pulse == "mp_g2.5_nu0.5"
    np.testing.assert_array_equal(a.grid, b.grid)
    outcomes = set(a.grid.ravel())
    assert {"overturned", "rest", "no_rocking"} <= outcomes
    np.testing.assert_allclose(
        a.cells.theta_max_over_alpha, b.cells.theta_max_over_alpha, rtol=1e-6, atol=1e-9
    )


def test_scene_reads_an_mp_pulse(tmp_path):
    from multimass.scenes.toml_scene import arguments_from_mapping

    data = {
        "name": "B6M under a near-fault pulse",
        "structure": {"specimen": "B6M"},
        "excitation": {"kind": "mp_pulse", "amplitude_m_per_s": 0.5, "fp_hz": 1.0, "gamma": 2.5},
        "question": {"kind": "overturning"},
    }
    args = arguments_from_mapping(data, "scene.toml", tmp_path)
    assert args["excitation"] == MPPulse(amplitude=0.5, fp=1.0, gamma=2.5)
    data["excitation"]["fp_hz"] = 100.0
    with pytest.raises(InputError, match="fp"):
        arguments_from_mapping(data, "scene.toml", tmp_path)


def test_stability_cli_maps_an_mp_pulse(tmp_path, capsys):
    from multimass.cli import main

    args = ["stability", "B6M", "--pulse", "mp", "--gamma", "2.5", "--nu", "0.5"]
    args += ["--omega-p", "2:6:3", "--amp", "0.5:4:3", "--executor", "serial"]
    assert main(args + ["--out", str(tmp_path), "--json"]) == 0
    info = __import__("json").loads(capsys.readouterr().out)
    assert info["pulse"] == "mp_g2.5_nu0.5" and info["n_simulations"] >= 9  # grid + refinement
    assert list(tmp_path.glob("B6M_mp_g2.5_nu0.5_modified*.png"))
    assert main(["stability", "B6M", "--gamma", "3", "--executor", "serial"]) == 2
    assert "--pulse mp" in capsys.readouterr().err
    assert main(["simulate", "B6M", "--pulse", "mp", "--omega", "10", "--amp", "0.5g"]) == 0
    capsys.readouterr()
    args = ["simulate", "B6M", "--pulse", "sine", "--nu", "1", "--omega", "10", "--amp", "0.5g"]
    assert main(args) == 2  # --nu would be ignored by a sine
    assert "--pulse mp" in capsys.readouterr().err


def test_spectrum_sweeps_an_mp_pulse_on_both_paths(capsys):
    from multimass.cli import main
    from multimass.sweeps.spectra import pulse_spectrum

    shape = MPShape(gamma=2.5, nu=0.5)
    kw = dict(omega=[8.0, 12.0], amp=0.6 * multimass.G, t_free=2.0, executor="serial")
    a = pulse_spectrum("S1", shape, **kw)
    b = pulse_spectrum("S1", shape, backend="scipy", **kw)
    assert a.kind == "mp_g2.5_nu0.5_pulse" and a.options["pulse"] == "mp_g2.5_nu0.5"
    np.testing.assert_allclose(a.table.theta_max, b.table.theta_max, rtol=1e-5)
    assert (a.table.theta_max > 0).all() and (a.table.status == b.table.status).all()
    args = ["spectrum", "S1", "--pulse", "mp", "--gamma", "2.5", "--omega", "8:12:2"]
    assert main(args + ["--amp", "0.6g", "--t-free", "2", "--executor", "serial"]) == 0
    assert (
        main(["spectrum", "S1", "--pulse", "sine", "--nu", "1", "--omega", "8", "--amp", "1g"]) == 2
    )
    assert "--pulse mp" in capsys.readouterr().err


def test_gamma_is_bounded_as_in_a_suite_file_at_every_entry_point(capsys):
    """γ above 10 (a harmonic wave, not a pulse; 1e6 ran until memory ran out) is refused
    by the pulse itself, so the shape, the pulse by name and the stability command refuse
    it at once with the same bound a suite file applies to a drawn γ."""
    from multimass.cli import main
    from multimass.inputs.excitations import MP_MAX_GAMMA

    assert MPPulse(amplitude=0.5, fp=1.0, gamma=MP_MAX_GAMMA).gamma == MP_MAX_GAMMA
    with pytest.raises(InputError, match="γ ≤ 10"):
        MPShape(gamma=1e6)
    with pytest.raises(InputError, match="γ ≤ 10"):
        multimass.inputs.excitations.pulse("mp", amplitude=3.0, omega=4.0, gamma=10.5)
    argv = ["stability", "B6M", "--pulse", "mp", "--gamma", "1e6", "--executor", "serial"]
    assert main(argv + ["--omega-p", "1:2:2", "--amp", "1:2:2"]) == 2
    err = capsys.readouterr().err
    assert "`--gamma` = 1000000.0" in err and "γ ≤ 10" in err and err.count("\n") == 1
    assert "give e.g. --gamma 2" in err
