"""``multimass nscd`` and ``multimass nscd-convergence``: a rigid block rocking on a
finite-element beam by Moreau–Jean time stepping (paper 002).

Every argument is checked, with its flag named, before anything is computed;
then the cost of the run (or of every run of a study) is estimated and a run
over the budget (``--max-hours``, default 1) is refused; then the output folder
is checked; only then does the computing start, with a progress bar for runs
estimated above a few seconds. A run whose accuracy checks fail is reported
"inaccurate" with its warnings, and the command exits with status 1.
"""

from __future__ import annotations

import argparse
import json
import math
import re
from pathlib import Path

from ..errors import InputError
from ..validation import number
from ._output import output_folder

__all__ = ["register", "NAMES"]

#: API argument -> the flag named in messages
NAMES = {
    "dt": "--dt",
    "t_end": "--t-end",
    "theta_method": "--theta-method",
    "mu": "--mu",
    "restitution": "--restitution",
    "E": "--E",
    "n_elements": "--elements",
    "x_centre": "--x-centre",
    "theta0": "--theta0-deg",
    "gs_tol": "--gs-tol",
    "gs_max_iter": "--gs-max-iter",
    "rest_fraction": "--rest-fraction",
    "dts": "--dts",
    "meshes": "--meshes",
    "exponents": "--exponents",
    "base_dt": "--dt",
    "base_mesh": "--elements",
    "blocks": "BLOCK",
    "max_hours": "--max-hours",
}
_NORMAL = ("completed", "overturned", "fell_off_beam")


def _common(p) -> None:
    p.add_argument("block", metavar="BLOCK", help="block specimen (B4M, B6M, B8M or a TOML file)")
    p.add_argument(
        "--beam",
        default="beam_mudric2024",
        help="beam specimen (default: paper 002's beam, beam_mudric2024)",
    )
    p.add_argument(
        "--theta0-deg",
        type=float,
        default=None,
        help="release angle (deg; > 0 rests on the right corner; below the block's "
        "overturning angle; default: the block's paper 002 value)",
    )
    stiff = p.add_mutually_exclusive_group()
    stiff.add_argument(
        "--E",
        type=float,
        default=None,
        metavar="PA",
        help="Young's modulus of the beam (Pa; default: the beam's, 1e24 = rigid "
        "base); from the modulus giving a midspan deflection L/30 up to 1e30",
    )
    stiff.add_argument(
        "--flex",
        type=float,
        default=None,
        metavar="N",
        help="E = Ē·10^N, Ē giving a midspan deflection L/2500 under the block; "
        "N from about -1.9 (L/30) to the value giving 1e30 Pa",
    )
    p.add_argument(
        "--theta-method",
        type=float,
        default=1.0,
        metavar="THETA",
        help="θ-method parameter in [0, 1] (paper 002: 1, backward Euler)",
    )
    p.add_argument(
        "--mu", type=float, default=None, help="friction coefficient >= 0 (default: the beam's)"
    )
    p.add_argument(
        "--restitution", type=float, default=0.0, help="Newton's e in [0, 1] (default 0, plastic)"
    )
    p.add_argument(
        "--gs-tol",
        type=float,
        default=1e-8,
        help="Gauss–Seidel relative tolerance, 1e-15 to 1e-2 (default 1e-8)",
    )
    p.add_argument(
        "--gs-max-iter",
        type=int,
        default=5000,
        help="Gauss–Seidel iteration cap, 1 to 1e6 (default 5000)",
    )
    p.add_argument(
        "--max-hours",
        type=float,
        default=None,
        help="budget: refuse a run (a whole study) estimated to take longer "
        "(default 1; inf for none)",
    )
    p.add_argument(
        "--progress",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="show progress bars (default: for runs estimated above a few seconds)",
    )
    p.add_argument("--out", type=Path, default=None, help="folder for JSON, CSV and figures")
    p.add_argument("--json", action="store_true", help="print the result as JSON")


def register(sub) -> None:
    p = sub.add_parser(
        "nscd",
        help="Moreau–Jean simulation of a rigid block rocking on a beam (paper 002)",
        description="Free rocking of a rigid block released at rest on a simply supported FE "
        "beam: θ-method, velocity Signorini + Coulomb, Gauss–Seidel (paper 002).",
    )
    _common(p)
    p.add_argument("--dt", type=float, default=1e-5, help="time step (s; default 1e-5)")
    p.add_argument(
        "--elements",
        type=int,
        default=None,
        help="number of beam elements, 3 to 1000 (default: the beam's)",
    )
    p.add_argument("--t-end", type=float, default=4.0, help="duration (s; default 4)")
    p.add_argument(
        "--rest-fraction",
        type=float,
        default=0.01,
        help="at rest once |θ| stays below this fraction of |θ0| (default 0.01)",
    )
    p.add_argument(
        "--x-centre",
        type=float,
        default=None,
        metavar="X",
        help="abscissa of the upright block's centre on the span (m; default midspan)",
    )
    p.set_defaults(func=run)

    c = sub.add_parser(
        "nscd-convergence",
        help="convergence studies of the paper 002 simulation, with verdicts",
        description="Refine the time step or the mesh, compare successive levels and flag "
        "non-convergence (paper 002, Figs 10-11 and 16-19). With --study first-peak, "
        "BLOCK may be `all` (B4M, B6M, B8M).",
    )
    _common(c)
    c.add_argument(
        "--study",
        required=True,
        choices=("dt", "mesh", "first-peak", "flexibility"),
        help="dt: Fig 10; mesh: Fig 11; first-peak: B4M/B6M/B8M vs exact; flexibility: Figs 16-19",
    )
    c.add_argument(
        "--dts",
        type=float,
        nargs="+",
        default=None,
        metavar="DT",
        help="time steps, at least 2, distinct, one refinement ratio (default: 1e-3 "
        "1e-4 1e-5 1e-6; first-peak: 3 per decade, any spacing; flexibility: "
        "1e-4 1e-5 1e-6)",
    )
    c.add_argument(
        "--meshes",
        type=int,
        nargs="+",
        default=None,
        metavar="N",
        help="element counts, at least 2, distinct, one ratio (default: 3 6 12; "
        "flexibility: 6 12 24)",
    )
    c.add_argument(
        "--exponents",
        type=float,
        nargs="+",
        default=[8, 6, 4, 2, 0],
        metavar="N",
        help="flexibility study: E = Ē·10^N (default 8 6 4 2 0)",
    )
    c.add_argument(
        "--dt",
        type=float,
        default=None,
        help="time step of the mesh study (s; default 1e-5); flexibility: the base "
        "step, one of --dts (default the middle one)",
    )
    c.add_argument(
        "--elements",
        type=int,
        default=None,
        help="elements of the dt and first-peak studies (default 6); flexibility: "
        "the base mesh, one of --meshes (default the coarsest)",
    )
    c.add_argument(
        "--t-end", type=float, default=None, help="duration (s; default 4, first-peak: 2)"
    )
    c.set_defaults(func=run_convergence)


def _default(value, default):
    """`default` when the flag was not given (None); a given 0 stays 0 and is refused later."""
    return default if value is None else value


def _safe(name: str) -> str:
    """A file-name stem from a specimen name (a path or odd characters become '_')."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", str(name)).strip("._") or "block"


def _budget(args) -> float | None:
    if args.max_hours is None:
        return None
    return number(
        "--max-hours",
        args.max_hours,
        low=0.0,
        low_open=True,
        allow_inf=True,
        what="the longest run allowed, in hours",
    )


def _modulus(args, block=None):
    """E in Pa from --E or --flex; --flex is range-checked before 10**N is computed."""
    if args.flex is None:
        return args.E
    import multimass.engines.nscd as nscd
    from multimass.engines.nscd import model

    n = model.check_exponent(args.flex, block or args.block, args.beam, "--flex")
    return nscd.flexible_modulus(block or args.block, args.beam) * 10.0**n


def _theta0(args, block=None):
    """θ0 in rad from --theta0-deg (checked against the block's α, in degrees) or the block's."""
    from multimass.engines.nscd import model

    blk = model.load_block(block or args.block)
    if args.theta0_deg is None:
        if blk.reference.theta0_deg is None:
            raise InputError(
                f"`--theta0-deg` is required: block {blk.name!r} has no reference release angle"
            )
        return math.radians(blk.reference.theta0_deg)
    deg = number("--theta0-deg", args.theta0_deg, what="the release angle in degrees")
    alpha = math.degrees(blk.alpha)
    if abs(deg) >= alpha:
        raise InputError(
            f"`--theta0-deg` = {args.theta0_deg!r}: beyond the overturning angle "
            f"α = {alpha:.3f}° of {blk.name}: the block would not rest on its "
            f"corner; give |θ0| < {alpha:.3f}°"
        )
    return math.radians(deg)


def _references(block, theta0):
    from multimass.engines.nscd import convergence, model

    blk = model.load_block(block)
    return {
        "exact_rigid_first_peak_deg": math.degrees(convergence.housner_first_peak(blk, theta0)),
        "paper_first_peak_deg": blk.reference.first_peak_deg,
        "paper_rest_time_s": blk.reference.rest_time_s,
    }


def _write_series(res, path: Path) -> None:
    import numpy as np

    cols = np.column_stack(
        [res.t, res.theta, res.thetadot, res.X, res.Y, res.v_mid, res.energy, res.n_contacts]
    )
    np.savetxt(
        path,
        cols,
        delimiter=",",
        fmt="%.10g",
        header="t_s,theta_rad,thetadot_rad_per_s,X_m,Y_m,v_mid_m,energy_J,n_contacts",
        comments="",
    )


def _inputs(args):
    """Validated inputs and options of one run, and its cost checked against the budget."""
    from multimass.engines.nscd.model import check_inputs
    from multimass.engines.nscd.run import check_run, estimate_cost
    from multimass.progress import budget_seconds

    theta0 = _theta0(args)
    kw = dict(
        theta0=theta0,
        dt=args.dt,
        E=_modulus(args),
        n_elements=args.elements,
        theta_method=args.theta_method,
        mu=args.mu,
        restitution=args.restitution,
        x_centre=args.x_centre,
    )
    inp = check_inputs(args.block, args.beam, names=NAMES, **kw)
    o = check_run(
        args.t_end,
        inp.dt,
        gs_tol=args.gs_tol,
        gs_max_iter=args.gs_max_iter,
        rest_fraction=args.rest_fraction,
        names=NAMES,
    )
    estimate_cost(inp.n_elements, inp.dt, o.t_end, o.stride).check(
        f"nscd {inp.block.name} (--dt {inp.dt:g}, --t-end {o.t_end:g}, {inp.n_elements} elements)",
        "raise --dt, shorten --t-end or use fewer --elements",
        max_seconds=budget_seconds(_budget(args)),
    )
    return kw, theta0


def _status_lines(name, res) -> list[str]:
    head = f"{name}: {res.status}"
    if res.status == "inaccurate":
        head += f" (the run {res.outcome}, but an accuracy check failed)"
    return [f"{head} ({res.message})"] + [f"  warning: {w}" for w in res.warnings]


def _exit(statuses) -> int:
    """0 when every run is trustworthy, 1 when one failed or is inaccurate."""
    return 0 if all(s in _NORMAL for s in statuses) else 1


def run(args) -> int:
    import multimass.engines.nscd as nscd
    from multimass.engines.nscd.plots import plot_history

    kw, theta0 = _inputs(args)
    out = output_folder(args.out)
    res = nscd.simulate(
        args.block,
        args.beam,
        t_end=args.t_end,
        gs_tol=args.gs_tol,
        gs_max_iter=args.gs_max_iter,
        rest_fraction=args.rest_fraction,
        max_hours=_budget(args),
        progress=args.progress,
        **kw,
    )
    info = {**res.summary(), **_references(args.block, theta0)}
    if out is not None:
        stem = f"nscd_{_safe(res.params['block'])}"
        (out / f"{stem}.json").write_text(json.dumps(info, indent=2))
        _write_series(res, out / f"{stem}_series.csv")
        plot_history(
            res,
            out / f"{stem}.png",
            exact_first_peak_deg=info["exact_rigid_first_peak_deg"],
            paper_first_peak_deg=info["paper_first_peak_deg"],
            paper_rest_time_s=info["paper_rest_time_s"],
        )
    if args.json:
        print(json.dumps(info, indent=2))
        return _exit([res.status])
    fp = None if res.first_peak is None else math.degrees(res.first_peak)  # display: degrees
    rest = "still rocking" if res.rest_time is None else f"{res.rest_time:.3f} s"
    print("\n".join(_status_lines(res.params["block"], res)))
    print(
        f"  first peak {'-' if fp is None else f'{fp:.4f}'}° (paper {info['paper_first_peak_deg']}°, "
        f"rigid block with Housner η {info['exact_rigid_first_peak_deg']:.4f}°); "
        f"{len(res.peaks)} half-cycles (the release's included); rest {rest}"
    )
    print(
        f"  {res.n_steps} steps, {res.cost_per_step_us:.2f} µs/step, wall {res.wall_time_s:.2f} s "
        f"(estimated {res.estimated_s:.2g} s); Gauss–Seidel max {res.max_gs_iterations} "
        f"iterations, cap hit {res.n_gs_cap_hits} times; sliding steps {res.n_slip_steps}; "
        f"max energy increase {res.max_energy_increase:.2e} J"
    )
    if out is not None:
        print(f"  written to {out}/")
    return _exit([res.status])


def _print_study(st) -> None:
    print(f"{st.block} {st.kind} study {list(st.levels)}: {st.status.upper()}")
    for v in st.verdicts:
        diffs = ", ".join("inf" if not math.isfinite(d) else f"{d:.3g}" for d in v.differences)
        order = ", ".join("-" if o is None else f"{o:.2f}" for o in v.observed_order)
        print(
            f"  {v.measure:<15} differences [{diffs}] {v.unit} (tol {v.tolerance:g}) "
            f"order [{order}] -> {v.status}: {v.reason}"
        )
    for w in st.warnings:
        print(f"  warning: {w}")


def _first_peak(args, C, plots, out, common):
    if args.flex is not None:
        raise InputError(
            "`--flex` does not apply to the first-peak study (Ē differs per "
            "block); give `--E` in Pa or leave the rigid base"
        )
    blocks = ("B4M", "B6M", "B8M") if args.block.lower() == "all" else (args.block,)
    fps = C.first_peak_study(
        blocks,
        args.dts,
        t_end=_default(args.t_end, 2.0),
        E=args.E,
        n_elements=_default(args.elements, 6),
        **common,
    )
    if not args.json:
        for b in fps.blocks:
            peak, order = fps.peaks_deg[b][-1], fps.fitted_order[b]
            print(
                f"{b}: exact {fps.exact_deg[b]:.4f}°, paper {fps.paper_deg[b]}°; first peak at "
                f"dt = {fps.dts[-1]:g}: {'-' if peak is None else f'{peak:.4f}°'}; observed "
                f"order {'-' if order is None else f'{order:.2f}'} (least squares), per decade "
                + ", ".join("-" if o is None else f"{o:.2f}" for o in fps.successive_order[b])
            )
        for w in fps.warnings:
            print(f"  warning: {w}")
    statuses = ["inaccurate"] if fps.warnings else []
    return fps.to_dict(), [plots.plot_first_peak(fps, out / "first_peak_convergence.png")], statuses


def _refinement(args, C, plots, out, common):
    th0, E = _theta0(args), _modulus(args)
    if args.study == "dt":
        st = C.dt_study(
            args.block,
            _default(args.dts, (1e-3, 1e-4, 1e-5, 1e-6)),
            E=E,
            n_elements=_default(args.elements, 6),
            t_end=_default(args.t_end, 4.0),
            theta0=th0,
            **common,
        )
        title = f"{st.block}: time-step study (paper 002, Fig 10)"
    else:
        st = C.mesh_study(
            args.block,
            _default(args.meshes, (3, 6, 12)),
            dt=_default(args.dt, 1e-5),
            E=E,
            t_end=_default(args.t_end, 4.0),
            theta0=th0,
            **common,
        )
        title = f"{st.block}: mesh study (paper 002, Fig 11)"
    if not args.json:
        _print_study(st)
    fig = plots.plot_study(st, out / f"{args.study}_study_{_safe(st.block)}.png", title)
    return st.to_dict(), [fig], [r.status for r in st.runs]


def _flexibility(args, C, plots, out, common):
    if args.E is not None or args.flex is not None:
        raise InputError(
            "`--E`/`--flex` do not apply to the flexibility study; "
            "use `--exponents` to choose E = Ē·10^N"
        )
    flex = C.flexibility_study(
        args.block,
        tuple(args.exponents),
        meshes=tuple(_default(args.meshes, (6, 12, 24))),
        dts=tuple(_default(args.dts, (1e-4, 1e-5, 1e-6))),
        base_dt=args.dt,
        base_mesh=args.elements,
        t_end=_default(args.t_end, 4.0),
        theta0=_theta0(args),
        **common,
    )
    info = {
        "block": flex["block"],
        "E_bar_Pa": flex["E_bar"],
        "rigid": flex["rigid"].summary(),
        "mesh": {str(n): st.to_dict() for n, st in flex["mesh"].items()},
        "dt": {str(n): st.to_dict() for n, st in flex["dt"].items()},
        "status": {
            str(n): {"mesh": flex["mesh"][n].status, "dt": flex["dt"][n].status}
            for n in flex["exponents"]
        },
    }
    if not args.json:
        print(f"{flex['block']}: Ē = {flex['E_bar']:.4g} Pa (L/2500 under the block)")
        for line in _status_lines("beam's own E", flex["rigid"])[1:]:
            print(line)
        for n in flex["exponents"]:
            for kind in ("mesh", "dt"):
                print(f"E = Ē·10^{n:g}:", end=" ")
                _print_study(flex[kind][n])
    statuses = [flex["rigid"].status] + [
        r.status for kind in ("mesh", "dt") for st in flex[kind].values() for r in st.runs
    ]
    return info, plots.plot_flexibility(flex, out), statuses


def run_convergence(args) -> int:
    import multimass.engines.nscd.convergence as C
    from multimass.engines.nscd import plots

    say = (lambda m: None) if args.json else (lambda m: print("  " + m, flush=True))
    common = {
        "report": say,
        "progress": args.progress,
        "max_hours": _budget(args),
        "names": NAMES,
        "beam": args.beam,
        "theta_method": args.theta_method,
        "mu": args.mu,
        "restitution": args.restitution,
        "gs_tol": args.gs_tol,
        "gs_max_iter": args.gs_max_iter,
    }
    study = {
        "first-peak": _first_peak,
        "dt": _refinement,
        "mesh": _refinement,
        "flexibility": _flexibility,
    }[args.study]
    target = Path(args.out or "nscd_convergence")
    created = not target.exists()
    out = output_folder(target)
    try:
        info, figs, statuses = study(args, C, plots, out, common)
    except InputError:
        if created and not any(out.iterdir()):  # refused before computing: leave no trace
            out.rmdir()
        raise
    name = f"convergence_{args.study}_{_safe(args.block)}.json"
    info["figures"] = [str(f) for f in figs]
    (out / name).write_text(json.dumps(info, indent=2, default=_jsonable))
    if args.json:
        print(json.dumps(info, indent=2, default=_jsonable))
    else:
        print(f"written to {out}/ ({name} and {len(figs)} figure(s))")
    return _exit(statuses)


def _jsonable(x):
    try:
        x = float(x)
    except (TypeError, ValueError):
        return str(x)
    return x if math.isfinite(x) else None
