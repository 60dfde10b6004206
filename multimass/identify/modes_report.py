"""Reports of `multimass.identify.modes`: Markdown, a figure of the shapes, the shapes CSV.

The figure draws the identified operational shapes over the sensors' heights beside the
model's (compound shapes while rocking, full-contact shapes at rest), as paper 001
Fig 5 does; the arrays are drawn as stored (`IdentifiedModes.shapes` carry the sign
that correlates with the model's shape). Headless: matplotlib's object API.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import MaxNLocator

from ..errors import InputError
from .modes import IdentifiedModes, OperationalModes

__all__ = ["modes_figure", "plot_modes", "modes_markdown", "write_modes_report"]

_TITLES = {"rocking": "rocking (uplifted, compound shapes)", "full_contact": "full contact"}


def _paper(result: OperationalModes, phase: str) -> tuple:
    ref = getattr(result.structure.specimen, "reference", None)
    key = "rocking_freq_hz" if phase == "rocking" else "full_contact_freq_hz"
    return tuple(getattr(ref, key, ()) or ()) if ref is not None else ()


def _panel(ax, result: OperationalModes, pm: IdentifiedModes, k: int) -> None:
    h = result.analysis.heights
    ax.plot(pm.shapes[:, k], h, "D-", color="tab:red", lw=2.5, ms=7, zorder=2)
    ax.plot(pm.model_shapes[:, k], h, "o--", color="k", mfc="white", lw=1, ms=5, zorder=3)
    ax.set_title(
        f"{pm.phase.replace('_', ' ')} mode {pm.mode[k]}\n"
        f"[{pm.freq_hz[k]:.2f}, {pm.model_freq_hz[k]:.2f}] Hz, MAC {pm.mac[k]:.3f}",
        fontsize=9,
    )


def modes_figure(result: OperationalModes) -> Figure:
    """Identified against predicted shapes over height, one panel per mode and phase.

    Rows: the rocking phase (compound shapes v_c) and full contact (v_n); the
    brackets hold [identified, model] frequency.
    """
    phases = [p for p in result.phases() if p.mode.size]
    if not phases:
        raise InputError("no identified mode to draw")
    ncol = max(p.mode.size for p in phases)
    fig = Figure(figsize=(max(2.8 * ncol + 0.6, 5.6), 4.2 * len(phases)), layout="constrained")
    axes = np.atleast_2d(fig.subplots(len(phases), ncol, sharey=True, squeeze=False))
    top = float(result.structure.H.max())
    for row, pm in enumerate(phases):
        for k in range(ncol):
            ax = axes[row, k]
            if k >= pm.mode.size:
                ax.set_axis_off()
                continue
            _panel(ax, result, pm, k)
            ax.axvline(0, color="0.7", lw=0.6)
            ax.axhline(0, color="k", lw=3, solid_capstyle="butt")
            ax.xaxis.set_major_locator(MaxNLocator(nbins=4))
            ax.set_xlim(-1.05, 1.05)
            ax.grid(alpha=0.3)
            ax.set_xlabel("ordinate (unit norm)", fontsize=8)
        axes[row, 0].set_ylabel("height above the base (m)")
    axes[0, 0].set_ylim(0.0, 1.06 * top)
    handles = [
        Line2D([], [], marker="D", color="tab:red", lw=2.5, label="identified (trace)"),
        Line2D([], [], marker="o", ls="--", color="k", mfc="white", lw=1,
               label="model (multimass.modal)"),
        Line2D([], [], color="k", lw=3, label="base (0 m)"),
    ]  # fmt: skip
    fig.legend(handles=handles, loc="outside lower center", ncol=3, fontsize=8)
    fig.suptitle(
        f"{result.structure.name}: operational shapes from {Path(result.source).name} "
        f"({result.method})\n[f_identified, f_model]",
        fontsize=10,
    )
    return fig


def plot_modes(result: OperationalModes, path) -> Path:
    """Save `modes_figure` to `path` (PNG); returns the path."""
    path = Path(path)
    modes_figure(result).savefig(path, dpi=110)
    return path


def _fmt(x: float, digits: int = 3) -> str:
    return "–" if x is None or not np.isfinite(x) else f"{x:.{digits}f}"


def _phase_table(result: OperationalModes, pm: IdentifiedModes) -> list[str]:
    paper = _paper(result, pm.phase)
    lines = [
        "| mode | f identified (Hz) | f model (Hz) | error | f paper Fig 4 (Hz) | ζ identified (%) "
        "| ζ model (%) | MAC | segments |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for k, j in enumerate(pm.mode):
        fp = paper[j - 1] if j - 1 < len(paper) else None
        lines.append(
            f"| {j} | {pm.with_spread(k)} | {pm.model_freq_hz[k]:.3f} "
            f"| {100 * (pm.freq_hz[k] / pm.model_freq_hz[k] - 1):+.2f} % | "
            f"{'–' if fp is None else f'{fp:g}'} | "
            f"{pm.with_spread(k, 'damping', 100.0, 2)} | "
            f"{100 * pm.model_damping[k]:.2f} | {pm.mac[k]:.4f} | {pm.n_segments[k]} |"
        )
    return lines


def _shape_table(result: OperationalModes, pm: IdentifiedModes) -> list[str]:
    head = ["sensor", "node", "height (m)"]
    for j in pm.mode:
        head += [f"mode {j} identified", f"mode {j} model"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---:|" * len(head)]
    for s, (name, node, h) in enumerate(zip(result.sensors, result.nodes, result.analysis.heights)):
        cells = [name, str(node), f"{h:.2f}"]
        for k in range(pm.mode.size):
            cells += [f"{pm.shapes[s, k]:+.3f}", f"{pm.model_shapes[s, k]:+.3f}"]
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def _segments_line(pm: IdentifiedModes, fs: float) -> str:
    segs = pm.segments.drop_duplicates("segment")
    span = float(((segs["stop"] - segs["start"]) / fs).sum())
    if pm.phase == "rocking":
        return (
            f"{len(segs)} half-cycle(s) used ({span:.2f} s of samples; "
            f"{pm.skipped.get('too_short', 0)} too short of "
            f"{pm.skipped.get('half_cycles_large', len(segs))} above theta_min)"
        )
    cut = ", ".join(f"{x:.2f}" for x in pm.skipped.get("settled_s", []))
    return (
        f"{len(segs)} full-contact stretch(es) used ({span:.2f} s; cut from their start "
        f"before the free decay: {cut} s; {pm.skipped.get('too_short', 0)} too short)"
    )


def modes_markdown(
    result: OperationalModes, figure: str | None = None, csv: dict | None = None
) -> str:
    """The Markdown report: the Fig 5 table per phase, the shapes, what was left out."""
    sensors = ", ".join(
        f"{n} (node {k}, {h:.2f} m)"
        for n, k, h in zip(result.sensors, result.nodes, result.analysis.heights)
    )
    out = [
        f"# Operational modes of {result.structure.name} from `{result.source}`",
        "",
        f"- method: `{result.method}`; sampling rate {result.fs:g} Hz; sensors: {sensors}",
        f"- half-cycles used: peak ≥ theta_min = {result.segments.theta_min:g} rad; the model: "
        "`multimass.modal.analyse` at the sensors' nodes (compound shapes while rocking, "
        "paper 001 Section 4.2)",
        "",
    ]
    for pm in result.phases():
        out += [f"## {_TITLES[pm.phase].capitalize()}", "", _segments_line(pm, result.fs), ""]
        if pm.mode.size:
            out += _phase_table(result, pm) + [""] + _shape_table(result, pm) + [""]
        if pm.not_identified:
            out += ["Not identified:", ""]
            out += [f"- mode {j}: {why}" for j, why in sorted(pm.not_identified.items())] + [""]
        if csv and pm.phase in csv:
            out += [f"Shapes for `multimass modal --measured`: `{csv[pm.phase]}`", ""]
    if figure:
        out += [f"![operational shapes]({figure})", ""]
    if result.warnings:
        out += ["## Warnings", ""] + [f"- {w}" for w in result.warnings] + [""]
    return "\n".join(out)


def write_modes_report(
    result: OperationalModes, out, stem: str | None = None, *, figure: bool = True
) -> dict:
    """Write ``<stem>.md``, ``<stem>.png``, ``<stem>.json`` and one shapes CSV per phase
    (``<stem>_rocking_shapes.csv``, ``<stem>_full_contact_shapes.csv``) into folder `out`.

    Returns
    -------
    dict
        File kind → path written.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    stem = stem or f"{result.structure.name}_modes"
    files, csv = {}, {}
    for pm in result.phases():
        if pm.mode.size:
            path = out / f"{stem}_{pm.phase}_shapes.csv"
            path.write_text(result.shapes_csv(pm.phase), encoding="utf-8")
            files[f"{pm.phase}_shapes"] = path
            csv[pm.phase] = path.name
    png = None
    if figure and any(pm.mode.size for pm in result.phases()):
        png = plot_modes(result, out / f"{stem}.png")
        files["figure"] = png
    md = out / f"{stem}.md"
    md.write_text(modes_markdown(result, png.name if png else None, csv), encoding="utf-8")
    files["markdown"] = md
    js = out / f"{stem}.json"
    js.write_text(result.to_json(indent=1) + "\n", encoding="utf-8")
    files["json"] = js
    return files
