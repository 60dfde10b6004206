"""Per-job random seeds: a job's randomness depends only on (base seed, job index).

Seeds come from ``numpy.random.SeedSequence(base_seed).spawn``: child ``i``
is ``SeedSequence(base_seed, spawn_key=(i,))``, statistically independent of
the others and unchanged when more jobs are added. A job carries its seed, so
which worker or batch runs it cannot change its draws.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError

__all__ = ["job_seeds", "job_seed"]

_INT63 = (1 << 63) - 1


def _base_sequence(base_seed: Any) -> np.random.SeedSequence:
    if isinstance(base_seed, np.random.SeedSequence):
        # a fresh copy, so that repeated calls spawn the same children
        return np.random.SeedSequence(
            base_seed.entropy, spawn_key=base_seed.spawn_key, pool_size=base_seed.pool_size
        )
    if base_seed is None or (
        isinstance(base_seed, (int, np.integer))
        and not isinstance(base_seed, bool)
        and base_seed >= 0
    ):
        return np.random.SeedSequence(None if base_seed is None else int(base_seed))
    raise InputError(
        f"`base_seed` = {base_seed!r}: expected a non-negative integer, a "
        "numpy SeedSequence, or None (fresh entropy, not reproducible)"
    )


def _child_seed(base: np.random.SeedSequence, i: int) -> int:
    """64 bits of child `i`'s state, top bit dropped so the seed fits int64."""
    child = np.random.SeedSequence(
        base.entropy, spawn_key=(*base.spawn_key, i), pool_size=base.pool_size
    )
    return int(child.generate_state(1, np.uint64)[0]) & _INT63


def job_seed(base_seed: int | np.random.SeedSequence, i: int) -> int:
    """The seed of job `i` alone: ``job_seeds(base_seed, n)[i]`` for any n > i.

    It builds only child `i` of ``SeedSequence(base_seed)`` (spawn key ``(i,)``), so a
    sweep of billions of jobs derives each seed when its job is made, never a list of all.

    Parameters
    ----------
    base_seed : int or numpy.random.SeedSequence
        Seed of the whole sweep (None is refused: fresh entropy per call would give every
        job unrelated, unreproducible seeds).
    i : int
        The job's index, ≥ 0.

    Examples
    --------
    >>> job_seed(2024, 2) == job_seeds(2024, 3)[2]
    True
    """
    if base_seed is None:
        raise InputError("`base_seed` = None: give a seed (an integer ≥ 0) to derive job seeds")
    if isinstance(i, bool) or not hasattr(i, "__index__") or i.__index__() < 0:
        raise InputError(f"`i` = {i!r}: expected a job index, an integer ≥ 0")
    return _child_seed(_base_sequence(base_seed), i.__index__())


def job_seeds(
    base_seed: int | np.random.SeedSequence | None, n: int, *, as_int: bool = True
) -> list:
    """One independent seed per job.

    Parameters
    ----------
    base_seed : int, numpy.random.SeedSequence or None
        Seed of the whole sweep. None draws fresh entropy (not reproducible).
    n : int
        Number of jobs.
    as_int : bool, default True
        Return Python ints in [0, 2**63) (they fit an int64 table column and
        JSON); False returns the ``SeedSequence`` children themselves.

    Returns
    -------
    list
        ``n`` seeds; pass one to ``numpy.random.default_rng`` inside the job.
        Seed ``i`` depends only on (`base_seed`, ``i``), so ``job_seeds(s, 5)``
        is the start of ``job_seeds(s, 10)``.

    Examples
    --------
    >>> import numpy as np
    >>> seeds = job_seeds(2024, 3)
    >>> seeds == job_seeds(2024, 5)[:3]
    True
    >>> rng = np.random.default_rng(seeds[0])   # inside job 0
    """
    if isinstance(n, bool) or not hasattr(n, "__index__") or n.__index__() < 0:
        raise InputError(f"`n` = {n!r}: expected a non-negative integer number of jobs")
    base = _base_sequence(base_seed)
    if not as_int:
        return base.spawn(n.__index__())
    return [_child_seed(base, i) for i in range(n.__index__())]
