"""The compiled fast path of `multimass.simulate` (``backend="compiled"``).

solve_ivp stays the reference. This backend keeps the Python phase loop of
`multimass.simulate` (the transitions) and runs each phase segment —
steps, dense output, events, the output grid — in numba-compiled kernels
that follow SciPy's explicit Runge–Kutta solvers (RK23, RK45, DOP853), so the
two backends give the same events and the same `Response` up to round-off;
a column's full contact under a record or after a release is solved in
closed form by default (`multimass.engines.fast.contact_modes`, ``full_contact``).
A column whose impact model and restitution the compiled loop knows runs that loop
whole in one compiled call instead (`multimass.engines.fast.column_runs`): spectra
keep its outcome, `multimass.simulate` its log of rows, events and peaks
(`multimass.engines.fast.column_trace`) — the phase loop's result, bit for bit.

* `FastPath` — replaces one solve_ivp call (`multimass.engines.fast.path`);
* `encode` — the excitations the kernels know (`multimass.engines.fast.excitation`);
* `warm_up`, `warm_up_contact`, `warm_up_columns`, `warm_up_exponential` — compile or
  load the kernels (the closed-form contact, the whole column runs of
  `multimass.engines.fast.column_runs` and the exponential rocking integrator of
  ``method="exponential"`` are groups of their own) once per process, timed apart, with a notice and a
  progress bar when it compiles (`multimass.engines.fast.compile`).

`multimass.engines.fast.compile` is imported first, on purpose: it decides where numba
caches the kernels (``NUMBA_CACHE_DIR`` when the package folder is read-only)
before any kernel module defines its ``cache=True`` functions.
"""

from . import compile as _compile  # noqa: F401  (first: the cache folder, before any kernel)
from .compile import (
    CompileReport,
    warm_up,
    warm_up_columns,
    warm_up_contact,
    warm_up_exponential,
)
from .excitation import KNOWN, encode
from .path import FastPath, check_model

__all__ = [
    "FastPath",
    "check_model",
    "encode",
    "KNOWN",
    "warm_up",
    "warm_up_contact",
    "warm_up_columns",
    "warm_up_exponential",
    "CompileReport",
]
