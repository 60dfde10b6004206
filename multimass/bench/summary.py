"""The table of figures of a benchmark run, as Markdown (``summary.md``)."""

from __future__ import annotations

__all__ = ["summary_markdown", "fastest_within"]

_LABELS = {
    "speedup_single": "S1 DD2 release: solve_ivp path / compiled path",
    "peak_error_rad": "largest peak error of the compiled run vs a tight reference (rad)",
    "speedup_map": "B6M sine map: solve_ivp loop / compiled map on 2 workers",
    "scaling_2_workers": "compiled map: 1 worker / 2 workers",
}


def _fmt(x, spec=".3g") -> str:
    return "—" if x is None else format(x, spec)


def _verdict(passed) -> str:
    return "— (smaller case than the target's)" if passed is None else "yes" if passed else "NO"


def _spread(d: dict) -> str:
    return f"{d['median']:.3g} [{d['min']:.3g}–{d['max']:.3g}]"


def fastest_within(rows: list[dict], model: str, tol: float) -> dict | None:
    """The fastest run of `model` whose peak error is ≤ `tol` rad and which fails nothing."""
    ok = [
        r
        for r in rows
        if r["model"] == model and r["error"] is not None and r["error"] <= tol and not r["failure"]
    ]
    return min(ok, key=lambda r: r["wall_time_s"], default=None)


def _targets(res: dict) -> list[str]:
    t = res["targets"]
    single, mp = t["single"]["output_dt=1e-3 (default)"], t["map"]
    reps = {
        "speedup_single": _spread(single["speedup"]),
        "speedup_map": _spread(mp["speedup_map"]),
        "scaling_2_workers": _spread(mp["scaling_2_workers"]),
        "peak_error_rad": _fmt(res["peak_error_rad"], ".2e"),
    }
    lines = ["| target | measured: median [min–max] | threshold | pass |", "|---|---|---|---|"]
    for k, lab in _LABELS.items():
        op = "≤" if k == "peak_error_rad" else "≥"
        lines.append(
            f"| {lab} | {reps[k]} | {op} {t['thresholds'][k]:g} | {_verdict(t['pass'][k])} |"
        )
    nodt = t["single"]["output_dt=None"]
    base = mp["baseline"]
    lines += [
        "",
        f"- {t['single']['case']}: solve_ivp {_spread(single['scipy_s'])} s, compiled "
        f"{_spread(single['compiled_s'])} s per call (output every 1 ms); without output "
        f"(output_dt=None) the ratio is {_spread(nodt['speedup'])}.",
        f"- Map: {base['cells']} cells; solve_ivp loop {base['ms_per_cell']:.2f} ms per cell "
        f"({base['cells_timed']} cells timed{', seeded random subsample' if base['sampled'] else ''}"
        f", {base['seconds_scaled_to_grid']:.1f} s for the grid); compiled map "
        f"{_spread(mp['compiled_s']['2_workers'])} s on 2 workers, "
        f"{_spread(mp['compiled_s']['1_worker'])} s on 1, "
        f"{mp['compiled_s']['serial_executor']:.2f} s with the serial executor; same outcome "
        f"as the map in {100 * base['same_outcome_as_map']:.1f} % of the timed cells. "
        f"Best times: speed-up {mp['best_of']['speedup_map']:.3g}, 2-worker scaling "
        f"{mp['best_of']['scaling_2_workers']:.3g}; 1-min load average before each map "
        + ", ".join(f"{x:.2f}" for x in mp["load_average_before_each_map"])
        + ".",
    ]
    if "machine_scaling" in mp:
        lines.append(
            f"- The machine's own 2-worker scaling (a pure-Python loop on the same pools, "
            f"after each map pair): {_spread(mp['machine_scaling'])}, what the machine allowed at "
            "that moment."
        )
    return lines


def _compile(res: dict) -> list[str]:
    c = res["compile"]
    out = []
    if "cold_compile_s" in c:
        out.append(
            f"- Compiled path, one-off: {c['cold_compile_s']:.1f} s to compile in a fresh "
            f"process with an empty cache, {c['load_from_cache_s']:.2f} s to load from the "
            "disk cache in the next process; never inside a timed run."
        )
    k = c["kernels"]
    out.append(
        f"- This run: fast path {k['fast_path']['seconds']:.2f} s ({k['fast_path']['source']}), "
        f"Newmark kernel {k['newmark_s']:.2f} s, Moreau–Jean kernel {k['nscd_s']:.2f} s."
    )
    return out


def _models(res: dict) -> list[str]:
    rows = res["rows"]
    lines = [
        "| model | fastest run with peak error ≤ 1e-6 rad | fastest with ≤ 1e-9 rad | "
        "runs that fail |",
        "|---|---|---|---|",
    ]
    for model in dict.fromkeys(r["model"] for r in rows):
        cells = []
        for tol in (1e-6, 1e-9):
            b = fastest_within(rows, model, tol)
            cells.append(
                "—"
                if b is None
                else f"{b['method']} ({b['level_name']} {b['tolerance']:g}): "
                f"{b['wall_time_s']:.3g} s, {b['n_rhs']} RHS"
            )
        n_fail = sum(1 for r in rows if r["model"] == model and r["failure"])
        n = sum(1 for r in rows if r["model"] == model)
        lines.append(f"| {model} | {cells[0]} | {cells[1]} | {n_fail} of {n} |")
    return lines


def _failures(res: dict) -> list[str]:
    counts = {}
    for r in res["rows"] + res["stiffness"]["rows"]:
        for k in r["failure"]:
            counts.setdefault(k, []).append(f"{r['model']} {r['method']} @ {r['tolerance']:g}")
    lines = [
        f"- **{k}** ({len(v)}): " + ", ".join(v[:12]) + (" …" if len(v) > 12 else "")
        for k, v in counts.items()
    ]
    for s, w in res["stiffness"]["implicit_wins"].items():
        lines.append(
            f"- stiffness × {float(s):g}: fastest explicit {w['explicit']} "
            f"{w['explicit_s']:.2f} s, fastest implicit {w['implicit']} {w['implicit_s']:.2f} s"
            f" → {'implicit wins' if w['implicit_wins'] else 'explicit wins'}"
        )
    for v in res["nscd_convergence"]:
        lines.append(
            f"- {v['method']}, Δt {v['dt_coarse']:g} → {v['dt_fine']:g} s: {v['status']}"
            + (f" ({v['measure']}: {v['reason']})" if v["reason"] else "")
        )
    return lines


def summary_markdown(res: dict) -> str:
    """Markdown tables of the targets, the compile cost, the models and the failures."""
    parts = [
        f"# Benchmark summary ({res['config']['name']} run, {res['wall_time_s']:.0f} s, "
        f"{res['machine']['cpus']} CPUs, load average at start "
        f"{res['machine']['load_average_start'][0]:.2f})",
        "",
        "## Targets",
        "",
        *_targets(res),
        "",
        "## Compilation",
        "",
        *_compile(res),
        "",
        "## Work precision",
        "",
        *_models(res),
        "",
        "## Where methods fail",
        "",
        *_failures(res),
        "",
    ]
    return "\n".join(parts)
