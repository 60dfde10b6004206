"""Executors by name: serial, a local process pool, or Dask; and the registry.

Executors are chosen by name from `EXECUTORS` (``"serial"``, ``"process"``,
``"dask"``) through `get_executor`, which also accepts an `Executor` subclass
or an instance, as scipy's ``solve_ivp`` does for its methods. The contract
is in `multimass.sweeps.base`.
"""

from __future__ import annotations

import os
import pickle
import sys
import threading
import time
import types
from contextlib import contextmanager, nullcontext
from typing import TYPE_CHECKING

from ..errors import InputError
from .base import Executor, available_workers, validate_workers
from .dask_executor import DaskExecutor

if TYPE_CHECKING:  # multiprocessing and its pool: imported by the pool's first use (~5 ms)
    from concurrent.futures import ProcessPoolExecutor

__all__ = [
    "SerialExecutor",
    "ProcessExecutor",
    "DaskExecutor",
    "EXECUTORS",
    "get_executor",
    "exit_with_parent",
]


class SerialExecutor(Executor):
    """Run every task in this process, one after the other, in order.

    The reference executor: no pickling, tracebacks point into the job.
    """

    name = "serial"
    needs_pickle = False

    def __init__(self, workers: int | None = None):
        if validate_workers(workers) not in (None, 1):
            raise InputError(
                f"`workers` = {workers!r}: the serial executor runs one job at "
                "a time; drop `workers` or use executor='process'"
            )

    @property
    def workers(self) -> int:
        return 1

    def map_unordered(self, fn, args):
        for i, a in enumerate(args):
            yield i, fn(a)


def _default_start_method() -> str:
    """'forkserver' where it exists (Linux, macOS), else 'spawn' (Windows).

    Not 'fork': forking a process that runs other threads (an OpenMP pool
    after a numba ``parallel=True`` kernel, a Dask client, a GUI) can
    deadlock or kill the child (``python -m benchmarks.sweep_overhead
    --fork-hazard`` shows it); Python 3.14 made the same change.
    """
    import multiprocessing

    methods = multiprocessing.get_all_start_methods()
    return "forkserver" if "forkserver" in methods else "spawn"


#: Seconds between a pool worker's checks that the process that made its pool is alive.
PARENT_CHECK_S = 1.0


def _alive(pid: int) -> bool:
    """Whether process `pid` runs (a zombie, killed but not yet reaped, does not)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:  # Linux: state after "(name)"
            return f.read().rsplit(b")", 1)[1].split()[0] != b"Z"
    except (OSError, IndexError):
        return True


def exit_with_parent(parent_pid: int) -> None:
    """Initializer of pool workers: end the worker once `parent_pid` has gone.

    A pool's workers otherwise outlive a parent killed with SIGKILL (or by the
    out-of-memory killer), blocked on their task queue; a daemon thread checks
    every `PARENT_CHECK_S` seconds. (A normal exit or Ctrl-C shuts the pool down.)
    """

    def watch():
        while True:
            time.sleep(PARENT_CHECK_S)
            if not _alive(parent_pid):
                os._exit(1)

    threading.Thread(target=watch, name="multimass-parent-watch", daemon=True).start()


def _preload_in_forkserver(*modules: str | None) -> None:
    """Have the forkserver import multimass and `modules` once, before it forks workers,
    then freeze its garbage collector (`multimass.sweeps.forkserver_freeze`).

    Each worker then starts with them imported: a fresh 2-worker pool's first
    sweep falls from ~2 s to ~0.05 s (benchmarks/sweep_overhead.py). Effective
    only before the server starts (the first forkserver pool of this process);
    modules others asked for are kept (read from a private attribute, defensively).
    """
    from multiprocessing import forkserver

    current = list(
        getattr(getattr(forkserver, "_forkserver", None), "_preload_modules", None) or ["__main__"]
    )
    kept = [m for m in current if m != _FREEZE]
    wanted = kept + [m for m in ("multimass", *modules) if m and m not in kept] + [_FREEZE]
    if wanted != current:
        forkserver.set_forkserver_preload(wanted)


#: Imported last by the forkserver (`multimass.sweeps.forkserver_freeze`): `gc.freeze`.
_FREEZE = "multimass.sweeps.forkserver_freeze"


def _refers_to_main(obj) -> bool:
    """True if pickling `obj` refers to ``__main__`` (a class or function of the user's script)."""
    try:
        return b"__main__" in pickle.dumps(obj)
    except Exception:  # let the pool report the pickling problem itself
        return True


@contextmanager
def _script_not_rerun():
    """Start pool workers without re-running the user's script in each of them.

    With 'forkserver' and 'spawn', multiprocessing prepares each new worker by
    importing the parent's ``__main__`` file again, so that functions defined in
    it can be unpickled. A script written without an ``if __name__ ==
    "__main__":`` guard (the README's example, saved as a file or piped to
    ``python -``) then runs again in every worker, which starts a pool of its
    own and breaks the parent's pool. Jobs that refer to nothing in
    ``__main__`` do not need it: while their workers start, ``__main__`` is a
    blank module, so nothing is re-run.
    """
    main = sys.modules.get("__main__")
    sys.modules["__main__"] = types.ModuleType("__main__")
    try:
        yield
    finally:
        sys.modules["__main__"] = main


_BROKEN_HINT = (
    "a worker process died before it could run a job. In a script, this is "
    "usually the missing guard: process pools start each worker by importing the "
    "script again, so put the code that runs the sweep under "
    '`if __name__ == "__main__":` (or pass executor="serial"); otherwise a job '
    "ran out of memory or crashed its worker"
)


class ProcessExecutor(Executor):
    """A pool of worker processes on this machine (concurrent.futures).

    Parameters
    ----------
    workers : int, optional
        Number of processes; default all cores (`available_workers`).
    start_method : {'forkserver', 'spawn', 'fork'}, optional
        How workers start. Default 'forkserver' (POSIX) or 'spawn' (Windows).
    preload : sequence of str, optional
        Modules the forkserver imports before forking workers (e.g.
        ``"multimass.engines.fast.preload"``, which loads the compiled kernels once so
        workers do not each load them).
        'fork' starts in ~10 ms and shares already-compiled numba functions,
        but is unsafe once the calling process runs other threads (measured:
        after a numba ``parallel=True`` kernel with the OpenMP layer the
        forked workers abort); use it only in single-threaded scripts.

    Notes
    -----
    The pool starts at the first sweep and is reused until `close`, so run
    several sweeps inside ``with ProcessExecutor() as ex:`` to pay the start
    once. With 'forkserver' the server process (one per Python session)
    imports multimass and the first job function's module, so later pools
    start in tens of milliseconds.
    Workers started by 'forkserver' or 'spawn' compile numba functions again
    on first call; ``@njit(cache=True)`` makes that a cache load.
    With these start methods the job function must be importable by the
    workers: functions typed into an interactive session or a notebook are
    rejected with a clear error (use 'dask', 'fork' or 'serial' there).
    """

    name = "process"

    def __init__(self, workers: int | None = None, start_method: str | None = None, preload=()):
        import multiprocessing

        self._workers = validate_workers(workers) or available_workers()
        methods = multiprocessing.get_all_start_methods()
        if start_method is not None and start_method not in methods:
            raise InputError(
                f"`start_method` = {start_method!r}: not available here; "
                f"choose one of {', '.join(map(repr, methods))} or None"
            )
        self.start_method = start_method or _default_start_method()
        self.preload = tuple(preload)
        self._pool: ProcessPoolExecutor | None = None

    @property
    def workers(self) -> int:
        return self._workers

    def prepare(self, func):
        """Check that workers can import `func`; with 'forkserver', preload its module."""
        super().prepare(func)
        target = getattr(func, "func", func)  # a functools.partial's function
        module = getattr(target, "__module__", None)
        if (
            self.start_method != "fork"
            and module == "__main__"
            and not getattr(sys.modules.get("__main__"), "__file__", None)
        ):
            raise InputError(
                f"`func` = {func!r} is defined in an interactive session, which "
                f"'{self.start_method}' workers cannot import; put it in a .py module and "
                "import it, or use executor='dask' (pickles by value) or "
                "ProcessExecutor(start_method='fork')"
            )
        if self.start_method == "forkserver":
            _preload_in_forkserver(module, *self.preload)

    def _get_pool(self) -> ProcessPoolExecutor:
        if self._pool is None:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor

            ctx = multiprocessing.get_context(self.start_method)
            self._pool = ProcessPoolExecutor(
                self._workers,
                mp_context=ctx,
                initializer=exit_with_parent,
                initargs=(os.getpid(),),
            )
        return self._pool

    def map_unordered(self, fn, args):
        from concurrent.futures import FIRST_COMPLETED, wait
        from concurrent.futures.process import BrokenProcessPool

        pool = self._get_pool()
        args = list(args)
        hide = self.start_method != "fork" and not _refers_to_main((fn, args))
        with _script_not_rerun() if hide else nullcontext():  # workers start in submit
            position = {pool.submit(fn, a): i for i, a in enumerate(args)}
        pending = set(position)
        try:
            while pending:
                done, pending = wait(pending, return_when=FIRST_COMPLETED)
                for fut in done:
                    try:
                        result = fut.result()
                    except BrokenProcessPool as exc:
                        raise BrokenProcessPool(f"{exc}; {_BROKEN_HINT}") from exc
                    yield position[fut], result
        finally:
            for fut in pending:
                fut.cancel()

    def close(self):
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None

    def __repr__(self):
        return f"ProcessExecutor(workers={self._workers}, start_method={self.start_method!r})"


#: Registry of executors by name; `get_executor` reads it.
EXECUTORS: dict[str, type[Executor]] = {
    "serial": SerialExecutor,
    "process": ProcessExecutor,
    "dask": DaskExecutor,
}


def get_executor(
    executor: str | type[Executor] | Executor = "process", workers: int | None = None, **options
) -> Executor:
    """An executor from a registry name, an `Executor` subclass or an instance.

    Parameters
    ----------
    executor : str, Executor subclass or Executor
        ``"serial"``, ``"process"`` (default) or ``"dask"``; a class is
        instantiated as ``cls(workers, **options)``; an instance is returned
        as is (then `workers` and `options` must not be given).
    workers : int, optional
        Number of workers; default all cores.
    **options
        Extra keyword arguments of the executor class (e.g. ``address=``
        for Dask, ``start_method=`` for the process pool).

    Returns
    -------
    Executor
        The caller owns a new executor and should `close` it (or use ``with``).
    """
    if isinstance(executor, Executor):
        if workers is not None or options:
            raise InputError(
                f"`workers`/options given with the executor instance "
                f"{executor!r}: pass them to its constructor instead"
            )
        return executor
    if isinstance(executor, str):
        cls = EXECUTORS.get(executor.lower())
        if cls is None:
            raise InputError(
                f"`executor` = {executor!r}: unknown executor; choose one of "
                f"{', '.join(map(repr, EXECUTORS))}, or pass an Executor"
            )
    elif isinstance(executor, type) and issubclass(executor, Executor):
        cls = executor
    else:
        raise InputError(
            f"`executor` = {executor!r}: expected a name "
            f"({', '.join(map(repr, EXECUTORS))}), an Executor subclass "
            "or an Executor instance"
        )
    return cls(workers, **options)
