"""Rocking spectra (paper 001, Section 4.4, Figs 10 and 12)."""

import numpy as np
import pytest

from multimass import G, InputError, read_two_column
from multimass.sweeps.ranges import parse_range
from multimass.sweeps.spectra import pulse_spectrum, record_spectrum


def test_pulse_spectrum_falls_with_frequency():
    # paper 001, Fig 10 (top): at fixed amplitude, θ_max falls as the pulse gets faster
    sp = pulse_spectrum(
        "S1", "cosine", [8.0, 15.0, 25.0], 0.4 * G, impact="DD2", t_free=1.5, executor="serial"
    )
    theta = sp.table.sort_values("omega").theta_max.to_numpy()
    assert np.all(np.diff(theta) < 0)
    assert list(sp.table.status) == ["completed"] * 3


def test_pulse_spectrum_grows_with_amplitude():
    # paper 001, Fig 10 (bottom): at fixed frequency, θ_max grows with the amplitude
    sp = pulse_spectrum(
        "S2",
        "cosine",
        15.0,
        [0.3 * G, 0.45 * G, 0.6 * G],
        impact="DD2",
        t_free=1.5,
        executor="serial",
    )
    assert np.all(np.diff(sp.table.sort_values("amp").theta_max.to_numpy()) > 0)


def test_random_restitution_spectrum_is_identical_whatever_the_executor(ground_motions):
    rec = read_two_column(ground_motions / "elcentro_1940_NS.dat", units="g")
    short = type(rec).from_arrays(
        rec.time[:150], rec.accel[:150] / G, units="g", name="el centro, 3 s"
    )
    kw = dict(scale=[3.0], repeats=3, seed=11, t_free=0.5, impact="DD5")
    serial = record_spectrum("S1", short, executor="serial", **kw)
    pooled = record_spectrum("S1", short, executor="process", workers=2, **kw)
    assert serial.table.equals(pooled.table)
    assert serial.table.n_impacts.min() >= 2
    assert serial.table.theta_max.nunique() == 3  # the seeds matter: repeats differ
    stats = serial.stats("scale")
    assert list(stats.columns[:5]) == ["scale", "mean", "std", "min", "max"]


@pytest.mark.parametrize(
    "text, expected", [("0.5:5:10", np.linspace(0.5, 5, 10)), ("3", [3.0]), ("1:1:1", [1.0])]
)
def test_parse_range(text, expected):
    np.testing.assert_allclose(parse_range(text, "--x"), expected)


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("5:1:4", "inverted"),
        ("1:5:0", "empty"),
        ("a:b:c", "START:STOP:COUNT"),
        ("1:2", "START:STOP:COUNT"),
    ],
)
def test_parse_range_errors(text, fragment):
    with pytest.raises(InputError, match=fragment):
        parse_range(text, "--x")


@pytest.mark.parametrize(
    "kwargs, fragment",
    [
        (dict(omega=[-1.0]), "`omega`"),
        (dict(amp=[-1.0]), "`amp`"),
        (dict(repeats=0), "`repeats`"),
        (dict(pulse="square"), "`pulse`"),
    ],
)
def test_bad_spectrum_input(kwargs, fragment):
    args = dict(pulse="cosine", omega=[15.0], amp=[3.0], executor="serial") | kwargs
    with pytest.raises(InputError, match=fragment):
        pulse_spectrum("S1", **args)


def test_one_convention_for_the_mean_overturned_and_inaccurate_runs_apart():
    # the printed mean and the plot use one convention: overturned runs (θ_max = π/2) left out
    import pandas as pd

    from multimass.cli.spectrum_cmd import _stats_line
    from multimass.sweeps.spectra import Spectrum

    table = pd.DataFrame(
        {
            "scale": [1.0, 1.0, 1.0, 2.0, 2.0],
            "theta_max": [0.01, 0.03, 1.5707963, 0.02, 1.5707963],
            "status": ["completed", "completed", "overturned", "inaccurate", "overturned"],
        }
    )
    stats = Spectrum("S1", "record", table).stats("scale")
    one, two = stats.iloc[0], stats.iloc[1]
    assert one["mean"] == pytest.approx(0.02) and one["max"] == pytest.approx(0.03)
    assert (one.n, one.completed, one.overturned, one.inaccurate) == (3, 2, 1, 0)
    assert np.isnan(two["mean"]) and (two.n, two.completed, two.overturned, two.inaccurate) == (
        2,
        0,
        1,
        1,
    )
    line = _stats_line("scale", stats.replace({np.nan: None}).to_dict(orient="records")[0])
    assert "mean 0.02000 rad" in line and "over 2 of 3 runs" in line and "1 overturned" in line
    line = _stats_line("scale", stats.replace({np.nan: None}).to_dict(orient="records")[1])
    assert "no completed run of 2" in line and "1 overturned, 1 inaccurate" in line


def test_spectrum_options_are_checked_before_the_workers_start():
    # --t-free nan and --dt nan are named in the parent, not a JobError from a worker
    with pytest.raises(InputError, match="`t_free` = nan"):
        pulse_spectrum("S1", "cosine", omega=15.0, amp=0.4 * G, t_free=float("nan"))
    with pytest.raises(InputError, match="`rtol` = nan"):
        pulse_spectrum("S1", "cosine", omega=15.0, amp=0.4 * G, rtol=float("nan"))
    with pytest.raises(InputError, match="`repeats` = 0"):
        pulse_spectrum("S1", "cosine", omega=15.0, amp=0.4 * G, repeats=0)


def _short_record(ground_motions, seconds=3.0):
    rec = read_two_column(ground_motions / "elcentro_1940_NS.dat", units="g")
    n = int(round(seconds / rec.dt))
    return type(rec).from_arrays(rec.time[:n], rec.accel[:n] / G, units="g", name="el centro")


def _per_run(points) -> list:
    """Each point alone through `outcome_summary` (`spectrum_point`), one job per run."""
    from multimass.sweeps.engine import run_jobs
    from multimass.sweeps.spectra import spectrum_point

    return run_jobs(spectrum_point, points, executor="serial")


def _same_rows(table, expected):
    for k, column in enumerate(("theta_max", "status", "n_impacts", "overturn_time")):
        got, want = table[column].to_numpy(), np.array([e[k] for e in expected])
        assert np.array_equal(got, want, equal_nan=column == "overturn_time"), column


def test_a_record_spectrum_batch_gives_each_run_as_it_runs_alone(ground_motions):
    # the runs of a batch share their preparation (`outcome_summaries`); each must still be
    # the run `outcome_summary` makes alone, bit for bit (random restitution, seeded)
    from multimass import from_specimen
    from multimass.sweeps.spectra import _Point

    st, rec = from_specimen("S1"), _short_record(ground_motions)
    sp = record_spectrum(st, rec, [1.0, 3.0, 6.0], repeats=3, seed=5, t_free=1.0, executor="serial")
    options = {"impact": "DD5", "backend": "compiled"}
    points = [
        _Point(st, rec.scaled(scale), rec.duration + 1.0, seed, options)
        for scale, seed in zip(sp.table.scale, sp.table.seed)
    ]
    _same_rows(sp.table, _per_run(points))
    # each run its own draws: the completed runs' θ_max all differ, and so do the overturned
    # runs' times of overturning (their θ_max is the overturning angle, π/2 to round-off)
    t, done = sp.table, sp.table.status == "completed"
    assert t.n_impacts.min() >= 1 and done.sum() == 6
    assert t.theta_max[done].nunique() == 6 and t.overturn_time[~done].nunique() == 3


def test_a_batch_of_pulses_gives_each_run_as_it_runs_alone():
    # pulses of several lengths in one batch: a longer run is prepared again, a shorter
    # one reuses the prepared parts; every run is the one made alone
    from multimass import from_specimen
    from multimass.inputs.excitations import pulse
    from multimass.sweeps.spectra import _Point, spectrum_points

    st = from_specimen("S1")
    options = {"impact": "DD2", "backend": "compiled"}
    points = []
    for w, a in [(20.0, 0.3 * G), (8.0, 0.3 * G), (12.0, 0.6 * G), (20.0, 0.6 * G)]:
        exc = pulse("cosine", structure_kind="column", amplitude=a, omega=w)
        points.append(_Point(st, exc, exc.duration + 1.0, 0, options))
    batch, alone = spectrum_points(points), _per_run(points)
    assert [r[:3] for r in batch] == [r[:3] for r in alone]
    assert np.array_equal([r[3] for r in batch], [r[3] for r in alone], equal_nan=True)
    assert len({r[0] for r in batch}) == 4


def test_a_spectrum_wall_time_counts_its_checks_and_its_table(monkeypatch):
    # `wall_time_s` is the whole call: a slow check before the runs and a slow table after
    # them are both counted (each step made 0.3 s slower here)
    import time

    from multimass.sweeps import spectra

    def slow(step):
        def run(*args):
            time.sleep(0.3)
            return step(*args)

        return run

    monkeypatch.setattr(spectra, "_check_in_parent", slow(spectra._check_in_parent))
    monkeypatch.setattr(spectra, "_table", slow(spectra._table))
    sp = pulse_spectrum("S1", "cosine", 15.0, 0.3 * G, t_free=0.5, executor="serial")
    assert sp.wall_time_s >= 0.6
    assert "table" in sp.summary()["wall_time_covers"]


def test_the_spectrum_command_wall_time_counts_writing_its_files(tmp_path, capsys, monkeypatch):
    # the command's `wall_time_s` runs from its start to its JSON: the figure written counts
    import json
    import time

    from multimass.cli import main
    from multimass.sweeps import plots

    draw = plots.plot_spectrum
    monkeypatch.setattr(plots, "plot_spectrum", lambda *a: time.sleep(0.5) or draw(*a))
    args = ["spectrum", "S1", "--pulse", "cosine", "--omega", "15", "--amp", "0.3g"]
    assert main(args + ["--t-free", "0.5", "--executor", "serial", "--out", str(tmp_path)]) == 0
    saved = json.loads((tmp_path / "S1_spectrum_omega.json").read_text())
    assert saved["wall_time_s"] >= 0.5 and "the whole command" in saved["wall_time_covers"]
    printed = capsys.readouterr().out.splitlines()[-1]  # "1 simulations in 0.9 s; files in ..."
    assert float(printed.split(" in ")[1].split(" s")[0]) >= 0.5
