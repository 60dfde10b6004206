"""Frequency-response figures of the linearised phases (headless: matplotlib's object API).

The model lines are `modal.frequency_response.frf` of the state-space models; a
measured H1 estimate (`modal.measured_frf`) is drawn over the full-contact panels.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from .analysis import ModalAnalysis
from .frequency_response import frf, sensor_label, sensor_nodes
from .measured_frf import MeasuredFRF

__all__ = ["frf_figure", "plot_frf", "frf_grid", "MEASURED_COHERENCE"]

#: Measured H1 points with a lower coherence γ² are not drawn (the coherence panel shows all).
MEASURED_COHERENCE = 0.5
_PHASES = (
    ("full_contact", "full contact (paper 001, Eq 3)"),
    ("rocking", "rocking, linearised at θ = 0 (Eqs 19–20)"),
)


def _underdamped(analysis: ModalAnalysis, phase: str):
    pm = getattr(analysis, phase)
    return pm.mode, pm.freq_hz, pm.damping


def frf_grid(analysis: ModalAnalysis, n: int = 2000) -> np.ndarray:
    """Frequencies (Hz) for FRF plots: log-spaced from a fifth of the lowest full-contact
    mode to 1.3 × the highest underdamped mode of either phase, refined within ±8
    half-power bandwidths of each mode so that every peak is drawn at its height."""
    fs = [_underdamped(analysis, ph)[1:] for ph, _ in _PHASES]
    f_all = np.concatenate([f for f, _ in fs])
    lo = 0.2 * float(analysis.full_contact.undamped_omega.min()) / (2 * np.pi)
    hi = 1.3 * float(f_all.max()) if f_all.size else 50.0 * lo
    parts = [np.geomspace(lo, hi, n)]
    for f, z in fs:
        for fk, zk in zip(f, z):
            half = 8 * max(zk, 1e-4) * fk
            parts.append(np.linspace(max(fk - half, lo), min(fk + half, hi), 201))
    return np.unique(np.concatenate(parts))


def _wrap_to(phase_deg: np.ndarray, reference_deg: np.ndarray) -> np.ndarray:
    """`phase_deg` shifted by whole turns to within ±180° of `reference_deg`."""
    return reference_deg + (phase_deg - reference_deg + 180.0) % 360.0 - 180.0


def _mark_modes(axes, analysis: ModalAnalysis, phase: str) -> None:
    modes, freq, _ = _underdamped(analysis, phase)
    for ax in axes:
        for f in freq:
            ax.axvline(f, color="0.55", ls=":", lw=0.9, zorder=1)
    top = axes[0]
    for j, f in zip(modes, freq):
        top.annotate(
            f"{j}",
            (f, 1.0),
            xycoords=("data", "axes fraction"),
            xytext=(0, 2),
            textcoords="offset points",
            ha="center",
            va="bottom",
            fontsize=8,
            color="0.3",
        )


def _overlay(ax_mag, ax_ph, ax_coh, measured: MeasuredFRF, nodes, colors, model_phase) -> None:
    """Measured H1 in each node's colour (γ² ≥ MEASURED_COHERENCE), coherence below."""
    f = measured.freq_hz
    rows = {name: k for k, name in enumerate(measured.outputs)}
    for node, color in zip(nodes, colors):
        k = rows.get(f"a{node}")
        if k is None:
            continue
        h, coh = measured.H[k], measured.coherence[k]
        keep = (coh >= MEASURED_COHERENCE) & (f > 0) & np.isfinite(h)
        mag = np.where(keep, np.abs(h), np.nan)
        ph = _wrap_to(np.degrees(np.angle(h)), np.interp(f, *model_phase[node]))
        style = dict(color=color, lw=0.0, marker=".", ms=2.0, alpha=0.35, zorder=2)
        ax_mag.plot(f, mag, **style)
        ax_ph.plot(f, np.where(keep, ph, np.nan), **style)
        ax_coh.plot(f[f > 0], coh[f > 0], color=color, lw=0.8)
    ax_coh.axhline(MEASURED_COHERENCE, color="0.5", ls="--", lw=0.8)
    ax_coh.set_ylim(0.0, 1.02)
    ax_coh.set_ylabel("coherence γ² (–)")


def _measured_note(ax, measured: MeasuredFRF) -> None:
    spans = measured.segment_times()
    total = sum(b - a for a, b in spans)
    lines = [
        "measured FRF: H1 = S_xy / S_xx (Welch, Hann)",
        *(
            [
                f"full contact: |θ| ≤ {measured.theta_max:g} rad",
                f"   for ≥ {measured.min_periods:g} periods of mode 1",
            ]
            if measured.theta_max is not None
            else []
        ),
        f"{len(spans)} segment(s), {total:.1f} s in all:",
        *(f"   {a:.2f}–{b:.2f} s" for a, b in spans[:6]),
        *([f"   … and {len(spans) - 6} more"] if len(spans) > 6 else []),
        f"{len(measured.skipped)} shorter segment(s) not used" if measured.skipped else "",
        f"window {measured.nperseg} samples, Δf = {measured.fs / measured.nperseg:.4g} Hz,",
        f"{measured.n_averages} averages; fs = {measured.fs:.4g} Hz",
        f"points with γ² < {MEASURED_COHERENCE} not drawn",
    ]
    ax.axis("off")
    ax.text(0.02, 0.98, "\n".join(x for x in lines if x), va="top", fontsize=8, family="monospace")


def frf_figure(
    analysis: ModalAnalysis,
    sensors=None,
    measured: MeasuredFRF | None = None,
    freq_hz=None,
) -> Figure:
    """Frequency responses ü_g → sensor total accelerations of both linearised phases.

    Magnitude (log) and phase over frequency (log), one line per sensor, from the
    state-space models of `modal.frequency_response` (left: full contact; right:
    rocking, a formal response of an unstable linearisation whose peaks are the
    uplifted modes); dotted lines mark the underdamped modes (numbered). With
    `measured`, its H1 points (rows named ``a<node>``) are drawn over the
    full-contact panels in each sensor's colour, points with coherence below
    `MEASURED_COHERENCE` left out, and the coherence is drawn beneath.

    Parameters
    ----------
    analysis : ModalAnalysis
    sensors : sequence of int or str, optional
        Nodes or sensor names (`modal.frequency_response.sensor_nodes`).
    measured : MeasuredFRF, optional
    freq_hz : array_like, optional
        Frequencies of the model lines (default `frf_grid`).
    """
    s = analysis.structure
    nodes = sensor_nodes(s, sensors)
    f = frf_grid(analysis) if freq_hz is None else np.asarray(freq_hz, dtype=float)
    rows = 3 if measured is not None else 2
    fig = Figure(figsize=(11, 3.0 * rows + 1.2), layout="constrained")
    axes = fig.subplots(rows, 2, sharex="col", height_ratios=[3, 2, 1.5][:rows])
    colors = [f"C{k % 10}" for k in range(len(nodes))]
    model_phase = {}
    for col, (phase, title) in enumerate(_PHASES):
        ax_mag, ax_ph = axes[0, col], axes[1, col]
        H = frf(s, f, phase, sensors=nodes)[: len(nodes)]
        for node, h, color in zip(nodes, H, colors):
            ph = np.degrees(np.unwrap(np.angle(h)))
            ax_mag.plot(f, np.abs(h), color=color, lw=1.3, zorder=3, label=sensor_label(s, node))
            ax_ph.plot(f, ph, color=color, lw=1.3, zorder=3)
            if phase == "full_contact":
                model_phase[node] = (f, ph)
        _mark_modes((ax_mag, ax_ph), analysis, phase)
        ax_mag.set_yscale("log")
        ax_mag.set_title(title, fontsize=10, pad=14)
        ax_mag.set_ylabel("|a / ü_g| (–)")
        ax_ph.set_ylabel("phase (deg)")
    if measured is not None:
        _overlay(axes[0, 0], axes[1, 0], axes[2, 0], measured, nodes, colors, model_phase)
        _measured_note(axes[2, 1], measured)
    for ax in axes.ravel():
        if ax.axison:
            ax.set_xscale("log")
            ax.set_xlim(f.min(), f.max())
            ax.grid(alpha=0.3, which="both")
    for col in range(2):
        bottom = axes[rows - 1, col] if axes[rows - 1, col].axison else axes[rows - 2, col]
        bottom.set_xlabel("frequency (Hz)")
        bottom.xaxis.set_tick_params(labelbottom=True)
    handles = axes[0, 0].get_legend_handles_labels()[0]
    handles.append(Line2D([], [], color="0.55", ls=":", label="mode (Foss, underdamped)"))
    if measured is not None:
        handles.append(
            Line2D(
                [],
                [],
                color="0.3",
                lw=0,
                marker=".",
                label=f"measured H1 (γ² ≥ {MEASURED_COHERENCE})",
            )
        )
    fig.legend(handles=handles, loc="outside lower center", ncol=min(len(handles), 4), fontsize=8)
    fig.suptitle(f"{s.name}: frequency response, ground acceleration ü_g → total acceleration a")
    return fig


def plot_frf(
    analysis: ModalAnalysis, path: str | Path, sensors=None, measured: MeasuredFRF | None = None
) -> Path:
    """Save `frf_figure` to `path` (PNG, 120 dpi like `modal.plots`); returns the path."""
    path = Path(path)
    frf_figure(analysis, sensors, measured).savefig(path, dpi=120)
    return path
