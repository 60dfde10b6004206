"""``multimass calibrate``: fit a column's restitution means, C_p and damping to test traces.

The calibration loop of DESIGN.md: a researcher loads their recorded θ and
acceleration traces and calibrates restitution and C_p (paper 001, Section 4.3) —
`multimass.identify.calibrate`, with a report (`multimass.identify.calibration_report`).
"""

from __future__ import annotations

import json
from pathlib import Path

from ..errors import InputError
from . import _types as types
from ._output import output_folder

__all__ = ["register", "parse_pairs"]


def register(sub) -> None:
    p = sub.add_parser(
        "calibrate",
        help="fit restitution means, C_p and damping to recorded traces (θ, accelerations)",
        description="Calibrate a column model against one or more recorded traces (CSV with "
        "units in the header, `# specimen: NAME`): least squares of the simulated θ and "
        "sensor accelerations against the recorded ones, first on the rocking peaks, then "
        "on the time histories of the large half-cycles, with each trace's clock offset, "
        "θ bias, release angle and each impact's deviation from its corner mean fitted "
        "too. Writes figures before/after, residuals, a Markdown report, JSON and the "
        "fitted specimen TOML.",
    )
    p.add_argument(
        "traces", nargs="+", type=Path, metavar="TRACE.csv",
        help="recorded traces, fitted jointly; free vibration (no `ag` column) or table "
        "motion (`ag`)",
    )  # fmt: skip
    p.add_argument(
        "--specimen", default=None,
        help="bundled name (S1, ...) or TOML file; default: the traces' `# specimen:` line",
    )  # fmt: skip
    p.add_argument(
        "--impact", default="DD2",
        help="impact model of paper 001 Table 2: CIM, DD1..DD5, DD (default DD2)",
    )  # fmt: skip
    p.add_argument(
        "--fit", default=None, metavar="LIST",
        help="parameters to fit, comma list of r_er, r_el, cp, zeta1, zeta2 (default: "
        "every one not given; named, the others keep the specimen's values)",
    )  # fmt: skip
    p.add_argument(
        "--given", default=None, metavar="NAME=VALUE,...",
        help="parameters known, used as they are and not fitted, e.g. cp=2300,zeta1=0.005",
    )  # fmt: skip
    for flag, what in (("cp", "C_p of the Dirac-delta force"),
                       ("zeta1", "damping ratio of full-contact mode 1"),
                       ("zeta2", "damping ratio of full-contact mode 2")):  # fmt: skip
        p.add_argument(
            f"--{flag}", type=types.positive, default=None,
            help=f"{what}, if known (as --given {flag}=VALUE; default: fitted)",
        )  # fmt: skip
    p.add_argument(
        "--start", default=None, metavar="NAME=VALUE,...",
        help="start values, e.g. r_er=0.9,cp=1500 (default: the specimen's, Table 2's C_p)",
    )  # fmt: skip
    p.add_argument(
        "--bounds", default=None, metavar="NAME=LOW:HIGH,...",
        help="bounds replacing the defaults, e.g. cp=500:5000",
    )  # fmt: skip
    p.add_argument(
        "--channels", default=None, metavar="LIST",
        help="acceleration channels to fit (θ always is); default every sensor of the specimen",
    )  # fmt: skip
    p.add_argument(
        "--theta-min", type=types.positive, default=0.01,
        help="half-cycles with peaks at least this large (rad) form the window fitted "
        "(default 0.01, paper 001 Sec 4.3)",
    )  # fmt: skip
    p.add_argument(
        "--history", type=types.count, default=9,
        help="most large half-cycles of each trace whose time histories are fitted: 5, "
        "then more while the model still follows the test (default 9)",
    )  # fmt: skip
    p.add_argument(
        "--means-only", action="store_true",
        help="fit the corner means alone, without each impact's deviation",
    )  # fmt: skip
    p.add_argument(
        "--out", type=Path, default=None,
        help="folder for figures, report, JSON and the fitted TOML (default: "
        "calibration_report unless --json)",
    )  # fmt: skip
    p.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


def parse_pairs(text: str | None, flag: str, ranged: bool = False) -> dict:
    """``a=1,b=2`` → {"a": 1.0, "b": 2.0}; with `ranged`, ``a=1:2`` → {"a": (1.0, 2.0)}."""
    if text is None:
        return {}
    out = {}
    for item in (s.strip() for s in text.split(",") if s.strip()):
        key, sep, value = (s.strip() for s in item.partition("="))
        form = "NAME=LOW:HIGH" if ranged else "NAME=VALUE"
        if not sep or not key or not value:
            raise InputError(f"`{flag}` = {text!r}: cannot read {item!r}; write {form},...")
        try:
            if ranged:
                lo, colon, hi = value.partition(":")
                if not colon:
                    raise ValueError
                out[key] = (float(lo), float(hi))
            else:
                out[key] = float(value)
        except ValueError:
            raise InputError(
                f"`{flag}` = {text!r}: cannot read {value!r} for {key!r}; write {form},..."
            ) from None
    return out


def run(args) -> int:
    from multimass.identify.calibration import calibrate
    from multimass.identify.calibration_report import write_report

    channels = None
    if args.channels is not None:
        channels = [c.strip() for c in args.channels.split(",") if c.strip()]
    out = output_folder(
        args.out if args.out is not None or args.json else Path("calibration_report")
    )
    given = parse_pairs(args.given, "--given")
    for flag in ("cp", "zeta1", "zeta2"):
        value = getattr(args, flag)
        if value is not None:
            if flag in given and given[flag] != value:
                raise InputError(
                    f"`--{flag}` = {value:g} and `--given {flag}={given[flag]:g}` differ; give it once"
                )
            given[flag] = value
    cal = calibrate(
        list(args.traces),
        args.specimen,
        args.impact,
        fit=args.fit,
        given=given or None,
        start=parse_pairs(args.start, "--start") or None,
        bounds=parse_pairs(args.bounds, "--bounds", ranged=True) or None,
        channels=channels,
        per_impact=not args.means_only,
        theta_min=args.theta_min,
        history=args.history,
        progress=False if args.quiet else True,
    )
    files = [str(f) for f in write_report(cal, out, figures=not args.no_figures)] if out else []
    if args.json:
        summary = cal.summary()
        keep = ("specimen", "impact", "status", "message", "parameters", "fixed", "provenance",
                "nuisance", "residuals", "stages", "n_simulations", "wall_time_s",
                "warnings")  # fmt: skip
        data = {k: summary[k] for k in keep}
        data["features"] = {
            which: {
                label: {k: f[k] for k in ("rms_peak_error", "rms_impact_time_error",
                                          "missing_impacts")}
                for label, f in per.items()
            }
            for which, per in summary["features"].items()
        }  # fmt: skip
        data["files"] = files
        print(json.dumps(data, indent=1))
    else:
        _print(cal, files)
    return 1 if cal.status == "failed" else 0


def _print(cal, files) -> None:
    print(f"{cal.structure.name} ({cal.impact}): {cal.status} — {cal.message}")
    from multimass.identify._parameter_status import lines

    shown = {k: p for k, p in cal.provenance.items() if k != "structure"}
    for line in lines(shown):
        print(f"  {line}")
    print("  structure  fixed by the specimen file (geometry, masses, stiffnesses, sensors)")
    for label, n in cal.nuisance.items():
        t0 = "" if n["theta0"] is None else f", θ0 {n['theta0']:.5g} rad"
        print(f"  {label}: t_offset {n['t_offset']:.4f} s{t0}, θ bias {n['theta_bias']:.2g} rad")
    print(f"  {cal.n_simulations} simulations, {cal.wall_time_s:.1f} s")
    if files:
        print(f"files written to {Path(files[0]).parent}/")
