"""Recorded test traces: reading, validation and error metrics (multimass.inputs.traces)."""

import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

import multimass
from multimass import FreeRelease, InputError, Trace, compare_trace, read_trace
from multimass.analysis.trace_metrics import align

G = 9.81  # DESIGN.md: g = 9.81 m/s²
DT = 1e-3  # simulate's default output_dt (s)


# ---------------------------------------------------------------------------- helpers
def write_trace(path, header, columns):
    """A CSV trace: one header row, then the columns at full precision."""
    rows = np.column_stack(columns)
    path.write_text(
        "# synthetic trace\n"
        + header
        + "\n"
        + "\n".join(",".join(f"{x:.17g}" for x in row) for row in rows)
        + "\n"
    )
    return path


def grid_samples(resp):
    """The simulation's samples on its output grid k·DT (event samples dropped)."""
    df = resp.series
    on_grid = np.abs(df.t / DT - np.round(df.t / DT)) < 1e-6
    df = df[on_grid]
    return df[~df.t.round(9).duplicated(keep="last")]


def fake_response(t, **columns):
    """A stand-in for a Response: compare_trace reads only its series."""
    return SimpleNamespace(series=pd.DataFrame(dict(t=t, **columns)))


@pytest.fixture(scope="module")
def s1():
    return multimass.column("S1")


@pytest.fixture(scope="module")
def release(s1):
    # paper 001 Section 4.3: free vibration of S1 (smaller angle, 1 s, to stay fast)
    return multimass.simulate(s1, FreeRelease(0.05), impact="DD2", t_end=1.0)


@pytest.fixture(scope="module")
def pulse(s1):
    # paper 001 Section 4.4, Fig 9: S1 under the cosine pulse ω = 15 rad/s, A = 0.4 g
    return multimass.simulate(
        s1, multimass.CosinePulse(omega=15.0, amplitude=0.4 * G), impact="DD2", t_end=1.0
    )


# ---------------------------------------------------------------------------- identical trace
def test_trace_of_the_same_simulation_has_zero_error(tmp_path, s1, release):
    df = grid_samples(release)
    path = write_trace(
        tmp_path / "free.csv",
        "t [s],theta [deg],a_A2 [g],a_A4 [m/s2]",
        [df.t, np.degrees(df.theta), df.a3 / G, df.a5],
    )
    trace = read_trace(path)
    metrics = compare_trace(trace, release, s1)
    assert list(metrics) == ["theta", "a_A2", "a_A4"]
    # S1.toml [sensors]: A2 at node 3, A4 at node 5
    assert [m.column for m in metrics.values()] == ["theta", "a3", "a5"]
    for name, col in (("theta", "theta"), ("a_A2", "a3"), ("a_A4", "a5")):
        m = metrics[name]
        signal_rms = float(np.sqrt(np.mean(df[col] ** 2)))
        assert m.rms_error < 1e-6 * signal_rms
        assert m.peak_error == pytest.approx(0.0, abs=1e-12 * m.peak_measured)
        assert m.peak_time_shift_s == 0.0
        assert m.n_samples == len(df) and (m.t_start, m.t_end) == (0.0, 1.0)
        assert m.units == ("rad" if name == "theta" else "m/s2")
    # a free release: the largest |θ| is the release angle, at t = 0
    assert metrics["theta"].peak_measured == pytest.approx(0.05, rel=1e-14)
    assert metrics["theta"].t_peak_measured == 0.0


# ---------------------------------------------------------------------------- perturbed trace
@pytest.mark.parametrize("shift", [0.0, 0.05])
def test_scaled_and_shifted_trace_is_recovered(tmp_path, s1, pulse, shift):
    df = grid_samples(pulse)
    keep = df.t <= 1.0 - shift + 1e-9
    d = df[keep]
    # measured(t) = 1.1 · simulated(t − shift), on the shifted grid
    path = write_trace(
        tmp_path / "pulse.csv",
        "t [s],theta [rad],a_A2 [g],a_A4 [cm/s2]",
        [d.t + shift, 1.1 * d.theta, 1.1 * d.a3 / G, 110.0 * d.a5],
    )
    metrics = compare_trace(read_trace(path), pulse, s1)
    window = (df.t >= shift - 1e-9) & (df.t <= 1.0 - shift + 1e-9)
    for name, col in (("theta", "theta"), ("a_A2", "a3"), ("a_A4", "a5")):
        y = np.abs(df[col].to_numpy())
        peak, t_peak = y[window].max(), df.t.to_numpy()[window][np.argmax(y[window])]
        assert y.max() == peak  # the global peak is inside both spans
        m = metrics[name]
        # closed form: max|sim| − max|meas| = P − 1.1 P, relative 1/1.1 − 1
        assert m.peak_simulated == pytest.approx(peak, rel=1e-9)
        assert m.peak_measured == pytest.approx(1.1 * peak, rel=1e-9)
        assert m.peak_error_rel == pytest.approx(1 / 1.1 - 1, abs=1e-9)
        assert m.peak_time_shift_s == pytest.approx(-shift, abs=DT)
        assert m.t_peak_simulated == pytest.approx(t_peak, abs=DT)
        if shift == 0.0:
            # closed form: |1.1 s − s| = 0.1 |s| everywhere, so NRMSE = 0.1 / 1.1
            assert m.nrmse == pytest.approx(0.1 / 1.1, rel=1e-9)
        else:
            assert m.t_start == pytest.approx(shift, abs=1e-12) and m.t_end == pytest.approx(1.0)


# ---------------------------------------------------------------------------- closed forms
def test_rms_is_time_weighted_on_a_non_uniform_grid(s1):
    # meas = sin 2πt on [0, 2] s, dense on [0, 1], sparse on [1, 2]; sim = 1.1 meas
    t = np.unique(np.r_[np.linspace(0.0, 1.0, 4001), np.linspace(1.0, 2.0, 401)])
    trace = Trace(time=t, channels={"theta": np.sin(2 * np.pi * t)}, units={"theta": "rad"})
    t_sim = np.linspace(0.0, 2.0, 20001)
    resp = fake_response(t_sim, theta=1.1 * np.sin(2 * np.pi * t_sim))
    m = compare_trace(trace, resp, s1)["theta"]
    # closed form: RMS of sin over whole periods is 1/√2; the error is 0.1 sin
    assert m.rms_measured == pytest.approx(1 / math.sqrt(2), rel=1e-4)
    assert m.rms_error == pytest.approx(0.1 / math.sqrt(2), rel=1e-4)
    assert m.nrmse == pytest.approx(0.1, rel=1e-6)


def test_jump_at_an_event_is_not_smeared(s1):
    # a series recording a jump 0 → 1 at t = 0.5 s as two samples at the same time
    resp = fake_response([0.0, 0.5, 0.5, 1.0], theta=[0.0, 0.0, 1.0, 1.0])
    trace = Trace(
        time=[0.0, 0.499, 0.5, 0.501, 1.0], channels={"theta": np.zeros(5)}, units={"theta": "rad"}
    )
    t, meas, sim = align(trace, resp, s1, "theta")
    # closed form: 0 before the jump, the post-event value from it on
    np.testing.assert_array_equal(sim, [0.0, 0.0, 1.0, 1.0, 1.0])


def test_units_are_converted_to_si(tmp_path):
    path = tmp_path / "units.csv"
    path.write_text(
        "time [ms],theta [deg],a_A2 [g],a3 [cm/s2],a_node5 [gal],a_A4 [m/s^2]\n"
        "0,180,1,100,-250,2\n"
        "500,-90,-0.5,0,0,0\n"
    )
    tr = read_trace(path)
    # closed form: 1 ms = 1e-3 s, 180° = π rad, 1 g = 9.81 m/s², 100 cm/s² = 1 m/s², 1 gal = 1 cm/s²
    np.testing.assert_allclose(tr.time, [0.0, 0.5], rtol=1e-15)
    np.testing.assert_allclose(tr.channels["theta"], [math.pi, -math.pi / 2], rtol=1e-15)
    np.testing.assert_allclose(tr.channels["a_A2"], [G, -G / 2], rtol=1e-15)
    np.testing.assert_allclose(tr.channels["a3"], [1.0, 0.0], rtol=1e-15)
    np.testing.assert_allclose(tr.channels["a_node5"], [-2.5, 0.0], rtol=1e-15)
    np.testing.assert_allclose(tr.channels["a_A4"], [2.0, 0.0], rtol=1e-15)
    assert dict(tr.units) == {
        "theta": "deg",
        "a_A2": "g",
        "a3": "cm/s2",
        "a_node5": "gal",
        "a_A4": "m/s^2",
    }
    assert tr.time_units == "ms" and tr.source == str(path)
    np.testing.assert_allclose(tr.to_written_units("theta", tr.channels["theta"]), [180, -90])
    assert tr.si_units("theta") == "rad" and tr.si_units("a_A2") == "m/s2"
    assert read_trace(path, g=9.80665).channels["a_A2"][0] == 9.80665
    with pytest.raises(ValueError):
        tr.channels["theta"][0] = 0.0  # read-only


def test_node_and_sensor_names_map_to_columns(tmp_path, s1):
    from multimass.analysis.trace_metrics import channel_columns

    path = tmp_path / "names.csv"
    path.write_text("T [s],THETA [rad],A_a2 [g],a1 [g],a_node4 [g]\n0,0,0,0,0\n1,0,0,0,0\n")
    assert channel_columns(read_trace(path), s1) == {
        "THETA": "theta",
        "A_a2": "a3",
        "a1": "a1",
        "a_node4": "a4",
    }


def test_free_release_from_first_sample(tmp_path):
    path = tmp_path / "r.csv"
    path.write_text("t [s],theta [deg]\n-0.5,5.0\n0.0,4.0\n")
    tr = read_trace(path)
    assert tr.free_release() == FreeRelease(theta0=math.radians(5.0))
    assert tr.duration == 0.5
    path.write_text("t [s],a_A2 [g]\n0,0\n1,0\n")
    with pytest.raises(InputError, match=r"no `theta` column"):
        read_trace(path).free_release()


# ---------------------------------------------------------------------------- bad input
BAD = [
    ("t [s],theta\n0,1\n1,2\n", r"line 1: column `theta` has no unit.*rad, deg"),
    ("t [s],a_A2\n0,1\n1,2\n", r"line 1: column `a_A2` has no unit.*g, m/s2, cm/s2"),
    ("t,theta [rad]\n0,1\n1,2\n", r"line 1: column `t` has no unit.*s, ms"),
    (
        "t [s],theta [grad]\n0,1\n1,2\n",
        r"line 1: column `theta` has unit 'grad'; accepted: rad, deg",
    ),
    ("t [s],a_A2 [ft/s2]\n0,1\n1,2\n", r"line 1: column `a_A2` = 'ft/s2': unknown acceleration"),
    (
        "t [s],theta [rad],u5 [m]\n0,1,0\n1,2,0\n",
        r"line 1: unknown column `u5` \(column 3\); "
        r"accepted columns: `t \[s\]`",
    ),
    ("theta [rad],a_A2 [g]\n0,1\n1,2\n", r"line 1: no time column"),
    ("t [s],time [s],theta [rad]\n0,0,1\n1,1,2\n", r"line 1: more than one time column"),
    ("t [s],theta [rad],Theta [deg]\n0,1,1\n1,2,2\n", r"line 1: column `Theta` appears twice"),
    ("t [s]\n0\n1\n", r"line 1: no channel column besides time"),
    ("t [s],,theta [rad]\n0,1,1\n", r"line 1: column 2 has no name"),
    ("t [s],theta [rad]\n0,1\n", r"1 sample\(s\); a trace needs at least 2 rows"),
    ("t [s],theta [rad]\n", r"0 sample\(s\); a trace needs at least 2 rows"),
    (
        "# comment\n\nt [s],theta [rad]\n0,1\n0.1,2\n0.1,3\n",
        r"line 6, column `time`: t = 0.1 s does not increase",
    ),
    (
        "t [s],theta [rad],a_A2 [g]\n0,1,0\n0.1,2,nan\n",
        r"line 3, column `a_A2`: value nan is not a finite",
    ),
    ("t [s],theta [rad]\n0,1\ninf,2\n", r"line 3, column `time`: value inf is not a finite"),
    ("t [s],theta [rad]\n0,1\n0.1,abc\n", r"line 3, column `theta`: cannot read 'abc' as a number"),
    ("t [s],theta [rad]\n0,1\n0.1,\n", r"line 3, column `theta`: cannot read '' as a number"),
    ("t [s],theta [rad]\n0,1\n0.1,2,3\n", r"line 3: 3 cell\(s\) but the header has 2 columns"),
    ("# only a comment\n", r"empty file"),
]


@pytest.mark.parametrize("text, message", BAD)
def test_bad_trace_files(tmp_path, text, message):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(InputError, match=message) as err:
        read_trace(path)
    assert str(path) in str(err.value)


def test_bad_trace_arrays():
    with pytest.raises(InputError, match=r"column `theta` has no unit"):
        Trace(time=[0, 1], channels={"theta": [0, 1]}, units={})
    with pytest.raises(InputError, match=r"unknown channel `phi`"):
        Trace(time=[0, 1], channels={"phi": [0, 1]}, units={"phi": "rad"})
    with pytest.raises(InputError, match=r"sample 1, column `time`: t = 0.0 s does not increase"):
        Trace(time=[0, 0], channels={"theta": [0, 1]}, units={"theta": "rad"})
    with pytest.raises(InputError, match=r"column `theta` has shape \(3,\)"):
        Trace(time=[0, 1], channels={"theta": [0, 1, 2]}, units={"theta": "rad"})


@pytest.mark.parametrize(
    "header, message",
    [
        (
            "t [s],a_A9 [g]",
            r"column `a_A9`: specimen 'S1' has no sensor 'A9'; known sensors: A1, A2",
        ),
        ("t [s],a7 [g]", r"column `a7`: node 7 does not exist; 'S1' has nodes 1..5"),
        ("t [s],a_node0 [g]", r"column `a_node0`: node 0 does not exist"),
    ],
)
def test_unknown_sensor_or_node(tmp_path, s1, header, message):
    path = tmp_path / "n.csv"
    path.write_text(header + "\n0,0\n1,0\n")
    resp = fake_response([0.0, 1.0], theta=[0.0, 0.0])
    with pytest.raises(InputError, match=message):
        compare_trace(read_trace(path), resp, s1)


def test_block_allows_only_theta(tmp_path):
    block = multimass.rigid_block("B6M")
    path = tmp_path / "b.csv"
    path.write_text("t [s],theta [deg],a_A2 [g]\n0,1,0\n1,0,0\n")
    resp = fake_response([0.0, 1.0], theta=[math.radians(1.0), 0.0])
    with pytest.raises(InputError, match=r"column `a_A2`: 'B6M' is a rigid block.*only `theta`"):
        compare_trace(read_trace(path), resp, block)
    path.write_text("t [s],theta [deg]\n0,1\n1,0\n")
    m = compare_trace(read_trace(path), resp, block)["theta"]
    assert m.rms_error == pytest.approx(0.0, abs=1e-15)


def test_no_overlap_or_no_series(s1):
    trace = Trace(time=[0.0, 1.0], channels={"theta": [0.0, 1.0]}, units={"theta": "rad"})
    resp = fake_response([0.0, 1.0], theta=[0.0, 1.0])
    with pytest.raises(InputError, match=r"fewer than 2 samples.*`t_offset` = 5 s"):
        compare_trace(trace, resp, s1, t_offset=5.0)
    with pytest.raises(InputError, match=r"no recorded series.*`output_dt`"):
        compare_trace(trace, fake_response([], theta=[]), s1)
    with pytest.raises(InputError, match=r"`name` = 'a_A2': not a channel"):
        align(trace, resp, s1, "a_A2")


def test_metrics_never_nan_for_a_zero_signal(s1):
    trace = Trace(time=[0.0, 1.0], channels={"theta": [0.0, 0.0]}, units={"theta": "rad"})
    m = compare_trace(trace, fake_response([0.0, 1.0], theta=[0.0, 0.5]), s1)["theta"]
    assert m.nrmse is None and m.peak_error_rel is None
    # closed form: error samples [0, 0.5] over 1 s; trapezoid of e² = (0 + 0.25) / 2
    assert m.peak_error == 0.5 and m.rms_error == pytest.approx(math.sqrt(0.125), rel=1e-15)
    assert m.to_dict()["channel"] == "theta"


# ---------------------------------------------------------------------------- the file itself
@pytest.mark.parametrize(
    "make, problem",
    [
        (lambda d: d / "missing.csv", "no such file"),
        (lambda d: d, "is a directory"),
        (lambda d: _bytes(d, "empty.csv", b""), "the file is empty"),
        (
            lambda d: _bytes(d, "bin.csv", b"t [s],theta [rad]\n\x00\x01"),
            r"a binary file \(NUL byte at offset 18\)",
        ),
        (
            lambda d: _bytes(d, "latin.csv", "# Málaga\nt [s],theta [rad]\n".encode("latin-1")),
            r"not UTF-8 text \(byte 0xe1 on line 1\)",
        ),
    ],
    ids=["missing", "directory", "empty", "binary", "latin-1"],
)
def test_a_bad_trace_file_is_named_with_what_to_give(tmp_path, make, problem):
    path = make(tmp_path)
    with pytest.raises(InputError, match=problem) as info:
        read_trace(path)
    assert str(path) in str(info.value) and "a trace CSV file with units in its header" in str(
        info.value
    )


def test_a_directory_lists_its_csv_files(tmp_path):
    _bytes(tmp_path, "run1.csv", b"x")
    with pytest.raises(InputError, match=r"is a directory.*files there: run1.csv\)"):
        read_trace(tmp_path)


def test_excel_byte_order_mark_is_not_part_of_the_header(tmp_path):
    # Excel's "CSV UTF-8" writes a byte-order mark before the first header cell
    path = _bytes(tmp_path, "excel.csv", "\ufefft [s],theta [rad]\n0,0.1\n1,0.2\n".encode("utf-8"))
    assert read_trace(path).channels["theta"].tolist() == [0.1, 0.2]


@pytest.mark.parametrize("path", [None, 3.5, b"t.csv", ""])
def test_trace_path_must_be_a_path(path):
    with pytest.raises(InputError, match="`path` = "):
        read_trace(path)


@pytest.mark.parametrize("g", [0.0, -9.81, float("nan"), "9.81", True])
def test_trace_gravity_is_a_positive_number(tmp_path, g):
    path = tmp_path / "t.csv"
    path.write_text("t [s],a_A2 [g]\n0,1\n1,2\n")
    with pytest.raises(InputError, match="`g` = "):
        read_trace(path, g=g)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (
            dict(channels={"theta": ["0", "1"]}),
            r"`channels\['theta'\]` holds 'str",
        ),  # no '1' -> 1.0
        (
            dict(channels={"theta": [0, 1]}, units={"theta": 1}),
            r"`units\['theta'\]` = 1: give the unit",
        ),
        (dict(channels=[("theta", [0, 1])]), r"`channels` = .*give a mapping"),
        (dict(time_units=1), r"`time_units` = 1"),
    ],
)
def test_trace_arrays_are_checked_before_use(kwargs, match):
    args = dict(time=[0.0, 1.0], channels={"theta": [0, 1]}, units={"theta": "rad"}) | kwargs
    with pytest.raises(InputError, match=match):
        Trace(**args)


def test_compare_trace_arguments(s1):
    trace = Trace(time=[0.0, 1.0], channels={"theta": [0.0, 1.0]}, units={"theta": "rad"})
    resp = fake_response([0.0, 1.0], theta=[0.0, 1.0])
    with pytest.raises(
        InputError, match=r"`response` = None: give the result of multimass.simulate"
    ):
        compare_trace(trace, None, s1)
    with pytest.raises(InputError, match=r"`trace` = 'x.csv': give a Trace.*read_trace"):
        compare_trace("x.csv", resp, s1)
    with pytest.raises(InputError, match=r"`specimen` = None: give a column or block specimen"):
        compare_trace(trace, resp, None)
    for bad in (float("nan"), "0", True):
        with pytest.raises(InputError, match=r"`t_offset` = "):
            compare_trace(trace, resp, s1, t_offset=bad)
    trace_a = Trace(time=[0.0, 1.0], channels={"a3": [0.0, 1.0]}, units={"a3": "g"})
    with pytest.raises(InputError, match=r"`response` has no column 'a3' for channel `a3`"):
        compare_trace(trace_a, resp, s1)


def _bytes(folder, name, data: bytes):
    path = folder / name
    path.write_bytes(data)
    return path


# ---------------------------------------------------------------------------- table motion, specimen
def test_ground_acceleration_channel_in_every_unit(tmp_path):
    path = tmp_path / "table.csv"
    for unit, si in (("g", G), ("m/s2", 1.0), ("cm/s2", 0.01), ("gal", 0.01), ("mm/s2", 1e-3)):
        path.write_text(f"t [s],theta [rad],AG [{unit}]\n0,0,1\n0.005,0,-2\n")
        tr = read_trace(path)
        # closed form: 1 unit = `si` m/s², the same rules as the a_... channels
        np.testing.assert_allclose(tr.ag, [si, -2 * si], rtol=1e-15)
        assert tr.ag is tr.channels["AG"] and tr.units["AG"] == unit
        assert tr.si_units("AG") == "m/s2"
    path.write_text("t [s],theta [rad]\n0,0\n1,0\n")
    assert read_trace(path).ag is None
    assert Trace(time=[0, 1], channels={"ag": [0, 1]}, units={"ag": "g"}).ag[1] == 1.0  # SI


@pytest.mark.parametrize(
    "header, message",
    [
        (
            "t [s],theta [rad],ag [deg]",
            r"line 1: column `ag` = 'deg': unknown acceleration unit; accepted: g, m/s2.*"
            r"ground \(table\) acceleration: write it as `ag \[g\]`",
        ),
        ("t [s],theta [rad],ag", r"line 1: column `ag` has no unit.*`ag \[g\]`"),
        ("t [s],ag [g],Ag [g]", r"line 1: column `Ag` appears twice"),
    ],
)
def test_ground_acceleration_in_a_wrong_unit(tmp_path, header, message):
    path = tmp_path / "bad_ag.csv"
    path.write_text(
        header + "\n" + "\n".join(",".join(["0"] * (header.count(",") + 1)) for _ in "ab")
    )
    with pytest.raises(InputError, match=message) as err:
        read_trace(path)
    assert str(path) in str(err.value)


def test_ground_acceleration_is_compared_with_the_simulated_one(s1, pulse):
    from multimass.analysis.trace_metrics import channel_columns

    grid = grid_samples(pulse)
    trace = Trace(time=grid.t.to_numpy(), channels={"ag": grid.ag.to_numpy()}, units={"ag": "m/s2"})
    assert channel_columns(trace, s1) == {"ag": "ag"}
    assert compare_trace(trace, pulse, s1)["ag"].rms_error == pytest.approx(0.0, abs=1e-12)
    block = Trace(time=[0.0, 1.0], channels={"ag": [0.0, 0.0]}, units={"ag": "g"})
    assert channel_columns(block, multimass.rigid_block("B6M")) == {"ag": "ag"}


@pytest.mark.parametrize(
    "comments, specimen",
    [
        ("# specimen: S1\n", "S1"),
        ("#Specimen:  S2 tested twice \n# other\n", "S2 tested twice"),
        ("# specimen: S3\n# specimen: S3\n", "S3"),
        ("# a comment\n", None),
        ("", None),
    ],
)
def test_specimen_comment_line(tmp_path, comments, specimen):
    path = tmp_path / "named.csv"
    path.write_text(comments + "t [s],theta [rad]\n0,0\n1,0\n")
    assert read_trace(path).specimen == specimen


@pytest.mark.parametrize(
    "comments, message",
    [
        ("# specimen:\n", r"line 1: `# specimen:` without a name; write e.g. `# specimen: S1`"),
        (
            "# specimen: S1\n# x\n# specimen: S2\n",
            r"line 3: a second `# specimen:` line \('S2'; line 1 says 'S1'\); keep one",
        ),
    ],
)
def test_bad_specimen_comment_line(tmp_path, comments, message):
    path = tmp_path / "named.csv"
    path.write_text(comments + "t [s],theta [rad]\n0,0\n1,0\n")
    with pytest.raises(InputError, match=message):
        read_trace(path)


@pytest.mark.parametrize("bad", [5, "", "S1\nS2", ["S1"]])
def test_trace_specimen_is_one_line_of_text(bad):
    with pytest.raises(InputError, match=r"`specimen` = .*give the specimen's name"):
        Trace(time=[0, 1], channels={"theta": [0, 1]}, units={"theta": "rad"}, specimen=bad)


# ---------------------------------------------------------------------------- writing traces
def test_written_trace_reads_back(tmp_path):
    from multimass.inputs import traces

    rng = np.random.default_rng(7)
    t = np.sort(rng.uniform(0.0, 2.0, 50))
    tr = Trace(
        time=t * 1e3,
        channels={"theta": rng.normal(0, 5, 50), "a_A2": rng.normal(0, 1, 50), "ag": t},
        units={"theta": "deg", "a_A2": "g", "ag": "cm/s2"},
        time_units="ms",
        specimen="S1",
    )
    path = traces.write_trace(tr, tmp_path / "out.csv")
    text = path.read_text()
    assert text.startswith("# specimen: S1\nt [ms],theta [deg],a_A2 [g],ag [cm/s2]\n")
    back = read_trace(path)
    assert back.specimen == "S1" and dict(back.units) == dict(tr.units) and back.time_units == "ms"
    np.testing.assert_allclose(back.time, tr.time, rtol=1e-9)
    for name in tr.names:
        np.testing.assert_allclose(back.channels[name], tr.channels[name], rtol=1e-9)
    # what was read once writes the same text again, and parse_trace reads what read_trace reads
    assert traces.format_trace(back) == text
    same = traces.parse_trace(text, source="text")
    for name in tr.names:
        np.testing.assert_array_equal(same.channels[name], back.channels[name])
    assert "a_A2" not in traces.format_trace(
        Trace(time=[0, 1], channels={"theta": [0, 1]}, units={"theta": "rad"})
    )


def test_writing_and_parsing_arguments(tmp_path):
    from multimass.inputs import traces

    tr = Trace(time=[0, 1], channels={"theta": [0, 1]}, units={"theta": "rad"})
    with pytest.raises(InputError, match=r"`path` = .*out.txt': give a file name ending in .csv"):
        traces.write_trace(tr, tmp_path / "out.txt")
    with pytest.raises(InputError, match=r"the folder .*no_such.* does not exist"):
        traces.write_trace(tr, tmp_path / "no_such" / "out.csv")
    with pytest.raises(InputError, match=r"`digits` = 0: must be in 1..17"):
        traces.format_trace(tr, digits=0)
    with pytest.raises(InputError, match=r"`trace` = 'x': give a Trace"):
        traces.format_trace("x")
    with pytest.raises(InputError, match=r"`text` = 3: give the text of a trace CSV file"):
        traces.parse_trace(3)
    with pytest.raises(InputError, match=r"here: empty text; expected a header"):
        traces.parse_trace("# specimen: S1\n", source="here")
    with pytest.raises(InputError, match=r"`g` = 0"):
        traces.parse_trace("t [s],theta [rad]\n0,0\n1,0\n", g=0)
