"""Charts of the benchmarks (matplotlib object API, no display needed).

* `work_precision_chart` — one figure per model, SciML style: error against
  wall time (left) and against right-hand-side evaluations (right), log–log,
  one line per method, the marker giving the tolerance (or Δt) decade; rows:
  peak error, event-time error, final-energy error. Runs that missed
  transitions have no finite error: they are drawn as ✕ on the top edge.
* `failure_map_chart` — every (model, method) × level cell coloured by its
  most severe failure kind.
* `stiffness_chart` — the stiffness sweep: cost and error against the scale.
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import NullFormatter

from .failures import KINDS

__all__ = ["work_precision_chart", "failure_map_chart", "stiffness_chart", "FAILURE_COLOURS"]

ERRORS = (
    ("peak_error_rad", "max |Δ peak| (rad)"),
    ("event_time_error_s", "max |Δ event time| (s)"),
    ("energy_error", "|Δ final energy| / E scale"),
)
COSTS = (
    ("wall_time_s", "wall time (s)"),
    ("n_rhs", "RHS evaluations\n(Newmark: Newton its; MJ: steps)"),
)
MARKERS = "os^Dv<>pP*hX"
FAILURE_COLOURS = {
    "ok": "#e8f1e4",
    "solver_failed": "#7f0000",
    "missed_impacts": "#d7301f",
    "not_converging": "#807dba",
    "chattering": "#fc8d59",
    "energy_drift": "#fdd49e",
    "cost_blowup": "#6baed6",
}
DPI = 100


def _decade(level: float) -> int:
    return int(round(-math.log10(level)))


def _marker(level: float) -> str:
    return MARKERS[_decade(level) % len(MARKERS)]


def _by_method(rows):
    out = {}
    for r in rows:
        out.setdefault(r["method"], []).append(r)
    return out


def _panel(ax, rows, err_key, cost_key, colours):
    tops = [r[err_key] for r in rows if np.isfinite(r[err_key]) and r[err_key] > 0]
    top = 10 ** math.ceil(math.log10(max(tops))) if tops else 1.0
    for name, rs in _by_method(rows).items():
        ok = [
            r for r in rs if r["status"] != "failed" and np.isfinite(r[err_key]) and r[err_key] > 0
        ]
        bad = [r for r in rs if r["status"] != "failed" and r[err_key] == math.inf]
        if ok:
            ax.plot(
                [r[cost_key] for r in ok],
                [r[err_key] for r in ok],
                "-",
                color=colours[name],
                lw=1.2,
                alpha=0.85,
            )
            for r in ok:
                ax.plot(r[cost_key], r[err_key], _marker(r["tolerance"]), color=colours[name], ms=5)
        for r in bad:
            ax.plot(r[cost_key], top, "x", color=colours[name], ms=7, mew=2, clip_on=False)
    _log_axes(ax, bool(tops))
    return top


def _log_axes(ax, has_data: bool) -> None:
    """Log–log axes, or a note where no run has a positive value to draw."""
    if has_data:
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.grid(True, which="major", alpha=0.3)
    else:
        ax.text(
            0.5,
            0.5,
            "no positive values",
            ha="center",
            va="center",
            transform=ax.transAxes,
            color="gray",
        )


def work_precision_chart(rows: list[dict], title: str, path) -> None:
    """Error (3 measures) against wall time and RHS evaluations for one model."""
    methods = list(_by_method(rows))
    cmap = [f"C{i}" for i in range(10)] + ["#444444", "#aa7700"]
    colours = {m: cmap[i % len(cmap)] for i, m in enumerate(methods)}
    fig = Figure(figsize=(11, 10.5))
    axes = fig.subplots(3, 2, sharex="col", sharey="row")
    for i, (ek, elab) in enumerate(ERRORS):
        for j, (ck, clab) in enumerate(COSTS):
            _panel(axes[i, j], rows, ek, ck, colours)
            if j == 0:
                axes[i, j].set_ylabel(elab)
            if i == 2:
                axes[i, j].set_xlabel(clab)
    lines = [Line2D([], [], color=colours[m], lw=1.5, label=m) for m in methods]
    lines.append(
        Line2D(
            [],
            [],
            ls="",
            marker="x",
            color="k",
            mew=2,
            label="missed / added transitions (error ∞)",
        )
    )
    decades = sorted({_decade(r["tolerance"]) for r in rows})
    marks = [
        Line2D([], [], ls="", marker=MARKERS[d % len(MARKERS)], color="gray", label=f"1e-{d}")
        for d in decades
    ]
    fig.legend(
        handles=lines,
        loc="upper left",
        bbox_to_anchor=(0.08, 0.965),
        ncol=3,
        fontsize=8,
        frameon=False,
    )
    fig.legend(
        handles=marks,
        loc="upper right",
        bbox_to_anchor=(0.98, 0.965),
        ncol=4,
        fontsize=8,
        title="marker: rtol, or Δt (s)",
        title_fontsize=8,
        frameon=False,
    )
    failed = sorted(
        {f"{r['method']} @ {r['tolerance']:g}" for r in rows if r["status"] == "failed"}
    )
    note = ("solver failed (not drawn): " + ", ".join(failed)) if failed else ""
    fig.suptitle(title, fontsize=12, y=0.995)
    fig.text(0.5, 0.004, note[:220], ha="center", fontsize=7.5)
    fig.subplots_adjust(top=0.87, bottom=0.085, left=0.09, right=0.98, hspace=0.08, wspace=0.05)
    for ax in axes.flat:
        _major_labels_only(ax)
    fig.savefig(path, dpi=DPI)


def _major_labels_only(ax) -> None:
    """No minor tick labels on a log axis that shows a power of ten: on a 1.5-decade axis
    matplotlib labels the minor ticks too, and they ran into each other."""
    for axis, (lo, hi) in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
        lo, hi = sorted((lo, hi))
        if (
            axis.get_scale() == "log"
            and lo > 0
            and math.floor(math.log10(hi)) >= math.ceil(math.log10(lo))
        ):
            axis.set_minor_formatter(NullFormatter())


def _worst(kinds: list[str]) -> str:
    return min(kinds, key=KINDS.index) if kinds else "ok"


def failure_map_chart(rows: list[dict], path) -> None:
    """Grid of (model · method) × level, coloured by the most severe failure kind."""
    groups = []
    for r in rows:
        key = (r["model"], r["method"])
        if key not in groups:
            groups.append(key)
    width = max(len([r for r in rows if (r["model"], r["method"]) == g]) for g in groups)
    fig = Figure(figsize=(1.2 * width + 4.5, 0.27 * len(groups) + 1.6))
    ax = fig.add_subplot(111)
    for y, g in enumerate(groups):
        rs = sorted(
            (r for r in rows if (r["model"], r["method"]) == g),
            key=lambda r: r["tolerance"],
            reverse=_loosest_first(g),
        )
        for x, r in enumerate(rs):
            kind = _worst(r["failure"])
            ax.fill_between([x, x + 1], y, y + 1, color=FAILURE_COLOURS[kind], ec="white", lw=1)
            label = f"{r['tolerance']:g}" + (
                "+" * (len(r["failure"]) - 1) if len(r["failure"]) > 1 else ""
            )
            ax.text(
                x + 0.5,
                y + 0.5,
                label,
                ha="center",
                va="center",
                fontsize=6.5,
                color="white"
                if kind in ("solver_failed", "missed_impacts", "not_converging")
                else "black",
            )
    ax.set_xlim(0, width)
    ax.set_ylim(len(groups), 0)
    ax.set_yticks(np.arange(len(groups)) + 0.5)
    ax.set_yticklabels([f"{m} · {meth}" for m, meth in groups], fontsize=7)
    ax.set_xticks([])
    ax.set_xlabel(
        "level: rtol, Δt (s) or stiffness scale, loosest → tightest (+: more than one failure)",
        fontsize=8,
    )
    handles = [Patch(color=FAILURE_COLOURS[k], label=k.replace("_", " ")) for k in ("ok",) + KINDS]
    ax.legend(
        handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1), fontsize=7.5, frameon=False
    )
    ax.set_title("Where methods fail (most severe failure per run)", fontsize=10)
    fig.subplots_adjust(
        left=0.32, right=0.84, top=1 - 0.5 / fig.get_figheight(), bottom=0.6 / fig.get_figheight()
    )
    fig.savefig(path, dpi=DPI)


def _loosest_first(group) -> bool:
    """Loosest first: rtol and Δt descending; stiffness ascending (stiffer = harder)."""
    return group[0] != "S1 stiffness"


def stiffness_chart(rows: list[dict], path) -> None:
    """Stiffness sweep: RHS evaluations, wall time and peak error against the scale."""
    fig = Figure(figsize=(15, 4.2))
    axes = fig.subplots(1, 4)
    keys = (
        ("n_rhs", "RHS evaluations"),
        ("wall_time_s", "wall time (s)"),
        ("peak_error_rad", "max |Δ peak| (rad)"),
        ("event_time_error_s", "max |Δ event time| (s)"),
    )
    for ax, (k, lab) in zip(axes, keys):
        any_data = False
        for i, (name, rs) in enumerate(_by_method(rows).items()):
            rs = sorted(rs, key=lambda r: r["tolerance"])
            ok = [r for r in rs if r["status"] != "failed" and np.isfinite(r[k]) and r[k] > 0]
            any_data |= bool(ok)
            ax.plot(
                [r["tolerance"] for r in ok],
                [r[k] for r in ok],
                "-o",
                color=f"C{i}",
                ms=4,
                label=name,
            )
            for r in ok:
                if "cost_blowup" in r["failure"] and k in ("n_rhs", "wall_time_s"):
                    ax.plot(r["tolerance"], r[k], "o", mfc="none", mec="k", ms=9)
        _log_axes(ax, any_data)
        ax.set_xlabel("stiffness scale (E_s, K_rot, K_fp ×)")
        ax.set_ylabel(lab)
    axes[0].legend(fontsize=7.5)
    axes[0].plot([], [], "o", mfc="none", mec="k", ms=9, label="cost blow-up")
    axes[0].legend(fontsize=7.5)
    fig.suptitle(
        "S1 with scaled stiffness, released from 0.11 rad, CIM, rtol "
        f"{rows[0].get('rtol', 0):g}: explicit cost grows with the top frequency",
        fontsize=10,
    )
    fig.subplots_adjust(left=0.05, right=0.99, wspace=0.32, bottom=0.14, top=0.88)
    fig.savefig(path, dpi=DPI)
