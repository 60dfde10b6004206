"""The report of a calibration (`multimass.identify.calibrate`): figures, Markdown, JSON, TOML.

`write_report` writes into a folder, per trace and channel, the measured channel with
the simulation before (start values) and after (the calibrated model) calibration and
their residuals (`multimass.analysis.plots.plot_overlay`); per trace, the residuals of the fit
over its window in units of each channel's residual RMS (`plot_residuals`); a
Markdown summary (`markdown`), the result as JSON and the fitted specimen file
(``<specimen>_calibrated.toml``, which `multimass.specimens.load` reads back).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ..analysis.plots import plot_overlay
from ..analysis.trace_metrics import align
from ..specimens import SpecimenError

__all__ = ["write_report", "plot_residuals", "markdown"]


def plot_residuals(cal, label: str, path) -> Path:
    """The fit's residuals (simulated − measured) of one trace over its window, each
    channel in units of its residual RMS, with their lag-1 autocorrelation."""
    case = next(c for c in cal.traces if c.label == label)
    resp = cal.views[label]["fit"]
    chans = list(case.channels)
    fig = Figure(figsize=(10, 1.2 + 1.5 * len(chans)), layout="constrained")
    axes = np.atleast_1d(fig.subplots(len(chans), 1, sharex=True))
    for ax, ch in zip(axes, chans):
        t, meas, sim = align(case.trace, resp, cal.structure, ch, t_offset=0.0)
        lo, hi = cal.nuisance[label]["window"]  # the window fitted
        keep = (t >= lo) & (t <= hi)
        info = cal.residuals.get(f"{label}:{ch}", {})
        scale = info.get("scale") or 1.0
        ax.plot(t[keep], (sim - meas)[keep] / scale, lw=0.6, color="C3")
        ax.axhline(0.0, color="k", lw=0.5)
        ax.set_ylabel(f"{ch}\n(/ {scale:.3g} {case.trace.si_units(ch)})", fontsize=8)
        ax.text(
            0.995, 0.95, f"ρ₁ = {info.get('rho1', math.nan):+.2f}", transform=ax.transAxes,
            ha="right", va="top", fontsize=8,
        )  # fmt: skip
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("t (s, trace clock)")
    fig.suptitle(
        f"{cal.structure.name} ({cal.impact}): residuals of the fit, {label} — status {cal.status}"
    )
    path = Path(path)
    fig.savefig(path, dpi=110)
    return path


def _fmt(x, spec=".4g") -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "—" if x is None else "∞"
    return format(x, spec)


def markdown(cal) -> str:
    """A Markdown summary: status, parameters, nuisance, metrics before/after, features."""
    lines = [
        f"# Calibration of {cal.structure.name} with {cal.impact}",
        "",
        f"**Status: {cal.status}** — {cal.message}.",
        "",
        f"{len(cal.traces)} trace(s), {cal.n_simulations} simulations, {cal.wall_time_s:.1f} s.",
        "",
        "## Parameters",
        "",
        "| parameter | value | std | start | bounds | constrained |",
        "|---|---|---|---|---|---|",
    ]
    for name, p in cal.parameters.items():
        flag = "yes" if p["constrained"] else f"**no**: {p['reason']}"
        lines.append(
            f"| {name} | {_fmt(p['value'], '.5g')} | {_fmt(p['std'], '.2g')} | "
            f"{_fmt(p['start'], '.5g')} | [{_fmt(p['bounds'][0])}, {_fmt(p['bounds'][1])}] "
            f"| {flag} |"
        )
    fixed = ", ".join(f"{k} = {_fmt(v, '.5g')}" for k, v in cal.fixed.items())
    lines += ["", f"Fixed: {fixed}.", "", "## Traces", ""]
    for label, n in cal.nuisance.items():
        t0 = _fmt(n["theta0"], ".5g") if n["theta0"] is not None else "— (table motion)"
        lines += [
            f"### {label} ({n['source']})",
            "",
            f"- {n['kind']} test; window {n['window'][0]:.3f}–{n['window'][1]:.3f} s; "
            f"t_offset {n['t_offset']:.5f} s; θ0 {t0} rad; θ bias {n['theta_bias']:.3g} rad",
            "- sensor biases (m/s²): "
            + ", ".join(f"{k} {v:+.3g}" for k, v in n["sensor_bias"].items()),
            "- per-impact restitution (corner mean + deviation): "
            + ", ".join(f"{i['corner'][0]} {i['r']:.4f}" for i in n["impacts"]),
            "",
            "| channel | span | NRMSE before | NRMSE after | NRMSE fit | peak err before "
            "| peak err after |",
            "|---|---|---|---|---|---|---|",
        ]
        for span in ("window", "trace"):
            b = cal.metrics["before"][label][span]
            a = cal.metrics.get("after", {}).get(label, {}).get(span, {})
            f = cal.metrics.get("fit", {}).get(label, {}).get(span, {})
            for ch, m in b.items():
                lines.append(
                    f"| {ch} | {span} | {_fmt(m.nrmse, '.1%')} | "
                    f"{_fmt(a[ch].nrmse, '.1%') if ch in a else '—'} | "
                    f"{_fmt(f[ch].nrmse, '.1%') if ch in f else '—'} | "
                    f"{_fmt(m.peak_error, '+.3g')} | "
                    f"{_fmt(a[ch].peak_error, '+.3g') if ch in a else '—'} |"
                )
        lines.append("")
        for which in ("before", "after", "fit"):
            fe = cal.features.get(which, {}).get(label)
            if fe:
                lines.append(
                    f"- {which}: RMS peak error {fe['rms_peak_error']:.3g} rad, RMS impact-time "
                    f"error {_fmt(fe['rms_impact_time_error'], '.3g')} s, "
                    f"{fe['missing_impacts']} impact(s) missing"
                )
        lines.append("")
    if cal.warnings:
        lines += ["## Warnings", ""] + [f"- {w}" for w in cal.warnings] + [""]
    lines += [
        "NRMSE = RMS(simulated − measured) / RMS(measured) (`multimass.analysis.trace_metrics`); "
        "*before*: start values; *after*: the calibrated model (corner means); *fit*: "
        "with each impact's fitted deviation, over the window fitted.",
        "",
    ]
    return "\n".join(lines)


def write_report(cal, out, *, figures: bool = True) -> list[Path]:
    """Write the figures, ``calibration.md``, ``calibration.json`` and the fitted specimen.

    Parameters
    ----------
    cal : Calibration
    out : str or Path
        An existing folder.
    figures : bool, optional
        Draw the figures (default True).

    Returns
    -------
    list of Path
        The files written.
    """
    out = Path(out)
    files = []
    if figures:
        for case in cal.traces:
            label = case.label
            views = cal.views.get(label, {})
            shown = {k: views[k] for k in ("before", "after") if k in views}
            for ch in case.trace.names:
                metrics = {k: cal.metrics[k][label]["trace"][ch] for k in shown if k in cal.metrics}
                files.append(
                    plot_overlay(
                        case.trace, ch, shown, cal.structure, out / f"{label}_{ch}.png",
                        t_offset=0.0, metrics=metrics,
                        title=f"{cal.structure.name} ({cal.impact}): {ch}, {label}, before "
                        "and after calibration",
                    )
                )  # fmt: skip
            if "fit" in views:
                files.append(plot_residuals(cal, label, out / f"{label}_residuals.png"))
    md = out / "calibration.md"
    md.write_text(markdown(cal), encoding="utf-8")
    js = out / "calibration.json"
    js.write_text(cal.to_json() + "\n", encoding="utf-8")
    files += [md, js]
    if cal.status != "failed":
        try:
            files.append(cal.write_specimen(out / f"{cal.structure.name}_calibrated.toml"))
        except SpecimenError:  # a specimen built in Python, from no file: nothing to rewrite
            pass
    return files
