"""The README runs as written: its Python example (also as a saved script and piped to
``python -``), and every ``multimass`` command line it shows (shortened where a full run
would take minutes)."""

import re
import shlex
import subprocess
import sys

import pytest

from multimass.cli import build_parser, main
from tests.conftest import REPO

README = (REPO / "README.md").read_text()
PYTHON_BLOCKS = re.findall(r"```python\n(.*?)```", README, flags=re.S)


@pytest.mark.parametrize("how", ["file", "stdin"])
def test_readme_python_example_runs_as_a_script(how, tmp_path):
    # saved as script.py (or piped to `python -`) the example runs once: the overturning map's
    # process pool must not re-run the unguarded script (BrokenProcessPool)
    assert PYTHON_BLOCKS, "README.md has no python example"
    code = "\n".join(PYTHON_BLOCKS)
    script = tmp_path / "script.py"
    script.write_text(code)
    argv = [sys.executable, str(script)] if how == "file" else [sys.executable, "-"]
    # from a folder of its own, as a user would: nothing may depend on the repository's cwd
    done = subprocess.run(
        argv,
        cwd=tmp_path,
        input=None if how == "file" else code,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    assert "Traceback" not in done.stderr


def test_readme_has_exactly_two_setup_commands():
    section = README.split("## Set up and run", 1)[1].split("\n## ", 1)[0]
    commands = re.findall(r"```bash\n(.*?)```", section, flags=re.S)
    assert len(commands) == 2
    ci = (REPO / ".ci" / "run").read_text()
    assert commands[1].strip() in ci  # CI runs the README's test command


# --- every command line -------------------------------------------------------------------


def _command_lines() -> list[str]:
    """`multimass ...` in backticks, and the lines of code blocks that start with it."""
    spans = re.findall(r"`(multimass [^`]+)`", README)
    blocks = re.findall(r"```[a-z]*\n(.*?)```", README, flags=re.S)
    lines = [ln.split("  #")[0].strip() for b in blocks for ln in b.splitlines()]
    lines += [ln.split("&& ", 1)[1] for ln in lines if "&& multimass" in ln]
    found = [c.replace("\\|", "|") for c in spans] + [
        ln for ln in lines if ln.startswith("multimass ")
    ]
    return list(dict.fromkeys(found))


def _distinct(commands: list[str]) -> list[str]:
    """One command per distinct shortened form (the bench lines all shorten to --smoke)."""
    seen, keep = set(), []
    for c in commands:
        argv = shlex.split(c)[1:]
        key = (
            tuple(
                sorted(
                    t
                    for t in _shortened(argv, REPO / "out")
                    if t not in ("--json",) and "/" not in t
                )
            )
            if argv and argv[0] in SUBCOMMANDS
            else tuple(argv)
        )
        if key not in seen:
            seen.add(key)
            keep.append(c)
    return keep


COMMANDS = _command_lines()
SUBCOMMANDS = set(
    next(
        a for a in build_parser()._actions if hasattr(a, "choices") and isinstance(a.choices, dict)
    ).choices
)


def _shortened(argv: list[str], tmp) -> list[str]:
    """The same command, quick: short runs, small grids, outputs in `tmp`."""
    out, it = [], iter(argv)
    for tok in it:
        if tok == "--out":
            out += [tok, str(tmp / next(it).strip("/"))]
        elif tok == "--t-end":
            out += [tok, str(min(float(next(it)), 1.0 if argv[0] != "nscd" else 0.05))]
        elif tok == "--repeats":
            out += [tok, "1"]
            next(it)
        elif tok == "--quick":
            out.append("--smoke")
        elif tok in ("--dask-address", "--dask-timeout"):
            next(it)  # no cluster in the README test: the sweep runs serially (below)
        elif re.fullmatch(r"[^:]+:[^:]+:\d+", tok):  # START:STOP:COUNT
            start, stop, count = tok.split(":")
            out.append(f"{start}:{stop}:{min(int(count), 3)}")
        else:
            out.append(tok)
    if argv[0] in ("stability", "spectrum"):
        out += ["--executor", "serial", "--no-progress"]
    if argv[0] == "simulate" and "--t-end" not in argv:
        out += ["--t-end", "1.0"]
    if argv[0] in ("nscd-convergence", "modal", "compare") and "--out" not in argv:
        out += ["--out", str(tmp / "default_out")]  # their default folder is in the cwd
    if argv[0] == "bench" and "--smoke" not in out:
        out.append("--smoke")
    if argv[0] == "nscd-convergence":
        out += ["--dts", "1e-3", "1e-4"]
    return out


def test_the_readme_shows_commands_of_every_kind():
    kinds = {shlex.split(c)[1] for c in COMMANDS if len(shlex.split(c)) > 1}
    assert {
        "modal",
        "simulate",
        "compare",
        "stability",
        "spectrum",
        "nscd",
        "choose",
        "bench",
        "specimens",
        "synthetic",
        "identify",
        "restitution",
        "calibrate",
    } <= kinds


@pytest.mark.parametrize("command", _distinct(COMMANDS))
def test_readme_command_runs(command, tmp_path, monkeypatch, capsys):
    argv = shlex.split(command)[1:]
    if argv == ["--help"]:
        assert main(argv) == 0
        return
    assert argv[0] in SUBCOMMANDS, f"{command}: no such command"
    if len(argv) == 1 and argv[0] != "specimens":
        return  # a reference to the command, not a command line
    monkeypatch.chdir(REPO)
    code = main(_shortened(argv, tmp_path))
    err = capsys.readouterr().err
    assert code == 0, f"{command}: exit {code}\n{err[-2000:]}"
    if argv[0] == "bench":  # the default run's bench check (the JSON one is marked slow)
        out = tmp_path / argv[argv.index("--out") + 1].strip("/")
        names = (
            ("scaling.json", "scaling.md", "scaling_cells.png", "scaling_nodes.png")
            if "--scaling" in argv
            else ("bench.json", "rows.csv", "failures.md", "summary.md", "wp_S1_DD2.png")
        )
        for name in names:
            assert (out / name).is_file(), name


@pytest.mark.parametrize("name", sorted(SUBCOMMANDS))
def test_every_help_runs(name, capsys):
    assert main([name, "--help"]) == 0
    assert "usage: multimass" in capsys.readouterr().out
