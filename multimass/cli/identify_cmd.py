"""``multimass identify``: operational modes of a test trace against the model.

Paper 001, Section 4.2 (Fig 5): the frequencies, damping and operational shapes of the
uplifted modes, identified half-cycle by half-cycle from the accelerations of a test,
compared (MAC) with the model's compound shapes; and the full-contact modes from the
stretches at rest (`multimass.identify.modes.operational_modes`). ``--out`` writes a
Markdown report, a figure, the JSON and the shapes as CSV files that
``multimass modal SPECIMEN --measured FILE`` reads.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from ..errors import InputError
from . import _types as types
from ._output import output_folder

__all__ = ["register"]


def register(sub) -> None:
    p = sub.add_parser(
        "identify",
        help="operational modes (frequency, damping, shapes) of a test trace vs the model",
        description="Cut a recorded trace (CSV with units in the header) into rocking "
        "half-cycles and full-contact stretches, remove the rigid-body acceleration of "
        "rocking, identify each mode's frequency, damping and operational shape at the "
        "sensors, and compare them with the model's uplifted compound shapes and "
        "full-contact shapes (MAC; paper 001 Fig 5). Modes above 0.4 × the sampling rate "
        "are reported as not identifiable.",
    )
    p.add_argument(
        "trace", type=Path, metavar="TRACE.csv",
        help="recorded trace with theta and the sensors' accelerations (a_<sensor>)",
    )  # fmt: skip
    p.add_argument(
        "--specimen",
        default=None,
        help="bundled name (S1, S2, S3) or TOML file; default: the trace's `# specimen:` line",
    )
    p.add_argument(
        "--method",
        choices=("fit", "fft"),
        default="fit",
        help="fit: damped sinusoids by least squares (default, the more accurate); "
        "fft: spectral peaks (paper 001's way)",
    )
    p.add_argument(
        "--phase",
        choices=("both", "rocking", "full_contact"),
        default="both",
        help="which phase to identify (default both; each must be in the trace)",
    )
    p.add_argument(
        "--modes", default=None, metavar="LIST",
        help="comma-separated model mode numbers (default: every mode below 0.4 fs)",
    )  # fmt: skip
    p.add_argument(
        "--sensors", default=None, metavar="LIST",
        help="comma-separated sensor names or node numbers (default: every named sensor)",
    )  # fmt: skip
    p.add_argument(
        "--theta-min",
        type=types.positive,
        default=0.01,
        help="half-cycles with a smaller peak (rad) are not used (default 0.01, paper 001)",
    )
    p.add_argument(
        "--min-periods",
        type=types.positive,
        default=2.0,
        help="shortest half-cycle used, in periods of the lowest mode asked (default 2)",
    )
    p.add_argument("--out", type=Path, default=None, help="folder for report, figure, CSV")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.set_defaults(func=run)


def _items(text: str | None, flag: str, pattern: str, example: str) -> list[str] | None:
    if text is None:
        return None
    items = [x.strip() for x in text.split(",")]
    if not all(re.fullmatch(pattern, x) for x in items):
        raise InputError(f"`{flag}` = {text!r}: give a comma-separated list, e.g. {example}")
    return items


def _line(pm) -> list[str]:
    name = "rocking (compound shapes)" if pm.phase == "rocking" else "full contact"
    out = [f"{name}:"]
    for k, j in enumerate(pm.mode):
        out.append(
            f"  mode {j}: {pm.with_spread(k)} Hz "
            f"(model {pm.model_freq_hz[k]:.3f}, {100 * (pm.freq_hz[k] / pm.model_freq_hz[k] - 1):+.2f} %)"
            f", ζ {100 * pm.damping[k]:.2f} % (model {100 * pm.model_damping[k]:.2f} %), "
            f"MAC {pm.mac[k]:.4f}, {pm.n_segments[k]} segment(s)"
        )
    out += [f"  mode {j}: not identified: {why}" for j, why in sorted(pm.not_identified.items())]
    return out


def run(args) -> int:
    from multimass.identify.modes import operational_modes
    from multimass.identify.modes_report import write_modes_report
    from multimass.structure import from_specimen
    from multimass.traces import read_trace

    out = output_folder(args.out)
    modes = _items(args.modes, "--modes", r"[0-9]+", "1,2")
    sensors = _items(args.sensors, "--sensors", r"[A-Za-z0-9_]+", "A1,A2,A4 or 2,3,5")
    trace = read_trace(args.trace)
    name = args.specimen or trace.specimen
    st = from_specimen(name) if name else None
    if st is not None and st.g != trace.g:
        trace = read_trace(args.trace, g=st.g)
    result = operational_modes(
        trace,
        st,
        method=args.method,
        phases=("rocking", "full_contact") if args.phase == "both" else (args.phase,),
        modes=None if modes is None else [int(x) for x in modes],
        sensors=None if sensors is None else [int(x) if x.isdigit() else x for x in sensors],
        theta_min=args.theta_min,
        min_periods=args.min_periods,
    )
    info = result.to_dict()
    if out is not None:
        files = write_modes_report(result, out, f"{args.trace.stem}_modes")
        info["files"] = sorted(p.name for p in files.values())
    if args.json:
        print(json.dumps(info, indent=1))
        return 0
    print(
        f"{result.structure.name}: operational modes of {trace.source} ({result.method}, "
        f"{result.fs:g} Hz, sensors {', '.join(result.sensors)})"
    )
    for pm in result.phases():
        print("\n".join(_line(pm)))
    print(
        "estimated from the accelerations alone (no model fitted): frequencies, damping, "
        "shapes; not used: C_p, restitution; fixed by the specimen file: the model's modes "
        "compared with (geometry, masses, stiffnesses) and its damping shown beside"
    )
    for w in result.warnings:
        print(f"warning: {w}")
    if out is not None:
        print(f"wrote {', '.join(info['files'])} in {out}")
    return 0
