"""One-off compilation of the kernels: where it is cached, what the user sees, how long.

The kernels are ``numba.njit(cache=True)``: the first process on a machine that
calls them compiles them (~17 s) and writes the machine code to numba's disk
cache; later processes load it (~0.3 s). `warm_up` does that once per process,
on a tiny problem whose argument types are those of every real call, and says
how long it took and whether the code came from the cache.
`multimass.simulate` calls it before starting its clock, so
``Response.wall_time_s`` never includes compilation; ``multimass warm-up``
calls it (and the other kernels' warm-ups) from the shell.

**What the user sees.** Loading from the cache is silent. Compiling prints on
stderr, once::

    multimass: compiling the fast kernels once for this machine (~17 s; cached in DIR) ...
    multimass: compiling:  45%|████▌     | 9/20 kernels [00:06<00:07]
    multimass: compiled the fast kernels in 17 s (20 kernels); later runs load them in ~0.3 s

The notice comes from numba's own compile events (`watch_compiles`), so it
appears whenever numba really compiles — an empty cache, a stale one, a numba
upgrade — and never when it loads. Quiet mode, for services and batch logs:
set the environment variable ``MULTIMASS_QUIET=1``, or call
``warm_up(progress=False)`` once at start-up (later calls find the kernels in
memory).

**Where the machine code goes** (decided when `multimass.engines.fast` is imported,
before numba compiles anything, see `choose_cache_dir`): ``NUMBA_CACHE_DIR``
if the user set it; else numba's default, ``__pycache__`` beside the sources;
if that folder is not writable (a system-wide install, a read-only container),
the per-user cache ``$XDG_CACHE_HOME/multimass/numba`` (``~/.cache/...``;
``~/Library/Caches/...`` on macOS, ``%LOCALAPPDATA%\\...`` on Windows), set
through ``NUMBA_CACHE_DIR`` for this process and its children (numba functions
of other packages defined later in the process are cached there too); if that
is not writable either, a fresh private temporary folder (compiled again by each
process). numba reads ``NUMBA_CACHE_DIR`` when it is imported and each
``cache=True`` function picks its cache folder when it is defined, so the
variable is set, and numba's configuration reloaded if numba was already
imported, before the kernel modules are.

**Stale caches.** numba keys a cached function on the file that defines it, not
on the files of the functions it calls: after an edit of `._maths` or `._rk`
(or an upgrade) the cached `._kernel.integrate_phase` would be stale.
`compile_once` therefore keeps a fingerprint of the kernel sources, of the
equations they compile (`multimass.model.equations`,
`multimass.impact_models.gaussian_force`, the accuracy rule of `multimass.checks`) and
of numba's version beside the cache, and drops the cached kernels when it changes.
"""

from __future__ import annotations

import functools
import hashlib
import importlib
import os
import pickle
import sys
import tempfile
import time
from collections.abc import Callable, Iterable
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from ...progress import Progress, format_duration

__all__ = [
    "warm_up",
    "warm_up_contact",
    "warm_up_columns",
    "columns_ready",
    "warm_up_exponential",
    "compile_once",
    "cached_on_disk",
    "kernel_ready",
    "watch_compiles",
    "CompileReport",
    "CacheChoice",
    "choose_cache_dir",
    "user_cache_dir",
    "CACHE",
    "QUIET_ENV",
    "COLD_COMPILE_S",
    "CONTACT_COMPILE_S",
    "COLUMNS_COMPILE_S",
    "columns_estimate",
    "EXPONENTIAL_COMPILE_S",
    "LOAD_S",
]

#: Set this environment variable to 1 to silence the one-off compile notice.
QUIET_ENV = "MULTIMASS_QUIET"
#: Wall time of a cold compile of the fast kernels (s; 2-core machine, idle), shown up front.
COLD_COMPILE_S = 17.0
#: Wall time to load them from the disk cache (s).
LOAD_S = 0.3

_HERE = Path(__file__).resolve().parent
_KERNEL_MODULES = ("_maths", "_rk", "_kernel")  # the modules holding njit(cache=True) code
_CONTACT = "_contact_kernel"  # its own group: compiled when a run first needs it
_CONTACT_STAMP = "multimass_contact.sources"
#: Wall time of a cold compile of the closed-form full contact (s; 2-core machine, idle).
CONTACT_COMPILE_S = 7.0
_COLUMNS = "_column_kernel"  # whole column runs for sweeps: a group of its own too
_COLUMNS_STAMP = "multimass_columns.sources"
#: Wall time of a cold compile of the whole column runs alone (s; 2-core machine, load
#: ~0.5, the groups they call cached: 10.1–10.4 s); `columns_estimate` adds those groups.
COLUMNS_COMPILE_S = 11.0
_EXPONENTIAL = "_exp_kernel"  # the exponential rocking integrator (method "exponential")
_EXPONENTIAL_STAMP = "multimass_exponential.sources"
#: Wall time of a cold compile of the exponential rocking integrator (s; 2-core machine at
#: load ~2, fresh processes with empty caches: 15.2–15.4 s, the fast kernels 17–18 s then).
EXPONENTIAL_COMPILE_S = 15.0
_STAMP = "multimass_fast.sources"


# ---------------------------------------------------------------------------- cache folder
def user_cache_dir() -> Path:
    """The per-user folder for multimass's compiled kernels (``.../multimass/numba``)."""
    home = Path(os.path.expanduser("~"))
    if sys.platform == "win32":
        base = Path(os.environ.get("LOCALAPPDATA") or home / "AppData" / "Local")
    elif sys.platform == "darwin":
        base = home / "Library" / "Caches"
    else:  # XDG: a relative XDG_CACHE_HOME is invalid and ignored
        xdg = os.environ.get("XDG_CACHE_HOME", "")
        base = Path(xdg) if os.path.isabs(xdg) else home / ".cache"
    return base / "multimass" / "numba"


def _writable(folder: Path) -> bool:
    """numba's own test of a cache folder: create it, then a temporary file in it."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
        return True
    except OSError:
        return False


@dataclass(frozen=True)
class CacheChoice:
    """Where numba keeps the compiled kernels, and why.

    Attributes
    ----------
    path : str or None
        The ``NUMBA_CACHE_DIR`` in force; None: numba's default, ``__pycache__``
        beside the sources.
    reason : str
        Why, in words for the user.
    set_here : bool
        True when multimass set ``NUMBA_CACHE_DIR`` itself (read-only package folder).
    """

    path: str | None
    reason: str
    set_here: bool = False


def choose_cache_dir(package_dir: Path = _HERE) -> CacheChoice:
    """Decide where numba caches the kernels of `package_dir` (see the module docstring).

    Reads the environment (``NUMBA_CACHE_DIR``, ``XDG_CACHE_HOME``) and may create
    the cache folder; changes nothing else.

    Parameters
    ----------
    package_dir : Path
        The folder of the kernel sources (numba's default cache is its ``__pycache__``).
    """
    if os.environ.get("NUMBA_CACHE_DIR"):
        return CacheChoice(os.environ["NUMBA_CACHE_DIR"], "NUMBA_CACHE_DIR is set")
    if _writable(Path(package_dir) / "__pycache__"):
        return CacheChoice(None, "beside the package's sources")
    user = user_cache_dir()
    if _writable(user):
        return CacheChoice(str(user), "per-user cache: the package folder is read-only", True)
    private = tempfile.mkdtemp(prefix="multimass-numba-")  # never a shared, guessable folder
    return CacheChoice(
        private,
        "a temporary folder, not kept: neither the package folder nor "
        f"{user} is writable (set NUMBA_CACHE_DIR to keep the kernels)",
        True,
    )


def _use(choice: CacheChoice) -> None:
    """Point numba at `choice` before any kernel module defines its functions."""
    if not choice.set_here:
        return
    os.environ["NUMBA_CACHE_DIR"] = choice.path
    if "numba" in sys.modules:  # imported already: it read the variable then; read it again
        from numba.core import config

        config.reload_config()


#: Where this process caches the kernels (decided on import, before numba compiles).
CACHE = choose_cache_dir()
_use(CACHE)


# ---------------------------------------------------------------------------- the notice
def _quiet_env() -> bool:
    return os.environ.get(QUIET_ENV, "").strip().lower() in ("1", "true", "yes", "on")


def _kernels_of(modules: Iterable[str]) -> list:
    """The numba dispatchers compiled as units in `modules` (not the ones inlined)."""
    from numba.core.registry import CPUDispatcher

    out = []
    for name in modules:
        for obj in vars(importlib.import_module(name)).values():
            if (
                isinstance(obj, CPUDispatcher)
                and obj.py_func.__module__ == name
                and obj.targetoptions.get("inline", "never") != "always"
            ):
                out.append(obj)
    return out


class _Watch:
    """Counts (and, if `show`, announces with a progress bar) the kernels numba compiles."""

    def __init__(self, what, modules: tuple, show: bool, cache_dir: str, estimate, load):
        self.what, self.modules, self.show = what, modules, show
        self.cache_dir, self.estimate, self.load = cache_dir, estimate, load
        self.total = len(_kernels_of(modules))
        self.compiled = 0  # kernels of `modules` compiled (not loaded)
        self.started: float | None = None
        self.seconds = 0.0
        self._bar: Progress | None = None

    def _ours(self, event) -> bool:
        disp = event.data.get("dispatcher") if isinstance(event.data, dict) else None
        return getattr(getattr(disp, "py_func", None), "__module__", None) in self.modules

    def start(self, event) -> None:
        if self.started is not None or not self._ours(event):
            return
        self.started = time.perf_counter()
        if self.show:
            where = f" — {CACHE.reason}" if CACHE.set_here else ""
            estimate = self.estimate() if callable(self.estimate) else self.estimate
            print(
                f"multimass: compiling {self.what} once for this machine "
                f"(~{format_duration(estimate)}; cached in {self.cache_dir}{where}) ...",
                file=sys.stderr,
                flush=True,
            )
            self._bar = Progress(
                max(self.total, 1), "multimass: compiling", show=True, unit="kernels"
            )

    def end(self, event) -> None:
        if self._ours(event):
            self.compiled += 1
            if self._bar is not None:
                self._bar.update(self.compiled)

    def close(self, failed: bool = False) -> None:
        if self._bar is not None:
            self._bar.close()
        if self.started is None:
            return
        self.seconds = time.perf_counter() - self.started
        if self.show and not failed:  # a failure speaks for itself (its exception)
            print(
                f"multimass: compiled {self.what} in {format_duration(self.seconds)} "
                f"({self.compiled} kernels); later runs load them in ~{self.load:g} s",
                file=sys.stderr,
                flush=True,
            )


@contextmanager
def watch_compiles(
    what: str,
    modules: Iterable[str],
    cache_dir: str,
    progress: bool | None = None,
    estimate: float | Callable[[], float] = COLD_COMPILE_S,
    load: float = LOAD_S,
):
    """Announce and count the kernels of `modules` numba compiles inside the block.

    Loading from the disk cache is silent; the first real compilation prints one
    line naming `what`, the estimated time and the cache folder, then a progress
    bar per compiled kernel, then the time it took (all on stderr).

    Parameters
    ----------
    what : str
        The kernels, as the user reads them (e.g. "the fast kernels").
    modules : iterable of str
        Full names of the modules whose numba functions are counted.
    cache_dir : str
        Where they are cached (shown).
    progress : bool, optional
        False: silent; True or None: the notice, unless ``MULTIMASS_QUIET`` is set
        (None) — True shows it even then.
    estimate : float or callable
        The expected compile time (s), shown up front; a function returning it is
        asked only then (when numba starts compiling and the notice is shown).
    load : float
        The time to load the kernels from the cache (s), shown at the end.

    Yields
    ------
    watch
        ``.compiled`` (kernels compiled), ``.total`` (kernels in `modules`) and,
        after the block, ``.seconds`` from the first compilation to the end.
    """
    from numba.core import event

    show = progress if progress is not None else not _quiet_env()
    watch = _Watch(what, tuple(modules), bool(show), str(cache_dir), estimate, load)

    class _Listener(event.Listener):
        def on_start(self, ev):
            watch.start(ev)

        def on_end(self, ev):
            watch.end(ev)

    try:
        with event.install_listener("numba:compile", _Listener()):
            yield watch
    except BaseException:
        watch.close(failed=True)
        raise
    watch.close()


# ---------------------------------------------------------------------------- compile once
@dataclass(frozen=True)
class CompileReport:
    """How a group of compiled kernels became ready in this process.

    Attributes
    ----------
    seconds : float
        Time to compile or load them (0 if they were ready already).
    source : {"compiled", "disk cache", "in memory"}
        "compiled": built now (and written to the disk cache); "disk cache":
        loaded from it; "in memory": this process had them already.
    cache_dir : str
        Where numba keeps the cached machine code.
    kernels : int
        How many kernels were compiled (0 when loaded).
    what : str
        The group of kernels.
    """

    seconds: float
    source: str
    cache_dir: str
    kernels: int = 0
    what: str = "the fast kernels"

    def to_dict(self) -> dict:
        return {
            "what": self.what,
            "seconds": self.seconds,
            "source": self.source,
            "kernels_compiled": self.kernels,
            "cache_dir": self.cache_dir,
        }


def _fingerprint(sources: Iterable[Path]) -> str:
    import numba

    h = hashlib.sha256(numba.__version__.encode())
    for path in sources:
        h.update(Path(path).read_bytes())
    return h.hexdigest()


def _drop_stale_cache(cache_dir: Path, stamp_file: str, stamp: str, own: Iterable[str]) -> None:
    """Delete the cached kernels of the modules `own` if their sources changed."""
    try:
        if (cache_dir / stamp_file).read_text() == stamp:
            return
    except OSError:
        pass
    for mod in own:
        for f in cache_dir.glob(f"{mod}.*.nb[ic]"):
            try:
                f.unlink()
            except OSError:  # another process got there first, or read-only
                pass


def _fresh_fast_cache(cache_dir: Path) -> None:
    """Drop the fast kernels' cached code in `cache_dir` if their sources changed, as
    `warm_up` does, and stamp it. The other groups call those kernels: a group recompiled
    after an edit of ``._rk`` or ``._maths`` alone would otherwise link the cached code of
    ``._kernel`` (numba checks only the file defining each function), compiled from the
    old sources, in a process that never ran `warm_up`."""
    stamp = _fingerprint(_sources())
    _drop_stale_cache(cache_dir, _STAMP, stamp, _KERNEL_MODULES)
    try:
        (cache_dir / _STAMP).write_text(stamp)
    except OSError:
        pass


def compile_once(
    what: str,
    call: Callable[[], object],
    modules: Iterable[str],
    sources: Iterable[Path] = (),
    stamp_file: str | None = None,
    progress: bool | None = None,
    estimate: float | Callable[[], float] = COLD_COMPILE_S,
    load: float = LOAD_S,
) -> CompileReport:
    """Compile (or load) a group of kernels by running `call`, visibly and timed.

    With a `stamp_file`, drops the group's cached machine code first if any of
    `sources` or numba's version changed since it was compiled (numba itself
    checks only the file that defines each function).

    Parameters
    ----------
    what : str
        The group, as the user reads it.
    call : callable
        Calls the kernels once with the argument types of every real call.
    modules : iterable of str
        Full names of the modules holding the group's ``cache=True`` functions
        (counted in the notice; their cache files are dropped when stale).
    sources : iterable of Path
        Every source file the group compiles (for the fingerprint).
    stamp_file : str, optional
        Name of the fingerprint file kept in the cache folder; None: no check.
    progress, estimate, load :
        As in `watch_compiles`.

    Returns
    -------
    CompileReport
        "compiled" if numba compiled any kernel of the group, "disk cache" if it
        loaded them, "in memory" if this process had them already.
    """
    modules = tuple(modules)
    kernels = _kernels_of(modules)
    if not kernels:  # numba's JIT is off (NUMBA_DISABLE_JIT): no cache to stamp
        stamp_file = None
    cache_dir = Path(kernels[0].stats.cache_path) if kernels else Path(CACHE.path or "")
    stamp = _fingerprint(sources) if stamp_file else ""
    hits = lambda: sum(sum(k.stats.cache_hits.values()) for k in kernels)  # noqa: E731
    start, hits_before = time.perf_counter(), hits()
    if stamp_file:  # numba names its cache files after the source file's stem
        stems = [Path(importlib.import_module(m).__file__).stem for m in modules]
        if stamp_file != _STAMP:  # the group calls the fast kernels: theirs first
            _fresh_fast_cache(cache_dir)
        _drop_stale_cache(cache_dir, stamp_file, stamp, stems)
    with watch_compiles(what, modules, str(cache_dir), progress, estimate, load) as watch:
        call()
    seconds = time.perf_counter() - start
    if stamp_file:
        try:
            (cache_dir / stamp_file).write_text(stamp)
        except OSError:
            pass
    if watch.compiled:
        source = "compiled"
    else:
        source = "disk cache" if hits() > hits_before else "in memory"
    return CompileReport(seconds, source, str(cache_dir), watch.compiled, what)


def cached_on_disk(dispatcher, stamp_file: str | None = None, sources: Iterable[Path] = ()) -> bool:
    """Whether numba would load `dispatcher` from its disk cache: compiles and loads nothing.

    True when numba's index of the function holds machine code for its current source
    file, its bytecode and this machine's CPU (the key numba looks up before compiling)
    and, with a `stamp_file`, the group's fingerprint of `sources` in the cache folder is
    current (else `compile_once` drops the cached code). False when any of these is
    missing, and when numba's cache cannot be read this way (caching off, another numba
    layout): the caller then counts on a compile.

    Parameters
    ----------
    dispatcher : numba dispatcher
        A ``cache=True`` function (numba keeps one index file per function).
    stamp_file, sources :
        As in `compile_once`.
    """
    try:
        cache = dispatcher._cache  # numba's FunctionCache (a NullCache without cache=True)
        if stamp_file is not None:
            folder = Path(dispatcher.stats.cache_path)
            if (folder / stamp_file).read_text() != _fingerprint(sources):
                return False
        index = cache._cache_file._load_index()  # {} if absent or of another source stamp
        codegen = dispatcher.targetctx.codegen()
        return any(cache._index_key(key[0], codegen) == key for key in index)
    except (OSError, AttributeError, TypeError, ValueError, EOFError, pickle.UnpicklingError):
        return False


# ---------------------------------------------------------------------------- the fast kernels
_REPORT: CompileReport | None = None


def _one_node() -> tuple:
    """(start, model) arguments of a one-node column for the tiny calls below."""
    import numpy as np

    one, eye = np.ones(1), np.eye(1)
    mp = np.array([2.0, 1.0, 1.0, 1.0, 0.2, 9.81, 0.0, 0.0])
    y0 = np.array([0.0, 0.01, 0.0, 0.0, 0.0, 0.0, 0.0])
    return (0.0, 1e-3, y0, np.array([1e-3])), (one, one, eye * 1e4, eye, mp)


def _tiny_call() -> None:
    """Call the kernel once with the argument types of every real call (1 node, rocking)."""
    import numpy as np

    from . import _maths as mx
    from ._kernel import integrate_phase

    start, model = _one_node()
    codes = np.array([mx.EV_ZERO, mx.EV_PEAK, mx.EV_ACTIVATE], dtype=np.int64)
    integrate_phase(
        *start,
        1,
        *model,
        np.zeros(mx.FP_SIZE),
        codes,
        np.array([-1.0, 0.0, -1.0]),
        np.array([1, 0, 1], dtype=np.int64),
        np.array([1.0, 0.0, 1.0]),
        np.full(3, -np.inf),
        np.zeros(mx.EP_SIZE) + 1.0,
        mx.EXC_NONE,
        np.zeros(mx.PAR_SIZE),
        np.zeros(2),
        2,
        1e-8,
        1e-10,
        5e-3,
        np.zeros(1),
    )
    m, H, K, _, mp = model
    mx._total_energy(1.0, start[2], m, H, K, mp)  # the per-run path's transitions (FastPath)
    mx._pivot_momentum(start[2], m, H, mp)


def _tiny_contact_call() -> None:
    """Call the closed-form full contact once with the argument types of every real call."""
    import numpy as np

    from . import _maths as mx
    from ._contact_kernel import contact_phase

    start, model = _one_node()
    one = np.ones(1)
    codes = np.array([mx.EV_UPLIFT_RIGHT, mx.EV_UPLIFT_LEFT], dtype=np.int64)
    uplift_events = (codes, np.ones(2), -np.ones(2), np.full(2, -np.inf))
    ground = (mx.EXC_NONE, np.zeros(mx.PAR_SIZE), np.zeros(2))
    modes = (np.eye(1), one * 100.0, one * 0.05, one.copy(), 1e-4, np.zeros((3, 1)))
    contact_phase(*start, *model, *uplift_events, np.zeros(mx.EP_SIZE) + 1.0, *ground, *modes)


def _tiny_column_call() -> None:
    """Run `column_run` once with the argument types of every real call (1 node, 1 ms)."""
    import numpy as np

    from . import _column_kernel as ck
    from . import _maths as mx
    from .column_runs import _NO_ROCK, _TABLES, NO_LOG

    (_, _, y0, _), model = _one_node()
    one = np.ones(1)
    ground = (mx.EXC_NONE, np.zeros(mx.PAR_SIZE), np.zeros(2))
    modes = (np.eye(1), one * 100.0, one * 0.05, one.copy(), 1e-4, np.zeros((3, 1)))
    cfg = np.zeros(ck.CF_SIZE)
    cfg[ck.CF_TDMIN], cfg[ck.CF_COUNT], cfg[ck.CF_RTOL], cfg[ck.CF_ATOL] = 1e-3, 2, 1e-6, 1e-8
    cfg[ck.CF_MAX_STEP], cfg[ck.CF_R_RIGHT], cfg[ck.CF_R_LEFT] = 1e-3, 0.9, 0.9
    ep = np.zeros(mx.EP_SIZE) + 1.0
    t_end = np.array([1e-3])
    ck.column_run(
        1e-3, 1, y0, t_end, *model, *ground, modes, _NO_ROCK, _TABLES, ep, cfg, np.zeros(0), NO_LOG
    )


def _tiny_exponential_call() -> None:
    """Call the exponential rocking integrator once with the argument types of every real
    call (1 node, rocking)."""
    import numpy as np

    from . import _maths as mx
    from ._exp_kernel import exp_phase, new_cache

    start, model = _one_node()
    codes = np.array([mx.EV_ZERO, mx.EV_PEAK, mx.EV_ACTIVATE], dtype=np.int64)
    rock = (
        np.zeros((4, 4)),
        np.array([-1.0 + 10.0j, 1.0 + 0.0j]),
        np.ones((4, 2), np.complex128),
        np.ones((2, 4), np.complex128),
        np.array([2.0, 1.0]),
    )
    exp_phase(
        *start,
        1,
        *model,
        np.zeros(mx.FP_SIZE),
        codes,
        np.array([-1.0, 0.0, -1.0]),
        np.array([1, 0, 1], dtype=np.int64),
        np.array([1.0, 0.0, 1.0]),
        np.full(3, -np.inf),
        np.zeros(mx.EP_SIZE) + 1.0,
        mx.EXC_NONE,
        np.zeros(mx.PAR_SIZE),
        np.zeros(2),
        *rock,
        new_cache(2),
        1e-8,
        1e-10,
        5e-3,
    )


def _sources(contact: bool = False, columns: bool = False, exponential: bool = False) -> list[Path]:
    """The kernel modules and the equations they compile (of the contact group's kernel,
    of the exponential integrator's, or of the whole column runs', which compile all
    groups' code)."""
    from ...checks import __file__ as checks
    from ...impact_models.gaussian_force import __file__ as gaussian_force
    from ...impact_models.models import __file__ as impact_models
    from ...inputs.pulse_shapes import __file__ as pulse_shapes
    from ...model._nigam_jennings import __file__ as nigam_jennings
    from ...model.equations import __file__ as equations

    physics = [Path(equations), Path(gaussian_force), Path(pulse_shapes), Path(checks)]
    physics.append(_HERE / "_tableaus.py")  # `._rk`'s constants, frozen into the kernels
    physics.append(_HERE / "_unowned.py")  # `unowned`, an intrinsic compiled into them
    if columns:
        own = [_HERE / f"{_COLUMNS}.py", _HERE / f"{_EXPONENTIAL}.py", Path(impact_models)]
        return _sources(contact=True) + own
    if exponential:
        return _sources() + [_HERE / f"{_EXPONENTIAL}.py"]
    if contact:  # the closed-form contact compiles the others' event code too
        return (
            [_HERE / f"{m}.py" for m in (*_KERNEL_MODULES, _CONTACT)]
            + physics
            + [Path(nigam_jennings)]
        )
    return [_HERE / f"{m}.py" for m in _KERNEL_MODULES] + physics


def warm_up(progress: bool | None = None) -> CompileReport:
    """Compile (or load from the disk cache) the kernels of the compiled backend.

    Parameters
    ----------
    progress : bool, optional
        The compile notice on stderr (see the module docstring): None (default)
        shows it unless ``MULTIMASS_QUIET`` is set; False never; True always.
        Loading from the cache is always silent.

    Returns
    -------
    CompileReport
        Seconds spent and where the code came from. Later calls in the same
        process return the first report's cache directory with ``seconds`` 0
        and source "in memory".
    """
    global _REPORT
    if _REPORT is not None:
        return CompileReport(0.0, "in memory", _REPORT.cache_dir, 0, _REPORT.what)
    _REPORT = compile_once(
        "the fast kernels",
        _tiny_call,
        (f"{__package__}.{m}" for m in _KERNEL_MODULES),
        sources=_sources(),
        stamp_file=_STAMP,
        progress=progress,
    )
    return _REPORT


#: The reports of the groups compiled apart (`warm_up_contact`, `warm_up_columns`), by module.
_GROUP_REPORTS: dict[str, CompileReport] = {}


def _warm_up_group(module, what, call, sources, stamp, estimate, progress) -> CompileReport:
    """`compile_once` of the group of kernel module `module`, once per process (then the
    first report's cache folder, "in memory", 0 s); `sources()` lists its source files
    (asked only the first time: every compiled run calls this)."""
    r = _GROUP_REPORTS.get(module)
    if r is not None:
        return CompileReport(0.0, "in memory", r.cache_dir, 0, r.what)
    _GROUP_REPORTS[module] = compile_once(
        what,
        call,
        (f"{__package__}.{module}",),
        sources=sources(),
        stamp_file=stamp,
        progress=progress,
        estimate=estimate,
        load=0.1,
    )
    return _GROUP_REPORTS[module]


def warm_up_contact(progress: bool | None = None) -> CompileReport:
    """Compile (or load) the closed-form full contact (`._contact_kernel`), once per process.

    A group of its own, compiled on the first run that uses it (a column under a record
    or released, backend "compiled"), with the notice of `warm_up`. Arguments and
    result as `warm_up`.
    """
    return _warm_up_group(
        _CONTACT,
        "the closed-form full contact",
        _tiny_contact_call,
        lambda: _sources(contact=True),
        _CONTACT_STAMP,
        CONTACT_COMPILE_S,
        progress,
    )


def warm_up_columns(progress: bool | None = None) -> CompileReport:
    """Compile (or load) the whole column runs (`._column_kernel`), once per process.

    A group of its own, compiled on the first sweep of a column that uses it (a
    spectrum or a suite on the compiled path), with the notice of `warm_up`.
    Arguments and result as `warm_up`.
    """
    return _warm_up_group(
        _COLUMNS,
        "the whole column runs",
        _tiny_column_call,
        lambda: _sources(columns=True),
        _COLUMNS_STAMP,
        columns_estimate,
        progress,
    )


def _group_ready(module: str, kernel: str, stamp_file: str, sources) -> bool:
    """Whether the group of kernel module `module` runs without compiling: its report is
    in this process, or `kernel_ready` of its function `kernel`. Compiles nothing."""
    if module in _GROUP_REPORTS or (module == "_kernel" and _REPORT is not None):
        return True
    k = getattr(importlib.import_module(f"{__package__}.{module}"), kernel)
    return kernel_ready(k, stamp_file, sources)


def columns_estimate() -> float:
    """Expected seconds of a cold compile of the whole column runs: `COLUMNS_COMPILE_S`,
    plus the estimate of each group they call that is not compiled yet (the fast kernels,
    the closed-form full contact, the exponential integrator: compiled with them).
    Compiles and loads nothing."""
    groups = (
        (COLD_COMPILE_S, "_kernel", "integrate_phase", _STAMP, _sources),
        (CONTACT_COMPILE_S, _CONTACT, "contact_phase", _CONTACT_STAMP,
         lambda: _sources(contact=True)),
        (EXPONENTIAL_COMPILE_S, _EXPONENTIAL, "exp_phase", _EXPONENTIAL_STAMP,
         lambda: _sources(exponential=True)),
    )  # fmt: skip
    return COLUMNS_COMPILE_S + sum(s for s, *group in groups if not _group_ready(*group))


def kernel_ready(kernel, stamp_file: str, sources: Callable[[], Iterable[Path]]) -> bool:
    """Whether the ``cache=True`` function `kernel` runs without compiling: numba's JIT is
    off, it is compiled in this process, or `cached_on_disk` (with `stamp_file` and the
    group's ``sources()``, listed only if needed). Compiles and loads nothing."""
    if not hasattr(kernel, "overloads"):  # no JIT: nothing to compile
        return True
    return bool(kernel.overloads) or cached_on_disk(kernel, stamp_file, sources())


@functools.cache
def _columns_on_disk() -> bool:
    """`kernel_ready` of the whole column runs, asked once (the sources do not change in a
    process)."""
    kernel = importlib.import_module(f"{__package__}.{_COLUMNS}").column_run
    return kernel_ready(kernel, _COLUMNS_STAMP, lambda: _sources(columns=True))


def columns_ready() -> bool:
    """Whether the whole column runs (`warm_up_columns`) are ready without compiling them:
    in this process's memory, or in numba's disk cache for the current sources (loaded in
    ~0.1 s; `kernel_ready`). Compiles and loads nothing.

    `simulate` asks it before running a column in one compiled call: compiling the group
    cold took 50 s on an idle 2-core machine (11 kernels, each the whole run's code)
    where the phase loop's kernels took 18 s, for a call that saves ~5 ms per run; a
    sweep of columns or `multimass warm-up` compiles it.
    """
    return _COLUMNS in _GROUP_REPORTS or _columns_on_disk()


def warm_up_exponential(progress: bool | None = None) -> CompileReport:
    """Compile (or load) the exponential rocking integrator (`._exp_kernel`), once per
    process.

    A group of its own, compiled on the first run with ``method="exponential"``, with
    the notice of `warm_up`. Arguments and result as `warm_up`.
    """
    return _warm_up_group(
        _EXPONENTIAL,
        "the exponential rocking integrator",
        _tiny_exponential_call,
        lambda: _sources(exponential=True),
        _EXPONENTIAL_STAMP,
        EXPONENTIAL_COMPILE_S,
        progress,
    )
