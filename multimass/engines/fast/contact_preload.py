"""Import this module to have the closed-form full contact ready (for a forkserver to preload).

The companion of `multimass.engines.fast.preload` for `multimass.engines.fast.compile.warm_up_contact`:
sweeps of columns (spectra, suites) ask their pool's forkserver to import it, so its
workers start with the kernel in memory, and a cold machine compiles it once, in the
server, with one notice.
"""

from .compile import warm_up_contact

__all__ = ["REPORT"]

#: What warming up cost in the process that imported this module.
REPORT = warm_up_contact()
