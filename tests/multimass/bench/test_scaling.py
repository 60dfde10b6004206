"""``multimass bench --scaling`` (multimass/bench/scaling.py).

The smoke configuration (seconds; its numbers mean nothing) runs the whole
pipeline and writes every file; only the structure is checked (benchmarks are
not timed tests). The exponent fit is checked on synthetic power laws.
"""

import json

import numpy as np
import pytest

from multimass.bench.config import scaling_preset
from multimass.bench.scaling import FILES, fit_exponent, uniform_column
from multimass.cli import main
from multimass.errors import InputError


def test_fit_recovers_a_known_exponent():
    n = np.array([1e2, 1e3, 1e4, 1e5, 1e6])
    fit = fit_exponent(n, 3.0 * n**1.5)  # cost = 3 n^1.5, exactly
    assert fit["exponent"] == pytest.approx(1.5, abs=1e-12)
    assert fit["prefactor"] == pytest.approx(3.0, rel=1e-10)
    assert fit["stderr"] == pytest.approx(0.0, abs=1e-10)
    assert fit["size_range"] == pytest.approx([1e2, 1e6]) and fit["points"] == 5


def test_fit_of_noisy_data_brackets_the_exponent():
    rng = np.random.default_rng(15)  # seeded: 5 % log-normal noise on cost = 0.2 N^-0.7
    n = np.geomspace(1, 40, 12)
    fit = fit_exponent(n, 0.2 * n**-0.7 * np.exp(rng.normal(0, 0.05, n.size)))
    assert abs(fit["exponent"] + 0.7) < 4 * fit["stderr"] and fit["stderr"] < 0.05


def test_fit_of_two_points_is_their_slope_and_of_one_is_none():
    fit = fit_exponent([1, 2], [4.0, 2.0])  # ideal 2-worker scaling
    assert fit["exponent"] == pytest.approx(-1.0) and fit["stderr"] is None
    assert fit_exponent([5], [1.0])["exponent"] is None


def test_uniform_column_keeps_the_height_and_mass():
    s = uniform_column(4)
    assert s.n == 4
    assert s.H == pytest.approx([1.93 * i / 4 for i in (1, 2, 3, 4)])  # S1's top node: 1.93 m
    assert s.m == pytest.approx([226.1 / 4] * 4)  # S1's masses sum to 226.1 kg


def test_unknown_scaling_preset_names_the_choices():
    with pytest.raises(InputError, match="full, quick, smoke"):
        scaling_preset("huge")


def test_smoke_scaling_writes_every_file(tmp_path, capsys):
    out = tmp_path / "scaling"
    assert main(["bench", "--smoke", "--scaling", "--out", str(out), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    for name in FILES:
        assert (out / name).is_file() and (out / name).stat().st_size > 0, name
    assert json.loads((out / "scaling.json").read_text()) == res
    cfg = scaling_preset("smoke")
    # map cost against cells: one point per grid for each method, all cells counted
    cells = res["cells"]
    assert set(cells["series"]) == {"brute_force", "adaptive"}  # `adaptive=True` exists here
    for name, pts in cells["series"].items():
        assert [p["side"] for p in pts] == list(cfg.map_sides)
        for p in pts:
            assert p["cells"] == p["side"] ** 2 and 0 < p["computed"] <= p["cells"]
            assert set(p["seconds"]) == {"median", "min", "max", "values"}
            assert len(p["seconds"]["values"]) == cfg.repeats
        assert cells["fits"][name]["points"] == len(cfg.map_sides)
    assert all(p["computed"] == p["cells"] for p in cells["series"]["brute_force"])
    # against workers, the machine's own scaling beside it
    w = res["workers"]
    assert w["workers"] == [1, 2] and set(w["fits"]) == {"map", "machine"}
    assert set(w["map_seconds"]) == set(w["machine_seconds"]) == {"1", "2"}
    assert set(w["speedup_2_workers"]) == {"map", "machine"}
    # the column engine against N, both paths (smoke: every run within budget)
    nd = res["nodes"]
    paths = {"compiled", "compiled_rk", "exponential", "scipy"}
    assert set(nd["series"]) == paths and nd["skipped"] == []
    for pts in nd["series"].values():
        assert [p["N"] for p in pts] == list(cfg.nodes)
        assert all(p["n_rhs"] > 0 and p["outcome"] == "completed" for p in pts)
    for key in (*paths, "compiled_rk_per_rhs", "scipy_per_rhs"):
        assert isinstance(nd["fits"][key]["exponent"], float)
    assert "compiled_per_rhs" not in nd["fits"]  # its full contact takes no RHS calls
    assert "exponential_per_rhs" not in nd["fits"]
    closed, rk = nd["series"]["compiled"], nd["series"]["compiled_rk"]
    # (the smoke run ends before any full contact; then the two are the same run)
    assert all(a["n_rhs"] <= b["n_rhs"] and a["events"] == b["events"] for a, b in zip(closed, rk))
    md = (out / "scaling.md").read_text()
    for heading in ("## Map cost against cells", "## Map cost against workers", "## Column engine"):
        assert heading in md
    assert md.count("| series | exponent |") == 3


def test_over_budget_runs_are_skipped_and_said():
    import dataclasses

    from multimass.bench import scaling

    cfg = dataclasses.replace(
        scaling_preset("smoke"), nodes=(1,), compiled_budget_s=1e-9, scipy_budget_s=1e-9
    )
    res = scaling.nodes_series(cfg, lambda m: None)
    assert res["series"] == {"compiled": [], "compiled_rk": [], "exponential": [], "scipy": []}
    assert {(s["N"], s["backend"]) for s in res["skipped"]} == {
        (1, "compiled"),
        (1, "compiled_rk"),
        (1, "exponential"),
        (1, "scipy"),
    }
    assert res["fits"]["scipy"]["exponent"] is None
