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
