"""Charts and Markdown of ``multimass bench --scaling`` (`multimass.bench.scaling`).

Each chart is log–log: the median wall time of every point with its min–max bar,
and the fitted power law of each series drawn over its fitted range, its
exponent in the legend.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import FormatStrFormatter, LogLocator

__all__ = ["scaling_charts", "scaling_markdown"]

_STYLE = {
    "brute_force": ("C0", "o", "brute force"),
    "adaptive": ("C1", "s", "adaptive"),
    "adaptive_computed_cells": ("C2", "^", "adaptive: cells computed"),
    "compiled": ("C0", "o", "compiled (full contact in closed form)"),
    "compiled_rk": ("C2", "^", "compiled, every phase RK"),
    "exponential": ("C1", "D", "compiled, exponential method"),
    "scipy": ("C3", "s", "solve_ivp"),
    "map": ("C0", "o", "map"),
    "machine": ("0.4", "D", "machine's own (pure-Python loop)"),
}


def _exp(fit: dict | None) -> str:
    if not fit or fit.get("exponent") is None:
        return "exponent: —"
    se = f" ± {fit['stderr']:.2f}" if fit.get("stderr") is not None else ""
    lo, hi = fit["size_range"]
    return f"exponent {fit['exponent']:.2f}{se} over {lo:g}–{hi:g}"


def _series(ax, x, spreads, fit, key):
    colour, marker, label = _STYLE[key]
    x = np.asarray(x, dtype=float)
    med = np.array([s["median"] for s in spreads])
    err = np.array(
        [[s["median"] - s["min"] for s in spreads], [s["max"] - s["median"] for s in spreads]]
    )
    ax.errorbar(x, med, yerr=err, color=colour, marker=marker, ls="none", capsize=3)
    if fit and fit.get("exponent") is not None:
        lo, hi = fit["size_range"]
        xx = np.geomspace(lo, hi, 50)
        ax.plot(
            xx,
            fit["prefactor"] * xx ** fit["exponent"],
            color=colour,
            lw=1.2,
            label=f"{label}: {_exp(fit)}",
        )
    else:
        ax.plot([], [], color=colour, marker=marker, label=f"{label}: {_exp(fit)}")


def _axes(ax, xlabel, ylabel, title, xticks=None):
    ax.set_xscale("log")
    if ax.get_yscale() != "log":  # (setting it again would drop a chart's own locators)
        ax.set_yscale("log")
    if xticks:
        ax.set_xticks(xticks, [str(k) for k in xticks])
        ax.set_xticks([], minor=True)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(_wrap(title), fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="best")


def _wrap(title: str, width: int = 80) -> str:
    return "\n".join(textwrap.fill(line, width) for line in title.splitlines())


def _finish(fig, ax, xlabel, ylabel, title, path: Path, xticks=None):
    _axes(ax, xlabel, ylabel, title, xticks)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def _cells_chart(res: dict, path: Path):
    c = res["cells"]
    fig = Figure(figsize=(6.4, 4.6))
    ax = fig.subplots()
    for key, pts in c["series"].items():
        _series(ax, [p["cells"] for p in pts], [p["seconds"] for p in pts], c["fits"][key], key)
    title = f"Map cost against cells ({res['config']['name']} run)\n{c['case']}"
    if c.get("note"):
        title += f"\n{c['note']}"
    _finish(fig, ax, "cells in the grid", "wall time (s)", title, path)


def _workers_chart(res: dict, path: Path):
    w = res["workers"]
    fig = Figure(figsize=(6.4, 4.6))
    ax = fig.subplots()
    ws = w["workers"]
    for key, field in (("map", "map_seconds"), ("machine", "machine_seconds")):
        spreads = [w[field][str(k)] for k in ws]
        _series(ax, ws, spreads, w["fits"][key], key)
        # the ideal 1/workers line from the 1-worker median
        ax.plot(ws, [spreads[0]["median"] / k for k in ws], color=_STYLE[key][0], ls=":", lw=1)
    ax.plot([], [], color="k", ls=":", lw=1, label="ideal: exponent −1")
    title = f"Map cost against workers ({res['config']['name']} run)\n{w['case']}"
    # under a decade of wall time: labelled minor ticks, plain numbers
    ax.set_yscale("log")
    ax.yaxis.set_minor_locator(LogLocator(subs=(1.25, 1.5, 1.75, 2.0, 3.0, 5.0, 8.0)))
    ax.yaxis.set_minor_formatter(FormatStrFormatter("%g"))
    ax.yaxis.set_major_formatter(FormatStrFormatter("%g"))
    _finish(fig, ax, "workers", "wall time (s)", title, path, xticks=ws)


def _per_rhs(p: dict) -> dict:
    return {k: p["seconds"][k] / p["n_rhs"] for k in ("median", "min", "max")}


def _nodes_chart(res: dict, path: Path):
    nd = res["nodes"]
    fig = Figure(figsize=(11.0, 4.8))
    total, each = fig.subplots(1, 2)
    for key, pts in nd["series"].items():
        ns = [p["N"] for p in pts]
        _series(total, ns, [p["seconds"] for p in pts], nd["fits"][key], key)
        if f"{key}_per_rhs" in nd["fits"]:  # paths whose every phase takes RHS calls
            _series(each, ns, [_per_rhs(p) for p in pts], nd["fits"][f"{key}_per_rhs"], key)
    ns = sorted({p["N"] for pts in nd["series"].values() for p in pts})
    _axes(total, "nodes N", "wall time (s)", "whole run", ns)
    _axes(each, "nodes N", "wall time per RHS evaluation (s)", "per RHS evaluation", ns)
    title = f"Column engine cost against N ({res['config']['name']} run): {nd['case']}"
    if nd["skipped"]:
        sk = ", ".join(f"{s['backend']} N={s['N']}" for s in nd["skipped"])
        title += f"\nskipped (estimate over budget): {sk}"
    fig.suptitle(_wrap(title, 140), fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def scaling_charts(res: dict, out: Path) -> list[str]:
    """Write the three charts of `res` (a `run_scaling` result) into `out`; their names."""
    out = Path(out)
    names = []
    for name, chart in (
        ("scaling_cells.png", _cells_chart),
        ("scaling_workers.png", _workers_chart),
        ("scaling_nodes.png", _nodes_chart),
    ):
        chart(res, out / name)
        names.append(name)
    return names


def _fmt(s: dict) -> str:
    return f"{s['median']:.3g} ({s['min']:.3g}–{s['max']:.3g})"


def _fit_row(name: str, fit: dict) -> str:
    if fit.get("exponent") is None:
        return f"| {name} | — | — | — | {fit.get('points', 0)} |"
    se = f"{fit['stderr']:.2f}" if fit.get("stderr") is not None else "—"
    lo, hi = fit["size_range"]
    return f"| {name} | {fit['exponent']:.2f} | {se} | {lo:g}–{hi:g} | {fit['points']} |"


def _fits(fits: dict) -> list[str]:
    return [
        "| series | exponent | std. error | sizes fitted | points |",
        "|---|---|---|---|---|",
    ] + [_fit_row(k, f) for k, f in fits.items()]


def scaling_markdown(res: dict) -> str:
    """The tables of `res` (a `run_scaling` result): every point, then the exponents."""
    cfg, c, w, nd = res["config"], res["cells"], res["workers"], res["nodes"]
    lines = [
        f"# How cost grows (`multimass bench --scaling`, {cfg['name']} run)",
        "",
        f"Wall time {res['wall_time_s']:.0f} s on {res['machine']['cpus']} CPUs; load average "
        f"{res['machine']['load_average_start'][0]:.2f} at the start, "
        f"{res['machine']['load_average_end'][0]:.2f} at the end. Each point: median "
        f"(min–max) of {cfg['repeats']} runs, seconds. Exponent: least-squares slope of log "
        "time against log size (cost ∝ size^exponent).",
        "",
        "## Map cost against cells",
        "",
        c["case"] + ".",
        "",
        "| grid | cells | method | computed cells | seconds | µs per grid cell |",
        "|---|---|---|---|---|---|",
    ]
    for name, pts in c["series"].items():
        lines += [
            f"| {p['side']}×{p['side']} | {p['cells']} | {name} | {p['computed']} | "
            f"{_fmt(p['seconds'])} | {p['us_per_cell']:.3g} |"
            for p in pts
        ]
    lines += [""] + _fits(c["fits"]) + [""]
    if c.get("note"):
        lines += [f"Note: {c['note']}.", ""]
    lines += [
        "## Map cost against workers",
        "",
        w["case"] + "; beside it " + w["machine"] + ".",
        "",
    ]
    lines += ["| workers | map seconds | machine seconds |", "|---|---|---|"] + [
        f"| {k} | {_fmt(w['map_seconds'][str(k)])} | {_fmt(w['machine_seconds'][str(k)])} |"
        for k in w["workers"]
    ]
    lines += [""] + _fits(w["fits"]) + [""]
    if "speedup_2_workers" in w:
        sp = w["speedup_2_workers"]
        lines += [
            f"1 worker over 2: map {_fmt(sp['map'])}, the machine's own {_fmt(sp['machine'])} "
            "(ideal 2; exponent −1).",
            "",
        ]
    lines += ["## Column engine cost against nodes", "", nd["case"] + ".", ""]
    lines += [
        "| N | path | seconds | estimate (s) | RHS evaluations | events | outcome |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, pts in nd["series"].items():
        lines += [
            f"| {p['N']} | {name} | {_fmt(p['seconds'])} | {p['estimate_s']:.3g} | {p['n_rhs']} | "
            f"{p['events']} | {p['outcome']} |"
            for p in pts
        ]
    lines += [""] + _fits(nd["fits"]) + [""]
    lines += [
        "Paths: `compiled` as run by default (full contact in closed form between "
        "events, no RHS calls there), `compiled_rk` with every phase on the compiled "
        "Runge–Kutta pair, `exponential` as `compiled` with the rocking phases advanced by "
        'the exponential method (`method="exponential"`: the elastic modes exactly, '
        "its steps set by accuracy alone), `scipy` solve_ivp. For `compiled_rk` and "
        "`scipy`, whole-run cost = RHS evaluations × cost per evaluation (`_per_rhs` rows). "
        "The number of evaluations need not grow with N: impacts set the steps of few-node "
        "columns, the stiffest mode (|λ_max| growing with N) those of many-node ones "
        "(except with the exponential method); "
        "the whole-run exponent summarises both, the per-evaluation exponent is the engine's.",
        "",
    ]
    if nd["skipped"]:
        lines += [
            "Skipped (estimated over the budget per run: "
            + ", ".join(f"{k} {v:g} s" for k, v in nd["budget_s"].items())
            + "): "
            + ", ".join(
                f"{s['backend']} N={s['N']} (~{s['estimate_s']:.3g} s)" for s in nd["skipped"]
            )
            + ".",
            "",
        ]
    lines += [f"Charts: {', '.join(res.get('charts', []))}.", ""]
    return "\n".join(lines)
