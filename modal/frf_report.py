"""The frequency-response part of a modal report: a JSON-ready block and its Markdown section.

Plotting lives in `modal.frf_plots` (`frf_figure`); this module only computes and formats.
"""

from __future__ import annotations

import numpy as np

from .analysis import ModalAnalysis
from .frequency_response import frf, sensor_label, sensor_nodes
from .measured_frf import MeasuredFRF

__all__ = ["frf_summary", "frf_markdown", "resolution_bias"]

_PEAK_WINDOW = 0.15  # a measured peak is looked for within ±15 % of the model's mode


def resolution_bias(df_hz: float, freq_hz: float, damping: float) -> float:
    """Relative bias of a Hann-window estimate at the peak of a lightly damped mode.

    −(1/3)(B_e/B_r)², with B_e = 1.5 Δf the Hann window's effective bandwidth and
    B_r = 2ζf the mode's half-power bandwidth (Bendat & Piersol, *Random Data*,
    4th ed., Chapter 8): negative, the estimated peak is too low.
    """
    return -((1.5 * df_hz / (2.0 * damping * freq_hz)) ** 2) / 3.0


def _measured_peaks(analysis: ModalAnalysis, measured: MeasuredFRF, node: int) -> list[dict]:
    """Per full-contact mode below Nyquist: the model's and the measured peak at `node`."""
    s, fc = analysis.structure, analysis.full_contact
    row = measured.outputs.index(f"a{node}")
    f, h, coh = measured.freq_hz, measured.H[row], measured.coherence[row]
    df = measured.fs / measured.nperseg
    out = []
    for j, fk, zk in zip(fc.mode, fc.freq_hz, fc.damping):
        if (1 + _PEAK_WINDOW) * fk >= measured.fs / 2:
            break
        near = (f >= (1 - _PEAK_WINDOW) * fk) & (f <= (1 + _PEAK_WINDOW) * fk) & np.isfinite(h)
        if not near.any():
            continue
        k = np.flatnonzero(near)[np.argmax(np.abs(h[near]))]
        fine = np.linspace((1 - _PEAK_WINDOW) * fk, (1 + _PEAK_WINDOW) * fk, 4001)
        model = np.abs(frf(s, fine, sensors=[node])[0])
        out.append(
            {
                "mode": int(j),
                "model_freq_hz": float(fine[np.argmax(model)]),
                "model_peak": float(model.max()),
                "measured_freq_hz": float(f[k]),
                "measured_peak": float(np.abs(h[k])),
                "coherence": float(coh[k]),
                "resolution_bias": float(resolution_bias(df, fk, zk)),
            }
        )
    return out


def frf_summary(
    analysis: ModalAnalysis,
    figure: str | None,
    sensors=None,
    measured: MeasuredFRF | None = None,
    source: str | None = None,
) -> dict:
    """JSON-ready block of the FRF part of a report.

    Keys: ``figure`` (file name or None), ``sensors`` (nodes) and ``labels``, and with
    `measured` a ``measured`` object: ``source``, ``segments_s`` (first and last sample
    time of each full-contact segment used), ``skipped_s``, ``fs_hz``, ``nperseg``,
    ``df_hz``, ``n_averages``, and ``peaks`` (per full-contact mode below the Nyquist
    frequency, at the highest measured sensor: model and measured peak frequency and
    height, the coherence there and the expected resolution bias).
    """
    s = analysis.structure
    nodes = sensor_nodes(s, sensors)
    out = {
        "figure": figure,
        "sensors": list(nodes),
        "labels": [sensor_label(s, k) for k in nodes],
    }
    if measured is not None:
        recorded = [k for k in nodes if f"a{k}" in measured.outputs]
        top = max(recorded, key=lambda k: s.H[k - 1]) if recorded else None
        out["measured"] = {
            "source": source or "arrays",
            "theta_max_rad": measured.theta_max,
            "min_periods": measured.min_periods,
            "segments_s": [list(x) for x in measured.segment_times()],
            "skipped_s": [list(x) for x in measured.segment_times("skipped")],
            "fs_hz": float(measured.fs),
            "nperseg": int(measured.nperseg),
            "df_hz": float(measured.fs / measured.nperseg),
            "n_averages": int(measured.n_averages),
            "peak_sensor": top,
            "peaks": _measured_peaks(analysis, measured, top) if top is not None else [],
        }
    return out


def _fmt(x) -> str:
    return f"{x:.4g}" if isinstance(x, float) else str(x)


def frf_markdown(info: dict) -> list[str]:
    """Lines of the report's "Frequency response" section, from `frf_summary`'s block."""
    parts = [
        "## Frequency response",
        "",
        "State-space models of the linearised phases (`multimass.modal.state_space`, "
        "python-control) from the ground acceleration ü_g to the total acceleration of "
        f"each sensor: {', '.join(info['labels'])}. The rocking phase is linearised about "
        "θ = 0 and is unstable (pole +p_l): its frequency response is a formal one, whose "
        "peaks are the uplifted modes.",
    ]
    if info.get("figure"):
        parts += ["", f"![frequency response]({info['figure']})"]
    meas = info.get("measured")
    if meas is None:
        return parts
    spans = meas["segments_s"]
    total = sum(b - a for a, b in spans)
    parts += [
        "",
        f"Measured: H1 = S_xy / S_xx from `{meas['source']}` over {len(spans)} full-contact "
        f"segment(s), {total:.1f} s in all (Welch, Hann window of {meas['nperseg']} samples, "
        f"Δf = {meas['df_hz']:.4g} Hz, {meas['n_averages']} averages, fs = "
        f"{meas['fs_hz']:.4g} Hz)."
        + (
            f" A full-contact segment is a stretch where |θ| ≤ {meas['theta_max_rad']:g} rad "
            f"for at least {meas['min_periods']:g} periods of the first full-contact mode."
            if meas["theta_max_rad"] is not None
            else ""
        ),
    ]
    if meas["skipped_s"]:
        parts += [
            "",
            f"{len(meas['skipped_s'])} full-contact segment(s) shorter than the window were "
            "not used: " + ", ".join(f"{a:.2f}–{b:.2f} s" for a, b in meas["skipped_s"]) + ".",
        ]
    if meas["peaks"]:
        header = [
            "mode",
            "model peak (Hz)",
            "measured peak (Hz)",
            "model peak height",
            "measured peak height",
            "γ²",
            "expected window bias",
        ]
        rows = [
            [
                p["mode"],
                p["model_freq_hz"],
                p["measured_freq_hz"],
                p["model_peak"],
                p["measured_peak"],
                f"{p['coherence']:.3f}",
                f"{100 * p['resolution_bias']:+.1f} %",
            ]
            for p in meas["peaks"]
        ]
        parts += [
            "",
            f"Peaks at node {meas['peak_sensor']} (the highest sensor measured); the "
            "expected window bias −(1/3)(1.5 Δf / 2ζf)² of a peak's height says whether "
            "the window resolves the mode:",
            "",
            "| " + " | ".join(header) + " |",
            "|" + "---|" * len(header),
            *("| " + " | ".join(_fmt(x) for x in r) + " |" for r in rows),
        ]
    return parts
