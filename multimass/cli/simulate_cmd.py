"""``multimass simulate``: one nonlinear time history, with CSV, figures and JSON."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from . import _types as types
from ._args import (
    add_excitation_args,
    add_impact_args,
    add_solver_args,
    excitation_from_args,
    impact_kwargs,
    solver_kwargs,
)
from ._output import output_folder, write_csv

__all__ = ["register", "sensor_nodes", "default_t_end", "status_line", "exit_code"]


def register(sub) -> None:
    p = sub.add_parser(
        "simulate",
        help="nonlinear time history: free release, pulse or record",
        description="Simulate the rocking response of a bundled specimen or TOML file "
        "(paper 001 Section 2; paper 004 for blocks). Writes the time series (CSV), "
        "the event log, the summary (JSON) and figures to --out.",
    )
    p.add_argument("specimen", metavar="SPECIMEN", help="bundled name (S1, B6M, ...) or TOML file")
    add_excitation_args(p)
    add_impact_args(p)
    add_solver_args(p)
    g = p.add_argument_group("integrator")
    g.add_argument(
        "--integrator",
        choices=("solve_ivp", "newmark"),
        default="solve_ivp",
        help="solve_ivp (default; any structure) or paper 004's Newmark + "
        "Newton-Raphson (rigid blocks with classical impacts, e.g. --impact CIM)",
    )
    g.add_argument(
        "--dt",
        type=types.positive,
        default=1e-3,
        help="time step of --integrator newmark (s; default 0.001)",
    )
    p.add_argument(
        "--t-end",
        type=types.positive,
        default=None,
        help="end time (s); default 10 s for a release, else the excitation + 5 s",
    )
    p.add_argument(
        "--progress",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="show a progress bar (default: for runs estimated above a few seconds)",
    )
    p.add_argument("--out", type=Path, default=None, help="folder for CSV, JSON and figures")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(func=run)


def default_t_end(excitation) -> float:
    """10 s of free rocking, or the excitation's duration plus 5 s."""
    d = float(getattr(excitation, "duration", 0.0))
    return 10.0 if d == 0.0 else d + 5.0


def sensor_nodes(structure, names=("A2", "A4")) -> dict[str, int]:
    """Nodes to plot accelerations at: the specimen's sensors, else mid-height and top."""
    spec = structure.specimen
    found = {k: v for k, v in getattr(spec, "sensors", ()) if k in names}
    if found:
        return found
    if structure.n == 0:
        return {}
    return {"mid": max(1, (structure.n + 1) // 2), "top": structure.n}


def status_line(name: str, resp) -> str:
    """One line for the terminal: status, counts, the ledger, and why a run is not normal."""
    line = (
        f"{name}: {resp.status}; {resp.n_impacts} impacts, {resp.n_full_contact} full-contact "
        f"transitions; theta_max = {resp.theta_max:.5f} rad; energy balance error "
        f"{resp.energy_balance_error:.2e}; {resp.wall_time_s:.2f} s"
    )
    if resp.status == "failed":
        line += f"\n  failed: {resp.message}"
    if resp.status == "inaccurate":
        line += f" (the run {resp.outcome}, but an accuracy check failed)"
    for w in resp.warnings:
        line += f"\n  warning: {w}"
    return line


def exit_code(status: str) -> int:
    """0 for a trustworthy result, 1 for a failed or inaccurate run."""
    return 0 if status in ("completed", "overturned") else 1


def run(args) -> int:
    import multimass
    from multimass.analysis.plots import plot_accelerations, plot_energy, plot_rocking

    st = multimass.from_specimen(args.specimen)
    exc = excitation_from_args(args, st)
    out = output_folder(args.out)
    t_end = args.t_end if args.t_end is not None else default_t_end(exc)
    sim = impact_kwargs(args) | solver_kwargs(args) | {"progress": args.progress}
    if args.integrator == "newmark":
        for key in ("method", "rtol", "atol", "max_step", "backend"):
            sim.pop(key, None)
        sim |= {"integrator": "newmark", "dt": args.dt}
    resp = multimass.simulate(st, exc, t_end=t_end, **sim)
    info = resp.summary()
    if out is not None:
        stem = out / st.name
        write_csv(resp.series, f"{stem}_series.csv", args.progress)
        resp.events_frame().to_csv(f"{stem}_events.csv", index=False)
        Path(f"{stem}_summary.json").write_text(json.dumps(info, indent=2))
        if not resp.series.empty:
            plot_rocking(resp, f"{stem}_rocking.png", g=st.g)
            plot_energy(resp, f"{stem}_energy.png")
            nodes = sensor_nodes(st)
            if nodes:
                plot_accelerations(resp, nodes, f"{stem}_accelerations.png", st.g)
    if args.json:
        print(json.dumps(info, indent=2))
    else:
        print(status_line(st.name, resp) + (f"\nfiles in {out}/" if out else ""))
    return exit_code(resp.status)
