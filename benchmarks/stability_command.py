"""The ``multimass stability`` command, start to finish, against the batched kernel.

Run:  python -m benchmarks.stability_command [--n 100] [--small-n 20] [--repeat 3]

In one run (`multimass.bench.command_speed`, whose docstring says what is timed):
(a) the command ``multimass stability B6M --pulse sine --omega-p 0.5:10:100 --amp
0.25:8:100 --executor serial --json`` as a subprocess, wall time start to exit over its
n_simulations; (b) the batched kernel per cell on the same cells; (c) the 20 × 20 map on
the solve_ivp path and on the compiled path, per simulation, outcome for outcome.
Targets: (a)/(b) ≤ 1.3, (c) ≥ 150×. Prints one JSON dict (median, min, max of the repeats).
"""

from __future__ import annotations

import argparse
import json

__all__ = ["main"]


def main(argv=None) -> dict:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=int, default=100, help="the command's map: n x n (default 100)")
    p.add_argument("--small-n", type=int, default=20, help="solve_ivp vs compiled map (20)")
    p.add_argument("--repeat", type=int, default=3, help="repeats (median, min, max)")
    args = p.parse_args(argv)
    from multimass.bench.command_speed import measure
    from multimass.bench.run import json_safe

    result = measure(args.n, args.small_n, args.repeat, progress=print)
    print(json.dumps(json_safe(result), indent=2))
    return result


if __name__ == "__main__":
    main()
