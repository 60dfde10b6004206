"""Where methods fail: automatic detection on every run, a stiffness sweep, NSCD convergence.

Failure kinds, each detected from the run alone or against its reference:

* ``solver_failed`` — status "failed" or the call raised (the message is kept);
* ``missed_impacts`` — the transitions up to the comparison time differ from the
  reference's in number or kind (see `multimass.bench.work_precision`);
* ``chattering`` — more transitions inside one impact (following the previous one
  within 0.02 s, paper 001 Section 4.3) than the reference has;
* ``energy_drift`` — the energy balance does not close: largest balance error
  above `DRIFT_TOL` of the energy scale (for Moreau–Jean with e = 0: an energy
  increase over one step above that share);
* ``not_converging`` — Moreau–Jean: refining Δt does not shrink the differences
  between successive levels (`nscd.convergence.judge`, paper 002 Sections 6.1,
  6.3), attached to the coarser level of the refinement that failed to improve;
* ``cost_blowup`` — stiffness sweep: an explicit method's RHS count grows at
  least half as fast as the highest frequency (∝ √scale): its step is set by
  stability, not accuracy.
"""

from __future__ import annotations

import math

from multimass.inputs.excitations import FreeRelease
from multimass.simulation import DEFAULTS

from .cases import IMPLICIT, NSCDRunner, engine_runner, scaled_column
from .config import Config
from .work_precision import compare, window_end

__all__ = [
    "KINDS",
    "DRIFT_TOL",
    "detect",
    "annotate",
    "stiffness_sweep",
    "nscd_convergence",
    "failure_table",
    "markdown_table",
]

KINDS = (
    "solver_failed",
    "missed_impacts",
    "not_converging",
    "chattering",
    "energy_drift",
    "cost_blowup",
)
DRIFT_TOL = 1e-3
STIFF_METHODS = (
    ("RK45", "scipy"),
    ("DOP853", "scipy"),
    ("LSODA", "scipy"),
    ("Radau", "scipy"),
    ("BDF", "scipy"),
    ("DOP853", "compiled"),
)


def detect(row: dict) -> list[tuple[str, str]]:
    """(kind, detail) of every failure a benchmark row shows."""
    out = []
    if row["status"] == "failed":
        return [("solver_failed", row.get("message", "")[:160])]
    if row.get("events_match") is False:
        out.append(
            (
                "missed_impacts",
                f"{row['n_events']} transitions, reference "
                f"{row['n_events_ref']} (up to t = {row['t_compare']:.3g} s); "
                f"{row.get('first_mismatch', '')}",
            )
        )
    if row["chatter"] > row["chatter_ref"]:
        out.append(
            (
                "chattering",
                f"{row['chatter']} transitions within 0.02 s of the previous, "
                f"reference {row['chatter_ref']}",
            )
        )
    if math.isfinite(row["balance_error"]) and row["balance_error"] > DRIFT_TOL:
        out.append(
            (
                "energy_drift",
                f"energy balance error {row['balance_error']:.2g} "
                f"of the energy scale (> {DRIFT_TOL:g})",
            )
        )
    return out


def annotate(rows: list[dict]) -> list[dict]:
    """Add ``failure`` (list of kinds) and ``failure_detail`` to each row, in place."""
    for r in rows:
        found = detect(r) + r.pop("_extra_failures", [])
        r["failure"] = [k for k, _ in found]
        r["failure_detail"] = "; ".join(f"{k}: {d}" for k, d in found)
    return rows


def stiffness_sweep(cfg: Config, progress=None) -> list[dict]:
    """S1 with E_s, K_rot, K_fp × scale: each method at `stiffness_rtol` against a tight run.

    The reference of each scale is the compiled DOP853 path at the reference
    tolerance (the same steps as solve_ivp's DOP853, tests/multimass/engines/test_fast.py;
    solve_ivp would take minutes at the stiffest scale).
    """
    say = progress or (lambda msg: None)
    rows, base = [], {}
    t_end, tol = cfg.stiffness_t_end, cfg.stiffness_rtol
    for s in cfg.stiffness_scales:
        run = engine_runner(
            scaled_column(s), FreeRelease(0.11), "CIM", t_end, cfg, max_step=DEFAULTS["max_step"]
        )
        run(1e-3, method="DOP853", backend="compiled")  # warm this column's kernels
        ref = run(cfg.ref_rtol, method="DOP853", backend="compiled", atol=cfg.ref_atol)
        kinds = ("uplift", "impact", "full_contact", "overturn")
        t_cmp = window_end(ref, kinds, t_end, t_end)  # every transition and completed peak
        for method, backend in STIFF_METHODS:
            name = method if backend == "scipy" else f"compiled {method}"
            res = run(tol, method=method, backend=backend)
            errors = compare(res, ref, kinds, t_cmp) | {"t_compare": t_cmp}
            row = {
                "model": "S1 stiffness",
                "method": name,
                "family": "implicit"
                if method in IMPLICIT
                else (
                    "LSODA (switching)"
                    if method == "LSODA"
                    else "compiled"
                    if backend == "compiled"
                    else "explicit"
                ),
                "level_name": "stiffness",
                "tolerance": s,
                "rtol": tol,
                "error": errors["peak_error_rad"],
                **errors,
                "wall_time_s": res.wall_time_s,
                "n_rhs": res.n_rhs,
                "status": res.status,
                "message": res.message if res.status == "failed" else "",
                "chatter": res.chatter,
                "chatter_ref": ref.chatter,
                "balance_error": res.balance_error,
                "reference": f"compiled DOP853, rtol {cfg.ref_rtol:g}",
            }
            base.setdefault(name, res.n_rhs if res.status != "failed" else None)
            growth = res.n_rhs / base[name] if base[name] else math.nan
            row["rhs_growth"] = growth
            if (
                row["family"] in ("explicit", "compiled")
                and s >= 100
                and growth >= 0.5 * math.sqrt(s)
            ):
                row["_extra_failures"] = [
                    (
                        "cost_blowup",
                        f"RHS evaluations × {growth:.1f} "
                        f"at stiffness × {s:g} (√ = {math.sqrt(s):.1f})",
                    )
                ]
            rows.append(row)
            say(f"  stiffness ×{s:<7g} {name:16s} {res.wall_time_s:8.3f} s  n_rhs {res.n_rhs}")
    return annotate(rows)


def implicit_wins(rows: list[dict]) -> dict:
    """Per stiffness scale: fastest explicit solve_ivp method, fastest implicit, who wins."""
    out = {}
    for s in sorted({r["tolerance"] for r in rows}):
        ok = [r for r in rows if r["tolerance"] == s and r["status"] != "failed"]
        exp = min(
            (r for r in ok if r["family"] == "explicit"),
            key=lambda r: r["wall_time_s"],
            default=None,
        )
        imp = min(
            (r for r in ok if r["family"] == "implicit"),
            key=lambda r: r["wall_time_s"],
            default=None,
        )
        if exp and imp:
            out[s] = {
                "explicit": exp["method"],
                "explicit_s": exp["wall_time_s"],
                "implicit": imp["method"],
                "implicit_s": imp["wall_time_s"],
                "implicit_wins": imp["wall_time_s"] < exp["wall_time_s"],
            }
    return out


def nscd_convergence(cfg: Config, mj: NSCDRunner, rows: list[dict]) -> list[dict]:
    """Verdicts of successive Δt refinements of Moreau–Jean per flexible beam (and rigid base).

    Reuses `nscd.convergence.compare_runs` on the runs of the NSCD chart; a
    refinement whose verdict is "not converged" marks the coarser level's row
    with ``not_converging``.
    """
    from multimass.engines.nscd.convergence import compare_runs

    out = []
    for n in (None,) + tuple(cfg.nscd_exponents):
        dts = sorted(
            set(cfg.mj_dts) | ({cfg.nscd_ref_dt} if n is not None else set()), reverse=True
        )
        runs = [mj.result(dt, n) for dt in dts]
        if len(dts) < 2 or any(isinstance(r, BaseException) for r in runs):
            continue
        name = "Moreau–Jean, rigid base" if n is None else f"Moreau–Jean, E = Ē·10^{n}"
        for k in range(1, len(dts) - 1):
            verdicts = compare_runs(dts[: k + 2], runs[: k + 2], dts[0] / dts[1])
            worst = next((v for v in verdicts if v.status == "not converged"), None)
            out.append(
                {
                    "method": name,
                    "dt_coarse": dts[k],
                    "dt_fine": dts[k + 1],
                    "status": "not converged" if worst else "converging or converged",
                    "measure": worst.measure if worst else "",
                    "reason": worst.reason if worst else "",
                    "differences": {v.measure: v.differences[-1] for v in verdicts},
                }
            )
            if worst:
                for r in rows:
                    if r["model"] == "nscd" and r["method"] == name and r["tolerance"] == dts[k]:
                        r.setdefault("_extra_failures", []).append(
                            (
                                "not_converging",
                                f"Δt {dts[k]:g} → {dts[k + 1]:g} s: {worst.measure} {worst.reason}",
                            )
                        )
    return out


def failure_table(rows: list[dict]) -> list[dict]:
    """One line per (model, method, level) that fails, with its failure kinds."""
    return [
        {
            "model": r["model"],
            "method": r["method"],
            "level_name": r["level_name"],
            "level": r["tolerance"],
            "failure": ", ".join(r["failure"]),
            "detail": r["failure_detail"],
        }
        for r in rows
        if r["failure"]
    ]


def markdown_table(table: list[dict]) -> str:
    """The failure table as Markdown."""
    lines = ["| model | method | level | failure | detail |", "|---|---|---|---|---|"]
    for t in table:
        lines.append(
            f"| {t['model']} | {t['method']} | {t['level_name']} = {t['level']:g} | "
            f"{t['failure']} | {t['detail'].replace('|', '/')} |"
        )
    return "\n".join(lines) + "\n"
