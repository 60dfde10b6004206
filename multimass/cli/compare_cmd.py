"""``multimass compare``: simulations overlaid on a recorded test trace, with error metrics.

The calibration loop of DESIGN.md: a researcher loads their recorded θ and
acceleration traces and overlays simulations with several impact models (paper 001,
Section 4.3, Figs 6-8: CIM against Dirac-delta, mean restitution, C_p varied).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..errors import InputError
from . import _types as types
from ._args import (
    add_excitation_args,
    add_impact_args,
    add_solver_args,
    excitation_from_args,
    solver_kwargs,
)
from ._output import output_folder

__all__ = ["register", "model_specs"]

# option key in MODEL:key=value → keyword of multimass.simulate
_KEYS = {
    "cp": "C_p",
    "c_p": "C_p",
    "restitution": "restitution",
    "r": "restitution",
    "k": "k",
    "seed": "seed",
}
_OPTIONS_HELP = (
    "write options as MODEL:key=value[:key=value] with key one of cp, restitution "
    "(or r), k, seed; e.g. DD2:cp=3000 or CIM:r=0.9"
)


def register(sub) -> None:
    p = sub.add_parser(
        "compare",
        help="overlay simulations on a recorded trace (θ, accelerations); error metrics",
        description="Read a recorded trace (CSV with units in the header: `t [s],theta [deg],"
        "a_A2 [g],...`), run the matching simulation with one or more impact models "
        "and write overlay plots and error metrics (RMS error, NRMSE, peak error, "
        "peak-time shift). Without an excitation flag the simulation is a free "
        "release from the trace's θ at its first sample, up to its last sample. "
        "Each --impact model may carry its own options, MODEL:key=value (keys cp, "
        "restitution or r, k, seed), e.g. --impact CIM,DD2,DD2:cp=3000 (paper 001 "
        "Fig 8). The specimen is SPECIMEN or --specimen if given, else the one the "
        "trace names in its `# specimen: NAME` line.",
    )
    p.add_argument(
        "specimen",
        nargs="?",
        default=None,
        metavar="SPECIMEN",
        help="bundled name (S1, B6M, ...) or TOML file; optional (as --specimen): "
        "default the trace's `# specimen:` line",
    )
    p.add_argument(
        "trace",
        type=Path,
        metavar="TRACE.csv",
        help="recorded trace; columns t|time [s|ms], theta [rad|deg], a_<sensor>, "
        "a<k> or a_node<k> [g|m/s2|cm/s2|mm/s2]; a comment line `# specimen: NAME` "
        "names its specimen",
    )
    p.add_argument(
        "--specimen",
        dest="specimen_option",
        default=None,
        metavar="NAME",
        help="the specimen, as the SPECIMEN argument (as in restitution, identify, calibrate)",
    )
    add_impact_args(p, multiple=True)
    add_excitation_args(p)
    add_solver_args(p)
    p.add_argument(
        "--t-end",
        type=types.positive,
        default=None,
        help="end of the simulation (s, on its own clock); default: the trace's last sample",
    )
    p.add_argument(
        "--t-offset",
        type=types.finite,
        default=None,
        help="trace time of the simulation's t = 0 (s); default: the trace's first "
        "time for a release, 0 for a pulse or a record",
    )
    p.add_argument(
        "--out",
        type=Path,
        default=None,
        help="folder for figures, metrics (CSV, Markdown) and JSON "
        "(default: compare_report unless --json)",
    )
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.set_defaults(func=run)
    _options_between_positionals(p)


def _options_between_positionals(parser) -> None:
    """Let options stand between SPECIMEN and TRACE.csv, as when SPECIMEN was required.

    ``multimass compare S1 --impact CIM trace.csv`` worked while both positionals were
    required; with SPECIMEN optional, argparse (of Python 3.11 at least) gives TRACE.csv
    an empty match at ``S1`` and rejects ``trace.csv`` as unrecognized. Parsing the options first and
    the positionals after them (argparse's `parse_known_intermixed_args`) keeps it working.
    """

    class Intermixed(type(parser)):
        _inner = False

        def parse_known_args(self, args=None, namespace=None):
            if self._inner:  # the two passes of parse_known_intermixed_args
                return super().parse_known_args(args, namespace)
            self._inner = True
            try:
                return self.parse_known_intermixed_args(args, namespace)
            finally:
                self._inner = False

    parser.__class__ = Intermixed


# per-model option -> the type of its flag (--cp, --k, --seed), so the same mistake gets
# the same message whether it is written --cp -1 or --impact DD2:cp=-1
_TYPES = {
    "cp": types.positive,
    "c_p": types.positive,
    "k": types.unit_interval,
    "seed": types.whole,
}


def _option(label: str, key: str, value: str):
    if key in ("restitution", "r"):
        return value
    try:
        return _TYPES[key](value)
    except argparse.ArgumentTypeError as err:
        raise InputError(f"`--impact` = {label!r}: {key} {err}") from None


def model_specs(args) -> dict[str, dict]:
    """Label → `multimass.simulate` impact keywords, one per requested model.

    ``--impact`` may be repeated or hold a comma list; each item is a model name
    (``CIM``, ``DD1``..``DD5``, ``DD``) with optional per-model overrides
    ``:cp=``, ``:restitution=`` (``:r=``), ``:k=``, ``:seed=`` that take precedence
    over ``--cp``, ``--restitution``, ``--k``, ``--seed``. Repeated labels collapse.
    """
    labels = [x.strip() for item in (args.impact or ["DD2"]) for x in item.split(",") if x.strip()]
    if not labels:
        raise InputError("`--impact` is empty: give one or more models, e.g. --impact CIM,DD2")
    base = dict(restitution=args.restitution, k=args.k, C_p=args.cp, seed=args.seed)
    specs = {}
    for label in labels:
        name, *opts = label.split(":")
        kw = dict(base, impact=name.strip())
        for opt in opts:
            key, sep, value = (s.strip() for s in opt.partition("="))
            if not sep or key.lower() not in _KEYS or not value:
                raise InputError(
                    f"`--impact` = {label!r}: cannot read option {opt!r}; {_OPTIONS_HELP}"
                )
            kw[_KEYS[key.lower()]] = _option(label, key.lower(), value)
        specs[label] = kw
    return specs


def _excitation(args, structure, trace):
    """(excitation, t_offset): a release from the trace's first θ unless a flag is given."""
    release = args.release is not None or args.release_u is not None
    if not (release or args.pulse is not None or args.record is not None):
        offset = float(trace.time[0]) if args.t_offset is None else args.t_offset
        return trace.free_release(), offset
    exc = excitation_from_args(args, structure)
    if args.t_offset is not None:
        return exc, args.t_offset
    return exc, float(trace.time[0]) if release else 0.0


def _specimen_and_trace(args):
    """(Structure, Trace): the specimen given (SPECIMEN or --specimen), else the trace's own.

    A specimen given that differs from the trace's ``# specimen:`` line is used, with a
    warning: comparing a trace with another model of its column (e.g. the TOML file
    that ``multimass restitution`` writes, named ``S1_r_DD``) is what the command is for.
    """
    from multimass.inputs.traces import read_trace
    from multimass.model.structure import from_specimen

    given = [x for x in (args.specimen, args.specimen_option) if x is not None]
    if len(given) == 2 and given[0].lower() != given[1].lower():
        raise InputError(
            f"the specimen is given twice, as SPECIMEN = {given[0]!r} and `--specimen` = "
            f"{given[1]!r}; give one"
        )
    if given:  # as before: the specimen first, then the trace in its g
        st = from_specimen(given[0])
        trace = read_trace(args.trace, g=st.g)
        if trace.specimen is not None and trace.specimen.lower() not in (
            st.name.lower(),
            str(given[0]).lower(),
        ):
            print(
                f"multimass compare: warning: {trace.source} says `# specimen: "
                f"{trace.specimen}`; comparing with {st.name} as given",
                file=sys.stderr,
            )
        return st, trace
    if args.specimen is None and not args.trace.exists() and not args.trace.suffix:
        raise InputError(
            f"TRACE.csv = {str(args.trace)!r}: no such file; to name the specimen, give "
            f"the trace after it: `multimass compare {args.trace} TRACE.csv`"
        )
    trace = read_trace(args.trace)
    if trace.specimen is None:
        raise InputError(
            f"{trace.source} has no `# specimen: NAME` line, so the specimen is unknown; "
            f"give it (`multimass compare SPECIMEN {args.trace}` or `--specimen NAME`) or "
            "add the line `# specimen: NAME` above the trace's header"
        )
    try:
        st = from_specimen(trace.specimen)
    except InputError as err:
        raise InputError(
            f"{trace.source} names its specimen `# specimen: {trace.specimen}`: {err}; or "
            "give the specimen's TOML file with --specimen FILE"
        ) from None
    if st.g != trace.g:
        trace = read_trace(args.trace, g=st.g)
    return st, trace


def run(args) -> int:
    import multimass
    from multimass.analysis.trace_metrics import channel_columns, compare_trace
    from multimass.impact_models import impact_model

    st, trace = _specimen_and_trace(args)
    columns = channel_columns(trace, st)  # fail before simulating
    specs = model_specs(args)
    for kw in specs.values():  # unknown names / options: fail early too
        impact_model(kw["impact"], st.specimen, kw["restitution"], kw["k"], kw["C_p"])
    exc, t_offset = _excitation(args, st, trace)
    out = output_folder(args.out if args.out is not None or args.json else Path("compare_report"))
    t_end = args.t_end if args.t_end is not None else float(trace.time[-1]) - t_offset
    if not t_end > 0.0:
        raise InputError(
            f"`--t-end` = {t_end!r} s: the simulation would not run; the trace ends "
            f"at {trace.time[-1]:g} s and `--t-offset` = {t_offset:g} s"
        )
    models, responses, metrics = {}, {}, {}
    for label, kw in specs.items():
        resp = multimass.simulate(st, exc, t_end=t_end, **kw, **solver_kwargs(args))
        entry = {
            "impact": kw["impact"],
            "overrides": {k: kw[k] for k in ("restitution", "k", "C_p", "seed")},
            "summary": resp.summary(),
            "metrics": None,
        }
        try:
            metrics[label] = compare_trace(trace, resp, st, t_offset=t_offset)
            entry["metrics"] = {ch: m.to_dict() for ch, m in metrics[label].items()}
            responses[label] = resp
        except InputError as err:  # e.g. failed at once: nothing to compare
            entry["metrics_error"] = str(err)
        models[label] = entry
    info = {
        "specimen": st.name,
        "trace": {
            "source": trace.source,
            "n_samples": int(trace.time.size),
            "t_start": float(trace.time[0]),
            "t_end": float(trace.time[-1]),
            "channels": {
                ch: {
                    "units": trace.units[ch],
                    "si_units": trace.si_units(ch),
                    "column": columns[ch],
                }
                for ch in trace.names
            },
        },
        "excitation": exc.describe(),
        "t_offset": t_offset,
        "t_end": t_end,
        "models": models,
        "files": [],
    }
    if out is not None:
        info["files"] = _write(out, st, trace, responses, metrics, t_offset, info)
    _print(args, info)
    return (
        1 if any(m["summary"]["status"] in ("failed", "inaccurate") for m in models.values()) else 0
    )


def _write(out: Path, st, trace, responses, metrics, t_offset, info) -> list[str]:
    from multimass.analysis.plots import plot_overlay

    stem = f"{st.name}_{Path(trace.source).stem}"
    files = []
    if responses:
        for ch in trace.names:
            per = {label: m[ch] for label, m in metrics.items()}
            path = plot_overlay(
                trace,
                ch,
                responses,
                st,
                out / f"{stem}_{ch}.png",
                t_offset=t_offset,
                metrics=per,
                title=f"{st.name}: {ch} measured ({Path(trace.source).name}) and simulated",
            )
            files.append(str(path))
    rows = [
        dict(model=label, status=info["models"][label]["summary"]["status"], **m.to_dict())
        for label, chans in metrics.items()
        for m in chans.values()
    ]
    if rows:
        import pandas as pd

        pd.DataFrame(rows).to_csv(out / f"{stem}_metrics.csv", index=False)
        files.append(str(out / f"{stem}_metrics.csv"))
    (out / f"{stem}_metrics.md").write_text(_markdown(st, trace, info, metrics))
    files.append(str(out / f"{stem}_metrics.md"))
    files.append(str(out / f"{stem}_compare.json"))
    info = dict(info, files=files)
    (out / f"{stem}_compare.json").write_text(json.dumps(info, indent=2, default=_jsonable))
    return files


def _jsonable(x):
    """JSON fallback: objects nested in a summary's options (e.g. a restitution source
    inside another one's description) are written as their description or their repr."""
    if hasattr(x, "describe"):
        return x.describe()
    if hasattr(x, "tolist"):  # numpy scalars and arrays
        return x.tolist()
    return repr(x)


def _fmt(x, spec=".4g") -> str:
    return "—" if x is None else format(x, spec)


def _markdown(st, trace, info, metrics) -> str:
    lines = [
        f"# {st.name} against {trace.source}",
        "",
        f"Excitation: `{json.dumps(info['excitation'])}`; simulated 0–{info['t_end']:g} s, "
        f"trace time = simulation time + {info['t_offset']:g} s.",
        "",
        "Metrics on the trace's samples in the overlap, SI units (rad, m/s²); RMS values are "
        "time-weighted (trapezoidal); NRMSE = RMS error / RMS measured; peak error = "
        "max|sim| − max|meas|; peak-time shift = t(max|sim|) − t(max|meas|).",
        "",
    ]
    for label, entry in info["models"].items():
        s = entry["summary"]
        lines.append(
            f"- **{label}**: {s['status']}, {s['n_impacts']} impacts, "
            f"{s['n_full_contact']} full-contact transitions, {s['wall_time_s']:.2f} s"
            + (f" — {entry['metrics_error']}" if "metrics_error" in entry else "")
        )
    for ch in trace.names:
        lines += [
            "",
            f"## {ch} (written in {trace.units[ch]}; metrics in {trace.si_units(ch)})",
            "",
            "| model | RMS error | NRMSE | peak measured | peak simulated | peak error | "
            "peak error (rel.) | peak-time shift (s) |",
            "|---|---|---|---|---|---|---|---|",
        ]
        for label, chans in metrics.items():
            m = chans[ch]
            lines.append(
                f"| {label} | {_fmt(m.rms_error)} | {_fmt(m.nrmse, '.2%')} | "
                f"{_fmt(m.peak_measured)} | {_fmt(m.peak_simulated)} | "
                f"{_fmt(m.peak_error, '+.4g')} | {_fmt(m.peak_error_rel, '+.2%')} | "
                f"{m.peak_time_shift_s:+.4f} |"
            )
    return "\n".join(lines) + "\n"


def _print(args, info) -> None:
    if args.json:
        print(json.dumps(info, indent=2, default=_jsonable))
        return
    for label, entry in info["models"].items():
        s = entry["summary"]
        print(
            f"{label}: {s['status']}, {s['n_impacts']} impacts, {s['wall_time_s']:.2f} s"
            + (f"\n  failed: {s['message']}" if s["status"] == "failed" else "")
            + "".join(f"\n  warning: {w}" for w in s.get("warnings", ()))
        )
        for ch, m in (entry["metrics"] or {}).items():
            nrmse = "—" if m["nrmse"] is None else f"{100 * m['nrmse']:.1f} %"
            print(
                f"  {ch:<8} RMS error {m['rms_error']:.4g} {m['units']} (NRMSE {nrmse}), "
                f"peak error {m['peak_error']:+.4g} {m['units']}, "
                f"peak-time shift {m['peak_time_shift_s']:+.4f} s"
            )
    if info["files"]:
        print(f"files written to {Path(info['files'][0]).parent}/")
