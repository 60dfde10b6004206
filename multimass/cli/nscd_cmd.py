"""``multimass nscd`` and ``multimass nscd-convergence``: a rigid block rocking on a
finite-element beam by Moreau–Jean time stepping (paper 002)."""

from __future__ import annotations

import json
import math
from pathlib import Path

from ..errors import InputError

__all__ = ["register"]


def _common(p) -> None:
    p.add_argument("block", metavar="BLOCK", help="block specimen (B4M, B6M, B8M or a TOML file)")
    p.add_argument("--beam", default="beam_mudric2024",
                   help="beam specimen (default: paper 002's beam, beam_mudric2024)")
    p.add_argument("--theta0-deg", type=float, default=None,
                   help="release angle (deg; > 0 rests on the right corner; default: the block's "
                        "paper 002 value)")
    stiff = p.add_mutually_exclusive_group()
    stiff.add_argument("--E", type=float, default=None, metavar="PA",
                       help="Young's modulus of the beam (Pa; default: the beam's, 1e24 = rigid base)")
    stiff.add_argument("--flex", type=float, default=None, metavar="N",
                       help="E = Ē·10^N, Ē giving a midspan deflection L/2500 under the block")
    p.add_argument("--theta-method", type=float, default=1.0, metavar="THETA",
                   help="θ-method parameter in [0, 1] (paper 002: 1, backward Euler)")
    p.add_argument("--mu", type=float, default=None, help="friction coefficient (default: the beam's)")
    p.add_argument("--restitution", type=float, default=0.0, help="Newton's e (default 0, plastic)")
    p.add_argument("--gs-tol", type=float, default=1e-8, help="Gauss–Seidel relative tolerance")
    p.add_argument("--gs-max-iter", type=int, default=5000, help="Gauss–Seidel iteration cap")
    p.add_argument("--out", type=Path, default=None, help="folder for JSON, CSV and figures")
    p.add_argument("--json", action="store_true", help="print the result as JSON")


def register(sub) -> None:
    p = sub.add_parser(
        "nscd", help="Moreau–Jean simulation of a rigid block rocking on a beam (paper 002)",
        description="Free rocking of a rigid block released at rest on a simply supported FE "
                    "beam: θ-method, velocity Signorini + Coulomb, Gauss–Seidel (paper 002).")
    _common(p)
    p.add_argument("--dt", type=float, default=1e-5, help="time step (s; default 1e-5)")
    p.add_argument("--elements", type=int, default=None, help="number of beam elements (>= 3)")
    p.add_argument("--t-end", type=float, default=4.0, help="duration (s; default 4)")
    p.add_argument("--rest-fraction", type=float, default=0.01,
                   help="at rest once |θ| stays below this fraction of |θ0| (default 0.01)")
    p.add_argument("--x-centre", type=float, default=None, metavar="X",
                   help="abscissa of the upright block's centre on the span (m; default midspan)")
    p.set_defaults(func=run)

    c = sub.add_parser(
        "nscd-convergence", help="convergence studies of the paper 002 simulation, with verdicts",
        description="Refine the time step or the mesh, compare successive levels and flag "
                    "non-convergence (paper 002, Figs 10-11 and 16-19). With --study first-peak, "
                    "BLOCK may be `all` (B4M, B6M, B8M).")
    _common(c)
    c.add_argument("--study", required=True, choices=("dt", "mesh", "first-peak", "flexibility"),
                   help="dt: Fig 10; mesh: Fig 11; first-peak: B4M/B6M/B8M vs exact; "
                        "flexibility: Figs 16-19")
    c.add_argument("--dts", type=float, nargs="+", default=None, metavar="DT",
                   help="time steps (default: 1e-3 1e-4 1e-5 1e-6; first-peak: 3 per decade; "
                        "flexibility: 1e-4 1e-5 1e-6)")
    c.add_argument("--meshes", type=int, nargs="+", default=None, metavar="N",
                   help="element counts (default: 3 6 12; flexibility: 6 12 24)")
    c.add_argument("--exponents", type=float, nargs="+", default=[8, 6, 4, 2, 0], metavar="N",
                   help="flexibility study: E = Ē·10^N (default 8 6 4 2 0)")
    c.add_argument("--dt", type=float, default=1e-5, help="time step of the mesh study (s)")
    c.add_argument("--elements", type=int, default=6, help="elements of the dt study")
    c.add_argument("--t-end", type=float, default=None,
                   help="duration (s; default 4, first-peak: 2)")
    c.set_defaults(func=run_convergence)


def _modulus(args):
    if args.flex is None:
        return args.E
    import nscd
    return nscd.flexible_modulus(args.block, args.beam) * 10.0 ** args.flex


def _theta0(args):
    import nscd.model
    if args.theta0_deg is not None:
        return math.radians(args.theta0_deg)
    blk = nscd.model.load_block(args.block)
    if blk.reference.theta0_deg is None:
        raise InputError(f"`--theta0-deg` is required: block {blk.name!r} has no reference "
                         "release angle")
    return math.radians(blk.reference.theta0_deg)


def _references(block, theta0):
    import nscd.convergence
    import nscd.model
    blk = nscd.model.load_block(block)
    return {"exact_rigid_first_peak_deg": math.degrees(nscd.convergence.housner_first_peak(blk, theta0)),
            "paper_first_peak_deg": blk.reference.first_peak_deg,
            "paper_rest_time_s": blk.reference.rest_time_s}


def _write_series(res, path: Path) -> None:
    import numpy as np
    cols = np.column_stack([res.t, res.theta, res.theta_dot, res.X, res.Y, res.v_mid,
                            res.energy, res.n_contacts])
    np.savetxt(path, cols, delimiter=",", fmt="%.10g",
               header="t_s,theta_rad,theta_dot_rad_per_s,X_m,Y_m,v_mid_m,energy_J,n_contacts",
               comments="")


def run(args) -> int:
    import nscd
    from nscd.plots import plot_history

    theta0 = _theta0(args)
    res = nscd.simulate(args.block, args.beam, theta0=theta0, dt=args.dt, t_end=args.t_end,
                        E=_modulus(args), n_elements=args.elements,
                        theta_method=args.theta_method, mu=args.mu,
                        restitution=args.restitution, gs_tol=args.gs_tol,
                        gs_max_iter=args.gs_max_iter, rest_fraction=args.rest_fraction,
                        x_centre=args.x_centre)
    info = {**res.summary(), **_references(args.block, theta0)}
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        stem = f"nscd_{res.params['block']}"
        (args.out / f"{stem}.json").write_text(json.dumps(info, indent=2))
        _write_series(res, args.out / f"{stem}_series.csv")
        plot_history(res, args.out / f"{stem}.png",
                     exact_first_peak_deg=info["exact_rigid_first_peak_deg"],
                     paper_first_peak_deg=info["paper_first_peak_deg"],
                     paper_rest_time_s=info["paper_rest_time_s"])
    if args.json:
        print(json.dumps(info, indent=2))
        return 0
    fp = res.first_peak_deg
    rest = "still rocking" if res.rest_time_s is None else f"{res.rest_time_s:.3f} s"
    print(f"{res.params['block']}: {res.status} ({res.message})")
    print(f"  first peak {'-' if fp is None else f'{fp:.4f}'}° (paper {info['paper_first_peak_deg']}°, "
          f"rigid block with Housner η {info['exact_rigid_first_peak_deg']:.4f}°); "
          f"{len(res.peaks_deg)} half-cycles; rest {rest}")
    print(f"  {res.n_steps} steps, {res.cost_per_step_us:.2f} µs/step, wall {res.wall_time_s:.2f} s; "
          f"Gauss–Seidel max {res.max_gs_iterations} iterations, cap hit {res.n_gs_cap_hits} times; "
          f"sliding steps {res.n_slip_steps}; max energy increase {res.max_energy_increase_J:.2e} J")
    if args.out is not None:
        print(f"  written to {args.out}/")
    return 0


def _print_study(st) -> None:
    print(f"{st.block} {st.kind} study {list(st.levels)}: {st.status.upper()}")
    for v in st.verdicts:
        diffs = ", ".join("inf" if not math.isfinite(d) else f"{d:.3g}" for d in v.differences)
        order = ", ".join("-" if o is None else f"{o:.2f}" for o in v.observed_order)
        print(f"  {v.measure:<15} differences [{diffs}] {v.unit} (tol {v.tolerance:g}) "
              f"order [{order}] -> {v.status}: {v.reason}")


def run_convergence(args) -> int:
    import nscd.convergence as C
    from nscd import plots

    out = args.out or Path("nscd_convergence")
    t_end = args.t_end
    say = (lambda m: None) if args.json else (lambda m: print("  " + m, flush=True))
    common = {"beam": args.beam, "theta_method": args.theta_method, "mu": args.mu,
              "restitution": args.restitution, "gs_tol": args.gs_tol, "gs_max_iter": args.gs_max_iter}
    if args.study == "first-peak":
        if args.flex is not None:
            raise InputError("`--flex` does not apply to the first-peak study (Ē differs per "
                             "block); give `--E` in Pa or leave the rigid base")
        fps = C.first_peak_study((args.block,) if args.block.lower() != "all" else ("B4M", "B6M", "B8M"),
                                 args.dts, t_end=t_end or 2.0, E=args.E, n_elements=args.elements,
                                 progress=say)
        info = fps.to_dict()
        figs = [plots.plot_first_peak(fps, out / "first_peak_convergence.png")]
        if not args.json:
            for b in fps.blocks:
                print(f"{b}: exact {fps.exact_deg[b]:.4f}°, paper {fps.paper_deg[b]}°; "
                      f"first peak at dt = {fps.dts[-1]:g}: {fps.peaks_deg[b][-1]:.4f}°; "
                      f"observed order {fps.fitted_order[b]:.2f} (least squares), per decade "
                      + ", ".join("-" if o is None else f"{o:.2f}" for o in fps.successive_order[b]))
    elif args.study in ("dt", "mesh"):
        th0, E = _theta0(args), _modulus(args)
        if args.study == "dt":
            st = C.dt_study(args.block, args.dts or (1e-3, 1e-4, 1e-5, 1e-6), E=E,
                            n_elements=args.elements, t_end=t_end or 4.0, theta0=th0,
                            progress=say, **common)
            title = f"{st.block}: time-step study (paper 002, Fig 10)"
        else:
            st = C.mesh_study(args.block, args.meshes or (3, 6, 12), dt=args.dt, E=E,
                              t_end=t_end or 4.0, theta0=th0, progress=say, **common)
            title = f"{st.block}: mesh study (paper 002, Fig 11)"
        info = st.to_dict()
        figs = [plots.plot_study(st, out / f"{args.study}_study_{st.block}.png", title)]
        if not args.json:
            _print_study(st)
    else:
        if args.E is not None or args.flex is not None:
            raise InputError("`--E`/`--flex` do not apply to the flexibility study; "
                             "use `--exponents` to choose E = Ē·10^N")
        flex = C.flexibility_study(args.block, tuple(args.exponents),
                                   meshes=tuple(args.meshes or (6, 12, 24)),
                                   dts=tuple(args.dts or (1e-4, 1e-5, 1e-6)), base_dt=args.dt,
                                   base_mesh=args.elements, t_end=t_end or 4.0,
                                   theta0=_theta0(args), progress=say, **common)
        info = {"block": flex["block"], "E_bar_Pa": flex["E_bar"],
                "rigid": flex["rigid"].summary(),
                "mesh": {str(n): st.to_dict() for n, st in flex["mesh"].items()},
                "dt": {str(n): st.to_dict() for n, st in flex["dt"].items()},
                "status": {str(n): {"mesh": flex["mesh"][n].status, "dt": flex["dt"][n].status}
                           for n in flex["exponents"]}}
        figs = plots.plot_flexibility(flex, out)
        if not args.json:
            print(f"{flex['block']}: Ē = {flex['E_bar']:.4g} Pa (L/2500 under the block)")
            for n in flex["exponents"]:
                for kind in ("mesh", "dt"):
                    print(f"E = Ē·10^{n:g}:", end=" ")
                    _print_study(flex[kind][n])
    out.mkdir(parents=True, exist_ok=True)
    name = f"convergence_{args.study}_{args.block}.json"
    info["figures"] = [str(f) for f in figs]
    (out / name).write_text(json.dumps(info, indent=2, default=_jsonable))
    if args.json:
        print(json.dumps(info, indent=2, default=_jsonable))
    else:
        print(f"written to {out}/ ({name} and {len(figs)} figure(s))")
    return 0


def _jsonable(x):
    try:
        return float(x)
    except (TypeError, ValueError):
        return str(x)
