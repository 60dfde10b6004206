"""The `multimass nscd` and `multimass nscd-convergence` commands."""

import importlib
import json
import math

import pytest

from multimass.cli import main


def test_nscd_json(capsys):
    assert (
        main(
            [
                "nscd",
                "B6M",
                "--theta0-deg",
                "11.268",
                "--dt",
                "1e-4",
                "--elements",
                "6",
                "--E",
                "1e24",
                "--t-end",
                "1",
                "--json",
            ]
        )
        == 0
    )
    data = json.loads(capsys.readouterr().out)
    for key in (
        "status",
        "peaks_deg",
        "rest_time",
        "n_steps",
        "max_gs_iterations",
        "wall_time_s",
        "cost_per_step_us",
        "exact_rigid_first_peak_deg",
        "paper_first_peak_deg",
    ):
        assert key in data
    assert data["status"] == "completed" and data["n_steps"] == 10000
    assert data["rest_time"] is None  # still rocking at 1 s
    assert data["paper_first_peak_deg"] == 7.76  # paper 002, Section 6.2
    assert data["peaks_deg"][0] == pytest.approx(11.268, abs=1e-12)  # the release angle
    assert data["peaks_deg"][1] == pytest.approx(7.76, abs=0.03)
    assert data["first_peak_deg"] == data["peaks_deg"][1]
    assert data["first_peak"] == pytest.approx(math.radians(data["first_peak_deg"]), rel=1e-12)


def test_nscd_writes_files(tmp_path, capsys):
    assert (
        main(
            ["nscd", "B4M", "--dt", "1e-4", "--t-end", "0.6", "--flex", "4", "--out", str(tmp_path)]
        )
        == 0
    )
    out = capsys.readouterr().out
    assert "B4M: completed" in out and "µs/step" in out
    for name in ("nscd_B4M.json", "nscd_B4M_series.csv", "nscd_B4M.png"):
        assert (tmp_path / name).is_file()
    info = json.loads((tmp_path / "nscd_B4M.json").read_text())
    assert info["theta0_deg"] == pytest.approx(
        14.839, abs=1e-12
    )  # the block's paper 002 release angle


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["--dt", "0"], "`--dt`"),
        (["--dt=-1e-5"], "`--dt`"),
        (["--dt", "nan"], "`--dt`"),
        (["--elements", "2"], "`--elements`"),
        (["--elements", "100000"], "`--elements` = 100000: at most 1000 elements"),
        (["--theta-method", "1.5"], "`--theta-method`"),
        (["--theta-method=-0.1"], "`--theta-method`"),
        (["--theta0-deg", "20"], "`--theta0-deg` = 20.0: beyond the overturning angle"),
        (["--theta0-deg", "inf"], "`--theta0-deg`"),
        (["--mu=-0.1"], "`--mu`"),
        (["--mu", "inf"], "`--mu`"),
        (["--restitution", "2"], "`--restitution`"),
        (["--t-end", "0"], "`--t-end`"),
        (["--t-end", "1e300"], "`--t-end`"),
        (["--x-centre", "0.29"], "`--x-centre`"),
        (["--flex", "1000"], "`--flex` = 1000.0: must lie in"),
        (["--flex", "-3"], "`--flex`"),
        (["--E", "1e9"], "`--E` = 1e+09 Pa: too soft"),
        (["--E", "1e31"], "`--E`"),
        (["--E", "-1"], "`--E`"),
        (["--gs-tol", "0"], "`--gs-tol`"),
        (["--gs-tol", "0.5"], "`--gs-tol`"),
        (["--gs-max-iter", "0"], "`--gs-max-iter`"),
        (["--gs-max-iter", "10000000"], "`--gs-max-iter`"),
        (["--rest-fraction", "1"], "`--rest-fraction`"),
        (["--max-hours", "0"], "`--max-hours`"),
        (["--max-hours", "nan"], "`--max-hours`"),
    ],
)
def test_bad_input_is_one_clear_line(capsys, argv, fragment):
    assert main(["nscd", "B6M", "--t-end", "0.01", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("multimass nscd: error:") and fragment in err and "\n" not in err


def test_rigid_base_convention_e_1e24_keeps_working(capsys):
    # paper 002, Section 6.1: E = 1e24 Pa is the rigid base; E_MAX (1e30) leaves room above it
    assert main(["nscd", "B6M", "--E", "1e24", "--dt", "1e-4", "--t-end", "0.05", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["E"] == 1e24


def test_a_billion_steps_are_refused_with_their_estimate(capsys):
    # the reviewer's case: --dt 1e-9 over the default 4 s is 4e9 steps, ~2 h on this machine
    assert main(["nscd", "B6M", "--dt", "1e-9"]) == 2
    err = capsys.readouterr().err
    assert "estimated" in err and "4e+09 steps" in err and "over the budget of 1 h" in err
    assert "--max-hours" in err and "--dt" in err and "\n" not in err.strip()


def test_progress_flags(capsys):
    # --progress forces the bar with its estimate (automatic: above a few seconds; the bar's
    # movement between kernel chunks is tested in test_simulate.py); --no-progress hides it
    assert main(["nscd", "B6M", "--dt", "1e-4", "--t-end", "0.2", "--progress"]) == 0
    err = capsys.readouterr().err
    assert "nscd B6M: estimated" in err and "/0.2 s" in err
    assert main(["nscd", "B6M", "--dt", "1e-4", "--t-end", "0.2", "--no-progress"]) == 0
    assert capsys.readouterr().err == ""


def test_outputs_are_checked_before_computing(tmp_path, capsys, monkeypatch):
    engine = importlib.import_module("multimass.engines.nscd.run")  # the module, not the function

    def no_run(*a, **k):  # computing would fail the test
        raise AssertionError("computed before the output folder was checked")

    monkeypatch.setattr(engine, "execute", no_run)
    monkeypatch.setattr(engine, "_run", no_run)
    afile = tmp_path / "results.txt"
    afile.write_text("keep me")
    assert main(["nscd", "B6M", "--t-end", "0.01", "--out", str(afile)]) == 2
    assert "`--out`" in capsys.readouterr().err and afile.read_text() == "keep me"
    assert main(["nscd", "B6M", "--t-end", "0.01", "--out", str(afile / "sub")]) == 2
    assert "`--out`" in capsys.readouterr().err
    assert (
        main(
            [
                "nscd-convergence",
                "B6M",
                "--study",
                "mesh",
                "--meshes",
                "3",
                "6",
                "--dt",
                "1e-3",
                "--t-end",
                "0.05",
                "--out",
                str(afile),
            ]
        )
        == 2
    )
    assert "`--out`" in capsys.readouterr().err


def test_read_only_output_folder_is_refused(tmp_path, capsys, monkeypatch):
    # the OS refuses the write (a read-only folder does not stop root, who runs CI: the
    # refusal is made here, where multimass.cli._output tries its test file)
    import tempfile

    def refuse(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(tempfile, "NamedTemporaryFile", refuse)
    assert main(["nscd", "B6M", "--t-end", "0.01", "--out", str(tmp_path / "ro")]) == 2
    err = capsys.readouterr().err
    assert "`--out`" in err and "cannot write there (Permission denied)" in err


def test_inaccurate_run_is_reported_with_warnings(tmp_path, capsys):
    # Gauss–Seidel capped at 3 sweeps on a stiff flexible beam: the impulses do not converge
    argv = [
        "nscd",
        "B6M",
        "--flex",
        "2",
        "--dt",
        "1e-4",
        "--t-end",
        "4",
        "--gs-max-iter",
        "3",
        "--gs-tol",
        "1e-14",
    ]
    assert main(argv) == 1
    out = capsys.readouterr().out
    assert "B6M: inaccurate (the run completed, but an accuracy check failed)" in out
    assert "  warning: Gauss–Seidel stopped at its cap of 3 iterations" in out
    assert main(argv + ["--json", "--out", str(tmp_path)]) == 1
    data = json.loads(capsys.readouterr().out)
    assert data["status"] == "inaccurate" and data["outcome"] == "completed"
    assert data["checks"]["gauss_seidel_residual"]["passed"] is False
    assert any("Gauss–Seidel" in w for w in data["warnings"])
    assert json.loads((tmp_path / "nscd_B6M.json").read_text())["warnings"] == data["warnings"]


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["--study", "dt", "--dts", "1e-3", "0"], "`--dts[1]` = 0.0"),  # was ZeroDivisionError
        (["--study", "dt", "--dts", "1e-3"], "at least 2 levels"),
        (["--study", "dt", "--dts", "1e-3", "1e-3"], "repeated"),
        (["--study", "dt", "--dts", "1e-3", "1e-4", "5e-5"], "refinement ratios 10, 2 differ"),
        (["--study", "dt", "--dts", "1e-3", "nan"], "`--dts[1]`"),
        (["--study", "dt", "--dts", "1e-8", "1e-9"], "over the budget"),
        (["--study", "mesh", "--meshes", "3"], "at least 2 levels"),
        (["--study", "mesh", "--meshes", "3", "6", "2000"], "`--meshes[2]` = 2000"),
        (["--study", "mesh", "--dt", "0"], "`--dt`"),
        (["--study", "mesh", "--t-end", "0"], "`--t-end`"),
        (["--study", "flexibility", "--exponents", "1000"], "`--exponents[0]` = 1000.0"),
        (["--study", "flexibility", "--exponents", "2", "2"], "repeated"),
        (["--study", "flexibility", "--dt", "2e-5"], "`--dt` = 2e-05: must be one of `--dts`"),
        (["--study", "flexibility", "--flex", "2"], "`--E`/`--flex` do not apply"),
        (["--study", "first-peak", "--dts", "1e-3"], "at least 2 levels"),
        (["--study", "dt", "--theta0-deg", "15"], "`--theta0-deg`"),
        (["--study", "dt", "--gs-max-iter", "0"], "`--gs-max-iter`"),
        (["--study", "dt", "--restitution", "-1"], "`--restitution`"),
        (["--study", "dt", "--mu", "nan"], "`--mu`"),
    ],
)
def test_bad_study_input_is_one_clear_line(tmp_path, capsys, argv, fragment):
    out = tmp_path / "conv"
    assert main(["nscd-convergence", "B6M", *argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("multimass nscd-convergence: error:") and fragment in err
    assert "\n" not in err
    assert not out.exists()  # refused before computing: no folder left


def test_block_wider_than_the_span(tmp_path, capsys):
    from multimass import specimens

    text = (
        specimens.loader._bundled()["beam_mudric2024"]
        .read_text()
        .replace("span_m = 0.30", "span_m = 0.04")
    )
    beam = tmp_path / "short.toml"
    beam.write_text(text)
    assert main(["nscd", "B6M", "--beam", str(beam), "--t-end", "0.01"]) == 2
    err = capsys.readouterr().err
    assert "`block`" in err and "span" in err


def test_block_not_resting_on_the_beam():
    from multimass.engines import nscd
    from multimass.errors import InputError

    with pytest.raises(InputError, match="`x_centre`.*does not rest on the beam"):
        nscd.simulate("B6M", theta0=0.1, dt=1e-4, t_end=0.01, x_centre=0.01)
    with pytest.raises(InputError, match="`block`.*is a column specimen"):
        nscd.simulate("S1", theta0=0.1, dt=1e-4, t_end=0.01)


def test_convergence_command(tmp_path, capsys):
    assert (
        main(
            [
                "nscd-convergence",
                "B6M",
                "--study",
                "mesh",
                "--meshes",
                "3",
                "6",
                "12",
                "--dt",
                "1e-4",
                "--t-end",
                "1",
                "--out",
                str(tmp_path),
                "--json",
            ]
        )
        == 0
    )
    data = json.loads(capsys.readouterr().out)
    assert data["kind"] == "mesh" and data["status"] == "converged" and data["warnings"] == []
    assert {v["measure"] for v in data["verdicts"]} == {
        "first_peak_deg",
        "peaks_deg",
        "rest_time_s",
        "history_deg",
    }
    assert (tmp_path / "mesh_study_B6M.png").is_file()
    assert (tmp_path / "convergence_mesh_B6M.json").is_file()


def test_a_block_given_as_a_path_names_the_files(tmp_path, capsys):
    from multimass import specimens

    path = str(specimens.loader._bundled()["B6M"])  # ".../specimens/data/B6M.toml"
    assert (
        main(
            [
                "nscd-convergence",
                path,
                "--study",
                "mesh",
                "--meshes",
                "3",
                "6",
                "--dt",
                "1e-3",
                "--t-end",
                "0.05",
                "--out",
                str(tmp_path),
                "--json",
            ]
        )
        == 0
    )
    capsys.readouterr()
    names = sorted(p.name for p in tmp_path.iterdir())
    assert "mesh_study_B6M.png" in names
    assert [n for n in names if n.startswith("convergence_mesh_")] and all(
        "/" not in n for n in names
    )


FLOAT_FLAGS = [
    "--dt",
    "--t-end",
    "--theta0-deg",
    "--E",
    "--flex",
    "--theta-method",
    "--mu",
    "--restitution",
    "--gs-tol",
    "--rest-fraction",
    "--x-centre",
    "--max-hours",
]
INT_FLAGS = ["--elements", "--gs-max-iter"]


@pytest.mark.parametrize("flag", FLOAT_FLAGS + INT_FLAGS)
@pytest.mark.parametrize("value", ["nan", "-inf", "-1", "1e308", "1e-308"])
def test_no_value_of_any_flag_gives_a_traceback(capsys, flag, value):
    # every number a user can type: a result (0, or 1 with its warnings) or one clear line (2)
    code = main(["nscd", "B6M", "--t-end", "0.01", "--dt", "1e-3", f"{flag}={value}"])
    out, err = capsys.readouterr()
    assert code in (0, 1, 2)
    if code == 2:  # named flag, one line (argparse's for ints)
        assert err.startswith("multimass nscd: error: ") and flag in err
        assert "\n" not in err.strip()
    else:
        assert out.startswith("B6M: ") and "nan" not in out.lower()
