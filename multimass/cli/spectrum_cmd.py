"""``multimass spectrum``: rocking response spectra (paper 001, Figs 10 and 12)."""

from __future__ import annotations

import json
import time
from pathlib import Path

from ..errors import InputError
from . import _types as types
from ._args import (
    PULSES,
    add_impact_args,
    add_mp_args,
    add_solver_args,
    impact_kwargs,
    pulse_from_args,
    solver_kwargs,
)
from ._output import output_folder
from ._sweep_args import add_executor_args, executor_kwargs

__all__ = ["register", "WALL_TIME_COVERS"]


def register(sub) -> None:
    p = sub.add_parser(
        "spectrum",
        help="θ_max against pulse frequency or amplitude, or record scale factor",
        description="Rocking response spectra (paper 001 Section 4.4): pulses swept in ω or "
        "amplitude, or a record swept in scale factor with repeats (random "
        "restitution). Ranges are inclusive: START:STOP:COUNT.",
    )
    p.add_argument(
        "specimen",
        metavar="SPECIMEN",
        help="bundled name (S1, S2, S3, B6M, ...) or a specimen TOML file",
    )
    p.add_argument(
        "--pulse",
        choices=PULSES,
        default=None,
        help="sweep a pulse: cosine (paper 001's cosine pulse), sine, ricker or mp "
        "(Mavroeidis-Papageorgiou; --amp its peak acceleration, --omega 2π f_p, shape from "
        "--gamma and --nu); with --omega and --amp, one of them a range",
    )
    add_mp_args(p)
    p.add_argument("--omega", default=None, help="rad/s: one value or START:STOP:COUNT")
    p.add_argument("--amp", default=None, help="e.g. 0.4g or 0.2g:0.8g:7 (default unit g)")
    p.add_argument(
        "--record",
        default=None,
        metavar="FILE",
        help="sweep a record's scale: PEER .AT2 or two-column file (with --units)",
    )
    p.add_argument(
        "--units", default=None, help="units of a two-column record: g, m/s2, cm/s2, mm/s2"
    )
    p.add_argument("--scale", default=None, help="scale factors START:STOP:COUNT or one value")
    p.add_argument(
        "--repeats",
        type=types.count,
        default=None,
        help="runs per point, ≥ 1 (default 1 for pulses, 3 for records)",
    )
    p.add_argument(
        "--t-free",
        type=types.positive,
        default=5.0,
        help="free response after the excitation (s; default 5)",
    )
    add_impact_args(p, default=None)
    add_solver_args(p)
    add_executor_args(p)
    p.add_argument(
        "--out",
        type=Path,
        default=None,
        help="folder for the table (CSV), the summary (JSON) and the figure (PNG)",
    )
    p.add_argument(
        "--json", action="store_true", help="print the summary and the statistics per point as JSON"
    )
    p.set_defaults(func=run)


#: What the command's ``wall_time_s`` (JSON, printed line) counts.
WALL_TIME_COVERS = (
    "the whole command: from its start (its imports, loading the compiled kernels, "
    "reading the record, starting the workers) through the runs, the table, the "
    "statistics and the CSV and figure written, to the JSON summary"
)


def run(args) -> int:
    started = time.perf_counter()
    import multimass
    from multimass.inputs.excitations import plausible_amplitude
    from multimass.inputs.units import parse_acceleration
    from multimass.sweeps.ranges import check_values, parse_range
    from multimass.sweeps.spectra import pulse_spectrum, record_spectrum

    st = multimass.from_specimen(args.specimen)
    out = output_folder(args.out)
    sim = impact_kwargs(args)
    seed = sim.pop("seed")
    sim["impact"] = sim["impact"] or ("DD2" if args.pulse is not None else "DD5")
    common = dict(
        t_free=args.t_free,
        seed=0 if seed is None else seed,
        **executor_kwargs(args),
        **sim,
        **{k: v for k, v in solver_kwargs(args).items() if k != "output_dt"},
    )
    if (args.pulse is None) == (args.record is None):
        raise InputError("give either --pulse (with --omega and --amp) or --record (with --scale)")
    if args.pulse is not None:
        if args.omega is None or args.amp is None:
            raise InputError("`--pulse` needs --omega and --amp (one of them may be a range)")
        omega = check_values("--omega", parse_range(args.omega, "--omega"), positive=True)
        amp = check_values(
            "--amp",
            parse_range(
                args.amp,
                "--amp",
                lambda x: plausible_amplitude(
                    "--amp", parse_acceleration(x, "g", argument="--amp")
                ),
            ),
            nonnegative=True,
        )
        family = pulse_from_args(args)
        sp = pulse_spectrum(st, family, omega, amp, repeats=args.repeats or 1, **common)
        x = "omega" if omega.size >= amp.size else "amp"
        xlabel = "ω (rad/s)" if x == "omega" else "amplitude (m/s²)"
        title = (
            f"{st.name}: {args.pulse} pulse, "
            + (f"A = {amp[0] / multimass.G:.3g} g" if x == "omega" else f"ω = {omega[0]:.3g} rad/s")
            + f", {sim['impact']}"
        )
    else:
        if args.scale is None:
            raise InputError("`--record` needs --scale START:STOP:COUNT (or one value)")
        rec = multimass.read_record(args.record, units=args.units)
        scale = check_values("--scale", parse_range(args.scale, "--scale"), positive=True)
        sp = record_spectrum(st, rec, scale, repeats=args.repeats or 3, **common)
        x, xlabel = "scale", "scale factor A_sc"
        title = f"{st.name}: {rec.name} scaled, {sim['impact']}, {args.repeats or 3} repeats"
    info = sp.summary() | {
        "stats": sp.stats(x).replace({float("nan"): None}).to_dict(orient="records")
    }
    if out is not None:
        from multimass.sweeps.plots import plot_spectrum  # matplotlib: only for the figure

        stem = out / f"{st.name}_spectrum_{x}"
        sp.table.to_csv(f"{stem}.csv", index=False)
        table, px = sp.table, x
        if x == "amp":  # plot amplitudes in g
            table, px, xlabel = (
                table.assign(amp_g=table.amp / multimass.G),
                "amp_g",
                "amplitude A (g)",
            )
        plot_spectrum(table, px, f"{stem}.png", xlabel, title)
    info["wall_time_s"] = time.perf_counter() - getattr(args, "started", started)
    info["wall_time_covers"] = WALL_TIME_COVERS
    if out is not None:
        Path(f"{stem}.json").write_text(json.dumps(info, indent=2))
    if args.json:
        print(json.dumps(info, indent=2))
    else:
        if "method_choice" in sp.options:
            print(f"method {sp.options['method_choice']['reason']}")
        print("θ_max over the completed runs (overturned and inaccurate runs counted apart):")
        for row in info["stats"]:
            print(_stats_line(x, row))
        print(
            f"{info['n_simulations']} simulations in {info['wall_time_s']:.1f} s"
            + (f"; files in {out}/" if out else "")
        )
    return 0


def _stats_line(x: str, row: dict) -> str:
    """One point of the spectrum: θ_max over its completed runs, and the other counts."""
    head = f"{x} = {row[x]:.4g}: "
    if row["completed"]:
        head += (
            f"θ_max mean {row['mean']:.5f} rad (min {row['min']:.5f}, max {row['max']:.5f}) "
            f"over {row['completed']} of {row['n']} runs"
        )
    else:
        head += f"no completed run of {row['n']}"
    extra = [f"{row[k]} {k}" for k in ("overturned", "inaccurate") if row[k]]
    return head + (f"; {', '.join(extra)}" if extra else "")
