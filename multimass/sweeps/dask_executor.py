"""The Dask executor: batches of a sweep on a ``dask.distributed`` cluster.

dask is an optional dependency (extra ``multimass[dask]``), imported only
when a `DaskExecutor` is created.
"""

from __future__ import annotations

from typing import Any

from ..errors import InputError
from ..validation import positive
from .base import Executor, available_workers, validate_workers

__all__ = ["DaskExecutor"]

_DASK_HINT = 'install the extra with  pip install "multimass[dask]"'


def _import_distributed():
    try:
        import distributed
    except ImportError as exc:
        raise ImportError(
            f"the `dask` executor needs dask.distributed, which is not installed; {_DASK_HINT}"
        ) from exc
    return distributed


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
        **cluster_options,
    ):
        self._distributed = _import_distributed()
        if address is not None and (not isinstance(address, str) or not address.strip()):
            raise InputError(
                f"`address` = {address!r}: give the scheduler address, e.g. "
                "'tcp://10.0.0.5:8786' (printed by `dask scheduler`)"
            )

        self._timeout = positive("connect_timeout", connect_timeout, "s")
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

    @property
    def client(self):
        """The ``distributed.Client`` in use, connecting or starting a cluster on first use."""
        if self._client is None:
            self._client = self._connect()
        return self._client

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
            try:
                self._own_client = d.Client(address, set_as_default=False, timeout=self._timeout)
            except (OSError, TimeoutError, ValueError) as exc:
                raise InputError(
                    f"no Dask scheduler answered at `address` (--dask-address) = {address!r} "
                    f"within {self._timeout:g} s ({type(exc).__name__}: {exc}); start one with "
                    "`dask scheduler` and workers with `dask worker ADDRESS`, or check the "
                    "address"
                ) from None
            return self._own_client
        options = dict(
            n_workers=self._n_local or available_workers(),
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",
        )
        options.update(self._cluster_options)
        self._own_cluster = d.LocalCluster(**options)
        self._own_client = d.Client(self._own_cluster, set_as_default=False)
        return self._own_client

    @property
    def workers(self) -> int:
        return max(1, sum(self.client.nthreads().values()))

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
        futures = client.map(fn, list(args), pure=False)
        position = {fut.key: i for i, fut in enumerate(futures)}
        try:
            for fut in self._distributed.as_completed(futures, loop=client.loop):
                yield position[fut.key], fut.result()
        finally:
            client.cancel([f for f in futures if not f.done()])

    def close(self):
        if self._own_client is not None:
            self._own_client.close()
            if self._client is self._own_client:
                self._client = None
            self._own_client = None
        if self._own_cluster is not None:
            self._own_cluster.close()
            self._own_cluster = None

    def __repr__(self):
        where = self._address or ("client" if self._client is not None else "local")
        return f"DaskExecutor({where})"
