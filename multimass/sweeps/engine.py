"""The sweep driver: run a list of independent jobs in batches on an executor.

`run_jobs` splits the jobs into batches (`batch_plan`), sends each batch to the
executor as one task, shows a progress bar as batches finish and returns the
results in job order. A job that raises stops the sweep with a `JobError`
naming the job's index, its original exception chained.
"""

from __future__ import annotations

import math
import pickle
import sys
import traceback
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from functools import cache, partial
from typing import Any

import numpy as np

from ..errors import InputError, SolverError
from .base import Executor
from .executors import get_executor

__all__ = ["run_jobs", "run_batches", "batch_plan", "JobError", "ExecutorError"]

#: Default plan, guided self-scheduling (Polychronopoulos & Kuck, IEEE Trans.
#: Computers C-36(12), 1987) over strided stripes: the jobs are dealt into
#: STRIPES_PER_WORKER · workers stripes (stripe k: jobs k, k + S, k + 2S, ...,
#: each a sample of the whole grid, since neighbouring jobs often cost alike),
#: and each batch takes 1/(GUIDED_DIVISOR · workers) of the stripes not yet
#: sent, at least one. Large batches first keep the task count low (26 for 10 000
#: jobs on 2 workers; per-task cost ~0.2-0.5 ms for the process pool, ~5-9 ms for a local
#: Dask cluster, benchmarks/sweep_overhead.py); single stripes last keep the
#: tail short: on the 100 x 100 B6M map the last batch is 78 cells (~40 ms)
#: instead of 313 with 16 equal batches per worker.
STRIPES_PER_WORKER = 64
GUIDED_DIVISOR = 4
#: Sweeps with more jobs than this show a progress bar by default (on a terminal).
PROGRESS_MIN_JOBS = 50


class JobError(SolverError):
    """A job of a sweep raised; its exception is chained as ``__cause__``.

    Attributes
    ----------
    index : int
        Position of the failing job in the `jobs` given to `run_jobs`.
    """

    def __init__(self, message: str, index: int):
        super().__init__(message)
        self.index = index

    def __reduce__(self):
        return type(self), (self.args[0], self.index)


class ExecutorError(SolverError):
    """The executor could not run a batch (a worker died, data could not be sent)."""


class _RemoteTraceback(Exception):
    """The traceback of an exception raised in a worker, as text."""

    def __str__(self):
        return self.args[0]


def _portable(exc: BaseException) -> BaseException:
    """`exc` if it survives a pickle round trip, else a RuntimeError carrying its text."""
    try:
        pickle.loads(pickle.dumps(exc))
        return exc
    except Exception:
        return RuntimeError(
            f"{type(exc).__module__}.{type(exc).__qualname__}: {exc} "
            "(the original exception could not be pickled)"
        )


class _Failure:
    """What a batch returns when one of its jobs raised."""

    def __init__(self, index: int, exc: BaseException, tb: str, remote: bool = False):
        self.index, self.exc, self.tb, self.remote = index, exc, tb, remote

    def __reduce__(self):  # only when it crosses to another process
        return _Failure, (self.index, _portable(self.exc), self.tb, True)


class _Batch:
    """The jobs sent as one task (their positions stay with the driver).

    An opaque object, so that Dask does not search the jobs for tasks or futures.
    """

    __slots__ = ("jobs",)

    def __init__(self, jobs: list):
        self.jobs = jobs

    def __reduce__(self):
        return _Batch, (self.jobs,)


def _run_batch(func: Callable, batch: _Batch) -> list | _Failure:
    """Apply `func` to each job of a batch; stop at the first job that raises.

    A `_Failure` carries the job's position within the batch.
    """
    out = []
    for k, job in enumerate(batch.jobs):
        try:
            out.append(func(job))
        except Exception as exc:
            return _Failure(k, exc, traceback.format_exc())
    return out


def _strided(n_jobs: int, n_batches: int) -> list[range]:
    return [range(k, n_jobs, n_batches) for k in range(n_batches)]


def batch_plan(n_jobs: int, workers: int, batch_size: int | None = None) -> list[list[int]]:
    """The positions of the jobs in each batch, in the order the batches are sent.

    Parameters
    ----------
    n_jobs, workers : int
    batch_size : int, optional
        Most jobs per batch: ``B = ceil(n_jobs / batch_size)`` strided batches
        of equal size (±1), batch k holding jobs k, k + B, k + 2B, ...
        Default: guided self-scheduling over ``S = min(n_jobs,
        STRIPES_PER_WORKER · workers)`` strided stripes, each batch taking
        ``ceil(R / (GUIDED_DIVISOR · workers))`` of the R stripes left.

    Returns
    -------
    list of list of int
        Every position in ``range(n_jobs)`` exactly once.

    Raises
    ------
    InputError
        `n_jobs` not an integer ≥ 0, `workers` not an integer ≥ 1, or
        `batch_size` not None or an integer ≥ 1.

    Examples
    --------
    >>> from multimass.sweeps import batch_plan
    >>> batch_plan(10, 1, batch_size=3)
    [[0, 4, 8], [1, 5, 9], [2, 6], [3, 7]]
    """
    for name, value, least in (("n_jobs", n_jobs, 0), ("workers", workers, 1)):
        if isinstance(value, bool) or not hasattr(value, "__index__") or value.__index__() < least:
            raise InputError(f"`{name}` = {value!r}: expected an integer ≥ {least}")
    n_jobs, workers = n_jobs.__index__(), workers.__index__()
    batch_size = _validate_batch_size(batch_size)
    if batch_size is not None:
        return [list(b) for b in _strided(n_jobs, math.ceil(n_jobs / batch_size))]
    stripes = _strided(n_jobs, min(n_jobs, STRIPES_PER_WORKER * workers))
    plan = []
    while stripes:
        take = math.ceil(len(stripes) / (GUIDED_DIVISOR * workers))
        plan.append([i for stripe in stripes[:take] for i in stripe])
        stripes = stripes[take:]
    return plan


def _validate_batch_size(batch_size: Any) -> int | None:
    if batch_size is None:
        return None
    if isinstance(batch_size, bool) or not hasattr(batch_size, "__index__"):
        raise InputError(
            f"`batch_size` = {batch_size!r}: expected a positive integer or "
            "None (None picks a few batches per worker)"
        )
    if batch_size.__index__() < 1:
        raise InputError(f"`batch_size` = {batch_size!r}: must be at least 1")
    return batch_size.__index__()


def _show_progress(progress: Any, n_jobs: int) -> bool:
    if progress is None:
        return n_jobs > PROGRESS_MIN_JOBS and bool(getattr(sys.stderr, "isatty", bool)())
    if not isinstance(progress, bool):
        raise InputError(
            f"`progress` = {progress!r}: expected True, False or None "
            "(None shows a bar for long sweeps on a terminal)"
        )
    return progress


class _HiddenBar:
    """A progress bar that is not shown: `update` and `close` do nothing (no tqdm import)."""

    def update(self, n=1) -> None:
        pass

    def close(self) -> None:
        pass


@cache
def _bar_class():
    from tqdm import tqdm

    class MonitorlessBar(tqdm):
        """tqdm without its monitor thread (a live thread makes forking workers unsafe)."""

        monitor_interval = 0

    return MonitorlessBar


def _Bar(**options):
    """A tqdm bar without its monitor thread; with ``disable=True``, a `_HiddenBar`: tqdm
    (~20 ms to import) is imported only for a bar that is shown."""
    if options.get("disable"):
        return _HiddenBar()
    return _bar_class()(**options)


def _raise_job_error(fail: _Failure, index: int, n_jobs: int, executor: Executor):
    exc = fail.exc
    if fail.remote:  # the pickled exception lost its traceback: chain the worker's text
        exc.__cause__ = _RemoteTraceback(f'\n"""\n{fail.tb}"""')
    raise JobError(
        f"job {index} of {n_jobs} failed in the `{executor.name}` executor: "
        f"{type(exc).__name__}: {exc}",
        index,
    ) from exc


def run_jobs(
    func: Callable[[Any], Any],
    jobs: Iterable[Any],
    *,
    executor: str | type[Executor] | Executor = "process",
    workers: int | None = None,
    batch_size: int | None = None,
    progress: bool | None = None,
    desc: str | None = None,
    weights=None,
    unit: str = "job",
) -> list:
    """Apply `func` to every job and return the results in job order.

    Parameters
    ----------
    func : callable
        ``func(job) -> result``. For the process pool and Dask it must be
        picklable: a function defined at module level (or a
        ``functools.partial`` of one).
    jobs : iterable
        One argument per call, e.g. dicts or small dataclasses; picklable
        for the process pool and Dask. Randomness inside a job should come
        from a seed carried by the job (see `job_seeds`), so results do not
        depend on the executor, the worker count or the batch size.
    executor : str, Executor subclass or Executor, default "process"
        ``"serial"``, ``"process"`` (local pool) or ``"dask"``; a class or an
        instance implementing `Executor`. An executor created here from a
        name or class is closed on return; an instance is left open.
    workers : int, optional
        Workers of an executor created here; default all cores (Dask: the
        cluster's worker threads).
    batch_size : int, optional
        Most jobs per task, in strided batches: with B batches, batch k holds
        jobs k, k + B, k + 2B, ... Default: guided self-scheduling, large
        batches first and small ones last (see `batch_plan`).
    progress : bool, optional
        Show a tqdm bar on stderr, advanced per finished batch. Default:
        only if there are more than 50 jobs and stderr is a terminal.
    desc : str, optional
        Label of the progress bar.
    weights : sequence of int, optional
        What each job counts for on the progress bar (e.g. the cells of a chunk of
        a map); default 1 each. With `unit`, the bar counts those, not jobs.
    unit : str, default "job"
        The unit the progress bar counts.

    Returns
    -------
    list
        ``[func(job) for job in jobs]``, whatever the executor.

    Raises
    ------
    JobError
        A job raised; ``.index`` is its position, the original exception is
        ``__cause__`` (with the worker's traceback chained below it).
    ExecutorError
        The executor failed (a worker died, a job could not be pickled).
    InputError
        Invalid arguments.

    Examples
    --------
    >>> from multimass.sweeps import run_jobs
    >>> run_jobs(abs, [-2, 3, -5], executor="serial")
    [2, 3, 5]
    """
    if not callable(func):
        raise InputError(f"`func` = {func!r}: expected a callable taking one job")
    jobs = list(jobs)
    batch_size = _validate_batch_size(batch_size)
    weights = _validate_weights(weights, len(jobs))
    show = _show_progress(progress, sum(weights))
    ex = get_executor(executor, workers)  # validates `executor` and `workers` first
    owned = ex is not executor
    try:
        if not jobs:
            return []
        ex.prepare(func)
        plan = batch_plan(len(jobs), ex.workers, batch_size)
        return _drive(func, plan, jobs, ex, _Progress(show, desc, weights, unit))
    finally:
        if owned:
            ex.close()


def run_batches(
    func: Callable[[list], list],
    jobs: Iterable[Any],
    *,
    executor: Executor,
    progress: bool | None = None,
    desc: str | None = None,
    unit: str = "job",
) -> list:
    """`run_jobs` for a `func` that takes a whole batch: one task per batch of
    `batch_plan` (``func(list of jobs) -> list of their results``, so what the batch's
    jobs share is prepared once), the progress bar counting jobs; the results in the order
    of `jobs`."""
    jobs = list(jobs)
    plan = batch_plan(len(jobs), executor.workers)
    got = run_jobs(
        func,
        [[jobs[i] for i in b] for b in plan],
        executor=executor,
        batch_size=1,
        progress=progress,
        desc=desc,
        weights=[len(b) for b in plan],
        unit=unit,
    )
    out: list = [None] * len(jobs)
    for b, results in zip(plan, got):
        for i, r in zip(b, results):
            out[i] = r
    return out


def _validate_weights(weights, n_jobs: int) -> list:
    if weights is None:
        return [1] * n_jobs
    weights = list(weights)
    if len(weights) != n_jobs or not all(
        isinstance(w, (int, np.integer)) and not isinstance(w, bool) and w >= 0 for w in weights
    ):
        raise InputError(
            f"`weights`: expected one integer ≥ 0 per job ({n_jobs}), got {len(weights)} "
            "values or a non-integer"
        )
    return [int(w) for w in weights]


@dataclass(frozen=True)
class _Progress:
    """What the progress bar shows: on or off, its label, each job's count and the unit."""

    show: bool
    desc: str | None
    weights: list
    unit: str


def _drive(func, plan, jobs, ex: Executor, progress: _Progress) -> list:
    """Run the batches of `plan` on `ex`, fill the results in order, advance the bar."""
    n_jobs = len(jobs)
    batches = [_Batch([jobs[i] for i in index]) for index in plan]
    results: list = [None] * n_jobs
    bar = _Bar(
        total=sum(progress.weights),
        desc=progress.desc,
        unit=progress.unit,
        file=sys.stderr,
        disable=not progress.show,
    )
    stream = None
    done = 0
    try:
        stream = iter(ex.map_unordered(partial(_run_batch, func), batches))
        for pos, out in stream:
            index = plan[pos]
            if isinstance(out, _Failure):
                _raise_job_error(out, index[out.index], n_jobs, ex)
            size = len(index)
            if not isinstance(out, list) or len(out) != size:
                raise ExecutorError(
                    f"the `{ex.name}` executor returned {type(out).__name__} "
                    f"for batch {pos}; expected a list of {size} results"
                )
            for i, r in zip(index, out):
                results[i] = r
            done += size
            bar.update(sum(progress.weights[i] for i in index))
    except (JobError, ExecutorError):
        raise
    except Exception as exc:
        raise ExecutorError(
            f"the `{ex.name}` executor failed after {done} of {n_jobs} jobs: "
            f"{type(exc).__name__}: {exc}. `func`, the jobs and their results must be "
            "picklable, and a job must not kill its worker (memory, segfault)"
        ) from exc
    finally:
        getattr(stream, "close", lambda: None)()  # a generator cancels pending tasks
        bar.close()
    if done != n_jobs:
        raise ExecutorError(
            f"the `{ex.name}` executor finished {done} of {n_jobs} jobs; "
            "its map_unordered must yield every batch once"
        )
    return results
