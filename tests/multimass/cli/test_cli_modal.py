"""The `multimass modal` and `multimass specimens` commands."""

import json

import numpy as np
import pytest
import scipy.linalg as sla

import multimass
from multimass.cli import main
from tests.conftest import column_toml


def test_specimens_lists_bundled(capsys):
    assert main(["specimens", "--json"]) == 0
    names = [r["name"] for r in json.loads(capsys.readouterr().out)]
    assert {"S1", "S2", "S3"} <= set(names)


def test_modal_json_array(capsys):
    assert main(["modal", "S1", "S2", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [d["specimen"] for d in data] == ["S1", "S2"]
    s1 = data[0]
    assert s1["full_contact"]["freq_hz"][0] == pytest.approx(7.47, abs=0.01)
    assert s1["rocking"]["freq_hz"][0] == pytest.approx(20.50, abs=0.01)
    assert len(s1["mac_full_vs_compound"]) == 5
    assert s1["reference"]["rocking_freq_hz"] == [20.7, 46.9]  # paper 001, Section 4.2


def test_modal_writes_report(tmp_path, capsys):
    assert main(["modal", "S3", "--out", str(tmp_path), "--no-figures"]) == 0
    assert (tmp_path / "S3_modal.md").is_file()
    assert "S3:" in capsys.readouterr().out


def test_modal_user_file(tmp_path, capsys):
    from multimass import specimens

    path = tmp_path / "col.toml"
    path.write_text(
        specimens.loader._bundled()["S1"].read_text().replace('name = "S1"', 'name = "Mine"')
    )
    assert main(["modal", str(path), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)[0]["specimen"] == "Mine"


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["modal", "S7", "--json"], "no such bundled specimen"),
        (["modal", "S1", "--shape-nodes", "a,b", "--json"], "--shape-nodes"),
        (["modal", "S1", "--shape-nodes", "2.5", "--json"], "`--shape-nodes` = '2.5'"),
        (["modal", "S1", "--shape-nodes", "2,,3", "--json"], "integer node numbers"),
        (["modal", "S1", "--shape-nodes", "2,\u00b3", "--json"], "integer node numbers"),
        (["modal", "nowhere/col.toml", "--json"], "nowhere/col.toml"),
        (
            ["modal", "S1", "--shape-nodes", "0,2", "--json"],
            "`--shape-nodes` = (0, 2): node(s) [0]",
        ),
        (["modal", "S1", "S2", "--measured", "x.csv", "--json"], "--measured"),
        (["modal", "B6M", "--json"], "'B6M' is a rigid block"),
    ],
)
def test_bad_input_exits_2_with_one_line(argv, fragment, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert fragment in err and err.count("\n") == 1


def _forty_nodes(tmp_path):
    heights = [round(0.05 * (i + 1), 4) for i in range(40)]
    return column_toml(tmp_path, heights, [20.0] * 40, name="col40")


def test_forty_node_column_gets_its_full_report(tmp_path, capsys):
    # the reviewer's case: Rayleigh damping overdamps the high modes of a fine mesh
    path = _forty_nodes(tmp_path)
    out = tmp_path / "report"
    assert main(["modal", str(path), "--out", str(out)]) == 0
    line = capsys.readouterr().out
    for name in ("col40_modal.md", "col40_modal.json", "col40_eigenvalues.png", "col40_shapes.png"):
        assert (out / name).is_file(), name
    # which modes are overdamped, from the closed form ζ_j = a0/(2ω_j) + a1 ω_j/2 (full contact)
    s = multimass.column(path)
    w = np.sqrt(sla.eigh(s.K, s.M, eigvals_only=True))
    a0, a1 = s.rayleigh
    over = [int(j) for j in np.flatnonzero(a0 / (2 * w) + a1 * w / 2 > 1) + 1]
    data = json.loads((out / "col40_modal.json").read_text())
    assert data["full_contact"]["overdamped"]["mode"] == over and len(over) >= 20
    assert sorted(data["full_contact"]["mode"] + over) == list(range(1, 41))
    assert all(z >= 1 for z in data["rocking"]["overdamped"]["damping"])
    assert len(data["rocking"]["rocking_eigenvalues"]) == 2
    md = (out / "col40_modal.md").read_text()
    assert "## Overdamped modes" in md and f"| full contact | {over[0]} |" in md
    assert "First 10 of 40 modes" in md and "| n10 |" in md and "| n11 |" not in md
    assert "overdamped modes: full contact" in line


def test_heavily_damped_column_lists_overdamped_uplifted_modes(tmp_path, capsys):
    path = column_toml(
        tmp_path,
        [0.06, 0.49, 0.93, 1.43, 1.93],
        [77.3, 6.2, 88.2, 8.2, 46.2],
        name="z09",
        **{"zeta_1 = 0.005": "zeta_1 = 0.9", "zeta_2 = 0.015": "zeta_2 = 0.9"},
    )
    assert main(["modal", str(path), "--out", str(tmp_path), "--no-figures"]) == 0
    line = capsys.readouterr().out.splitlines()[0]
    assert "(overdamped)" in line and "uplifted 1, 3–5" in line
    data = json.loads((tmp_path / "z09_modal.json").read_text())
    assert data["rocking"]["overdamped"]["mode"] == [1, 3, 4, 5]
    assert data["rocking"]["mode"] == [2]


# --- --frf: the state-space FRFs, and a trace's measured H1 over them ---------------------------
@pytest.fixture(scope="module")
def s1_trace(tmp_path_factory):
    """150 s of S1 at 200 Hz: linear full contact but for 60–75 s of rocking."""
    from tests.frf_synthetic import full_contact_record, with_rocking, write_trace

    t, ag, acc = full_contact_record(multimass.column("S1"), 150.0, sensors=[2, 3, 4, 5])
    theta, acc = with_rocking(t, ag, acc, [(60.0, 75.0)])
    path = tmp_path_factory.mktemp("trace") / "s1_table.csv"
    write_trace(path, t, theta, ag, acc, ["a_A1", "a_A2", "a_A3", "a_A4"])
    return path


def test_modal_frf_writes_the_figure_into_the_report(tmp_path, capsys):
    assert main(["modal", "S1", "--frf", "--frf-sensors", "A2,5", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "S1_frf.png").stat().st_size > 50_000
    data = json.loads((tmp_path / "S1_modal.json").read_text())
    assert data["frf"]["sensors"] == [3, 5] and data["frf"]["figure"] == "S1_frf.png"
    assert "measured" not in data["frf"]
    assert "![frequency response](S1_frf.png)" in (tmp_path / "S1_modal.md").read_text()


def test_modal_trace_overlays_the_measured_frf(s1_trace, tmp_path, capsys):
    argv = ["modal", "S1", "--trace", str(s1_trace), "--out", str(tmp_path), "--json"]
    assert main(argv) == 0
    meas = json.loads(capsys.readouterr().out)[0]["frf"]["measured"]
    assert meas["segments_s"] == [[0.0, 59.995], [75.0, 149.995]]
    assert (
        meas["theta_max_rad"] == 2e-4 and meas["nperseg"] == 4096
    )  # 2^k within 27 000 / 4 samples
    mode1 = meas["peaks"][0]
    assert abs(mode1["measured_freq_hz"] - mode1["model_freq_hz"]) < 2 * meas["df_hz"]
    assert (tmp_path / "S1_frf.png").is_file()
    assert main(["modal", "S1", "--trace", str(s1_trace), "--out", str(tmp_path)]) == 0
    assert "2 full-contact segment(s), 135.0 s" in capsys.readouterr().out


def _small_trace(tmp_path, header, rows, name="t.csv"):
    path = tmp_path / name
    path.write_text(header + "\n" + "\n".join(",".join(map(str, r)) for r in rows) + "\n")
    return str(path)


@pytest.mark.parametrize(
    "header, rows, extra, fragment",
    [
        ("t [s],theta [rad],a_A4 [g]", [(0.005 * k, 0, 0.01) for k in range(20)], [], "`ag`"),
        ("t [s],ag [g],a_A4 [g]", [(0.005 * k, 0.1, 0.01) for k in range(20)], [], "`theta"),
        ("t [s],theta [rad],ag [g]", [(0.005 * k, 0, 0.1) for k in range(20)], [], "a_A4 [g]"),
        (
            "t [s],theta [rad],ag [g],a_A4 [g]",
            [(0.05 * k, 0, 0.1, 0.01) for k in range(20)],
            [],
            "too slow for the first full-contact mode",
        ),
        (
            "t [s],theta [rad],ag [g],a_A4 [g]",
            [(0.005 * k + 0.001 * (k == 7), 0, 0.1, 0.01) for k in range(400)],
            [],
            "sampling is not uniform",
        ),
        (
            "t [s],theta [rad],ag [g],a_A4 [g]",
            [(0.005 * k, 0.01, 0.1, 0.01) for k in range(400)],
            [],
            "no full-contact segment",
        ),
        (
            "t [s],theta [rad],ag [g],a_A4 [g]",
            [(0.005 * k, 0, 0.1, 0.01) for k in range(400)],
            ["--nperseg", "4"],
            "`--nperseg` = 4",
        ),
        (
            "t [s],theta [rad],ag [g],a_A9 [g]",
            [(0.005 * k, 0, 0.1, 0.01) for k in range(20)],
            [],
            "no sensor 'A9'",
        ),
    ],
)
def test_bad_traces_exit_2_with_one_line(tmp_path, capsys, header, rows, extra, fragment):
    trace = _small_trace(tmp_path, header, rows)
    assert main(["modal", "S1", "--trace", trace, "--out", str(tmp_path), *extra]) == 2
    err = capsys.readouterr().err
    assert fragment in err and err.count("\n") == 1, err


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["--frf", "--no-figures"], "drop `--no-figures`"),
        (["--frf", "--json"], "give the folder with `--out DIR`"),
        (["--frf-sensors", "A2"], "add `--frf`"),
        (["--theta-max", "1e-3"], "add `--trace CSV`"),
        (["--frf", "--frf-sensors", "B9"], "no sensor 'B9'"),
        (["--frf", "--frf-sensors", "2;3"], "`--frf-sensors` = '2;3'"),
        (["--frf", "--frf-sensors", "2,9"], "outside 1..5"),
        (["S2", "--trace", "x.csv"], "a trace belongs to one specimen"),
        (["--trace", "x.csv", "--theta-max", "-1"], "`--theta-max` = -1.0"),
    ],
)
def test_bad_frf_flags_exit_2_with_one_line(tmp_path, capsys, argv, fragment):
    out = [] if "--json" in argv else ["--out", str(tmp_path)]
    assert main(["modal", "S1", *argv, *out]) == 2
    err = capsys.readouterr().err
    assert fragment in err and err.count("\n") == 1, err
