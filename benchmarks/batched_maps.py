"""Batched overturning maps against the per-cell compiled map.

Run:  python -m benchmarks.batched_maps [--n 100] [--repeat 3]

The n × n B6M sine map of `multimass.bench.targets.map_speedup` (paper 004; ω/p
0.5–10, a0/(α g) 0.25–8, η_M, t_free 10 s, runs stopped once the block cannot
overturn), on warm process pools of 1 and 2 workers, two ways:

* ``per_cell``: one `map_cell` job per cell, each a `simulate_outcome` on the
  compiled path (``maps.BATCHED = False``: one compiled run per cell);
* ``batched``: chunks of cells, one compiled call each (``maps.BATCHED = True``).

Each repeat runs the pools in ABBA order (1, 2, 2, 1, ...) and, on each pool, the
two paths one after the other (alternating which goes first), so a drift of the
machine's speed hits both alike; the ratio of a repeat is per-cell time over batched
time on the same pool. Wall times on a shared machine suffer from its other jobs, so
the two maps are also run on the serial executor (everything in this process) and
timed in CPU time (``serial_cpu``), which other jobs on the machine barely change.
Also: the batched kernel alone (CPU time per cell, no executor), and cell-for-cell
equality of the two maps (outcome, impacts, accuracy flag, overturning time, max
``|θ|``). Prints one JSON dict; timings depend on the machine and its load
(reported), compare medians.
"""

from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np

__all__ = ["main", "batched_vs_per_cell"]


def _equality(a, b) -> dict:
    """How far the batched map `b` is from the per-cell map `a`, cell for cell."""
    ca, cb = a.cells, b.cells
    same = (ca.outcome.to_numpy() == cb.outcome.to_numpy()) & (
        ca.n_impacts.to_numpy() == cb.n_impacts.to_numpy()
    )
    same &= ca.accurate.to_numpy() == cb.accurate.to_numpy()
    t_a, t_b = ca.overturn_time.to_numpy(), cb.overturn_time.to_numpy()
    both = ~(np.isnan(t_a) & np.isnan(t_b))
    return {
        "cells": int(len(ca)),
        "same_outcome": int((ca.outcome.to_numpy() == cb.outcome.to_numpy()).sum()),
        "same_outcome_impacts_accuracy": int(same.sum()),
        "max_abs_diff_theta_max_over_alpha": float(
            np.max(np.abs(ca.theta_max_over_alpha.to_numpy() - cb.theta_max_over_alpha.to_numpy()))
        ),
        "max_abs_diff_overturn_time_s": float(np.max(np.abs(t_a[both] - t_b[both]), initial=0.0)),
        "bitwise_identical_cells_table": bool(ca.equals(cb)),
    }


def _kernel_cpu(n: int, repeats: int) -> dict:
    """CPU ms per cell of `run_pulses` alone on the n × n grid (this process, warm)."""
    import multimass
    from multimass.bench.targets import map_axes, spread
    from multimass.engines._run import QUIET_DELAY
    from multimass.engines.fast.block_runs import BlockRuns, run_pulses
    from multimass.sweeps.map_cells import UNDECIDED_RETRY
    from multimass.sweeps.maps import default_backend

    st = multimass.rigid_block("B6M")
    options = default_backend(dict(impact="CIM", restitution="modified", k=None))
    runs = BlockRuns.of(st, options, QUIET_DELAY, UNDECIDED_RETRY)
    omega_p, amp = map_axes(n)
    w = np.array([float(x * st.p) for a in amp for x in omega_p])
    a0 = np.array([float(a * st.alpha_cg * st.g) for a in amp for x in omega_p])
    run_pulses(runs, "sine", a0[:4], w[:4], 10.0)
    cpu = []
    for _ in range(repeats):
        t0 = time.process_time()
        run_pulses(runs, "sine", a0, w, 10.0)
        cpu.append(1e3 * (time.process_time() - t0) / w.size)
    return spread(cpu)


def _serial_cpu(run_map, cells: int, repeats: int) -> dict:
    """Both maps on the serial executor, in CPU time of this process (ms per cell)."""
    from multimass.bench.targets import spread

    cpu = {False: [], True: []}
    for r in range(repeats):
        for batched in (False, True) if r % 2 == 0 else (True, False):
            t0 = time.process_time()
            run_map(batched, "serial")
            cpu[batched].append(1e3 * (time.process_time() - t0) / cells)
    return {
        "per_cell_ms_per_cell": spread(cpu[False]),
        "batched_ms_per_cell": spread(cpu[True]),
        "speedup": spread([a / b for a, b in zip(cpu[False], cpu[True])]),
    }


def batched_vs_per_cell(n: int = 100, repeats: int = 3, progress=None) -> dict:
    """The comparison of the module docstring."""
    import multimass
    from multimass.bench.targets import map_axes, spread
    from multimass.sweeps import ProcessExecutor, maps

    say = progress or (lambda msg: None)
    block = multimass.rigid_block("B6M")
    omega_p, amp = map_axes(n)

    def run_map(batched: bool, ex):
        saved, maps.BATCHED = maps.BATCHED, batched  # True: batched at any size
        try:
            t0 = time.perf_counter()
            m = maps.overturning_map(
                block, "sine", omega_p, amp, restitution="modified", t_free=10.0,
                executor=ex, progress=False,
            )  # fmt: skip
            return time.perf_counter() - t0, m
        finally:
            maps.BATCHED = saved

    pools = {w: ProcessExecutor(workers=w) for w in (1, 2)}
    times = {(p, w): [] for p in ("per_cell", "batched") for w in (1, 2)}
    load = []
    try:
        for ex in pools.values():  # start the pools, load the kernels in the workers
            run_map(True, ex)
            run_map(False, ex)
        for r in range(repeats):
            for w in (1, 2) if r % 2 == 0 else (2, 1):
                load.append(os.getloadavg()[0])
                order = (False, True) if (r + w) % 2 else (True, False)
                for batched in order:
                    sec, m = run_map(batched, pools[w])
                    times["batched" if batched else "per_cell", w].append(sec)
                    if batched:
                        m_batched = m
                    else:
                        m_per_cell = m
                say(
                    f"map {n}x{n}, {w} worker(s): per cell {times['per_cell', w][-1]:.2f} s, "
                    f"batched {times['batched', w][-1]:.2f} s"
                )
    finally:
        for ex in pools.values():
            ex.close()
    cells = n * n
    out = {
        "case": f"B6M sine map {n}x{n}, ω/p {omega_p[0]:g}–{omega_p[-1]:g}, a0/(α g) "
        f"{amp[0]:g}–{amp[-1]:g}, η_M, t_free 10 s, stop_when_safe, compiled (DOP853)",
        "repeats": repeats,
        "equality": _equality(m_per_cell, m_batched),
    }
    for w in (1, 2):
        key = f"{w}_worker" + ("s" if w > 1 else "")
        per, bat = times["per_cell", w], times["batched", w]
        out[key] = {
            "per_cell_s": spread(per),
            "batched_s": spread(bat),
            "per_cell_ms_per_cell": spread([1e3 * t / cells for t in per]),
            "batched_ms_per_cell": spread([1e3 * t / cells for t in bat]),
            "speedup": spread([a / b for a, b in zip(per, bat)]),
        }
    out["scaling_2_workers"] = {
        p: spread([a / b for a, b in zip(times[p, 1], times[p, 2])])
        for p in ("per_cell", "batched")
    }
    out["serial_cpu"] = _serial_cpu(run_map, cells, repeats)
    out["batched_kernel_cpu_ms_per_cell"] = _kernel_cpu(n, repeats)
    out["load_average_before_each_pair"] = load
    out["load_average"] = os.getloadavg()
    return out


def main(argv=None) -> dict:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=int, default=100, help="map of n x n cells (default 100)")
    p.add_argument("--repeat", type=int, default=3, help="repeats (median, min, max)")
    args = p.parse_args(argv)
    from multimass.bench.run import json_safe

    result = batched_vs_per_cell(args.n, args.repeat, progress=print)
    print(json.dumps(json_safe(result), indent=2))
    return result


if __name__ == "__main__":
    main()
