"""Cost per step of the Moreau–Jean simulation of a block on a beam (`nscd`, paper 002).

Run:  python -m benchmarks.nscd_cost [--repeat 3] [--t-end 4]
      python -m benchmarks.nscd_cost --calibrate   (the constants of multimass.engines.nscd.cost)

Prints
1. the numba compile (or cache-load) time of the kernel, paid once per process;
2. for B6M released at 11.268° (dt = 1e-5 s, `--t-end` s): wall time per run and
   µs per step of the compiled kernel on the rigid base with 3, 6, 12 and 24
   elements, and on flexible beams E = Ē·10² and Ē·10⁰ with 6 elements;
3. µs per step of the pure-NumPy reference step (a few hundred steps), for scale.
Timings are the best of `--repeat` runs; they depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from multimass.engines import nscd
from multimass.engines.nscd import cost
from multimass.engines.nscd.model import build_system
from multimass.engines.nscd.reference import reference_run
from multimass.engines.nscd.run import run_system

__all__ = ["main", "calibrate"]

THETA0 = math.radians(11.268)  # paper 002, Section 6.2 (B6M)


def _cases():
    Ebar = nscd.flexible_modulus("B6M")
    yield "rigid base, 3 elements", {"n_elements": 3}
    yield "rigid base, 6 elements", {"n_elements": 6}
    yield "rigid base, 12 elements", {"n_elements": 12}
    yield "rigid base, 24 elements", {"n_elements": 24}
    yield "E = Ebar·10^2, 6 elements", {"n_elements": 6, "E": 1e2 * Ebar}
    yield "E = Ebar·10^0, 6 elements", {"n_elements": 6, "E": Ebar}


def calibrate(n_elements=(3, 6, 12, 24, 48, 96, 192), setup_elements=(96, 192, 384)) -> None:
    """Time the kernel and the assembly on this machine and fit the constants (prints)."""
    theta0 = math.radians(11.268)  # B6M, paper 002, Section 6.2
    run_system(build_system("B6M", theta0=theta0, dt=1e-3), 0.01)  # load the compiled kernel
    rows = []
    for n_el in n_elements:
        sys = build_system("B6M", theta0=theta0, dt=1e-5, n_elements=n_el)
        steps = int(min(4e5, 2e8 / cost.n_dof(n_el) ** 2))
        best = min(run_system(sys, steps * 1e-5, progress=False).kernel_time_s for _ in range(2))
        rows.append((cost.n_dof(n_el), best / steps))
        print(
            f"{n_el:5d} elements: {1e6 * best / steps:9.3f} µs/step "
            f"(model {1e6 * cost.step_seconds(n_el):9.3f})",
            flush=True,
        )
    n, t = np.array(rows).T
    c0, c2 = np.linalg.lstsq(np.column_stack([1 / t, n**2 / t]), np.ones_like(t), rcond=None)[0]
    print(f"relative least squares: STEP_S = {c0:.3g} s, STEP_S_PER_N2 = {c2:.3g} s")
    for n_el in setup_elements:
        t0 = time.perf_counter()
        build_system("B6M", theta0=theta0, dt=1e-5, n_elements=n_el)
        wall = time.perf_counter() - t0
        print(
            f"{n_el:5d} elements: set-up {wall:.2f} s = {1e9 * wall / cost.n_dof(n_el) ** 3:.2f} ns · n³"
        )


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument(
        "--calibrate",
        action="store_true",
        help="fit the constants of multimass.engines.nscd.cost on this machine instead",
    )
    ap.add_argument("--t-end", type=float, default=4.0)
    ap.add_argument("--dt", type=float, default=1e-5)
    args = ap.parse_args(argv)
    if args.calibrate:
        calibrate()
        return
    t0 = time.perf_counter()
    nscd.simulate("B6M", theta0=THETA0, dt=1e-3, t_end=0.01)
    print(f"numba kernel compile / cache load: {time.perf_counter() - t0:.2f} s")
    print(
        f"B6M, θ0 = 11.268°, dt = {args.dt:g} s, t_end = {args.t_end:g} s "
        f"({round(args.t_end / args.dt)} steps)"
    )
    print(f"{'case':28s} {'s/run':>7s} {'µs/step':>8s} {'GS max':>6s} {'2-contact steps':>15s}")
    for name, kw in _cases():
        best = None
        for _ in range(args.repeat):
            res = nscd.simulate("B6M", theta0=THETA0, dt=args.dt, t_end=args.t_end, **kw)
            if best is None or res.kernel_time_s < best.kernel_time_s:
                best = res
        print(
            f"{name:28s} {best.kernel_time_s:7.2f} {best.cost_per_step_us:8.2f} "
            f"{best.max_gs_iterations:6d} {best.n_multi_contact_steps:15d}"
        )
    sys = build_system("B6M", theta0=0.003, dt=1e-4, n_elements=6)
    n = 200
    t0 = time.perf_counter()
    reference_run(sys, n)
    print(
        f"NumPy reference step, rigid base, 6 elements: "
        f"{1e6 * (time.perf_counter() - t0) / n:.0f} µs/step"
    )


if __name__ == "__main__":
    main()
