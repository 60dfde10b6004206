"""Sweeps: many independent jobs (spectra, overturning maps, Monte Carlo) on an executor.

The engine knows nothing about rocking: it applies a picklable function to a
list of jobs, in batches, on a serial loop, a local process pool (default,
all cores) or a Dask cluster (extra ``multimass[dask]``), and returns the
results in job order. Give each job its own seed (`job_seeds`) and the
results are the same whatever the executor, worker count or batch size.

>>> from multimass.sweeps import run_jobs, job_seeds
>>> run_jobs(abs, [-1, 2, -3], executor="serial")
[1, 2, 3]

Several sweeps on one pool (it starts once)::

    with ProcessExecutor() as ex:         # or DaskExecutor(address="tcp://...")
        a = run_jobs(simulate_one, jobs_a, executor=ex)
        b = run_jobs(simulate_one, jobs_b, executor=ex)
"""

from .base import Executor, available_workers
from .dask_executor import DaskExecutor
from .engine import ExecutorError, JobError, batch_plan, run_batches, run_jobs
from .executors import EXECUTORS, ProcessExecutor, SerialExecutor, get_executor
from .seeding import job_seed, job_seeds

__all__ = [
    "run_jobs",
    "run_batches",
    "job_seeds",
    "job_seed",
    "get_executor",
    "batch_plan",
    "available_workers",
    "EXECUTORS",
    "Executor",
    "SerialExecutor",
    "ProcessExecutor",
    "DaskExecutor",
    "JobError",
    "ExecutorError",
]
