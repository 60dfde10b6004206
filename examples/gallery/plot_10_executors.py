"""
Scaling out: serial, process pool or Dask, one answer
=====================================================

Every sweep (overturning maps, spectra, suites) runs its jobs in batches through an
executor: ``"serial"``, ``"process"`` (a local process pool, the default, all cores) or
``"dask"`` (a Dask cluster given its scheduler's address). Each job's randomness depends
only on the seed and the job's index, so the result is the same whatever runs it.
"""

# %%
# The same map on one process and on a pool of two
# ------------------------------------------------
import time

import numpy as np

from multimass.sweeps import available_workers, batch_plan
from multimass.sweeps.maps import overturning_map

grid = dict(omega_p=np.linspace(0.5, 10, 30), amp=np.linspace(0.25, 8, 30))
out = {}
for executor, workers in (("serial", None), ("process", 2)):
    t0 = time.perf_counter()
    out[executor] = overturning_map(
        "B6M", "sine", **grid, executor=executor, workers=workers, progress=False
    )
    print(f"{executor:8s} {time.perf_counter() - t0:5.2f} s (including the pool's start)")
same = np.array_equal(out["serial"].grid, out["process"].grid)
print("identical outcome in every cell:", same)
print("cores available here:", available_workers())

# %%
# How the jobs are cut into batches
# ---------------------------------
# Guided batches: large first, small last, so that the workers finish together.
plan = batch_plan(900, workers=2)
print(len(plan), "batches of", [len(b) for b in plan])

# %%
# On a Dask cluster
# -----------------
# Start a scheduler and workers (one single-threaded worker process per core, with the
# compiled kernels preloaded), then pass the address; from the shell::
#
#     dask scheduler --port 8786
#     dask worker tcp://HOST:8786 --nworkers 4 --nthreads 1 --preload multimass.fast.preload
#     multimass stability B6M --omega-p 0.5:10:200 --amp 0.25:8:200 \
#         --executor dask --dask-address tcp://HOST:8786
#
# or from Python, ``overturning_map(..., executor=DaskExecutor(address=...))`` with
# `multimass.sweeps.DaskExecutor`. A worker that dies mid-sweep costs only the tasks it
# held; a scheduler that does not answer is one line before any simulation runs.
