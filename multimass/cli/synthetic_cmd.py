"""``multimass synthetic``: a synthetic test trace with a known truth, from the shell.

`multimass.identify.synthetic_trace` simulates a test and records it as a data logger
would (restitution drawn per impact, anti-alias filter and sampling, clock offset,
sensor bias and noise); this command writes the trace CSV (with its ``# specimen:``
line and nothing of the truth) and the truth beside it (``NAME.truth.json``,
`multimass.identify.read_truth`), so that ``multimass restitution``, ``identify``,
``calibrate`` and ``compare`` can be tried on a trace whose answer is known.
"""

from __future__ import annotations

import argparse
import json
import math
import re
from pathlib import Path

from ..errors import InputError
from . import _types as types
from ._args import add_excitation_args, excitation_from_args
from ._output import output_file

__all__ = ["register", "DEFAULTS"]

#: Defaults of the recording options: those of `multimass.identify.synthetic_trace`
#: (a test checks that they agree), shown in the help without importing it.
DEFAULTS = {
    "impact": "DD2",
    "t_end": 10.0,
    "fs": 200.0,
    "noise": 0.02,
    "bias": 0.005,
    "t_offset": 0.012,
    "passband": 0.4,
    "oversample": 40,
}

# argument of synthetic_trace -> the flag that sets it, for its error messages
_FLAGS = {
    "t_end": "--duration",
    "fs": "--fs",
    "noise": "--noise",
    "bias": "--bias",
    "t_offset": "--t-offset",
    "passband": "--passband",
    "oversample": "--oversample",
    "sensors": "--sensors",
    "restitution_means": "--r-means",
    "restitution_spread": "--sigma-r",
    "C_p": "--cp",
    "impact": "--impact",
    "seed": "--seed",
    "excitation": "--release/--pulse/--record",
    "rtol": "--rtol",
    "atol": "--atol",
}


def _between(low: float, high: float, whole: bool = False):
    """An argparse type: a number (a whole number if `whole`) in [low, high]."""
    rule = f"a {'whole number' if whole else 'number'} in [{low:g}, {high:g}]"

    def check(text: str):
        try:
            x = int(text) if whole else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be {rule}, got {text!r}") from None
        if not low <= x <= high:  # NaN fails too
            raise argparse.ArgumentTypeError(f"must be {rule}, got {text!r}")
        return x

    return check


def register(sub) -> None:
    p = sub.add_parser(
        "synthetic",
        help="a synthetic test trace with a known truth (sidecar file), for trying identification",
        description="Simulate a test of a specimen and record it as a data logger would "
        "(multimass.identify.synthetic_trace): each impact's coefficient of restitution "
        "drawn about the corner means, the response filtered (anti-alias) and sampled at "
        "--fs on a clock offset by --t-offset, a constant bias and white noise added to "
        "each channel. Writes the trace CSV (θ in rad, accelerations in g, the table "
        "motion as ag; a `# specimen:` line and nothing of the truth) and the truth "
        "beside it (NAME.truth.json: impacts, drawn r, peaks, noise, bias, offset). "
        "The same arguments and --seed write the same file.",
    )
    p.add_argument("specimen", metavar="SPECIMEN", help="bundled name (S1, S2, S3) or TOML file")
    add_excitation_args(p)
    g = p.add_argument_group("impact model and restitution drawn")
    g.add_argument(
        "--impact",
        default=DEFAULTS["impact"],
        help="CIM, DD1..DD5 or DD (paper 001 Table 2; default DD2); its restitution is "
        "replaced by the drawn one",
    )
    g.add_argument(
        "--cp",
        type=types.positive,
        default=None,
        help="C_p of a Dirac-delta model (kg m/rad/s; default Table 2's)",
    )
    g.add_argument(
        "--r-means",
        default=None,
        metavar="R_ER,R_EL",
        help="corner means of the drawn restitution, right and left, each in (0, 1] "
        "(default the specimen's, paper 001 Table 1)",
    )
    g.add_argument(
        "--sigma-r",
        type=_between(0.0, 0.5),
        default=None,
        help="standard deviation of the drawn coefficients, in [0, 0.5] (default the "
        "specimen's σ_r; 0: the means at every impact)",
    )
    g.add_argument(
        "--seed",
        type=types.whole,
        required=True,
        help="seed (a whole number ≥ 0) of every draw: restitution, bias, noise",
    )
    r = p.add_argument_group("recording")
    r.add_argument(
        "--duration",
        "--t-end",
        dest="t_end",
        metavar="SECONDS",
        type=types.positive,
        default=DEFAULTS["t_end"],
        help=f"end of the test (s, simulation clock; default {DEFAULTS['t_end']:g})",
    )
    r.add_argument(
        "--fs",
        type=types.positive,
        default=DEFAULTS["fs"],
        help=f"sampling rate (Hz; default {DEFAULTS['fs']:g})",
    )
    r.add_argument(
        "--noise",
        type=types.unit_interval,
        default=DEFAULTS["noise"],
        help="standard deviation of the white noise, a fraction of each channel's peak "
        f"in [0, 1] (default {DEFAULTS['noise']:g})",
    )
    r.add_argument(
        "--bias",
        type=types.unit_interval,
        default=DEFAULTS["bias"],
        help="each channel's constant bias is drawn in ± this fraction of its peak, in "
        f"[0, 1] (default {DEFAULTS['bias']:g})",
    )
    r.add_argument(
        "--t-offset",
        type=types.finite,
        default=DEFAULTS["t_offset"],
        help="trace time of the simulation's t = 0 (s): > 0 records the column still "
        f"before the release (default {DEFAULTS['t_offset']:g})",
    )
    r.add_argument(
        "--sensors",
        default=None,
        metavar="LIST",
        help="accelerometers recorded: comma-separated sensor names (A2,A4) or 1-based "
        "nodes (3,5) (default every named sensor of the specimen)",
    )
    r.add_argument(
        "--passband",
        type=_between(0.1, 0.45),
        default=DEFAULTS["passband"],
        help="end of the anti-alias filter's flat band, a fraction of --fs in [0.1, 0.45] "
        f"(default {DEFAULTS['passband']:g})",
    )
    r.add_argument(
        "--oversample",
        type=_between(4, 1000, whole=True),
        default=DEFAULTS["oversample"],
        help="simulated rate as a multiple of --fs, in [4, 1000] (default "
        f"{DEFAULTS['oversample']})",
    )
    s = p.add_argument_group("solver")
    s.add_argument(
        "--method",
        choices=("RK23", "RK45", "DOP853", "Radau", "BDF", "LSODA"),
        default=None,
        help="solve_ivp's method (default DOP853)",
    )
    s.add_argument("--rtol", type=types.positive, default=None, help="relative tolerance")
    s.add_argument("--atol", type=types.positive, default=None, help="absolute tolerance")
    s.add_argument(
        "--backend",
        choices=("scipy", "compiled"),
        default=None,
        help="default: compiled where its kernels know the model and the excitation",
    )
    p.add_argument(
        "--out",
        type=Path,
        required=True,
        metavar="TRACE.csv",
        help="the trace file to write; the truth goes beside it as TRACE.truth.json",
    )
    p.add_argument("--force", action="store_true", help="replace existing files")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(func=run)


def _pair(text: str | None) -> tuple[float, float] | None:
    """``--r-means 0.93,0.87`` → (0.93, 0.87), each in (0, 1]."""
    if text is None:
        return None
    items = text.split(",")
    try:
        pair = tuple(float(x) for x in items)
    except ValueError:
        pair = ()
    if len(pair) != 2 or not all(0.0 < r <= 1.0 for r in pair):
        raise InputError(
            f"`--r-means` = {text!r}: give the corner means r̄_er,r̄_el, two numbers in "
            "(0, 1], e.g. 0.93,0.87"
        )
    return pair


def _sensors(text: str | None) -> list | None:
    """``A2,A4`` → ["A2", "A4"]; ``3,5`` → [3, 5]."""
    if text is None:
        return None
    items = [x.strip() for x in text.split(",")]
    if not all(re.fullmatch(r"[A-Za-z0-9_]+", x) for x in items):
        raise InputError(
            f"`--sensors` = {text!r}: give a comma-separated list of sensor names or "
            "node numbers, e.g. A2,A4 or 3,5"
        )
    return [int(x) if x.isdigit() else x for x in items]


# names also written bare in the messages (words that are not English ones)
_BARE = ("t_end", "t_offset", "oversample", "restitution_means", "restitution_spread")
# fixes written for Python callers, as a user of the command writes them
_FIXES = {
    "give sensors=None": "leave out --sensors",
    "restitution_means=(r_right, r_left)": "--r-means R_ER,R_EL",
    ", DD or a Classical / DiracDelta object": " or DD",
    ", DD, LCP, or an ImpactModel object": " or DD",
}


def _with_flags(message: str) -> str:
    """A message of `synthetic_trace` with its argument names replaced by the flags."""
    for python, shell in _FIXES.items():
        message = message.replace(python, shell)
    for name, flag in _FLAGS.items():
        message = re.sub(rf"`{name}(\[[^`]*\])?`", f"`{flag}`", message)
        if name in _BARE:  # a bare name in the fix: "raise t_end or t_offset"
            message = re.sub(rf"(?<![\w`-]){name}\b", flag, message)
    return message


def run(args) -> int:
    from multimass.identify.synthetic import synthetic_trace, truth_path
    from multimass.model.structure import from_specimen

    st = from_specimen(args.specimen)
    exc = excitation_from_args(args, st)
    out = output_file(args.out, force=args.force, companions=lambda p: [truth_path(p)])
    if args.record is not None and Path(args.record).resolve() == out.resolve():
        raise InputError(f"`--out` = {str(out)!r} is the --record file; give another name")
    options = {
        k: getattr(args, k)
        for k in ("method", "rtol", "atol", "backend")
        if getattr(args, k) is not None
    }
    try:
        syn = synthetic_trace(
            st,
            exc,
            args.impact,
            args.t_end,
            seed=args.seed,
            fs=args.fs,
            noise=args.noise,
            bias=args.bias,
            t_offset=args.t_offset,
            sensors=_sensors(args.sensors),
            restitution_means=_pair(args.r_means),
            restitution_spread=args.sigma_r,
            C_p=args.cp,
            passband=args.passband,
            oversample=args.oversample,
            **options,
        )
    except InputError as err:
        raise InputError(_with_flags(str(err))) from None
    trace_file, truth_file = syn.write(out)
    info = summary(syn, trace_file, truth_file)
    if args.json:
        print(json.dumps(info, indent=1))
    else:
        print("\n".join(_text(info)))
    return 0 if info["status"] == "completed" else 1


def summary(syn, trace_file: Path, truth_file: Path) -> dict:
    """The JSON summary of a written synthetic trace (SI units, rad)."""
    truth, trace = syn.truth, syn.trace
    theta = syn.clean.channels["theta"]
    k = int(abs(theta).argmax())
    return {
        "trace_file": str(trace_file),
        "truth_file": str(truth_file),
        "specimen": truth["specimen"],
        "impact": truth["impact"]["name"],
        "seed": truth["seed"],
        "excitation": truth["excitation"],
        "n_samples": int(trace.time.size),
        "fs_hz": truth["sampling"]["fs_hz"],
        "t_start": float(trace.time[0]),
        "t_end": float(trace.time[-1]),
        "t_offset": truth["t_offset"],
        "channels": dict(trace.units),
        "n_impacts": len(truth["impacts"]),
        "peak_theta_rad": float(abs(theta[k])),
        "t_peak_theta_s": float(syn.clean.time[k]),
        "r_means_drawn_about": truth["restitution"]["means"],
        "sigma_r_drawn": truth["restitution"]["spread"],
        "r_mean_right": truth["r_mean_right"],
        "r_mean_left": truth["r_mean_left"],
        "sigma_r": truth["sigma_r"],
        "noise": truth["noise"]["fraction_of_peak"],
        "bias": truth["bias"]["fraction_of_peak"],
        "status": truth["simulation"]["status"],
        "warnings": truth["simulation"]["warnings"],
    }


_UNITS = {"amplitude": " m/s²", "pga": " m/s²", "omega": " rad/s", "theta0": " rad"}


def _excitation(d) -> str:
    """One phrase for an excitation's description."""
    if not isinstance(d, dict):
        return str(d)
    if d.get("kind") == "free_release":
        text = f"free release from θ0 = {d['theta0']:g} rad"
        return text + (f", u0 = {d['u0']:g} m" if d.get("u0") is not None else "")
    skip = ("kind", "duration", "source", "npts", "dt", "t_start")
    items = [
        f"{k} {v:.4g}{_UNITS.get(k, '')}" if isinstance(v, float) else f"{k} {v}"
        for k, v in d.items()
        if k not in skip and v is not None
    ]
    return f"{str(d.get('kind', 'excitation')).replace('_', ' ')} ({', '.join(items)})"


def _text(info: dict) -> list[str]:
    """The lines printed without --json: the two files and a one-paragraph summary."""
    channels = ", ".join(f"{k} [{u}]" for k, u in info["channels"].items())
    means = info["r_means_drawn_about"]
    peak = info["peak_theta_rad"]
    n = info["n_impacts"]
    bias = "" if info["bias"] is None else f", bias up to {100 * info['bias']:g} %"
    lines = [
        f"wrote the trace {info['trace_file']} ({info['n_samples']} samples at "
        f"{info['fs_hz']:g} Hz, {info['t_start']:g}–{info['t_end']:.6g} s; {channels})",
        f"wrote its truth {info['truth_file']} (keep it away from the identification)",
        f"{info['specimen']}, {_excitation(info['excitation'])}, {info['impact']}, seed "
        f"{info['seed']}: {n} impact{'' if n == 1 else 's'} in the trace, restitution "
        f"drawn about r̄_er = {means['right']:.4g}, r̄_el = {means['left']:.4g} "
        f"(σ {info['sigma_r_drawn']:.4g}); peak |θ| = {peak:.5g} rad "
        f"({math.degrees(peak):.4g}°) at t = {info['t_peak_theta_s']:.4g} s; noise "
        f"{100 * info['noise']:g} % of each channel's peak{bias}; the simulation's t = 0 "
        f"is at {info['t_offset']:g} s on the trace's clock.",
    ]
    if n == 0:
        lines.append(
            "warning: no impact in the trace: the column did not rock; raise --release, "
            "--amp or the record's --scale"
        )
    lines += [f"warning: {w}" for w in info["warnings"]]
    if info["status"] != "completed":
        lines.append(f"the simulation is {info['status']}: do not trust the truth file")
    return lines
