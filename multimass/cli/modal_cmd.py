"""``multimass modal``: modal analysis and report of one or more specimens."""

from __future__ import annotations

import json
import re
from pathlib import Path

from ..errors import InputError

__all__ = ["register"]


def register(sub) -> None:
    p = sub.add_parser(
        "modal",
        help="full-contact and uplifted modes, damping, MAC; Markdown report and figures",
        description="Foss state-space modal analysis of full contact and rocking (paper 001, "
        "Sections 3 and 4.2), with a report against the published values.",
    )
    p.add_argument(
        "specimens",
        nargs="+",
        metavar="SPECIMEN",
        help="bundled specimen name (see `multimass specimens`) or TOML file",
    )
    p.add_argument(
        "--out",
        type=Path,
        default=None,
        help="folder for the reports and figures (default: modal_report unless --json)",
    )
    p.add_argument(
        "--json", action="store_true", help="print a JSON array, one object per specimen"
    )
    p.add_argument(
        "--measured",
        type=Path,
        default=None,
        metavar="CSV",
        help="measured mode shapes (nodes x modes) for MAC; one specimen only",
    )
    p.add_argument(
        "--shape-nodes",
        default=None,
        metavar="LIST",
        help="comma-separated 1-based nodes for shapes (default: 2..N)",
    )
    p.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    frf = p.add_argument_group(
        "frequency response",
        "state-space FRFs from the ground acceleration to the sensors' total accelerations "
        "(multimass.modal.state_space), written as <name>_frf.png and added to the report",
    )
    frf.add_argument(
        "--frf",
        action="store_true",
        help="plot the FRFs (magnitude and phase) of full contact and rocking, modes marked",
    )
    frf.add_argument(
        "--trace",
        type=Path,
        default=None,
        metavar="CSV",
        help="a trace with the table motion (column `ag`) and `theta`: overlay its measured "
        "FRF, H1 over the full-contact segments; one specimen only; implies --frf",
    )
    frf.add_argument(
        "--frf-sensors",
        default=None,
        metavar="LIST",
        help="comma-separated sensor names (e.g. A2,A4) or node numbers drawn (default: the "
        "trace's acceleration channels with --trace, else the specimen's named sensors)",
    )
    frf.add_argument(
        "--theta-max",
        type=float,
        default=None,
        metavar="RAD",
        help="full contact where |theta| <= RAD (default 2e-4 rad) for at least 10 periods "
        "of the first full-contact mode",
    )
    frf.add_argument(
        "--nperseg",
        type=int,
        default=None,
        metavar="N",
        help="Welch window of the measured FRF in samples (default: the largest power of two "
        "within the shortest segment and a quarter of all full-contact samples)",
    )
    p.set_defaults(func=run)


def _comma_items(text: str, flag: str, pattern: str, what: str) -> list[str]:
    """The comma-separated items of `text`, each matching `pattern`, or one clear error."""
    items = [x.strip() for x in text.split(",")]
    if not all(re.fullmatch(pattern, x) for x in items):
        raise InputError(f"`{flag}` = {text!r}: give comma-separated {what}")
    return items


def _nodes(text: str | None):
    """Parse ``--shape-nodes 2,3,4``: integers separated by commas, nothing else."""
    if text is None:
        return None
    items = _comma_items(text, "--shape-nodes", r"[0-9]+", "integer node numbers, e.g. 2,3,4,5")
    return tuple(int(x) for x in items)


def _ranges(modes) -> str:
    """1, 3, 4, 5 -> "1, 3–5"."""
    out, run = [], []
    for j in list(modes) + [None]:
        if run and (j is None or j != run[-1] + 1):
            out.append(str(run[0]) if len(run) == 1 else f"{run[0]}–{run[-1]}")
            run = []
        if j is not None:
            run.append(j)
    return ", ".join(out)


def _first_modes(phase: dict, k: int = 3) -> str:
    """Frequencies of modes 1..k by mode number; an overdamped one is marked."""
    freq = dict(zip(phase["mode"], phase["freq_hz"]))
    od = dict(zip(phase["overdamped"]["mode"], phase["overdamped"]["freq_hz"]))
    return ", ".join(
        f"{freq[j]:.2f}" if j in freq else f"{od[j]:.2f} (overdamped)"
        for j in range(1, k + 1)
        if j in freq or j in od
    )


def _line(info: dict) -> str:
    text = (
        f"{info['specimen']}: full contact {_first_modes(info['full_contact'])} Hz; "
        f"uplifted {_first_modes(info['rocking'])} Hz; "
        f"rocking ±{info['rocking']['rocking_eigenvalues'][0]:.4f} rad/s"
    )
    od = [
        f"{name} {_ranges(info[key]['overdamped']['mode'])}"
        for name, key in (("full contact", "full_contact"), ("uplifted", "rocking"))
        if info[key]["overdamped"]["mode"]
    ]
    return text + (f"; overdamped modes: {'; '.join(od)}" if od else "")


def _sensor_list(text: str | None):
    """Parse ``--frf-sensors A2,A4`` or ``2,5``: names or node numbers, by commas."""
    if text is None:
        return None
    what = "sensor names or node numbers, e.g. A2,A4 or 3,5"
    items = _comma_items(text, "--frf-sensors", r"[A-Za-z0-9_]+", what)
    return [int(x) if x.isdigit() else x for x in items]


def _check_frf_args(args) -> None:
    """The FRF flags' combinations, each mistake one line."""
    frf = args.frf or args.trace is not None
    if not frf and args.frf_sensors is not None:
        raise InputError("`--frf-sensors` chooses the FRF figure's lines: add `--frf`")
    if args.trace is None and (args.theta_max is not None or args.nperseg is not None):
        raise InputError(
            "`--theta-max` and `--nperseg` shape the measured FRF: add `--trace CSV` "
            "(a trace with the table motion `ag`)"
        )
    if args.nperseg is not None and args.nperseg < 8:
        raise InputError(f"`--nperseg` = {args.nperseg}: give a window of 8 samples or more")
    if frf and args.no_figures:
        raise InputError("`--frf` draws a figure: drop `--no-figures`")
    if frf and args.json and args.out is None:
        raise InputError("`--frf` with `--json` writes a figure: give the folder with `--out DIR`")
    if args.trace is not None and len(args.specimens) != 1:
        raise InputError(
            f"`--trace` was given with {len(args.specimens)} specimens; a trace belongs to "
            "one specimen: run them one at a time"
        )
    if args.theta_max is not None and not (args.theta_max > 0 and args.theta_max < 1):
        raise InputError(
            f"`--theta-max` = {args.theta_max!r}: give |theta| in rad, > 0 and < 1 (e.g. 2e-4)"
        )


def _measured_frf(path: Path, structure, analysis, sensors, args):
    """The H1 estimate over a trace's full-contact segments, and the nodes to draw."""
    import numpy as np

    from multimass.modal import ModalError
    from multimass.modal.measured_frf import MIN_PERIODS, THETA_MAX, full_contact_h1
    from multimass.modal.validate import show

    from ..analysis.trace_metrics import channel_columns
    from ..inputs.traces import Trace, read_trace

    trace = read_trace(path)
    ag = getattr(trace, "ag", None)
    if ag is None:
        raise InputError(
            f"{trace.source}: no `ag` column; the measured FRF needs the table motion: add "
            "the ground acceleration as a column `ag [g]` (or m/s2)"
        )
    names = [k for k in trace.names if k.lower() not in ("theta", "ag")]
    theta = next((v for k, v in trace.channels.items() if k.lower() == "theta"), None)
    if theta is None or not names:
        missing = (
            "`theta [rad]` (full-contact segments are found from it)"
            if theta is None
            else ("an acceleration column such as `a_A4 [g]`")
        )
        raise InputError(f"{trace.source}: no {missing}; add it to the trace")
    accel = Trace(
        time=trace.time,
        channels={k: trace.channels[k] for k in names},
        units={k: trace.units[k] for k in names},
        source=trace.source,
        g=trace.g,
    )
    nodes = [int(c[1:]) for c in channel_columns(accel, structure).values()]
    if len(set(nodes)) != len(nodes):
        raise InputError(f"{trace.source}: two acceleration columns name the same node ({nodes})")
    if sensors is None:
        sensors = tuple(nodes)
    elif not set(sensors) & set(nodes):
        raise InputError(
            f"`--frf-sensors` = {show(list(sensors))}: none is recorded in {trace.source} "
            f"(its accelerations are at nodes {nodes})"
        )
    f1 = float(analysis.full_contact.undamped_omega.min()) / (2 * np.pi)
    try:
        est = full_contact_h1(
            trace.time,
            ag,
            np.array([accel.channels[k] for k in names]),
            theta,
            f1,
            theta_max=THETA_MAX if args.theta_max is None else args.theta_max,
            min_periods=MIN_PERIODS,
            nperseg=args.nperseg,
            outputs=[f"a{k}" for k in nodes],
        )
    except ModalError as err:
        raise ModalError(f"{trace.source}: {err}") from None
    return est, sensors


def run(args) -> int:
    import multimass.modal as modal
    from multimass.modal.measured import read_measured_shapes
    from multimass.modal.report import summary, write_report
    from multimass.modal.validate import validate_shape_nodes, validate_structure

    if args.measured is not None and len(args.specimens) != 1:
        raise InputError(
            f"`--measured` was given with {len(args.specimens)} specimens; "
            "measured shapes belong to one specimen: run them one at a time"
        )
    _check_frf_args(args)
    frf = args.frf or args.trace is not None
    measured = read_measured_shapes(args.measured) if args.measured is not None else None
    out = args.out if args.out is not None or args.json else Path("modal_report")
    results = []
    for name in args.specimens:
        structure = validate_structure(name)
        default = modal.default_shape_nodes(structure.n)
        nodes = validate_shape_nodes(
            _nodes(args.shape_nodes),
            structure.n,
            default,
            "--shape-nodes",
            "--shape-nodes " + ",".join(map(str, default[:3])),
        )
        analysis = modal.analyse(structure, nodes)
        measured_frf, sensors = None, None
        if args.frf_sensors is not None:
            sensors = modal.sensor_nodes(structure, _sensor_list(args.frf_sensors))
        if args.trace is not None:
            measured_frf, sensors = _measured_frf(args.trace, structure, analysis, sensors, args)
        if out is not None:
            info = write_report(
                analysis,
                out,
                measured,
                figures=not args.no_figures,
                frf=frf,
                frf_sensors=sensors,
                measured_frf=measured_frf,
                frf_source=str(args.trace) if args.trace is not None else None,
            )
        else:
            info = summary(analysis, measured)
        results.append(info)
    if args.json:
        print(json.dumps(results, indent=2))
    else:
        for info in results:
            print(_line(info))
            if "measured" in info.get("frf", {}):
                meas = info["frf"]["measured"]
                spans = meas["segments_s"]
                print(
                    f"{info['specimen']}: measured FRF from {meas['source']}: "
                    f"{len(spans)} full-contact segment(s), {sum(b - a for a, b in spans):.1f} s, "
                    f"Δf = {meas['df_hz']:.3g} Hz, {meas['n_averages']} averages"
                )
        print(f"reports written to {out}/")
    return 0
