"""Figures of a runs table (multimass.suites.plots): written, non-empty PNGs, degenerate cases."""

import numpy as np
import pytest

from multimass.errors import InputError
from multimass.suites.analysis import fragility_curves, im_efficiency
from multimass.suites.plots import (
    plot_fragility,
    plot_ida,
    plot_im_efficiency,
    plot_pulse_fragility,
)

from .test_analysis import ida_table, pulse_runs, record_runs, scaled_by_factor

PNG = b"\x89PNG\r\n\x1a\n"


def _is_png(path, min_bytes=10_000):
    data = path.read_bytes()
    return data[:8] == PNG and len(data) > min_bytes


def test_fragility_per_level_with_excluded_runs(tmp_path):
    runs = record_runs(draws=5)
    runs.loc[runs.index[:4], "status"] = "inaccurate"
    out = plot_fragility(runs, fragility_curves(runs), tmp_path / "f.png")
    assert out == tmp_path / "f.png" and _is_png(out)


def test_fragility_per_run_with_bootstrap_band(tmp_path):
    runs = scaled_by_factor()
    curves = fragility_curves(runs, im="pga", measures=["overturned"], bootstrap=20)
    assert _is_png(plot_fragility(runs, curves, tmp_path / "f.png"))


def test_fragility_with_a_damage_state_no_run_reaches(tmp_path):
    runs = record_runs(draws=4)
    runs["overturned"] = False
    runs["status"] = "completed"
    runs["theta_max_over_alpha"] = np.linspace(0.0, 0.6, len(runs))
    curves = fragility_curves(runs)
    assert curves.set_index("measure").loc["overturned", "status"] == 1
    assert _is_png(plot_fragility(runs, curves, tmp_path / "f.png"))


def test_ida(tmp_path):
    assert _is_png(plot_ida(ida_table(), tmp_path / "ida.png"))
    assert _is_png(plot_ida(record_runs(draws=3), tmp_path / "ida2.png"))


def test_pulse_fragility_with_a_frequency_that_never_overturns(tmp_path):
    runs = pulse_runs(medians={1.0: 1.2, 3.0: 2.0, 6.0: 50.0}, draws=5)
    assert _is_png(plot_pulse_fragility(runs, tmp_path / "p.png"))
    with pytest.raises(InputError, match="pulse"):
        plot_pulse_fragility(record_runs(draws=2), tmp_path / "no.png")
    assert not (tmp_path / "no.png").exists()


def test_im_efficiency_with_an_im_without_fit(tmp_path):
    table = im_efficiency(record_runs(draws=3).assign(pgd=0.01))
    assert np.isnan(table["beta"].iloc[-1])
    assert _is_png(plot_im_efficiency(table, tmp_path / "e.png"))
