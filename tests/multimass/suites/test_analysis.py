"""Fragility analysis of a runs table (multimass.suites.analysis) on synthetic runs.

The runs are drawn here with known fragility parameters: run i overturns with probability
Φ(ln(im_i/θ)/β) (Baker 2015's lognormal model), from a seeded generator. Expectations
are written out independently (scipy's Nelder–Mead on the Bernoulli likelihood, counts by
hand), never taken from the code under test.
"""

import json
import math

import numpy as np
import pandas as pd
import pytest
from scipy.optimize import minimize
from scipy.stats import norm

from multimass.errors import InputError
from multimass.suites.analysis import (
    DAMAGE_STATES,
    exceedance_counts,
    fragility_curves,
    ida_curves,
    ida_summary,
    im_efficiency,
    pulse_fragility,
    summary_dict,
)

G = 9.81


def record_runs(
    theta=2.0,
    beta=0.4,
    levels=np.geomspace(0.5, 8.0, 10),
    motions=("rec_a", "rec_b", "rec_c", "rec_d"),
    draws=10,
    seed=0,
    im_name="pga",
):
    """A record suite scaled to common PGA levels; overturning ~ Φ(ln(pga/θ)/β).

    θ/α of a run that does not overturn is drawn below 1 (so thresholds 0.5 and 0.8 are
    reached by some), an overturned run has θ/α = 1.
    """
    rng = np.random.default_rng(seed)
    rows = []
    for m, motion in enumerate(motions):
        for j, x in enumerate(levels):
            for d in range(draws):
                over = bool(rng.random() < norm.cdf(math.log(x / theta) / beta))
                r = 1.0 if over else float(rng.uniform(0.0, 0.99))
                rows.append(
                    {
                        "structure": "B6M",
                        "alpha": 0.2,
                        "p": 2.0,
                        "motion": motion,
                        "motion_kind": "record",
                        "im_name": im_name,
                        "im": x,
                        "level": j,
                        "draw": d,
                        "seed": 1000 * m + 10 * j + d,
                        "theta_max_over_alpha": r,
                        "overturned": over,
                        "n_impacts": 3,
                        "status": "overturned" if over else "completed",
                        "pga": x,
                        "pgv": 0.1 * x,
                        "pgd": 0.01 * x,
                        "arias": 0.5 * x * x,
                        "sa_1.000s": 1.5 * x,
                        "omega_p_over_p": np.nan,
                        "amp_over_g_tan_alpha": np.nan,
                        "fp": np.nan,
                        "gamma": np.nan,
                        "nu": np.nan,
                    }
                )
    return pd.DataFrame(rows)


def independent_mle(x, y):
    """(θ, β) maximising Σ y ln Φ(s) + (1-y) ln Φ(-s), s = ln(x/θ)/β (Nelder–Mead)."""
    x, y = np.asarray(x, float), np.asarray(y, float)

    def nll(p):
        s = np.log(x / math.exp(p[0])) / math.exp(p[1])
        return -np.sum(y * norm.logcdf(s) + (1 - y) * norm.logcdf(-s))

    start = [math.log(np.median(x)), 0.0]
    opts = {"xatol": 1e-10, "fatol": 1e-12, "maxiter": 10000}
    ref = minimize(nll, start, method="Nelder-Mead", options=opts)
    assert ref.success, ref.message
    return math.exp(ref.x[0]), math.exp(ref.x[1])


# ------------------------------------------------------------------- recovery
def test_recovers_theta_and_beta_of_overturning_within_the_fisher_band():
    runs = record_runs()
    c = fragility_curves(runs).set_index("measure")
    row = c.loc["overturned"]
    assert row.converged and row.status == 0 and row.grouping == "level"
    assert row.im_name == "pga" and row.unit == "m/s²" and row.n_runs == 400
    # same numbers as an independent maximisation of the Bernoulli likelihood
    th, be = independent_mle(runs.im, runs.overturned)
    assert row.theta == pytest.approx(th, rel=1e-5)
    assert row.beta == pytest.approx(be, rel=1e-4)
    # the truth (2.0, 0.4) inside the 95 % Fisher band, and the band is informative:
    # with 400 runs, σ(ln θ) ≈ 0.05 and σ(ln β) ≈ 0.1, so half-widths of ≈ 10 % and 20 %.
    # One seed: over seeds 0–39 the band held θ in 39 and β in 37 of 40 (95 % expected).
    assert row.theta_low < 2.0 < row.theta_high
    assert row.beta_low < 0.4 < row.beta_high
    assert row.theta_high / row.theta_low < 1.3
    assert row.beta_high / row.beta_low < 2.0
    assert row.band == "fisher" and row.band_level == 0.95
    # the θ/α thresholds are reached earlier: their medians are lower
    assert c.loc["theta_over_alpha>=0.5", "theta"] < c.loc["theta_over_alpha>=0.8", "theta"]
    assert c.loc["theta_over_alpha>=0.8", "theta"] < row.theta
    assert list(c.index) == ["overturned", "theta_over_alpha>=0.5", "theta_over_alpha>=0.8"]
    assert len(DAMAGE_STATES) == 3


def test_bootstrap_band_contains_the_estimate_and_the_truth():
    runs = record_runs()
    row = fragility_curves(runs, measures=["overturned"], bootstrap=200, seed=3).iloc[0]
    assert row.band == "bootstrap" and row.n_resamples == 200
    assert row.theta_low < row.theta < row.theta_high
    assert row.theta_low < 2.0 < row.theta_high
    again = fragility_curves(runs, measures=["overturned"], bootstrap=200, seed=3).iloc[0]
    assert again.theta_low == row.theta_low  # seeded


# ------------------------------------------------------------------- grouping
def scaled_by_factor(seed=2):
    """Records scaled by common factors (im = scale), each record with its own PGA."""
    runs = record_runs(levels=np.geomspace(0.5, 8.0, 8), draws=6, seed=seed, im_name="scale")
    base_pga = {"rec_a": 1.0, "rec_b": 1.7, "rec_c": 0.6, "rec_d": 2.3}
    runs["pga"] = runs["im"] * runs["motion"].map(base_pga)
    return runs


def test_counts_per_level_when_the_im_is_common_and_per_run_when_it_is_not():
    runs = scaled_by_factor()
    per_level = exceedance_counts(runs, measures=["overturned"])
    assert per_level.attrs["grouping"] == "level"
    assert list(per_level["level"]) == list(range(8))
    assert (per_level["n_runs"] == 24).all()
    expect = runs.groupby("level").overturned.sum().to_numpy()
    assert per_level["n_exceed[overturned]"].tolist() == expect.tolist()
    assert per_level["im"].tolist() == pytest.approx(np.geomspace(0.5, 8.0, 8).tolist())

    per_run = exceedance_counts(runs, im="pga", measures=["overturned"])
    assert per_run.attrs["grouping"] == "run"
    assert len(per_run) == len(runs) and (per_run["n_runs"] == 1).all()
    assert per_run["im"].is_monotonic_increasing
    back = runs.loc[per_run["run"]]
    assert per_run["im"].tolist() == back["pga"].tolist()
    assert per_run["n_exceed[overturned]"].tolist() == back["overturned"].astype(int).tolist()

    fit = fragility_curves(runs, im="pga", measures=["overturned"]).iloc[0]
    assert fit.grouping == "run" and fit.n_levels == len(runs) and fit.im_name == "pga"
    th, be = independent_mle(runs.pga, runs.overturned)
    assert fit.theta == pytest.approx(th, rel=1e-5)
    assert fit.beta == pytest.approx(be, rel=1e-4)


def test_per_run_bootstrap_resamples_runs():
    runs = scaled_by_factor()
    row = fragility_curves(runs, im="pga", measures=["overturned"], bootstrap=50, seed=1).iloc[0]
    assert row.band == "bootstrap"
    # resampling within a one-run level would give a zero-width band
    assert row.theta_low < row.theta < row.theta_high
    assert row.beta_high > row.beta_low


# ------------------------------------------------------------------ exclusion
def test_inaccurate_and_failed_runs_are_excluded_and_counted():
    runs = record_runs(draws=5)
    bad = runs.index[(runs.level == 3) & (runs.draw < 2)]  # 4 motions × 2 draws
    runs.loc[bad[:5], "status"] = "inaccurate"
    runs.loc[bad[5:], "status"] = "failed"
    runs.loc[bad, "overturned"] = True  # would change the counts if they were kept
    runs.loc[bad[5:], "theta_max_over_alpha"] = np.nan
    counts = exceedance_counts(runs, measures=["overturned"])
    row = counts.set_index("level").loc[3]
    assert row.n_runs == 20 - 8 and row.n_excluded == 8
    kept = runs[(runs.level == 3) & (runs.draw >= 2)]
    assert row["n_exceed[overturned]"] == kept.overturned.sum()
    assert counts.attrs["n_excluded"] == 8
    assert counts.attrs["excluded"] == {"inaccurate": 5, "failed": 3}
    c = fragility_curves(runs).iloc[0]
    assert c.n_excluded == 8 and c.n_runs == len(runs) - 8

    # every run of a level excluded: the level stays in the table with n_runs = 0
    runs.loc[runs.level == 9, "status"] = "failed"
    counts = exceedance_counts(runs, measures=["overturned"]).set_index("level")
    assert counts.loc[9, "n_runs"] == 0 and counts.loc[9, "n_excluded"] == 20
    assert fragility_curves(runs).iloc[0].n_levels == 9

    # per-run grouping lists excluded runs as rows with n_runs = 0
    per_run = exceedance_counts(runs, im="sa_1.000s", measures=["overturned"])
    assert per_run.attrs["grouping"] == "level"  # sa is 1.5 pga: common per level
    runs["pgv"] = runs["pgv"] * np.where(runs.motion == "rec_a", 1.0, 1.3)
    per_run = exceedance_counts(runs, im="pgv", measures=["overturned"])
    assert per_run.attrs["grouping"] == "run"
    assert (per_run.n_runs == 0).sum() == 28 and (per_run.n_excluded == 1).sum() == 28


def test_an_overturned_run_exceeds_every_threshold_whatever_its_theta():
    # θ/α of an overturned run as recorded before it tipped (0.3): still an exceedance
    runs = record_runs(levels=[1.0, 2.0], draws=3)
    runs["overturned"] = (runs.level == 1) & (runs.draw == 0)
    runs["theta_max_over_alpha"] = np.where(runs.draw == 2, 0.85, 0.3)
    runs["status"] = np.where(runs.overturned, "overturned", "completed")
    c = exceedance_counts(runs, measures=["overturned", 0.8, 1.5]).set_index("level")
    # per level 4 motions × 3 draws; draw 2 (θ/α = 0.85) of each motion exceeds 0.8
    assert c["n_runs"].tolist() == [12, 12]
    assert c["n_exceed[overturned]"].tolist() == [0, 4]
    assert c["n_exceed[theta_over_alpha>=0.8]"].tolist() == [4, 8]
    assert c["n_exceed[theta_over_alpha>=1.5]"].tolist() == [0, 4]


# ----------------------------------------------------------------- degenerate
def test_damage_state_no_run_reaches_is_a_status_not_an_error():
    runs = record_runs(draws=4)
    runs["overturned"] = False
    runs["status"] = "completed"
    runs["theta_max_over_alpha"] = 0.1
    c = fragility_curves(runs).set_index("measure")
    for label in ("overturned", "theta_over_alpha>=0.5", "theta_over_alpha>=0.8"):
        row = c.loc[label]
        assert row.status == 1 and not row.converged
        assert math.isnan(row.theta) and math.isnan(row.beta)
        assert math.isnan(row.theta_low) and row.band is None
        assert "no run exceeded" in row.message
        assert row.theta_bound_low == pytest.approx(8.0)  # above the highest level
    doc = summary_dict(runs)
    assert json.loads(json.dumps(doc))["fragility"][0]["theta"] is None


def test_single_level_and_separated_data_report_their_status():
    runs = record_runs(levels=[1.0, 2.0, 4.0], draws=4)
    runs["overturned"] = runs.im >= 2.0  # separated at 2.0
    runs["theta_max_over_alpha"] = np.where(runs.overturned, 1.0, 0.3)
    row = fragility_curves(runs, measures=["overturned"]).iloc[0]
    assert row.status == 3 and row.beta == 0.0
    assert row.theta_bound_low == 1.0 and row.theta_bound_high == 2.0
    one = runs[runs.level == 1].copy()
    one["overturned"] = one.draw < 2
    row = fragility_curves(one, measures=["overturned"]).iloc[0]
    assert row.status == 4 and math.isnan(row.theta)


# --------------------------------------------------------------- IM efficiency
def test_im_efficiency_ranks_the_im_that_drives_failure_first():
    rng = np.random.default_rng(5)
    n = 600
    pgv = np.exp(rng.uniform(math.log(0.05), math.log(2.0), n))
    over = rng.random(n) < norm.cdf(np.log(pgv / 0.4) / 0.2)  # pgv drives it, β = 0.2
    pga = 9.0 * pgv * np.exp(rng.normal(0.0, 0.5, n))  # pga = pgv × lognormal noise
    runs = pd.DataFrame(
        {
            "structure": "B6M",
            "motion": [f"rec_{i}" for i in range(n)],
            "motion_kind": "record",
            "im_name": "scale",
            "im": 1.0,
            "level": 0,
            "draw": 0,
            "theta_max_over_alpha": np.where(over, 1.0, 0.2),
            "overturned": over,
            "status": np.where(over, "overturned", "completed"),
            "pga": pga,
            "pgv": pgv,
        }
    )
    t = im_efficiency(runs)
    assert t["im"].tolist() == ["pgv", "pga"]
    b = t.set_index("im")["beta"]
    assert b["pgv"] == pytest.approx(0.2, abs=0.08)
    # pga's dispersion adds the noise: √(0.2² + 0.5²) ≈ 0.54
    assert b["pga"] == pytest.approx(math.hypot(0.2, 0.5), abs=0.12)
    assert t.attrs["measure"] == "overturned"


def test_im_efficiency_puts_fits_without_maximum_last():
    runs = record_runs(draws=4)
    runs["pgd"] = 0.01  # constant: a single level, no fit
    t = im_efficiency(runs, ims=["pgd", "pga", "sa_1.000s"])
    assert t["im"].iloc[-1] == "pgd" and math.isnan(t["beta"].iloc[-1])
    assert t["status"].iloc[-1] == 4
    # sa = 1.5 pga: the same β
    assert t["beta"].iloc[0] == pytest.approx(t["beta"].iloc[1], rel=1e-6)


# -------------------------------------------------------------------------- IDA
def ida_table():
    """2 records × 3 draws × 3 levels, θ/α written out; failed run at (b, 2, 1)."""
    r = {
        # (motion, draw): θ/α at levels 0, 1, 2 (≥ 1: overturned)
        ("a", 0): [0.1, 0.4, 1.0],
        ("a", 1): [0.2, 1.0, 1.0],
        ("a", 2): [0.3, 0.5, 0.9],
        ("b", 0): [0.05, 0.2, 0.6],
        ("b", 1): [0.1, 0.3, 0.7],
        ("b", 2): [0.2, 0.9, 1.0],
    }
    im = {"a": [1.0, 2.0, 3.0], "b": [1.5, 3.0, 4.5]}
    rows = []
    for (motion, draw), vals in r.items():
        for lv, v in enumerate(vals):
            rows.append(
                {
                    "structure": "S",
                    "motion": motion,
                    "motion_kind": "record",
                    "im_name": "pga",
                    "im": im[motion][lv],
                    "level": lv,
                    "draw": draw,
                    "theta_max_over_alpha": v,
                    "overturned": v >= 1.0,
                    "status": "overturned" if v >= 1.0 else "completed",
                }
            )
    t = pd.DataFrame(rows).sample(frac=1.0, random_state=0)  # shuffled
    t.loc[(t.motion == "b") & (t.draw == 2) & (t.level == 1), "status"] = "failed"
    return t


def test_ida_curves_are_sorted_and_flag_excluded_runs():
    c = ida_curves(ida_table())
    assert len(c) == 18
    assert c[["motion", "draw", "level"]].values.tolist()[:4] == [
        ["a", 0, 0],
        ["a", 0, 1],
        ["a", 0, 2],
        ["a", 1, 0],
    ]
    assert c["included"].sum() == 17


def test_ida_summary_median_and_first_overturning_level_by_hand():
    s = ida_summary(ida_table()).set_index("motion")
    a, b = s.loc["a"], s.loc["b"]
    # record a: medians of (0.1, 0.2, 0.3), (0.4, 1, 0.5), (1, 1, 0.9)
    assert a.median_theta_over_alpha == pytest.approx([0.2, 0.5, 1.0])
    assert a.fraction_overturned == pytest.approx([0.0, 1 / 3, 2 / 3])
    assert a.im_overturn_50 == 3.0 and a.level_overturn_50 == 2
    # record b, level 1 without the failed draw 2: median of (0.2, 0.3)
    assert b.median_theta_over_alpha == pytest.approx([0.1, 0.25, 0.7])
    assert b.n_runs == [3, 2, 3] and b.n_excluded == 1
    # only 1 of 3 draws overturns at level 2: never ≥ 50 %
    assert math.isnan(b.im_overturn_50) and b.level_overturn_50 == -1
    assert b.im == [1.5, 3.0, 4.5]


def test_ida_exactly_half_of_the_draws_overturning_counts():
    t = ida_table()
    t = t[t.motion == "b"].copy()
    at = (t.draw == 0) & (t.level == 1)
    t.loc[at, ["theta_max_over_alpha", "overturned", "status"]] = [1.0, True, "overturned"]
    s = ida_summary(t).iloc[0]
    # level 1: draw 0 overturned, draw 1 at 0.3, draw 2 failed → 1 of 2 = 50 %
    assert s.fraction_overturned == pytest.approx([0.0, 0.5, 1 / 3])
    assert s.median_theta_over_alpha == pytest.approx([0.1, 0.65, 0.7])
    assert s.im_overturn_50 == 3.0 and s.level_overturn_50 == 1


def test_ida_refuses_duplicate_runs():
    t = ida_table()
    with pytest.raises(InputError, match="share a"):
        ida_curves(pd.concat([t, t.iloc[:1]]))


# ------------------------------------------------------------- pulse fragility
MEDIANS = {1.0: 1.2, 3.0: 2.0, 6.0: 3.5}  # ω_p/p → median a_p/(g tan α) to overturn


def pulse_runs(medians=MEDIANS, beta=0.25, draws=25, seed=4):
    rng = np.random.default_rng(seed)
    amps = np.geomspace(0.5, 10.0, 14)
    rows = []
    for w, th in medians.items():
        for j, a in enumerate(amps):
            for d in range(draws):
                over = bool(rng.random() < norm.cdf(math.log(a / th) / beta))
                rows.append(
                    {
                        "structure": "B6M",
                        "alpha": 0.2,
                        "p": 2.0,
                        "motion": f"mp_w{w:g}",
                        "motion_kind": "pulse",
                        "im_name": "amp_over_g_tan_alpha",
                        "im": a,
                        "level": j,
                        "draw": d,
                        "theta_max_over_alpha": 1.0 if over else 0.3,
                        "overturned": over,
                        "status": "overturned" if over else "completed",
                        "pga": a * G * math.tan(0.2),
                        "omega_p_over_p": w,
                        "amp_over_g_tan_alpha": a,
                    }
                )
    return pd.DataFrame(rows)


def test_pulse_fragility_recovers_the_median_per_frequency():
    pf = pulse_fragility(pulse_runs())
    c = pf.curves.set_index("omega_p_over_p")
    assert list(c.index) == [1.0, 3.0, 6.0]
    for w, th in MEDIANS.items():
        row = c.loc[w]
        assert row.converged
        # 350 runs per frequency: σ(ln θ) ≈ 0.03, so the band is a few % wide
        assert row.theta_low < th < row.theta_high
        assert row.theta == pytest.approx(th, rel=0.1)
        assert row.n_runs == 350
    assert pf.probabilities.shape == (3, 14)
    runs = pulse_runs()
    w3 = runs[runs.omega_p_over_p == 3.0]
    expect = w3.groupby("amp_over_g_tan_alpha").overturned.mean().to_numpy()
    assert pf.probabilities.loc[3.0].to_numpy() == pytest.approx(expect)
    json.dumps(pf.as_dict())


def test_pulse_fragility_refuses_record_runs():
    runs = record_runs(draws=2).drop(columns=["omega_p_over_p", "amp_over_g_tan_alpha"])
    with pytest.raises(InputError, match="omega_p_over_p.*amp_over_g_tan_alpha"):
        pulse_fragility(runs)
    with pytest.raises(InputError, match="no pulse run"):
        pulse_fragility(record_runs(draws=2))


# ------------------------------------------------------------------ bad input
@pytest.mark.parametrize(
    "mutate, match",
    [
        (lambda t: t.iloc[:0], "empty"),
        (lambda t: t.drop(columns=["overturned"]), "overturned"),
        (lambda t: t.drop(columns=["im_name"]), "im_name"),
        (lambda t: t.assign(status="failed"), "no run to analyse"),
        (lambda t: t.assign(status="weird"), "unknown run status"),
        (lambda t: t.assign(im=0.0), "finite and > 0"),
        (lambda t: t.assign(im_name=np.where(t.draw == 0, "pga", "pgv")), "mix"),
        (lambda t: t.assign(structure=np.where(t.draw == 0, "A", "B")), "structure="),
        (lambda t: t.assign(theta_max_over_alpha=np.nan), "theta_max_over_alpha"),
    ],
)
def test_bad_runs_tables_raise_input_error(mutate, match):
    with pytest.raises(InputError, match=match):
        fragility_curves(mutate(record_runs(draws=2)))


def test_bad_arguments_raise_input_error():
    runs = record_runs(draws=2)
    with pytest.raises(InputError, match="damage state"):
        fragility_curves(runs, measures=["collapse"])
    with pytest.raises(InputError, match="bootstrap"):
        fragility_curves(runs, bootstrap=5)
    with pytest.raises(InputError, match="lacks the column"):
        fragility_curves(runs, im="sa_2.000s")
    with pytest.raises(InputError, match="DataFrame"):
        fragility_curves(runs.to_dict())
    # a second structure is fine once one is chosen
    two = pd.concat([runs, runs.assign(structure="other")])
    assert fragility_curves(two, structure="other").iloc[0].structure == "other"


def test_summary_dict_is_json_ready():
    runs = pd.concat([record_runs(draws=3), pulse_runs(draws=3)], ignore_index=True)
    runs = runs[runs.motion_kind == "record"]
    doc = json.loads(json.dumps(summary_dict(runs)))
    assert doc["im_name"] == "pga" and doc["n_runs"] == len(runs)
    assert [r["measure"] for r in doc["fragility"]] == [
        "overturned",
        "theta_over_alpha>=0.5",
        "theta_over_alpha>=0.8",
    ]
    assert {r["motion"] for r in doc["ida"]} == {"rec_a", "rec_b", "rec_c", "rec_d"}
    assert doc["pulse"] is None
    assert {r["im"] for r in doc["im_efficiency"]} == {"pga", "pgv", "pgd", "arias", "sa_1.000s"}
    p = json.loads(json.dumps(summary_dict(pulse_runs(draws=3))))
    assert len(p["pulse"]["curves"]) == 3 and p["ida"] is None
