"""The `multimass calibrate` command: restitution means and C_p fitted to recorded traces."""

import json

import numpy as np
import pytest

import multimass
from multimass import FreeRelease
from multimass.cli import main
from multimass.cli.calibrate_cmd import parse_pairs
from multimass.errors import InputError
from multimass.identify import synthetic_trace

# paper 001 Section 4.3: S1 released from 0.11 rad (kept to 2.6 s: five impacts), DD2
THETA0, T_END = 0.11, 2.6


@pytest.fixture(scope="module")
def syn():
    return synthetic_trace("S1", FreeRelease(theta0=THETA0), "DD2", T_END, seed=11)


@pytest.fixture(scope="module")
def trace_file(syn, tmp_path_factory):
    path, _ = syn.write(tmp_path_factory.mktemp("traces") / "free_011.csv")
    return path


@pytest.fixture(scope="module")
def json_run(trace_file, tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    argv = ["calibrate", str(trace_file), "--fit", "r_er,r_el", "--out", str(out), "--json",
            "--quiet"]  # fmt: skip
    return argv, out


def test_json_parameters_status_and_files(json_run, syn, capsys):
    argv, out = json_run
    assert main(argv) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["specimen"] == "S1"  # from the trace's `# specimen:` line
    assert data["impact"] == "DD2" and data["status"] == "converged"
    assert set(data["parameters"]) == {"r_er", "r_el"}
    for name, corner in (("r_er", "right"), ("r_el", "left")):
        p = data["parameters"][name]
        assert {"value", "std"} <= set(p) and p["std"] > 0.0
        assert abs(p["value"] - syn.truth["restitution"]["means"][corner]) < 3.0 * p["std"]
    nu = data["nuisance"]["free_011"]
    assert nu["t_offset"] == pytest.approx(syn.truth["t_offset"], abs=2e-3)
    files = {p.split("/")[-1] for p in data["files"]}
    assert {"calibration.md", "calibration.json", "S1_calibrated.toml",
            "free_011_theta.png", "free_011_a_A2.png", "free_011_residuals.png"} <= files  # fmt: skip
    spec = multimass.specimens.load(out / "S1_calibrated.toml")
    assert spec.r_right == pytest.approx(data["parameters"]["r_er"]["value"], abs=1e-6)


def test_text_output(trace_file, tmp_path, capsys):
    argv = ["calibrate", str(trace_file), "--specimen", "S1", "--fit", "r_er,r_el", "--out",
            str(tmp_path), "--no-figures", "--quiet"]  # fmt: skip
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "S1 (DD2): converged" in text and "r_er" in text and "t_offset" in text
    assert "files written to" in text
    assert not list(tmp_path.glob("*.png"))


def _error(argv, capsys) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err
    return err


def test_unknown_fit_name(trace_file, capsys):
    err = _error(["calibrate", str(trace_file), "--fit", "r_er,Cp2"], capsys)
    assert "'Cp2'" in err and "r_er, r_el, cp, zeta1, zeta2" in err


def test_cp_with_cim(trace_file, capsys):
    err = _error(["calibrate", str(trace_file), "--impact", "CIM", "--fit", "cp"], capsys)
    assert "'cp'" in err and "CIM" in err


def _write(path, syn, names, extra=None):
    tr = syn.trace
    head = "# specimen: S1\nt [s]," + ",".join(f"{n} [{tr.units[n]}]" for n in names)
    cols = [tr.time] + [tr.to_written_units(n, tr.channels[n]) for n in names]
    if extra is not None:
        head += f",{extra[0]}"
        cols.append(extra[1])
    rows = [",".join(f"{x:.9g}" for x in row) for row in np.column_stack(cols)]
    path.write_text(head + "\n" + "\n".join(rows) + "\n")
    return path


def test_missing_sensors(syn, tmp_path, capsys):
    path = _write(tmp_path / "two.csv", syn, ["theta", "a_A4"])
    err = _error(["calibrate", str(path)], capsys)
    assert "two.csv" in err and "A1, A2, A3" in err and "--channels" in err


def test_nan_sample(syn, tmp_path, capsys):
    path = _write(tmp_path / "nan.csv", syn, list(syn.trace.names))
    lines = path.read_text().splitlines()
    cells = lines[10].split(",")
    cells[3] = "nan"  # a_A2
    lines[10] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
    err = _error(["calibrate", str(path)], capsys)
    assert "nan.csv, line 11, column `a_A2`" in err and "not a finite number" in err


def test_table_acceleration_in_the_wrong_unit(syn, tmp_path, capsys):
    t = syn.trace.time
    ag = 0.4 * 9.81 * np.sin(15.0 * t) * (t < 0.42)  # m/s2 under a g header
    path = _write(tmp_path / "table.csv", syn, list(syn.trace.names), ("ag [g]", ag))
    err = _error(["calibrate", str(path)], capsys)
    assert "column `ag`" in err and "m/s2 under a `g` header" in err


def test_no_rocking(tmp_path, capsys):
    rng = np.random.default_rng(1)
    t = np.arange(600) / 200.0
    cols = [t, 1e-4 * rng.standard_normal(t.size)] + [0.01 * rng.standard_normal(t.size)] * 4
    head = "# specimen: S1\nt [s],theta [rad],a_A1 [g],a_A2 [g],a_A3 [g],a_A4 [g]"
    rows = [",".join(f"{x:.6g}" for x in row) for row in np.column_stack(cols)]
    path = tmp_path / "still.csv"
    path.write_text(head + "\n" + "\n".join(rows) + "\n")
    err = _error(["calibrate", str(path)], capsys)
    assert "still.csv: no rocking" in err


def test_start_and_bounds_are_read():
    assert parse_pairs("r_er=0.9, cp=1500", "--start") == {"r_er": 0.9, "cp": 1500.0}
    assert parse_pairs("cp=500:5000", "--bounds", ranged=True) == {"cp": (500.0, 5000.0)}
    with pytest.raises(InputError, match="`--bounds`.*NAME=LOW:HIGH"):
        parse_pairs("cp=500", "--bounds", ranged=True)
    with pytest.raises(InputError, match="`--start`.*'x'"):
        parse_pairs("cp=x", "--start")
