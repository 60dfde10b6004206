"""Figures of the Moreau–Jean simulations and convergence studies (paper 002, Figs 10–19).

Plotting only; the numbers come from `multimass.engines.nscd.run` and `nscd.convergence`.
Every convergence figure states its verdicts, and a study that does not
converge says so in red in its title.

Layout rules, which the tests check on every figure: a legend sits outside
the axes it labels (it never hides a curve or a marker line); every text lies
inside the figure; every line contrasts with the white background at least
3:1 (the WCAG ratio for graphics: no yellow on white). Each ``*_figure``
function returns the figure; each ``plot_*`` function saves it.
"""

from __future__ import annotations

import math
import textwrap
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

__all__ = [
    "plot_history",
    "plot_study",
    "plot_first_peak",
    "plot_flexibility",
    "history_figure",
    "study_figure",
    "first_peak_figure",
    "flexibility_figures",
    "PALETTE",
]

_DPI = 100
_STATUS_COLOUR = {
    "converged": "tab:green",
    "converging": "#d95f02",
    "not converged": "tab:red",
    "undetermined": "tab:gray",
    "failed": "tab:red",
}
#: line colours, each at least 3:1 against white; the finest level (or the reference) is black
PALETTE = (
    "tab:blue",
    "#d95f02",
    "tab:green",
    "tab:red",
    "tab:purple",
    "tab:brown",
    "#e7298a",
    "tab:gray",
)


def _save(fig, path: Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=_DPI)
    return path


def _legend_outside(ax, **kw):
    """The legend to the right of the axes, outside the data area."""
    return ax.legend(
        fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, **kw
    )


def _thin(t, y, n=4000):
    """At most ~n points per line, keeping the extremes of each bin (peaks stay visible)."""
    if t.size <= n:
        return t, y
    k = int(math.ceil(t.size / (n // 2)))
    m = (t.size // k) * k
    tb, yb = t[:m].reshape(-1, k), y[:m].reshape(-1, k)
    i_min, i_max = yb.argmin(1), yb.argmax(1)
    first = np.minimum(i_min, i_max)
    second = np.maximum(i_min, i_max)
    rows = np.arange(tb.shape[0])
    tt = np.column_stack([tb[rows, first], tb[rows, second]]).ravel()
    yy = np.column_stack([yb[rows, first], yb[rows, second]]).ravel()
    return tt, yy


def _reference_lines(ax, res, exact_first_peak_deg, paper_first_peak_deg, paper_rest_time_s):
    p = res.params
    if paper_first_peak_deg is not None:
        ax.axhline(
            paper_first_peak_deg,
            color="tab:red",
            ls=":",
            lw=1,
            label=f"paper 002 first peak ±{paper_first_peak_deg:g}°",
        )
        ax.axhline(-paper_first_peak_deg, color="tab:red", ls=":", lw=1)
    if exact_first_peak_deg is not None:
        ax.axhline(
            -exact_first_peak_deg if p["theta0"] > 0 else exact_first_peak_deg,
            color="k",
            ls="--",
            lw=0.8,
            label=f"rigid block, Housner η: {exact_first_peak_deg:.3f}°",
        )
    if res.rest_time is not None:
        ax.axvline(
            res.rest_time,
            color="tab:green",
            lw=1,
            label=f"at rest (|θ| < {100 * p['rest_fraction']:g} % θ0): {res.rest_time:.2f} s",
        )
    if paper_rest_time_s is not None:
        ax.axvline(
            paper_rest_time_s,
            color="tab:red",
            ls="-.",
            lw=1,
            label=f"paper 002 rest ≈ {paper_rest_time_s:g} s",
        )


def history_figure(
    res, *, exact_first_peak_deg=None, paper_first_peak_deg=None, paper_rest_time_s=None
):
    """Block angle, angular velocity and beam deflection against time (paper 002, Figs 12–15)."""
    fig = Figure(figsize=(10, 7.5), layout="constrained")
    ax = fig.subplots(3, 1, sharex=True, gridspec_kw={"height_ratios": [2, 1, 1]})
    p = res.params
    ax[0].plot(*_thin(res.t, np.degrees(res.theta)), lw=0.8, color="tab:blue", label="NSCD")
    _reference_lines(ax[0], res, exact_first_peak_deg, paper_first_peak_deg, paper_rest_time_s)
    ax[0].set_ylabel("θ (deg)")
    _legend_outside(ax[0])
    status = res.status + (f" ({res.outcome})" if res.status != res.outcome else "")
    fig.suptitle(
        f"{p['block']} on {p['beam']}: E = {p['E']:.3g} Pa, {p['n_elements']} "
        f"elements, Δt = {p['dt']:g} s, θ-method {p['theta_method']:g} — {status}",
        fontsize=9,
        color="k" if res.status in ("completed", "overturned") else "tab:red",
    )
    ax[1].plot(*_thin(res.t, res.thetadot), lw=0.8, color="tab:purple")
    ax[1].set_ylabel("θ̇ (rad/s)")
    ax[2].plot(*_thin(res.t, 1e3 * res.v_mid), lw=0.8, color="tab:brown")
    ax[2].set_ylabel("v mid (mm)")
    ax[2].set_xlabel("t (s)")
    for a in ax:
        a.grid(alpha=0.3)
    return fig


def plot_history(res, path, **references) -> Path:
    """Save `history_figure` (keywords: exact_first_peak_deg, paper_first_peak_deg,
    paper_rest_time_s)."""
    return _save(history_figure(res, **references), path)


def _verdict_lines(study, width: int = 140) -> list[str]:
    """The verdict panel's lines, wrapped to `width` characters (monospace)."""
    lines = ["differences between successive levels:"]
    for v in study.verdicts:
        diffs = ", ".join("∞" if not math.isfinite(d) else f"{d:.3g}" for d in v.differences)
        lines.append(f"{v.measure}: Δ = [{diffs}] {v.unit} (tol {v.tolerance:g}) → {v.status}")
    lines += [f"warning: {w}" for w in study.warnings]
    return [part for line in lines for part in textwrap.wrap(line, width, subsequent_indent="  ")]


def _level_label(kind, level):
    return f"Δt = {level:g} s" if kind == "dt" else f"{level} elements"


def _level_style(k: int, n: int) -> dict:
    """The finest level in thick black underneath, coarser levels in the palette on top."""
    if k == n - 1:
        return {"color": "k", "lw": 1.8, "zorder": 2}
    return {"color": PALETTE[k % len(PALETTE)], "lw": 0.9, "zorder": 3}


def _study_axes(ax, study, t_max=None):
    n = len(study.runs)
    for k, (lev, r) in enumerate(zip(study.levels, study.runs)):
        t, th = r.t, np.degrees(r.theta)
        if t_max is not None:
            keep = t <= t_max
            t, th = t[keep], th[keep]
        ax.plot(
            *_thin(t, th),
            **_level_style(k, n),
            label=_level_label(study.kind, lev)
            + ("" if r.status == "completed" else f" ({r.status})"),
        )
    ax.set_ylabel("θ (deg)")
    ax.grid(alpha=0.3)
    _legend_outside(ax)


def study_figure(study, title: str = ""):
    """θ(t) at each refinement level above a panel of the verdicts (paper 002, Figs 10–11)."""
    lines = _verdict_lines(study)
    text_h = 0.2 + 0.16 * len(lines)  # inches of the verdict panel
    fig = Figure(figsize=(10, 5.5 + text_h), layout="constrained")
    ax, box = fig.subplots(2, 1, gridspec_kw={"height_ratios": [5.5, text_h]})
    _study_axes(ax, study)
    ax.set_xlabel("t (s)")
    colour = _STATUS_COLOUR[study.status]
    ax.set_title(
        (title or f"{study.block}: {study.kind} study") + f" — {study.status.upper()}",
        color=colour,
        fontsize=10,
    )
    box.axis("off")
    box.text(
        0.0,
        1.0,
        "\n".join(lines),
        transform=box.transAxes,
        fontsize=7,
        family="monospace",
        va="top",
        ha="left",
        bbox={"facecolor": "white", "edgecolor": colour},
    )
    return fig


def plot_study(study, path, title: str = "") -> Path:
    """Save `study_figure`."""
    return _save(study_figure(study, title), path)


def first_peak_figure(fps):
    """First-peak error against Δt, log–log, with the fitted order for each block."""
    fig = Figure(figsize=(13, 4.5), layout="constrained")
    ax = fig.subplots(1, 2)
    dts = np.array(fps.dts)
    for i, name in enumerate(fps.blocks):
        colour = PALETTE[i % len(PALETTE)]
        err = np.array([np.nan if e is None else e for e in fps.errors_deg[name]], dtype=float)
        peaks = np.array([np.nan if p is None else p for p in fps.peaks_deg[name]], dtype=float)
        order = fps.fitted_order[name]
        ax[0].loglog(
            dts,
            np.maximum(err, 1e-12),
            "o-",
            ms=4,
            color=colour,
            label=f"{name}: fitted order " + ("-" if order is None else f"{order:.2f}"),
        )
        ax[1].semilogx(dts, peaks, "o-", ms=4, color=colour, label=name)
        ax[1].axhline(fps.exact_deg[name], color=colour, ls="--", lw=0.8)
        if fps.paper_deg.get(name) is not None:
            ax[1].plot([1e-5], [fps.paper_deg[name]], "*", ms=11, color=colour, markeredgecolor="k")
    finite = [e for errs in fps.errors_deg.values() for e in errs if e is not None]
    if finite:
        ax[0].loglog(dts, 0.5 * dts / dts[0] * max(finite), "k:", lw=1, label="order 1")
    ax[0].set_xlabel("Δt (s)")
    ax[0].set_ylabel("|first peak − exact| (deg)")
    ax[0].set_title("first post-impact peak vs rigid block with Housner η", fontsize=9)
    ax[1].set_xlabel("Δt (s)")
    ax[1].set_ylabel("first peak (deg)")
    ax[1].set_title("dashed: exact (Housner η); stars: paper 002 at Δt = 1e-5 s", fontsize=9)
    for a in ax:
        a.grid(alpha=0.3, which="both")
        _legend_outside(a)
    return fig


def plot_first_peak(fps, path) -> Path:
    """Save `first_peak_figure`."""
    return _save(first_peak_figure(fps), path)


def _exp_label(n):
    return f"E = Ē·10^{n}"


def _sweep_figure(flex, lim):
    """θ(t) on the rigid base and for each E = Ē·10ⁿ, up to t = `lim` (paper 002, Figs 16–17)."""
    name, exps, base, rigid = flex["block"], flex["exponents"], flex["base"], flex["rigid"]
    fig = Figure(figsize=(11, 5), layout="constrained")
    ax = fig.subplots()
    E = rigid.params["E"]
    own = f"rigid base (E = {E:.0e} Pa)" if E >= 1e20 else f"beam's own E = {E:.3g} Pa"
    curves = [(rigid, own, {"color": "k", "lw": 1.8})]
    curves += [
        (base[n], _exp_label(n), {"lw": 0.9, "color": PALETTE[i % len(PALETTE)]})
        for i, n in enumerate(exps)
    ]
    for r, lab, kw in curves:
        keep = r.t <= lim
        ax.plot(*_thin(r.t[keep], np.degrees(r.theta[keep])), label=lab, **kw)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("θ (deg)")
    ax.set_title(
        f"{name}: flexibility sweep, Ē = {flex['E_bar']:.3g} Pa (L/2500 under the block), "
        f"{base[exps[0]].params['n_elements']} elements, "
        f"Δt = {base[exps[0]].params['dt']:g} s",
        fontsize=9,
    )
    ax.grid(alpha=0.3)
    _legend_outside(ax)
    return fig


def _sensitivity_figure(flex, key):
    """Mesh or Δt sensitivity per exponent, each panel titled with its verdict (Figs 18–19)."""
    exps = flex["exponents"]
    fig = Figure(figsize=(10, 2.4 * len(exps) + 0.4), layout="constrained")
    axes = fig.subplots(len(exps), 1, sharex=True, squeeze=False)
    for ax, n in zip(axes[:, 0], exps):
        st = flex[key][n]
        _study_axes(ax, st)
        bad = [v.measure for v in st.verdicts if v.status in ("not converged", "converging")]
        ax.set_title(
            f"{_exp_label(n)}: {st.status.upper()}" + (f" ({', '.join(bad)})" if bad else ""),
            color=_STATUS_COLOUR[st.status],
            fontsize=9,
        )
    axes[-1, 0].set_xlabel("t (s)")
    return fig


def flexibility_figures(flex) -> list[tuple[str, object]]:
    """(file stem, figure) of paper 002, Figs 16–19 for a `flexibility_study` result."""
    name, rigid = flex["block"], flex["rigid"]
    pk = rigid.peak_times  # the release, then the post-impact peaks: pk[2] after the 2nd impact
    t_zoom = pk[2] + 0.05 if len(pk) > 2 else rigid.t[-1]
    return [
        (f"fig16_flexibility_{name}", _sweep_figure(flex, rigid.t[-1])),
        (f"fig17_first_impacts_{name}", _sweep_figure(flex, t_zoom)),
        (f"fig18_mesh_{name}", _sensitivity_figure(flex, "mesh")),
        (f"fig19_dt_{name}", _sensitivity_figure(flex, "dt")),
    ]


def plot_flexibility(flex, outdir) -> list[Path]:
    """Paper 002, Figs 16–19: flexibility sweep, zoom on the first impacts, mesh and dt studies."""
    return [_save(fig, Path(outdir) / f"{stem}.png") for stem, fig in flexibility_figures(flex)]
