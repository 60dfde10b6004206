"""Figures of time histories (headless: matplotlib's object API, no pyplot state).

Paper 001 Figs 6–7 style: rocking angle with the Dirac-delta impact force,
the energy ledger, and accelerations at instrumented nodes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ..response import Response
from .trace_metrics import align, channel_columns

__all__ = ["plot_rocking", "plot_energy", "plot_accelerations", "plot_overlay", "plot_models"]


def _save(fig: Figure, path) -> Path:
    path = Path(path)
    fig.savefig(path, dpi=110)
    return path


# event kind -> (marker, colour, label) drawn on the θ line where the event happens
_EVENT_MARKS = {
    "uplift": ("^", "tab:green", "uplift"),
    "impact": ("|", "0.1", "impact (new half-cycle)"),
    "full_contact": ("s", "tab:orange", "full contact"),
    "chatter_guard": ("D", "tab:purple", "chattering guard"),
    "overturn": ("X", "k", "overturned"),
}


def _event_marks(ax, resp: Response) -> None:
    """Markers on the θ line at each transition, one legend entry per kind with its count."""
    for kind, (marker, colour, label) in _EVENT_MARKS.items():
        times = [e.time for e in resp.events if e.kind == kind]
        thetas = [e.theta for e in resp.events if e.kind == kind]
        if times:
            ax.plot(
                times,
                thetas,
                ls="",
                marker=marker,
                color=colour,
                ms=4 if marker != "|" else 7,
                mew=1.0,
                alpha=0.8,
                zorder=3,
                label=f"{label} ({len(times)})",
            )


def plot_rocking(resp: Response, path, title: str = "", g: float = 9.81) -> Path:
    """Ground acceleration (if any), θ(t) with its transitions marked, θ̇(t), and the
    Dirac-delta impact force F_i (if any), each on its own panel."""
    df = resp.series
    panels = (
        (["ag"] if np.any(df.ag != 0) else [])
        + ["theta", "thetadot"]
        + (["F_i"] if np.any(df.F_i != 0) else [])
    )
    ratios = {"ag": 1.0, "theta": 2.2, "thetadot": 1.2, "F_i": 1.0}
    fig = Figure(figsize=(10, 1.0 + 1.6 * sum(ratios[p] for p in panels)), layout="constrained")
    axes = dict(
        zip(
            panels,
            np.atleast_1d(
                fig.subplots(len(panels), 1, sharex=True, height_ratios=[ratios[p] for p in panels])
            ),
        )
    )
    if "ag" in axes:
        axes["ag"].plot(df.t, df.ag / g, color="0.3", lw=0.8)
        axes["ag"].set_ylabel("ground ü_g (g)")
    ax = axes["theta"]
    ax.plot(df.t, df.theta, color="tab:blue", lw=1.0, label="θ", zorder=2)
    _event_marks(ax, resp)
    ax.set_ylabel("θ (rad)")
    ax.legend(fontsize=8, ncol=6, loc="lower left", bbox_to_anchor=(0.0, 1.0), frameon=False)
    axes["thetadot"].plot(df.t, df.thetadot, color="tab:red", lw=0.8)
    axes["thetadot"].set_ylabel("θ̇ (rad/s)")
    if "F_i" in axes:
        axes["F_i"].plot(df.t, df.F_i / 1e3, color="0.4", lw=0.8)
        axes["F_i"].set_ylabel("impact force\nF_i (kN)")
    for a in axes.values():
        a.grid(alpha=0.3)
    axes[panels[-1]].set_xlabel("t (s)")
    status = resp.status + (f" — {resp.warnings[0]}" if resp.warnings else "")
    over = next((e.time for e in resp.events if e.kind == "overturn"), None)
    if over is not None:  # the series, ground motion included, ends at the overturn
        status += f" at t = {over:.4g} s (nothing computed after it; t_end = {resp.t_end:g} s)"
    fig.suptitle(
        title
        or f"{resp.structure_name}: {resp.options.get('impact', '')}, "
        f"{resp.n_impacts} impacts, {resp.n_full_contact} full-contact transitions; "
        f"status {status}",
        fontsize=10,
        wrap=True,
    )
    return _save(fig, path)


def plot_energy(resp: Response, path) -> Path:
    """Energy ledger over time (paper 001, Fig 6 third row) and its balance error."""
    df = resp.series
    fig = Figure(figsize=(10, 5.5), layout="constrained")
    ax, ax2 = fig.subplots(2, 1, sharex=True, height_ratios=[3, 1])
    for col, style in (
        ("kinetic", "-"),
        ("gravitational", "-"),
        ("elastic", "-"),
        ("damping", "--"),
        ("impact", "--"),
        ("ground_work", ":"),
    ):
        ax.plot(df.t, df[col], style, lw=1.0, label=col.replace("_", " "))
    ax.plot(df.t, df.kinetic + df.gravitational + df.elastic, "k", lw=1.2, label="mechanical total")
    ax.set_ylabel("energy (J)")
    ax.legend(ncol=4, fontsize=8)
    ax.grid(alpha=0.3)
    ax2.plot(df.t, df.balance_error / resp.energy_reference, color="tab:purple", lw=0.8)
    ax2.set_ylabel("balance error\n(relative)")
    ax2.set_xlabel("t (s)")
    ax2.grid(alpha=0.3)
    ax.set_title(
        f"{resp.structure_name}: energy ledger (max relative balance error "
        f"{resp.energy_balance_error:.2e})"
    )
    return _save(fig, path)


def plot_accelerations(resp: Response, nodes: dict[str, int], path, g: float = 9.81) -> Path:
    """Total accelerations (paper 001, Eq 7) at named nodes, in g (paper 001, Fig 7)."""
    df = resp.series
    fig = Figure(figsize=(10, 2.4 * max(1, len(nodes)) + 0.6), layout="constrained")
    axes = np.atleast_1d(fig.subplots(len(nodes), 1, sharex=True))
    for ax, (label, node) in zip(axes, nodes.items()):
        ax.plot(df.t, df[f"a{node}"] / g, lw=0.7)
        ax.set_ylabel(f"a_{label} (g)\nnode {node}")
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("t (s)")
    axes[0].set_title(f"{resp.structure_name}: total lateral accelerations")
    return _save(fig, path)


def plot_overlay(
    trace,
    name: str,
    responses: dict,
    structure,
    path,
    *,
    t_offset: float = 0.0,
    metrics: dict | None = None,
    title: str = "",
) -> Path:
    """A measured channel against one or more simulations, with the residuals below.

    Parameters
    ----------
    trace : multimass.inputs.traces.Trace
    name : str
        The channel to plot (e.g. ``"theta"``, ``"a_A2"``); shown in the unit it
        was written in (e.g. deg, g).
    responses : mapping of str to Response
        Model label (e.g. ``"CIM"``, ``"DD2"``) → simulation.
    structure : Structure, specimen or str
        Maps sensor names to nodes.
    path : str or Path
    t_offset : float, optional
        Trace time of the simulations' t = 0 (s).
    metrics : mapping of str to ChannelMetrics, optional
        Per label, the metrics of this channel (shown in the legend, converted to
        the unit the channel was written in).
    title : str, optional
    """

    column = channel_columns(trace, structure)[name]
    unit = trace.units[name]
    fig = Figure(figsize=(10, 5.2 + 0.2 * len(responses)), layout="constrained")
    ax, ax2 = fig.subplots(2, 1, sharex=True, height_ratios=[3, 1.3])
    ax.plot(
        trace.time,
        trace.to_written_units(name, trace.channels[name]),
        color="k",
        lw=1.1,
        label="measured",
    )
    lo, hi = trace.time[0], trace.time[-1]
    for i, (label, resp) in enumerate(responses.items()):
        color = f"C{(i + 3) % 10}"
        df = resp.series
        t = df["t"].to_numpy() + t_offset
        keep = (t >= lo) & (t <= hi)
        m = (metrics or {}).get(label)
        text = (
            label
            if m is None
            else (
                f"{label}: RMS err {float(trace.to_written_units(name, m.rms_error)):.3g} {unit}"
                + (f" (NRMSE {100 * m.nrmse:.1f} %)" if m.nrmse is not None else "")
                + f", peak err {float(trace.to_written_units(name, m.peak_error)):+.3g} {unit}, "
                f"peak-time shift {m.peak_time_shift_s:+.3f} s"
            )
        )
        ax.plot(
            t[keep],
            trace.to_written_units(name, df[column].to_numpy()[keep]),
            color=color,
            lw=0.9,
            alpha=0.85,
            label=text,
        )
        tt, meas, sim = align(trace, resp, structure, name, t_offset=t_offset)
        ax2.plot(tt, trace.to_written_units(name, sim - meas), color=color, lw=0.8)
    ax.set_ylabel(f"{name} ({unit})")
    ax.legend(fontsize=8, loc="lower left", bbox_to_anchor=(0.0, 1.0), frameon=False)
    ax.grid(alpha=0.3)
    ax2.axhline(0.0, color="k", lw=0.6)
    ax2.set_ylabel(f"simulated −\nmeasured ({unit})")
    ax2.set_xlabel("t (s)")
    ax2.grid(alpha=0.3)
    fig.suptitle(title or f"{name}: measured ({trace.source}) and simulated")
    return _save(fig, path)


def plot_models(responses: dict, path, title: str = "") -> Path:
    """θ(t) and the mechanical energy of several runs of one scene (e.g. impact models)."""
    fig = Figure(figsize=(10, 6), layout="constrained")
    ax, ax2 = fig.subplots(2, 1, sharex=True)
    for label, resp in responses.items():
        df = resp.series
        ax.plot(
            df.t,
            df.theta,
            lw=0.9,
            label=f"{label}: {resp.n_impacts} impacts, {resp.n_full_contact} full contacts",
        )
        ax2.plot(df.t, df.kinetic + df.gravitational + df.elastic, lw=0.9, label=label)
    ax.set_ylabel("θ (rad)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    ax2.set_ylabel("mechanical energy (J)")
    ax2.set_xlabel("t (s)")
    ax2.grid(alpha=0.3)
    ax.set_title(title)
    return _save(fig, path)
