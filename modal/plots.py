"""Figures of a modal analysis (headless: matplotlib's object API, no pyplot state).

The figures draw the analysis's arrays as stored: shapes follow the scale and
sign rule of `modal.shapes`, the same numbers as the JSON and Markdown reports.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import MaxNLocator

from .analysis import ModalAnalysis

__all__ = ["eigenvalue_figure", "shapes_figure", "plot_eigenvalues", "plot_shapes"]

_FC = dict(marker="o", facecolors="none", edgecolors="tab:blue")
_RK = dict(marker="x", color="tab:red")
_ZOOM_MODES = 2


def _save(fig: Figure, path: str | Path) -> Path:
    path = Path(path)
    fig.savefig(path, dpi=120)
    return path


def _overview(ax, analysis: ModalAnalysis) -> None:
    """All eigenvalues on symmetric-log axes (overdamped couples reach far along Re < 0)."""
    fc, rk = analysis.full_contact.eigenvalues, analysis.rocking.eigenvalues
    ax.scatter(fc.real, fc.imag, **_FC)
    ax.scatter(rk.real, rk.imag, **_RK)
    ax.set_xscale("symlog", linthresh=1.0)
    ax.set_yscale("symlog", linthresh=1.0)
    ax.set_title(f"{analysis.structure.name}: all eigenvalues (symmetric log axes)")


def _zoom_set(analysis: ModalAnalysis):
    """Underdamped eigenvalues (Im > 0) of modes 1–2 per phase, and their overdamped couples."""
    out = {}
    for key, pm in (("n", analysis.full_contact), ("u", analysis.rocking)):
        keep = pm.mode <= _ZOOM_MODES
        over = pm.overdamped_mode <= _ZOOM_MODES
        out[key] = (
            pm.mode[keep],
            pm.vibration_eigenvalues[keep],
            pm.overdamped_mode[over],
            pm.overdamped_eigenvalues[over],
        )
    return out


def _label_sides(zs) -> dict:
    """Which side each label goes: of the two phases' points of one mode, the left one's
    label to the left, the other's to the right (so the two labels never cross)."""
    side = {}
    for j in range(1, _ZOOM_MODES + 1):
        pts = {key: l for key in zs for m, l in zip(zs[key][0], zs[key][1]) if m == j}
        left = min(pts, key=lambda key: pts[key].real) if len(pts) == 2 else "u"
        side.update({(key, j): key == left for key in pts})
    return side


def _zoom(ax, analysis: ModalAnalysis) -> None:
    """Rocking couple, ±p_l and modes 1–2, labelled; overdamped couples noted under the axis."""
    zs = _zoom_set(analysis)
    p = analysis.structure.p_l
    im = [abs(l.imag) for key in zs for l in zs[key][1]] + [p]
    re = [abs(l.real) for key in zs for l in zs[key][1]] + list(
        np.abs(analysis.rocking_eigenvalues)
    )
    xlim, ylim = 1.6 * max(re), 1.25 * max(im)
    side = _label_sides(zs)
    for key, style in (("n", _FC), ("u", _RK)):
        modes, lam, _, olam = zs[key]
        pts = np.concatenate([lam, lam.conj(), olam.ravel().astype(complex)])
        ax.scatter(pts.real, pts.imag, **style)
        for j, l in zip(modes, lam):
            left = side[(key, j)]
            ax.annotate(
                f"{key}{j}: {abs(l) / (2 * np.pi):.1f} Hz",
                (l.real, l.imag),
                textcoords="offset points",
                xytext=(-6 if left else 6, 5),
                fontsize=8,
                ha="right" if left else "left",
                color=style.get("color", "tab:blue"),
            )
    rk = analysis.rocking_eigenvalues
    ax.scatter(rk, [0, 0], **_RK)
    ax.scatter([p, -p], [0, 0], marker="+", s=140, color="k", zorder=3)
    ax.set_xlim(-xlim, xlim)
    ax.set_ylim(-ylim, ylim)
    notes = [
        f"\n{'full contact' if key == 'n' else 'uplifted'} mode {j} overdamped: Λ = "
        + ", ".join(f"{x:.4g}" + (" (off frame)" if x < -xlim else "") for x in (a, b))
        + " rad/s"
        for key in zs
        for j, (a, b) in zip(zs[key][2], zs[key][3])
    ]
    ax.set_xlabel("Re Λ (rad/s)" + "".join(notes))
    ax.set_title(f"zoom: rocking pair and modes 1–{_ZOOM_MODES}")


def eigenvalue_figure(analysis: ModalAnalysis) -> Figure:
    """Damped eigenvalues of both phases on the complex plane (paper 001, Fig 4 left).

    Left: every eigenvalue (symmetric-log axes); right: the rocking couple,
    ±p_l and modes 1–2 (linear axes), labelled with their frequencies.
    """
    fig = Figure(figsize=(11, 5), layout="constrained")
    axes = fig.subplots(1, 2)
    _overview(axes[0], analysis)
    _zoom(axes[1], analysis)
    for ax in axes:
        ax.axhline(0, color="0.7", lw=0.6)
        ax.axvline(0, color="0.7", lw=0.6)
        ax.set_ylabel("Im Λ (rad/s)")
        ax.grid(alpha=0.3)
    axes[0].set_xlabel("Re Λ (rad/s)")
    handles = [
        Line2D([], [], ls="none", marker="o", mfc="none", mec="tab:blue", label="full contact"),
        Line2D([], [], ls="none", marker="x", color="tab:red", label="rocking (uplifted)"),
        Line2D([], [], ls="none", marker="+", ms=11, color="k", label="±p_l (Eq 6)"),
    ]
    fig.legend(handles=handles, loc="outside lower center", ncol=3, fontsize=9)
    return fig


def plot_eigenvalues(analysis: ModalAnalysis, path: str | Path) -> Path:
    """Save `eigenvalue_figure` to `path` (PNG); returns the path."""
    return _save(eigenvalue_figure(analysis), path)


def _marker_size(n_points: int) -> float:
    """Full-size markers for a few nodes, small ones for a fine mesh."""
    return 6.0 if n_points <= 12 else 3.0


def _freq_label(table, j: int) -> str:
    row = table[table["mode"] == j].iloc[0]
    return f"{row.freq_hz:.1f}" + (" od" if row.kind == "overdamped" else "")


def _mode_panel(ax, analysis: ModalAnalysis, j: int, tables) -> None:
    """Mode j: v_n, v_t and v_c as stored (sign rule of `modal.shapes`)."""
    h = analysis.heights  # v_n drawn last, hollow, so it shows where it coincides
    ms = _marker_size(h.size)
    ax.plot(
        analysis.compound_shapes()[:, j - 1],
        h,
        "D-",
        color="tab:red",
        lw=2,
        ms=ms,
        zorder=2,
        label="uplifted compound v_c",
    )
    ax.plot(
        analysis.elastic_shapes()[:, j - 1],
        h,
        "s-",
        color="tab:blue",
        lw=1,
        ms=ms,
        zorder=3,
        label="uplifted elastic v_t",
    )
    ax.plot(
        analysis.full_contact_shapes()[:, j - 1],
        h,
        "o--",
        color="0.3",
        mfc="white",
        ms=ms,
        zorder=4,
        label="full contact v_n",
    )
    fn, fu = (_freq_label(t, j) for t in tables)
    ax.set_title(f"mode {j}\n[{fn}, {fu}] Hz", fontsize=10)


def _rocking_panel(ax, analysis: ModalAnalysis) -> None:
    rs, h = analysis.rocking_shape, analysis.heights
    idx = np.asarray(analysis.shape_nodes) - 1
    rt, rc = rs[idx], rs[idx] + h * rs[-1]
    scale = np.linalg.norm(rc)
    ms = _marker_size(h.size)
    ax.plot(rc / scale, h, "D-", color="tab:red", lw=2, ms=ms)
    ax.plot(rt / scale, h, "s-", color="tab:blue", lw=1, ms=ms)
    ax.set_title(f"rocking mode\nΛ = ±{analysis.rocking_eigenvalues[0]:.3f} rad/s", fontsize=10)


def shapes_figure(analysis: ModalAnalysis, n_modes: int = 3) -> Figure:
    """Mode shapes over height (paper 001, Fig 4 right).

    Full contact v_n, uplifted elastic part v_t and compound shape
    v_c = v_t + H v_r for modes 1..`n_modes`, and the rocking mode; the height
    axis starts at the base (0 m, the pivots). "od" marks an overdamped mode.
    """
    k = min(n_modes, analysis.structure.n)
    tables = (analysis.full_contact.to_pandas(), analysis.rocking.to_pandas())
    fig = Figure(figsize=(3.0 * (k + 1), 5.0), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, k + 1, sharey=True))
    for j in range(1, k + 1):
        _mode_panel(axes[j - 1], analysis, j, tables)
    _rocking_panel(axes[k], analysis)
    top = float(analysis.structure.H.max())
    for ax in axes:
        ax.axvline(0, color="0.7", lw=0.6)
        ax.axhline(0, color="k", lw=3, solid_capstyle="butt")
        ax.xaxis.set_major_locator(MaxNLocator(nbins=4))
        ax.set_xlabel("ordinate (normalised)")
        ax.grid(alpha=0.3)
    axes[0].set_ylim(0.0, 1.06 * top)
    axes[0].set_ylabel("height above the base (m)")
    handles = axes[0].get_legend_handles_labels()[0][::-1]  # v_n, v_t, v_c
    handles.append(Line2D([], [], color="k", lw=3, label="base (0 m)"))
    fig.legend(handles=handles, loc="outside lower center", ncol=4, fontsize=8)
    od = any(t["kind"].eq("overdamped").iloc[:k].any() for t in tables)
    fig.suptitle(
        f"{analysis.structure.name}: mode shapes [f_full contact, f_uplifted]"
        + (" (od: overdamped)" if od else "")
    )
    return fig


def plot_shapes(analysis: ModalAnalysis, path: str | Path, n_modes: int = 3) -> Path:
    """Save `shapes_figure` to `path` (PNG); returns the path."""
    return _save(shapes_figure(analysis, n_modes), path)
