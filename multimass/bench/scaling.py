"""How cost grows: ``multimass bench --scaling``.

Three series, each point repeated (median, min and max of the wall times), each
series summarised by the least-squares slope of log cost against log size
(`fit_exponent`):

* ``cells`` — the B6M sine overturning map (paper 004; ω/p 0.5–10, a0/(α g)
  0.25–8, η_M, t_free 10 s) on side × side grids, on the serial executor (one
  core: the cost per cell, no pool), brute force and, where
  `overturning_map` has the keyword, ``adaptive=True`` (with the cells it
  computed). Cost against the grid's cells.
* ``workers`` — one map on warm process pools of 1 and 2 workers, in ABBA order,
  and beside it the machine's own scaling: pure-Python loops on the same pools
  (`multimass.bench.targets.machine_times`), right after each map pair.
* ``nodes`` — 10 s of free rocking of uniform N-node columns (`uniform_column`)
  on four paths (`NODE_PATHS`): the compiled path as run by default (full contact
  in closed form), the compiled path integrating every phase (``compiled_rk``), the
  compiled path with the exponential method in the rocking phases (``exponential``)
  and the solve_ivp path. A run whose `multimass.estimate` exceeds its backend's
  budget is skipped and listed. Cost per RHS evaluation is fitted for the paths
  that integrate every phase.

`run_scaling` writes ``scaling.json``, ``scaling.md`` and the charts
``scaling_cells.png``, ``scaling_workers.png``, ``scaling_nodes.png``.
"""

from __future__ import annotations

import dataclasses
import inspect
import json
import os
import time
from pathlib import Path

import numpy as np

from .config import ScalingConfig
from .targets import machine_times, map_axes, spread

__all__ = [
    "fit_exponent",
    "uniform_column",
    "NODE_PATHS",
    "cells_series",
    "workers_series",
    "nodes_series",
    "run_scaling",
    "FILES",
]

FILES = (
    "scaling.json",
    "scaling.md",
    "scaling_cells.png",
    "scaling_workers.png",
    "scaling_nodes.png",
)


def fit_exponent(sizes, costs) -> dict:
    """Least-squares fit of log cost = log c + b log size: the exponent b of cost ∝ size^b.

    Parameters
    ----------
    sizes, costs : array_like
        Positive sizes and costs (e.g. cells and the median wall time); at least two
        distinct sizes.

    Returns
    -------
    dict
        ``exponent`` b, ``prefactor`` c, ``stderr`` of b (None with two points),
        ``size_range`` [min, max] of the sizes fitted, ``points``.
    """
    x, y = np.log(np.asarray(sizes, dtype=float)), np.log(np.asarray(costs, dtype=float))
    if x.size < 2 or np.ptp(x) == 0:
        return {
            "exponent": None,
            "prefactor": None,
            "stderr": None,
            "size_range": None,
            "points": int(x.size),
        }
    b, a = np.polyfit(x, y, 1)
    stderr = None
    if x.size > 2:
        resid = y - (a + b * x)
        stderr = float(np.sqrt(resid @ resid / (x.size - 2) / np.sum((x - x.mean()) ** 2)))
    return {
        "exponent": float(b),
        "prefactor": float(np.exp(a)),
        "stderr": stderr,
        "size_range": [float(np.exp(x.min())), float(np.exp(x.max()))],
        "points": int(x.size),
    }


def _timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def _has_adaptive() -> bool:
    from multimass.sweeps.maps import overturning_map

    return "adaptive" in inspect.signature(overturning_map).parameters


def _map(side: int, executor, **kw):
    """The B6M sine map of `side` × `side` cells, batched whatever its size: the batch
    kernels compiled or loaded first (a small map would otherwise run per cell until they
    are in numba's cache, `multimass.sweeps.map_cells.BATCH_COMPILE_CELLS`)."""
    import multimass
    from multimass.engines.fast.block_runs import ensure_ready
    from multimass.sweeps.maps import overturning_map

    ensure_ready()  # once per process

    omega_p, amp = map_axes(side)
    return overturning_map(
        multimass.rigid_block("B6M"),
        "sine",
        omega_p,
        amp,
        restitution="modified",
        t_free=10.0,
        executor=executor,
        progress=False,
        **kw,
    )


def _computed(m) -> int:
    adaptive = (getattr(m, "options", None) or {}).get("adaptive")
    return int(adaptive["computed"]) if adaptive else len(m.cells)


def cells_series(cfg: ScalingConfig, say) -> dict:
    """Map wall time against cells, brute force and adaptive (serial executor)."""
    methods = {"brute_force": {}}
    note = None
    if _has_adaptive():
        methods["adaptive"] = {"adaptive": True}
    else:
        note = "`overturning_map` has no `adaptive` keyword here: the adaptive series is left out"
    _map(8, "serial")  # kernels loaded before any timing
    series = {name: [] for name in methods}
    for side in cfg.map_sides:
        for name, kw in methods.items():
            times, computed = [], None
            for _ in range(cfg.repeats):
                sec, m = _timed(lambda kw=kw, side=side: _map(side, "serial", **kw))
                times.append(sec)
                computed = _computed(m)
                del m
            s = spread(times)
            series[name].append(
                {"side": side, "cells": side * side, "computed": computed, "seconds": s}
                | {"us_per_cell": 1e6 * s["median"] / (side * side)}
            )
            say(f"scaling cells: {side}x{side} {name}: {s['median']:.3g} s, {computed} computed")
    fits = {
        name: fit_exponent([p["cells"] for p in pts], [p["seconds"]["median"] for p in pts])
        for name, pts in series.items()
    }
    if "adaptive" in series:
        pts = series["adaptive"]
        fits["adaptive_computed_cells"] = fit_exponent(
            [p["cells"] for p in pts], [p["computed"] for p in pts]
        )
    return {
        "case": "B6M sine map, ω/p 0.5–10, a0/(α g) 0.25–8, η_M, t_free 10 s, serial executor",
        "series": series,
        "fits": fits,
        "note": note,
    }


def workers_series(cfg: ScalingConfig, say) -> dict:
    """One map on warm pools of 1, 2, ... workers (ABBA) and the machine's own scaling."""
    from multimass.sweeps import ProcessExecutor

    pools = {w: ProcessExecutor(workers=w) for w in cfg.workers}
    maps = {w: [] for w in cfg.workers}
    spins = {w: [] for w in cfg.workers}
    load = []
    side = cfg.workers_side
    try:
        for ex in pools.values():
            _map(side, ex)  # pool start and kernel load, untimed
        for r in range(cfg.repeats):
            order = cfg.workers if r % 2 == 0 else cfg.workers[::-1]
            for w in order:
                load.append(os.getloadavg()[0])
                maps[w].append(_timed(lambda w=w: _map(side, pools[w]))[0])
            for w, sec in machine_times(pools, cfg.spin_tasks, cfg.spin_steps).items():
                spins[w].append(sec)
            say(
                "scaling workers: map "
                + ", ".join(f"{w}: {maps[w][-1]:.3g} s" for w in cfg.workers)
                + "; spin "
                + ", ".join(f"{w}: {spins[w][-1]:.3g} s" for w in cfg.workers)
            )
    finally:
        for ex in pools.values():
            ex.close()
    ws = list(cfg.workers)
    out = {
        "case": f"B6M sine map {side}x{side} ({side * side} cells), process executor, warm pools",
        "machine": f"{cfg.spin_tasks} pure-Python loops of {cfg.spin_steps} steps on the same pools",
        "workers": ws,
        "map_seconds": {str(w): spread(maps[w]) for w in ws},
        "machine_seconds": {str(w): spread(spins[w]) for w in ws},
        "fits": {
            "map": fit_exponent(ws, [spread(maps[w])["median"] for w in ws]),
            "machine": fit_exponent(ws, [spread(spins[w])["median"] for w in ws]),
        },
        "load_average_before_each_map": load,
    }
    if 1 in pools and 2 in pools:
        out["speedup_2_workers"] = {
            "map": spread([a / b for a, b in zip(maps[1], maps[2])]),
            "machine": spread([a / b for a, b in zip(spins[1], spins[2])]),
        }
    return out


def uniform_column(n: int, like: str = "S1"):
    """A column like `like` (its top height, total mass, base, section, damping) on `n`
    equally spaced nodes of equal mass: heights H·i/n, masses m_t/n, i = 1..n."""
    import multimass
    import multimass.specimens as specimens

    spec = specimens.load(like)
    top, mass = spec.heights[-1], sum(spec.masses)
    return multimass.column(
        dataclasses.replace(
            spec,
            name=f"uniform {n}-node {like}",
            heights=tuple(top * (i + 1) / n for i in range(n)),
            masses=(mass / n,) * n,
            sensors=(),
        )
    )


#: The nodes series' paths: simulate options, and whether every phase takes RHS calls.
NODE_PATHS = {
    "compiled": (dict(backend="compiled"), False),
    "compiled_rk": (dict(backend="compiled", full_contact="integrate"), True),
    "exponential": (dict(backend="compiled", method="exponential"), False),
    "scipy": (dict(backend="scipy"), True),
}


def nodes_series(cfg: ScalingConfig, say) -> dict:
    """Free rocking of uniform N-node columns: wall time of each of `NODE_PATHS` against N."""
    import multimass

    release = multimass.FreeRelease(theta0=cfg.theta0)
    impact, t_end = cfg.nodes_impact, cfg.nodes_t_end
    multimass.simulate("S1", release, impact, 0.1, backend="compiled")  # kernels loaded
    series = {path: [] for path in NODE_PATHS}
    budget = {"compiled": cfg.compiled_budget_s, "scipy": cfg.scipy_budget_s}
    skipped = []
    for n in cfg.nodes:
        st = uniform_column(n)
        for path, pts in series.items():
            kw = NODE_PATHS[path][0] | dict(progress=False, max_hours=1e3)
            est = multimass.estimate(st, release, impact, t_end, **kw).seconds
            if est > budget[kw["backend"]]:
                skipped.append({"N": n, "backend": path, "estimate_s": est})
                say(f"scaling nodes: N={n} {path} skipped (estimate {est:.3g} s)")
                continue
            times = []
            for _ in range(cfg.repeats):
                sec, r = _timed(
                    lambda kw=kw, st=st: multimass.simulate(st, release, impact, t_end, **kw)
                )
                times.append(sec)
            s = spread(times)
            pts.append(
                {
                    "N": n,
                    "seconds": s,
                    "estimate_s": est,
                    "n_rhs": int(r.n_rhs),
                    "events": len(r.events),
                    "outcome": r.outcome,
                }
            )
            say(f"scaling nodes: N={n} {path}: {s['median']:.3g} s ({r.n_rhs} RHS)")
    fits = {
        b: fit_exponent([p["N"] for p in pts], [p["seconds"]["median"] for p in pts])
        for b, pts in series.items()
    }
    fits |= {
        f"{b}_per_rhs": fit_exponent(
            [p["N"] for p in pts], [p["seconds"]["median"] / p["n_rhs"] for p in pts]
        )
        for b, pts in series.items()
        if NODE_PATHS[b][1]
    }
    return {
        "case": f"uniform N-node S1-like columns (`uniform_column`), FreeRelease({cfg.theta0:g}), "
        f"{impact}, t_end {t_end:g} s, default options",
        "series": series,
        "fits": fits,
        "skipped": skipped,
        "budget_s": budget,
    }


def run_scaling(cfg: ScalingConfig, out: Path, progress=None) -> dict:
    """Measure the three series of `cfg`, write the files `FILES` into `out`, return the result."""
    from .run import json_safe
    from .scaling_report import scaling_charts, scaling_markdown

    say = progress or (lambda msg: None)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    result = {
        "config": dataclasses.asdict(cfg),
        "machine": {"cpus": os.cpu_count(), "load_average_start": os.getloadavg()},
    }
    result["cells"] = cells_series(cfg, say)
    result["workers"] = workers_series(cfg, say)
    result["nodes"] = nodes_series(cfg, say)
    result["machine"]["load_average_end"] = os.getloadavg()
    result["wall_time_s"] = time.perf_counter() - t0
    safe = json_safe(result)
    result["charts"] = safe["charts"] = scaling_charts(safe, out)
    (out / "scaling.json").write_text(json.dumps(safe, indent=1))
    (out / "scaling.md").write_text(scaling_markdown(safe))
    return safe
