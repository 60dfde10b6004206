"""Figures of the Moreau–Jean simulations and convergence studies (paper 002, Figs 10–19).

Plotting only; the numbers come from `nscd.simulate` and `nscd.convergence`.
Every convergence figure states its verdicts, and a study that does not
converge says so in red in its title.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

__all__ = ["plot_history", "plot_study", "plot_first_peak", "plot_flexibility"]

_DPI = 100
_STATUS_COLOUR = {"converged": "tab:green", "converging": "tab:orange", "not converged": "tab:red",
                  "undetermined": "tab:gray"}


def _save(fig, path: Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=_DPI)
    plt.close(fig)
    return path


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


def plot_history(res, path, *, exact_first_peak_deg=None, paper_first_peak_deg=None,
                 paper_rest_time_s=None) -> Path:
    """Block angle, angular velocity and beam deflection against time (paper 002, Figs 12–15)."""
    fig, ax = plt.subplots(3, 1, figsize=(8, 7.5), sharex=True,
                           gridspec_kw={"height_ratios": [2, 1, 1]})
    p = res.params
    ax[0].plot(*_thin(res.t, np.degrees(res.theta)), lw=0.8, color="tab:blue", label="NSCD")
    if paper_first_peak_deg is not None:
        ax[0].axhline(paper_first_peak_deg, color="tab:red", ls=":", lw=1,
                      label=f"paper 002 first peak {paper_first_peak_deg:g}°")
        ax[0].axhline(-paper_first_peak_deg, color="tab:red", ls=":", lw=1)
    if exact_first_peak_deg is not None:
        ax[0].axhline(-exact_first_peak_deg if p["theta0_deg"] > 0 else exact_first_peak_deg,
                      color="k", ls="--", lw=0.8,
                      label=f"rigid block, Housner η: {exact_first_peak_deg:.3f}°")
    if res.rest_time_s is not None:
        ax[0].axvline(res.rest_time_s, color="tab:green", lw=1,
                      label=f"at rest (|θ| < {100 * p['rest_fraction']:g} % θ0): {res.rest_time_s:.2f} s")
    if paper_rest_time_s is not None:
        ax[0].axvline(paper_rest_time_s, color="tab:red", ls=":", lw=1,
                      label=f"paper 002 rest ≈ {paper_rest_time_s:g} s")
    ax[0].set_ylabel("θ (deg)")
    ax[0].legend(fontsize=7, loc="upper right")
    ax[0].set_title(f"{p['block']} on {p['beam']}: E = {p['E_Pa']:.3g} Pa, {p['n_elements']} elements, "
                    f"Δt = {p['dt_s']:g} s, θ-method {p['theta_method']:g} — {res.status}", fontsize=9)
    ax[1].plot(*_thin(res.t, res.theta_dot), lw=0.8, color="tab:purple")
    ax[1].set_ylabel("θ̇ (rad/s)")
    ax[2].plot(*_thin(res.t, 1e3 * res.v_mid), lw=0.8, color="tab:brown")
    ax[2].set_ylabel("v mid (mm)")
    ax[2].set_xlabel("t (s)")
    for a in ax:
        a.grid(alpha=0.3)
    fig.tight_layout()
    return _save(fig, path)


def _verdict_text(study) -> str:
    lines = []
    for v in study.verdicts:
        diffs = ", ".join("∞" if not math.isfinite(d) else f"{d:.3g}" for d in v.differences)
        lines.append(f"{v.measure}: Δ = [{diffs}] {v.unit} (tol {v.tolerance:g}) → {v.status}")
    return "\n".join(lines)


def _level_label(kind, level):
    return f"Δt = {level:g} s" if kind == "dt" else f"{level} elements"


def _study_axes(ax, study, t_max=None, legend=True):
    cmap = plt.get_cmap("viridis")
    n = len(study.runs)
    for k, (lev, r) in enumerate(zip(study.levels, study.runs)):
        t, th = r.t, np.degrees(r.theta)
        if t_max is not None:
            keep = t <= t_max
            t, th = t[keep], th[keep]
        ax.plot(*_thin(t, th), lw=0.9, color=cmap(k / max(n - 1, 1)),
                label=_level_label(study.kind, lev) + ("" if r.status == "completed" else f" ({r.status})"))
    ax.set_ylabel("θ (deg)")
    ax.grid(alpha=0.3)
    if legend:
        ax.legend(fontsize=7, loc="upper right")


def plot_study(study, path, title: str = "") -> Path:
    """θ(t) at each refinement level with the verdicts (paper 002, Figs 10–11)."""
    fig, ax = plt.subplots(figsize=(9, 6))
    _study_axes(ax, study)
    ax.set_xlabel("t (s)")
    colour = _STATUS_COLOUR[study.status]
    ax.set_title((title or f"{study.block}: {study.kind} study") + f" — {study.status.upper()}",
                 color=colour, fontsize=10)
    fig.tight_layout(rect=(0, 0.15, 1, 1))
    fig.text(0.01, 0.01, "differences between successive levels:\n" + _verdict_text(study),
             fontsize=7, family="monospace", va="bottom",
             bbox={"facecolor": "white", "edgecolor": colour})
    return _save(fig, path)


def plot_first_peak(fps, path) -> Path:
    """First-peak error against Δt, log–log, with the fitted order for each block."""
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.5))
    dts = np.array(fps.dts)
    for name in fps.blocks:
        err = np.array(fps.errors_deg[name])
        line, = ax[0].loglog(dts, np.maximum(err, 1e-12), "o-", ms=4,
                             label=f"{name}: fitted order {fps.fitted_order[name]:.2f}")
        ax[1].semilogx(dts, fps.peaks_deg[name], "o-", ms=4, color=line.get_color(), label=name)
        ax[1].axhline(fps.exact_deg[name], color=line.get_color(), ls="--", lw=0.8)
        if fps.paper_deg.get(name) is not None:
            ax[1].plot([1e-5], [fps.paper_deg[name]], "*", ms=11, color=line.get_color(),
                       markeredgecolor="k")
    ax[0].loglog(dts, 0.5 * dts / dts[0] * max(max(e) for e in fps.errors_deg.values()), "k:",
                 lw=1, label="order 1")
    ax[0].set_xlabel("Δt (s)")
    ax[0].set_ylabel("|first peak − exact| (deg)")
    ax[0].set_title("first post-impact peak vs rigid block with Housner η", fontsize=9)
    ax[1].set_xlabel("Δt (s)")
    ax[1].set_ylabel("first peak (deg)")
    ax[1].set_title("dashed: exact (Housner η); stars: paper 002 at Δt = 1e-5 s", fontsize=9)
    for a in ax:
        a.grid(alpha=0.3, which="both")
        a.legend(fontsize=7)
    fig.tight_layout()
    return _save(fig, path)


def _exp_label(n):
    return f"E = Ē·10^{n}"


def plot_flexibility(flex, outdir) -> list[Path]:
    """Paper 002, Figs 16–19: flexibility sweep, zoom on the first impacts, mesh and dt studies."""
    outdir = Path(outdir)
    name, exps = flex["block"], flex["exponents"]
    paths = []
    base = flex["base"]
    rigid = flex["rigid"]
    pk = rigid.peak_times_s          # the second post-impact peak follows the second impact
    t_zoom = pk[1] + 0.05 if len(pk) > 1 else rigid.t[-1]
    for tag, lim in (("fig16_flexibility", rigid.t[-1]), ("fig17_first_impacts", t_zoom)):
        fig, ax = plt.subplots(figsize=(9, 5))
        curves = [(rigid, f"rigid base (E = {rigid.params['E_Pa']:.0e} Pa)", {"color": "k", "lw": 1.4})]
        curves += [(base[n], _exp_label(n), {"lw": 0.9}) for n in exps]
        for r, lab, kw in curves:
            keep = r.t <= lim
            ax.plot(*_thin(r.t[keep], np.degrees(r.theta[keep])), label=lab, **kw)
        ax.set_xlabel("t (s)")
        ax.set_ylabel("θ (deg)")
        ax.set_title(f"{name}: flexibility sweep, Ē = {flex['E_bar']:.3g} Pa (L/2500 under the block), "
                     f"{base[exps[0]].params['n_elements']} elements, Δt = {base[exps[0]].params['dt_s']:g} s",
                     fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper right")
        fig.tight_layout()
        paths.append(_save(fig, outdir / f"{tag}_{name}.png"))
    for tag, key in (("fig18_mesh", "mesh"), ("fig19_dt", "dt")):
        fig, axes = plt.subplots(len(exps), 1, figsize=(9, 2.4 * len(exps)), sharex=True)
        for ax, n in zip(np.atleast_1d(axes), exps):
            st = flex[key][n]
            _study_axes(ax, st)
            bad = [v.measure for v in st.verdicts if v.status in ("not converged", "converging")]
            ax.set_title(f"{_exp_label(n)}: {st.status.upper()}"
                         + (f" ({', '.join(bad)})" if bad else ""),
                         color=_STATUS_COLOUR[st.status], fontsize=9)
        np.atleast_1d(axes)[-1].set_xlabel("t (s)")
        fig.tight_layout()
        paths.append(_save(fig, outdir / f"{tag}_{name}.png"))
    return paths
