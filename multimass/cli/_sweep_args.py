"""Argument groups of the sweep commands (executor, workers, progress)."""

from __future__ import annotations

from ._types import count as _count
from ._types import positive as _positive

__all__ = ["add_executor_args", "executor_kwargs"]


def add_executor_args(p) -> None:
    g = p.add_argument_group("sweep execution")
    g.add_argument(
        "--executor",
        default="process",
        choices=("serial", "process", "dask"),
        help="serial, local process pool (default, all cores) or Dask",
    )
    g.add_argument(
        "--workers", type=_count, default=None, help="number of workers, ≥ 1 (default: all cores)"
    )
    g.add_argument(
        "--dask-address",
        default=None,
        metavar="ADDR",
        help="scheduler address of a Dask cluster, e.g. tcp://10.0.0.5:8786 (with --executor dask)",
    )
    g.add_argument(
        "--dask-timeout",
        type=_positive,
        default=None,
        metavar="SECONDS",
        help="seconds to wait for the scheduler at --dask-address (default 10)",
    )
    g.add_argument("--no-progress", action="store_true", help="hide the progress bar")


def executor_kwargs(args) -> dict:
    from multimass.errors import InputError
    from multimass.sweeps import get_executor

    if args.dask_address and args.executor != "dask":
        raise InputError(f"`--dask-address` = {args.dask_address!r} needs `--executor dask`")
    if args.dask_timeout is not None and not args.dask_address:
        raise InputError(f"`--dask-timeout` = {args.dask_timeout:g} needs `--dask-address`")
    if args.executor == "dask" and args.dask_address:
        timeout = {} if args.dask_timeout is None else {"connect_timeout": args.dask_timeout}
        ex = get_executor("dask", args.workers, address=args.dask_address, **timeout)
        ex.connect()  # an unreachable scheduler is reported now, before any simulation runs
    else:
        ex = args.executor
    return dict(
        executor=ex,
        workers=None if not isinstance(ex, str) else args.workers,
        progress=False if args.no_progress else None,
    )
