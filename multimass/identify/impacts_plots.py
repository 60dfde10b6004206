"""Figures of `multimass.identify.restitution`: r per impact with the corner means, and
the fitted simulation over the trace's θ."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

__all__ = ["plot_restitution"]

_COLOURS = {"right": "tab:red", "left": "tab:blue"}


def plot_restitution(est, path=None):
    """Two panels: r_e per impact (model-based and energy estimates, corner means ± σ_r)
    and θ of the trace with the simulation that uses every fitted coefficient.

    Parameters
    ----------
    est : RestitutionEstimate
    path : str or Path, optional
        Where to save the PNG; the figure is returned either way.
    """
    fig = Figure(figsize=(9.0, 7.5), layout="constrained")
    ax, ax2 = fig.subplots(2, 1)
    df = est.impacts
    for corner, colour in _COLOURS.items():
        rows = df[df["corner"] == corner]
        done = rows[rows["estimated"]]
        ax.errorbar(
            done["t"], done["r"], yerr=np.nan_to_num(done["r_std"].to_numpy(float), nan=0.0),
            fmt="o", color=colour, label=f"{corner} corner: model-based r", capsize=2,
        )  # fmt: skip
        ax.plot(rows["t"], rows["r_energy"], "x", color=colour, label=f"{corner}: energy estimate")
        mean = est.r_mean_right if corner == "right" else est.r_mean_left
        if mean is None:  # no estimated impact on this corner: no line
            continue
        ax.axhline(mean, color=colour, lw=1.0, ls="--", label=f"r̄ {corner} = {mean:.3f}")
        if est.sigma_r is not None:
            ax.axhspan(mean - est.sigma_r, mean + est.sigma_r, color=colour, alpha=0.08)
    ax.set_ylabel("coefficient of restitution r")
    ax.set_xlabel("impact time on the trace's clock (s)")
    spread = "not estimated" if est.sigma_r is None else f"{est.sigma_r:.3f}"
    ax.set_title(
        f"{est.structure.name}: restitution per impact for {est.impact} "
        f"(σ_r = {spread}; open: below θ_min = {est.theta_min:g} rad)"
    )
    small = df[~df["estimated"]]
    ax.plot(small["t"], small["r"], "o", mfc="none", color="0.5")
    ax.legend(fontsize=7, ncol=3, loc="lower right")
    ax.grid(alpha=0.3)
    trace = est.segments.trace
    a = est.alignment
    ax2.plot(trace.time, trace.channels["theta"], ".", ms=2, color="0.4", label="trace θ")
    r = est.response
    ax2.plot(r.t + a["t_offset"], r.theta + a["theta_bias"], color="tab:green", lw=1.0,
             label="simulation with the fitted r")  # fmt: skip
    for _, row in df.iterrows():
        ax2.axvline(row["t"], color=_COLOURS[row["corner"]], lw=0.5, alpha=0.5)
    ax2.set_xlabel("time (s)")
    ax2.set_ylabel("θ (rad)")
    ax2.legend(fontsize=8)
    ax2.grid(alpha=0.3)
    if path is not None:
        fig.savefig(Path(path), dpi=110)
    return fig
