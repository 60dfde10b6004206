"""The sweep engine: executors, batching, ordering, seeds, errors, progress.

Job functions live at module level so worker processes can import them.
"""

import io
import os
import signal
import subprocess
import sys
import time
import types
from pathlib import Path

import numba
import numpy as np
import pytest

from multimass.errors import InputError
from multimass.sweeps import (
    EXECUTORS,
    DaskExecutor,
    Executor,
    ExecutorError,
    JobError,
    ProcessExecutor,
    SerialExecutor,
    batch_plan,
    get_executor,
    job_seed,
    job_seeds,
    run_batches,
    run_jobs,
)
from tests.conftest import unavailable

# --- job functions (top level: picklable by reference) -------------------------------


def draw(job):
    """Random draws that depend only on the job's own seed."""
    rng = np.random.default_rng(job["seed"])
    return (job["i"], rng.standard_normal(4).tolist(), float(rng.uniform()))


def square(x):
    return x * x


def slow_first(job):
    """Early jobs sleep longest, so batches finish out of order."""
    i, n = job
    time.sleep(0.002 * (n - i))
    return i


def squares_of_a_batch(batch):
    """A batch job: a list of jobs in, their results in the same order out."""
    assert isinstance(batch, list)
    return [x * x for x in batch]


def fail_at_seven(x):
    if x == 7:
        raise KeyError("no such record", x)
    return x


class _Unpicklable(Exception):
    def __reduce__(self):
        raise TypeError("this exception refuses to be pickled")


def unpicklable_failure(x):
    if x == 3:
        raise _Unpicklable("lost in transit")
    return x


class _TwoArgError(Exception):
    def __init__(self, a, b):  # unpickling calls cls(message): TypeError
        super().__init__(f"{a}/{b}")


def two_arg_failure(x):
    if x == 2:
        raise _TwoArgError("left", "right")
    return x


def call_pair(job):
    f, x = job
    return f(x)


def unpicklable_result(x):
    return lambda: x


def kill_worker(x):
    if x == 1:
        os._exit(3)
    return x


@numba.njit(cache=False)
def _compiled_sum(n):
    s = 0.0
    for k in range(n):
        s += k * 0.5
    return s


def compiled_job(n):
    return _compiled_sum(n)


# --- fixtures: one pool / cluster per module -----------------------------------------


@pytest.fixture(scope="module")
def pool1():
    with ProcessExecutor(workers=1) as ex:
        yield ex


@pytest.fixture(scope="module")
def pool2():
    with ProcessExecutor(workers=2) as ex:
        yield ex


@pytest.fixture(scope="module")
def dask_client():
    try:
        import distributed
    except ImportError:
        unavailable("dask.distributed not installed (pip install -e '.[test]')")
    try:
        cluster = distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
        )
    except OSError as exc:  # a sandbox without sockets
        unavailable(f"dask.distributed cannot start a LocalCluster here: {exc!r}")
    client = distributed.Client(cluster)
    yield client
    client.close()
    cluster.close()


def _seeded_jobs(n=37, seed=2024):
    return [{"i": i, "seed": s} for i, s in enumerate(job_seeds(seed, n))]


# --- seeds ---------------------------------------------------------------------------


def test_job_seeds_are_the_seedsequence_children_and_stable_under_more_jobs():
    seeds = job_seeds(12345, 6)
    # closed form: child i of SeedSequence(s).spawn is SeedSequence(s, spawn_key=(i,))
    expected = [
        int(np.random.SeedSequence(12345, spawn_key=(i,)).generate_state(1, np.uint64)[0])
        & (2**63 - 1)
        for i in range(6)
    ]
    assert seeds == expected
    assert job_seeds(12345, 10)[:6] == seeds
    assert len(set(seeds)) == 6 and all(0 <= s < 2**63 for s in seeds)
    children = job_seeds(12345, 3, as_int=False)
    assert [c.spawn_key for c in children] == [(0,), (1,), (2,)]


def test_job_seeds_from_a_seedsequence_repeat_and_differ_by_base():
    base = np.random.SeedSequence(99)
    assert job_seeds(base, 4) == job_seeds(base, 4) == job_seeds(99, 4)
    assert job_seeds(1, 4) != job_seeds(2, 4)
    assert job_seeds(0, 0) == []


@pytest.mark.parametrize("base, n", [(-1, 3), (1.5, 3), (True, 3), ("7", 3), (1, -2), (1, 2.0)])
def test_job_seeds_reject_bad_input(base, n):
    with pytest.raises(InputError, match="`(base_seed|n)`"):
        job_seeds(base, n)


def test_job_seed_is_one_child_without_the_list():
    """`job_seed(s, i)` is seed i of `job_seeds(s, n)` (also from a SeedSequence with a
    spawn key), made alone, so a sweep of 1e10 jobs needs no list of its seeds."""
    ss = np.random.SeedSequence(7, spawn_key=(3,))
    for base in (12345, ss):
        assert [job_seed(base, i) for i in range(6)] == job_seeds(base, 6)
    expected = np.random.SeedSequence(12345, spawn_key=(10**10,)).generate_state(1, np.uint64)
    assert job_seed(12345, 10**10) == int(expected[0]) & (2**63 - 1)
    for base, i in ((None, 0), (1, -1), (1, 2.0), (-1, 0)):
        with pytest.raises(InputError, match="`(base_seed|i)`"):
            job_seed(base, i)


# --- determinism across executors, worker counts and batch sizes ---------------------


@pytest.mark.parametrize("batch_size", [None, 1, 3, 7, 100])
def test_process_pool_matches_serial_for_any_batch_size(pool2, batch_size):
    jobs = _seeded_jobs()
    reference = run_jobs(draw, jobs, executor="serial")
    assert [r[0] for r in reference] == list(range(len(jobs)))
    assert run_jobs(draw, jobs, executor=pool2, batch_size=batch_size) == reference


def test_one_and_two_workers_and_a_fresh_pool_agree(pool1):
    jobs = _seeded_jobs()
    reference = run_jobs(draw, jobs, executor="serial")
    assert run_jobs(draw, jobs, executor=pool1) == reference
    assert run_jobs(draw, jobs, executor="process", workers=2, batch_size=5) == reference


def test_dask_local_cluster_matches_serial(dask_client):
    jobs = _seeded_jobs()
    reference = run_jobs(draw, jobs, executor="serial")
    ex = DaskExecutor(client=dask_client)
    assert ex.workers == 2
    assert run_jobs(draw, jobs, executor=ex) == reference
    assert run_jobs(draw, jobs, executor=ex, batch_size=1) == reference


def test_jobs_that_look_like_dask_tasks_reach_the_function_untouched(dask_client):
    jobs = [(abs, -1.5), (len, "abc"), (abs, 2)]
    assert run_jobs(call_pair, jobs, executor=DaskExecutor(client=dask_client)) == [1.5, 3, 2]


def test_fork_start_method_gives_the_same_results():
    jobs = _seeded_jobs(n=9)
    with ProcessExecutor(workers=2, start_method="fork") as ex:
        assert run_jobs(draw, jobs, executor=ex) == run_jobs(draw, jobs, executor="serial")


def test_results_come_back_in_job_order_although_batches_finish_out_of_order(pool2):
    n = 12
    assert run_jobs(slow_first, [(i, n) for i in range(n)], executor=pool2, batch_size=1) == list(
        range(n)
    )


@pytest.mark.parametrize("n", [0, 1, 5, 37])
def test_run_batches_hands_whole_batches_and_returns_job_order(pool2, n):
    want = [x * x for x in range(n)]  # squares, by hand
    assert run_batches(squares_of_a_batch, range(n), executor=SerialExecutor()) == want
    assert run_batches(squares_of_a_batch, range(n), executor=pool2) == want


def test_numba_compiled_function_runs_in_workers(pool2):
    # closed form: sum_{k<n} k/2 = n(n-1)/4
    out = run_jobs(compiled_job, [10, 100, 1000], executor=pool2, batch_size=1)
    assert out == [10 * 9 / 4, 100 * 99 / 4, 1000 * 999 / 4]


# --- executors: registry, reuse, user's own ------------------------------------------


def test_registry_names_and_get_executor():
    assert set(EXECUTORS) == {"serial", "process", "dask"}
    assert isinstance(get_executor("serial"), SerialExecutor)
    with get_executor("Process", workers=3) as ex:
        assert isinstance(ex, ProcessExecutor) and ex.workers == 3
    inst = SerialExecutor()
    assert get_executor(inst) is inst


def test_an_executor_instance_is_reused_and_left_open(pool2):
    run_jobs(square, range(5), executor=pool2)
    pool = pool2._pool
    assert run_jobs(square, range(5), executor=pool2) == [0, 1, 4, 9, 16]
    assert pool2._pool is pool  # same processes, not closed by run_jobs


class ReversedExecutor(Executor):
    """A user's executor: runs the tasks in reverse order, counts them."""

    name = "reversed"
    needs_pickle = False

    def __init__(self, workers=None):
        self.n_workers = workers or 2
        self.tasks = 0

    @property
    def workers(self):
        return self.n_workers

    def map_unordered(self, fn, args):
        for i in reversed(range(len(args))):
            self.tasks += 1
            yield i, fn(args[i])


class LossyExecutor(ReversedExecutor):
    def map_unordered(self, fn, args):
        yield 0, fn(args[0])  # forgets the other batches


def test_users_own_executor_class_and_instance():
    assert run_jobs(square, range(10), executor=ReversedExecutor, workers=3) == [
        i * i for i in range(10)
    ]
    ex = ReversedExecutor(workers=2)
    assert run_jobs(square, range(17), executor=ex) == [i * i for i in range(17)]
    # guided plan: min(17, 64·2) = 17 stripes of one job; batches take ceil(R / (4·2))
    # of the R left: 3, 2, 2, 2, then 8 single stripes → 12 tasks
    assert ex.tasks == 12


class RecordingExecutor(ReversedExecutor):
    def map_unordered(self, fn, args):
        self.batches = [list(a.jobs) for a in args]
        yield from super().map_unordered(fn, args)


def test_batches_are_strided_and_no_larger_than_batch_size():
    ex = RecordingExecutor()
    assert run_jobs(square, range(10), executor=ex, batch_size=3) == [i * i for i in range(10)]
    # closed form: B = ceil(10 / 3) = 4 batches; batch k holds jobs k, k+4, k+8
    assert ex.batches == [[0, 4, 8], [1, 5, 9], [2, 6], [3, 7]]


@pytest.mark.parametrize("n_jobs, workers", [(1, 1), (17, 2), (400, 2), (10_000, 2), (999, 3)])
def test_guided_plan_covers_every_job_once_large_batches_first(n_jobs, workers):
    plan = batch_plan(n_jobs, workers)
    assert sorted(i for b in plan for i in b) == list(range(n_jobs))
    n_stripes = min(n_jobs, 64 * workers)  # STRIPES_PER_WORKER · workers
    stripes = [range(k, n_jobs, n_stripes) for k in range(n_stripes)]
    left, at = n_stripes, 0
    for batch in plan:  # each batch: the next ceil(R / (4·workers)) stripes
        take = -(-left // (4 * workers))
        assert batch == [i for s in stripes[at : at + take] for i in s]
        left, at = left - take, at + take
    assert left == 0
    sizes = [len(b) for b in plan]
    assert sizes == sorted(sizes, reverse=True)


@pytest.mark.parametrize(
    "args, field",
    [
        ((10, 0), "workers"),
        ((-1, 2), "n_jobs"),
        ((10.0, 2), "n_jobs"),
        ((10, True), "workers"),
        ((10, 2, 0), "batch_size"),
    ],
)
def test_batch_plan_rejects_bad_sizes(args, field):
    with pytest.raises(InputError, match=f"`{field}`"):
        batch_plan(*args)


def test_guided_plan_for_the_100x100_map_on_two_workers():
    # hand count: 128 stripes of 78-79 jobs; first batch 16 stripes (the first 16
    # stripes hold 79 jobs each), last batches one stripe (78 jobs) each
    plan = batch_plan(10_000, 2)
    assert len(plan[0]) == 16 * 79 and plan[0][:3] == [0, 128, 256]
    assert [len(b) for b in plan[-8:]] == [78] * 8
    assert len(plan) == 26


def test_an_executor_that_loses_batches_is_caught():
    with pytest.raises(ExecutorError, match="finished 3 of 10 jobs"):
        run_jobs(square, range(10), executor=LossyExecutor(workers=1), batch_size=3)


# --- errors from jobs and from executors ---------------------------------------------


def _executor(kind, request):
    if kind == "serial":
        return SerialExecutor()
    if kind == "process":
        return request.getfixturevalue("pool2")
    return DaskExecutor(client=request.getfixturevalue("dask_client"))


@pytest.mark.parametrize("kind", ["serial", "process", "dask"])
def test_a_failing_job_raises_job_error_with_index_and_cause(kind, request):
    ex = _executor(kind, request)
    with pytest.raises(JobError, match=r"job 7 of 20 failed .*KeyError") as info:
        run_jobs(fail_at_seven, range(20), executor=ex, batch_size=3)
    assert info.value.index == 7
    cause = info.value.__cause__
    assert isinstance(cause, KeyError) and cause.args == ("no such record", 7)
    if kind != "serial":  # the worker's traceback is chained below the cause
        assert "fail_at_seven" in str(cause.__cause__)
    # the executor still works after a failed sweep
    assert run_jobs(square, range(4), executor=ex) == [0, 1, 4, 9]


@pytest.mark.parametrize(
    "func, index, text",
    [
        (unpicklable_failure, 3, "lost in transit"),
        (two_arg_failure, 2, "left/right"),
    ],
)
def test_exceptions_that_cannot_travel_are_replaced_by_their_text(pool2, func, index, text):
    with pytest.raises(JobError) as info:
        run_jobs(func, range(6), executor=pool2, batch_size=2)
    assert info.value.index == index
    assert isinstance(info.value.__cause__, RuntimeError)
    assert text in str(info.value.__cause__)


def test_a_dead_worker_is_an_executor_error():
    with pytest.raises(ExecutorError, match="`process` executor failed"):
        run_jobs(kill_worker, range(4), executor="process", workers=2, batch_size=1)


def test_an_unpicklable_job_is_an_executor_error(pool2):
    jobs = [1, 2, lambda: 3]
    with pytest.raises(ExecutorError, match="picklable"):
        run_jobs(repr, jobs, executor=pool2, batch_size=1)


def test_an_unpicklable_result_is_an_executor_error(pool2):
    with pytest.raises(ExecutorError, match="results must be picklable"):
        run_jobs(unpicklable_result, range(3), executor=pool2)


# --- bad arguments -------------------------------------------------------------------


def test_empty_jobs_give_an_empty_list_without_starting_workers():
    for name in ("serial", "process"):
        assert run_jobs(square, [], executor=name) == []
    ex = ProcessExecutor(workers=2)
    assert run_jobs(square, iter(()), executor=ex) == [] and ex._pool is None


@pytest.mark.parametrize(
    "kwargs, field",
    [
        (dict(executor="threads"), "executor"),
        (dict(executor=42), "executor"),
        (dict(executor=dict), "executor"),
        (dict(workers=0), "workers"),
        (dict(workers=-3), "workers"),
        (dict(workers=1.5), "workers"),
        (dict(workers=True), "workers"),
        (dict(batch_size=0), "batch_size"),
        (dict(batch_size=2.5), "batch_size"),
        (dict(progress="yes"), "progress"),
        (dict(executor="serial", workers=4), "workers"),
        (dict(executor=SerialExecutor(), workers=2), "workers"),
    ],
)
def test_bad_arguments_raise_input_error_naming_the_argument(kwargs, field):
    with pytest.raises(InputError, match=f"`{field}`") as info:
        run_jobs(square, range(3), **kwargs)
    assert isinstance(info.value, ValueError)


def test_unknown_executor_lists_the_known_ones():
    with pytest.raises(InputError, match="'serial', 'process', 'dask'"):
        get_executor("cluster")


def test_func_must_be_callable_and_picklable_for_the_pool():
    with pytest.raises(InputError, match="`func`"):
        run_jobs(3, range(3), executor="serial")
    with pytest.raises(InputError, match="`func`.*cannot be pickled"):
        run_jobs(lambda x: x, range(3), executor="process")
    assert run_jobs(lambda x: x + 1, range(3), executor="serial") == [1, 2, 3]


def test_functions_from_an_interactive_session_are_rejected_for_forkserver(monkeypatch):
    main = types.ModuleType("__main__")  # like a notebook: no __file__

    def typed_in(x):
        return x

    typed_in.__module__, typed_in.__qualname__ = "__main__", "typed_in"
    main.typed_in = typed_in
    monkeypatch.setitem(sys.modules, "__main__", main)
    with pytest.raises(InputError, match="interactive session"):
        ProcessExecutor(workers=1, start_method="spawn").prepare(typed_in)


def test_unavailable_start_method():
    with pytest.raises(InputError, match="`start_method`"):
        ProcessExecutor(start_method="teleport")


# --- progress bar --------------------------------------------------------------------


class _FakeTerminal(io.StringIO):
    def isatty(self):
        return True


def test_progress_bar_shown_when_asked_even_off_a_terminal(capsys):
    run_jobs(square, range(10), executor="serial", progress=True, desc="spectra")
    err = capsys.readouterr().err
    assert "spectra" in err and "10/10" in err


def test_progress_bar_counts_weights(capsys):
    # e.g. the chunks of a batched map, counted in cells
    run_jobs(
        square, range(4), executor="serial", progress=True, weights=[30, 30, 30, 10], unit="cell"
    )
    err = capsys.readouterr().err
    assert "100/100" in err and "cell" in err
    for bad in ([1, 2], [1, 2, 3, -1], [1.5, 1, 1, 1], [True, 1, 1, 1]):
        with pytest.raises(InputError, match="weights"):
            run_jobs(square, range(4), executor="serial", weights=bad)


def test_no_progress_bar_by_default_off_a_terminal(capsys):
    run_jobs(square, range(200), executor="serial")
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize("n, shown", [(51, True), (50, False)])
def test_default_progress_on_a_terminal_only_for_long_sweeps(monkeypatch, n, shown):
    term = _FakeTerminal()
    monkeypatch.setattr(sys, "stderr", term)
    run_jobs(square, range(n), executor="serial")
    assert (f"{n}/{n}" in term.getvalue()) is shown


# --- Dask: finding, owning and closing clusters --------------------------------------


def test_dask_missing_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(ImportError, match=r'pip install "multimass\[dask\]"'):
        DaskExecutor()


def test_dask_leaves_a_given_client_open_and_uses_the_default_one(dask_client):
    with DaskExecutor(client=dask_client) as ex:
        assert run_jobs(square, range(3), executor=ex) == [0, 1, 4]
    assert dask_client.status == "running"
    ex = DaskExecutor()  # finds the default client
    assert ex.client is dask_client
    ex.close()
    assert dask_client.status == "running"
    with pytest.raises(InputError, match="`workers`"):
        DaskExecutor(2, client=dask_client)


def test_dask_closes_the_cluster_it_started(dask_client):
    ex = DaskExecutor(workers=1, processes=False)  # threads: starts fast
    assert run_jobs(square, range(5), executor=ex) == [0, 1, 4, 9, 16]
    cluster = ex._own_cluster
    assert cluster is not None and ex.client is not dask_client
    ex.close()
    assert cluster.status.name == "closed"
    assert dask_client.status == "running"


# --- scripts without the __main__ guard run sweeps on the process pool ------------------------

UNGUARDED = """
import multimass
from multimass.sweeps import run_jobs

def square(x):          # defined in the script: workers must import it from __main__
    return x * x

print(run_jobs(square, range(60), executor="process", workers=2))
"""


def test_an_unguarded_script_is_told_about_the_guard(tmp_path):
    import subprocess

    script = tmp_path / "unguarded.py"
    script.write_text(UNGUARDED)
    done = subprocess.run(
        [sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True, timeout=300
    )
    assert done.returncode != 0
    assert 'if __name__ == "__main__":' in done.stderr and 'executor="serial"' in done.stderr


def test_an_unreachable_dask_scheduler_is_an_input_error_naming_the_address():
    ex = DaskExecutor(address="tcp://127.0.0.1:1", connect_timeout=1.0)
    t0 = time.perf_counter()
    with pytest.raises(
        InputError,
        match=r"no Dask scheduler answered at .*'tcp://127.0.0.1:1' "
        r"within 1 s.*dask scheduler",
    ):
        run_jobs(abs, [1, 2], executor=ex)
    assert time.perf_counter() - t0 < 20.0
    with pytest.raises(InputError, match="`address` = ''"):
        DaskExecutor(address="")


# --- a parent killed with SIGKILL --------------------------------------------------------


def _children(pid: int) -> list[int]:
    """Every descendant of `pid` (Linux /proc)."""
    kids = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_bytes().rsplit(b")", 1)[1].split()
        except OSError:
            continue
        kids.setdefault(int(fields[1]), []).append(int(stat.parent.name))
    out, todo = [], [pid]
    while todo:
        for c in kids.get(todo.pop(), []):
            out.append(c)
            todo.append(c)
    return out


def _running(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_bytes().rsplit(b")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state != b"Z"


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs Linux /proc")
def test_pool_workers_end_when_their_parent_is_killed(tmp_path):
    script = tmp_path / "sweep.py"
    script.write_text(
        "import time\n"
        "from multimass.sweeps import run_jobs\n"
        "run_jobs(time.sleep, [60.0, 60.0], executor='process', workers=2)\n"
    )
    parent = subprocess.Popen([sys.executable, str(script)])
    try:
        deadline = time.monotonic() + 60.0
        workers = []
        while time.monotonic() < deadline and len(workers) < 3:  # forkserver + 2 workers
            time.sleep(0.2)
            workers = [p for p in _children(parent.pid) if _running(p)]
        assert len(workers) >= 3, "the pool did not start"
        parent.send_signal(signal.SIGKILL)
        parent.wait()
        deadline = time.monotonic() + 20.0
        while time.monotonic() < deadline and any(_running(p) for p in workers):
            time.sleep(0.2)
        left = [p for p in workers if _running(p)]
        assert not left, f"processes {left} outlived their killed parent"
    finally:
        if parent.poll() is None:
            parent.kill()


def test_forkserver_freezes_its_collector_last(monkeypatch):
    # the forkserver imports multimass and the asked modules, then the module that calls
    # gc.freeze, which stays last whatever is asked later
    from multiprocessing import forkserver

    from multimass.sweeps import executors

    asked = []
    server = forkserver._forkserver
    monkeypatch.setattr(server, "_preload_modules", ["__main__"], raising=False)
    monkeypatch.setattr(forkserver, "set_forkserver_preload", asked.append)
    executors._preload_in_forkserver("multimass.engines.fast.block_preload")
    assert asked[-1] == [
        "__main__", "multimass", "multimass.engines.fast.block_preload", executors._FREEZE,
    ]  # fmt: skip
    monkeypatch.setattr(server, "_preload_modules", asked[-1])
    executors._preload_in_forkserver("other.module")
    assert asked[-1][-2:] == ["other.module", executors._FREEZE]
    assert asked[-1].count(executors._FREEZE) == 1
    import gc

    import multimass.sweeps.forkserver_freeze  # noqa: F401  (the module the server imports)

    assert gc.get_freeze_count() > 0
    gc.unfreeze()
