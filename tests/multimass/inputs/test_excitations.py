"""Ground excitations: closed forms, breakpoints, validation, pickling (multimass.inputs.excitations)."""

import dataclasses
import json
import math
import pickle

import numpy as np
import pytest

import multimass
from multimass import CosinePulse, CosineWave, FreeRelease, InputError, Ricker, SineWave
from multimass.inputs.excitations import Excitation

A, W = 3.924, 15.0  # paper 001, Section 4.4: ω = 15 rad/s, A = 0.4 g
T = 2 * math.pi / W  # one period


def _times():
    return [0.0, T / 8, T / 4, T / 3, T / 2, 0.9 * T, T, 1.01 * T, 10 * T, -1e-9, -1.0]


def _window(t, f):
    return f(t) if 0.0 <= t <= T else 0.0


@pytest.mark.parametrize(
    "exc, closed_form",
    [
        (SineWave(amplitude=A, omega=W), lambda t: A * math.sin(W * t)),  # paper 004, Fig 2
        (CosineWave(amplitude=A, omega=W), lambda t: A * math.cos(W * t)),  # paper 004, Fig 2
        (
            CosinePulse(omega=W, amplitude=A),
            lambda t: A * math.cos(W * t),
        ),  # paper 001, Sec 4.4 (decided: table displacement (A/ω²)(1 − cos ωt))
    ],
)
def test_harmonic_pulses_match_closed_forms(exc, closed_form):
    assert exc.duration == pytest.approx(T, rel=1e-15)
    for t in _times():
        assert exc(t) == pytest.approx(_window(t, closed_form), abs=1e-12), t
        assert isinstance(exc(t), float)
    ts = np.array(_times())
    got = exc.acceleration(ts)
    assert isinstance(got, np.ndarray) and got.shape == ts.shape
    np.testing.assert_allclose(got, [_window(t, closed_form) for t in ts], atol=1e-12)


def test_special_values_of_the_waves():
    # closed form: sin 0 = 0, sin(π/2) = 1; cos 0 = cos 2π = 1; the pulse peaks at A at π/ω
    assert SineWave(amplitude=A, omega=W)(T / 4) == pytest.approx(A, rel=1e-14)
    assert SineWave(amplitude=A, omega=W)(T) == pytest.approx(0.0, abs=1e-12)
    assert CosineWave(amplitude=A, omega=W)(0.0) == A
    assert CosineWave(amplitude=A, omega=W)(T) == pytest.approx(
        A, rel=1e-14
    )  # jumps to 0 just after T
    assert CosineWave(amplitude=A, omega=W)(T * (1 + 1e-12)) == 0.0
    assert CosinePulse(omega=W, amplitude=A)(T / 2) == pytest.approx(-A, rel=1e-14)
    assert CosinePulse(omega=W, amplitude=A)(0.0) == A
    # the table displacement it comes from starts and ends at rest at zero
    d = CosinePulse(omega=W, amplitude=A).displacement
    assert d(0.0) == 0.0 and d(T) == pytest.approx(0.0, abs=1e-15)
    assert d(T / 2) == pytest.approx(2 * A / W**2, rel=1e-14)


def test_ricker_closed_form_and_default_t0():
    a_p, w_p = 0.16 * 9.81, 1.95 * 2.0  # paper 000, Fig 6: a_g/g = 0.16 (ω_g chosen here)
    r = Ricker(amplitude=a_p, omega=w_p)

    def closed(t):  # Vassiliou & Makris: a_p (1 − ω²τ²/2) exp(−ω²τ²/4), τ = t − t0
        x2 = (w_p * (t - r.t0)) ** 2
        return a_p * (1 - x2 / 2) * math.exp(-x2 / 4)

    assert r.duration == 2 * r.t0
    assert abs(r(0.0)) < 1e-6 * a_p  # brief: default t0 makes |ü_g(0)| < 1e-6 a_p
    assert abs(r(r.duration)) < 1e-6 * a_p
    assert r(r.t0) == pytest.approx(a_p, rel=1e-15)
    # closed form: zero crossings at ω_p |t − t0| = √2, minima −2a_p e^{−3/2} at √6
    assert r(r.t0 + math.sqrt(2) / w_p) == pytest.approx(0.0, abs=1e-12)
    assert r(r.t0 - math.sqrt(6) / w_p) == pytest.approx(-2 * a_p * math.exp(-1.5), rel=1e-12)
    for t in [0.0, 0.3 * r.t0, r.t0, 1.7 * r.t0, r.duration]:
        assert r(t) == pytest.approx(closed(t), rel=1e-12, abs=1e-15)
    assert r(-0.01) == 0.0 and r(r.duration + 1e-9) == 0.0
    ts = np.linspace(-1, r.duration + 1, 101)
    np.testing.assert_allclose(
        r(ts),
        [closed(t) if 0 <= t <= r.duration else 0.0 for t in ts],
        atol=1e-15 * a_p,
        rtol=1e-12,
    )


def test_ricker_default_t0_is_tight():
    # the default is not needlessly long: 1 % earlier the tail exceeds 1e-6 a_p
    r = Ricker(amplitude=1.0, omega=10.0)
    x = 0.99 * r.t0 * 10.0
    assert abs(1 - x * x / 2) * math.exp(-x * x / 4) > 1e-6  # closed form of the tail


def test_ricker_explicit_t0():
    r = Ricker(amplitude=2.0, omega=5.0, t0=1.0)
    assert r.t0 == 1.0 and r.duration == 2.0
    assert r(1.0) == 2.0
    x2 = 25.0  # closed form at t = 0: (ω_p t0)² = 25
    assert r(0.0) == pytest.approx(2.0 * (1 - x2 / 2) * math.exp(-x2 / 4), rel=1e-14)


@pytest.mark.parametrize(
    "exc",
    [
        SineWave(amplitude=A, omega=W),
        CosineWave(amplitude=A, omega=W),
        CosinePulse(omega=W, amplitude=A),
        Ricker(amplitude=A, omega=W),
    ],
)
def test_breakpoints_are_start_and_end(exc):
    assert exc.breakpoints == (0.0, exc.duration)
    assert all(0.0 <= b <= exc.duration for b in exc.breakpoints)


def test_free_release_is_no_ground_motion():
    f = FreeRelease(theta0=0.1)
    assert f.duration == 0.0 and f.breakpoints == ()
    assert f(0.0) == 0.0 and f(5.0) == 0.0
    np.testing.assert_array_equal(f(np.linspace(0, 1, 5)), np.zeros(5))


def test_free_release_initial_displacement_vector_and_none():
    s1 = multimass.column("S1")
    np.testing.assert_array_equal(FreeRelease().initial_displacement(s1), np.zeros(s1.n))
    u0 = np.linspace(0.001, 0.004, s1.n)
    f = FreeRelease(0.0, u0)
    assert f.u0 == tuple(u0)
    np.testing.assert_array_equal(f.initial_displacement(s1), u0)
    with pytest.raises(InputError, match=r"`u0` has 2 values.*N = "):
        FreeRelease(0.0, [0.001, 0.002]).initial_displacement(s1)


def test_free_release_scalar_u0_is_static_shape_under_top_load():
    s1 = multimass.column("S1")
    u = FreeRelease(0.0, 0.01).initial_displacement(s1)
    assert u.shape == (s1.n,)
    assert u[-1] == pytest.approx(0.01, rel=1e-14)
    # closed form: K u = F e_N with a single top load, so K u vanishes except at node N
    f = s1.K @ u
    assert np.max(np.abs(f[:-1])) < 1e-9 * abs(f[-1])
    assert f[-1] > 0
    assert np.all(np.diff(u) > 0)  # a cantilever's deflection grows with height


def test_free_release_on_rigid_block():
    block = multimass.rigid_block("B6M")
    assert FreeRelease(0.05).initial_displacement(block).shape == (0,)
    assert FreeRelease(0.05, 0.0).initial_displacement(block).shape == (0,)
    with pytest.raises(InputError, match=r"`u0` = 0.01.*no elastic nodes.*theta0"):
        FreeRelease(0.05, 0.01).initial_displacement(block)


@pytest.mark.parametrize(
    "make, field",
    [
        (lambda: FreeRelease(float("nan")), "theta0"),
        (lambda: FreeRelease(0.0, float("inf")), "u0"),
        (lambda: FreeRelease(0.0, [0.0, float("nan")]), r"u0\[1\]"),
        (lambda: FreeRelease(0.0, [[0.0]]), "u0"),
        (lambda: SineWave(amplitude=-1.0, omega=W), "amplitude"),
        (lambda: SineWave(amplitude=float("nan"), omega=W), "amplitude"),
        (lambda: SineWave(amplitude=A, omega=0.0), "omega"),
        (lambda: CosineWave(amplitude=A, omega=-2.0), "omega"),
        (lambda: CosineWave(amplitude=float("inf"), omega=W), "amplitude"),
        (lambda: CosinePulse(omega=W, amplitude=-A), "amplitude"),
        (lambda: CosinePulse(omega=float("inf"), amplitude=A), "omega"),
        (lambda: Ricker(amplitude=-A, omega=W), "amplitude"),
        (lambda: Ricker(amplitude=A, omega=0.0), "omega"),
        (lambda: Ricker(amplitude=A, omega=W, t0=0.0), "t0"),
        (lambda: SineWave(amplitude="0.4g", omega=W), "amplitude"),
        (lambda: SineWave(amplitude=True, omega=W), "amplitude"),
    ],
)
def test_bad_parameters_name_the_argument(make, field):
    with pytest.raises(InputError, match=rf"`{field}`"):
        make()


def test_negative_amplitude_says_how_to_reverse():
    with pytest.raises(InputError, match=r"`amplitude` = -1.0.*>= 0.*To reverse the pulse, pass 1"):
        SineWave(amplitude=-1.0, omega=W)


@pytest.mark.parametrize("cls", [SineWave, CosineWave, CosinePulse, Ricker])
def test_amplitudes_beyond_any_earthquake_are_refused_before_a_run(cls):
    """An amplitude above 100 g (1e300 g made the solver fail on a non-finite state) is
    refused by the constructor, naming the argument, the value in g and the fix; 8 g (a
    squat block's map at a0/(α g) = 10) is accepted."""
    assert cls(amplitude=8.0 * multimass.G, omega=W).amplitude == 8.0 * multimass.G
    with pytest.raises(InputError, match=r"`amplitude` = 9.81e\+300 m/s² \(1e\+300 g\).*100 g"):
        cls(amplitude=1e300 * multimass.G, omega=W)
    with pytest.raises(InputError, match=r"`amplitude`.*unit"):
        multimass.MPShape()(amplitude=101.0 * multimass.G, omega=W)


def test_zero_amplitude_is_allowed():
    assert SineWave(amplitude=0.0, omega=W)(T / 4) == 0.0


@pytest.mark.parametrize(
    "exc",
    [
        FreeRelease(0.1, 0.002),
        FreeRelease(-0.05, [0.001, 0.002]),
        SineWave(amplitude=A, omega=W),
        CosineWave(amplitude=A, omega=W),
        CosinePulse(omega=W, amplitude=A),
        Ricker(amplitude=A, omega=W),
        Ricker(amplitude=A, omega=W, t0=2.0),
    ],
)
def test_pickle_round_trip_and_describe(exc):
    back = pickle.loads(pickle.dumps(exc))
    assert back == exc and hash(back) == hash(exc)
    assert back(0.1) == exc(0.1)
    d = exc.describe()
    assert json.loads(json.dumps(d)) == d
    assert d["kind"] == exc.kind and d["duration"] == exc.duration
    assert isinstance(exc, Excitation)


def test_describe_parameters_in_si():
    assert SineWave(amplitude=A, omega=W).describe() == {
        "kind": "sine_wave",
        "amplitude": A,
        "omega": W,
        "duration": T,
    }
    assert CosinePulse(omega=W, amplitude=A).describe()["amplitude"] == A
    assert Ricker(amplitude=1.0, omega=2.0, t0=3.0).describe()["t0"] == 3.0


def test_excitations_are_frozen():
    with pytest.raises(AttributeError):
        SineWave(amplitude=A, omega=W).amplitude = 1.0


def test_numpy_scalars_and_0d_arrays_return_floats():
    s = SineWave(amplitude=A, omega=W)
    assert isinstance(s(np.float64(0.1)), float)
    assert isinstance(s(np.float32(0.1)), float)
    assert isinstance(s(np.array(0.1)), float)
    assert s(np.int64(0)) == 0.0


# Read positionally, `CosinePulse(0.4*G, 15)` could mean ω = 3.9 rad/s, A = 15 m/s² (S1 overturns
# instead of rocking to 0.025 rad): pulses take keyword arguments only, named alike.
@pytest.mark.parametrize("cls", [SineWave, CosineWave, CosinePulse, Ricker])
def test_pulses_refuse_positional_arguments(cls):
    with pytest.raises(
        InputError, match=rf"{cls.__name__}\(3.924, 15\).*by keyword.*amplitude=.*omega="
    ):
        cls(3.924, 15)


@pytest.mark.parametrize("cls, old", [(SineWave, "a0"), (Ricker, "a_p"), (Ricker, "omega_p")])
def test_pulses_name_the_keyword_to_use_for_an_old_one(cls, old):
    with pytest.raises(InputError, match=rf"unknown keyword `{old}`; write `(amplitude|omega)=`"):
        cls(**{old: 1.0, "omega": 2.0} if old != "omega_p" else {old: 1.0, "amplitude": 2.0})


@pytest.mark.parametrize("cls", [SineWave, CosineWave, CosinePulse, Ricker])
def test_pulses_share_their_keywords(cls):
    exc = cls(amplitude=A, omega=W)
    assert (exc.amplitude, exc.omega) == (A, W)
    assert exc.describe()["amplitude"] == A and exc.describe()["omega"] == W
    assert dataclasses.replace(exc, amplitude=2 * A).amplitude == 2 * A


def test_cosine_pulse_by_keyword_rocks_s1_as_paper_001():
    # paper 001 Section 4.4, Fig 9: S1 under the 0.4 g cosine pulse of ω = 15 rad/s rocks to
    # ~0.025 rad (Fig 9a); the swapped pulse (ω = 3.9 rad/s, 15 m/s²) overturned it.
    r = multimass.simulate(
        "S1",
        CosinePulse(amplitude=0.4 * multimass.G, omega=15.0),
        "DD2",
        4.0,
        backend="compiled",
        output_dt=None,
    )
    assert r.status == "completed" and 0.015 < r.theta_max < 0.035


def test_pulse_by_name():
    from multimass.inputs.excitations import pulse

    assert pulse("sine", amplitude=A, omega=W) == SineWave(amplitude=A, omega=W)
    assert pulse("cosine", amplitude=A, omega=W) == CosinePulse(amplitude=A, omega=W)
    assert pulse("cosine", amplitude=A, omega=W, structure_kind="block") == CosineWave(
        amplitude=A, omega=W
    )
    assert pulse("ricker", amplitude=A, omega=W) == Ricker(amplitude=A, omega=W)
    with pytest.raises(InputError, match="`pulse` = 'square'"):
        pulse("square", amplitude=A, omega=W)
