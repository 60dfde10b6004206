"""The figures of the convergence studies are written (tiny studies, coarse steps)."""

import math

from nscd import plots
from nscd.convergence import first_peak_study, flexibility_study


def test_first_peak_figure(tmp_path):
    fps = first_peak_study(("B6M",), (1e-3, 1e-4), t_end=0.8)
    assert set(fps.errors_deg) == {"B6M"} and fps.fitted_order["B6M"] > 0
    path = plots.plot_first_peak(fps, tmp_path / "fp.png")
    assert path.is_file() and path.stat().st_size < 300_000


def test_flexibility_figures(tmp_path):
    flex = flexibility_study("B6M", (2,), meshes=(6, 12), dts=(2e-4, 1e-4), base_dt=1e-4,
                             base_mesh=6, t_end=1.0)
    assert flex["base"][2] is flex["mesh"][2].runs[0] is flex["dt"][2].runs[1]
    assert flex["E_bar"] > 0 and math.isfinite(flex["E_bar"])
    paths = plots.plot_flexibility(flex, tmp_path)
    assert [p.name for p in paths] == ["fig16_flexibility_B6M.png", "fig17_first_impacts_B6M.png",
                                       "fig18_mesh_B6M.png", "fig19_dt_B6M.png"]
    assert all(p.is_file() and p.stat().st_size < 300_000 for p in paths)
