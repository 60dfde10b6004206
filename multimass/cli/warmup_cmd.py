"""``multimass warm-up``: compile (or load) every compiled kernel now, and say what it did.

The numba kernels compile on their first use on a machine and are cached on disk
(`multimass.engines.fast.compile`). This command does it on purpose — when building a
container image, after installing on a cluster's nodes, before timing a sweep —
and reports, for each group of kernels, whether it was compiled or loaded, how
long it took and where the machine code is kept. It also writes the bytecode of the
package's own modules (`bytecode`), which Python does not write where
``PYTHONDONTWRITEBYTECODE`` is set (as in many container images).
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

__all__ = ["register", "run", "GROUPS", "warm", "bytecode"]


def _fast(progress):
    from multimass.engines.fast import warm_up

    return warm_up(progress)


def _contact(progress):
    from multimass.engines.fast import warm_up_contact

    return warm_up_contact(progress)


def _columns(progress):
    from multimass.engines.fast import warm_up_columns

    return warm_up_columns(progress)


def _blocks(progress):
    from multimass.engines.fast import block_runs
    from multimass.engines.fast.compile import compile_once

    return compile_once(
        "the batched map kernels",
        block_runs.warm_up_blocks,
        (
            "multimass.engines.fast._block_uplift",
            "multimass.engines.fast._block_segment",
            "multimass.engines.fast._block_kernel",
        ),
        progress=progress,
        estimate=15.0,
        load=0.1,
    )


def _newmark(progress):
    from multimass.engines import _newmark_kernel as kern
    from multimass.engines.fast.compile import compile_once

    kern.compiled_advance()  # defines the cached function (compiles nothing yet)
    return compile_once(
        "the Newmark kernel", kern._warm_up, ("multimass.engines._newmark_kernel",), progress=progress,
        estimate=1.0, load=0.01,
    )  # fmt: skip


def _nscd_run():
    from multimass.engines import nscd

    nscd.simulate("B6M", theta0=math.radians(11.268), dt=1e-3, t_end=3e-3, progress=False)


def _nscd(progress):
    from multimass.engines.fast.compile import compile_once

    modules = (
        "multimass.engines.nscd.geometry",
        "multimass.engines.nscd.contact",
        "multimass.engines.nscd.kernel",
    )
    return compile_once(
        "the Moreau-Jean kernels", _nscd_run, modules, progress=progress, estimate=12.0, load=0.1
    )


#: name → (what it serves, warm-up function); warmed in this order.
GROUPS = {
    "fast": ("simulate(..., backend='compiled'), spectra, sweeps", _fast),
    "contact": ("a column's full contact in closed form (records, releases)", _contact),
    "columns": ("a column's whole run in one call: simulate, spectra, suites", _columns),
    "blocks": ("overturning maps of rigid blocks, batched", _blocks),
    "newmark": ("simulate(..., integrator='newmark')", _newmark),
    "nscd": ("multimass nscd (block on a beam)", _nscd),
}


def register(sub) -> None:
    p = sub.add_parser(
        "warm-up",
        help="compile (or load) every compiled kernel now, and say what it did",
        description="The compiled kernels (numba) are built the first time a machine uses "
        "them — about 17 s for the fast path, about 50 s for all of them — and "
        "cached on disk; later runs load them in well under a second. This command "
        "does it now (for a container image, a cluster's nodes, before timing a run) "
        "and prints, for each group, whether it was compiled or loaded, the seconds "
        "and the cache folder. Where the cache goes: NUMBA_CACHE_DIR if set; else "
        "__pycache__ beside the package's sources; if that folder is read-only, the "
        "per-user cache ($XDG_CACHE_HOME or ~/.cache)/multimass/numba. A first use "
        "prints a notice with a progress bar while it compiles; set MULTIMASS_QUIET=1 "
        "to silence it. It also writes the bytecode of multimass's own modules, which "
        "Python does not write itself where PYTHONDONTWRITEBYTECODE is set. Groups: "
        + "; ".join(f"{name}: {serves}" for name, (serves, _) in GROUPS.items())
        + ".",
    )
    p.add_argument(
        "--only",
        metavar="GROUP",
        action="append",
        choices=tuple(GROUPS),
        help=f"warm only this group (repeatable; one of {', '.join(GROUPS)}; default all)",
    )
    p.add_argument(
        "--json", action="store_true", help="print a JSON object (cache folder, one row a group)"
    )
    p.set_defaults(func=run)


def bytecode() -> dict:
    """Write the bytecode (``__pycache__/*.pyc``) of multimass's own modules where it is
    missing or older than its source.

    Python writes it at a module's first import, unless ``PYTHONDONTWRITEBYTECODE`` is
    set; then every run compiles the sources of the ~90 modules a command imports again
    (~0.1 s of the start-up of ``multimass stability``; docs/guide/speed.md). pip writes
    it when it installs a wheel; a source checkout or an editable install relies on the
    first import.

    Returns
    -------
    dict
        ``folder`` (the package's), ``written`` (False if some file could not be
        written, e.g. a read-only folder: Python then compiles those sources at each
        import, as before) and ``seconds``.
    """
    import compileall

    import multimass

    start = time.perf_counter()
    folder = Path(multimass.__file__).parent
    ok = compileall.compile_dir(folder, quiet=2)  # skips the files whose bytecode is fresh
    return {"folder": str(folder), "written": bool(ok), "seconds": time.perf_counter() - start}


def warm(names=None, progress: bool | None = None) -> dict:
    """Warm the groups `names` (default all, in the order of `GROUPS`).

    Returns
    -------
    dict
        ``cache`` (the folder numba writes to and why), ``groups`` (one
        `multimass.engines.fast.CompileReport` as a dict per group, with its ``group``
        name), ``bytecode`` (`bytecode`, whatever the groups) and ``seconds`` (the total).
    """
    from multimass.engines.fast.compile import CACHE

    start = time.perf_counter()
    rows = []
    for name in [g for g in GROUPS if names is None or g in names]:
        report = GROUPS[name][1](progress)
        rows.append({"group": name} | report.to_dict())
    return {
        "cache": {"numba_cache_dir": CACHE.path, "reason": CACHE.reason},
        "groups": rows,
        "bytecode": bytecode(),
        "seconds": time.perf_counter() - start,
    }


def _line(r: dict) -> str:
    if r["source"] == "in memory":
        return "already in memory"
    if r["source"] == "disk cache":
        return f"loaded from the cache in {r['seconds']:.2f} s"
    return f"compiled in {r['seconds']:.1f} s ({r['kernels_compiled']} kernels)"


def run(args) -> int:
    out = warm(args.only)
    if args.json:
        print(json.dumps(out, indent=1))
        return 0
    width = max(len(r["what"]) for r in out["groups"])
    for r in out["groups"]:
        print(f"{r['what']:<{width}}  {_line(r)}  [{r['group']}]")
        print(f"{'':<{width}}  cache: {r['cache_dir']}")
    b = out["bytecode"]
    print(
        f"bytecode of multimass's modules {'up to date' if b['written'] else 'NOT all written'} "
        f"in {b['seconds']:.1f} s: {b['folder']}"
    )
    print(f"ready in {out['seconds']:.1f} s; numba's cache: {out['cache']['reason']}")
    return 0
