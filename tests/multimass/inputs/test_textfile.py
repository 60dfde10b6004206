"""Opening a user's text file (multimass.inputs.textfile) and the scene file that relies on it."""

import pytest

from multimass import InputError
from multimass.inputs.textfile import as_path, read_text
from multimass.scenes.toml_scene import scene_arguments as scene_from_file

WHAT = "a test file"


def _bytes(folder, name, data: bytes):
    path = folder / name
    path.write_bytes(data)
    return path


def test_utf8_text_is_returned_without_byte_order_mark(tmp_path):
    assert read_text(_bytes(tmp_path, "a.txt", "\ufeffé 1\n".encode("utf-8")), what=WHAT) == "é 1\n"


@pytest.mark.parametrize(
    "data, problem",
    [
        (b"", "the file is empty"),
        (b" \n\t\n", "the file is empty"),
        (b"abc\x00def", r"a binary file \(NUL byte at offset 3\), not text"),
        (b"line 1\nline \xff\n", r"not UTF-8 text \(byte 0xff on line 2\)"),
    ],
)
def test_unusable_contents(tmp_path, data, problem):
    path = _bytes(tmp_path, "f.txt", data)
    with pytest.raises(InputError, match=problem) as info:
        read_text(path, what=WHAT)
    assert f"`path` = {str(path)!r}" in str(info.value) and WHAT in str(info.value)


def test_missing_file_and_directory(tmp_path):
    with pytest.raises(InputError, match=r"no such file; give a test file"):
        read_text(tmp_path / "missing.txt", what=WHAT)
    _bytes(tmp_path, "b.csv", b"x")
    _bytes(tmp_path, "a.txt", b"x")
    with pytest.raises(
        InputError,
        match=r"is a directory; give a test file inside it "
        r"\(files there: b.csv\)",
    ):
        read_text(tmp_path, what=WHAT, suffixes=(".csv",))


def test_long_directory_listing_is_cut(tmp_path):
    for k in range(8):
        _bytes(tmp_path, f"r{k}.csv", b"x")
    with pytest.raises(InputError, match=r"r4.csv, … \(8 in all\)"):
        read_text(tmp_path, what=WHAT)


def test_unreadable_file(tmp_path, monkeypatch):
    # the OS refuses the read (chmod 0 does not stop root, who runs CI: the refusal is made here)
    path = _bytes(tmp_path, "locked.txt", b"x")

    def refuse(self):
        raise PermissionError(13, "Permission denied", str(self))

    monkeypatch.setattr(type(path), "read_bytes", refuse)
    with pytest.raises(InputError, match=r"cannot be read \(Permission denied\)"):
        read_text(path, what=WHAT)


@pytest.mark.parametrize("value", [None, 1, 2.5, b"f.txt", "", "  ", "a\0b", ["f.txt"]])
def test_not_a_path(value):
    with pytest.raises(InputError, match=r"`record` = .*a test file"):
        as_path(value, what=WHAT, argument="record")


# ---------------------------------------------------------------------------- scenes
@pytest.mark.parametrize(
    "make, problem",
    [
        (lambda d: d / "missing.toml", "no such file"),
        (lambda d: d, "is a directory"),
        (lambda d: _bytes(d, "empty.toml", b""), "the file is empty"),
        (lambda d: _bytes(d, "bin.toml", b"\x00\x01"), "a binary file"),
        (
            lambda d: _bytes(d, "latin.toml", 'name = "M\xe1laga"\n'.encode("latin-1")),
            "not UTF-8 text",
        ),
        (lambda d: _bytes(d, "bad.toml", b"name = = 1\n"), "not valid TOML"),
    ],
    ids=["missing", "directory", "empty", "binary", "latin-1", "syntax"],
)
def test_scene_file_problems_are_input_errors(tmp_path, make, problem):
    path = make(tmp_path)
    with pytest.raises(InputError, match=problem) as info:
        scene_from_file(path)
    assert str(path) in str(info.value)


def test_a_scene_directory_lists_its_scene_files(tmp_path):
    _bytes(tmp_path, "s1.toml", b"x")
    with pytest.raises(
        InputError,
        match=r"`scene` = .* is a directory; give a scene TOML file "
        r"\(see examples/scenes/\) inside it \(files there: s1.toml\)",
    ):
        scene_from_file(tmp_path)
