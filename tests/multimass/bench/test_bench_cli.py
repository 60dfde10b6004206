"""``multimass bench`` (multimass/cli/bench_cmd.py, benchmarks/run.py): structure of the output.

A smoke configuration (seconds; its numbers mean nothing) runs the whole
pipeline: targets, the five models, the stiffness sweep, failure detection,
tables and charts. Only the structure is checked — no timing assertions
(benchmarks are not timed tests).
"""

import json

import pytest

from multimass.bench.failures import KINDS
from multimass.cli import main

HEADLINE = ("speedup_single", "speedup_map", "scaling_2_workers", "peak_error_rad")  # bench.json
ROW_KEYS = ("model", "method", "tolerance", "error", "wall_time_s", "n_rhs", "failure")  # rows.csv
MODELS = {"rigid_block", "S1_CIM", "S1_DD2", "lcp_block", "nscd", "S1 stiffness"}


@pytest.mark.slow  # ~15 s (91 s with a cold numba cache); tests/test_readme.py runs the smoke
def test_bench_json_structure(tmp_path, capsys):
    out = tmp_path / "bench"
    assert main(["bench", "--smoke", "--out", str(out), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert list(res)[:4] == list(HEADLINE)
    for key in HEADLINE:
        assert isinstance(res[key], float) and res[key] > 0
    assert set(res["targets"]["pass"]) == set(HEADLINE)
    # the smoke case is smaller than the target cases: measured, not judged
    assert all(v is None for v in res["targets"]["pass"].values())
    rows = res["rows"]
    assert {r["model"] for r in rows} == MODELS
    for r in rows:
        assert set(ROW_KEYS) <= set(r)
        assert isinstance(r["failure"], list) and set(r["failure"]) <= set(KINDS)
        assert r["wall_time_s"] >= 0 and r["n_rhs"] >= 0
    methods = {r["method"] for r in rows}
    for m in (
        "RK45",
        "DOP853",
        "Radau",
        "BDF",
        "LSODA",
        "compiled DOP853",
        "Newmark + NR",
        "Moreau–Jean, rigid base",
        "paper-000 driver (DOP853)",
    ):
        assert m in methods
    # the files the README section points to
    for name in (
        "bench.json",
        "rows.csv",
        "failures.csv",
        "failures.md",
        "summary.md",
        "failure_map.png",
        "stiffness.png",
        "wp_rigid_block.png",
        "wp_S1_CIM.png",
        "wp_S1_DD2.png",
        "wp_lcp_block.png",
        "wp_nscd.png",
    ):
        assert (out / name).is_file(), name
    assert json.loads((out / "bench.json").read_text())["charts"] == res["charts"]
    # the map's ratios, ABBA-timed, and the machine's own scaling beside them
    mp = res["targets"]["map"]
    assert len(mp["scaling_2_workers"]["values"]) == len(mp["machine_scaling"]["values"]) == 1
    assert "machine's own 2-worker scaling" in (out / "summary.md").read_text()


def test_spin_is_the_loop_it_says():
    # closed form: i² mod 7 over one period of 7 is 0+1+4+2+2+4+1 = 14
    from multimass.bench.targets import spin

    assert spin(700) == 1400 and spin(7) == 14 and spin(0) == 0


def test_bench_rejects_quick_with_smoke(capsys):
    assert main(["bench", "--quick", "--smoke", "--out", "x"]) == 2
    err = capsys.readouterr().err
    assert "not allowed with argument" in err and err.count("\n") == 1


def test_the_full_run_measures_the_target_cases():
    # the target cases: S1 DD2 release for 10 s, the 100 x 100 B6M map
    from multimass.bench.config import preset
    from multimass.bench.targets import TARGET_CASE

    full = preset("full")
    assert TARGET_CASE == {"t_end": 10.0, "map_n": 100}
    assert (full.target_t_end, full.map_n) == (TARGET_CASE["t_end"], TARGET_CASE["map_n"])
