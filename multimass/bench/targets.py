"""The three speed targets of the compiled path, measured as ratios within one run, and the compile cost.

* ``speedup_single`` — S1 released from 0.11 rad, DD2, 10 s: one
  `multimass.simulate` call with the solve_ivp path over one with the compiled
  path (default options: DOP853, rtol 1e-8, output every 1 ms; also reported
  with ``output_dt=None``), calls interleaved so both see the same machine load;
  ``peak_error_rad``: the compiled run's largest ``|peak difference|`` from a tight
  solve_ivp reference (target ≤ 1e-6 rad).
* ``speedup_map`` — the B6M sine overturning map (paper 004; ω/p 0.5–10,
  a0/(α g) 0.25–8, η_M, t_free 10 s): a plain loop of one solve_ivp
  `simulate` call per cell (``stop_when_safe=True``) over
  `multimass.sweeps.maps.overturning_map` on the compiled path with the process
  pool on all cores (2 here), warm. The loop may be timed on a seeded random
  subsample of the cells and scaled to the grid (said in the output).
* ``scaling_2_workers`` — the compiled map on a warm pool of 1 worker over 2.
  The pools take turns in ABBA order (1, 2, 2, 1, ...), so a slow drift of the
  machine's speed hits both alike. ``machine_scaling``: the same pools run a
  pure-Python loop of fixed length (no I/O, no memory traffic), 1 worker over 2,
  right after each map pair: the ceiling this machine allows at that moment, so
  a low map scaling can be told apart from a busy or throttled machine.

Each ratio is measured `repeats` times: median, min and max are reported, and
for the map the ratio of the best (shortest) times and the 1-minute load
average before each map: the 2-worker time is the one that suffers when
another process holds a core of a 2-core machine.
The numba compilation is paid once per machine (disk cache) and per process
(cache load): `compile_times` measures both in fresh processes, apart.
"""

from __future__ import annotations

import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

__all__ = [
    "compile_times",
    "single_speedup",
    "map_speedup",
    "map_axes",
    "spread",
    "spin",
    "machine_times",
    "TARGETS",
    "TARGET_CASE",
]

#: the targets' thresholds
TARGETS = {
    "speedup_single": 30.0,
    "peak_error_rad": 1e-6,
    "speedup_map": 50.0,
    "scaling_2_workers": 1.7,
}
#: ... set on these cases: S1 DD2 release for t_end seconds, the map_n x map_n B6M map
TARGET_CASE = {"t_end": 10.0, "map_n": 100}
_COMPILE_SNIPPET = (
    "import json, multimass.engines.fast as f; r = f.warm_up(); print(json.dumps(r.to_dict()))"
)


def spread(values) -> dict:
    """Median, min, max and the values of a repeated ratio."""
    v = [float(x) for x in values]
    return {"median": statistics.median(v), "min": min(v), "max": max(v), "values": v}


def _fresh_process_warm_up(cache_dir: str) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    out = subprocess.run(
        [sys.executable, "-c", _COMPILE_SNIPPET],
        env=env,
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    return json.loads(out.strip().splitlines()[-1])


def compile_times(cold: bool = True) -> dict:
    """The compiled path's one-off cost: cold compile and cache load, each in a fresh process.

    With `cold` False only this process's `warm_up` report (a cache load, or
    nothing if already loaded).
    """
    import multimass.engines.fast

    here = multimass.engines.fast.warm_up().to_dict()
    if not cold:
        return {"this_process": here}
    with tempfile.TemporaryDirectory() as tmp:
        first = _fresh_process_warm_up(tmp)
        second = _fresh_process_warm_up(tmp)
    return {
        "cold_compile_s": first["seconds"],
        "cold_source": first["source"],
        "load_from_cache_s": second["seconds"],
        "cached_source": second["source"],
        "this_process": here,
    }


def _timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def _peak_error(resp, ref) -> float:
    if resp.peaks.shape != ref.peaks.shape:
        return math.inf
    return float(np.max(np.abs(resp.peaks - ref.peaks)))


def single_speedup(
    repeats: int, t_end: float = 10.0, ref_rtol: float = 1e-12, ref_atol: float = 1e-14
) -> dict:
    """S1 DD2 release: solve_ivp path / compiled path, and the compiled peak error."""
    from multimass.inputs.excitations import FreeRelease
    from multimass.simulation import simulate

    case = lambda **kw: simulate("S1", FreeRelease(0.11), "DD2", t_end, **kw)  # noqa: E731
    sec, ref = _timed(lambda: case(rtol=ref_rtol, atol=ref_atol, output_dt=None))
    from multimass.engines.fast.compile import warm_up_columns

    warm_up_columns(progress=False)  # `simulate`'s one-call path, as after `multimass warm-up`
    case(backend="compiled", output_dt=None)  # warm: kernels loaded
    out = {
        "case": f"S1, FreeRelease(0.11), DD2, t_end = {t_end:g} s, default options",
        "reference": {
            "rtol": ref_rtol,
            "atol": ref_atol,
            "seconds": sec,
            "n_events": len(ref.events),
            "n_peaks": int(ref.peaks.size),
        },
    }
    for label, output_dt in (("output_dt=1e-3 (default)", 1e-3), ("output_dt=None", None)):
        ratios, t_s, t_c = [], [], []
        for _ in range(repeats):
            s, rs = _timed(lambda dt=output_dt: case(output_dt=dt))
            c, rc = _timed(lambda dt=output_dt: case(output_dt=dt, backend="compiled"))
            ratios.append(s / c), t_s.append(s), t_c.append(c)
        out[label] = {
            "speedup": spread(ratios),
            "scipy_s": spread(t_s),
            "compiled_s": spread(t_c),
            "n_rhs": [int(rs.n_rhs), int(rc.n_rhs)],
            "same_event_kinds": [e.kind for e in rs.events] == [e.kind for e in rc.events],
            "peak_error_rad": {"scipy": _peak_error(rs, ref), "compiled": _peak_error(rc, ref)},
            "max_event_time_difference_s": max(
                (abs(a.time - b.time) for a, b in zip(rs.events, rc.events)), default=0.0
            ),
        }
    return out


def map_axes(n: int) -> tuple[np.ndarray, np.ndarray]:
    """ω/p and a0/(α g) of an n × n map (the ranges of `multimass stability`)."""
    return np.linspace(0.5, 10.0, n), np.linspace(0.25, 8.0, n)


def _baseline(block, cells, t_free: float, restitution: str) -> tuple[float, list]:
    """One solve_ivp `simulate` call per cell; (seconds, outcomes)."""
    from multimass.inputs.excitations import SineWave
    from multimass.simulation import simulate

    outcomes = []
    t0 = time.perf_counter()
    for w, a in cells:
        exc = SineWave(amplitude=a * block.alpha_cg * block.g, omega=w * block.p)
        r = simulate(
            block,
            exc,
            "CIM",
            t_end=exc.duration + t_free,
            stop_when_safe=True,
            restitution=restitution,
        )
        outcomes.append(
            "overturned"
            if r.outcome == "overturned"
            else "no_rocking"
            if not any(e.kind == "uplift" for e in r.events)
            else "rest"
            if any(e.kind == "rest" for e in r.events)
            else "undecided"
        )
    return time.perf_counter() - t0, outcomes


def spin(n: int) -> int:
    """A pure-Python loop of `n` steps: CPU only, for the machine's own scaling."""
    s = 0
    for i in range(n):
        s += i * i % 7
    return s


def machine_times(pools: dict, tasks: int = 32, steps: int = 1_000_000) -> dict:
    """Wall time (s) of `tasks` spin tasks on each pool of `pools` (workers → executor).

    The machine's own scaling: ~3 s on 1 worker here with the defaults.
    """
    from multimass.sweeps import run_jobs

    return {
        w: _timed(
            lambda ex=ex: run_jobs(spin, [steps] * tasks, executor=ex, batch_size=1, progress=False)
        )[0]
        for w, ex in pools.items()
    }


def _machine_scaling(pools: dict, tasks: int = 32, steps: int = 1_000_000) -> float:
    """1-worker over 2-worker wall time of `tasks` spin tasks (`machine_times`)."""
    t = machine_times(pools, tasks, steps)
    return t[1] / t[2]


def map_speedup(
    n: int,
    baseline_cells: int | None,
    repeats: int,
    seed: int = 7,
    progress=None,
    spin_steps: int = 1_000_000,
) -> dict:
    """Compiled map (1 and 2 workers, warm pools) against the solve_ivp loop; see module doc."""
    import multimass
    from multimass.sweeps import ProcessExecutor
    from multimass.sweeps.maps import overturning_map

    say = progress or (lambda msg: None)
    block, t_free, rest = multimass.rigid_block("B6M"), 10.0, "modified"
    omega_p, amp = map_axes(n)
    grid = [(w, a) for a in amp for w in omega_p]
    run_map = lambda ex: overturning_map(
        block,
        "sine",
        omega_p,
        amp,
        restitution=rest,  # noqa: E731
        t_free=t_free,
        executor=ex,
        progress=False,
    )
    pools, times = {w: ProcessExecutor(workers=w) for w in (1, 2)}, {1: [], 2: []}
    load, ceiling = [], []
    try:
        cold = {w: _timed(lambda ex=ex: run_map(ex))[0] for w, ex in pools.items()}  # start, cache
        say(f"map {n}x{n}: first map (pool start, cache load) {cold}")
        for r in range(repeats):
            for w in (1, 2) if r % 2 == 0 else (2, 1):  # ABBA
                load.append(os.getloadavg()[0])
                sec, m = _timed(lambda w=w: run_map(pools[w]))
                times[w].append(sec)
            ceiling.append(_machine_scaling(pools, steps=spin_steps))
            say(
                f"map {n}x{n}: 1 worker {times[1][-1]:.2f} s, 2 workers {times[2][-1]:.2f} s, "
                f"machine scaling {ceiling[-1]:.2f}"
            )
        serial_sec, m_serial = _timed(lambda: run_map("serial"))
    finally:
        for ex in pools.values():
            ex.close()
    rng = np.random.default_rng(seed)
    idx = (
        np.arange(len(grid))
        if baseline_cells is None or baseline_cells >= len(grid)
        else np.sort(rng.choice(len(grid), baseline_cells, replace=False))
    )
    say(f"map baseline: {len(idx)} solve_ivp cells")
    base_sec, outcomes = _baseline(block, [grid[i] for i in idx], t_free, rest)
    base_full = base_sec * len(grid) / len(idx)
    mine = m.grid.ravel()[idx]  # cells are amp-major, as `grid`
    return {
        "case": f"B6M sine map {n}x{n}, ω/p {omega_p[0]:g}–{omega_p[-1]:g}, a0/(α g) "
        f"{amp[0]:g}–{amp[-1]:g}, η_M, t_free {t_free:g} s, stop_when_safe",
        "baseline": {
            "cells_timed": int(len(idx)),
            "cells": len(grid),
            "seed": seed,
            "sampled": bool(len(idx) < len(grid)),
            "seconds_timed": base_sec,
            "seconds_scaled_to_grid": base_full,
            "ms_per_cell": 1e3 * base_sec / len(idx),
            "same_outcome_as_map": float(np.mean(np.array(outcomes) == mine)),
        },
        "compiled_s": {
            "1_worker": spread(times[1]),
            "2_workers": spread(times[2]),
            "serial_executor": serial_sec,
            "first_map_with_pool_start": cold,
        },
        "speedup_map": spread([base_full / t for t in times[2]]),
        "speedup_map_1_worker": spread([base_full / t for t in times[1]]),
        "scaling_2_workers": spread([a / b for a, b in zip(times[1], times[2])]),
        "machine_scaling": spread(ceiling),
        "best_of": {
            "speedup_map": base_full / min(times[2]),
            "scaling_2_workers": min(times[1]) / min(times[2]),
        },
        "load_average_before_each_map": load,
        "load_average": os.getloadavg(),
    }
