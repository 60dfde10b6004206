"""`multimass bench --command`: the stability command against the batched kernel.

The smoke size (a 10 × 10 command, a 4 × 4 solve_ivp map, one repeat) checks what the
benchmark measures and that its comparisons are like for like; its numbers mean nothing.
"""

import json

import pytest

from multimass.bench.command_speed import FLOOR_PARTS, command_argv
from multimass.cli import main


def test_command_benchmark_compares_like_for_like(tmp_path, capsys):
    assert main(["bench", "--command", "--smoke", "--out", str(tmp_path), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res == json.loads((tmp_path / "command_speed.json").read_text())
    assert res["command"].startswith("multimass stability B6M --pulse sine --omega-p 0.5:10:10")
    assert res["kernel_outcomes_as_command"]  # the kernel ran the command's cells
    small = res["small_map"]
    assert small["identical_outcomes"] and small["identical_impacts"]
    assert small["n_simulations"][0] == small["n_simulations"][1] >= 16
    for key in ("command_over_kernel", "command_over_kernel_cpu", "floor_over_kernel"):
        assert res[key]["median"] > 0.0 and len(res[key]["values"]) == 1
    parts = res["breakdown_s"]
    # the floor: the kernel plus what no change to multimass removes, over the kernel
    kernel = parts["kernel_on_its_cells"]["median"]
    fixed = sum(res["start_up_floor_s"][p]["median"] for p in FLOOR_PARTS)
    assert res["floor_over_kernel"]["median"] == pytest.approx((kernel + fixed) / kernel)
    assert parts["command_wall_time_s"]["median"] <= parts["subprocess_wall"]["median"]
    floor = {"numba", "multimass", "numba_target", "kernel_cache_load", "not_imported_pandas"}
    assert set(res["start_up_floor_s"]) >= floor
    assert res["start_up_imports"] == []  # neither scipy.integrate nor pandas


def test_the_command_is_the_console_script_or_its_entry_point():
    argv = command_argv(100)
    assert argv[-10:] == [
        "B6M", "--pulse", "sine", "--omega-p", "0.5:10:100", "--amp", "0.25:8:100",
        "--executor", "serial", "--json",
    ]  # fmt: skip
    assert argv[0].endswith("multimass") or "from multimass.cli import main" in argv[2]
