"""The `multimass nscd` and `multimass nscd-convergence` commands."""

import json

import pytest

from multimass.cli import main


def test_nscd_json(capsys):
    assert main(["nscd", "B6M", "--theta0-deg", "11.268", "--dt", "1e-4", "--elements", "6",
                 "--E", "1e24", "--t-end", "1", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    for key in ("status", "peaks_deg", "rest_time_s", "n_steps", "max_gs_iterations", "wall_time_s",
                "cost_per_step_us", "exact_rigid_first_peak_deg", "paper_first_peak_deg"):
        assert key in data
    assert data["status"] == "completed" and data["n_steps"] == 10000
    assert data["rest_time_s"] is None                      # still rocking at 1 s
    assert data["paper_first_peak_deg"] == 7.76             # paper 002, Section 6.2
    assert data["peaks_deg"][0] == pytest.approx(7.76, abs=0.03)


def test_nscd_writes_files(tmp_path, capsys):
    assert main(["nscd", "B4M", "--dt", "1e-4", "--t-end", "0.6", "--flex", "4",
                 "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "B4M: completed" in out and "µs/step" in out
    for name in ("nscd_B4M.json", "nscd_B4M_series.csv", "nscd_B4M.png"):
        assert (tmp_path / name).is_file()
    info = json.loads((tmp_path / "nscd_B4M.json").read_text())
    assert info["theta0_deg"] == pytest.approx(14.839, abs=1e-12)                    # the block's paper 002 release angle


@pytest.mark.parametrize("argv, fragment", [
    (["--dt", "0"], "`dt`"),
    (["--dt=-1e-5"], "`dt`"),
    (["--elements", "2"], "`n_elements`"),
    (["--theta-method", "1.5"], "`theta_method`"),
    (["--theta-method=-0.1"], "`theta_method`"),
    (["--theta0-deg", "20"], "`theta0`"),
    (["--mu=-0.1"], "`mu`"),
    (["--restitution", "2"], "`restitution`"),
    (["--t-end", "0"], "`t_end`"),
    (["--x-centre", "0.29"], "`x_centre`"),
])
def test_bad_input_is_one_clear_line(capsys, argv, fragment):
    assert main(["nscd", "B6M", "--t-end", "0.01", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("multimass nscd: error:") and fragment in err and "\n" not in err


def test_block_wider_than_the_span(tmp_path, capsys):
    import specimens
    text = specimens.loader._bundled()["beam_mudric2024"].read_text().replace("span_m = 0.30", "span_m = 0.04")
    beam = tmp_path / "short.toml"
    beam.write_text(text)
    assert main(["nscd", "B6M", "--beam", str(beam), "--t-end", "0.01"]) == 2
    err = capsys.readouterr().err
    assert "`block`" in err and "span" in err


def test_block_not_resting_on_the_beam():
    import nscd
    from multimass.errors import InputError
    with pytest.raises(InputError, match="`x_centre`.*does not rest on the beam"):
        nscd.simulate("B6M", theta0=0.1, dt=1e-4, t_end=0.01, x_centre=0.01)
    with pytest.raises(InputError, match="`block`.*is a column specimen"):
        nscd.simulate("S1", theta0=0.1, dt=1e-4, t_end=0.01)


def test_convergence_command(tmp_path, capsys):
    assert main(["nscd-convergence", "B6M", "--study", "mesh", "--meshes", "3", "6", "12",
                 "--dt", "1e-4", "--t-end", "1", "--out", str(tmp_path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["kind"] == "mesh" and data["status"] == "converged"
    assert {v["measure"] for v in data["verdicts"]} == {"first_peak_deg", "peaks_deg", "rest_time_s",
                                                        "history_deg"}
    assert (tmp_path / "mesh_study_B6M.png").is_file()
    assert (tmp_path / "convergence_mesh_B6M.json").is_file()
