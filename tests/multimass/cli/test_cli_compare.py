"""The `multimass compare` command: simulations overlaid on a recorded trace."""

import argparse
import json
import math

import numpy as np
import pytest

import multimass
from multimass.cli import main
from multimass.cli.compare_cmd import model_specs

G = 9.81  # DESIGN.md: g = 9.81 m/s²
DT = 1e-3  # simulate's default output_dt (s)
T_END = 0.6  # s: one impact of S1 released from 0.05 rad (around 0.2 s), kept short


def write_trace(path, resp, t_shift=0.0):
    """θ (rad), a_A2 (g) and a_A4 (m/s²) of a simulation, on its output grid, as a trace.

    θ is written in rad so that the release angle read back is bit-identical and the
    re-simulation repeats the original one exactly (a deg round trip changes θ0 by an
    ulp, and the re-simulation then agrees only to the solver's tolerance).
    """
    df = resp.series
    df = df[np.abs(df.t / DT - np.round(df.t / DT)) < 1e-6]
    df = df[~df.t.round(9).duplicated(keep="last")]
    rows = np.column_stack([df.t + t_shift, df.theta, df.a3 / G, df.a5])
    path.write_text(
        "t [s],theta [rad],a_A2 [g],a_A4 [m/s2]\n"
        + "\n".join(",".join(f"{x:.17g}" for x in row) for row in rows)
        + "\n"
    )
    return path


@pytest.fixture(scope="module")
def dd2_release():
    # paper 001 Section 4.3: a free release of S1 simulated with DD2 (Table 2)
    return multimass.simulate("S1", multimass.FreeRelease(0.05), impact="DD2", t_end=T_END)


@pytest.fixture()
def trace_file(tmp_path, dd2_release):
    return write_trace(tmp_path / "free_test.csv", dd2_release)


def test_two_models_overlaid_files_and_json(tmp_path, trace_file, capsys):
    out = tmp_path / "report"
    assert (
        main(["compare", "S1", str(trace_file), "--impact", "CIM,DD2", "--out", str(out), "--json"])
        == 0
    )
    data = json.loads(capsys.readouterr().out)
    assert set(data) == {"specimen", "trace", "excitation", "t_offset", "t_end", "models", "files"}
    assert data["specimen"] == "S1" and data["t_offset"] == 0.0
    assert data["t_end"] == pytest.approx(T_END, abs=1e-12)
    # no excitation flag: a free release from the trace's first θ
    assert data["excitation"]["kind"] == "free_release" and data["excitation"]["theta0"] == 0.05
    assert data["trace"]["channels"]["a_A2"] == {"units": "g", "si_units": "m/s2", "column": "a3"}
    assert list(data["models"]) == ["CIM", "DD2"]
    for label, model in data["models"].items():
        assert model["impact"] == label
        assert {"status", "n_impacts", "wall_time_s"} <= set(model["summary"])
        assert model["summary"]["status"] == "completed"
        assert list(model["metrics"]) == ["theta", "a_A2", "a_A4"]
        for m in model["metrics"].values():
            assert {
                "rms_error",
                "nrmse",
                "peak_error",
                "peak_error_rel",
                "peak_time_shift_s",
                "units",
                "n_samples",
            } <= set(m)
    dd2, cim = data["models"]["DD2"]["metrics"], data["models"]["CIM"]["metrics"]
    # the trace is the DD2 simulation itself: DD2 reproduces it, CIM does not
    for ch in ("theta", "a_A2", "a_A4"):
        assert dd2[ch]["nrmse"] < 1e-6
        assert cim[ch]["nrmse"] > 1e3 * dd2[ch]["nrmse"]
    names = sorted(p.name for p in out.iterdir())
    assert names == sorted(
        [
            "S1_free_test_theta.png",
            "S1_free_test_a_A2.png",
            "S1_free_test_a_A4.png",
            "S1_free_test_metrics.csv",
            "S1_free_test_metrics.md",
            "S1_free_test_compare.json",
        ]
    )
    assert sorted(data["files"]) == sorted(str(out / n) for n in names)
    saved = json.loads((out / "S1_free_test_compare.json").read_text())
    assert saved["models"]["CIM"]["metrics"] == data["models"]["CIM"]["metrics"]
    table = (out / "S1_free_test_metrics.md").read_text()
    assert "## a_A2 (written in g; metrics in m/s2)" in table and "| CIM |" in table
    csv = (out / "S1_free_test_metrics.csv").read_text().splitlines()
    assert len(csv) == 1 + 2 * 3 and csv[0].startswith("model,status,channel,")


def test_trace_starting_later_is_aligned_on_its_first_sample(tmp_path, dd2_release, capsys):
    trace = write_trace(tmp_path / "late.csv", dd2_release, t_shift=2.0)
    assert main(["compare", "S1", str(trace), "--json"]) == 0  # default model: DD2
    data = json.loads(capsys.readouterr().out)
    assert data["t_offset"] == 2.0 and data["t_end"] == pytest.approx(T_END, abs=1e-9)
    assert data["files"] == []  # --json without --out
    for m in data["models"]["DD2"]["metrics"].values():
        assert m["nrmse"] < 1e-6 and m["peak_time_shift_s"] == 0.0
        assert m["t_start"] == 2.0


def test_forced_test_with_a_pulse(tmp_path, capsys):
    # paper 001 Section 4.4 / Fig 9: S1, cosine pulse ω = 15 rad/s, A = 0.4 g, DD2
    resp = multimass.simulate(
        "S1", multimass.CosinePulse(omega=15.0, amplitude=0.4 * G), impact="DD2", t_end=0.5
    )
    trace = write_trace(tmp_path / "pulse.csv", resp)
    assert (
        main(
            [
                "compare",
                "S1",
                str(trace),
                "--pulse",
                "cosine",
                "--omega",
                "15",
                "--amp",
                "0.4g",
                "--json",
            ]
        )
        == 0
    )
    data = json.loads(capsys.readouterr().out)
    assert data["excitation"]["kind"] == "cosine_pulse" and data["t_offset"] == 0.0
    assert all(m["nrmse"] < 1e-6 for m in data["models"]["DD2"]["metrics"].values())


def test_text_output(tmp_path, trace_file, capsys):
    assert main(["compare", "S1", str(trace_file), "--out", str(tmp_path / "o")]) == 0
    text = capsys.readouterr().out
    assert text.startswith("DD2: completed") and "a_A4" in text and "files written to" in text


def _ns(impact, **kw):
    base = dict(restitution=None, k=None, cp=None, seed=None)
    base.update(kw)
    return argparse.Namespace(impact=impact, **base)


def test_model_specs_repeated_comma_and_overrides():
    specs = model_specs(_ns(["CIM,DD2", "DD2:cp=3000", "DD2"], cp=1000.0))
    assert list(specs) == ["CIM", "DD2", "DD2:cp=3000"]
    assert specs["DD2"]["C_p"] == 1000.0 and specs["DD2:cp=3000"]["C_p"] == 3000.0
    assert model_specs(_ns(["CIM:r=0.9:seed=3"]))["CIM:r=0.9:seed=3"] == dict(
        impact="CIM", restitution="0.9", k=None, C_p=None, seed=3
    )
    assert list(model_specs(_ns(None))) == ["DD2"]


@pytest.mark.parametrize(
    "extra, header, fragment",
    [
        (["--impact", "XYZ"], None, "unknown impact model"),
        (["--impact", "DD2:foo=1"], None, "cannot read option 'foo=1'"),
        (["--impact", "DD2:cp=abc"], None, "cp must be a finite number > 0, got 'abc'"),
        # the same mistake gets the same words whether it is written as a model option or a flag
        (["--impact", "DD2:cp=-1"], None, "cp must be a finite number > 0, got '-1'"),
        (["--cp", "-1"], None, "argument --cp: must be a finite number > 0, got '-1'"),
        (["--impact", ","], None, "`--impact` is empty"),
        ([], "t [s],a_A9 [g]", "column `a_A9`"),
        ([], "t [s],a_A2 [g]", "no `theta` column"),
        ([], "t [s],theta", "column `theta` has no unit"),
        (["--t-end", "-1"], None, "argument --t-end: must be a finite number > 0, got '-1'"),
    ],
)
def test_bad_input_exits_2_with_one_line(tmp_path, trace_file, extra, header, fragment, capsys):
    path = trace_file
    if header is not None:
        path = tmp_path / "bad.csv"
        path.write_text(header + "\n0,0.01\n0.1,0\n")
    assert main(["compare", "S1", str(path), "--json", *extra]) == 2
    err = capsys.readouterr().err
    assert fragment in err and err.count("\n") == 1


def test_block_only_theta(tmp_path, capsys):
    path = tmp_path / "block.csv"
    path.write_text("t [s],theta [deg],a_A2 [g]\n0,1,0\n0.1,0,0\n")
    assert main(["compare", "B6M", str(path), "--json"]) == 2
    assert "only `theta` can be compared" in capsys.readouterr().err
    path.write_text("t [s],theta [deg]\n0,1\n0.05,0.9\n0.1,0.7\n")
    assert main(["compare", "B6M", str(path), "--impact", "CIM", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["excitation"]["theta0"] == pytest.approx(math.radians(1.0), rel=1e-15)
    assert set(data["models"]["CIM"]["metrics"]) == {"theta"}


# --- the specimen from the trace's `# specimen:` line ---------------------------------------


def _named(path, name):
    path.write_text(f"# specimen: {name}\n" + path.read_text())
    return path


@pytest.mark.parametrize(
    "argv",
    [
        ["{trace}"],
        ["{trace}", "--specimen", "S1"],
        ["S1", "{trace}"],
        # options between SPECIMEN and TRACE.csv, as before SPECIMEN became optional
        ["S1", "--impact", "DD2", "{trace}"],
        ["s1", "{trace}", "--specimen", "S1"],  # the same specimen twice
    ],
)
def test_specimen_from_the_trace_or_given(argv, trace_file, capsys):
    trace = _named(trace_file, "S1")
    assert main(["compare", *(a.format(trace=trace) for a in argv), "--json"]) == 0
    out, err = capsys.readouterr()
    data = json.loads(out)
    assert data["specimen"] == "S1" and err == ""
    assert all(m["nrmse"] < 1e-6 for m in data["models"]["DD2"]["metrics"].values())


def test_trace_without_specimen_line_and_none_given(trace_file, capsys):
    assert main(["compare", str(trace_file), "--json"]) == 2
    err = capsys.readouterr().err
    assert "has no `# specimen: NAME` line" in err and err.count("\n") == 1
    assert "multimass compare SPECIMEN" in err and "--specimen NAME" in err


def test_specimen_given_twice_differently(trace_file, capsys):
    assert main(["compare", "S1", str(trace_file), "--specimen", "S2", "--json"]) == 2
    err = capsys.readouterr().err
    assert "SPECIMEN = 'S1' and `--specimen` = 'S2'" in err and err.count("\n") == 1


def test_specimen_given_wins_over_the_trace_with_a_warning(trace_file, capsys):
    # e.g. the trace of S1 against the specimen file `multimass restitution` fitted to it
    trace = _named(trace_file, "S2")
    assert main(["compare", "S1", str(trace), "--json"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["specimen"] == "S1"
    assert err.startswith("multimass compare: warning:") and "`# specimen: S2`" in err
    assert "comparing with S1 as given" in err


def test_specimen_alone_is_not_taken_for_a_trace(capsys):
    assert main(["compare", "S1", "--json"]) == 2
    err = capsys.readouterr().err
    assert "give the trace after it: `multimass compare S1 TRACE.csv`" in err


def test_specimen_the_trace_names_is_unknown(trace_file, capsys):
    trace = _named(trace_file, "MyColumn")
    assert main(["compare", str(trace), "--json"]) == 2
    err = capsys.readouterr().err
    assert "names its specimen `# specimen: MyColumn`" in err and "--specimen FILE" in err
    assert err.count("\n") == 1
