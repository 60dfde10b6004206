"""`multimass specimens`: a readable table whatever the lengths of its cells."""

import json

import pytest

from multimass import specimens
from multimass.cli import main
from multimass.cli.specimens_cmd import MIN_DESCRIPTION, NAME_WIDTH, format_table

LONG_SOURCE = ("shake-table campaign of 2025, " * 8)[:200]


@pytest.fixture
def long_source_file(tmp_path):
    """S1 with a 200-character `source` (a user's own file)."""
    text = specimens.loader._bundled()["S1"].read_text()
    old = 'source = "paper 001, Table 1"\ngravity'
    assert old in text
    path = tmp_path / "mine.toml"
    path.write_text(text.replace(old, f'source = "{LONG_SOURCE}"\ngravity', 1))
    return path


def _columns(header: str) -> list[int]:
    """Start of each column, from the header line."""
    return [header.index(word) for word in ("name", "kind", "source", "description")]


def test_long_source_wraps_inside_its_column(long_source_file, capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "100")
    assert main(["specimens", str(long_source_file)]) == 0
    lines = capsys.readouterr().out.splitlines()
    starts = _columns(lines[0])
    assert all(len(line) <= 100 for line in lines)
    # every line of every row keeps the description in its column (no row is pushed right)
    first = str(long_source_file)[:NAME_WIDTH]  # a long path wraps in its column too
    row = [i for i, line in enumerate(lines) if line.startswith(first)][0]
    assert lines[row][starts[3] :].startswith("Masses concentrated")
    # the whole source is there, word for word, in the source column of consecutive lines
    cells = [line[starts[2] : starts[3]].strip() for line in lines[row:]]
    assert " ".join(c for c in cells if c).startswith(LONG_SOURCE)
    # the bundled rows are unchanged in content: one line for S1
    s1 = [line for line in lines if line.startswith("S1 ")][0]
    assert "paper 001, Table 1" in s1 and "column" in s1


def test_every_line_fits_the_width_and_every_word_is_kept():
    rows = [{"name": "x" * 60, "kind": "column", "source": "s " * 150, "description": "d" * 300}]
    for width in (60, 80, 120):
        lines = format_table(rows, width)
        fixed = 24 + len("column") + 28 + 3 * 2
        assert all(len(line) <= max(width, fixed + MIN_DESCRIPTION) for line in lines)
        body = "".join(lines[1:])  # below the header row
        assert body.count("x") == 60 and body.count("d") == 300 and body.count("s") == 150


def test_json_lists_user_files(long_source_file, capsys):
    assert main(["specimens", str(long_source_file), "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert rows[-1] == {
        "name": str(long_source_file),
        "kind": "column",
        "source": LONG_SOURCE,
        "description": "Masses concentrated at mid-height and top (mass arrangement S1).",
    }
    assert {"S1", "B6M", "beam_mudric2024"} <= {r["name"] for r in rows}


def test_a_bad_user_file_is_one_clear_line(tmp_path, capsys):
    assert main(["specimens", str(tmp_path / "missing.toml")]) == 2
    err = capsys.readouterr().err.strip()
    assert (
        err.startswith("multimass specimens: error:") and "no such bundled specimen or file" in err
    )
    assert "\n" not in err
