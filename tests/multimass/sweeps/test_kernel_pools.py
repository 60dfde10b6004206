"""Which compiled kernels a sweep's process pool preloads (`multimass.sweeps.kernel_pools`)."""

import importlib.util

from multimass.sweeps.executors import ProcessExecutor, SerialExecutor
from multimass.sweeps.kernel_pools import kernel_session, preload_modules


def test_column_runs_preload_the_column_kernels_not_the_per_phase_ones():
    assert preload_modules(column=True, record=False) == ("multimass.engines.fast.column_preload",)
    assert preload_modules(column=True, record=True) == (
        "multimass.engines.fast.contact_preload",
        "multimass.engines.fast.column_preload",
    )
    assert preload_modules(column=False, record=True, batched=True) == (
        "multimass.engines.fast.preload",
        "multimass.engines.fast.block_preload",
    )
    for column in (True, False):
        for name in preload_modules(column, True, True):
            assert importlib.util.find_spec(name) is not None, name


def test_a_session_gives_its_pool_the_preload_and_leaves_a_given_executor_open():
    with kernel_session("process", 2, ("multimass.engines.fast.column_preload",)) as ex:
        assert isinstance(ex, ProcessExecutor) and ex.preload == (
            "multimass.engines.fast.column_preload",
        )
    with kernel_session("serial", None, ("x",)) as ex:
        assert isinstance(ex, SerialExecutor)
    own = SerialExecutor()
    with kernel_session(own, None) as ex:
        assert ex is own
