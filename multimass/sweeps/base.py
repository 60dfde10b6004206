"""The executor contract and the helpers every executor shares.

An executor has one duty, `Executor.map_unordered`: apply a function to each
of a list of arguments, one task per argument, and yield ``(position, value)``
pairs as the tasks finish. Batching, ordering, progress and job errors are the
sweep driver's business (`multimass.sweeps.run_jobs`), so a user's own
executor is a small class.
"""

from __future__ import annotations

import abc
import os
import pickle
from collections.abc import Callable, Iterator, Sequence
from typing import Any, ClassVar

from ..errors import InputError

__all__ = ["Executor", "available_workers", "validate_workers"]


def available_workers() -> int:
    """Number of CPU cores this process may run on (its affinity mask, else os.cpu_count())."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # macOS, Windows
        return max(1, os.cpu_count() or 1)


def validate_workers(workers: Any) -> int | None:
    """`workers` as a positive int, or None; raise InputError otherwise."""
    if workers is None:
        return None
    if isinstance(workers, bool) or not hasattr(workers, "__index__"):
        raise InputError(
            f"`workers` = {workers!r}: expected a positive integer or None (None uses all cores)"
        )
    n = workers.__index__()
    if n < 1:
        raise InputError(f"`workers` = {workers!r}: must be at least 1; pass None to use all cores")
    return n


class Executor(abc.ABC):
    """Contract of a sweep executor.

    Subclasses implement `workers` and `map_unordered`; `prepare` is called
    once per sweep with the job function, `close` releases what the executor
    started. Instances are context managers, and may be reused for several
    sweeps (a process pool or a Dask client then starts once).

    Attributes
    ----------
    name : str
        Registry name, shown in messages.
    needs_pickle : bool
        True if functions and arguments travel to other processes; the
        default `prepare` then checks that the job function pickles.
    """

    name: ClassVar[str] = "custom"
    needs_pickle: ClassVar[bool] = True

    @property
    @abc.abstractmethod
    def workers(self) -> int:
        """Number of tasks that can run at once (sizes the default batches)."""

    @abc.abstractmethod
    def map_unordered(
        self, fn: Callable[[Any], Any], args: Sequence[Any]
    ) -> Iterator[tuple[int, Any]]:
        """Apply `fn` to each of `args`, one task each.

        Yields ``(i, fn(args[i]))`` as tasks finish, in any order. If a task
        cannot run (a worker dies, an argument cannot be sent) it raises.
        When the consumer stops early (the generator is closed), pending
        tasks are cancelled.
        """

    def prepare(self, func: Callable) -> None:
        """Check, before a sweep starts, that `func` can reach the workers.

        Raises InputError if it cannot. Subclasses may also warm workers here.
        """
        if not self.needs_pickle:
            return
        try:
            pickle.dumps(func)
        except Exception as exc:  # pickle raises several types
            raise InputError(
                f"`func` = {func!r} cannot be pickled for the `{self.name}` executor "
                f"({type(exc).__name__}: {exc}); define it with `def` at the top level "
                "of a module (no lambda or nested function), or use executor='serial'"
            ) from exc

    def close(self) -> None:  # noqa: B027 (a no-op by default; executors that start things override it)
        """Release workers, pools or clusters this executor started (idempotent)."""

    def __enter__(self) -> Executor:
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"
