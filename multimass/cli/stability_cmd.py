"""``multimass stability``: overturning map of a rigid block (paper 004, Figs 4–9)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

from ..errors import InputError
from . import _types as types
from ._args import add_mp_args, pulse_from_args
from ._output import output_folder
from ._sweep_args import add_executor_args, executor_kwargs

STORE_MIN_CELLS = 250_000  # multimass.sweeps.map_store.STORE_MIN_CELLS (not imported at startup)

__all__ = ["register"]


def register(sub) -> None:
    p = sub.add_parser(
        "stability",
        help="overturning map of a rigid block under a single sine or cosine pulse",
        description="Outcome (no rocking, rocking then rest, overturned) over ω/p and a0/(α g) "
        "for a single sine or cosine pulse (paper 004). Ranges are inclusive: "
        "START:STOP:COUNT.",
    )
    p.add_argument("block", metavar="BLOCK", help="bundled block (B6M, B3L, ...) or TOML file")
    p.add_argument(
        "--pulse",
        choices=("sine", "cosine", "ricker", "mp"),
        default="sine",
        help="single sine or cosine wave of paper 004, Fig 2 (default sine), a Ricker "
        "wavelet (ω its ω_p, a0 its peak), or a Mavroeidis-Papageorgiou pulse (ω = 2π f_p, "
        "a0 its peak acceleration; shape from --gamma and --nu)",
    )
    add_mp_args(p)
    p.add_argument(
        "--restitution",
        default="modified",
        help="modified (η_M, paper 004 Eq 10) | housner (η_H, Eq 9) | VALUE",
    )
    p.add_argument(
        "--k",
        type=types.unit_interval,
        default=None,
        help="k of η_M, in [0, 1] (default: the block's published k)",
    )
    p.add_argument("--omega-p", default="0.5:10:40", help="ω/p range START:STOP:COUNT")
    p.add_argument("--amp", default="0.25:8:40", help="a0/(α g) range START:STOP:COUNT")
    p.add_argument(
        "--refine", type=types.whole, default=2, help="bisection rounds on the boundary (default 2)"
    )
    p.add_argument(
        "--integrator",
        choices=("solve_ivp", "newmark"),
        default="solve_ivp",
        help="solve_ivp with exact impact location, or paper 004's Newmark + Newton-Raphson",
    )
    p.add_argument(
        "--backend",
        choices=("scipy", "compiled"),
        default=None,
        help="solve_ivp path: compiled fast path (default) or scipy's solve_ivp",
    )
    p.add_argument(
        "--dt", type=types.positive, default=1e-3, help="Newmark step (s; default 0.001)"
    )
    p.add_argument(
        "--t-free",
        type=types.positive,
        default=10.0,
        help="free rocking after the pulse (s; default 10)",
    )
    add_executor_args(p)
    p.add_argument(
        "--compare",
        action="store_true",
        help="also run the other restitution (housner vs modified) and draw both",
    )
    p.add_argument(
        "--out", type=Path, default=None, help="folder for the table (CSV), JSON and figure"
    )
    p.add_argument(
        "--store",
        action="store_true",
        help="stream the cells to --out/cells/ in Parquet chunks, with --out/manifest.json "
        "(--compare: the other map in --out/ALT/; automatic above "
        f"{STORE_MIN_CELLS:,} cells); re-running the same command resumes an interrupted map",
    )
    p.add_argument(
        "--adaptive",
        action="store_true",
        help="compute only the cells near outcome boundaries, from a coarse lattice refined "
        "where neighbours disagree (islands of at least --coarse × --coarse cells are found)",
    )
    p.add_argument(
        "--coarse",
        type=types.whole,
        default=8,
        help="coarse spacing of --adaptive, a power of 2 (default 8)",
    )
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(func=run)


#: What the command's ``wall_time_s`` covers (said in its JSON).
WALL_TIME_COVERS = (
    "the whole command, from the start of its process: start-up and imports, loading the "
    "compiled kernels, the cells, the boundary refinement, assembling the tables and "
    "writing the table and figures (the JSON, written last, excepted)"
)


def run(args) -> int:
    import time

    import multimass
    from multimass.sweeps.map_cells import pulse_label
    from multimass.sweeps.maps import overturning_map
    from multimass.sweeps.ranges import check_values, parse_range

    started = getattr(args, "started", None)
    started = time.perf_counter() if started is None else started
    st = multimass.from_specimen(args.block)
    if st.n != 0:
        raise InputError(
            f"`BLOCK` = {args.block!r} is a column; `stability` maps rigid blocks "
            "(use `multimass spectrum` for a column)"
        )
    out = output_folder(args.out)
    omega_p = check_values("--omega-p", parse_range(args.omega_p, "--omega-p"), positive=True)
    amp = check_values("--amp", parse_range(args.amp, "--amp"), nonnegative=True)
    sim = dict(integrator=args.integrator, dt=args.dt) if args.integrator == "newmark" else {}
    if args.backend is not None and args.integrator != "newmark":
        sim["backend"] = args.backend
    store = args.store or (not args.adaptive and omega_p.size * amp.size > STORE_MIN_CELLS)
    if store and out is None:
        raise InputError(
            f"a map of {omega_p.size * amp.size:,} cells streams to disk: give `--out DIR` "
            "(or --adaptive, or fewer cells)"
        )
    if store and args.adaptive:
        raise InputError("`--store` and `--adaptive` do not combine: adaptive maps stay in memory")
    kw = dict(
        pulse=pulse_from_args(args),
        omega_p=omega_p,
        amp=amp,
        k=args.k,
        refine=args.refine,
        t_free=args.t_free,
        **executor_kwargs(args),
        **sim,
    )
    if args.adaptive:
        kw.update(adaptive=True, coarse=args.coarse)
    name = f"{st.name}_{pulse_label(kw['pulse'])}_{args.restitution}"
    at = lambda alt: {"store": out if alt is None else out / alt} if store else {}
    try:
        m = overturning_map(st, restitution=args.restitution, **kw, **at(None))
    except KeyboardInterrupt:
        if not store:
            raise
        done = len(list((out / "cells").glob("chunk-*.parquet")))
        print(
            f"\ninterrupted: {done} finished chunks are in {out}/cells/; run the same "
            "command again to resume (finished chunks are not recomputed)",
            file=sys.stderr,
        )
        return 130
    info = m.summary()
    other = None
    if args.compare:
        alt = "housner" if args.restitution != "housner" else "modified"
        other = overturning_map(st, restitution=alt, **kw, **at(alt))
        info["comparison"] = {alt: other.summary()}
    maps = [m] if other is None else [m, other]
    if out is not None:
        from multimass.sweeps.plots import plot_map, plot_map_comparison  # matplotlib: only here

        stem = out / name
        if not store and len(m.cells) > STORE_MIN_CELLS:  # an adaptive map of a large grid
            m.cells.to_parquet(f"{stem}_cells.parquet", index=False)  # 80 MB as CSV at 10⁶
        elif not store:
            m.cells.to_csv(f"{stem}_cells.csv", index=False)
        plot_map(m, f"{stem}_map.png")
        if other is not None:
            plot_map_comparison({args.restitution: m, alt: other}, f"{stem}_vs_{alt}.png")
    info.update(
        map_wall_time_s=float(sum(x.wall_time_s for x in maps)),
        simulation_time_s=float(sum(x.simulation_time_s for x in maps)),
        wall_time_covers=WALL_TIME_COVERS,
    )
    info["wall_time_s"] = time.perf_counter() - started  # last: everything above counts
    if out is not None:
        Path(f"{out / name}_map.json").write_text(json.dumps(info, indent=2))
    if args.json:
        print(json.dumps(info, indent=2))
    else:
        o = info["outcomes"]
        print(
            f"{st.name} {pulse_label(kw['pulse'])}: {info['n_simulations']} simulations in "
            f"{info['wall_time_s']:.1f} s; "
            f"overturned {o['overturned']}, rest {o['rest']}, no rocking {o['no_rocking']}"
            + (f", undecided {o['undecided']}" if o["undecided"] else "")
            + (
                f"; {info['inaccurate']} cells failed their accuracy check (outcome kept; "
                "tighten --dt or the tolerances)"
                if info["inaccurate"]
                else ""
            )
            + (
                f"; {info['options']['adaptive']['computed']} of "
                f"{info['options']['adaptive']['cells']} grid cells computed"
                if args.adaptive
                else ""
            )
            + (
                f"; chunks computed {info['store']['chunks_computed']}, "
                f"found on disk {info['store']['chunks_skipped']}; cells in {m.folder}/cells/"
                if store
                else ""
            )
            + (f"; files in {out}/" if out else "")
        )
    return 0
