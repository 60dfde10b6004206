"""The truth of a synthetic trace, as a JSON-ready dict (`multimass.identify.synthetic`)."""

from __future__ import annotations

import dataclasses

import numpy as np

__all__ = ["truth", "corner_statistics"]

_CORNER = {1: "right", -1: "left"}


def truth(st, excitation, response, model, tables, cfg, grid, law, levels, figures) -> dict:
    """Everything the trace was made from (SI units, rad; ``t`` on the trace's clock)."""
    lo, hi = float(grid.t_model[0]), float(grid.t_model[-1])
    impacts = _impacts(response, lo, hi, cfg.t_offset)
    out = {
        "specimen": st.name,
        "impact": _describe_model(model),
        "seed": cfg.seed,
        "excitation": excitation.describe()
        if hasattr(excitation, "describe")
        else repr(excitation),
        "t_end": cfg.t_end,
        "t_offset": cfg.t_offset,
        "units": {"time": "s", "theta": "rad", "acceleration": "m/s2"},
        "channels": {name: column for name, column in cfg.columns.items()},
        "impacts": impacts,
        **corner_statistics(impacts),
        "transitions": [
            {"kind": e.kind, "t": e.time + cfg.t_offset, "t_model": e.time}
            for e in response.events
            if e.kind in ("uplift", "full_contact", "chatter_guard") and lo <= e.time <= hi
        ],
        "peaks": [
            {"t": float(tp) + cfg.t_offset, "t_model": float(tp), "theta_abs": float(p)}
            for p, tp in zip(response.peaks, response.peak_times)
            if lo <= tp <= hi
        ],
        "restitution": {
            "means": {"right": law["means"][0], "left": law["means"][1]},
            "spread": law["spread"],
            "distribution": "normal about the corner's mean, truncated to (0, 1] by redrawing",
            "table_length": len(tables[0]),
        },
        "damping": _damping(st.specimen),
        "noise": {
            "fraction_of_peak": cfg.noise,
            "std": {k: cfg.noise * p for k, p in levels["peak"].items()},
            "kind": "white Gaussian, independent per sample and channel, after sampling",
        },
        "bias": {
            "fraction_of_peak": None if isinstance(cfg.bias, dict) else cfg.bias,
            "values": levels["bias"],
        },
        "peak": levels["peak"],
        "sampling": {"fs_hz": cfg.fs, "oversample": cfg.oversample, "anti_alias": figures},
        "simulation": _describe_run(response, grid),
    }
    return out


def _impacts(response, lo: float, hi: float, offset: float) -> list[dict]:
    """The impacts inside the trace: time, corner hit, r applied, peaks around it."""
    peaks, times = np.asarray(response.peaks), np.asarray(response.peak_times)
    out = []
    for e in response.events:
        if e.kind != "impact" or not lo <= e.time <= hi:
            continue
        before = np.flatnonzero(times < e.time)
        after = np.flatnonzero(times > e.time)
        out.append(
            {
                "t": e.time + offset,
                "t_model": e.time,
                "corner": _CORNER[int(np.sign(e.phase_after))],
                "r": e.restitution,  # None: a Dirac-delta force that never switched on
                "theta_before": float(peaks[before[-1]]) if before.size else None,
                "theta_after": float(peaks[after[0]]) if after.size else None,
            }
        )
    return out


def corner_statistics(impacts: list[dict]) -> dict:
    """``r_mean_right``, ``r_mean_left`` and ``sigma_r``, the pooled standard deviation
    about the corner means (one degree of freedom per corner used); None where undefined."""
    by = {
        c: [i["r"] for i in impacts if i["corner"] == c and i["r"] is not None]
        for c in _CORNER.values()
    }
    means = {c: float(np.mean(r)) if r else None for c, r in by.items()}
    dof = sum(len(r) - 1 for r in by.values() if r)
    ss = sum(float(np.sum((np.asarray(r) - means[c]) ** 2)) for c, r in by.items() if r)
    return {
        "r_mean_right": means["right"],
        "r_mean_left": means["left"],
        "sigma_r": float(np.sqrt(ss / dof)) if dof > 0 else None,
    }


def _damping(spec) -> dict | None:
    """The Rayleigh damping ratios simulated (a column's), None for a rigid block."""
    if not hasattr(spec, "zeta_1"):
        return None
    return {"zeta_1": float(spec.zeta_1), "zeta_2": float(spec.zeta_2)}


def _describe_model(model) -> dict:
    """The impact model's name, class and parameters (its restitution is the drawn one)."""
    fields = {
        f.name: getattr(model, f.name)
        for f in dataclasses.fields(model)
        if f.name not in ("restitution", "name")
    }
    return {"name": model.name, "class": type(model).__name__, **fields}


def _describe_run(response, grid) -> dict:
    options = {
        k: val for k, val in response.options.items() if k not in ("restitution", "excitation")
    }
    return {
        "status": response.status,
        "warnings": list(response.warnings),
        "t_simulated": grid.t_simulated,
        "output_dt": float(grid.t_high[1] - grid.t_high[0]),
        **options,
    }
