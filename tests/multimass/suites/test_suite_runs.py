"""Suites: the TOML, the runs, determinism, resume, bad input.

References: IMs of the scaled records are recomputed here with `multimass.analysis.intensity` on
`Record.scaled` (the suite scales IMs from unit-scale values: PGA, PGV, PGD and Sa
linearly, Arias with the square); the M&P pulse's peak is MPShape's exact peak.
"""

import dataclasses
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from multimass import G, InputError
from multimass.analysis import intensity as im
from multimass.suites.runs import RUN_COLUMNS, SuiteMismatch, _draw_options, run_suite
from multimass.suites.spec import PulseSet, Suite

ROOT = Path(__file__).resolve().parents[3]
# B6M's uplift acceleration g tan α = g b/h: b = 0.045 m, h = 0.2025 m, g = 9.81 m/s²
# (paper 004, Table 1: h/b = 4.5, α = 0.2187 rad; specimens/data/B6M.toml)
B6M_G_TAN_ALPHA = 9.81 * 0.045 / 0.2025
SUITES = ROOT / "examples" / "suites"
RECORDS = ROOT / "examples" / "data" / "records"


def _toml(tmp_path, text: str, name="suite.toml") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


S1_HEAD = """
name = "test"
[structure]
specimen = "S1"
[model]
impact = "DD5"
t_free_s = 2.0
[monte_carlo]
draws = 2
seed = 3
"""


def _record(path, units=None, name=None):
    lines = ["[[records]]", f'path = "{path}"']
    if units:
        lines.append(f'units = "{units}"')
    if name:
        lines.append(f'name = "{name}"')
    return "\n".join(lines) + "\n"


def _block_suite(**kw):
    b = Suite.from_toml(SUITES / "B6M_mp_pulses.toml")
    small = dict(
        pulses=PulseSet((1.0, 3.0), b.pulses.gamma, b.pulses.nu), levels=b.levels[::3], draws=3
    )
    return dataclasses.replace(b, **(small | kw))


def test_the_bundled_suites_read():
    b = Suite.from_toml(SUITES / "B6M_mp_pulses.toml")
    assert b.n_runs == 10 * 12 * 50 and b.k.kind == "normal" and b.restitution == "modified"
    s = Suite.from_toml(SUITES / "S1_records.toml")
    assert s.n_runs == 5 * 10 * 10 and len(s.records) == 5 and s.impact == "DD5"
    assert s.levels[0] == pytest.approx(0.2 * G) and s.levels[-1] == pytest.approx(1.6 * G)


def test_record_runs_reach_their_level_and_carry_exact_ims():
    s = Suite.from_toml(SUITES / "S1_records.toml")
    s = dataclasses.replace(s, records=s.records[2:4], levels=s.levels[[0, 5]], draws=2)
    r = run_suite(s, executor="serial", progress=False).runs
    assert list(r.columns[: len(RUN_COLUMNS)]) == RUN_COLUMNS
    assert len(r) == 2 * 2 * 2 and set(r.status) <= {"completed", "overturned"}
    np.testing.assert_allclose(r.pga, r.im, rtol=1e-12)
    for _, row in r.iloc[[0, 5]].iterrows():
        rec = next(x for x in s.records if x.name == row.motion).scaled(row.scale)
        assert row.arias == pytest.approx(im.arias_intensity(rec.time, rec.accel), rel=1e-12)
        assert row.pgv == pytest.approx(im.pgv(rec.time, rec.accel), rel=1e-12)
        sa = im.spectral_acceleration(rec.time, rec.accel, np.array([1.0]))[0]
        assert row["sa_1.000s"] == pytest.approx(sa, rel=1e-12)
    assert not r.theta_max_over_alpha.isna().any()
    assert (r.overturned == (r.status == "overturned")).all()


def test_pulse_runs_are_scaled_in_a_p_over_g_tan_alpha():
    r = run_suite(_block_suite(), executor="serial", progress=False).runs
    assert len(r) == 2 * 4 * 3
    np.testing.assert_array_equal(r.amp_over_g_tan_alpha, r.im)
    g_tan_alpha = B6M_G_TAN_ALPHA
    np.testing.assert_allclose(r.pga, r.im * g_tan_alpha, rtol=2e-4)  # sampled peak ≤ exact
    assert (r.pga <= r.im * g_tan_alpha * (1 + 1e-12)).all()
    assert set(r.omega_p_over_p) == {1.0, 3.0}
    k = r.restitution_draw
    assert k.between(0.0, 1.0).all() and k.nunique() == len(r)  # one k per run
    assert r.overturned.any() and (~r.overturned).any()


def test_k_draws_follow_the_distribution():
    s = _block_suite()
    ks = np.array([_draw_options(s, seed)[1] for seed in range(2000)])
    assert ks.mean() == pytest.approx(0.82, abs=0.004)  # σ/√n = 0.0011
    assert ks.std() == pytest.approx(0.05, rel=0.06)


def test_results_do_not_depend_on_executor_chunks_or_workers():
    s = _block_suite()
    a = run_suite(s, executor="serial", progress=False).runs
    b = run_suite(s, executor="process", workers=2, chunk_runs=5, progress=False).runs
    pd.testing.assert_frame_equal(a, b)


def test_resume_skips_finished_chunks_and_refuses_another_suite(tmp_path):
    s = _block_suite()
    first = run_suite(s, out=tmp_path, executor="serial", chunk_runs=5, progress=False)
    parts = sorted((tmp_path / "runs").glob("part-*.parquet"))
    assert len(parts) == math.ceil(len(first.runs) / 5)
    parts[2].unlink()
    again = run_suite(s, out=tmp_path, executor="serial", chunk_runs=5, progress=False)
    assert again.computed == 5 and again.resumed == len(first.runs) - 5
    pd.testing.assert_frame_equal(again.runs, first.runs)
    with pytest.raises(SuiteMismatch, match="another suite"):
        run_suite(dataclasses.replace(s, draws=4), out=tmp_path, executor="serial", progress=False)


def test_a_resumed_column_suite_keeps_the_method_its_runs_used(tmp_path, monkeypatch):
    # the manifest records the method the runs used; a resumed suite reads it there and
    # does not choose again (method "auto" times a sample run each way: its choice can
    # change between calls or versions, and a suite's runs must all use one method)
    import json

    import multimass.suites.runs as runs

    s, out = _column_suite(), tmp_path / "out"
    first = run_suite(s, out=out, executor="serial", chunk_runs=2, progress=False)
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["method"] == "DOP853" == first.chosen["method_choice"]["method"]

    used = []
    real_estimate = runs.estimate
    monkeypatch.setattr(
        runs, "estimate", lambda *a, **kw: used.append(kw["method"]) or real_estimate(*a, **kw)
    )
    monkeypatch.setattr(runs, "resolve", lambda *a, **kw: pytest.fail("chose again on resume"))

    def resume(record):
        (out / "manifest.json").write_text(json.dumps(record))
        (out / "runs" / "part-00001.parquet").unlink()
        return run_suite(s, out=out, executor="serial", chunk_runs=2, progress=False)

    # as if auto had picked the exponential method: the resumed runs use it too
    again = resume(manifest | {"method": "exponential"})
    assert used[-1] == "exponential" and again.computed == 2
    assert again.chosen == first.chosen
    # a folder written before the method was recorded: its runs used DOP853, the default
    # of every version before auto; the manifest gains the record
    old = {k: v for k, v in manifest.items() if k not in ("method", "chosen")}
    again = resume(old)
    assert used[-1] == "DOP853" and again.computed == 2
    pd.testing.assert_frame_equal(again.runs, first.runs)
    assert json.loads((out / "manifest.json").read_text())["method"] == "DOP853"


# --------------------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    "body, words",
    [
        ("[intensity]\nmeasure = 'pga'\nlevels = [0.5]\n", ["no motion", "[[records]]"]),
        (
            "[intensity]\nmeasure = 'pga'\nlevels = [0.5]\n"
            + _record(RECORDS / "kobe_1995.dat", "g"),
            ["kobe_1995", "units", "'g'", "m/s2 read as g"],  # the record's own check
        ),
        (
            "[intensity]\nmeasure = 'pga'\nlevels = [0.5]\n"
            + _record(RECORDS / "kobe_1995.dat", "cm/s2")
            + _record(RECORDS / "northridge_1994.dat", "m/s2"),
            ["different units", "kobe_1995", "northridge_1994", "`units` of its own file"],
        ),
        (
            "[intensity]\nmeasure = 'pgv'\nlevels = [0.5]\nunit = 'g'\n"
            + _record(RECORDS / "kobe_1995.dat", "m/s2"),
            ["intensity.unit", "m/s"],
        ),
        ("[intensity]\nmeasure = 'pga'\nlevels = []\n", ["intensity.levels", "at least one"]),
        ("[intensity]\nmeasure = 'pgaa'\nlevels = [1]\n", ["intensity.measure", "pgv"]),
        (
            "[intensity]\nmeasure = 'pga'\nlevels = [0.5]\nspeed = 2\n",
            ["unknown key", "intensity.speed"],
        ),
        (
            "[intensity]\nmeasure = 'pga'\nlevels = [0.5]\n" + _record(RECORDS / "none.dat", "g"),
            ["path", "no such file"],
        ),
    ],
)
def test_bad_suites_are_named_errors(tmp_path, body, words):
    with pytest.raises(InputError) as err:
        Suite.from_toml(_toml(tmp_path, S1_HEAD + body))
    for w in words:
        assert w in str(err.value), (w, str(err.value))


def test_sa_at_a_period_the_record_cannot_resolve(tmp_path):
    body = "[intensity]\nmeasure = 'sa'\nperiod_s = 0.02\nlevels = [0.5]\nunit = 'g'\n"
    s = Suite.from_toml(
        _toml(tmp_path, S1_HEAD + body + _record(RECORDS / "kobe_1995.dat", "m/s2"))
    )
    with pytest.raises(InputError) as err:
        run_suite(s, executor="serial", progress=False)
    for w in ("kobe_1995", "dt = 0.02", "Sa periods", "finer record"):
        assert w in str(err.value), (w, str(err.value))


def test_a_level_no_record_reaches_undistorted(tmp_path):
    body = "[intensity]\nmeasure = 'pga'\nlevels = [0.5, 5.0]\nunit = 'g'\n"
    s = Suite.from_toml(
        _toml(tmp_path, S1_HEAD + body + _record(RECORDS / "elcentro_1940_NS.dat", "g", "EC"))
    )
    with pytest.raises(InputError) as err:
        run_suite(s, executor="serial", progress=False)
    for w in ("'EC'", "level 1", "max_scale = 10", "Lower the highest level"):
        assert w in str(err.value), (w, str(err.value))


def test_k_needs_the_modified_restitution(tmp_path):
    text = (
        'name = "x"\n[structure]\nspecimen = "B6M"\n[model]\nrestitution = "housner"\n'
        "[monte_carlo]\nk = { distribution = 'uniform', low = 0.5, high = 0.9 }\n"
        "[intensity]\nmeasure = 'amp_over_g_tan_alpha'\nlevels = [2.0]\n"
        "[pulses]\nomega_p_over_p = [2.0]\n"
    )
    with pytest.raises(InputError, match="restitution = 'modified'"):
        Suite.from_toml(_toml(tmp_path, text))


def test_drawn_pulse_shapes_vary_per_run_within_their_ranges():
    r = run_suite(_block_suite(), executor="serial", progress=False).runs
    assert r.gamma.between(1.5, 3.0).all() and r.nu.between(0.0, 3.1416).all()
    assert r.gamma.nunique() == len(r) and r.nu.nunique() == len(r)
    assert set(r.motion) == {"mp_wp1", "mp_wp3"}
    # each run's own IMs: its sampled peak is the a_p it was scaled to (MPShape's exact peak)
    g_tan_alpha = B6M_G_TAN_ALPHA
    np.testing.assert_allclose(r.pga, r.amp_over_g_tan_alpha * g_tan_alpha, rtol=2e-4)
    assert r.pgv.nunique() == len(r)  # PGV depends on the drawn shape


def test_drawn_shapes_need_a_peak_acceleration_measure(tmp_path):
    text = (
        'name = "x"\n[structure]\nspecimen = "B6M"\n'
        "[intensity]\nmeasure = 'pgv'\nlevels = [0.5]\n"
        "[pulses]\nomega_p_over_p = [2.0]\n"
        "gamma = { distribution = 'uniform', low = 1.5, high = 3.0 }\n"
    )
    with pytest.raises(InputError, match="amp_over_g_tan_alpha or pga"):
        Suite.from_toml(_toml(tmp_path, text))


def test_sa_columns_are_the_listed_periods_and_the_measure_s(tmp_path):
    rec = _record(RECORDS / "kobe_1995.dat", "m/s2")
    body = "[intensity]\nmeasure = 'sa'\nperiod_s = 0.5\nlevels = [0.5]\nunit = 'g'\n"
    assert Suite.from_toml(_toml(tmp_path, S1_HEAD + body + rec)).sa_periods == (0.5,)
    body = "[intensity]\nmeasure = 'pga'\nlevels = [0.5]\nunit = 'g'\nsa_periods_s = [0.2, 1.0]\n"
    assert Suite.from_toml(_toml(tmp_path, S1_HEAD + body + rec)).sa_periods == (0.2, 1.0)
    body = "[intensity]\nmeasure = 'pga'\nlevels = [0.5]\nunit = 'g'\n"
    assert Suite.from_toml(_toml(tmp_path, S1_HEAD + body + rec)).sa_periods == ()


def test_per_run_seeds_are_the_children_of_the_suite_seed():
    """Each run's seed is child i of SeedSequence(suite seed) (its first 64 state bits,
    top bit dropped), derived when the run is made: the seeds of existing suites are
    unchanged, whatever the chunking."""
    s = _block_suite(draws=2)
    r = run_suite(s, executor="serial", progress=False, chunk_runs=5).runs
    children = np.random.SeedSequence(s.seed).spawn(len(r))  # numpy, independently
    expected = [int(c.generate_state(1, np.uint64)[0]) & (2**63 - 1) for c in children]
    assert r.seed.tolist() == expected


def test_a_suite_over_the_budget_is_refused_before_its_seeds_or_runs(monkeypatch):
    """draws = 1e9 (8e9 runs) is refused at once with the estimate (runs × the cost of
    the longest run), the memory of its table and the fix — it went silent while a list
    of 8e9 seeds was made. No seed list of the whole suite is ever built."""
    import multimass.sweeps.seeding as seeding

    def no_list(base, n, **kw):
        raise AssertionError(f"a list of {n} seeds was made")

    monkeypatch.setattr(seeding, "job_seeds", no_list)
    monkeypatch.setattr("multimass.suites.runs.job_seeds", no_list, raising=False)
    s = _block_suite(draws=10**9)
    with pytest.raises(InputError) as err:
        run_suite(s, executor="serial", progress=False)
    msg = str(err.value)
    for words in (
        "of 8,000,000,000 runs",
        "over the budget of 1 h",
        "(2 motions × 4 levels × 1,000,000,000 draws)",
        "lower [monte_carlo] draws",
        "--max-hours",
        "TiB",
    ):
        assert words in msg, (words, msg)


def test_the_suite_budget_is_max_hours_and_counts_every_run(tmp_path, capsys):
    """The whole suite's estimate is n × the longest run's cost, shared among a local
    pool's workers: a budget below it refuses the suite (Python and CLI), the default
    budget runs it."""
    from multimass.cli import main
    from multimass.progress import RunCost
    from multimass.suites.runs import ROW_BYTES, suite_cost

    s = _block_suite(draws=1, levels=_block_suite().levels[:1])
    one = RunCost(steps=10.0, seconds=2.0, memory=0.0, basis="")
    assert suite_cost(s, 5, one, "serial").seconds == 10.0
    assert suite_cost(s, 5, one, "process", workers=2).seconds == 5.0
    assert suite_cost(s, 5, one, "serial").memory == 5 * ROW_BYTES
    with pytest.raises(InputError, match="of 2 runs: estimated .* over the budget of 3.6e-06 s"):
        run_suite(s, executor="serial", progress=False, max_hours=1e-9)
    assert len(run_suite(s, executor="serial", progress=False).runs) == 2
    text = (
        (SUITES / "B6M_mp_pulses.toml").read_text().replace("draws = 50 ", "draws = 1_000_000_000")
    )
    path = _toml(tmp_path, text)
    assert main(["suite", str(path), "--out", str(tmp_path / "o"), "--executor", "serial"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "of 120,000,000,000 runs" in err, err


def _column_suite():
    import multimass

    rec = multimass.read_record(RECORDS / "kobe_1995.dat", units="m/s2", name="Kobe")
    short = type(rec).from_arrays(rec.time[:300], rec.accel[:300], units="m/s2", name="Kobe 6 s")
    return Suite(
        name="S1 under Kobe",
        structure=multimass.column("S1"),
        records=(short,),
        measure="pga",
        levels=np.array([0.8, 1.0]) * G,
        draws=4,
        impact="DD5",
        t_free=1.0,
    )


def test_column_suites_run_in_batches_with_the_per_run_table(monkeypatch):
    # a batch of column runs shares its preparation (`outcome_summaries`): the table must be
    # the one of a run per job (`suite_run`), run for run
    from multimass.suites import runs as runs_mod

    s = _column_suite()
    batched = run_suite(s, executor="serial", progress=False).runs
    pooled = run_suite(s, executor="process", workers=2, chunk_runs=3, progress=False).runs
    pd.testing.assert_frame_equal(batched, pooled)  # records sent unscaled, scaled in workers
    monkeypatch.setattr(runs_mod, "COLUMNS_BATCHED", False)
    pd.testing.assert_frame_equal(batched, run_suite(s, executor="serial", progress=False).runs)
    assert batched.n_impacts.gt(0).all() and batched.theta_max_over_alpha.nunique() == 8


def test_the_suite_wall_time_counts_reading_its_motions(monkeypatch):
    # `wall_time_s` is the whole call: a step before the runs made 0.5 s slower is counted
    import time

    from multimass.suites import runs as runs_mod

    read = runs_mod.motions
    monkeypatch.setattr(runs_mod, "motions", lambda suite: time.sleep(0.5) or read(suite))
    r = run_suite(_block_suite(draws=1), executor="serial", progress=False)
    assert r.wall_time_s >= 0.5 and "the motions" in r.summary()["wall_time_covers"]
