"""Cost of the sweep executors: pool start, per-job overhead, scaling with workers.

Run:  python -m benchmarks.sweep_overhead [--jobs 400] [--no-dask]

Prints
1. the time of a first sweep on a fresh 2-process pool for each start method
   (fork / forkserver / spawn), i.e. the start-up a sweep pays;
2. the per-job overhead of each executor on a trivial job (identity), with
   the default batching and with one job per task (batch_size=1), on a warm
   pool or cluster;
3. the speed-up of the process pool with 2 workers over 1 on a CPU-bound job
   (a Duffing oscillator integrated by solve_ivp, ~5 ms) × 400.
4. with --fork-hazard: why the pool does not fork by default — after a numba
   ``parallel=True`` kernel has run in the parent (OpenMP threading layer),
   forked workers abort; forkserver workers do not.
Timings are the best of `--repeat` runs; they depend on the machine and load
(the 1-minute load average is printed).
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import time

import numba
import numpy as np
from scipy.integrate import solve_ivp

from multimass.sweeps import DaskExecutor, ExecutorError, ProcessExecutor, run_jobs

__all__ = ["identity", "duffing", "timed_duffing", "parallel_sum", "main"]


def identity(x):
    """The trivial job."""
    return x


def _duffing_rhs(t, y):
    return [y[1], -0.05 * y[1] - y[0] - y[0] ** 3 + 0.3 * np.cos(1.2 * t)]


def duffing(t_end: float) -> float:
    """A CPU-bound job: a forced Duffing oscillator to `t_end`; returns the end displacement."""
    sol = solve_ivp(_duffing_rhs, (0.0, t_end), [0.1, 0.0], rtol=1e-8, atol=1e-10)
    return float(sol.y[0, -1])


@numba.njit(parallel=True, cache=False)
def _parallel_kernel(n):
    s = 0.0
    for i in numba.prange(n):
        s += np.sin(i * 1e-3)
    return s


def parallel_sum(n: int) -> float:
    """A job running a numba ``parallel=True`` kernel (compiled once per process)."""
    return float(_parallel_kernel(n))


def _fork_hazard_child(queue) -> None:
    parallel_sum(100_000)  # the parent now runs a threading layer
    lines = [f"threading layer in the parent: {numba.threading_layer()}"]
    for method in ("fork", "forkserver"):
        try:
            with ProcessExecutor(workers=2, start_method=method) as ex:
                run_jobs(parallel_sum, [100_000] * 4, executor=ex, batch_size=1)
            lines.append(f"{method:<11s} workers ran the kernel")
        except ExecutorError as exc:
            lines.append(f"{method:<11s} FAILED: {str(exc.__cause__)[:70]}")
    queue.put(lines)


def fork_hazard() -> None:
    print("4. sweeps after a numba parallel kernel ran in the parent")
    ctx = multiprocessing.get_context("spawn")  # keep this parent clean
    queue = ctx.Queue()
    child = ctx.Process(target=_fork_hazard_child, args=(queue,))
    child.start()
    for line in queue.get(timeout=300):
        print("  ", line)
    child.join()


def _best(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def start_methods() -> None:
    print("1. first sweep on a fresh 2-process pool (start + first tasks)")
    for method in multiprocessing.get_all_start_methods():

        def sweep(method=method):
            with ProcessExecutor(workers=2, start_method=method) as ex:
                run_jobs(duffing, [0.1, 0.1], executor=ex, batch_size=1)

        t = _best(sweep, 3)
        print(f"   {method:<11s} {t * 1e3:8.0f} ms")


def overhead(executors: dict, n: int, repeat: int) -> None:
    print(f"2. per-job overhead on a trivial job, {n} jobs, warm executors")
    jobs = list(range(n))
    for name, ex in executors.items():
        for batch_size in (None, 1):
            t = _best(
                lambda ex=ex, batch_size=batch_size: run_jobs(
                    identity, jobs, executor=ex, batch_size=batch_size, progress=False
                ),
                repeat,
            )
            label = "default batches" if batch_size is None else "batch_size=1"
            print(
                f"   {name:<8s} {label:<16s} {t * 1e6 / n:9.1f} µs/job   ({t * 1e3:7.1f} ms total)"
            )


def _cpu_time(t_end: float) -> float:
    duffing(t_end)  # warm up (first-call costs)
    t = time.thread_time()  # this thread only: not Dask's threads
    for _ in range(5):
        duffing(t_end)
    return (time.thread_time() - t) / 5


def timed_duffing(t_end: float) -> float:
    """`duffing`, returning the wall time spent inside the job."""
    t = time.perf_counter()
    duffing(t_end)
    return time.perf_counter() - t


def _sweep(jobs, executor, workers: int) -> tuple[float, float, float]:
    """Wall time of a sweep, the share of the workers' time spent inside jobs,
    and the mean wall time of one job (above its CPU time if the machine is busy)."""
    t = time.perf_counter()
    inside = run_jobs(timed_duffing, jobs, executor=executor)
    wall = time.perf_counter() - t
    return wall, sum(inside) / (wall * workers), sum(inside) / len(inside)


def scaling(n: int, repeat: int) -> None:
    t_end = 5.0 * 5e-3 / _cpu_time(5.0)  # calibrate to ~5 ms of CPU per job
    t_job = _cpu_time(t_end)
    jobs = [t_end] * n
    print(
        f"3. CPU-bound job of {t_job * 1e3:.1f} ms (CPU time) × {n} jobs; busy = share"
        " of the workers' time inside jobs, job = mean wall time of one job"
    )
    wall, busy, per_job = min(_sweep(jobs, "serial", 1) for _ in range(repeat))
    print(f"   serial              {wall:6.2f} s  busy {busy:4.0%}  job {per_job * 1e3:4.1f} ms")
    timings = {}
    for w in (1, 2):
        with ProcessExecutor(workers=w) as ex:
            cold = _sweep(jobs, ex, w)[0]  # includes pool start
            timings[w], busy, per_job = min(_sweep(jobs, ex, w) for _ in range(repeat))
        print(
            f"   process workers={w}  {timings[w]:6.2f} s  busy {busy:4.0%}"
            f"  job {per_job * 1e3:4.1f} ms  (warm; {cold:.2f} s with pool start)"
        )
    print(
        f"   speed-up 2 vs 1 worker (warm): {timings[1] / timings[2]:.2f}×;"
        f" 2 workers vs serial: {wall / timings[2]:.2f}×"
    )


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=400, help="jobs of the CPU-bound sweep")
    parser.add_argument("--trivial-jobs", type=int, default=4000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--no-dask", action="store_true", help="skip the Dask executor")
    parser.add_argument(
        "--fork-hazard",
        action="store_true",
        help="also show forked workers failing after a numba parallel kernel",
    )
    args = parser.parse_args(argv)
    print(f"{os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.2f}")
    start_methods()
    executors = {"serial": "serial", "process": ProcessExecutor(workers=2)}
    if not args.no_dask:
        executors["dask"] = DaskExecutor(workers=2)
    try:
        for ex in executors.values():  # warm up: start pools and clusters
            run_jobs(identity, range(8), executor=ex, batch_size=1)
        overhead(executors, args.trivial_jobs, args.repeat)
    finally:
        for ex in executors.values():
            if not isinstance(ex, str):
                ex.close()
    scaling(args.jobs, args.repeat)
    if args.fork_hazard:
        fork_hazard()


if __name__ == "__main__":
    main()
