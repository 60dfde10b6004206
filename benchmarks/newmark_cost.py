"""Cost of paper 004's Newmark integrator (`multimass.engines.newmark`): Python vs numba kernel.

Run:  python -m benchmarks.newmark_cost [--repeat 5] [--map 20]

Prints
1. the numba compile (or cache-load) time of the step kernel, paid once per process;
2. for a 3 s free release of B6M and a 3 s sine-pulse response of B6M (dt = 1e-3, no
   early stop): time per run and µs per Newmark step, for both kernels;
3. a small overturning map (``--map`` × ``--map`` sine pulses of B6M, ω/p in [1, 10],
   a0/(α g) in [1, 8], η_H, t_end = pulse + 5 s, rest_after = pulse duration): mean
   time per run with each kernel and the extrapolated serial time of a 60 × 60 map.
Timings are the best of `--repeat` runs; they depend on the machine and load.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

import multimass
from multimass.engines import _newmark_kernel as kern
from multimass.engines.newmark import newmark_block
from multimass.impact_models.restitution import housner_eta
from multimass.inputs.excitations import SineWave

__all__ = ["main"]


def _best(fn, repeat):
    best, out = math.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def _runs(repeat):
    st = multimass.rigid_block("B6M")
    eta, alpha, p = housner_eta(st.alpha_cg), st.alpha_cg, st.p
    pulse = SineWave(amplitude=1.5 * alpha * st.g, omega=4 * p)
    cases = {
        "free release 11.268°, 3 s": dict(ag=lambda t: 0.0, theta0=math.radians(11.268)),
        "sine pulse ω=4p a0=1.5αg, 3 s": dict(ag=pulse),
    }
    print(f"{'case':34s} {'engine':7s} {'ms/run':>8s} {'steps':>6s} {'µs/step':>8s} {'events':>6s}")
    for name, kw in cases.items():
        for engine in ("python", "numba"):
            sec, res = _best(
                lambda kw=kw, engine=engine: newmark_block(
                    st,
                    kw["ag"],
                    3.0,
                    dt=1e-3,
                    restitution=eta,
                    theta0=kw.get("theta0", 0.0),
                    engine=engine,
                ),
                repeat,
            )
            print(
                f"{name:34s} {engine:7s} {1e3 * sec:8.2f} {res.n_steps:6d} "
                f"{1e6 * sec / res.n_steps:8.2f} {len(res.events):6d}"
            )


def _map(n, repeat):
    st = multimass.rigid_block("B6M")
    eta, alpha, p = housner_eta(st.alpha_cg), st.alpha_cg, st.p
    grid = [(w, a) for w in np.linspace(1, 10, n) for a in np.linspace(1, 8, n)]

    def sweep(engine):
        stats = {"overturned": 0, "rest": 0, "completed": 0, "failed": 0, "steps": 0}
        for w, a in grid:
            exc = SineWave(amplitude=a * alpha * st.g, omega=w * p)
            res = newmark_block(
                st,
                exc,
                exc.duration + 5.0,
                dt=1e-3,
                restitution=eta,
                rest_after=exc.duration,
                engine=engine,
            )
            stats[res.outcome] += 1  # "rest": stopped early, at rest
            stats["steps"] += res.n_steps
        return stats

    for engine in ("python", "numba"):
        sec, stats = _best(lambda engine=engine: sweep(engine), max(1, repeat // 2))
        per = sec / len(grid)
        print(
            f"map {n}x{n} {engine:7s}: {1e3 * per:7.2f} ms/run, "
            f"{1e6 * sec / max(stats['steps'], 1):6.2f} µs/step, "
            f"60x60 serial ≈ {3600 * per:6.1f} s; outcomes {stats}"
        )


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--map", type=int, default=20)
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    kern._warm_up()
    print(f"numba kernel compile / cache load: {time.perf_counter() - t0:.2f} s")
    _runs(args.repeat)
    if args.map > 0:
        _map(args.map, args.repeat)


if __name__ == "__main__":
    main()
