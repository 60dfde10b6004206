"""One-off compilation of the kernels, cached on disk, timed apart from the runs.

The kernels are ``numba.njit(cache=True)``: the first process that calls them
compiles them (tens of seconds) and writes the machine code to numba's cache
(``__pycache__`` beside the sources, or ``NUMBA_CACHE_DIR``); later
processes load it (well under a second). `warm_up` does that once per
process, on a tiny problem whose argument types are those of every real call,
and says how long it took and whether the code came from the cache.
`multimass.simulate` calls it before starting its clock, so
``Response.wall_time_s`` never includes compilation.

Numba keys a cached function on the file that defines it, not on the files of
the functions it calls: after an edit of `._maths` or `._rk` (or an upgrade)
the cached `._kernel.integrate_phase` would be stale. `warm_up` therefore keeps
a fingerprint of the kernel sources, of the equations they compile
(`multimass.equations`, `multimass.impact_models.gaussian_force`) and of
numba's version beside the cache, and drops the cached kernels when it changes.
"""

from __future__ import annotations

import hashlib
import time
from dataclasses import dataclass
from pathlib import Path

import numba
import numpy as np

from . import _maths as mx

__all__ = ["warm_up", "CompileReport"]


@dataclass(frozen=True)
class CompileReport:
    """How the compiled kernels became ready in this process.

    Attributes
    ----------
    seconds : float
        Time to compile or load them (0 if they were ready already).
    source : {"compiled", "disk cache", "in memory"}
        "compiled": built now (and written to the disk cache); "disk cache":
        loaded from it; "in memory": this process had them already.
    cache_dir : str
        Where numba keeps the cached machine code.
    """

    seconds: float
    source: str
    cache_dir: str

    def to_dict(self) -> dict:
        return {"seconds": self.seconds, "source": self.source, "cache_dir": self.cache_dir}


_REPORT: CompileReport | None = None
_MODULES = ("_maths", "_rk", "_kernel")  # the modules holding njit(cache=True) code
_STAMP = "multimass_fast.sources"


def _fingerprint() -> str:
    h = hashlib.sha256(numba.__version__.encode())
    for mod in _MODULES:
        h.update((Path(__file__).parent / f"{mod}.py").read_bytes())
    for mod in (mx.eq, mx.gf):  # the equations the kernels compile
        h.update(Path(mod.__file__).read_bytes())
    return h.hexdigest()


def _drop_stale_cache(cache_dir: Path, stamp: str) -> None:
    """Delete the cached kernels if the sources changed since they were compiled."""
    try:
        if (cache_dir / _STAMP).read_text() == stamp:
            return
    except OSError:
        pass
    for mod in _MODULES:
        for f in cache_dir.glob(f"{mod}.*.nb[ic]"):
            try:
                f.unlink()
            except OSError:  # another process got there first, or read-only
                pass


def _tiny_call() -> None:
    """Call the kernel once with the argument types of every real call (1 node, rocking)."""
    from ._kernel import integrate_phase

    one, eye = np.ones(1), np.eye(1)
    mp = np.array([2.0, 1.0, 1.0, 1.0, 0.2, 9.81, 0.0, 0.0])
    y0 = np.array([0.0, 0.01, 0.0, 0.0, 0.0, 0.0, 0.0])
    codes = np.array([mx.EV_ZERO, mx.EV_PEAK, mx.EV_ACTIVATE], dtype=np.int64)
    integrate_phase(
        0.0,
        1e-3,
        y0,
        np.array([1e-3]),
        1,
        one,
        one,
        eye * 1e4,
        eye,
        mp,
        np.zeros(mx.FP_SIZE),
        codes,
        np.array([-1.0, 0.0, -1.0]),
        np.array([1, 0, 1], dtype=np.int64),
        np.array([1.0, 0.0, 1.0]),
        np.full(3, -np.inf),
        np.zeros(mx.EP_SIZE) + 1.0,
        mx.EXC_NONE,
        np.zeros(4),
        np.zeros(2),
        2,
        1e-8,
        1e-10,
        5e-3,
    )


def warm_up() -> CompileReport:
    """Compile (or load from the disk cache) the kernels of the compiled backend.

    Returns
    -------
    CompileReport
        Seconds spent and where the code came from. Later calls in the same
        process return the first report's cache directory with ``seconds`` 0
        and source "in memory".
    """
    global _REPORT
    from ._kernel import integrate_phase

    if _REPORT is not None:
        return CompileReport(0.0, "in memory", _REPORT.cache_dir)
    start = time.perf_counter()
    cache_dir, stamp = Path(integrate_phase.stats.cache_path), _fingerprint()
    _drop_stale_cache(cache_dir, stamp)
    _tiny_call()
    seconds = time.perf_counter() - start
    stats = integrate_phase.stats
    source = "disk cache" if stats.cache_hits and not stats.cache_misses else "compiled"
    try:
        (cache_dir / _STAMP).write_text(stamp)
    except OSError:
        pass
    _REPORT = CompileReport(seconds, source, str(cache_dir))
    return _REPORT
