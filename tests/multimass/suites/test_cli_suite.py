"""``multimass suite``: files, JSON, resume, bad input as exit 2."""

import json
from pathlib import Path

import pandas as pd

from multimass.cli import main

ROOT = Path(__file__).resolve().parents[3]

SMALL = """
name = "B6M small"
[structure]
specimen = "B6M"
[model]
t_free_s = 5.0
[monte_carlo]
draws = 4
seed = 7
k = { distribution = "normal", mean = 0.82, std = 0.05 }
[intensity]
measure = "amp_over_g_tan_alpha"
levels = { start = 1.0, stop = 8.0, count = 5, spacing = "log" }
[pulses]
omega_p_over_p = [1.5, 4.0]
gamma = { distribution = "uniform", low = 1.5, high = 3.0 }
"""


def test_suite_writes_tables_figures_and_json(tmp_path, capsys):
    suite = tmp_path / "small.toml"
    suite.write_text(SMALL)
    out = tmp_path / "out"
    args = ["suite", str(suite), "--out", str(out), "--executor", "serial", "--bootstrap", "20"]
    assert main(args + ["--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["summary"]["n_runs"] == 2 * 5 * 4 and info["summary"]["computed"] == 40
    assert [f["measure"] for f in info["fragility"]] == [
        "overturned",
        "theta_over_alpha>=0.5",
        "theta_over_alpha>=0.8",
    ]
    assert info["pulse"] is not None and info["ida"] is None
    for name in ("runs.parquet", "runs.csv", "fragility.csv", "fragility.png", "summary.json"):
        assert (out / name).stat().st_size > 0, name
    for name in ("im_efficiency.png", "pulse_fragility.png", "pulse_fragility.csv"):
        assert (out / name).stat().st_size > 0, name
    runs = pd.read_parquet(out / "runs.parquet")
    assert len(runs) == 40 and runs.status.isin(["completed", "overturned"]).all()
    # a second run reads every chunk back
    assert main(args + ["--json"]) == 0
    again = json.loads(capsys.readouterr().out)
    assert again["summary"]["computed"] == 0 and again["summary"]["resumed"] == 40
    assert again["fragility"] == info["fragility"]


def test_suite_bad_input_is_one_line_exit_2(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(SMALL.replace('measure = "amp_over_g_tan_alpha"', 'measure = "pgv"'))
    assert main(["suite", str(bad), "--out", str(tmp_path / "o"), "--executor", "serial"]) == 2
    err = capsys.readouterr().err
    assert "amp_over_g_tan_alpha or pga" in err and "Traceback" not in err
    assert main(["suite", str(tmp_path / "none.toml"), "--out", str(tmp_path / "o")]) == 2
    assert main(["suite", str(bad), "--out", str(tmp_path / "o"), "--bootstrap", "5"]) == 2
    assert "≥ 10 resamples" in capsys.readouterr().err
    other = tmp_path / "other.toml"
    other.write_text(SMALL.replace("draws = 4", "draws = 2"))
    good = tmp_path / "good.toml"
    good.write_text(SMALL.replace("draws = 4", "draws = 1"))
    assert main(["suite", str(good), "--out", str(tmp_path / "o2"), "--executor", "serial"]) == 0
    capsys.readouterr()
    assert main(["suite", str(other), "--out", str(tmp_path / "o2"), "--executor", "serial"]) == 2
    assert "another suite" in capsys.readouterr().err


def test_failed_runs_are_reported_in_text_mode_with_their_message(tmp_path, capsys, monkeypatch):
    """A run the solver could not carry is named on the terminal with its message, not
    only as a status in the files ("files in DIR/" alone said nothing of it)."""
    from multimass.suites import runs

    real = runs.suite_batch

    def one_fails(jobs):
        out = real(jobs)
        theta, over, impacts, _, t_over, _, ims = out[0]
        out[0] = (theta, over, impacts, "failed", t_over, "solve_ivp failed at t = 0.1 s", ims)
        return out

    monkeypatch.setattr(runs, "suite_batch", one_fails)
    monkeypatch.setattr(runs, "BATCHED", True)  # batched whether or not its kernels are cached
    suite = tmp_path / "small.toml"
    suite.write_text(SMALL.replace("draws = 4", "draws = 1"))
    out = tmp_path / "out"
    args = ["suite", str(suite), "--out", str(out), "--executor", "serial", "--bootstrap", "0"]
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "run(s) failed (left out of the fits), e.g. mp_wp1.5" in text
    assert ": solve_ivp failed at t = 0.1 s" in text and f"files in {out}/" in text


def test_the_suite_command_wall_time_counts_its_report(tmp_path, capsys, monkeypatch):
    # the command's `wall_time_s` runs from its start to its summary: a figure of the report
    # made 0.5 s slower is counted
    import time

    from multimass.suites import report

    draw = report.plot_fragility
    monkeypatch.setattr(report, "plot_fragility", lambda *a, **k: time.sleep(0.5) or draw(*a, **k))
    suite = tmp_path / "small.toml"
    suite.write_text(SMALL.replace("draws = 4", "draws = 1"))
    out = tmp_path / "out"
    args = ["suite", str(suite), "--out", str(out), "--executor", "serial", "--bootstrap", "0"]
    assert main(args + ["--json"]) == 0
    printed = json.loads(capsys.readouterr().out)["summary"]
    saved = json.loads((out / "summary.json").read_text())["summary"]
    assert printed == saved
    assert saved["wall_time_s"] >= 0.5 and "the whole command" in saved["wall_time_covers"]


def test_suite_method_auto_reports_its_choice(tmp_path, capsys):
    # S1 is not stiff (S ≈ 1.9 < 10, multimass.sweeps.method_choice): auto keeps DOP853, says why
    from multimass.cli.suite_cmd import METHODS
    from multimass.suites.spec import METHODS as SPEC_METHODS

    assert METHODS == SPEC_METHODS
    rec = ROOT / "examples" / "data" / "records" / "kobe_1995.dat"
    suite = tmp_path / "s1.toml"
    suite.write_text(
        'name = "S1 auto"\n[structure]\nspecimen = "S1"\n[model]\nt_free_s = 1.0\n'
        '[monte_carlo]\ndraws = 1\n[intensity]\nmeasure = "pga"\nlevels = [0.3]\nunit = "g"\n'
        f'[[records]]\npath = "{rec}"\nunits = "m/s2"\n'
    )
    out = tmp_path / "out"
    args = ["suite", str(suite), "--out", str(out), "--executor", "serial", "--bootstrap", "0"]
    assert main(args + ["--method", "auto", "--json"]) == 0
    choice = json.loads(capsys.readouterr().out)["summary"]["method_choice"]
    assert choice["method"] == "DOP853" and "not stiff" in choice["reason"]
    # auto is a column suite's default on the compiled path; --method DOP853 asks for none
    # (another folder each: a suite file with other settings is another suite's runs)
    args[3] = str(tmp_path / "default")
    assert main(args + ["--json"]) == 0
    assert json.loads(capsys.readouterr().out)["summary"]["method_choice"] == choice
    args[3] = str(tmp_path / "dop853")
    assert main(args + ["--method", "DOP853", "--json"]) == 0
    assert "method_choice" not in json.loads(capsys.readouterr().out)["summary"]
