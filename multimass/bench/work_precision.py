"""Error measures against a reference, and the tolerance / time-step sweeps of each case.

Three errors per run, each against the case's tight reference:

* **peaks** — max ``|Δ peak |θ||`` over the half-cycles the reference completes
  before the comparison time (rad);
* **event times** — max ``|Δt|`` over the matched transitions (uplift, impact,
  full contact, overturn) before the comparison time (s);
* **final energy** — ``|E_run(t_end) − E_ref(t_end)|`` / the reference's energy
  scale (initial energy or largest ground work).

Matching: the transitions of both runs up to the comparison time are paired
in order. If their numbers or kinds differ the run has missed (or added)
transitions: both the event-time and the peak errors are then infinite (a
missed impact shifts every later half-cycle) and the failure detector reports
"missed impacts". The comparison time starts at `Case.t_compare` and is moved
to the middle of the reference's gap between transitions that contains it,
so a run is never penalised for an event that falls just either side of it.
"""

from __future__ import annotations

import math

from .cases import Case, Method
from .config import Config
from .results import RunResult

__all__ = ["compare", "window_end", "sweep_case", "row_of"]


def window_end(ref: RunResult, kinds, nominal: float, t_end: float) -> float:
    """The comparison time: `nominal` moved to the middle of the reference's gap around it."""
    times = sorted(t for k, t in ref.events if k in kinds)
    before = [t for t in times if t <= nominal]
    after = [t for t in times if t > nominal]
    lo = before[-1] if before else 0.0
    hi = after[0] if after else t_end
    return 0.5 * (lo + hi)


def compare(run: RunResult, ref: RunResult, kinds, t_cmp: float) -> dict:
    """The three errors of `run` against `ref` and the event counts (see the module docstring)."""
    out = dict(
        peak_error_rad=math.nan,
        event_time_error_s=math.nan,
        energy_error=math.nan,
        n_events=None,
        n_events_ref=None,
        events_match=None,
        first_mismatch="",
    )
    r_ev = [(k, t) for k, t in ref.events if k in kinds and t <= t_cmp]
    out["n_events_ref"] = len(r_ev)
    if run.status == "failed":
        return out
    x_ev = [(k, t) for k, t in run.events if k in kinds and t <= t_cmp]
    match = [k for k, _ in r_ev] == [k for k, _ in x_ev]
    out.update(n_events=len(x_ev), events_match=match, first_mismatch=_first_mismatch(r_ev, x_ev))
    out["event_time_error_s"] = (
        max((abs(a[1] - b[1]) for a, b in zip(r_ev, x_ev)), default=0.0) if match else math.inf
    )
    n_pk = sum(1 for t in ref.peak_times if t <= t_cmp)
    if match and len(run.peaks) >= n_pk:
        out["peak_error_rad"] = max(
            (abs(a - b) for a, b in zip(ref.peaks[:n_pk], run.peaks[:n_pk])), default=0.0
        )
    else:
        out["peak_error_rad"] = math.inf
    if math.isfinite(run.final_energy) and ref.energy_scale > 0:
        out["energy_error"] = abs(run.final_energy - ref.final_energy) / ref.energy_scale
    return out


def _first_mismatch(r_ev, x_ev) -> str:
    """Where two transition sequences first part: "t = …: reference impact, run full_contact"."""
    for i in range(max(len(r_ev), len(x_ev))):
        a = r_ev[i] if i < len(r_ev) else None
        b = x_ev[i] if i < len(x_ev) else None
        if a is None or b is None or a[0] != b[0]:
            t = (a or b)[1]
            return (
                f"transition {i + 1} at t = {t:.4g} s: reference {a[0] if a else 'none'}, "
                f"run {b[0] if b else 'none'}"
            )
    return ""


def row_of(
    model: str,
    method: Method,
    level: float,
    run: RunResult,
    ref: RunResult,
    errors: dict,
    reference_label: str,
) -> dict:
    """One row of the benchmark table (JSON-ready except for infinities)."""
    return {
        "model": model,
        "method": method.name,
        "family": method.family,
        "level_name": method.level_name,
        "tolerance": level,
        "error": errors["peak_error_rad"],
        **errors,
        "wall_time_s": run.wall_time_s,
        "n_rhs": run.n_rhs,
        "status": run.status,
        "message": run.message if run.status == "failed" else "",
        "chatter": run.chatter,
        "chatter_ref": ref.chatter,
        "balance_error": run.balance_error,
        "reference": reference_label,
    }


def sweep_case(case: Case, cfg: Config, progress=None) -> tuple[RunResult, list[dict]]:
    """Run every method of `case` at every level; returns (case reference, rows)."""
    say = progress or (lambda msg: None)
    ref = case.reference()
    say(
        f"{case.key}: reference {case.reference_label} in {ref.wall_time_s:.2f} s "
        f"({len(ref.events)} transitions, {len(ref.peaks)} peaks)"
    )
    rows = []
    for m in case.methods:
        mref = m.reference() if m.reference is not None else ref
        label = m.reference_label or case.reference_label
        kinds = m.kinds or case.kinds
        t_cmp = window_end(mref, kinds, case.t_compare, case.t_end)
        if m.warm:
            m.run(m.levels[0])
        for level in m.levels:
            run = m.run(level)
            errors = compare(run, mref, kinds, t_cmp)
            errors["t_compare"] = t_cmp
            rows.append(row_of(case.key, m, level, run, mref, errors, label))
            say(
                f"  {m.name:32s} {m.level_name}={level:<8.0e} {run.wall_time_s:8.3f} s  "
                f"peak err {errors['peak_error_rad']:.2e}  {run.status}"
            )
    return ref, rows
