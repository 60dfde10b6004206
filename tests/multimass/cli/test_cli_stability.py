"""``multimass stability``: its wall time is the whole command's, and it loads only what it uses.

``wall_time_s`` counts from the command's start (the process start for the console
script) to the files written: slow steps patched into the command must show in it.
"""

import gc
import json
import subprocess
import sys
import textwrap
import time

import pytest

import multimass.cli
from multimass.cli import build_parser, main

SMALL = [
    "stability", "B6M", "--omega-p", "1:6:3", "--amp", "0.5:4:3", "--refine", "1",
    "--executor", "serial",
]  # fmt: skip


def _json(capsys):
    return json.loads(capsys.readouterr().out)


def test_wall_time_covers_writing_the_files(tmp_path, capsys, monkeypatch):
    import multimass.sweeps.plots as plots

    pause, start, drawn = 0.3, time.perf_counter(), []
    draw = plots.plot_map

    def slow_plot(*args, **kwargs):  # writing the figure, made slow on purpose
        time.sleep(pause)
        out = draw(*args, **kwargs)
        drawn.append(time.perf_counter())
        return out

    monkeypatch.setattr(plots, "plot_map", slow_plot)
    monkeypatch.setattr(multimass.cli, "command_start", lambda console: start)
    assert main(SMALL + ["--out", str(tmp_path), "--json"]) == 0
    info = _json(capsys)
    assert info["wall_time_s"] >= drawn[0] - start  # the figure was written inside it
    assert info["wall_time_s"] >= info["map_wall_time_s"] + pause
    assert info["map_wall_time_s"] >= info["simulation_time_s"] > 0.0
    assert "writing the table and figures" in info["wall_time_covers"]
    written = json.loads((tmp_path / "B6M_sine_modified_map.json").read_text())
    assert written["wall_time_s"] == info["wall_time_s"]


def test_wall_time_counts_from_the_start_of_the_console_command(capsys, monkeypatch):
    before = 5.0  # the process started this long before `main` (interpreter, imports)
    monkeypatch.setattr(
        multimass.cli, "command_start", lambda console: time.perf_counter() - before
    )
    monkeypatch.setattr(sys, "argv", ["multimass"] + SMALL + ["--json"])
    try:
        assert main() == 0
    finally:
        gc.unfreeze()  # the console script freezes the collector as it ends
    info = _json(capsys)
    assert info["wall_time_s"] >= info["map_wall_time_s"] + before


def test_process_start_is_when_the_interpreter_started():
    if not sys.platform.startswith("linux"):  # no /proc: the command counts from `main`
        from multimass.cli._clock import command_start, process_start

        assert process_start() is None and command_start(True) <= time.perf_counter()
        return
    code = textwrap.dedent(
        """
        import time
        from multimass.cli._clock import command_start, process_start
        called = command_start(False)
        time.sleep(0.5)
        now = time.perf_counter()
        print(now - process_start(), now - command_start(True), now - called)
        """
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    age, console, in_python = (float(x) for x in out.stdout.split())
    assert 0.5 <= age < 60.0 and 0.5 <= console < 60.0  # /proc: 10 ms ticks
    # a command run from Python counts from its call, after the interpreter's start-up
    assert 0.5 <= in_python < min(age, console) + 0.011


def test_a_command_registers_only_its_own_module():
    assert set(build_parser("stability")._subparsers._group_actions[0].choices) == {"stability"}
    full = set(build_parser()._subparsers._group_actions[0].choices)
    assert {"stability", "bench", "simulate"} <= full
    # a name whose module is named otherwise, or no module: the full parser
    assert set(build_parser("warm-up")._subparsers._group_actions[0].choices) == full
    assert set(build_parser("nonsense")._subparsers._group_actions[0].choices) == full


def test_unknown_command_still_lists_every_command(capsys):
    assert main(["nonsense"]) == 2
    assert "stability" in capsys.readouterr().err


@pytest.mark.parametrize("out", [False, True])
def test_stability_imports_matplotlib_only_to_draw(tmp_path, out):
    argv = SMALL + ["--json"] + (["--out", str(tmp_path)] if out else [])
    code = (
        "import sys; from multimass.cli import main; "
        f"assert main({argv!r}) == 0; print('matplotlib' in sys.modules, file=sys.stderr)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stderr.strip().splitlines()[-1] == str(out)


#: What ``stability --json`` must not import: the solve_ivp path's SciPy, the tables'
#: pandas and pyarrow (scipy.linalg is numba's own import: its array registry checks
#: for BLAS in scipy.linalg.cython_blas when it loads a cached kernel), tqdm when no
#: bar is shown (stderr is not a terminal here), the process pool's multiprocessing on
#: the serial executor, the Newmark engine and the LCP solver of Poisson's law.
NOT_FOR_A_SUMMARY = (
    "pandas", "pyarrow", "scipy.integrate", "scipy.optimize", "scipy.special", "tqdm",
    "multiprocessing", "multimass.engines.newmark", "multimass.impact_models.complementarity",
)  # fmt: skip


@pytest.mark.parametrize("out", [False, True])
def test_stability_json_imports_no_scipy_solvers_nor_pandas(tmp_path, out):
    argv = SMALL + ["--json"] + (["--out", str(tmp_path)] if out else [])
    code = (
        "import sys; from multimass.cli import main; "
        f"assert main({argv!r}) == 0; "
        f"print(*[m in sys.modules for m in {NOT_FOR_A_SUMMARY!r}], file=sys.stderr)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    loaded = dict(zip(NOT_FOR_A_SUMMARY, done.stderr.strip().splitlines()[-1].split()))
    assert loaded["pandas"] == str(out)  # the table written as CSV needs it
    assert loaded["scipy.integrate"] == loaded["scipy.optimize"] == "False"
    if not out:
        assert set(loaded.values()) == {"False"}
