"""``multimass choose`` (multimass/cli/choose_cmd.py)."""

import json
from pathlib import Path

from multimass.cli import main

EXAMPLES = Path(__file__).resolve().parents[3] / "examples" / "scenes"
KEYS = (
    "model",
    "reason",
    "answer",
    "verified_against",
    "difference",
    "tolerance",
    "time_saved_s",
)  # the keys the issue asks for


def test_json_keys_without_verify(capsys):
    assert main(["choose", str(EXAMPLES / "s1_uplifted_frequencies.toml"), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in KEYS:
        assert key in out
    assert out["model"] == "modal-2" and out["verified_against"] is None
    assert out["tolerance"]["unit"] == "Hz" and out["time_saved_estimated"] is True
    assert out["scene_description"]["specimen"] == "S1"


def test_json_with_verify(capsys):
    assert main(["choose", str(EXAMPLES / "b6m_rigid_ground.toml"), "--verify", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["model"] == "rigid-block" and out["verified_against"] == "nscd"
    assert out["adequate"] is True and out["difference"] <= out["tolerance"]["value"]
    assert out["time_saved_estimated"] is False


def test_several_scenes_give_an_array(capsys):
    files = [
        str(EXAMPLES / "s1_uplifted_frequencies.toml"),
        str(EXAMPLES / "b3l_sine_overturning.toml"),
    ]
    assert main(["choose", *files, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert isinstance(out, list) and [o["model"] for o in out] == ["modal-2", "rigid-block"]


def test_text_output_says_not_adequate(capsys):
    assert main(["choose", str(EXAMPLES / "b6m_flexible_beam.toml"), "--verify"]) == 0
    out = capsys.readouterr().out
    assert "model: nscd" in out and "NOT adequate" in out


def test_bad_scene_is_a_one_line_error(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(
        'name = "x"\n[structure]\nspecimen = "S1"\n[excitation]\nkind = "quake"\n'
        '[question]\nkind = "peak_rotation"\n[tolerance]\nrelative = 0.05\n'
    )
    assert main(["choose", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert "`excitation.kind`" in err and len(err.splitlines()) == 1
    assert main(["choose", str(tmp_path / "missing.toml")]) == 2
