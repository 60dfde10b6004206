"""``multimass identify`` (multimass/cli/identify_cmd.py): operational modes of a trace.

Reference values: the model's modes from `multimass.modal.analyse` (independent of the
identification); the trace is a synthetic S1 free-vibration test (0.11 rad, 10 s,
DD2, 200 Hz, noise 2 % of each channel's peak: paper 001 Section 4.3's test, logged).
"""

import json

import pytest

from multimass import FreeRelease, modal
from multimass.cli import main
from multimass.identify import synthetic_trace


@pytest.fixture(scope="module")
def trace_file(tmp_path_factory):
    syn = synthetic_trace("S1", FreeRelease(theta0=0.11), "DD2", 10.0, seed=5)
    path, _truth = syn.write(tmp_path_factory.mktemp("identify") / "s1_free.csv")
    return path


@pytest.fixture(scope="module")
def model():
    return modal.analyse("S1")


def _lines(text: str) -> list[str]:
    return [x for x in text.splitlines() if x.strip()]


def test_json_has_both_phases_with_frequencies_and_mac(trace_file, model, capsys):
    assert main(["identify", str(trace_file), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["specimen"] == "S1"  # from the trace's `# specimen:` line
    rk, fc = data["rocking"], data["full_contact"]
    assert rk["freq_hz"] == sorted(rk["freq_hz"]) and len(rk["mac"]) == len(rk["freq_hz"]) == 2
    assert rk["freq_hz"][0] == pytest.approx(model.rocking.freq_hz[0], rel=0.01)
    assert rk["freq_hz"][1] == pytest.approx(model.rocking.freq_hz[1], rel=0.02)
    assert fc["freq_hz"][0] == pytest.approx(model.full_contact.freq_hz[0], rel=0.01)
    assert min(rk["mac"]) >= 0.95 and fc["mac"][0] >= 0.95
    assert set(rk["not_identified"]) == {"3", "4", "5"}  # above 0.4 × 200 Hz
    assert len(rk["damping"]) == 2 and data["sensors"] == ["a_A1", "a_A2", "a_A3", "a_A4"]


def test_out_writes_a_report_that_modal_measured_reads(trace_file, tmp_path, capsys):
    out = tmp_path / "report"
    assert main(["identify", str(trace_file), "--specimen", "S1", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "rocking (compound shapes):" in text and "mode 1: 20." in text
    # a spread over the segments only where there are two or more (one gives no "± 0.000")
    for line in (x for x in text.splitlines() if " segment(s)" in x):
        assert ("±" in line) == (not line.endswith(" 1 segment(s)")), line
    names = {p.name for p in out.iterdir()}
    assert {"s1_free_modes.md", "s1_free_modes.png", "s1_free_modes.json"} <= names
    for phase, model_key in (("rocking", "mac_vs_compound"), ("full_contact", None)):
        csv = out / f"s1_free_modes_{phase}_shapes.csv"
        assert csv.is_file()
        argv = ["modal", "S1", "--measured", str(csv), "--json", "--out", str(tmp_path / phase)]
        assert main([*argv, "--no-figures"]) == 0
        measured = json.loads(capsys.readouterr().out)[0]["measured"]
        key = model_key or "mac_vs_full_contact"
        macs = [measured[key][i][i] for i in range(len(measured["modes"]))]
        assert macs[0] >= 0.95 and measured["nodes"] == [2, 3, 4, 5]


def test_one_phase_and_the_fft_method(trace_file, model, capsys):
    argv = ["identify", str(trace_file), "--phase", "rocking", "--method", "fft", "--json"]
    assert main([*argv, "--modes", "1"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["full_contact"] is None and data["method"] == "fft"
    assert data["rocking"]["mode"] == [1]
    assert data["rocking"]["freq_hz"][0] == pytest.approx(model.rocking.freq_hz[0], rel=0.01)


def _error(argv, capsys) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert len(_lines(err)) == 1 and "Traceback" not in err
    return err


def test_a_missing_sensor_column_is_one_line(trace_file, tmp_path, capsys):
    lines = trace_file.read_text().splitlines()
    header = lines[1].split(",")  # line 0 is `# specimen: S1`
    k = header.index("a_A3 [g]")
    rows = [",".join(c for i, c in enumerate(x.split(",")) if i != k) for x in lines[1:]]
    path = tmp_path / "no_a3.csv"
    path.write_text("\n".join([lines[0], *rows]) + "\n")
    err = _error(["identify", str(path), "--json"], capsys)
    assert "A3" in err and "a_A3 missing" in err and "--sensors" in err


def test_nan_samples_are_one_line(trace_file, tmp_path, capsys):
    lines = trace_file.read_text().splitlines()
    cells = lines[10].split(",")
    cells[1] = "nan"
    lines[10] = ",".join(cells)
    path = tmp_path / "nan.csv"
    path.write_text("\n".join(lines) + "\n")
    err = _error(["identify", str(path)], capsys)
    assert "line 11, column `theta`" in err


def test_no_full_contact_names_the_rocking_phase_alone(trace_file, tmp_path, capsys):
    lines = trace_file.read_text().splitlines()
    path = tmp_path / "short.csv"
    path.write_text("\n".join(lines[:602]) + "\n")  # 3 s: still rocking at the end
    err = _error(["identify", str(path)], capsys)
    assert "no full-contact stretch" in err and "--phase rocking" in err
    assert main(["identify", str(path), "--phase", "rocking", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["rocking"]["mode"] == [1, 2]


@pytest.mark.parametrize(
    "extra, fragment",
    [
        (["--modes", "a"], "`--modes` = 'a'"),
        (["--sensors", "A1;A2"], "`--sensors` = 'A1;A2'"),
        (["--specimen", "S9"], "S9"),
        (["--theta-min", "-1"], "--theta-min"),
    ],
)
def test_bad_flags_are_one_line(trace_file, capsys, extra, fragment):
    assert fragment in _error(["identify", str(trace_file), *extra], capsys)


def test_a_trace_without_specimen_needs_the_flag(trace_file, tmp_path, capsys):
    lines = trace_file.read_text().splitlines()
    path = tmp_path / "anon.csv"
    path.write_text("\n".join(lines[1:402]) + "\n")  # no `# specimen:` line
    assert "--specimen S1" in _error(["identify", str(path), "--json"], capsys)
