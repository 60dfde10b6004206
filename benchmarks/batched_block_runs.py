"""Batched rigid-block runs under pulses and records against one run at a time.

Run:  python -m benchmarks.batched_block_runs [--pulses 1000] [--records 200] [--repeat 5]

The runs of a suite (`multimass.suites.runs.run_suite`): B6M (paper 004) from rest,
classical impacts with η_M of a k drawn per run (normal, mean 0.82, std 0.05, as
``examples/suites/B6M_mp_pulses.toml``), each run to the end of its motion plus 5 s of
free rocking (no ``stop_when_safe``; stop at rest), on the compiled path (DOP853):

* ``mp_pulses``: M&P pulses of random shape (γ uniform in 1.5–3, ν in 0–π), ω_p/p
  log-uniform in 1–10, peak acceleration log-uniform in 1–8 g tan α;
* ``records``: El Centro 1940 NS (units g) and Kobe 1995 (units m/s²), scaled to a
  PGA uniform in 0.5–3 g tan α.

Each set runs two ways in this process: ``per_run``, one `simulate_outcome` per run
(what ``run_suite`` does today), and ``batched``, one
`multimass.sweeps.block_outcomes.simulate_outcomes` call (the restitution pairs, the
encoding and one compiled call for all runs). Each repeat runs both, alternating
which goes first, timed in CPU time of this process (other jobs on a shared machine
barely change it) and in wall time; the ratio of a repeat is per-run time over batched
time. Also: run-for-run equality of the two (outcome, status, impacts, RHS
evaluations; largest difference of θ_max and of the overturning time). Prints one
JSON dict; timings depend on the machine and its load (reported), compare medians.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import time
from pathlib import Path

import numpy as np

__all__ = ["main", "batched_vs_per_run", "mp_pulse_runs", "record_runs"]

_RECORDS = Path(__file__).resolve().parents[1] / "examples" / "data" / "records"
T_FREE = 5.0  # s of free rocking after the motion (examples/suites/B6M_mp_pulses.toml)
_OPTIONS = dict(impact="CIM", restitution="modified", backend="compiled")


def _k(rng) -> float:
    return float(np.clip(rng.normal(0.82, 0.05), 0.0, 1.0))


def mp_pulse_runs(st, n: int, seed: int = 2026) -> tuple[list, list]:
    """n (M&P pulse, options) runs of the module docstring."""
    from multimass import MPShape
    from multimass.engines._rigid import uplift_threshold

    rng = np.random.default_rng(seed)
    a_th = uplift_threshold(st)
    excitations, options = [], []
    for _ in range(n):
        shape = MPShape(gamma=float(rng.uniform(1.5, 3.0)), nu=float(rng.uniform(0.0, math.pi)))
        ratio, amp = np.exp(rng.uniform(0.0, math.log(10.0))), np.exp(rng.uniform(0.0, math.log(8)))
        excitations.append(shape(amplitude=float(amp * a_th), omega=float(ratio * st.p)))
        options.append(_OPTIONS | {"k": _k(rng)})
    return excitations, options


def record_runs(st, n: int, seed: int = 2027) -> tuple[list, list]:
    """n (scaled record, options) runs of the module docstring."""
    from multimass.engines._rigid import uplift_threshold
    from multimass.inputs.records import read_record

    records = (
        read_record(_RECORDS / "elcentro_1940_NS.dat", units="g"),
        read_record(_RECORDS / "kobe_1995.dat", units="m/s2"),
    )
    rng = np.random.default_rng(seed)
    a_th = uplift_threshold(st)
    excitations, options = [], []
    for i in range(n):
        r = records[i % 2]
        excitations.append(r.scaled(float(rng.uniform(0.5, 3.0) * a_th / r.pga)))
        options.append(_OPTIONS | {"k": _k(rng)})
    return excitations, options


def _per_run(st, excitations, t_end, options) -> list:
    from multimass.simulation import simulate_outcome

    return [
        simulate_outcome(st, e, t_end=float(te), **o)
        for e, te, o in zip(excitations, t_end, options)
    ]


def _equality(want, got) -> dict:
    """How far the batched runs `got` are from the per-run outcomes `want`."""
    t_over = np.array(
        [next((e.time for e in r.events if e.kind == "overturn"), math.nan) for r in want]
    )
    both = ~np.isnan(t_over) & ~np.isnan(got.overturn_time)
    same = np.array(
        [
            (r.status, r.n_impacts, r.n_rhs, r.message) == (s, i, h, m)
            for r, s, i, h, m in zip(
                want, got.status.tolist(), got.n_impacts.tolist(), got.n_rhs.tolist(), got.message
            )
        ]
    )
    same &= np.isnan(t_over) == np.isnan(got.overturn_time)
    theta = np.array([r.theta_max for r in want])
    return {
        "runs": len(want),
        "batched": int(got.batched.sum()),
        "same_status_impacts_rhs_message": int(same.sum()),
        "max_abs_diff_theta_max_rad": float(np.max(np.abs(theta - got.theta_max), initial=0.0)),
        "max_abs_diff_overturn_time_s": float(
            np.max(np.abs(t_over[both] - got.overturn_time[both]), initial=0.0)
        ),
        "bitwise_identical": bool(
            same.all()
            and np.array_equal(theta, got.theta_max)
            and np.array_equal(t_over, got.overturn_time, equal_nan=True)
        ),
        "statuses": {s: int(c) for s, c in zip(*np.unique(got.status, return_counts=True))},
    }


def _compare(st, excitations, options, repeats: int, say) -> dict:
    from multimass.bench.targets import spread
    from multimass.sweeps.block_outcomes import simulate_outcomes

    n = len(excitations)
    t_end = np.array([e.duration + T_FREE for e in excitations])
    want = _per_run(st, excitations[:5], t_end[:5], options[:5])  # warm both paths
    simulate_outcomes(st, excitations[:5], t_end[:5], options[:5])
    cpu, wall = {"per_run": [], "batched": []}, {"per_run": [], "batched": []}
    for r in range(repeats):
        for way in ("per_run", "batched") if r % 2 == 0 else ("batched", "per_run"):
            c0, w0 = time.process_time(), time.perf_counter()
            if way == "per_run":
                want = _per_run(st, excitations, t_end, options)
            else:
                got = simulate_outcomes(st, excitations, t_end, options)
            cpu[way].append(1e3 * (time.process_time() - c0) / n)
            wall[way].append(1e3 * (time.perf_counter() - w0) / n)
        say(
            f"{n} runs: per run {cpu['per_run'][-1]:.3f} ms, batched {cpu['batched'][-1]:.3f} "
            "ms CPU per run"
        )
    return {
        "runs": n,
        "cpu_ms_per_run": {w: spread(v) for w, v in cpu.items()},
        "wall_ms_per_run": {w: spread(v) for w, v in wall.items()},
        "speedup_cpu": spread([a / b for a, b in zip(cpu["per_run"], cpu["batched"])]),
        "speedup_wall": spread([a / b for a, b in zip(wall["per_run"], wall["batched"])]),
        "equality": _equality(want, got),
    }


def batched_vs_per_run(
    n_pulses: int = 1000, n_records: int = 200, repeats: int = 5, progress=None
) -> dict:
    """The comparison of the module docstring."""
    import multimass
    from multimass.engines.fast import warm_up
    from multimass.engines.fast.block_runs import ensure_ready

    say = progress or (lambda msg: None)
    st = multimass.rigid_block("B6M")
    warm_up()
    ensure_ready(progress=False)
    out = {
        "case": "B6M from rest, CIM with η_M(k), k ~ N(0.82, 0.05) per run, t_end = motion "
        f"duration + {T_FREE:g} s, stop at rest, no stop_when_safe, compiled (DOP853)",
        "repeats": repeats,
        "load_average_before": os.getloadavg(),
    }
    out["mp_pulses"] = _compare(st, *mp_pulse_runs(st, n_pulses), repeats, say)
    out["records"] = _compare(st, *record_runs(st, n_records), repeats, say)
    out["load_average_after"] = os.getloadavg()
    return out


def main(argv=None) -> dict:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--pulses", type=int, default=1000, help="runs under M&P pulses (1000)")
    p.add_argument("--records", type=int, default=200, help="runs under scaled records (200)")
    p.add_argument("--repeat", type=int, default=5, help="repeats (median, min, max)")
    args = p.parse_args(argv)
    from multimass.bench.run import json_safe

    result = batched_vs_per_run(args.pulses, args.records, args.repeat, progress=print)
    print(json.dumps(json_safe(result), indent=2))
    return result


if __name__ == "__main__":
    main()
