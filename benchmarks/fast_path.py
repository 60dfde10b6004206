"""Speed and accuracy of the compiled backend against the solve_ivp reference (issue 7).

Run:  python -m benchmarks.fast_path [--repeat 3] [--calls 200] [--no-compile]
                                     [--work-precision]

Prints one JSON dict, every figure measured in this run:

* ``compile``: the one-off numba compilation, timed in a fresh process with an
  empty cache (``NUMBA_CACHE_DIR`` in a temporary folder), and the load time from
  the disk cache in another fresh process; both paid once per process, never in
  the timings below (`multimass.fast.warm_up`);
* ``S1_DD2_release``: S1 released from 0.11 rad, DD2, t_end = 10 s, default options
  (output every 1 ms) and with output_dt = None: time of one ``simulate`` call with
  each backend (the median of `--repeat`, calls interleaved so both see the same
  machine load), the ratio, ``wall_time_s`` (the phase loop alone), and the largest
  |peak difference| and event-time difference of each backend from a tight
  solve_ivp reference (rtol = 1e-11, atol = 1e-13), with the numbers of events;
* ``B6M_sine``: the cell of an overturning map — B6M, SineWave(a0 = 1.5 g tan α,
  ω = 3p), CIM with η_H, t_end = pulse + 3 s, output_dt = None: ms per call (median
  of `--calls` compiled calls, a tenth as many solve_ivp calls), split into the phase
  loop (wall_time_s) and the rest (setup, Response);
* ``work_precision`` (with ``--work-precision``): compiled RK45 and DOP853 on the S1
  case at several rtol: seconds and max |peak error| against the tight reference.

Timings depend on the machine and its load; run it 2–3 times and compare medians.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

__all__ = ["main"]

_COMPILE_SNIPPET = ("import json, multimass.fast as f; r = f.warm_up(); "
                    "print(json.dumps(r.to_dict()))")


def _fresh_process_warm_up(cache_dir: str | None) -> dict:
    env = dict(os.environ)
    if cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = cache_dir
    out = subprocess.run([sys.executable, "-c", _COMPILE_SNIPPET], env=env, check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def compile_times() -> dict:
    """Cold compilation (empty cache) and load from the cache, each in a fresh process."""
    with tempfile.TemporaryDirectory() as tmp:
        cold = _fresh_process_warm_up(tmp)
        cached = _fresh_process_warm_up(tmp)
    return {"cold_compile_s": cold["seconds"], "cold_source": cold["source"],
            "load_from_cache_s": cached["seconds"], "cached_source": cached["source"]}


def _timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def _peak_error(resp, ref) -> float:
    if resp.peaks.shape != ref.peaks.shape:
        return math.inf
    return float(np.max(np.abs(resp.peaks - ref.peaks)))


def _event_time_error(resp, ref) -> float:
    if [e.kind for e in resp.events] != [e.kind for e in ref.events]:
        return math.inf
    return max(abs(a.time - b.time) for a, b in zip(resp.events, ref.events))


def s1_case(repeat: int, ref) -> dict:
    from multimass import FreeRelease, simulate

    out = {}
    for label, output_dt in (("output_dt=1e-3", 1e-3), ("output_dt=None", None)):
        run = lambda backend: simulate("S1", FreeRelease(0.11), "DD2", 10.0, backend=backend,
                                       output_dt=output_dt)
        t_s, t_c, w_s, w_c = [], [], [], []
        for _ in range(repeat):
            sec, rs = _timed(lambda: run("scipy"))
            t_s.append(sec), w_s.append(rs.wall_time_s)
            sec, rc = _timed(lambda: run("compiled"))
            t_c.append(sec), w_c.append(rc.wall_time_s)
        ts, tc = statistics.median(t_s), statistics.median(t_c)
        out[label] = {
            "scipy_s": ts, "compiled_s": tc, "speedup": ts / tc,
            "scipy_wall_time_s": statistics.median(w_s),
            "compiled_wall_time_s": statistics.median(w_c),
            "speedup_wall_time": statistics.median(w_s) / statistics.median(w_c),
            "n_events": [len(rs.events), len(rc.events)],
            "same_event_kinds": [e.kind for e in rs.events] == [e.kind for e in rc.events],
            "max_event_time_difference_s": max(abs(a.time - b.time)
                                               for a, b in zip(rs.events, rc.events)),
            "n_rhs": [rs.n_rhs, rc.n_rhs],
            "max_peak_error_vs_tight_rad": {"scipy": _peak_error(rs, ref),
                                            "compiled": _peak_error(rc, ref)},
            "max_event_time_error_vs_tight_s": {"scipy": _event_time_error(rs, ref),
                                                "compiled": _event_time_error(rc, ref)},
        }
    return out


def b6m_case(calls: int) -> dict:
    import multimass
    from multimass import SineWave, simulate

    blk = multimass.rigid_block("B6M")
    exc = SineWave(1.5 * blk.g * math.tan(blk.alpha_cg), 3.0 * blk.p)
    t_end = exc.duration + 3.0
    out = {"excitation": exc.describe(), "t_end": t_end}
    for backend, n in (("compiled", calls), ("scipy", max(3, calls // 10))):
        totals, walls = [], []
        for _ in range(n):
            sec, r = _timed(lambda: simulate(blk, exc, "CIM", t_end, restitution="housner",
                                             output_dt=None, backend=backend))
            totals.append(sec), walls.append(r.wall_time_s)
        out[backend] = {"calls": n, "ms_per_call": 1e3 * statistics.median(totals),
                        "ms_phase_loop": 1e3 * statistics.median(walls),
                        "status": r.status, "n_events": len(r.events), "n_rhs": r.n_rhs}
    out["speedup"] = out["scipy"]["ms_per_call"] / out["compiled"]["ms_per_call"]
    return out


def work_precision(ref) -> dict:
    from multimass import FreeRelease, simulate

    rows = []
    for method in ("RK45", "DOP853"):
        for rtol in (1e-6, 1e-8, 1e-10):
            sec, r = _timed(lambda: simulate("S1", FreeRelease(0.11), "DD2", 10.0, method=method,
                                             rtol=rtol, atol=rtol * 1e-2, output_dt=None,
                                             backend="compiled"))
            rows.append({"method": method, "rtol": rtol, "atol": rtol * 1e-2, "seconds": sec,
                         "n_rhs": r.n_rhs, "max_peak_error_rad": _peak_error(r, ref)})
    return {"rows": rows}


def main(argv=None) -> dict:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=3, help="S1 runs per backend (median)")
    p.add_argument("--calls", type=int, default=200, help="compiled calls of the B6M case")
    p.add_argument("--no-compile", action="store_true", help="skip the fresh-process compile timing")
    p.add_argument("--work-precision", action="store_true", help="RK45 vs DOP853 (compiled)")
    args = p.parse_args(argv)

    result = {"compile": None if args.no_compile else compile_times()}
    import multimass.fast
    from multimass import FreeRelease, simulate

    result["warm_up_this_process"] = multimass.fast.warm_up().to_dict()
    sec, ref = _timed(lambda: simulate("S1", FreeRelease(0.11), "DD2", 10.0, rtol=1e-11,
                                       atol=1e-13, output_dt=None))
    result["tight_reference"] = {"rtol": 1e-11, "atol": 1e-13, "seconds": sec,
                                 "n_events": len(ref.events), "n_peaks": int(ref.peaks.size)}
    result["S1_DD2_release"] = s1_case(args.repeat, ref)
    result["B6M_sine"] = b6m_case(args.calls)
    if args.work_precision:
        result["work_precision"] = work_precision(ref)
    result["load_average"] = os.getloadavg()
    print(json.dumps(result, indent=2))
    return result


if __name__ == "__main__":
    main()
