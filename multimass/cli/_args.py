"""Argument groups shared by the simulation commands (excitation, impact, solver)."""

from __future__ import annotations

from ..errors import InputError
from ..inputs.excitations import PULSE_NAMES, FreeRelease, MPShape, plausible_amplitude, pulse
from ..inputs.records import read_record
from ..inputs.units import parse_acceleration
from ..simulation import DEFAULTS
from . import _types as types

__all__ = [
    "add_excitation_args",
    "excitation_from_args",
    "add_impact_args",
    "impact_kwargs",
    "add_solver_args",
    "solver_kwargs",
    "PULSES",
    "add_mp_args",
    "pulse_from_args",
]

PULSES = PULSE_NAMES


def add_excitation_args(p, *, release=True) -> None:
    g = p.add_argument_group("excitation (one of: release, pulse, record)")
    if release:
        g.add_argument(
            "--release",
            type=types.finite,
            default=None,
            metavar="THETA0",
            help="free release from θ0 (rad); θ0 > 0 leans on the right pivot",
        )
        g.add_argument(
            "--release-u",
            type=types.finite,
            default=None,
            metavar="U0",
            help="free release with the top node displaced by U0 (m), static shape",
        )
    g.add_argument(
        "--pulse",
        choices=PULSES,
        default=None,
        help="sine, cosine: single waves (paper 004 Fig 2; paper 001's cosine pulse is "
        "the same acceleration, see multimass.CosinePulse); ricker: Ricker wavelet; mp: "
        "Mavroeidis-Papageorgiou near-fault pulse (--amp its peak acceleration, --omega 2π f_p)",
    )
    add_mp_args(g)
    g.add_argument(
        "--omega", type=types.positive, default=None, help="pulse circular frequency (rad/s)"
    )
    g.add_argument(
        "--amp", default=None, help="pulse amplitude, e.g. 0.4g, 3.5m/s2 (default unit g)"
    )
    g.add_argument(
        "--record",
        default=None,
        metavar="FILE",
        help="recorded motion: PEER .AT2 or two-column text file (t, a)",
    )
    g.add_argument(
        "--units", default=None, help="units of a two-column record: g, m/s2, cm/s2, mm/s2"
    )
    g.add_argument("--scale", type=types.positive, default=1.0, help="scale factor of the record")


def add_mp_args(g) -> None:
    """--gamma and --nu: the shape of an M&P pulse (`multimass.MPShape`)."""
    g.add_argument(
        "--gamma",
        type=types.finite,
        default=2.0,
        help="γ > 1 of an mp pulse: its window lasts γ/f_p (default 2; M&P 2003)",
    )
    g.add_argument(
        "--nu",
        type=types.finite,
        default=0.0,
        help="phase ν of an mp pulse, rad (default 0: symmetric velocity pulse)",
    )


def pulse_from_args(args):
    """The pulse of --pulse: its name, or for ``mp`` the `MPShape` of --gamma/--nu.

    Raises
    ------
    InputError
        For --gamma or --nu given with another pulse (they would be ignored).
    """
    try:
        shape = MPShape(gamma=args.gamma, nu=args.nu)  # validates them
    except InputError as exc:  # named as the user typed them
        text = str(exc).replace("`gamma`", "`--gamma`").replace("`nu`", "`--nu`")
        raise InputError(text.replace("gamma=2.0", "--gamma 2")) from None
    if args.pulse == "mp":
        return shape
    if shape != MPShape():
        raise InputError("`--gamma` and `--nu` shape an M&P pulse: add `--pulse mp`")
    return args.pulse


def excitation_from_args(args, structure):
    """The excitation the arguments describe; exactly one kind must be given."""
    kinds = [
        k
        for k, v in (
            (
                "--release",
                getattr(args, "release", None) is not None
                or getattr(args, "release_u", None) is not None,
            ),
            ("--pulse", args.pulse is not None),
            ("--record", args.record is not None),
        )
        if v
    ]
    if len(kinds) != 1:
        raise InputError(
            "give exactly one excitation: --release THETA0, --pulse KIND --omega W "
            f"--amp A, or --record FILE (got {', '.join(kinds) or 'none'})"
        )
    if kinds[0] == "--release":
        return FreeRelease(theta0=args.release or 0.0, u0=args.release_u)
    if kinds[0] == "--pulse":
        if args.omega is None or args.amp is None:
            raise InputError("`--pulse` needs --omega (rad/s) and --amp (e.g. 0.4g)")
        amp = plausible_amplitude("--amp", parse_acceleration(args.amp, "g", argument="--amp"))
        family = pulse_from_args(args)
        if isinstance(family, MPShape):
            return family(amplitude=amp, omega=args.omega)
        kind = getattr(getattr(structure, "specimen", None), "kind", "column")
        return pulse(family, amplitude=amp, omega=args.omega, structure_kind=kind)
    return read_record(args.record, units=args.units, scale=args.scale)


def add_impact_args(p, *, multiple: bool = False, default: str | None = "DD2") -> None:
    g = p.add_argument_group("impact model")
    if multiple:  # several models overlaid (e.g. `multimass compare`): a list, default ["DD2"]
        g.add_argument(
            "--impact",
            action="append",
            default=None,
            metavar="MODEL[,MODEL...]",
            help="CIM, DD1..DD5 (paper 001 Table 2) or DD; repeat the flag or give a "
            "comma list to overlay several models (default DD2)",
        )
    else:
        g.add_argument(
            "--impact",
            default=default,
            help="CIM, DD1..DD5 (paper 001 Table 2) or DD (default "
            f"{default or 'DD2 for pulses, DD5 for records'}; blocks: CIM is usual)",
        )
    g.add_argument(
        "--restitution",
        default=None,
        help="housner | modified | mean | random | r_h | VALUE (overrides Table 2)",
    )
    g.add_argument(
        "--k",
        type=types.unit_interval,
        default=None,
        help="k of the modified restitution (paper 004 Eq 10), in [0, 1]",
    )
    g.add_argument(
        "--cp", type=types.positive, default=None, help="C_p of the Dirac-delta model (kg m/rad/s)"
    )
    g.add_argument(
        "--eps-p",
        type=types.unit_interval,
        default=None,
        help="Poisson's coefficient of --impact LCP (paper 000; default 0)",
    )
    g.add_argument(
        "--seed",
        type=types.whole,
        default=None,
        help="seed (a whole number ≥ 0) of random restitution (DD5)",
    )


def impact_kwargs(args) -> dict:
    return dict(
        impact=args.impact,
        restitution=args.restitution,
        k=args.k,
        C_p=args.cp,
        eps_p=getattr(args, "eps_p", None),
        seed=args.seed,
    )


def add_solver_args(p) -> None:
    g = p.add_argument_group("solver (scipy.integrate.solve_ivp, or its compiled twin)")
    g.add_argument(
        "--method",
        default=None,
        help="RK23, RK45, DOP853, Radau, BDF or LSODA, or with --backend compiled "
        "exponential (the rocking phases of a column); `multimass spectrum` also takes auto "
        "(chosen for the column from its stiffness and a sample run timed and checked each "
        f"way; multimass.sweeps.method_choice). Default {DEFAULTS['method']}; a column's "
        "spectrum on the compiled path: auto",
    )
    g.add_argument(
        "--rtol",
        type=types.positive,
        default=DEFAULTS["rtol"],
        help=f"relative tolerance of the solver (default {DEFAULTS['rtol']:g})",
    )
    g.add_argument(
        "--atol",
        type=types.positive,
        default=DEFAULTS["atol"],
        help=f"absolute tolerance of the solver, in rad and m (default {DEFAULTS['atol']:g})",
    )
    g.add_argument(
        "--max-step",
        type=types.positive_or_inf,
        default=DEFAULTS["max_step"],
        help=f"longest solver step (s; default {DEFAULTS['max_step']:g}; inf for none)",
    )
    g.add_argument(
        "--output-dt",
        type=types.positive,
        default=DEFAULTS["output_dt"],
        help=f"sampling of the series (s; default {DEFAULTS['output_dt']:g})",
    )
    g.add_argument(
        "--backend",
        choices=("scipy", "compiled"),
        default=None,
        help="scipy: solve_ivp (the reference); compiled: the same explicit RK steps in "
        "numba kernels (multimass.engines.fast). Default: the function's own (scipy for "
        "one simulation)",
    )
    g.add_argument(
        "--full-contact",
        choices=("auto", "exact", "integrate"),
        default=None,
        help="how --backend compiled advances a column's full contact: exact (closed "
        "form between a record's samples or in free vibration), integrate (the RK "
        "steps), auto (the default: exact where it applies)",
    )
    g.add_argument(
        "--energy-tol",
        type=types.positive,
        default=DEFAULTS["energy_tol"],
        help="accuracy check: a run whose energy ledger is off by more than this "
        "share of its energy scale is reported 'inaccurate' "
        f"(default {DEFAULTS['energy_tol']:g})",
    )
    g.add_argument(
        "--max-hours",
        type=types.positive_or_inf,
        default=None,
        help="budget: refuse a run estimated to take longer (default 1; inf for none)",
    )


def solver_kwargs(args) -> dict:
    kw = dict(
        rtol=args.rtol,
        atol=args.atol,
        max_step=args.max_step,
        output_dt=args.output_dt,
        energy_tol=args.energy_tol,
    )
    if args.method is not None:  # else the function's own default
        kw["method"] = args.method
    if getattr(args, "backend", None) is not None:
        kw["backend"] = args.backend
    if getattr(args, "full_contact", None) is not None:
        kw["full_contact"] = args.full_contact
    if getattr(args, "max_hours", None) is not None:
        kw["max_hours"] = args.max_hours
    return kw
