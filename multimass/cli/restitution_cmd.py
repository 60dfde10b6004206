"""``multimass restitution``: each impact's coefficient of restitution from a test trace.

Paper 001, Section 4.3: the impact-specific r_e of CIM, DD1, DD3 and DD4 (Table 2)
and the corner means r̄_er, r̄_el, σ_r come from the tests. This command estimates
them from a recorded trace two ways (`multimass.identify.restitution`) and writes
a specimen fragment (``[restitution]`` table) and a full specimen file that
`multimass simulate` then uses.
"""

from __future__ import annotations

import json
from pathlib import Path

from . import _types as types
from ._output import output_folder

__all__ = ["register"]


def register(sub) -> None:
    p = sub.add_parser(
        "restitution",
        help="impact-specific coefficients of restitution from a test trace (paper 001, Sec 4.3)",
        description="Find the impacts of a recorded trace (CSV with units in the header), "
        "estimate each impact's coefficient of restitution from the peaks around it "
        "(the paper's energy estimate) and by fitting the chosen impact model, half-cycle "
        "by half-cycle, to θ and the accelerations (the best estimate), and report the "
        "corner means and σ_r. C_p and the damping ratios not given (--cp, --zeta1, "
        "--zeta2) are estimated from the trace too, and the result says which were given, "
        "estimated or fixed by the specimen file. "
        "--out writes a table, a figure, the [restitution] fragment and a specimen file "
        "with it.",
    )
    p.add_argument(
        "trace", type=Path, metavar="TRACE.csv",
        help="recorded trace with a theta column (free release, or table motion as ag)",
    )  # fmt: skip
    p.add_argument(
        "--specimen",
        default=None,
        help="bundled name (S1, S2, S3) or TOML file; default: the trace's `# specimen:` line",
    )
    p.add_argument(
        "--impact", default="DD",
        help="impact model the coefficients are for: DD (default), CIM, DD1, DD2, DD3, DD4",
    )  # fmt: skip
    p.add_argument(
        "--theta-min",
        type=types.positive,
        default=0.01,
        help="impacts between half-cycles of at least this peak (rad) are estimated "
        "(default 0.01, paper 001); smaller ones take the corner means",
    )
    p.add_argument(
        "--cp", type=types.positive, default=None,
        help="C_p of the Dirac-delta force, if known (default: estimated from the trace)",
    )  # fmt: skip
    p.add_argument(
        "--zeta1", type=types.positive, default=None,
        help="damping ratio of full-contact mode 1, if known (default: estimated)",
    )  # fmt: skip
    p.add_argument(
        "--zeta2", type=types.positive, default=None,
        help="damping ratio of full-contact mode 2, if known (default: estimated)",
    )  # fmt: skip
    p.add_argument("--out", type=Path, default=None, help="folder for table, figure, specimen")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.set_defaults(func=run)


_LABELS = {"r_mean_right": "r̄_er", "r_mean_left": "r̄_el", "sigma_r": "σ_r"}


def _value(x) -> str:
    return "not estimated" if x is None else f"{x:.4f}"


def _interval(iv) -> str:
    """`` (95 %: lo … hi)`` of an interval, empty for None."""
    return "" if iv is None else f" (95 %: {iv[0]:.4f} … {iv[1]:.4f})"


def run(args) -> int:
    from multimass.identify._parameter_status import lines
    from multimass.identify.impacts import restitution
    from multimass.identify.impacts_plots import plot_restitution
    from multimass.inputs.traces import read_trace
    from multimass.model.structure import from_specimen

    out = output_folder(args.out)
    trace = read_trace(args.trace)
    name = args.specimen or trace.specimen
    st = from_specimen(name) if name else None
    if st is not None and abs(st.g - trace.g) > 0.0:
        trace = read_trace(args.trace, g=st.g)
    kw = {"C_p": args.cp} if args.cp is not None else {}
    est = restitution(
        trace, st, args.impact, theta_min=args.theta_min, zeta1=args.zeta1, zeta2=args.zeta2,
        **kw,
    )  # fmt: skip
    info = est.summary()
    if out is not None:
        stem = f"{est.structure.name}_restitution"
        est.impacts.to_csv(out / f"{stem}.csv", index=False)
        (out / f"{stem}.toml").write_text(est.fragment(), encoding="utf-8")
        fitted = f"{est.structure.name}_r_{est.impact}"
        (out / f"{fitted}.toml").write_text(
            est.specimen_text(name=fitted, path=name), encoding="utf-8"
        )
        plot_restitution(est, out / f"{stem}.png")
        (out / f"{stem}.json").write_text(json.dumps(info, indent=1) + "\n", encoding="utf-8")
        info["files"] = sorted(
            p.name for p in out.iterdir() if p.name.startswith(est.structure.name)
        )
    if args.json:
        print(json.dumps(info, indent=1))
        return 0
    df = est.impacts
    print(f"{est.structure.name}: {len(df)} impacts in {trace.source}; impact model {est.impact}")
    print(
        df[
            ["t", "corner", "r", "r_std", "r_energy", "theta_before", "theta_after", "estimated"]
        ].to_string(index=False, float_format=lambda x: f"{x:.4f}", na_rep="—")
    )  # r_std "—": an impact not fitted (its r is the energy estimate)
    e = est.energy_means
    print(
        f"r̄_er = {_value(est.r_mean_right)}, r̄_el = {_value(est.r_mean_left)}, "
        f"σ_r = {_value(est.sigma_r)}{_interval(est.sigma_r_interval)} (energy estimate: "
        f"{_value(e['r_mean_right'])}, "
        f"{_value(e['r_mean_left'])}, {_value(e['sigma_r'])})"
    )
    used = est.values_used()
    for key, why in est.not_estimated.items():
        print(
            f"not estimated: {_LABELS[key]} ({why}); the simulations use the specimen's "
            f"{used[key]:g}, marked as not estimated in the files written"
        )
    sd = {c: m["std"] for c, m in est.r_mean_std.items() if m}
    if sd:
        print(
            "std of the corner means (as the means of the impacts they average): "
            + ", ".join(f"{c} {x:.4f}" for c, x in sd.items())
        )
    print(f"status: {est.status} — {est.message}")
    shown = {k: p for k, p in est.parameters.items() if k not in ("structure", "sensor_bias")}
    for line in lines(shown):
        print(f"  {line}")
    print("  structure  fixed by the specimen file (geometry, masses, stiffnesses, sensors)")
    for w in est.warnings:
        print(f"warning: {w}")
    if out is not None:
        print(f"wrote {', '.join(info['files'])} in {out}")
    return 0
