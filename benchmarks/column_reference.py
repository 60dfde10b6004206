"""The compiled column runs against DOP853 at rtol 1e-12: right-hand sides and errors.

Run:  python benchmarks/column_reference.py dump OUT.pkl [--quick]
      python benchmarks/column_reference.py compare RUNS.pkl [REFERENCE.pkl]

``dump`` runs, with the package that Python imports (so the same file serves another
checkout: ``PYTHONPATH=/path/to/other/checkout python benchmarks/column_reference.py
dump …``), each run twice on the compiled path (`multimass.simulate_outcome`,
``backend="compiled"``): with the default options (DOP853, rtol 1e-8, atol 1e-10,
max_step 5 ms) and with rtol 1e-12, atol 1e-14 (the reference of
`benchmarks.exponential_rocking`), and stores per run the status, θ_max, the
half-cycles' peaks, the events (kind, time) and the right-hand sides. The runs:

* the cases of `benchmarks.exponential_rocking`: S1, S2, S3 of paper 001 released from
  0.11 rad (DD2, 10 s) and under El Centro 1940 NS (DD5, seed 3, 20 s);
* the spectrum of `benchmarks.column_spectrum` with 5 repeats: S1 under the README's
  15 s of El Centro and 5 s of free rocking, 17 scales 0.4–2.0 × 5 repeats with DD5,
  the draws of ``record_spectrum(..., repeats=5, seed=0)`` (`job_seeds(0, 85)`);
  ``--quick``: its first 2 scales. ``--ref-atol``: the reference's atol (1e-14).

``--specimen uniform20`` (or S2, S3) runs the spectrum on that column instead of S1
(`multimass.bench.scaling.uniform_column`: a uniform 20-node column like S1),
``--method`` gives the default runs a method (``exponential``; the reference stays
DOP853 at rtol 1e-12), ``--no-cases`` leaves out the six cases above.

``compare`` prints, as JSON, the errors of the default runs of RUNS against the
rtol 1e-12 runs of REFERENCE (RUNS' own if not given): per case the RHS counts,
|θ_max − reference|, the largest peak and impact-time differences (when both have as
many); over the spectrum the largest |θ_max − reference|, the runs whose sequence of
events (kinds, in order) is the reference's, and the largest θ_max and event-time
differences among them and among the others.
"""

from __future__ import annotations

import argparse
import json
import pickle
import sys
from pathlib import Path

import numpy as np

__all__ = ["main", "dump", "compare"]

ROOT = Path(__file__).resolve().parents[1]
ELCENTRO = ROOT.parent / "shared" / "data" / "ground_motions" / "elcentro_1940_NS.dat"
RECORD_15S = ROOT / "examples" / "data" / "elcentro_1940_NS_15s.dat"
SCALES = np.linspace(0.4, 2.0, 17)
REPEATS = 5
REF = dict(rtol=1e-12, atol=1e-14)


def _summary(r) -> dict:
    return dict(
        status=r.status,
        theta_max=float(r.theta_max),
        peaks=np.asarray(r.peaks, dtype=float),
        events=[(e.kind, float(e.time)) for e in r.events],
        n_rhs=int(r.n_rhs),
    )


def _runs(quick: bool, specimen: str = "S1", cases: bool = True) -> list[tuple]:
    """(name, structure, excitation, impact, t_end, seed) of every run."""
    import multimass
    from multimass import FreeRelease
    from multimass.bench.scaling import uniform_column
    from multimass.sweeps.seeding import job_seeds

    rec = multimass.read_record(str(ELCENTRO), units="g")
    out = []
    for name in ("S1", "S2", "S3") if cases else ():
        st = multimass.column(name)
        out.append((f"{name} release DD2", st, FreeRelease(0.11), "DD2", 10.0, None))
        out.append((f"{name} El Centro DD5", st, rec, "DD5", 20.0, 3))
    short = multimass.read_record(str(RECORD_15S), units="g")
    st = uniform_column(20) if specimen == "uniform20" else multimass.column(specimen)
    grid = [(s, k) for s in SCALES for k in range(REPEATS)]
    seeds = job_seeds(0, len(grid))
    for (s, k), sd in list(zip(grid, seeds))[: 2 * REPEATS if quick else None]:
        name = f"spectrum {s:.2f} #{k}"
        out.append((name, st, short.scaled(float(s)), "DD5", short.duration + 5.0, int(sd)))
    return out


def dump(
    path: str,
    quick: bool = False,
    ref_atol: float = REF["atol"],
    method: str | None = None,
    specimen: str = "S1",
    cases: bool = True,
) -> None:
    """Run every run with the default options (and `method` if given) and against DOP853 at
    rtol 1e-12 (atol `ref_atol`); pickle them."""
    import multimass
    from multimass import simulate_outcome

    out = {"multimass": str(Path(multimass.__file__).parent), "ref_atol": ref_atol, "runs": {}}
    out["method"], out["specimen"] = method or "default", specimen
    how = {"method": method} if method else {}
    for name, st, exc, impact, t_end, seed in _runs(quick, specimen, cases):
        kw = dict(backend="compiled", output_dt=None, progress=False, seed=seed)
        out["runs"][name] = {
            "run": _summary(simulate_outcome(st, exc, impact, t_end, **kw, **how)),
            "ref": _summary(
                simulate_outcome(st, exc, impact, t_end, **kw, **(REF | {"atol": ref_atol}))
            ),
        }
        print(name, file=sys.stderr)
    with open(path, "wb") as f:
        pickle.dump(out, f)


def _pair(a: np.ndarray, b: np.ndarray) -> float | None:
    return float(np.abs(a - b).max()) if a.size == b.size and a.size else None


def compare(runs: dict, refs: dict) -> dict:
    """Errors of `runs`' default runs against `refs`' rtol 1e-12 runs (module docstring)."""
    cases, spectrum = {}, []
    for name, got in runs["runs"].items():
        r, ref = got["run"], refs["runs"][name]["ref"]
        kinds = lambda x: [k for k, _ in x["events"]]
        times = lambda x: np.array([t for _, t in x["events"]])
        imp = lambda x: np.array([t for k, t in x["events"] if k == "impact"])
        row = dict(
            n_rhs=r["n_rhs"],
            status=(r["status"], ref["status"]),
            theta_max_error=abs(r["theta_max"] - ref["theta_max"]),
            peak_error=_pair(r["peaks"], ref["peaks"]),
            impact_time_error=_pair(imp(r), imp(ref)),
            same_events=kinds(r) == kinds(ref),
            event_time_error=_pair(times(r), times(ref)) if kinds(r) == kinds(ref) else None,
        )
        if name.startswith("spectrum"):
            spectrum.append(row)
        else:
            cases[name] = row
    same = [x for x in spectrum if x["same_events"]]
    part = [x for x in spectrum if not x["same_events"]]
    return {
        "runs": runs["multimass"],
        "reference": refs["multimass"],
        "reference_atol": refs.get("ref_atol"),
        "method": runs.get("method", "default"),
        "specimen": runs.get("specimen", "S1"),
        "cases": cases,
        "spectrum": dict(
            runs=len(spectrum),
            same_status=sum(x["status"][0] == x["status"][1] for x in spectrum),
            theta_max_error=max(x["theta_max_error"] for x in spectrum),
            same_events=len(same),
            theta_max_error_where_same=max((x["theta_max_error"] for x in same), default=None),
            event_time_error=max((x["event_time_error"] for x in same), default=None),
            theta_max_error_where_parted=max((x["theta_max_error"] for x in part), default=None),
            n_rhs=sum(x["n_rhs"] for x in spectrum),
        ),
    }


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    d = sub.add_parser("dump")
    d.add_argument("out")
    d.add_argument("--quick", action="store_true")
    d.add_argument("--ref-atol", type=float, default=REF["atol"], help="the reference's atol")
    d.add_argument("--method", help="the default runs' method (the reference: DOP853)")
    d.add_argument("--specimen", default="S1", choices=("S1", "S2", "S3", "uniform20"))
    d.add_argument("--no-cases", action="store_true", help="the spectrum only")
    c = sub.add_parser("compare")
    c.add_argument("runs")
    c.add_argument("reference", nargs="?")
    a = p.parse_args(argv)
    if a.cmd == "dump":
        dump(a.out, a.quick, a.ref_atol, a.method, a.specimen, not a.no_cases)
        return
    load = lambda path: pickle.load(open(path, "rb"))
    runs = load(a.runs)
    print(json.dumps(compare(runs, load(a.reference) if a.reference else runs), indent=1))


if __name__ == "__main__":
    main()
