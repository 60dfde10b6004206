"""Process pools for the compiled sweeps of spectra and suites, their kernels loaded once.

A process pool's workers fork from a forkserver that imports the job's module and the
compiled kernels the runs call (`ProcessExecutor`'s ``preload``), so each worker starts
with them in memory. Which kernels (`preload_modules`):

* a column's whole runs call the column kernel only (`multimass.engines.fast.column_preload`),
  and under a record the closed-form full contact (`multimass.engines.fast.contact_preload`);
  the per-phase kernels load in a worker only if a run falls back to the phase loop;
* a rigid block's runs call the per-phase kernels (`multimass.engines.fast.preload`), a
  suite's batched block runs the batch kernels (`multimass.engines.fast.block_preload`).

Loading them is most of a pool's start: a fresh interpreter importing the column's two
took 3.4 s, and 3.8 s with the per-phase kernels too (2-core machine, loaded), which whole
column runs no longer load.
"""

from __future__ import annotations

from contextlib import contextmanager

from .base import Executor
from .executors import get_executor

__all__ = ["preload_modules", "kernel_session"]

_FAST = "multimass.engines.fast."


def preload_modules(column: bool, record: bool, batched: bool = False) -> tuple[str, ...]:
    """The modules a pool's forkserver imports for the compiled runs of a sweep.

    Parameters
    ----------
    column : bool
        A column (N ≥ 1): whole runs; else a rigid block.
    record : bool
        The ground motions include records (a column's full contact in closed form).
    batched : bool
        A block's runs in compiled batches (suites).
    """
    if column:
        return tuple(
            _FAST + m for m in (("contact_preload",) if record else ()) + ("column_preload",)
        )
    return tuple(_FAST + m for m in ("preload",) + (("block_preload",) if batched else ()))


@contextmanager
def kernel_session(executor, workers, preload: tuple[str, ...] = ()):
    """One executor for a sweep's `run_jobs` calls, closed after unless the caller owns it;
    a process pool made here preloads `preload` (`preload_modules`; empty: none)."""
    if isinstance(executor, Executor):
        yield executor
        return
    options = {}
    if preload and isinstance(executor, str) and executor.lower() == "process":
        options["preload"] = preload
    ex = get_executor(executor, workers, **options)
    try:
        yield ex
    finally:
        ex.close()
