"""The Dask executor: batches of a sweep on a ``dask.distributed`` cluster.

dask is an optional dependency (extra ``multimass[dask]``), imported only
when a `DaskExecutor` is created.

What a lost worker costs: the scheduler runs the tasks that were on it again
elsewhere (up to ``distributed.scheduler.allowed-failures`` deaths per task,
default 3); finished results the driver has taken are released at once, so
they are not recomputed when the worker that held them dies; and each task's
result is yielded once, however often it ran (jobs are deterministic, so a
rerun gives the same cells).
"""

from __future__ import annotations

import socket
import sys
import time
import weakref
from typing import Any

from ..errors import InputError
from ..validation import integer, positive
from .base import Executor, available_workers, validate_workers

__all__ = ["DaskExecutor"]

_DASK_HINT = 'install the extra with  pip install "multimass[dask]"'
#: While no worker has joined the scheduler, say so on stderr every this many seconds.
WAIT_REPORT_S = 30.0


def _import_distributed():
    try:
        import distributed
    except ImportError as exc:
        raise ImportError(
            f"the `dask` executor needs dask.distributed, which is not installed; {_DASK_HINT}"
        ) from exc
    return distributed


def _check_address(d, address: str, timeout: float) -> None:
    """Refuse an address that cannot be parsed, or a TCP/TLS one where nothing listens.

    Both are checked before a ``distributed.Client`` is made: a Client that failed to
    connect is closed when it is collected, and its clean-up printed a traceback up to
    20 s after the one-line error.
    """
    scheme, loc = d.comm.parse_address(address)
    if scheme in ("tcp", "tls"):
        try:
            host, port = d.comm.parse_host_port(loc)
        except ValueError as exc:
            raise InputError(
                f"`address` (--dask-address) = {address!r} is not a scheduler address ({exc}); "
                "give it as tcp://HOST:PORT, e.g. tcp://10.0.0.5:8786 (printed by `dask scheduler`)"
            ) from None
        try:
            socket.create_connection((host, port), timeout=timeout).close()
        except OSError as exc:
            raise InputError(
                f"no Dask scheduler answered at `address` (--dask-address) = {address!r} "
                f"within {timeout:g} s ({type(exc).__name__}: {exc}); start one with "
                "`dask scheduler` and workers with `dask worker ADDRESS`, or check the address"
            ) from None


def _close_owned(client, cluster) -> None:
    """Close what a `DaskExecutor` started: its client, then its LocalCluster."""
    if client is not None:
        client.close()
    if cluster is not None:
        cluster.close()


class DaskExecutor(Executor):
    """Run the batches on a Dask cluster (dask.distributed).

    The cluster is found in this order: `client`; `address` (or the Dask
    config ``scheduler-address``, e.g. env ``DASK_SCHEDULER_ADDRESS``); the
    default client of this process, if `workers` and `cluster_options` are
    not given; else a new ``LocalCluster`` of `workers` single-threaded
    worker processes. Only a client or cluster started here is closed by
    `close`. Functions are pickled by value (cloudpickle), so functions
    defined in a notebook work.

    Parameters
    ----------
    workers : int, optional
        Workers of a LocalCluster started here (default all cores). Not
        allowed with `client` or `address`: their cluster has its workers.
    address : str, optional
        Scheduler address of a running cluster, e.g. ``"tcp://10.0.0.5:8786"``.
    client : distributed.Client, optional
        A client the caller manages.
    connect_timeout : float
        Seconds to wait for the scheduler at `address` (default 10) before
        giving up with an `InputError` that names the address.
    retries : int
        Times a task that raised on its worker is run again (default 2), e.g.
        on a mixed cluster where one worker cannot unpickle it. Through
        `run_jobs`, a job's own exception is caught inside its task and
        reported as a `JobError`, never retried; a task whose worker died is
        rerun by the scheduler whatever `retries`.
    worker_timeout : float, optional
        Seconds to wait for a first worker when the scheduler has none (e.g.
        batch jobs still queued); default None waits as long as it takes,
        saying so on stderr every 30 s. Then an `InputError`.
    **cluster_options
        Passed to ``LocalCluster`` (e.g. ``processes=False``); defaults are
        ``threads_per_worker=1, processes=True, dashboard_address=":0"`` (any free port).
    """

    name = "dask"

    def __init__(
        self,
        workers: int | None = None,
        *,
        address: str | None = None,
        client: Any = None,
        connect_timeout: float = 10.0,
        retries: int = 2,
        worker_timeout: float | None = None,
        **cluster_options,
    ):
        self._distributed = _import_distributed()
        if address is not None and (not isinstance(address, str) or not address.strip()):
            raise InputError(
                f"`address` = {address!r}: give the scheduler address, e.g. "
                "'tcp://10.0.0.5:8786' (printed by `dask scheduler`)"
            )

        self._timeout = positive("connect_timeout", connect_timeout, "s")
        self.retries = integer("retries", retries, low=0, what="reruns of a task that raised")
        self._worker_timeout = (
            None if worker_timeout is None else positive("worker_timeout", worker_timeout, "s")
        )
        self._n_local = validate_workers(workers)
        if client is not None and address is not None:
            raise InputError("`client` and `address` both given: pass one of them")
        if (client is not None or address is not None) and (workers or cluster_options):
            raise InputError(
                f"`workers` = {workers!r} / cluster options "
                f"{sorted(cluster_options)} apply only to a LocalCluster started "
                "here; the cluster behind `client`/`address` has its own workers"
            )
        self._address = address
        self._client = client
        self._cluster_options = cluster_options
        self._own_client = self._own_cluster = None
        self._finalizer = None  # closes what was started here, if `close` is never called

    @property
    def client(self):
        """The ``distributed.Client`` in use, connecting or starting a cluster on first use."""
        if self._client is None:
            self._client = self._connect()
        return self._client

    def connect(self):
        """Connect now (or start the LocalCluster) and return the client.

        A sweep connects on first use; call this first to learn of an
        unreachable scheduler (an `InputError` naming the address) before any
        other work.
        """
        return self.client

    def _connect(self):
        d = self._distributed
        address = self._address
        if address is None and self._n_local is None and not self._cluster_options:
            import dask.config

            address = dask.config.get("scheduler-address", None)
            if address is None:
                try:
                    return d.default_client()
                except ValueError:  # no default client in this process
                    pass
        if address is not None:
            _check_address(d, address, self._timeout)
            try:
                client = d.Client(address, set_as_default=False, timeout=self._timeout)
            except (OSError, TimeoutError, ValueError) as exc:
                reason = f"{type(exc).__name__}: {exc}"
            else:
                return self._own(client, None)
            raise InputError(  # outside the except block: the failed client is not kept alive
                f"no Dask scheduler answered at `address` (--dask-address) = {address!r} "
                f"within {self._timeout:g} s ({reason}); start one with "
                "`dask scheduler` and workers with `dask worker ADDRESS`, or check the "
                "address"
            )
        options = dict(
            n_workers=self._n_local or available_workers(),
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",
        )
        options.update(self._cluster_options)
        cluster = d.LocalCluster(**options)
        try:
            client = d.Client(cluster, set_as_default=False)
        except BaseException:
            cluster.close()
            raise
        return self._own(client, cluster)

    def _own(self, client, cluster):
        """Keep the client (and cluster) started here; closed by `close`, or when this
        executor is collected or the interpreter exits, whichever comes first."""
        self._own_client, self._own_cluster = client, cluster
        self._finalizer = weakref.finalize(self, _close_owned, client, cluster)
        return client

    @property
    def workers(self) -> int:
        """Worker threads of the cluster; waits for a first worker if it has none."""
        n = sum(self.client.nthreads().values())
        return n if n > 0 else self._wait_for_workers()

    def _wait_for_workers(self) -> int:
        client = self.client
        where = self._address or getattr(client.scheduler, "address", "the scheduler")
        limit = self._worker_timeout
        t0 = last = time.monotonic()
        print(
            f"multimass: no Dask worker has joined the scheduler at {where}; waiting "
            f"(start workers with `dask worker {where}`; Ctrl-C stops)",
            file=sys.stderr,
            flush=True,
        )
        while True:
            n = sum(client.nthreads().values())
            now = time.monotonic()
            if n > 0:
                print(
                    f"multimass: {n} Dask worker thread(s) after {now - t0:.0f} s",
                    file=sys.stderr,
                    flush=True,
                )
                return n
            if limit is not None and now - t0 >= limit:
                raise InputError(
                    f"no Dask worker joined the scheduler at {where} within `worker_timeout` = "
                    f"{limit:g} s; start workers with `dask worker {where}` (or check that "
                    "the cluster's batch jobs are running)"
                )
            if now - last >= WAIT_REPORT_S:
                last = now
                print(
                    f"multimass: still no Dask worker at {where} after {now - t0:.0f} s",
                    file=sys.stderr,
                    flush=True,
                )
            time.sleep(0.2)

    def prepare(self, func):
        from distributed.protocol.pickle import (
            dumps,  # cloudpickle-backed, as Dask sends it
        )

        try:
            dumps(func)
        except Exception as exc:
            raise InputError(
                f"`func` = {func!r} cannot be pickled for Dask ({type(exc).__name__}: {exc})"
            ) from exc

    def map_unordered(self, fn, args):
        client = self.client
        futures = client.map(fn, list(args), pure=False, retries=self.retries)
        pending = {fut.key: (i, fut) for i, fut in enumerate(futures)}
        finished = self._distributed.as_completed(futures, loop=client.loop)
        del futures
        try:
            for fut in finished:
                i, _ = pending.pop(fut.key, (None, None))
                if i is None:
                    continue  # reported already: a task that ran twice yields once
                result = fut.result()
                # Released at once: were the worker that holds it to die later in
                # the sweep, the scheduler would otherwise compute it again for us.
                fut.release()
                yield i, result
        finally:
            if pending:
                client.cancel([f for _, f in pending.values()])

    def close(self):
        if self._finalizer is not None:
            self._finalizer()  # runs once: closes the client, then the cluster
            self._finalizer = None
        if self._own_client is not None and self._client is self._own_client:
            self._client = None
        self._own_client = self._own_cluster = None

    def __repr__(self):
        where = self._address or ("client" if self._client is not None else "local")
        return f"DaskExecutor({where})"
