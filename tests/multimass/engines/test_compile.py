"""The one-off compile (`multimass.engines.fast.compile`): where it is cached, what it says, staleness.

Compiling the real kernels takes ~17 s, so these tests drive the same machinery
(`compile_once`, `watch_compiles`, `choose_cache_dir`) with a probe: two tiny
``cache=True`` functions written to a temporary module. The one cold compile of
the real kernels is in ``test_cli_warmup.py`` (marked slow).
"""

import importlib.util
import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from multimass.engines.fast import compile as fc
from multimass.engines.fast import warm_up, warm_up_contact

REPO = Path(__file__).resolve().parents[3]

PROBE = textwrap.dedent(
    """
    from numba import njit


    @njit(cache=True)
    def inner(x):
        return 2 * x


    @njit(cache=True)
    def outer(x):
        return inner(x) + 1
    """
)


def _load(path: Path, name: str):
    """Import the file `path` as module `name` (new numba dispatchers each time)."""
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture
def probe(tmp_path, monkeypatch):
    """A folder with probe.py, and a loader that imports it under a fresh module name."""
    monkeypatch.delenv(fc.QUIET_ENV, raising=False)
    (tmp_path / "probe.py").write_text(PROBE)
    (tmp_path / "equations.py").write_text("# a source the probe compiles\n")
    names = []

    def load():
        name = f"_multimass_probe_{len(names)}_{tmp_path.name}"
        names.append(name)
        return _load(tmp_path / "probe.py", name)

    yield tmp_path, load
    for name in names:
        sys.modules.pop(name, None)


def _compile(folder: Path, mod, progress=None):
    return fc.compile_once(
        "the probe kernels",
        lambda: mod.outer(3),
        [mod.__name__],
        sources=[folder / "probe.py", folder / "equations.py"],
        stamp_file="probe.sources",
        progress=progress,
        estimate=1.0,
    )


# ---------------------------------------------------------------------------- the notice
def test_compiling_says_what_and_how_long_and_loading_is_silent(probe, capsys):
    folder, load = probe
    rep = _compile(folder, load())
    err = capsys.readouterr().err
    assert rep.source == "compiled" and rep.kernels == 2 and rep.what == "the probe kernels"
    assert rep.cache_dir == str(folder / "__pycache__")
    assert "multimass: compiling the probe kernels once for this machine (~1 s; cached in" in err
    assert str(folder / "__pycache__") in err
    assert "/2 kernels" in err  # the progress bar, one step per compiled kernel
    assert "multimass: compiled the probe kernels in" in err and "later runs load them" in err
    # a new process (here: new dispatchers from the same file) loads them, silently
    again = _compile(folder, load())
    assert again.source == "disk cache" and again.kernels == 0
    assert capsys.readouterr().err == ""


def test_in_memory_is_silent(probe, capsys):
    folder, load = probe
    mod = load()
    _compile(folder, mod)
    capsys.readouterr()
    rep = _compile(folder, mod)
    assert rep.source == "in memory" and capsys.readouterr().err == ""


@pytest.mark.parametrize("how", ["env", "argument"])
def test_quiet_mode(probe, capsys, monkeypatch, how):
    folder, load = probe
    if how == "env":
        monkeypatch.setenv(fc.QUIET_ENV, "1")
    rep = _compile(folder, load(), progress=False if how == "argument" else None)
    assert rep.source == "compiled" and rep.kernels == 2  # still compiled and counted
    assert capsys.readouterr().err == ""


def test_progress_true_overrides_the_quiet_variable(probe, capsys, monkeypatch):
    folder, load = probe
    monkeypatch.setenv(fc.QUIET_ENV, "1")
    _compile(folder, load(), progress=True)
    assert "multimass: compiling the probe kernels" in capsys.readouterr().err


def test_an_estimate_given_as_a_function_is_asked_only_when_compiling(probe, capsys):
    folder, load = probe
    asked = []

    def estimate():
        asked.append(1)
        return 42.0

    compile_ = lambda mod: fc.compile_once(  # noqa: E731
        "the probe kernels", lambda: mod.outer(3), [mod.__name__],
        sources=[folder / "probe.py"], stamp_file="probe.sources", estimate=estimate,
    )  # fmt: skip
    assert compile_(load()).source == "compiled" and asked == [1]
    assert "(~42 s; cached in" in capsys.readouterr().err
    assert compile_(load()).source == "disk cache" and asked == [1]  # loading: not asked


@pytest.mark.parametrize("pending", [(), ("_exp_kernel",), ("_kernel", "_contact_kernel")])
def test_the_column_runs_estimate_adds_the_groups_they_would_compile(monkeypatch, pending):
    """A cold compile of the whole column runs compiles whatever group they call that
    is not compiled yet: each such group's own estimate is added (measured apart: the
    column runs alone 10.1-10.4 s, the exponential group 15.2-15.4 s)."""
    monkeypatch.setattr(fc, "_GROUP_REPORTS", {})
    monkeypatch.setattr(fc, "_REPORT", None)
    monkeypatch.setattr(fc, "kernel_ready", lambda k, stamp, sources: k.__module__.split(".")[-1]
                        not in pending)  # fmt: skip
    own = {"_kernel": fc.COLD_COMPILE_S, "_contact_kernel": fc.CONTACT_COMPILE_S,
           "_exp_kernel": fc.EXPONENTIAL_COMPILE_S}  # fmt: skip
    expected = fc.COLUMNS_COMPILE_S + sum(own[m] for m in pending)
    assert fc.columns_estimate() == pytest.approx(expected)
    if pending:  # a group compiled in this process counts as ready whatever the disk says
        monkeypatch.setattr(fc, "_GROUP_REPORTS", dict.fromkeys(pending))
        monkeypatch.setattr(fc, "_REPORT", object())
        assert fc.columns_estimate() == pytest.approx(fc.COLUMNS_COMPILE_S)


# ---------------------------------------------------------------------------- staleness
def test_a_changed_source_drops_the_cache_and_recompiles(probe, capsys):
    folder, load = probe
    assert _compile(folder, load()).source == "compiled"
    stamp = (folder / "__pycache__" / "probe.sources").read_text()
    assert _compile(folder, load()).source == "disk cache"  # unchanged: loaded
    # an edit of a file the kernels compile, not the one numba keys the cache on
    (folder / "equations.py").write_text("# edited\n")
    rep = _compile(folder, load())
    assert rep.source == "compiled" and rep.kernels == 2
    assert (folder / "__pycache__" / "probe.sources").read_text() != stamp
    assert "multimass: compiling the probe kernels" in capsys.readouterr().err


def test_cached_on_disk_foretells_whether_compile_once_loads_or_compiles(probe):
    # the reference: what `compile_once` then reports, "disk cache" or "compiled"
    folder, load = probe
    sources = [folder / "probe.py", folder / "equations.py"]

    def foretold_then_done(mod) -> tuple[bool, str]:
        ahead = fc.cached_on_disk(mod.outer, "probe.sources", sources)
        return ahead, _compile(folder, mod).source

    assert foretold_then_done(load()) == (False, "compiled")  # an empty cache
    assert foretold_then_done(load()) == (True, "disk cache")
    (folder / "equations.py").write_text("# edited\n")  # a compiled source, not numba's key
    assert foretold_then_done(load()) == (False, "compiled")
    (folder / "probe.py").write_text(PROBE + "\n# edited\n")  # the file numba keys on
    mod = load()
    assert not fc.cached_on_disk(mod.outer)  # no fingerprint asked for: numba's index alone
    assert foretold_then_done(mod) == (False, "compiled")
    assert foretold_then_done(load()) == (True, "disk cache")
    mod = load()
    assert fc.cached_on_disk(mod.outer)
    assert not fc.cached_on_disk(mod.outer, "another.sources", sources)  # no such stamp


def test_kernel_ready_lists_the_sources_only_when_it_must_look_on_disk(probe):
    folder, load = probe
    listed = []

    def sources():
        listed.append(1)
        return [folder / "probe.py", folder / "equations.py"]

    mod = load()
    assert not fc.kernel_ready(mod.outer, "probe.sources", sources) and listed == [1]
    _compile(folder, mod)  # compiled in this process: no look on disk
    assert fc.kernel_ready(mod.outer, "probe.sources", sources) and listed == [1]
    assert fc.kernel_ready(load().outer, "probe.sources", sources) and listed == [1, 1]
    assert fc.kernel_ready(mod.outer.py_func, "probe.sources", sources)  # JIT off


def test_cached_on_disk_is_false_without_a_cache():
    from numba import njit

    assert not fc.cached_on_disk(njit(lambda x: x + 1))  # cache=False: numba's NullCache
    assert not fc.cached_on_disk(lambda x: x + 1)  # not a numba function at all


def test_without_jit_nothing_is_stamped_in_the_working_folder(probe, monkeypatch):
    """With numba's JIT off (``NUMBA_DISABLE_JIT``, for debugging) a group has no
    dispatchers and no cache: no fingerprint file may land in the user's working folder."""
    folder, load = probe
    work = folder / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    mod = load()
    monkeypatch.setattr(mod, "outer", mod.outer.py_func)  # what NUMBA_DISABLE_JIT leaves
    monkeypatch.setattr(mod, "inner", mod.inner.py_func)
    assert _compile(folder, mod).kernels == 0
    assert list(work.iterdir()) == []


def test_drop_stale_cache_removes_only_the_groups_files(tmp_path):
    files = ["_maths.rhs-10.py311.nbi", "_maths.rhs-10.py311.1.nbc", "other.f-3.py311.nbi"]
    for name in files:
        (tmp_path / name).write_text("x")
    (tmp_path / "stamp").write_text("new")
    fc._drop_stale_cache(tmp_path, "stamp", "new", ["_maths"])  # fresh: nothing dropped
    assert all((tmp_path / f).exists() for f in files)
    fc._drop_stale_cache(tmp_path, "stamp", "newer", ["_maths"])
    assert sorted(p.name for p in tmp_path.glob("*.nb?")) == ["other.f-3.py311.nbi"]


def test_another_group_first_drops_the_fast_kernels_stale_code(probe):
    # a group that calls the fast kernels (the contact, the whole runs, the exponential
    # method) in a process that never ran `warm_up`: numba would link `._kernel`'s cached
    # code compiled from an older `._rk`, so the group drops it first, as `warm_up` would
    folder, load = probe
    cache = folder / "__pycache__"
    cache.mkdir()
    fast = ["_kernel.integrate_phase-200.py311.nbi", "_rk.step_control-90.py311.1.nbc"]
    for name in fast:
        (cache / name).write_text("old machine code")
    (cache / fc._STAMP).write_text("the fingerprint of older sources")
    _compile(folder, load())
    assert not any((cache / f).exists() for f in fast)
    assert (cache / fc._STAMP).read_text() == fc._fingerprint(fc._sources())
    for name in fast:  # now current: kept
        (cache / name).write_text("current machine code")
    _compile(folder, load())
    assert all((cache / f).exists() for f in fast)


# ---------------------------------------------------------------------------- cache folder
@pytest.fixture
def no_numba_cache_dir(monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)


def _read_only_package(tmp_path) -> Path:
    """A package folder where numba cannot create __pycache__ (a file of that name):
    unwritable even for root, unlike a chmod."""
    pkg = tmp_path / "site" / "pkg"
    pkg.mkdir(parents=True)
    (pkg / "__pycache__").write_text("read-only install\n")
    return pkg


def test_cache_beside_the_sources_when_writable(tmp_path, no_numba_cache_dir):
    choice = fc.choose_cache_dir(tmp_path)
    assert choice.path is None and not choice.set_here
    assert "beside" in choice.reason


def test_numba_cache_dir_of_the_user_wins(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "mine"))
    choice = fc.choose_cache_dir(_read_only_package(tmp_path))
    assert choice.path == str(tmp_path / "mine") and not choice.set_here


def test_read_only_package_uses_the_user_cache(tmp_path, monkeypatch, no_numba_cache_dir):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    choice = fc.choose_cache_dir(_read_only_package(tmp_path))
    assert choice.set_here and choice.path == str(fc.user_cache_dir())
    if sys.platform.startswith("linux"):
        assert choice.path == str(tmp_path / "xdg" / "multimass" / "numba")
    assert Path(choice.path).is_dir() and "read-only" in choice.reason


def test_nothing_writable_uses_a_private_temporary_folder(
    tmp_path, monkeypatch, no_numba_cache_dir
):
    blocker = tmp_path / "blocker"
    blocker.write_text("a file, so no folder can be made below it")
    monkeypatch.setenv("XDG_CACHE_HOME", str(blocker / "cache"))
    monkeypatch.setenv("HOME", str(blocker))
    choice = fc.choose_cache_dir(_read_only_package(tmp_path))
    try:
        assert choice.set_here and Path(choice.path).is_dir()
        assert oct(Path(choice.path).stat().st_mode & 0o777) == "0o700"  # private
        assert "NUMBA_CACHE_DIR" in choice.reason  # says how to keep the kernels
    finally:
        shutil.rmtree(choice.path, ignore_errors=True)


_CHILD = """
import json, os, sys
if sys.argv[1] == "numba-first":
    import numba  # numba read NUMBA_CACHE_DIR already: multimass must make it read again
import multimass
import multimass.engines.fast
from multimass.engines.fast import _kernel, _probe, compile as fc
_probe.outer(3)
stats = _probe.outer.stats
print(json.dumps({
    "multimass": multimass.__file__,
    "env": os.environ.get("NUMBA_CACHE_DIR"),
    "reason": fc.CACHE.reason,
    "probe_cache": stats.cache_path,
    "kernel_cache": _kernel.integrate_phase.stats.cache_path,
    "hits": sum(stats.cache_hits.values()),
    "misses": sum(stats.cache_misses.values()),
}))
"""


def test_read_only_install_caches_in_the_user_cache_across_processes(tmp_path):
    # a copy of the package whose folder numba cannot write, with a probe kernel in it
    site = tmp_path / "site"
    shutil.copytree(
        REPO / "multimass", site / "multimass", ignore=shutil.ignore_patterns("__pycache__")
    )
    (site / "multimass" / "engines" / "fast" / "__pycache__").write_text("read-only install\n")
    (site / "multimass" / "engines" / "fast" / "_probe.py").write_text(PROBE)
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", fc.QUIET_ENV)}
    env |= {"PYTHONPATH": str(site), "XDG_CACHE_HOME": str(tmp_path / "xdg")}
    user = tmp_path / "xdg" / "multimass" / "numba"
    runs = []
    for order in ("numba-first", "multimass-first"):
        out = subprocess.run(
            [sys.executable, "-c", _CHILD, order],
            env=env,
            cwd=tmp_path,
            capture_output=True,
            text=True,
            check=True,
            timeout=120,
        )
        runs.append(json.loads(out.stdout.strip().splitlines()[-1]))
    first, second = runs
    assert first["multimass"].startswith(str(site))  # the copy ran, not the repository
    for run in runs:
        assert run["env"] == str(user) and "read-only" in run["reason"]
        assert run["probe_cache"].startswith(str(user))
        assert run["kernel_cache"].startswith(str(user))  # the real kernels go there too
    assert (first["misses"], first["hits"]) == (1, 0)  # compiled and written ...
    assert (second["misses"], second["hits"]) == (0, 1)  # ... loaded by the next process


# ---------------------------------------------------------------------------- the kernels
def test_warm_up_keeps_the_report_and_has_one_signature_per_kernel():
    from multimass import FreeRelease, Record, SineWave, simulate
    from multimass.engines.fast._contact_kernel import contact_phase
    from multimass.engines.fast._kernel import integrate_phase

    first = warm_up(progress=False)
    assert first.source in ("compiled", "disk cache", "in memory")
    assert first.what == "the fast kernels" and Path(first.cache_dir).is_dir()
    assert warm_up().source == "in memory"
    from multimass.engines.fast import _maths as mx

    # the per-run loop's transitions call the compiled energy and momentum (FastPath):
    # with the warm-up's types (other groups may add their own before this test)
    transitions = (mx._total_energy, mx._pivot_momentum)
    before = [set(f.signatures) for f in transitions]
    # real runs (a column, a block, two methods) reuse the warmed-up specialisation:
    # a second signature would compile again, silently, on first use
    simulate("S1", FreeRelease(0.11), "DD2", 0.3, backend="compiled")
    simulate("B6M", SineWave(amplitude=3.0, omega=20.0), "CIM", 0.5, backend="compiled")
    simulate("B6M", FreeRelease(0.1), "CIM", 0.3, backend="compiled", method="RK23")
    assert len(integrate_phase.signatures) == 1
    assert [set(f.signatures) for f in transitions] == before
    # and the closed-form full contact: a free release that settles, a record
    simulate("S1", FreeRelease(0.02), "DD2", 2.0, backend="compiled", output_dt=None)
    rec = Record.from_arrays([0.0, 0.02, 0.04], [0.0, 1.0, 0.0], units="m/s2")
    simulate("S1", rec, "DD2", 0.1, backend="compiled")
    assert len(contact_phase.signatures) == 1
    assert warm_up_contact().source == "in memory"


def test_the_kernel_count_of_the_notice():
    kernels = fc._kernels_of(f"multimass.engines.fast.{m}" for m in fc._KERNEL_MODULES)
    names = {k.py_func.__name__ for k in kernels}
    assert "integrate_phase" in names and "rhs_call" in names
    assert "contact_phase" not in names  # a group of its own (`warm_up_contact`)
    contact = fc._kernels_of([f"multimass.engines.fast.{fc._CONTACT}"])
    assert "contact_phase" in {k.py_func.__name__ for k in contact}
    assert "rhs" not in names and "rocking_rhs" not in names  # inlined, not compiled alone
    assert "column_run" not in names  # the whole column runs: a group of their own too
    columns = fc._kernels_of([f"multimass.engines.fast.{fc._COLUMNS}"])
    assert "column_run" in {k.py_func.__name__ for k in columns}
