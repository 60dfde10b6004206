"""The `multimass synthetic` command: a synthetic test trace and its sidecar truth file."""

import contextlib
import hashlib
import inspect
import io
import json

import numpy as np
import pytest

import multimass
from multimass.cli import build_parser, main
from multimass.cli.synthetic_cmd import DEFAULTS
from multimass.identify import read_truth, synthetic_trace, truth_path
from multimass.inputs.traces import read_trace

# paper 001 Section 4.3: S1 released from 0.11 rad, DD2; 1 s instead of 10 (two impacts)
RELEASE = ["S1", "--release", "0.11", "--impact", "DD2", "--noise", "0.02", "--seed", "1"]


def _run(argv) -> tuple[int, str]:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = main(argv)
    return code, out.getvalue()


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """(trace file, --json summary) of one run."""
    path = tmp_path_factory.mktemp("synthetic") / "s1_dd2.csv"
    code, text = _run(["synthetic", *RELEASE, "--duration", "1", "--out", str(path), "--json"])
    assert code == 0
    return path, json.loads(text)


def test_trace_reads_back_with_its_specimen_and_nothing_of_the_truth(written):
    path, info = written
    trace = read_trace(path)
    assert trace.specimen == "S1"
    assert trace.names == ("theta", "a_A1", "a_A2", "a_A3", "a_A4")  # S1's named sensors
    assert dict(trace.units) == {"theta": "rad", **{f"a_A{k}": "g" for k in range(1, 5)}}
    assert np.allclose(np.diff(trace.time), 1.0 / 200.0, rtol=0, atol=1e-12)  # 200 Hz
    assert trace.time[0] == 0.0 and trace.time.size == info["n_samples"]
    text = path.read_text()
    assert [ln for ln in text.splitlines() if ln.startswith("#")] == ["# specimen: S1"]
    for word in ("truth", "seed", "restitution", "impact", "noise", "bias", "offset", "DD2"):
        assert word not in text.lower()


def test_truth_file_is_what_read_truth_reads(written):
    path, info = written
    side = truth_path(path)
    assert info["trace_file"] == str(path) and info["truth_file"] == str(side)
    truth = read_truth(path)
    assert truth == read_truth(side) == json.loads(side.read_text())
    assert truth["trace_file"] == path.name
    assert truth["trace_sha256"] == hashlib.sha256(path.read_bytes()).hexdigest()
    assert truth["specimen"] == info["specimen"] == "S1" and truth["seed"] == info["seed"] == 1
    assert truth["impact"]["name"] == info["impact"] == "DD2"
    assert truth["excitation"]["kind"] == "free_release"
    assert truth["excitation"]["theta0"] == 0.11
    assert truth["noise"]["fraction_of_peak"] == info["noise"] == 0.02
    assert truth["sampling"]["fs_hz"] == info["fs_hz"] == 200.0
    assert info["n_impacts"] == len(truth["impacts"]) == 2
    assert info["peak_theta_rad"] == pytest.approx(truth["peak"]["theta"], rel=1e-12)
    assert info["peak_theta_rad"] == pytest.approx(0.11, rel=1e-3)  # the release angle
    assert info["status"] == "completed" and info["warnings"] == []


def test_the_file_is_the_python_functions(written, tmp_path):
    # the command is a thin layer: the same arguments give the same bytes
    path, _ = written
    syn = synthetic_trace("S1", multimass.FreeRelease(0.11), "DD2", 1.0, seed=1, noise=0.02)
    api, _ = syn.write(tmp_path / "api.csv")
    assert api.read_bytes() == path.read_bytes()


def test_compare_takes_the_specimen_from_the_written_trace(written, capsys):
    # the loop the command is for: a trace with a known truth, then `multimass compare`
    path, info = written
    assert main(["compare", str(path), "--t-offset", str(info["t_offset"]), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["specimen"] == "S1"
    # not exact: the restitution drawn per impact is not DD2's, and the trace is noisy
    assert data["models"]["DD2"]["metrics"]["theta"]["nrmse"] < 0.15


def test_same_seed_same_file_and_text_summary(tmp_path):
    files = {name: tmp_path / f"{name}.csv" for name in ("a", "b", "c")}
    code, text = _run(["synthetic", *RELEASE, "--duration", "0.5", "--out", str(files["a"])])
    assert code == 0
    lines = text.splitlines()
    assert lines[0].startswith(f"wrote the trace {files['a']} (") and "200 Hz" in lines[0]
    assert lines[1].startswith(f"wrote its truth {tmp_path / 'a.truth.json'}")
    assert "impact" in lines[2] and "peak |θ| = 0.11" in lines[2] and "seed 1" in lines[2]
    assert _run(["synthetic", *RELEASE, "--duration", "0.5", "--out", str(files["b"])])[0] == 0
    assert files["a"].read_bytes() == files["b"].read_bytes()
    a, b = (read_truth(files[k]) for k in "ab")
    assert a.pop("trace_file") == "a.csv" and b.pop("trace_file") == "b.csv"
    assert a == b  # the same truth, the same trace_sha256
    seed2 = [*RELEASE[:-1], "2"]
    assert _run(["synthetic", *seed2, "--duration", "0.5", "--out", str(files["c"])])[0] == 0
    assert files["c"].read_bytes() != files["a"].read_bytes()


def test_refuses_to_overwrite_without_force(written, tmp_path, capsys):
    path, _ = written
    before = path.read_bytes()
    assert main(["synthetic", *RELEASE, "--duration", "0.5", "--out", str(path)]) == 2
    err = capsys.readouterr().err
    assert "exists" in err and "--force" in err and err.count("\n") == 1
    assert path.read_bytes() == before
    # the truth file alone is protected too
    lone = tmp_path / "lone.csv"
    truth_path(lone).write_text("{}")
    assert main(["synthetic", *RELEASE, "--duration", "0.5", "--out", str(lone)]) == 2
    assert "lone.truth.json' exists" in capsys.readouterr().err and not lone.exists()
    argv = ["synthetic", *RELEASE, "--duration", "0.5", "--out", str(lone), "--force", "--json"]
    assert main(argv) == 0
    assert read_truth(lone)["t_end"] == 0.5 and read_trace(lone).specimen == "S1"


def test_table_motion_is_recorded_as_ag(tmp_path, capsys):
    # paper 001 Section 4.4: S1 under a cosine pulse, ω = 15 rad/s, 0.4 g
    path = tmp_path / "pulse.csv"
    argv = ["synthetic", "S1", "--pulse", "cosine", "--omega", "15", "--amp", "0.4g"]
    argv += ["--seed", "3", "--duration", "0.5", "--sensors", "A2,5", "--out", str(path)]
    assert main([*argv, "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    trace = read_trace(path)
    assert trace.names == ("theta", "a_A2", "a5", "ag") and trace.ag is not None
    assert trace.units["ag"] == "g" and info["channels"] == dict(trace.units)
    assert read_truth(path)["excitation"]["kind"] == "cosine_pulse"


def test_defaults_are_the_functions():
    sig = inspect.signature(synthetic_trace).parameters
    assert {k: sig[k].default for k in DEFAULTS} == DEFAULTS
    args = build_parser().parse_args(["synthetic", "S1", "--seed", "0", "--out", "x.csv"])
    assert {k: getattr(args, k) for k in DEFAULTS} == DEFAULTS


BASE = ["S1", "--release", "0.11", "--duration", "1", "--seed", "1"]


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["S1", "--duration", "1", "--seed", "1"], "give exactly one excitation"),
        ([*BASE, "--pulse", "sine"], "(got --release, --pulse)"),
        (["S1", "--release", "0.11"], "the following arguments are required: --seed"),
        ([*BASE, "--seed", "-1"], "argument --seed: must be a whole number ≥ 0, got '-1'"),
        ([*BASE, "--noise", "2"], "argument --noise: must be a number in [0, 1], got '2'"),
        ([*BASE, "--duration", "0"], "argument --duration/--t-end: must be a finite number > 0"),
        ([*BASE, "--sigma-r", "0.7"], "argument --sigma-r: must be a number in [0, 0.5]"),
        ([*BASE, "--passband", "0.5"], "argument --passband: must be a number in [0.1, 0.45]"),
        ([*BASE, "--oversample", "2.5"], "argument --oversample: must be a whole number"),
        ([*BASE, "--impact", "LCP"], "`--impact` = 'LCP' draws no coefficient of restitution"),
        ([*BASE, "--impact", "XYZ"], "`--impact` = 'XYZ': unknown impact model"),
        ([*BASE, "--impact", "CIM", "--cp", "100"], "`--cp` = 100.0: applies to the Dirac"),
        ([*BASE, "--r-means", "0.9"], "`--r-means` = '0.9': give the corner means"),
        ([*BASE, "--r-means", "1.2,0.9"], "two numbers in (0, 1]"),
        ([*BASE, "--sensors", "A9"], "`--sensors`: 'S1' has no sensor 'A9'"),
        ([*BASE, "--sensors", "A1;A2"], "`--sensors` = 'A1;A2': give a comma-separated list"),
        ([*BASE, "--t-offset", "5"], "`--t-offset` = 5.0: must lie in"),
        ([*BASE, "--oversample", "4"], "raise --oversample to at least"),
        (
            ["B6M", "--release", "0.1", "--seed", "1"],
            "has no corner means of restitution; give --r-means",
        ),
        (["S9", "--release", "0.1", "--seed", "1"], "specimen 'S9'"),
    ],
)
def test_bad_arguments_exit_2_with_one_line(argv, fragment, tmp_path, capsys):
    out = tmp_path / "t.csv"
    assert main(["synthetic", *argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert fragment in err and err.count("\n") == 1 and "Traceback" not in err
    assert not out.exists() and not truth_path(out).exists()


@pytest.mark.parametrize(
    "name, fragment",
    [
        ("t.txt", "give a file name ending in .csv"),
        ("folder.csv", "is a folder"),
        ("file.txt/t.csv", "file.txt' is a file, not a folder"),
    ],
)
def test_bad_output_paths(name, fragment, tmp_path, capsys):
    (tmp_path / "folder.csv").mkdir()
    (tmp_path / "file.txt").write_text("")
    assert main(["synthetic", *BASE, "--out", str(tmp_path / name)]) == 2
    err = capsys.readouterr().err
    assert "`--out`" in err and fragment in err and err.count("\n") == 1
