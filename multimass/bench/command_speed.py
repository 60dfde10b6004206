"""What a user waits for: the ``multimass stability`` command against the batched kernel.

Three figures, each a ratio measured within one run, repeated (median, min, max):

* ``command_over_kernel`` — the command ``multimass stability B6M --pulse sine --omega-p
  0.5:10:N --amp 0.25:8:N --executor serial --json`` run as a subprocess, its wall time
  from start to exit over its ``n_simulations``, against the batched kernel's cost per
  cell (`multimass.engines.fast.block_runs.run_pulses`, warm, in this process) on the
  same cells: the grid and the boundary cells the command refined (target ≤ 1.3 at
  N = 100). Also in CPU time (the child's user + system time over this process's CPU
  time in the kernel), which other jobs on a shared machine change less than wall time;
  and the command's own breakdown (its JSON: ``wall_time_s`` from its process start,
  ``map_wall_time_s`` the `overturning_map` call, ``simulation_time_s`` its cells).
* ``scipy_over_compiled`` — the same map at n × n (``--n 20``), in this process on the
  serial executor: the solve_ivp path (``backend="scipy"``, one `simulate_outcome` per
  cell) over the compiled path (batched), both per simulation, each the whole
  `overturning_map` call (target ≥ 150×). ``identical_outcomes``: the two maps give
  the same outcome (and impacts) in every cell, grid and refinement alike.

``breakdown_s`` splits the command's time (spawn and exit, start-up to the map, the map
outside its cells, the cells outside the kernel: numba's target start-up and the
kernel's cache load happen at the first compiled call, in the cells); ``start_up_floor_s``
times, in a fresh process, what every run pays before its first cell: the interpreter,
the imports of numpy, numba and multimass, numba's target start-up and loading the
kernel from its cache. ``floor_over_kernel`` is the ratio the command would reach if
everything but the kernel, the interpreter and numba's import and start-up (numpy, its
target, the cache load: `FLOOR_PARTS`) cost nothing.

``python -m benchmarks.stability_command`` or ``multimass bench --command --out DIR``.
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

from .targets import spread

__all__ = [
    "command_argv",
    "run_command",
    "kernel_per_cell",
    "small_maps",
    "startup_floor",
    "measure",
    "TARGETS",
    "FLOOR_PARTS",
]

#: ``command_over_kernel`` at most, ``scipy_over_compiled`` at least
TARGETS = {"command_over_kernel": 1.3, "scipy_over_compiled": 150.0}
#: The parts of `startup_floor` that no change to multimass removes (``floor_over_kernel``).
FLOOR_PARTS = ("interpreter", "numpy", "numba", "numba_target", "kernel_cache_load")


def command_argv(n: int) -> list[str]:
    """The ``multimass stability`` command of an n × n map, as a subprocess runs it: the
    console script installed beside this Python if there is one, else this Python
    calling the same entry point."""
    script = Path(sys.executable).with_name("multimass")
    head = (
        [str(script)]
        if script.is_file()
        else [sys.executable, "-c", "import sys; from multimass.cli import main; sys.exit(main())"]
    )
    return head + [
        "stability", "B6M", "--pulse", "sine", "--omega-p", f"0.5:10:{n}",
        "--amp", f"0.25:8:{n}", "--executor", "serial", "--json",
    ]  # fmt: skip


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_command(argv: list[str]) -> dict:
    """Run the command once: wall and CPU seconds start to exit, and its JSON."""
    cpu0, t0 = _children_cpu(), time.perf_counter()
    done = subprocess.run(argv, capture_output=True, text=True)
    wall, cpu = time.perf_counter() - t0, _children_cpu() - cpu0
    if done.returncode:
        raise RuntimeError(f"{' '.join(argv)} exited {done.returncode}: {done.stderr[-2000:]}")
    return {"wall_s": wall, "cpu_s": cpu, "json": json.loads(done.stdout)}


_FLOOR = """
import json, sys, time
from multimass.cli._clock import process_start
t = [process_start(), time.perf_counter()]
import numpy
t.append(time.perf_counter())
import numba
t.append(time.perf_counter())
import multimass.cli.stability_cmd, multimass.sweeps.maps, multimass.engines.fast.block_runs
t.append(time.perf_counter())
from numba.core.registry import cpu_target
cpu_target.target_context.refresh()  # numba's own start-up before any kernel runs or loads
t.append(time.perf_counter())
from multimass.engines.fast.block_runs import ensure_ready
ensure_ready()
t.append(time.perf_counter())
names = ["interpreter", "numpy", "numba", "multimass", "numba_target", "kernel_cache_load"]
out = dict(zip(names, [b - a for a, b in zip(t, t[1:])]))
out["cpu_total"] = time.process_time()  # the process's CPU time so far, start-up included
out["command_imports"] = [m for m in ("scipy.integrate", "pandas") if m in sys.modules]
t0 = time.perf_counter()
import scipy.integrate
t1 = time.perf_counter()
import pandas
out["not_imported_scipy_integrate"], out["not_imported_pandas"] = t1 - t0, time.perf_counter() - t1
print(json.dumps(out))
"""


def startup_floor() -> dict:
    """What any run of the command pays before its first cell, in a fresh process (s): the
    interpreter's start, numpy, numba, the command's multimass modules, numba's target
    start-up (its registries, loaded before any kernel can run or load from the cache;
    they import scipy.linalg to find BLAS), then loading the batched kernel from the
    cache; ``cpu_total``, the CPU time of all of it; ``command_imports``, which of
    scipy.integrate and pandas it imported (none since the command stopped needing them);
    and what importing those two would cost on top (``not_imported_*``)."""
    done = subprocess.run([sys.executable, "-c", _FLOOR], capture_output=True, text=True)
    if done.returncode:
        raise RuntimeError(f"the start-up probe failed: {done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def _map(n: int, **options):
    import multimass
    from multimass.sweeps.maps import overturning_map

    from .targets import map_axes

    omega_p, amp = map_axes(n)  # the ranges of the command: 0.5:10:n, 0.25:8:n
    return overturning_map(
        multimass.rigid_block("B6M"), "sine", omega_p, amp, refine=2, executor="serial",
        progress=False, **options,
    )  # fmt: skip


def kernel_per_cell(cells) -> dict:
    """The batched kernel alone on these cells (``omega_p``, ``amp`` columns of a map's
    cells table), in one call: wall and CPU seconds per cell, and its outcomes."""
    import multimass
    from multimass.engines._run import QUIET_DELAY
    from multimass.engines.fast.block_runs import OUTCOMES, BlockRuns, run_pulses
    from multimass.sweeps.map_cells import UNDECIDED_RETRY
    from multimass.sweeps.maps import default_backend

    st = multimass.rigid_block("B6M")
    runs = BlockRuns.of(
        st, default_backend({"impact": "CIM", "restitution": "modified", "k": None}),
        QUIET_DELAY, UNDECIDED_RETRY,
    )  # fmt: skip
    w = cells.omega_p.to_numpy() * st.p  # as the map's chunks compute them
    a0 = cells.amp.to_numpy() * (st.alpha_cg * st.g)
    run_pulses(runs, "sine", a0[:4], w[:4], 10.0)  # loaded
    cpu0, t0 = time.process_time(), time.perf_counter()
    b = run_pulses(runs, "sine", a0, w, 10.0)
    wall, cpu = time.perf_counter() - t0, time.process_time() - cpu0
    return {
        "wall_s_per_cell": wall / w.size,
        "cpu_s_per_cell": cpu / w.size,
        "outcomes": [OUTCOMES[c] for c in b.outcome.tolist()],
    }


def small_maps(n: int) -> dict:
    """The n × n map on the solve_ivp path and on the compiled path: seconds per
    simulation of each whole call, and whether every cell has the same outcome."""
    scipy_map = _map(n, backend="scipy")
    compiled = _map(n)
    a, b = scipy_map.cells, compiled.cells
    same = len(a) == len(b) and bool(
        (a.omega_p.to_numpy() == b.omega_p.to_numpy()).all()
        and (a.amp.to_numpy() == b.amp.to_numpy()).all()
        and (a.outcome.to_numpy() == b.outcome.to_numpy()).all()
    )
    return {
        "scipy_s_per_simulation": scipy_map.wall_time_s / scipy_map.n_simulations(),
        "compiled_s_per_simulation": compiled.wall_time_s / compiled.n_simulations(),
        "n_simulations": [scipy_map.n_simulations(), compiled.n_simulations()],
        "identical_outcomes": same,
        "identical_impacts": same
        and bool((a.n_impacts.to_numpy() == b.n_impacts.to_numpy()).all()),
    }


def measure(n: int = 100, small_n: int = 20, repeats: int = 3, progress=None) -> dict:
    """The figures of the module docstring, `repeats` times each, interleaved."""
    say = progress or (lambda msg: None)
    argv = command_argv(n)
    say(f"warming up: {' '.join(argv)}")
    from multimass.engines.fast.block_runs import ensure_ready

    # a cold cache compiles the batched kernel here, not in a timed run; the command (a map
    # too small to pay for that compile, `map_cells.BATCH_COMPILE_CELLS`) then loads it
    ensure_ready()
    first = run_command(argv)
    cells = _map(n).cells  # the command's cells: grid and refinement
    if len(cells) != first["json"]["n_simulations"]:
        raise RuntimeError("the in-process map and the command simulate different cells")
    _map(small_n)  # kernels loaded, pool-free
    rows = []
    for r in range(repeats):
        order = ("command", "kernel") if r % 2 == 0 else ("kernel", "command")
        got = {"load_average": os.getloadavg()[0]}
        for what in order:
            got[what] = run_command(argv) if what == "command" else kernel_per_cell(cells)
        got["small"] = small_maps(small_n)
        got["floor"] = startup_floor()
        rows.append(got)
        c, k, s = got["command"], got["kernel"], got["small"]
        n_sim = c["json"]["n_simulations"]
        say(
            f"repeat {r + 1}: command {c['wall_s']:.2f} s ({1e3 * c['wall_s'] / n_sim:.3f} ms "
            f"per simulation), kernel {1e3 * k['wall_s_per_cell']:.3f} ms per cell; "
            f"{small_n}x{small_n}: solve_ivp {1e3 * s['scipy_s_per_simulation']:.2f} ms, "
            f"compiled {1e3 * s['compiled_s_per_simulation']:.3f} ms per simulation"
        )
    same_as_kernel = all(
        r["kernel"]["outcomes"] == list(cells.outcome.to_numpy(dtype=object)) for r in rows
    )
    return _report(argv, n, small_n, rows, same_as_kernel)


def _report(argv, n, small_n, rows, same_as_kernel) -> dict:
    per_sim = lambda r: r["command"]["wall_s"] / r["command"]["json"]["n_simulations"]  # noqa: E731
    cpu_sim = lambda r: r["command"]["cpu_s"] / r["command"]["json"]["n_simulations"]  # noqa: E731
    js = [r["command"]["json"] for r in rows]
    kernel = [r["kernel"]["wall_s_per_cell"] * j["n_simulations"] for r, j in zip(rows, js)]
    ratio = spread([per_sim(r) / r["kernel"]["wall_s_per_cell"] for r in rows])
    speedup = spread(
        [
            r["small"]["scipy_s_per_simulation"] / r["small"]["compiled_s_per_simulation"]
            for r in rows
        ]
    )
    return {
        "command": " ".join(["multimass"] + argv[argv.index("stability") :]),
        "argv": argv,
        "repeats": len(rows),
        "n_simulations": js[0]["n_simulations"],
        "command_over_kernel": ratio,
        "command_over_kernel_cpu": spread(
            [cpu_sim(r) / r["kernel"]["cpu_s_per_cell"] for r in rows]
        ),
        "command_ms_per_simulation": spread([1e3 * per_sim(r) for r in rows]),
        "command_cpu_ms_per_simulation": spread([1e3 * cpu_sim(r) for r in rows]),
        "kernel_ms_per_cell": spread([1e3 * r["kernel"]["wall_s_per_cell"] for r in rows]),
        "kernel_cpu_ms_per_cell": spread([1e3 * r["kernel"]["cpu_s_per_cell"] for r in rows]),
        "floor_over_kernel": spread(
            [(sum(r["floor"][p] for p in FLOOR_PARTS) + k) / k for r, k in zip(rows, kernel)]
        ),
        "kernel_outcomes_as_command": same_as_kernel,
        "breakdown_s": {
            "subprocess_wall": spread([r["command"]["wall_s"] for r in rows]),
            "command_wall_time_s": spread([j["wall_time_s"] for j in js]),
            "map_wall_time_s": spread([j["map_wall_time_s"] for j in js]),
            "simulation_time_s": spread([j["simulation_time_s"] for j in js]),
            "kernel_on_its_cells": spread(kernel),
            # the differences: where the command's time goes besides the kernel
            "spawn_and_exit": spread(
                [r["command"]["wall_s"] - j["wall_time_s"] for r, j in zip(rows, js)]
            ),
            "start_up_to_the_map": spread([j["wall_time_s"] - j["map_wall_time_s"] for j in js]),
            "map_outside_the_cells": spread(
                [j["map_wall_time_s"] - j["simulation_time_s"] for j in js]
            ),
            "cells_outside_the_kernel": spread(
                [j["simulation_time_s"] - k for j, k in zip(js, kernel)]
            ),
        },
        "start_up_floor_s": {
            key: spread([r["floor"][key] for r in rows])
            for key in rows[0]["floor"]
            if key != "command_imports"
        },
        # of scipy.integrate and pandas, those the command's start-up imported
        "start_up_imports": sorted({m for r in rows for m in r["floor"]["command_imports"]}),
        "small_map": {
            "case": f"B6M sine map {small_n}x{small_n}, refine 2, serial, in this process",
            "scipy_over_compiled": speedup,
            "scipy_ms_per_simulation": spread(
                [1e3 * r["small"]["scipy_s_per_simulation"] for r in rows]
            ),
            "compiled_ms_per_simulation": spread(
                [1e3 * r["small"]["compiled_s_per_simulation"] for r in rows]
            ),
            "n_simulations": rows[0]["small"]["n_simulations"],
            "identical_outcomes": all(r["small"]["identical_outcomes"] for r in rows),
            "identical_impacts": all(r["small"]["identical_impacts"] for r in rows),
        },
        "targets": TARGETS,
        "pass": {
            "command_over_kernel": ratio["median"] <= TARGETS["command_over_kernel"],
            "scipy_over_compiled": speedup["median"] >= TARGETS["scipy_over_compiled"],
        },
        "load_average_before_each_repeat": [r["load_average"] for r in rows],
        "cpus": os.cpu_count(),
        "map_n": n,
    }
