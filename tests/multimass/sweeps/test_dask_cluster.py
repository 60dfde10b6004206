"""A real Dask cluster: a scheduler and two workers, each a separate process on localhost.

The fixture starts them with the `dask` command line over TCP, as on an
office cluster (``dask scheduler`` / ``dask worker``, each worker under a nanny that
restarts it if it dies), and the tests send sweeps through ``--executor dask
--dask-address``: the results must equal the serial executor's in every cell, and a worker
killed mid-sweep may cost only the tasks it held, never a wrong or missing cell.

Job functions live at module level: the workers import this module (the fixture puts its
folder and the repository on their PYTHONPATH).
"""

import json
import os
import signal
import subprocess
import sys
import threading
import time
from collections import defaultdict
from contextlib import contextmanager
from pathlib import Path
from types import SimpleNamespace

import pandas as pd
import pytest

import multimass
from multimass.cli import main
from multimass.engines.fast import warm_up
from multimass.errors import InputError
from multimass.sweeps import DaskExecutor, batch_plan, run_jobs
from tests.conftest import REPO, unavailable

#: Seconds for the scheduler to write its address file.
SCHEDULER_TIMEOUT = 60.0
#: Seconds for both workers to join. Generous: a worker that finds no compiled kernels in
#: the disk cache compiles them (~40 s on this machine kind; the fixture warms the cache
#: in this process first, so it normally loads them in ~0.3 s).
READY_TIMEOUT = 300.0
#: Longest a sweep through the cluster may take before the test fails (instead of hanging).
SWEEP_TIMEOUT = 240.0
#: Seconds each job of the killed-worker sweep sleeps, so that a worker dies mid-sweep.
PAUSE = 0.1

MAP_ARGS = ["stability", "B6M", "--pulse", "sine", "--omega-p", "1:8:8", "--amp", "0.5:6:8"]
SPECTRUM_ARGS = ["spectrum", "S1", "--pulse", "cosine", "--omega", "5:30:4", "--amp", "0.3g"]
SPECTRUM_ARGS += ["--repeats", "2", "--restitution", "random", "--seed", "7", "--t-free", "2"]


# --- the cluster -----------------------------------------------------------------------


def _dask_command(*args: str) -> list[str]:
    """The `dask` command line of this interpreter's environment (``dask scheduler ...``)."""
    return [sys.executable, "-m", "dask", *args]


def _multimass_command() -> list[str]:
    """The `multimass` console script of this environment (else the same entry point)."""
    script = Path(sys.executable).with_name("multimass")
    if script.exists():
        return [str(script)]
    return [sys.executable, "-c", "import sys; from multimass.cli import main; sys.exit(main())"]


def _environment() -> dict:
    path = os.pathsep.join(
        [str(REPO), str(Path(__file__).parent), os.environ.get("PYTHONPATH", "")]
    )
    return dict(
        os.environ,
        PYTHONPATH=path.rstrip(os.pathsep),
        # a worker killed while the scheduler fetches a result from it: the scheduler
        # retries the dead address until this timeout (default 30 s) before recomputing
        DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT="5s",
    )


def _tail(path: Path, lines: int = 15) -> str:
    try:
        return "\n".join(path.read_text(errors="replace").splitlines()[-lines:])
    except OSError:
        return "(no log)"


def _stop(procs: list[subprocess.Popen]) -> None:
    """SIGTERM each process group, SIGKILL what is left after 15 s, wait until all are gone.

    Each process leads its own group (``start_new_session``), which holds its nanny's
    worker process too, so nothing outlives the fixture.
    """
    for sig, grace in ((signal.SIGTERM, 15.0), (signal.SIGKILL, 10.0)):
        for p in procs:
            try:
                os.killpg(p.pid, sig)
            except ProcessLookupError:
                pass
        deadline = time.monotonic() + grace
        alive = list(procs)
        while alive and time.monotonic() < deadline:
            for p in alive:
                p.poll()
            alive = [p for p in procs if _group_alive(p.pid)]
            time.sleep(0.1)
        if not alive:
            return
    raise RuntimeError(f"processes of the groups {[p.pid for p in alive]} survived SIGKILL")


def _group_alive(pgid: int) -> bool:
    """True while a process of the group runs (zombies, dead but not yet reaped, do not count)."""
    proc = Path("/proc")
    if proc.is_dir():
        for stat in proc.glob("[0-9]*/stat"):
            try:
                fields = stat.read_text().rsplit(")", 1)[1].split()
            except (OSError, IndexError):
                continue  # the process ended while we looked
            if int(fields[2]) == pgid and fields[0] != "Z":  # fields: state, ppid, pgrp, ...
                return True
        return False
    try:
        os.killpg(pgid, 0)
    except ProcessLookupError:
        return False
    return True


def _wait_for(what: str, ready, procs, logs, timeout: float):
    """Poll `ready()` until true; fail early, with the logs, if a process exits or time runs out."""
    deadline = time.monotonic() + timeout
    while not ready():
        dead = [(p, log) for p, log in zip(procs, logs) if p.poll() is not None]
        late = time.monotonic() > deadline
        if dead or late:
            why = (
                f"the {dead[0][1].stem} exited with status {dead[0][0].returncode}"
                if dead
                else f"{timeout:g} s passed"
            )
            report = "\n".join(f"--- {log.name}\n{_tail(log)}" for log in logs)
            pytest.fail(f"Dask cluster not ready: waiting for {what}, {why}\n{report}")
        time.sleep(0.2)


def _distributed():
    """dask.distributed, or a skip (a failure in CI: the `test` extra installs it)."""
    try:
        import distributed
    except ImportError:
        unavailable("dask.distributed not installed (pip install -e '.[test]')")
    return distributed


@pytest.fixture(scope="module")
def dask_cluster(tmp_path_factory):
    """A scheduler and two single-threaded, nanny-managed workers, started with the `dask`
    command line as separate processes on 127.0.0.1 over TCP; stopped at the end even if a
    test or the start fails."""
    distributed = _distributed()
    # compile (or load) the kernels here first, so that the workers find them in the cache
    warm_up()
    folder = tmp_path_factory.mktemp("dask_cluster")
    scheduler_file = folder / "scheduler.json"
    env = _environment()
    commands = {
        "scheduler": _dask_command(
            "scheduler",
            *("--host", "127.0.0.1", "--port", "0", "--dashboard-address", "127.0.0.1:0"),
            *("--scheduler-file", str(scheduler_file)),
            *("--idle-timeout", "600"),  # an orphan (test runner killed) ends by itself
        ),
    }
    for k in range(2):
        commands[f"worker{k}"] = _dask_command(
            "worker",
            *("--scheduler-file", str(scheduler_file), "--name", f"w{k}"),
            *("--nworkers", "1", "--nthreads", "1", "--nanny"),
            *("--host", "127.0.0.1", "--dashboard-address", "127.0.0.1:0"),
            *("--local-directory", str(folder / f"w{k}"), "--death-timeout", "60"),
            *("--preload", "multimass.engines.fast.preload"),  # kernels in memory before joining
        )
    procs, logs, client = [], [], None
    try:
        for name, command in commands.items():
            log = folder / f"{name}.log"
            with open(log, "w") as out:
                procs.append(
                    subprocess.Popen(
                        command,
                        stdout=out,
                        stderr=subprocess.STDOUT,
                        env=env,
                        cwd=folder,
                        start_new_session=True,
                    )
                )
            logs.append(log)
        _wait_for(
            "the scheduler file",
            lambda: scheduler_file.exists() and scheduler_file.stat().st_size > 0,
            procs,
            logs,
            SCHEDULER_TIMEOUT,
        )
        time.sleep(0.1)  # the file is written at once, but let its writer finish
        address = json.loads(scheduler_file.read_text())["address"]
        client = distributed.Client(address, timeout=30, set_as_default=False)
        _wait_for("two workers", lambda: len(client.nthreads()) == 2, procs, logs, READY_TIMEOUT)
        yield SimpleNamespace(address=address, client=client, folder=folder, logs=logs)
    finally:
        if client is not None:
            client.close()
        _stop(procs)


@contextmanager
def _deadline(seconds: float, what: str):
    """Fail (not hang) if the block takes longer than `seconds` (main thread, POSIX)."""
    if not hasattr(signal, "SIGALRM") or threading.current_thread() is not threading.main_thread():
        yield
        return

    def expire(signum, frame):
        raise TimeoutError(f"{what} took more than {seconds:g} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def _same_tables(folder: Path, name: str) -> pd.DataFrame:
    """Assert that the table `name` of the Dask run (in d/) equals the serial run's (in s/)
    in every cell, to the last bit; return it."""
    serial, dask = (pd.read_csv(folder / d / name) for d in ("s", "d"))
    pd.testing.assert_frame_equal(dask, serial, check_exact=True)  # shows where they differ
    # floats are written in their shortest exact form: the same text is the same bits
    assert (folder / "d" / name).read_text() == (folder / "s" / name).read_text()
    return serial


def _transitions(client) -> int:
    """Task transitions the scheduler has made so far (grows when tasks run on it)."""
    return client.run_on_scheduler(lambda dask_scheduler: dask_scheduler.transition_counter)


# --- a map and a spectrum through --executor dask --dask-address ----------------------


def test_the_workers_are_separate_processes_on_localhost(dask_cluster):
    pids = dask_cluster.client.run(os.getpid)
    assert len(pids) == 2 and len(set(pids.values())) == 2 and os.getpid() not in pids.values()
    assert all(a.startswith("tcp://127.0.0.1:") for a in [dask_cluster.address, *pids])


def test_a_map_from_the_command_line_equals_the_serial_map(dask_cluster, tmp_path):
    # serial first: it also compiles anything the map needs that the workers' cache lacks
    assert (
        main([*MAP_ARGS, "--executor", "serial", "--no-progress", "--out", str(tmp_path / "s")])
        == 0
    )
    before = _transitions(dask_cluster.client)
    command = [*_multimass_command(), *MAP_ARGS, "--no-progress"]
    command += ["--executor", "dask", "--dask-address", dask_cluster.address]
    done = subprocess.run(
        [*command, "--out", str(tmp_path / "d")],
        capture_output=True,
        text=True,
        timeout=SWEEP_TIMEOUT,
        env=_environment(),
    )
    assert done.returncode == 0, done.stderr
    assert _transitions(dask_cluster.client) > before  # its tasks ran on the cluster
    cells = _same_tables(tmp_path, "B6M_sine_modified_cells.csv")
    assert len(cells) > 64  # the 8 x 8 grid and its boundary refinement


def test_a_spectrum_from_the_command_line_equals_the_serial_spectrum(dask_cluster, tmp_path):
    assert (
        main(
            [*SPECTRUM_ARGS, "--executor", "serial", "--no-progress", "--out", str(tmp_path / "s")]
        )
        == 0
    )
    before = _transitions(dask_cluster.client)
    with _deadline(SWEEP_TIMEOUT, "the spectrum on the cluster"):
        code = main(
            [*SPECTRUM_ARGS, "--executor", "dask", "--dask-address", dask_cluster.address]
            + ["--no-progress", "--out", str(tmp_path / "d")]
        )
    assert code == 0
    assert _transitions(dask_cluster.client) > before
    runs = _same_tables(tmp_path, "S1_spectrum_omega.csv")
    assert len(runs) == 8 and runs.seed.nunique() == 8  # random restitution, seeded per job


def test_a_suite_on_the_cluster_equals_the_serial_suite(dask_cluster, tmp_path):
    # `multimass suite` runs on the sweep engine, so on a cluster too
    suite = tmp_path / "suite.toml"
    suite.write_text(
        'name = "B6M on a cluster"\n[structure]\nspecimen = "B6M"\n'
        "[monte_carlo]\ndraws = 3\nseed = 5\n"
        "k = { distribution = 'normal', mean = 0.82, std = 0.05 }\n"
        "[intensity]\nmeasure = 'amp_over_g_tan_alpha'\nlevels = [1.5, 3.0, 6.0]\n"
        "[pulses]\nomega_p_over_p = [1.5, 3.0]\n"
        "gamma = { distribution = 'uniform', low = 1.5, high = 3.0 }\n"
    )
    args = ["suite", str(suite), "--bootstrap", "0", "--no-progress"]
    assert main([*args, "--executor", "serial", "--out", str(tmp_path / "s")]) == 0
    before = _transitions(dask_cluster.client)
    with _deadline(SWEEP_TIMEOUT, "the suite on the cluster"):
        code = main(
            [*args, "--executor", "dask", "--dask-address", dask_cluster.address]
            + ["--out", str(tmp_path / "d")]
        )
    assert code == 0
    assert _transitions(dask_cluster.client) > before
    runs = _same_tables(tmp_path, "runs.csv")
    assert len(runs) == 2 * 3 * 3 and runs.seed.nunique() == 18


# --- a worker killed mid-sweep -------------------------------------------------------


def _note(log: str, what: str, index: int) -> None:
    with open(log, "a") as f:  # one short append: whole lines, even from two processes
        f.write(f"{what} {os.getpid()} {index}\n")


def slow_block_run(job):
    """One run of a B6M overturning map (sine pulse, η_M), slowed by `pause` seconds;
    with a `log`, notes its start and end with the pid of the process that ran it."""
    log, index, omega_p, amp, pause = job
    if log:
        _note(log, "start", index)
    time.sleep(pause)
    st = multimass.from_specimen("B6M")
    exc = multimass.SineWave(amplitude=amp * st.alpha_cg * st.g, omega=omega_p * st.p)
    o = multimass.simulate_outcome(
        st, exc, "CIM", exc.duration + 5.0, restitution="modified", stop_when_safe=True
    )
    if log:
        _note(log, "end", index)
    return o.status, o.theta_max, o.n_impacts, tuple(e.time for e in o.events)


def _runs(log: Path) -> tuple[dict, dict]:
    """{job: [pids that started it]} and {job: [pids that finished it]}, from the log."""
    started, ended = defaultdict(list), defaultdict(list)
    for line in log.read_text().splitlines():
        if len(line.split()) != 3:
            continue  # a line being written right now
        what, pid, index = line.split()
        (started if what == "start" else ended)[int(index)].append(int(pid))
    return started, ended


def _kill_a_busy_worker(log: Path, after: int, killed: list, stop: threading.Event) -> None:
    """Once `after` jobs have ended, SIGKILL the worker process running a job right now.

    Appends (pid, job, time of the kill, whether the job had ended by then) to `killed`.
    """
    while not stop.is_set():
        started, ended = _runs(log) if log.exists() else ({}, {})
        if sum(map(len, ended.values())) >= after:
            busy = [(i, p[-1]) for i, p in started.items() if i not in ended]
            if busy:
                job, pid = max(busy)
                at = time.monotonic()
                os.kill(pid, signal.SIGKILL)
                killed.append((pid, job, at, job in _runs(log)[1]))  # ended in between?
                return
        time.sleep(0.005)


class RecordingDask(DaskExecutor):
    """The Dask executor, noting when the driver received each batch."""

    def map_unordered(self, fn, args):
        self.received = {}
        for i, out in super().map_unordered(fn, args):
            self.received[i] = time.monotonic()
            yield i, out


def test_a_worker_killed_mid_sweep_costs_only_its_tasks(dask_cluster, tmp_path):
    n_jobs, batch, after = 48, 2, 20
    grid = [(1.0 + 0.5 * (i % 8), 0.5 + 0.75 * (i // 8)) for i in range(n_jobs)]
    reference = run_jobs(
        slow_block_run, [(None, i, w, a, 0.0) for i, (w, a) in enumerate(grid)], executor="serial"
    )
    log = tmp_path / "jobs.log"
    jobs = [(str(log), i, w, a, PAUSE) for i, (w, a) in enumerate(grid)]
    client = dask_cluster.client
    pids = set(client.run(os.getpid).values())
    killed, stop = [], threading.Event()
    killer = threading.Thread(target=_kill_a_busy_worker, args=(log, after, killed, stop))
    killer.start()
    try:
        with _deadline(SWEEP_TIMEOUT, "the sweep with a killed worker"):
            with RecordingDask(address=dask_cluster.address) as ex:
                results = run_jobs(slow_block_run, jobs, executor=ex, batch_size=batch)
    finally:
        stop.set()
        killer.join()
    assert killed, "the sweep ended before a worker was killed; make the jobs slower"
    ((pid, job, t_kill, job_had_ended),) = killed
    assert pid in pids

    # no wrong or missing cell
    assert results == reference
    started, ended = _runs(log)
    assert sorted(ended) == list(range(n_jobs))

    # The jobs that ran twice are the killed worker's: the batch it was running, perhaps
    # one it had finished whose result was on its way; no job ran more than twice.
    rerun = {i: p for i, p in started.items() if len(p) > 1}
    log_text = log.read_text()
    assert all(len(p) == 2 and p[0] == pid and p[1] != pid for p in rerun.values()), log_text
    assert job in rerun or job_had_ended, log_text
    assert len(rerun) <= 2 * batch, log_text
    # Batches the driver had received (100 ms before the kill: time for the release of
    # their results to reach the scheduler) were not computed again, though the killed
    # worker ran some of them.
    plan = batch_plan(n_jobs, 2, batch)
    received = {i for b, t in ex.received.items() if t < t_kill - 0.1 for i in plan[b]}
    assert any(started[i][0] == pid for i in received), log_text
    assert not received & set(rerun), log_text

    # the nanny restarted the worker: the cluster is back to two
    client.wait_for_workers(2, timeout=READY_TIMEOUT)
    assert pid not in client.run(os.getpid).values()


# --- a scheduler that does not answer, or has no worker --------------------------------


def test_an_unreachable_scheduler_is_one_line_and_exit_2_before_any_run(monkeypatch, capsys):
    import multimass.sweeps.maps

    def refuse(*args, **kwargs):
        raise AssertionError("the map started although the scheduler did not answer")

    monkeypatch.setattr(multimass.sweeps.maps, "overturning_map", refuse)
    code = main(
        [*MAP_ARGS, "--executor", "dask", "--dask-address", "tcp://127.0.0.1:1"]
        + ["--dask-timeout", "1"]
    )
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("multimass stability: error: no Dask scheduler")
    assert "'tcp://127.0.0.1:1' within 1 s" in err and "`dask scheduler`" in err


@pytest.mark.parametrize(
    "address, words",
    [
        ("garbage", ["'garbage' is not a scheduler address", "tcp://HOST:PORT"]),
        ("tcp://127.0.0.1:1", ["no Dask scheduler answered", "ConnectionRefusedError"]),
    ],
)
def test_a_bad_or_refused_address_is_one_line_and_nothing_follows(address, words):
    """An address that cannot be parsed fails at once, and a closed port is refused
    without creating a Dask client: the process ends with exit 2 and a single line on
    stderr — no traceback from a failed client's clean-up (which came ~30 s later)."""
    start = time.perf_counter()
    done = subprocess.run(
        [*_multimass_command(), *MAP_ARGS, "--executor", "dask", "--dask-address", address]
        + ["--dask-timeout", "2", "--no-progress"],
        capture_output=True,
        text=True,
        env=_environment(),
        timeout=60,
    )
    elapsed = time.perf_counter() - start
    assert done.returncode == 2, done.stderr
    assert done.stderr.count("\n") == 1, done.stderr
    assert done.stderr.startswith("multimass stability: error: ")
    assert all(w in done.stderr for w in words), done.stderr
    assert elapsed < 15.0


def test_dask_timeout_needs_a_dask_address(capsys):
    assert main([*MAP_ARGS, "--executor", "dask", "--dask-timeout", "1"]) == 2
    assert "`--dask-timeout` = 1 needs `--dask-address`" in capsys.readouterr().err


def test_a_scheduler_without_workers_is_waited_for_then_named(capsys):
    distributed = _distributed()
    with distributed.LocalCluster(n_workers=0, processes=False, dashboard_address=":0") as cluster:
        with DaskExecutor(address=cluster.scheduler_address, worker_timeout=0.5) as ex:
            with pytest.raises(InputError, match=r"no Dask worker joined .*`worker_timeout`"):
                run_jobs(abs, [1, -2], executor=ex)
        assert "waiting (start workers with `dask worker" in capsys.readouterr().err
        timer = threading.Timer(0.5, cluster.scale, args=(1,))
        timer.start()
        with DaskExecutor(address=cluster.scheduler_address) as ex:
            assert run_jobs(abs, [1, -2, 3], executor=ex) == [1, 2, 3]
        timer.join()
        assert "Dask worker thread(s) after" in capsys.readouterr().err
