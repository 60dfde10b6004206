"""Recorded ground motions: readers, interpolation, validation (multimass.inputs.records)."""

import json
import pickle

import numpy as np
import pytest

from multimass import InputError, Record, read_at2, read_record, read_two_column

G = 9.81  # DESIGN.md: g = 9.81 m/s²


# ---------------------------------------------------------------------------- real records
def test_el_centro_two_column_in_g(ground_motions):
    rec = read_two_column(ground_motions / "elcentro_1940_NS.dat", units="g")
    # ground_motions/README.md: 2688 points, dt 0.02 s, 0–53.74 s, peaks +0.3487 / −0.2682 g
    assert rec.npts == 2688
    assert rec.dt == pytest.approx(0.02, rel=1e-9)
    assert rec.time[0] == 0.0 and rec.duration == pytest.approx(53.74, rel=1e-12)
    assert rec.accel.max() / G == pytest.approx(0.3487, abs=5e-5)
    assert rec.accel.min() / G == pytest.approx(-0.2682, abs=5e-5)
    assert rec.units == "g" and rec.scale == 1.0 and rec.name == "elcentro_1940_NS"
    # file's first row: 0.0000000e+000 -1.4275799e-003 (in g)
    assert rec(0.0) == pytest.approx(-1.4275799e-3 * G, rel=1e-12)


def test_el_centro_scaled_like_the_paper(ground_motions):
    # paper 001, Section 4.4: El Centro scaled by A_sc = 1.1
    base = read_record(ground_motions / "elcentro_1940_NS.dat", units="g")
    scaled = read_record(ground_motions / "elcentro_1940_NS.dat", units="g", scale=1.1)
    np.testing.assert_allclose(scaled.accel, 1.1 * base.accel, rtol=1e-15)
    assert scaled.scale == 1.1
    assert scaled.accel.max() / G == pytest.approx(1.1 * 0.3487, abs=1e-4)  # README peak × 1.1


def test_at2_file(ground_motions):
    rec = read_record(ground_motions / "RSN1044_DirRot2.AT2")
    # ground_motions/README.md: NPTS = 2000, DT = 0.020 s, units g
    assert rec.npts == 2000
    assert rec.dt == pytest.approx(0.02, rel=1e-12)
    assert rec.units == "g"
    assert rec.duration == pytest.approx(1999 * 0.02, rel=1e-12)
    # the file's first two values: -1.65951E-03 -3.40541E-03 (g), at t = 0 and t = DT
    assert rec(0.0) == pytest.approx(-1.65951e-3 * G, rel=1e-12)
    assert rec(0.02) == pytest.approx(-3.40541e-3 * G, rel=1e-9)
    assert read_at2(ground_motions / "RSN1044_DirRot2.AT2", scale=2.0).accel[1] == pytest.approx(
        2 * -3.40541e-3 * G, rel=1e-12
    )


def test_at2_units_argument_must_agree_with_header(ground_motions):
    path = ground_motions / "RSN1044_DirRot2.AT2"
    assert read_record(path, units="G").npts == 2000
    with pytest.raises(InputError, match=r"`units` = 'm/s2'.*header says 'g'"):
        read_record(path, units="m/s2")


@pytest.mark.parametrize(
    "name, npts, peak_pos, peak_neg",
    [
        ("kobe_1995", 1250, 3.53, -6.80),  # ground_motions/README.md
        ("northridge_1994", 1500, 8.48, -9.71),  # ground_motions/README.md
        ("loma_prieta_1989", 1300, 4.80, -5.32),  # ground_motions/README.md
    ],
)
def test_two_column_records_in_mps2(ground_motions, name, npts, peak_pos, peak_neg):
    rec = read_record(ground_motions / f"{name}.dat", units="m/s2")
    assert rec.npts == npts
    assert rec.dt == pytest.approx(0.02, rel=1e-9)
    assert rec.accel.max() == pytest.approx(peak_pos, abs=0.005)
    assert rec.accel.min() == pytest.approx(peak_neg, abs=0.005)
    assert rec.pga == pytest.approx(-peak_neg, abs=0.005)


def test_kobe_in_mps2_read_as_g_is_named_with_the_slip(ground_motions):
    """Kobe's values are m/s² (ground_motions/README.md: −6.80 at its peak); read as g
    they peak at 6.8 g, beyond any recorded earthquake (about 4 g), and 6.80 / 9.81 =
    0.693 g is what m/s² gives: the error names the sample, the peak, the slip and the fix,
    from every reader and from arrays."""
    path = ground_motions / "kobe_1995.dat"
    expect = (
        r"kobe_1995.dat, sample \d+.*`units` = '[gG]': peak 6.8\d* [gG].*"
        r"m/s2 read as g \(peak 0.693 g\).*--units m/s2"
    )
    for read in (
        lambda: read_record(path, units="g"),
        lambda: read_two_column(path, units="G"),
        lambda: Record.from_arrays(*np.loadtxt(path).T, units="g", source=str(path)),
    ):
        with pytest.raises(InputError, match=expect):
            read()


@pytest.mark.parametrize(
    "units, scale, slip",
    [
        ("m/s2", 1.0, r"cm/s2 read as m/s2 \(peak 0.693 g\)"),  # Kobe in gal: 680 "m/s²"
        ("g", 1.0, r"cm/s2 read as g \(peak 0.693 g\)"),  # 680 "g"
        ("g", 1e-3, r"cm/s2 read as g"),  # the check is on the values as written, not scaled
    ],
)
def test_a_peak_beyond_any_earthquake_is_refused(tmp_path, units, scale, slip):
    """Kobe's peak 6.80 m/s² written in cm/s² (×100, 680): read as m/s² it is 69 g, as g
    680 g; the peak is judged before `scale`."""
    t = np.arange(0.0, 1.0, 0.01)
    a = 680.0 * np.sin(2 * np.pi * t)
    with pytest.raises(InputError, match=f"{slip}.*synthetic input.*--scale"):
        Record.from_arrays(t, a, units=units, scale=scale)


def test_a_peak_below_any_motion_is_refused_and_names_both_likely_units(ground_motions):
    """El Centro's values are in g (peak 0.3487, README); read as mm/s² they are 3.6e-5 g,
    below 1e-4 g; in m/s² (0.0355 g) or g (0.349 g) they are plausible: both are named."""
    with pytest.raises(
        InputError, match=r"below 0.0001 g.*m/s2 read as mm/s2.*or g read as mm/s2 \(peak 0.349 g\)"
    ):
        read_record(ground_motions / "elcentro_1940_NS.dat", units="mm/s2")


def test_a_large_synthetic_peak_passes_through_scale():
    """A 10 g input written at 1 g and scaled by 10: the scale is the user's statement."""
    t = np.arange(0.0, 1.0, 0.01)
    rec = Record.from_arrays(t, np.sin(2 * np.pi * t), units="g", scale=10.0)
    assert rec.pga == pytest.approx(10.0 * G * np.abs(np.sin(2 * np.pi * t)).max(), rel=1e-12)
    assert rec.scaled(100.0).pga == pytest.approx(100.0 * rec.pga, rel=1e-12)
    zero = Record.from_arrays(t, np.zeros_like(t), units="g")  # no motion: not a unit slip
    assert zero.pga == 0.0


def test_cli_names_the_unit_slip_in_one_line(ground_motions, capsys):
    from multimass.cli import main

    argv = ["simulate", "S1", "--record", str(ground_motions / "kobe_1995.dat"), "--units", "g"]
    assert main(argv + ["--t-end", "1"]) == 2
    err = capsys.readouterr().err
    assert "m/s2 read as g" in err and "Traceback" not in err and err.count("\n") == 1


def test_two_column_needs_units(ground_motions):
    with pytest.raises(InputError, match=r"kobe_1995.dat.*`units` is missing.*never guessed"):
        read_record(ground_motions / "kobe_1995.dat")


def test_real_record_pickles_and_describes(ground_motions):
    rec = read_record(ground_motions / "elcentro_1940_NS.dat", units="g", scale=1.1)
    back = pickle.loads(pickle.dumps(rec))
    assert back == rec and hash(back) == hash(rec)
    assert back(12.345) == rec(12.345)
    d = rec.describe()
    assert json.loads(json.dumps(d)) == d
    assert d["kind"] == "record" and d["npts"] == 2688 and d["scale"] == 1.1


# ---------------------------------------------------------------------------- interpolation
def _rec():
    # samples at 0.5, 0.6, 0.7, 0.8 s: a = 1, 3, -1, 2 m/s²
    return Record.from_arrays([0.5, 0.6, 0.7, 0.8], [1.0, 3.0, -1.0, 2.0], units="m/s2")


def test_linear_interpolation_and_zero_outside():
    rec = _rec()
    # closed form: linear between samples, 0 before the first and after the last sample
    cases = [
        (0.0, 0.0),
        (0.49, 0.0),
        (0.5, 1.0),
        (0.55, 2.0),
        (0.6, 3.0),
        (0.675, 0.0),
        (0.8, 2.0),
        (0.8000001, 0.0),
        (5.0, 0.0),
        (-1.0, 0.0),
    ]
    for t, a in cases:
        assert rec(t) == pytest.approx(a, abs=1e-12), t
        assert isinstance(rec(t), float)
    ts = np.array([t for t, _ in cases])
    np.testing.assert_allclose(rec(ts), [a for _, a in cases], atol=1e-12)
    assert rec.breakpoints == (0.5, 0.8) and rec.duration == 0.8


def test_scalar_and_array_paths_agree_with_np_interp():
    rng = np.random.default_rng(1)
    time = 0.01 * np.arange(500)
    accel = rng.normal(size=500)
    rec = Record(time, accel)
    ts = rng.uniform(-0.5, 5.5, 2000)
    ref = np.interp(ts, time, accel, left=0.0, right=0.0)  # numpy's linear interpolation
    np.testing.assert_allclose(rec(ts), ref, atol=1e-12)
    np.testing.assert_allclose([rec(float(t)) for t in ts], ref, atol=1e-12)


def test_record_arrays_are_read_only():
    rec = _rec()
    with pytest.raises(ValueError):
        rec.accel[0] = 5.0
    with pytest.raises(AttributeError):
        rec.dt = 0.1


def test_from_arrays_converts_units_and_scales():
    rec = Record.from_arrays([0, 0.01], [100.0, -50.0], units="gal", scale=2.0)
    np.testing.assert_allclose(rec.accel, [2.0, -1.0], rtol=1e-15)  # 100 gal = 1 m/s², × 2
    assert rec.units == "gal" and rec.scale == 2.0


# ---------------------------------------------------------------------------- bad files
def _write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_comments_commas_and_blank_lines(tmp_path):
    path = _write(tmp_path, "ok.csv", "# t (s), a (g)\n\n0.0, 0.1\n0.01,0.2\n  0.02 \t 0.3\n")
    rec = read_two_column(path, units="g", name="mine")
    np.testing.assert_allclose(rec.accel, [0.981, 1.962, 2.943], rtol=1e-14)  # closed form
    assert rec.name == "mine" and rec.dt == pytest.approx(0.01)


@pytest.mark.parametrize(
    "text, match",
    [
        ("0 0\n0.01 x\n", r"bad.txt, line 2: cannot read.*as two numbers"),
        ("time acc\n0 0\n0.01 1\n", r"bad.txt, line 1: cannot read.*comment the line out with #"),
        ("0 0\n0.01 1 2\n", r"bad.txt, line 2: expected two columns `t a`.*found 3"),
        ("0 0\n0.01 nan\n0.02 1\n", r"bad.txt, line 2: acceleration = nan is not a finite"),
        ("0 0\ninf 1\n", r"bad.txt, line 2: time = inf is not a finite"),
        ("0 0\n0.02 1\n0.01 2\n", r"bad.txt, line 3: `time` = 0.01 s does not increase"),
        ("0 0\n0.01 1\n0.01 2\n", r"bad.txt, line 3: `time` = 0.01 s does not increase"),
        ("0 0\n0.01 1\n0.02 2\n0.035 3\n0.045 4\n", r"bad.txt, line 4: non-uniform time step"),
        ("# only one\n0 0\n", r"bad.txt: 1 sample\(s\); a record needs at least 2"),
        ("# comments only\n", r"bad.txt: 0 sample\(s\)"),
        ("-0.01 0\n0 1\n", r"bad.txt, line 1: `time` starts at -0.01 s < 0; shift"),
    ],
)
def test_bad_two_column_files(tmp_path, text, match):
    path = _write(tmp_path, "bad.txt", text)
    with pytest.raises(InputError, match=match):
        read_two_column(path, units="g")


def test_time_step_tolerance_is_relative_1e6(tmp_path):
    # a jitter of 5e-9 s on dt = 0.01 s (5e-7 relative) is accepted; 1e-7 s (1e-5) is not
    ok = _write(tmp_path, "ok.txt", "0 0\n0.01 1\n0.020000005 2\n0.03 3\n0.04 4\n")
    assert read_two_column(ok, units="g").npts == 5
    bad = _write(tmp_path, "bad.txt", "0 0\n0.01 1\n0.0200001 2\n0.03 3\n0.04 4\n")
    with pytest.raises(InputError, match="line 3: non-uniform"):
        read_two_column(bad, units="g")


@pytest.mark.parametrize("units", [None, "", "furlongs", "G-force"])
def test_unknown_units_are_errors(tmp_path, units):
    path = _write(tmp_path, "r.txt", "0 0\n0.01 1\n")
    with pytest.raises(InputError, match=r"r.txt: `units`.*accepted: g, m/s2"):
        read_two_column(path, units=units)


@pytest.mark.parametrize("scale", [0.0, -1.0, float("nan"), float("inf"), "2", True])
def test_bad_scale(tmp_path, scale):
    path = _write(tmp_path, "r.txt", "0 0\n0.01 1\n")
    with pytest.raises(InputError, match=r"r.txt: `scale` = "):
        read_two_column(path, units="g", scale=scale)


AT2_HEAD = (
    "PEER NGA STRONG MOTION DATABASE RECORD\nTEST, COMPONENT\n"
    "ACCELERATION TIME SERIES IN UNITS OF G\n"
)


@pytest.mark.parametrize(
    "line4",
    [
        "NPTS=  7, DT=   0.020 SEC",  # ground_motions/RSN1044_DirRot2.AT2 spelling
        "NPTS= 7 DT= .0200 SEC",  # brief: NGA spelling without comma
        "NPTS=7, DT=0.02 SEC,",
        "npts = 7 , dt = 2.0E-02 sec",
        "    7    0.0200    NPTS, DT",  # the old NGA format
    ],
)
def test_at2_header_spellings(tmp_path, line4):
    body = "1.0E-01 2.0E-01 3.0E-01 4.0E-01 5.0E-01\n-1.0E-01 -2.0E-01\n"
    rec = read_at2(_write(tmp_path, "x.AT2", AT2_HEAD + line4 + "\n" + body))
    assert rec.npts == 7 and rec.dt == pytest.approx(0.02, rel=1e-15)
    np.testing.assert_allclose(rec.accel / G, [0.1, 0.2, 0.3, 0.4, 0.5, -0.1, -0.2], rtol=1e-14)


def test_at2_units_from_header(tmp_path):
    head = AT2_HEAD.replace("UNITS OF G", "UNITS OF CM/S/S")
    rec = read_at2(_write(tmp_path, "x.at2", head + "NPTS= 2, DT= 0.01 SEC\n100.0 -50.0\n"))
    assert rec.units == "cm/s2"
    np.testing.assert_allclose(rec.accel, [1.0, -0.5], rtol=1e-15)  # 100 cm/s² = 1 m/s²


@pytest.mark.parametrize(
    "text, match",
    [
        (AT2_HEAD + "NPTS= 3, DT= 0.02 SEC\n0.1 0.2\n", r"x.AT2: `NPTS` = 3.*but 2 values"),
        (AT2_HEAD + "NPTS= 2, DT= 0.02 SEC\n0.1 0.2 0.3\n", r"`NPTS` = 2.*but 3 values"),
        (AT2_HEAD + "NPTS= 2, DT= 0.02 SEC\n0.1 abc\n", r"x.AT2, line 5: cannot read 'abc'"),
        (AT2_HEAD + "NPTS= 3, DT= 0.02 SEC\n0.1 0.2\nNaN\n", r"x.AT2, line 6: value 'NaN' is not"),
        (AT2_HEAD + "2000 points at 0.02 s\n0.1 0.2\n", r"x.AT2, line 4: cannot read NPTS and DT"),
        (AT2_HEAD + "NPTS= 2, DT= 0.0 SEC\n0.1 0.2\n", r"x.AT2, line 4: `DT` = 0.0"),
        (AT2_HEAD + "NPTS= 1, DT= 0.02 SEC\n0.1\n", r"x.AT2, line 4: `NPTS` = 1"),
        (
            AT2_HEAD.replace("UNITS OF G", "UNITS OF FT/S/S") + "NPTS= 2, DT= 0.02 SEC\n0.1 0.2\n",
            r"x.AT2, line 3: unknown units 'FT/S/S'",
        ),
        (
            AT2_HEAD.replace(" IN UNITS OF G", "") + "NPTS= 2, DT= 0.02 SEC\n0.1 0.2\n",
            r"x.AT2, line 3: cannot find the units",
        ),
        (
            AT2_HEAD.replace("ACCELERATION", "VELOCITY").replace("OF G", "OF CM/S")
            + "NPTS= 2, DT= 0.02 SEC\n0.1 0.2\n",
            r"x.AT2, line 3: .*velocity record",
        ),
        (AT2_HEAD + "NPTS= 2, DT= 0.02 SEC\n", r"x.AT2: 4 line\(s\)"),
    ],
)
def test_bad_at2_files(tmp_path, text, match):
    with pytest.raises(InputError, match=match):
        read_at2(_write(tmp_path, "x.AT2", text))


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"time": [0.0], "accel": [1.0]}, r"1 sample\(s\)"),
        ({"time": [0.0, 0.1], "accel": [1.0]}, r"same length"),
        ({"time": [0.0, 0.1, 0.3], "accel": [1, 2, 3]}, r"sample 2: non-uniform"),
        ({"time": [0.0, 0.1], "accel": [1, 2], "dt": 0.2}, r"`dt` = 0.2 s disagrees"),
        ({"time": [0.0, 0.1], "accel": [1, 2], "scale": -1.0}, r"`scale` = -1.0"),
    ],
)
def test_record_constructor_validates(kwargs, match):
    with pytest.raises(InputError, match=match):
        Record(**kwargs)


def _write_bytes(folder, name, data: bytes):
    path = folder / name
    path.write_bytes(data)
    return path


def test_errors_are_value_errors():
    assert issubclass(InputError, ValueError)


# ---------------------------------------------------------------------------- the file itself
READERS = [
    pytest.param(
        lambda p: read_two_column(p, units="g"), "two columns `t a`", id="read_two_column"
    ),
    pytest.param(lambda p: read_at2(p), "PEER .AT2", id="read_at2"),
    pytest.param(lambda p: read_record(p, units="g"), "two columns `t a`", id="read_record"),
]


@pytest.mark.parametrize("read, kind", READERS)
@pytest.mark.parametrize(
    "make, problem",
    [
        (lambda d: d / "missing.txt", "no such file"),
        (lambda d: d, "is a directory"),
        (lambda d: _write(d, "empty.txt", ""), "the file is empty"),
        (lambda d: _write(d, "blank.txt", "\n  \n"), "the file is empty"),
        (
            lambda d: _write_bytes(d, "bin.txt", bytes(range(256))),
            r"a binary file \(NUL byte at offset 0\)",
        ),
        (
            lambda d: _write_bytes(d, "latin.txt", "0 0\n# Málaga\n".encode("latin-1")),
            r"not UTF-8 text \(byte 0xe1 on line 2\); save it as UTF-8",
        ),
    ],
    ids=["missing", "directory", "empty", "blank", "binary", "latin-1"],
)
def test_a_bad_file_is_named_with_what_to_give(tmp_path, read, kind, make, problem):
    path = make(tmp_path)
    with pytest.raises(InputError, match=problem) as info:
        read(path)
    assert str(path) in str(info.value) and kind in str(info.value)


def test_a_directory_lists_its_record_files(tmp_path):
    _write(tmp_path, "elcentro.AT2", "x")
    _write(tmp_path, "notes.md", "x")
    with pytest.raises(InputError, match=r"files there: elcentro.AT2\)"):
        read_two_column(tmp_path, units="g")


@pytest.mark.parametrize("path", [None, 123, b"r.txt", "", "   ", "r\0.txt"])
def test_path_must_be_a_path(path):
    with pytest.raises(InputError, match="`path` = "):
        read_record(path, units="g")


def test_utf8_with_byte_order_mark_reads(tmp_path):
    # Excel's "CSV UTF-8" starts with a byte-order mark; it is not part of the first number
    path = _write_bytes(tmp_path, "bom.txt", "\ufeff0 1\n0.01 2\n".encode("utf-8"))
    assert read_two_column(path, units="m/s2").accel.tolist() == [1.0, 2.0]


def test_name_must_be_a_string(tmp_path):
    path = _write(tmp_path, "r.txt", "0 0\n0.01 1\n")
    with pytest.raises(InputError, match="`name` = 5"):
        read_two_column(path, units="g", name=5)


@pytest.mark.parametrize(
    "time, accel, match",
    [
        (["0", "0.01"], [1.0, 2.0], r"`time` holds 'str"),  # no silent '10' -> 10.0
        ([0.0, 0.01], [True, False], r"`accel` holds 'bool'"),
        ([0.0, 0.01], [1.0, None], r"`accel` holds 'object'"),
        ([0.0, 0.01], "12", r"`accel` = '12': expected an array of numbers"),
        ([[0.0, 0.01], [0.02]], [1.0, 2.0], r"`time` is not a rectangular array"),
    ],
)
def test_arrays_hold_numbers_only(time, accel, match):
    with pytest.raises(InputError, match=match):
        Record.from_arrays(time, accel, units="m/s2")
    with pytest.raises(InputError, match=match):
        Record(time=time, accel=accel)
