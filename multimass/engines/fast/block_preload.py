"""Import this module to have the batched rigid-block kernels ready (for a forkserver to preload).

The companion of `multimass.engines.fast.preload` for `multimass.engines.fast.block_runs`: importing
it calls `ensure_ready()`, so the workers of a batched overturning map start with
the batch kernels in memory instead of each loading them from the disk cache.
"""

from .block_runs import ensure_ready

__all__ = ["REPORT"]

#: What warming up cost in the process that imported this module.
REPORT = ensure_ready()
