"""Imported last by a process pool's forkserver: freezes the garbage collector.

A deliberate import side effect, like `multimass.engines.fast.preload`'s: `gc.freeze`
over everything the server imported (multimass, the compiled kernels), as the Python
documentation advises before forking. Workers forked from the server then leave those
objects' memory pages alone, and the server's own exit at the end of the session skips a
last collection over them — about 1 s with numba's kernels loaded, during which a
pipeline reading the command's output (``multimass stability ... --json | jq``, a
subprocess) still waits, since the server holds the same output open.
"""

import gc

__all__: list[str] = []

gc.freeze()
