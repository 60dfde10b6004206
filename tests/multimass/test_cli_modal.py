"""The `multimass modal` and `multimass specimens` commands."""

import json

import pytest

from multimass.cli import main


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
    assert s1["reference"]["rocking_freq_hz"] == [20.7, 46.9]   # paper 001, Section 4.2


def test_modal_writes_report(tmp_path, capsys):
    assert main(["modal", "S3", "--out", str(tmp_path), "--no-figures"]) == 0
    assert (tmp_path / "S3_modal.md").is_file()
    assert "S3:" in capsys.readouterr().out


def test_modal_user_file(tmp_path, capsys):
    import specimens

    path = tmp_path / "col.toml"
    path.write_text(specimens.loader._bundled()["S1"].read_text().replace('name = "S1"', 'name = "Mine"'))
    assert main(["modal", str(path), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)[0]["specimen"] == "Mine"


@pytest.mark.parametrize("argv, fragment", [
    (["modal", "S7", "--json"], "no such bundled specimen"),
    (["modal", "S1", "--shape-nodes", "a,b", "--json"], "--shape-nodes"),
    (["modal", "S1", "S2", "--measured", "x.csv", "--json"], "--measured"),
])
def test_bad_input_exits_2_with_one_line(argv, fragment, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert fragment in err and err.count("\n") == 1
