"""The figure of a `SideBySide` comparison: θ(t) with impacts, peaks, energy lost."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .side_by_side import SideBySide

__all__ = ["plot_side_by_side"]

_STYLE = {"CIM": ("C0", "-"), "DD2": ("C1", "-"), "OpenSees": ("k", "--")}


def plot_side_by_side(result: SideBySide, path=None, title: str | None = None):
    """Three panels: θ(t) with impact times marked; half-cycle peaks; energy lost.

    Returns the matplotlib figure (saved to `path` if given).
    """
    import matplotlib.pyplot as plt

    fig, (ax_t, ax_p, ax_e) = plt.subplots(3, 1, figsize=(8, 8.5))
    for k, (name, run) in enumerate(result.runs.items()):
        color, line = _STYLE.get(name, (f"C{k + 2}", "-"))
        label = f"{name} ({run.wall_time_s:.2g} s to run)"
        ax_t.plot(run.t, run.theta, color=color, ls=line, lw=1.0, label=label)
        ax_t.plot(run.impacts, np.zeros_like(run.impacts), "|", color=color, ms=10)
        n = np.arange(1, run.peaks.size + 1)
        ax_p.plot(n, run.peaks, "o" + line, color=color, ms=4, label=name)
        ax_e.plot(n[:-1] + 0.5, run.energy_lost, "s" + line, color=color, ms=4, label=name)
    if result.housner is not None:
        n = np.arange(1, result.housner.size + 1)
        ax_p.plot(n, result.housner, "x:", color="C3", label="Housner, r = 1 − 1.5 sin²α")
    ax_t.set(xlabel="t (s)", ylabel="θ (rad)")
    ax_t.set_title(title or f"{result.name}: θ(t); ticks at θ = 0 mark impacts", fontsize=10)
    ax_p.set(xlabel="half-cycle", ylabel="peak |θ| (rad)")
    ax_e.set(
        xlabel="impact (between half-cycles)",
        ylabel="E(peak n) − E(peak n+1) (J)",
        title="rocking energy lost between consecutive peaks\n(structure taken as rigid; "
        "under a record it includes the ground's work)",
    )
    ax_e.title.set_fontsize(9)
    for ax in (ax_t, ax_p, ax_e):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    if path is not None:
        fig.savefig(Path(path), dpi=110)
        plt.close(fig)
    return fig
