"""Figures of sweeps: overturning maps (paper 004, Figs 4–9) and rocking spectra (paper 001, Figs 10, 12)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

__all__ = ["plot_map", "plot_map_comparison", "plot_spectrum"]

_CODES = {"no_rocking": 0, "rest": 1, "undecided": 2, "overturned": 3}
_LABELS = {
    "no_rocking": "no rocking (never uplifts)",
    "rest": "rocks, then rests (safe)",
    "undecided": "undecided (still rocking at the end)",
    "overturned": "overturns",
}
# distinct in lightness as well as hue (legible in grey and to colour-blind readers)
_COLOURS = ["#f0f0f0", "#9ecae1", "#fdae6b", "#4d4d4d"]


_BOUNDARY_LABEL = "overturning boundary, refined by bisection in a0"


def _edges(v: np.ndarray) -> np.ndarray:
    if v.size == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])


def _draw_map(ax, m, boundary_colour="k"):
    codes = np.vectorize(_CODES.get)(m.grid)
    ax.pcolormesh(
        _edges(m.omega_p),
        _edges(m.amp),
        codes,
        cmap=ListedColormap(_COLOURS),
        vmin=-0.5,
        vmax=3.5,
        shading="flat",
    )
    b = m.boundaries
    if not b.empty:
        ax.plot(
            b.omega_p,
            0.5 * (b.amp_low + b.amp_high),
            ".",
            color=boundary_colour,
            ms=3,
            label=_BOUNDARY_LABEL,
        )
    ax.set_xlabel("ω/p")
    ax.set_ylabel("a0/(α g)")


def _restitution_label(m) -> str:
    """η_M (k = …), η_H or r = … for a map's restitution source."""
    rest = m.options.get("restitution_value", {})
    kind = rest.get("kind", "")
    if kind == "ModifiedRestitution":
        return f"η_M (paper 004 Eq 10, k = {rest.get('k')})"
    if kind == "HousnerRestitution":
        return "η_H (paper 004 Eq 9)"
    if kind == "FixedRestitution":
        return f"r = {rest.get('r')}"
    return kind


def plot_map(m, path, title: str = "") -> Path:
    """The overturning map: overturned cells shaded, refined boundary points marked."""
    fig = Figure(figsize=(7.5, 5.5), layout="constrained")
    ax = fig.subplots()
    _draw_map(ax, m, boundary_colour="tab:red")
    handles = [
        Patch(facecolor=c, edgecolor="0.6", label=_LABELS[k]) for k, c in zip(_CODES, _COLOURS)
    ]
    if not m.boundaries.empty:
        handles.append(Line2D([], [], ls="", marker=".", color="tab:red", label=_BOUNDARY_LABEL))
    bad = m.inaccurate_grid_cells()
    if not bad.empty:
        ax.plot(bad.omega_p, bad.amp, ls="", marker="x", ms=4, color="tab:purple")
        handles.append(
            Line2D(
                [],
                [],
                ls="",
                marker="x",
                color="tab:purple",
                label=f"accuracy check failed ({len(bad)} cells)",
            )
        )
    ax.legend(
        handles=handles,
        loc="upper center",
        bbox_to_anchor=(0.5, -0.12),
        ncol=2,
        fontsize=8,
        frameon=False,
    )
    ax.set_title(
        title
        or f"{m.block}: single {m.pulse} pulse, restitution {_restitution_label(m)}"
        f"\n{m.n_simulations()} simulations, {m.overturn_fraction():.1%} of the grid overturns"
        + (f", {m.undecided_fraction():.1%} undecided" if m.undecided().any() else "")
    )
    path = Path(path)
    fig.savefig(path, dpi=120)
    return path


def plot_map_comparison(maps: dict, path, title: str = "") -> Path:
    """Overturning regions of several maps of the same grid, as outlines (e.g. η_H vs η_M)."""
    fig = Figure(figsize=(7.5, 5.5), layout="constrained")
    ax = fig.subplots()
    colours = ["tab:red", "tab:blue", "tab:green", "tab:purple"]
    for (label, m), c in zip(maps.items(), colours):
        over = m.overturned().astype(float)
        ax.contourf(m.omega_p, m.amp, over, levels=[0.5, 1.5], colors=[c], alpha=0.25)
        ax.contour(m.omega_p, m.amp, over, levels=[0.5], colors=[c], linewidths=1.5)
        ax.plot(
            [],
            [],
            color=c,
            lw=6,
            alpha=0.4,
            label=f"{label}: {m.overturn_fraction():.1%} overturns",
        )
    ax.set_xlabel("ω/p")
    ax.set_ylabel("a0/(α g)")
    ax.legend(loc="upper left", fontsize=8)
    first = next(iter(maps.values()))
    ax.set_title(title or f"{first.block}: overturning regions, single {first.pulse} pulse")
    path = Path(path)
    fig.savefig(path, dpi=120)
    return path


def plot_spectrum(table, x: str, path, xlabel: str, title: str, y: str = "theta_max") -> Path:
    """θ_max against a swept parameter (paper 001, Figs 10 and 12).

    Every completed run is a marker and their mean a line (± 1 std shaded when
    repeated); overturned runs are crosses along the top edge and inaccurate runs
    hollow grey circles, both left out of the mean (the convention of
    `multimass.sweeps.spectra.Spectrum`). The axis turns logarithmic when θ_max
    spans over two decades.
    """
    fig = Figure(figsize=(9.0, 4.5), layout="constrained")
    ax = fig.subplots()
    ok = table[table.status == "completed"]
    over = table[table.status == "overturned"]
    odd = table[table.status == "inaccurate"]
    ax.plot(ok[x], ok[y], "o", ms=3.5, color="tab:blue", alpha=0.6, label="runs")
    if not odd.empty:
        ax.plot(
            odd[x],
            odd[y],
            "o",
            ms=5,
            mfc="none",
            color="0.45",
            label=f"inaccurate, not in the mean ({len(odd)} runs)",
        )
    if not ok.empty:
        g = ok.groupby(x)[y]
        mean = g.mean()
        ax.plot(mean.index, mean.values, "-", color="k", lw=1.5, label="mean of the completed runs")
        if ok.groupby(x).size().max() > 1:
            std = g.std().fillna(0.0)
            low = np.maximum((mean - std).values, 0.5 * mean.values)
            ax.fill_between(
                mean.index, low, (mean + std).values, color="0.8", alpha=0.7, label="± 1 std"
            )
        positive = ok[y][ok[y] > 0]
        if not positive.empty and positive.max() / positive.min() > 100:
            ax.set_yscale("log")
    if not over.empty:
        top = ax.get_ylim()[1]
        counts = over.groupby(x).size()
        ax.plot(
            counts.index,
            np.full(len(counts), top),
            "x",
            color="tab:red",
            ms=8,
            mew=2,
            clip_on=False,
            label=f"overturned ({len(over)} runs)",
        )
    ax.set_xlabel(xlabel)
    ax.set_ylabel("θ_max (rad)")
    ax.grid(alpha=0.3, which="both")
    # outside the axes, right: a legend inside always ends up on some spectrum's points
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    ax.set_title(title)
    path = Path(path)
    fig.savefig(path, dpi=120)
    return path
