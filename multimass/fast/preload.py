"""Import this module to have the compiled kernels ready (for a forkserver to preload).

Importing it calls `multimass.fast.warm_up()` — the one deliberate import side
effect in the package: the sweep engine asks a forkserver to import it, so the
kernels are loaded once in the server and every worker forked from it starts
with them in memory instead of loading the disk cache itself.
"""

from .compile import warm_up

__all__ = ["REPORT"]

#: What warming up cost in the process that imported this module.
REPORT = warm_up()
