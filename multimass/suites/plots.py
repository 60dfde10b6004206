"""Figures of a suite's runs table: fragility curves, IDA curves, pulse fragility, IM efficiency.

Each function draws on a matplotlib `~matplotlib.figure.Figure` (no pyplot, the Agg
canvas), saves it to `path` and returns the path. The numbers come from
`multimass.suites.analysis` (lognormal fits of Baker 2015; the dimensionless pulse
fragility of Dimitrakopoulos & Paraskeva 2015); nothing is fitted here that the analysis
does not fit.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib import colormaps
from matplotlib.cm import ScalarMappable
from matplotlib.colors import LogNorm, Normalize
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import FormatStrFormatter, LogLocator

from ..analysis.fragility import fit_lognormal
from . import analysis as _a

__all__ = ["plot_fragility", "plot_ida", "plot_pulse_fragility", "plot_im_efficiency"]

# distinct in lightness as well as hue, one per damage state
_COLOURS = ["#b2182b", "#2166ac", "#1b7837", "#762a83", "#e08214"]
_MARKERS = ["o", "s", "^", "D", "v"]


def _save(fig: Figure, path) -> Path:
    path = Path(path)
    fig.savefig(path, dpi=120)
    return path


def _plain_log_ticks(axis) -> None:
    """Ticks 1, 2, 5 × 10^k written plainly (0.5, 2, 10) on a log axis."""
    axis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(FormatStrFormatter("%g"))
    axis.set_minor_formatter(FormatStrFormatter(""))


def _measure_text(label: str) -> str:
    if label == "overturned":
        return "overturning"
    return label.replace("theta_over_alpha>=", "θ_max/α ≥ ")


def _band_text(row) -> str:
    if row["band"] == "bootstrap":
        return f"bootstrap {row['band_level']:.0%} band ({row['n_resamples']} resamples)"
    return f"Fisher {row['band_level']:.0%} band"


def plot_fragility(runs, curves, path, title: str = "") -> Path:
    """Empirical exceedance fractions and the fitted lognormal CDF of each damage state.

    Parameters
    ----------
    runs : pandas.DataFrame
        The runs table the curves were fitted to.
    curves : pandas.DataFrame
        `multimass.suites.analysis.fragility_curves` of `runs` (its ``im``, ``measure``
        and band columns say what to draw).
    path : str or Path
        Where to save the figure (the format follows the suffix).

    Notes
    -----
    Per-level counts are drawn as one marker per level, its area proportional to the
    number of runs there. Per-run data (the IM differs between the runs of a level) are
    drawn as one marker per level at the geometric mean of its runs' IM, plus a rug of
    the runs themselves at 0 (did not exceed) and 1 (exceeded). The fitted curve is
    Φ(ln(x/θ)/β) (Baker 2015) with its band (Fisher, or bootstrap as in `curves`); a
    damage state without a fit is listed in the legend with the reason and the range
    the data leave for θ shaded.
    """
    im = str(curves["im"].iloc[0])
    structure = curves["structure"].iloc[0] if "structure" in curves else None
    measures = list(curves["measure"])
    counts = _a.exceedance_counts(runs, im=im, measures=measures, structure=structure)
    used = counts[counts["n_runs"] > 0]
    xs = used["im"].to_numpy(dtype=float)
    grid = np.geomspace(xs.min() / 1.5, xs.max() * 1.5, 300)
    per_run = counts.attrs["grouping"] == "run"
    row0 = curves.iloc[0]
    boot = int(row0["n_resamples"]) if row0["band"] == "bootstrap" else 0
    _, fits = _a._fits(
        runs,
        im,
        measures,
        boot,
        int(row0["band_seed"]),
        float(row0["band_level"]),
        structure,
        grid,
    )

    fig = Figure(figsize=(8.5, 5.2), layout="constrained")
    ax = fig.subplots()
    n_max = max(int(used["n_runs"].max()), 1)
    for i, (res, (_, row)) in enumerate(zip(fits, curves.iterrows())):
        c, mk = _COLOURS[i % len(_COLOURS)], _MARKERS[i % len(_MARKERS)]
        col = f"n_exceed[{res.measure.label}]"
        if per_run:
            g = used.assign(lx=np.log(used["im"])).groupby("level")
            pts_x = np.exp(g["lx"].mean()).to_numpy()
            n = g["n_runs"].sum().to_numpy()
            frac = (g[col].sum() / g["n_runs"].sum()).to_numpy()
            jitter = 0.012 * (i - (len(fits) - 1) / 2)
            hit = used[col].to_numpy() > 0
            ax.plot(xs, np.where(hit, 1.03, -0.03) + jitter, "|", color=c, ms=6, alpha=0.35, lw=0.8)
        else:
            pts_x = xs
            n = used["n_runs"].to_numpy()
            frac = used[col].to_numpy() / n
        ax.scatter(
            pts_x,
            frac,
            s=12 + 90 * n / (n.max() if per_run else n_max),
            marker=mk,
            facecolor="none",
            edgecolor=c,
            lw=1.2,
            zorder=3,
        )
        name = _measure_text(res.measure.label)
        if row["converged"] or (row["status"] == 3 and math.isfinite(row["theta"])):
            p = res.fit.probability(grid) if row["converged"] else None
            if p is not None:
                ax.plot(
                    grid,
                    p,
                    color=c,
                    lw=2,
                    label=f"{name}: θ = {row['theta']:.3g} {row['unit']}, β = {row['beta']:.2f}",
                )
            else:
                ax.axvline(row["theta"], color=c, lw=2, ls="--", label=f"{name}: step at θ")
            if res.band is not None:
                ax.fill_between(grid, res.band.lower, res.band.upper, color=c, alpha=0.15, lw=0)
        else:
            lo, hi = row["theta_bound_low"], row["theta_bound_high"]
            if math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi:
                ax.axvspan(lo, hi, color=c, alpha=0.08, hatch="//", lw=0)
            ax.plot([], [], color=c, lw=2, ls=":", label=f"{name}: no fit — {_short(row)}")
    ax.set_xscale("log")
    _plain_log_ticks(ax.xaxis)
    ax.set_ylim(-0.07, 1.07)
    ax.set_xlabel(_a.im_label(str(row0["im_name"])))
    ax.set_ylabel("P(exceedance | IM)")
    ax.grid(alpha=0.3, which="both")
    handles, labels = ax.get_legend_handles_labels()
    handles.append(
        Line2D([], [], ls="", marker="o", mfc="none", color="0.3", label="fraction of runs")
    )
    labels.append(
        "fraction per level (mean IM of its runs; ticks: runs)"
        if per_run
        else "fraction of runs per level (area ∝ runs)"
    )
    handles.append(Line2D([], [], color="0.6", lw=6, alpha=0.4))
    labels.append(_band_text(row0))
    ax.legend(handles, labels, fontsize=8, loc="lower right")
    n_ex = counts.attrs["n_excluded"]
    ax.set_title(
        title
        or f"{structure or 'structure'}: fragility in {_a.im_label(str(row0['im_name']))}\n"
        f"{counts.attrs['n_runs']} runs"
        + (f", {n_ex} inaccurate/failed left out" if n_ex else "")
        + f" · lognormal MLE (Baker 2015), counts per {counts.attrs['grouping']}"
    )
    return _save(fig, path)


def _short(row) -> str:
    msg = str(row["message"])
    return msg.split(":")[0].split(";")[0].split(" (")[0]


def plot_ida(runs, path, im: str = "im", structure=None, title: str = "") -> Path:
    """IDA curves: θ_max/α (x) against the intensity (y), one colour per record.

    Thin lines are the draws, the thick line the median over the draws
    (`multimass.suites.analysis.ida_summary`); an overturned run is a cross at
    θ_max/α = 1 (the dashed line; θ_max/α is clipped there), and the lowest IM at which
    half the draws overturn is a filled marker on the median. Inaccurate/failed runs
    are left out and counted in the title.
    """
    curves = _a.ida_curves(runs, im=im, structure=structure)
    summary = _a.ida_summary(runs, im=im, structure=structure)
    ok = curves[curves["included"]]
    motions = list(summary["motion"])
    cmap = colormaps["tab10" if len(motions) <= 10 else "tab20"]
    fig = Figure(figsize=(8.0, 5.5), layout="constrained")
    ax = fig.subplots()
    for i, motion in enumerate(motions):
        c = cmap(i % cmap.N)
        g = ok[ok["motion"] == motion]
        for _, d in g.groupby("draw"):
            r = np.minimum(d["theta_max_over_alpha"].to_numpy(dtype=float), 1.0)
            ax.plot(r, d["im"], "-", color=c, lw=0.6, alpha=0.35)
        over = g[g["overturned"].astype(bool)]
        ax.plot(np.ones(len(over)), over["im"], "x", color=c, ms=5, alpha=0.6)
        s = summary[summary["motion"] == motion].iloc[0]
        med = np.minimum(np.asarray(s["median_theta_over_alpha"]), 1.0)
        ax.plot(med, s["im"], "-", color=c, lw=2.5, label=str(motion))
        if math.isfinite(s["im_overturn_50"]):
            ax.plot(1.0, s["im_overturn_50"], "o", color=c, ms=8, mec="k", zorder=4)
    ax.axvline(1.0, color="0.3", ls="--", lw=1)
    ax.set_xlim(0, 1.08)
    ax.set_xlabel("θ_max/α (1 = overturning)")
    ax.set_ylabel(_a.im_label(curves.attrs["im_name"]))
    ax.grid(alpha=0.3)
    handles, labels = ax.get_legend_handles_labels()
    if len(motions) > 12:
        handles, labels = handles[:0], labels[:0]
    handles += [
        Line2D([], [], color="0.4", lw=0.6, alpha=0.6),
        Line2D([], [], color="0.4", lw=2.5),
        Line2D([], [], ls="", marker="x", color="0.4"),
        Line2D([], [], ls="", marker="o", color="0.4", mec="k"),
    ]
    labels += ["one draw", "median over draws", "overturned run", "≥ 50 % of draws overturn"]
    ax.legend(handles, labels, fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    n_ex = int((~curves["included"]).sum())
    n_draws = int(summary["n_draws"].max())
    ax.set_title(
        title
        or f"{curves.attrs['structure'] or 'structure'}: IDA, {len(motions)} records × "
        f"{n_draws} draws"
        + (f" ({n_ex} inaccurate/failed run(s) left out)" if n_ex else "")
    )
    return _save(fig, path)


def plot_pulse_fragility(
    runs, path, measure="overturned", level: float = 0.95, structure=None, title: str = ""
) -> Path:
    """Dimensionless pulse fragility (Dimitrakopoulos & Paraskeva 2015), two panels.

    Left: the fraction of runs that exceed against a_p/(g tan α), one colour per ω_p/p
    (colour scale), with the fitted lognormal curves. Right: the median θ of a_p/(g tan α)
    with its confidence band against ω_p/p; an ω_p/p without a fit is shown by the range
    the data leave for θ (a grey bar), or an arrow when no run there exceeded.
    """
    pf = _a.pulse_fragility(runs, measure=measure, level=level, structure=structure)
    curves, counts = pf.curves, pf.counts
    ws = curves["omega_p_over_p"].to_numpy(dtype=float)
    log_w = ws.size > 1 and ws.min() > 0 and ws.max() / ws.min() > 10
    norm = (LogNorm if log_w else Normalize)(vmin=ws.min(), vmax=max(ws.max(), ws.min() * 1.0001))
    cmap = colormaps["viridis"]
    fig = Figure(figsize=(11.0, 4.8), layout="constrained")
    ax, bx = fig.subplots(1, 2)
    used = counts[counts["n_runs"] > 0]
    amps = used["amp_over_g_tan_alpha"].to_numpy(dtype=float)
    grid = np.geomspace(amps.min() / 1.3, amps.max() * 1.3, 200)
    for _, row in curves.iterrows():
        w = row["omega_p_over_p"]
        c = cmap(norm(w))
        g = used[used["omega_p_over_p"] == w]
        ax.plot(g["amp_over_g_tan_alpha"], g["fraction"], "o", ms=3.5, color=c, alpha=0.8)
        if row["converged"]:
            fit = fit_lognormal(g["amp_over_g_tan_alpha"], g["n_runs"], g["n_exceed"])
            ax.plot(grid, fit.probability(grid), "-", color=c, lw=1.5)
    ax.set_xscale("log")
    _plain_log_ticks(ax.xaxis)
    ax.set_ylim(-0.03, 1.03)
    ax.set_xlabel("a_p/(g tan α)")
    ax.set_ylabel(f"P({_measure_text(pf.measure)})")
    ax.grid(alpha=0.3, which="both")
    ax.legend(
        [
            Line2D([], [], ls="", marker="o", color="0.4"),
            Line2D([], [], color="0.4", lw=1.5),
        ],
        ["fraction of runs", "lognormal fit"],
        fontsize=8,
        loc="upper left",
    )
    fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=ax, label="ω_p/p")

    ok = curves[curves["converged"]]
    if len(ok):
        yerr = np.vstack([ok["theta"] - ok["theta_low"], ok["theta_high"] - ok["theta"]])
        bx.errorbar(
            ok["omega_p_over_p"],
            ok["theta"],
            yerr=yerr,
            fmt="o-",
            color="k",
            ecolor="0.5",
            capsize=3,
            ms=4,
            label=f"median θ, Fisher {level:.0%} band",
        )
        bx.scatter(
            ok["omega_p_over_p"],
            ok["theta"],
            c=ok["omega_p_over_p"],
            cmap=cmap,
            norm=norm,
            zorder=3,
            s=25,
        )
    bad = curves[~curves["converged"]]
    labelled = set()

    def once(text):
        if text in labelled:
            return None
        labelled.add(text)
        return text

    for _, row in bad.iterrows():
        lo, hi = row["theta_bound_low"], row["theta_bound_high"]
        w = row["omega_p_over_p"]
        if row["status"] == 1:  # nothing exceeded: θ above the largest amplitude
            bx.plot(w, lo, "^", color="tab:red", label=once("no fit: θ above the largest a_p"))
        elif math.isfinite(lo) and math.isfinite(hi) and hi > 0:
            bx.plot(
                [w, w],
                [max(lo, amps.min()), hi],
                color="0.6",
                lw=5,
                alpha=0.6,
                label=once("no fit: range the data leave for θ"),
            )
    bx.set_xlabel("ω_p/p")
    bx.set_ylabel(
        f"median a_p/(g tan α) to {_measure_text(pf.measure).replace('overturning', 'overturn')}"
    )
    if log_w:
        bx.set_xscale("log")
        _plain_log_ticks(bx.xaxis)
    bx.set_yscale("log")
    _plain_log_ticks(bx.yaxis)
    bx.grid(alpha=0.3, which="both")
    if bx.get_legend_handles_labels()[0]:
        bx.legend(fontsize=8, loc="upper left")
    n_ex = curves.attrs.get("n_excluded", 0)
    fig.suptitle(
        title
        or f"{curves.attrs.get('structure') or 'structure'}: dimensionless pulse fragility "
        f"(Dimitrakopoulos & Paraskeva 2015), {int(curves['n_runs'].sum())} runs"
        + (f", {n_ex} inaccurate/failed left out" if n_ex else "")
    )
    return _save(fig, path)


def plot_im_efficiency(table, path, title: str = "") -> Path:
    """Bar chart of the dispersion β per IM (`multimass.suites.analysis.im_efficiency`).

    Smaller β = more efficient IM. Bars carry their Fisher 95 % band; an IM whose fit has
    no maximum gets an empty hatched bar and the reason.
    """
    fig = Figure(figsize=(max(5.0, 1.1 * len(table) + 2.5), 4.5), layout="constrained")
    ax = fig.subplots()
    x = np.arange(len(table))
    beta = table["beta"].to_numpy(dtype=float)
    finite = np.isfinite(beta)
    top = np.nanmax(np.r_[table["beta_high"].to_numpy(dtype=float), beta, 0.1])
    top = top if math.isfinite(top) else 1.0
    colours = np.where(finite, "#2166ac", "none")
    ax.bar(x[finite], beta[finite], color=colours[finite], width=0.6)
    lo = (beta - table["beta_low"].to_numpy(dtype=float))[finite]
    hi = (table["beta_high"].to_numpy(dtype=float) - beta)[finite]
    ok_err = np.isfinite(lo) & np.isfinite(hi)
    ax.errorbar(
        x[finite][ok_err],
        beta[finite][ok_err],
        yerr=np.vstack([lo[ok_err], hi[ok_err]]),
        fmt="none",
        ecolor="k",
        capsize=4,
    )
    for xi, b in zip(x[finite], beta[finite]):
        ax.text(xi - 0.27, b, f"{b:.2f}", ha="left", va="bottom", fontsize=8)
    for xi, (_, row) in zip(x, table.iterrows()):
        if not math.isfinite(row["beta"]):
            ax.bar(xi, top * 1.15, width=0.6, facecolor="none", edgecolor="0.85", hatch="//")
            ax.text(
                xi,
                top * 0.5,
                f"no fit\n(status {row['status']}:\n{_short(row)})",
                ha="center",
                va="center",
                fontsize=7,
                wrap=True,
                bbox={"facecolor": "white", "edgecolor": "none", "pad": 1},
            )
    ax.set_xticks(x, [_a.im_label(str(i)) for i in table["im"]], rotation=20, ha="right")
    ax.set_ylabel("β of the fragility curve (smaller = more efficient)")
    ax.set_ylim(0, top * 1.15)
    ax.grid(alpha=0.3, axis="y")
    measure = table.attrs.get("measure", "overturned")
    ax.set_title(
        title
        or f"IM efficiency: dispersion β of the {_measure_text(measure)} fragility"
        "\n(lognormal MLE, Baker 2015; bars: Fisher 95 % band)"
    )
    return _save(fig, path)
