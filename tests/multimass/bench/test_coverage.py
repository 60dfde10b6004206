"""The identification coverage benchmark (multimass.bench.coverage*): its draws stay in
the stated ranges and reach the truth file; its error and coverage shares are those
worked by hand; its report writes every table and figure."""

import json
import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

import multimass
from multimass.bench import coverage_draws as draws
from multimass.bench.coverage_cases import restitution_rows
from multimass.bench.coverage_report import write_report
from multimass.bench.coverage_stats import add_errors, summarise
from multimass.identify import read_truth

RECORDS = "examples/data/records"


@pytest.mark.parametrize("spec", ["S1", "S2", "S3"])
def test_draws_are_in_the_stated_ranges(spec):
    sp = multimass.from_specimen(spec).specimen
    r = draws.RANGES
    for i in range(12):
        d = draws.draw_case(spec, i, seed=3)
        assert d == draws.draw_case(spec, i, seed=3)  # reproducible
        assert d.cp_table == 1750.0  # paper 001 Table 2, the Dirac-delta models' C_p
        assert 0.6 * 1750.0 <= d.cp <= 1.4 * 1750.0
        assert 0.5 * sp.zeta_1 <= d.zeta1 <= 1.5 * sp.zeta_1
        assert 0.5 * sp.zeta_2 <= d.zeta2 <= 1.5 * sp.zeta_2
        assert abs(d.r_right - sp.r_right) <= 0.03 + 1e-12 or d.r_right == r["mean_max"]
        assert abs(d.r_left - sp.r_left) <= 0.03 + 1e-12
        assert max(d.r_right, d.r_left) <= r["mean_max"]
        assert 0.01 <= d.sigma_r <= 0.04
        assert 100.0 <= d.fs <= 1000.0
        assert 0.01 <= d.noise <= 0.05 and 0.002 <= d.bias <= 0.02
        assert 0.005 <= d.t_offset <= 0.3
        if i % draws.TABLE_EVERY == draws.TABLE_EVERY - 1:
            assert d.kind == "table" and d.theta0 is None and d.record in draws.RECORDS
            assert 1.2 <= d.pga_over_uplift <= 2.5
        else:
            assert d.kind == "free" and 0.05 <= d.theta0 <= 0.15
    assert draws.draw_case(spec, 0, seed=3) != draws.draw_case(spec, 0, seed=4)
    assert not any(draws.draw_case(spec, i, records=False).kind == "table" for i in range(10))


def test_the_truth_file_records_the_hidden_parameters(tmp_path, monkeypatch):
    monkeypatch.setattr(draws, "FREE_T_END", 1.5)  # s: a short test keeps this fast
    d = draws.draw_case("S2", 1, seed=5)
    syn, _ = draws.make_trace(d)
    _, side = syn.write(tmp_path / "case.csv")
    truth = read_truth(side)
    assert truth["impact"]["C_p"] == pytest.approx(d.cp, rel=1e-12)
    assert truth["damping"] == pytest.approx({"zeta_1": d.zeta1, "zeta_2": d.zeta2}, rel=1e-12)
    assert truth["restitution"]["means"] == pytest.approx(
        {"right": d.r_right, "left": d.r_left}, rel=1e-12
    )
    assert truth["restitution"]["spread"] == pytest.approx(d.sigma_r, rel=1e-12)
    assert truth["excitation"]["theta0"] == pytest.approx(d.theta0, rel=1e-12)
    assert truth["sampling"]["fs_hz"] == d.fs and truth["t_offset"] == d.t_offset
    assert truth["noise"]["fraction_of_peak"] == d.noise
    assert truth["bias"]["fraction_of_peak"] == d.bias
    # each channel's bias within ± bias × its peak
    for name, b in truth["bias"]["values"].items():
        assert abs(b) <= d.bias * truth["peak"][name]


def test_a_record_window_is_tapered_and_scaled():
    rec = draws.record_window(f"{RECORDS}/elcentro_1940_NS.dat", "g", 1.0, 3.0)
    assert rec.time[0] == 0.0 and rec.time[-1] == pytest.approx(draws.WINDOW, abs=0.021)
    assert np.max(np.abs(rec.accel)) == pytest.approx(3.0, rel=1e-12)
    assert rec.accel[0] == 0.0 and rec.accel[-1] == pytest.approx(0.0, abs=1e-12)


# --------------------------------------------------------- a worked example, by hand
def _hand_table() -> pd.DataFrame:
    nan = math.nan
    rows = [  # (specimen, quantity, value, truth, std, lo, hi, truth_nominal)
        ("S1", "r", 0.90, 0.905, 0.002, nan, nan, nan),  # err −0.005; ±0.00392: misses
        ("S1", "r", 0.80, 0.82, 0.02, nan, nan, nan),  # err −0.02 (> 0.015); ±0.0392: holds
        ("S2", "r", 0.95, 0.95, nan, nan, nan, nan),  # no interval
        ("S2", "r", 0.93, 0.925, 0.001, 0.92, 0.94, nan),  # [lo, hi] given: holds
        ("S2", "r", 0.93, nan, 0.001, nan, nan, nan),  # no truth (unmatched): left out
        ("S1", "cp", 1900.0, 2000.0, 50.0, nan, nan, nan),  # −5 %; up to 1998: misses
        ("S1", "cp", 2300.0, 2000.0, 200.0, nan, nan, nan),  # +15 %; from 1908: holds
        ("S1", "r_mean_right", 0.93, 0.935, 0.003, nan, nan, 0.95),  # holds; nominal not
    ]
    cols = ["specimen", "quantity", "value", "truth", "std", "lo", "hi", "truth_nominal"]
    return pd.DataFrame(rows, columns=cols).assign(estimator="restitution")


def test_errors_and_coverage_of_a_hand_made_table():
    s = summarise(add_errors(_hand_table())).set_index(["specimen", "quantity"])
    r = s.loc[("all", "r")]
    # |err| = 0.005, 0.02, 0, 0.005: median 0.005; 95th percentile (linear) of the
    # sorted [0, 0.005, 0.005, 0.02] at position 2.85: 0.005 + 0.85 × 0.015 = 0.01775
    assert r["n"] == 4 and r["median"] == pytest.approx(0.005)
    assert r["p95"] == pytest.approx(0.01775) and r["max"] == pytest.approx(0.02)
    assert r["within"] == pytest.approx(3 / 4)
    assert r["n_interval"] == 3 and r["coverage"] == pytest.approx(2 / 3)
    assert math.isnan(r["coverage_ill_posed"])  # no status: none is ill-posed
    assert s.loc[("S1", "r"), "coverage"] == pytest.approx(1 / 2)
    assert s.loc[("S2", "r"), "coverage"] == 1.0 and s.loc[("S2", "r"), "n_interval"] == 1
    cp = s.loc[("S1", "cp")]  # relative errors −5 % and +15 %
    assert cp["median"] == pytest.approx(0.10) and cp["max"] == pytest.approx(0.15)
    assert cp["within"] == pytest.approx(1 / 2) and cp["coverage"] == pytest.approx(1 / 2)
    m = s.loc[("S1", "r_mean_right")]
    assert m["coverage"] == 1.0 and m["coverage_nominal"] == 0.0
    assert math.isnan(s.loc[("S1", "r"), "coverage_nominal"])


def _estimate():
    impacts = pd.DataFrame(
        {
            "t": [0.50, 1.02, 1.50, 2.0],
            "corner": ["left", "right", "left", "right"],
            "r": [0.86, 0.93, 0.85, 0.99],
            "r_std": [0.004, 0.003, 0.01, 0.01],
            "theta_before": [0.1, 0.08, 0.06, 0.05],
            "theta_after": [0.08, 0.06, 0.05, 0.04],
            "estimated": [True, True, True, False],
        }
    )
    return SimpleNamespace(
        impacts=impacts, r_mean_right=0.93, r_mean_left=0.855, sigma_r=0.006,
        alignment={"t_offset": 0.101, "theta_bias": 0.0, "theta0": 0.099},
    )  # fmt: skip


def _truth():
    return {
        "impacts": [  # the 1.00 s impact lands left: the estimate's right one is 1.03 s
            {"t": 0.49, "corner": "left", "r": 0.87},
            {"t": 1.00, "corner": "left", "r": 0.5},
            {"t": 1.03, "corner": "right", "r": None},  # no Dirac-delta force: r = 1
            {"t": 1.52, "corner": "left", "r": 0.83},
        ],
        "restitution": {"means": {"right": 0.94, "left": 0.86}, "spread": 0.02},
        "excitation": {"kind": "free_release", "theta0": 0.1},
        "t_offset": 0.1,
        "bias": {"values": {"theta": 0.001}},
    }


def test_estimates_meet_the_truth_of_their_impact():
    rows = pd.DataFrame(restitution_rows(_estimate(), _truth())).set_index("quantity")
    r = rows.loc["r"]
    np.testing.assert_allclose(r["truth"], [0.87, 1.0, 0.83])  # nearest, same corner
    assert rows.loc["r_mean_left", "truth"] == pytest.approx(0.85)  # (0.87 + 0.83) / 2
    assert rows.loc["r_mean_right", "truth"] == pytest.approx(1.0)
    assert rows.loc["r_mean_right", "truth_nominal"] == 0.94
    # pooled about the corner means: ((0.02² + 0.02²) / (3 − 2)) ** 0.5
    assert rows.loc["sigma_r", "truth"] == pytest.approx(math.sqrt(2 * 0.02**2))
    assert rows.loc["theta0", "truth"] == 0.1 and rows.loc["theta_bias", "truth"] == 0.001
    assert rows.loc["t_offset", "value"] == 0.101
    assert math.isnan(rows.loc["r_mean_right", "std"])  # none reported: no interval


def test_the_report_writes_its_tables_and_figures(tmp_path):
    rows = _hand_table().assign(case="S1-000", kind="free").to_dict(orient="records")
    case = draws.draw_case("S1", 0).to_dict() | {"restitution_s": 10.0,
                                                  "restitution_status": "estimated"}  # fmt: skip
    other = draws.draw_case("S2", 0).to_dict() | {"error": "SolverError: failed"}
    with open(tmp_path / "results.jsonl", "w") as fh:
        fh.write(json.dumps({"case": case, "rows": rows}) + "\n")
        fh.write(json.dumps({"case": other, "rows": []}) + "\n")
        fh.write('{"case": {"cut sho')  # an interrupted write is skipped
    res = write_report(tmp_path)
    for name in ("estimates.csv", "cases.csv", "summary.json", "coverage.md", *res["charts"]):
        assert (tmp_path / name).stat().st_size > 0
    assert len(res["charts"]) == 3
    assert res["facts"]["cases"] == 2 and res["facts"]["cases whose generation or run failed"] == 1
    text = (tmp_path / "coverage.md").read_text()
    assert "| all | per-impact r | 4 |" in text and "| 67 % [9–99 %] |" in text  # 2 of 3
    # the same rows again: their run claims every parameter estimated
    assert text.split("## Only the runs")[1].count("| all | per-impact r | 4 |") == 1


def test_bench_coverage_runs_the_cases_and_reports(tmp_path, monkeypatch, capsys):
    """``multimass bench --coverage --smoke``: one S1 case (the estimators replaced by the
    hand-made rows, so only the wiring is tested), its tables and figures."""
    from multimass.bench import coverage
    from multimass.cli import main

    seen = []

    def fake(draw, records, with_cal):
        seen.append((draw.case, records, with_cal))
        rows = _hand_table().assign(case=draw.case, kind=draw.kind).to_dict(orient="records")
        return {"case": draw.to_dict() | {"restitution_s": 1.0, "restitution_status": "ok"},
                "rows": rows}  # fmt: skip

    monkeypatch.setattr(coverage, "run_case", fake)
    assert main(["bench", "--coverage", "--smoke", "--out", str(tmp_path)]) == 0
    assert seen == [("S1-000", None, False)]
    assert "per-impact r" in capsys.readouterr().out
    assert (tmp_path / "coverage_per_quantity.png").is_file()
    assert main(["bench", "--coverage", "--smoke", "--out", str(tmp_path / "b"),
                 "--records", str(tmp_path / "none")]) != 0  # fmt: skip
    assert "`records`" in capsys.readouterr().err


def test_parameters_the_estimate_reports_are_compared_with_their_truth():
    """An estimate's ``parameters`` (status, value, std, 95 % interval): the estimated
    and ill-posed ones are rows with their interval; given, fixed and unused ones not."""
    est = _estimate()
    est.parameters = {
        "cp": {"status": "ill-posed", "value": 2100.0, "std": 300.0, "interval": [1500.0, 2900.0]},
        "zeta1": {"status": "fixed by the specimen file", "value": 0.005, "std": None},
        "zeta2": {"status": "given", "value": 0.015, "std": None},
        "theta0": {
            "status": "estimated",
            "value": 0.0995,
            "std": 1e-4,
            "interval": [0.0993, 0.0997],
        },  # fmt: skip
    }
    truth = _truth() | {"impact": {"C_p": 2000.0}, "damping": {"zeta_1": 0.004, "zeta_2": 0.01}}
    rows = pd.DataFrame(restitution_rows(est, truth)).set_index("quantity")
    assert "zeta1" not in rows.index and "zeta2" not in rows.index
    cp = rows.loc["cp"]
    assert (cp["value"], cp["truth"], cp["lo"], cp["hi"]) == (2100.0, 2000.0, 1500.0, 2900.0)
    assert cp["status"] == "ill-posed"
    assert rows.loc["theta0", "value"] == 0.0995 and rows.loc["theta0", "hi"] == 0.0997
    s = summarise(add_errors(rows.reset_index().assign(specimen="S1", estimator="restitution")))
    s = s.set_index(["specimen", "quantity"])
    # the ill-posed C_p counts in its own column, not in the 95 % coverage
    assert s.loc[("S1", "cp"), "n_ill_posed"] == 1 and s.loc[("S1", "cp"), "n_interval"] == 0
    assert s.loc[("S1", "cp"), "coverage_ill_posed"] == 1.0  # 2000 in [1500, 2900]
    assert math.isnan(s.loc[("S1", "cp"), "coverage"])  # its only one is ill-posed
    assert s.loc[("S1", "theta0"), "coverage"] == 0.0  # 0.1 is outside [0.0993, 0.0997]
    # the corner means' std and interval, where the estimate reports them
    est.r_mean_std = {"right": None, "left": {"std": 0.01, "interval": [0.835, 0.875], "n": 2}}
    rows = pd.DataFrame(restitution_rows(est, truth)).set_index("quantity")
    assert (rows.loc["r_mean_left", "lo"], rows.loc["r_mean_left", "hi"]) == (0.835, 0.875)
    assert math.isnan(rows.loc["r_mean_right", "std"])


@pytest.mark.parametrize("k, n", [(34, 38), (19, 22), (14, 17), (0, 5), (5, 5), (95, 100)])
def test_coverage_interval_is_the_exact_binomial_one(k, n):
    from scipy import stats

    from multimass.bench.coverage_stats import coverage_interval

    lo, hi = coverage_interval(k, n)
    # the defining tail probabilities (Clopper & Pearson 1934): at p = lo, P(X ≥ k) = 2.5 %;
    # at p = hi, P(X ≤ k) = 2.5 % (scipy's binomial, not the β quantiles used)
    if k > 0:
        assert stats.binom.sf(k - 1, n, lo) == pytest.approx(0.025, rel=1e-6)
    else:
        assert lo == 0.0
    if k < n:
        assert stats.binom.cdf(k, n, hi) == pytest.approx(0.025, rel=1e-6)
    else:
        assert hi == 1.0
    # statsmodels' "beta" interval, an implementation not written here
    from statsmodels.stats.proportion import proportion_confint

    assert (lo, hi) == pytest.approx(proportion_confint(k, n, 0.05, "beta"), abs=1e-12)
