"""Import this module to have the compiled kernels ready (for a forkserver to preload).

Importing it calls `multimass.engines.fast.warm_up()` — a deliberate import side effect
(the package's other one: `multimass.engines.fast.compile` choosing numba's cache folder
before any kernel is defined): the sweep engine asks a forkserver to import it, so the
kernels are loaded once in the server and every worker forked from it starts
with them in memory instead of loading the disk cache itself. On a machine whose
cache is empty, the server compiles them once and its compile notice (see
`multimass.engines.fast.compile`) goes to the terminal the sweep was started from.
"""

from .compile import warm_up

__all__ = ["REPORT"]

#: What warming up cost in the process that imported this module.
REPORT = warm_up()
