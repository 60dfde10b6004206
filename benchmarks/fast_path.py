"""Speed and accuracy of the compiled backend against the solve_ivp reference.

Run:  python -m benchmarks.fast_path [--repeat 3] [--map 100 [--baseline-cells 1000]] [--no-compile]

The measurements live in `multimass.bench.targets` (also run by ``multimass bench``);
this entry point prints, as one JSON dict, the ones about the compiled path alone:

* ``compile``: the one-off numba compilation (fresh process, empty cache) and the
  load from the disk cache (next fresh process), never inside a timed run;
* ``S1_DD2_release``: S1 released from 0.11 rad, DD2, 10 s: one ``simulate`` call
  per backend (default options, and output_dt = None), interleaved, `--repeat`
  times (median, min, max), and each backend's largest peak difference from a
  tight solve_ivp reference;
* ``B6M_sine_map`` (with ``--map N``): the N × N overturning map, compiled on 1
  and 2 workers against one solve_ivp call per cell (timed on a seeded random
  subsample of `--baseline-cells` cells, scaled to the grid).

Timings depend on the machine and its load; compare medians.
"""

from __future__ import annotations

import argparse
import json
import os

from multimass.bench.run import json_safe
from multimass.bench.targets import compile_times, map_speedup, single_speedup

__all__ = ["main"]


def main(argv=None) -> dict:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=3, help="repeats of each ratio (median)")
    p.add_argument("--map", type=int, default=0, metavar="N", help="also the N x N B6M map")
    p.add_argument(
        "--baseline-cells",
        type=int,
        default=1000,
        metavar="K",
        help="map baseline: solve_ivp calls timed on K random cells (0: every cell)",
    )
    p.add_argument(
        "--no-compile", action="store_true", help="skip the fresh-process compile timing"
    )
    args = p.parse_args(argv)
    result = {
        "compile": compile_times(cold=not args.no_compile),
        "S1_DD2_release": single_speedup(args.repeat),
    }
    if args.map:
        result["B6M_sine_map"] = map_speedup(args.map, args.baseline_cells or None, args.repeat)
    result["load_average"] = os.getloadavg()
    print(json.dumps(json_safe(result), indent=2))
    return result


if __name__ == "__main__":
    main()
