"""Batched runs of a rigid block: many map cells or suite runs per compiled call.

An overturning map runs the same block, impact law and options under thousands of
pulses; a suite runs it under pulses and scaled records, each run with its own
restitution (η_M of its own k, or its own value). `BlockRuns.of` (a map's runs:
``stop_when_safe``, an undecided cell rerun) and `BlockRuns.of_runs` (runs as the
options say) check once that the compiled batch (`._block_kernel`) runs them exactly
as ``simulate_outcome(..., backend="compiled")`` would — a rigid block, classical
impacts with a restitution fixed per corner, an explicit method — and lay out the
block's constants and options; `restitution_pairs` gives each run's restitution of
the right and left corner. Then `run_pulses` (a map's pulses) and `run_excitations`
(any list of pulses and records, each with its own end time and restitution) run a
whole list in one call, with no Python per run. Anything else (Dirac-delta or LCP
impacts, random or impact-indexed restitution, Newmark, backend "scipy") gets None
from `BlockRuns.of` and `restitution_pairs`: the caller runs those one
`simulate_outcome` at a time — as `multimass.sweeps.block_outcomes.simulate_outcomes`
does, which batches what it can and runs the rest (and any run the batch cannot
finish) per run.

The batch gives the per-run path's results bit for bit: the same compiled
integrator (its steps for the block's five states in `._block_segment`) and event
code, the same transition rules and the same uplift search (`._block_uplift`);
`tests/multimass/sweeps/test_batched_maps.py` and ``test_batched_block_runs.py``
compare them run by run.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...checks import scale_floor
from ...errors import InputError
from ...impact_models import (
    AngularMomentumRestitution,
    Classical,
    CornerRestitution,
    FixedRestitution,
    HousnerRestitution,
    ImpactContext,
    ModifiedRestitution,
    impact_model,
)
from ...inputs.excitations import (
    RICKER_X0,
    TWO_PI,
    CosinePulse,
    CosineWave,
    MPPulse,
    MPShape,
    Ricker,
    SineWave,
)
from ...inputs.records import Record
from ...model import kinematics as kin
from ...simulation_options import SimulationOptions
from .._events import overturn_message
from .._rigid import uplift_threshold
from .._run import QUIET_DELAY
from . import _block_kernel as bk
from . import _maths as mx
from ._rk import METHOD_CODES
from .compile import _drop_stale_cache, _fingerprint, kernel_ready
from .excitation import encode
from .path import ROCKING_EVENTS, event_params

__all__ = [
    "BlockRuns",
    "PulseRuns",
    "ExcitationRuns",
    "run_pulses",
    "run_excitations",
    "restitution_pairs",
    "encode_pulses",
    "ensure_ready",
    "batch_ready",
    "warm_up_blocks",
    "PULSE_KINDS",
    "EXCITATIONS",
    "OUTCOMES",
]

#: The pulses `run_pulses` knows: name → excitation kind of `._maths` (and any `MPShape`).
PULSE_KINDS = {
    "sine": mx.EXC_SINE,
    "cosine": mx.EXC_COSINE,
    "ricker": mx.EXC_RICKER,
    "mp": mx.EXC_MP,
}
#: Outcome names by code (the order of `multimass.sweeps.map_cells.OUTCOMES`).
OUTCOMES = ("no_rocking", "rest", "overturned", "undecided")
#: Restitution sources whose value depends on the impacted corner only (for N = 0).
_PER_CORNER = (
    FixedRestitution,
    CornerRestitution,
    HousnerRestitution,
    ModifiedRestitution,
    AngularMomentumRestitution,
)
#: The excitations `run_excitations` runs (exact classes: each starts from rest).
EXCITATIONS = (SineWave, CosineWave, CosinePulse, Ricker, MPPulse, Record)
#: Options a suite's runs may differ in within one batch (`restitution_pairs`).
_PER_RUN = ("restitution", "k", "seed")
_NO_SAMPLES = np.zeros(2)


def _options_and_model(st, options: dict, stop_when_safe: bool | None):
    """(SimulationOptions, impact model) of runs ``simulate_outcome(st, ..., **options)``
    (`stop_when_safe` replacing the options' unless None), or None if invalid."""
    opts = dict(options)
    impact, base = opts.pop("impact", "DD2"), opts.pop("options", None)
    fixed = {"output_dt": None}
    if stop_when_safe is not None:
        fixed["stop_when_safe"] = bool(stop_when_safe)
    try:
        o = SimulationOptions.of(base, **({"progress": False} | opts | fixed))
        model = impact_model(impact, st.specimen, o.restitution, o.k, o.C_p, o.eps_p)
    except (InputError, TypeError):
        return None  # the per-run path reports it
    return o, model


def _corner_pair(st, model) -> tuple[float, float] | None:
    """(r of an impact onto the right corner, onto the left) of classical impacts whose
    restitution depends on the corner only, as `PhaseLoop.draw` draws them; else None."""
    if type(model) is not Classical or type(model.restitution) not in _PER_CORNER:
        return None
    r = {
        side: float(model.restitution.value(ImpactContext(st, side, np.zeros(0), 0, None, 0)))
        for side in (1, -1)
    }
    return r[1], r[-1]


@dataclass(frozen=True, eq=False)
class BlockRuns:
    """A rigid block, its classical impacts and the run options, laid out for `run_pulses`
    and `run_excitations`.

    Attributes
    ----------
    cfg, mp, ep : ndarray
        Options and constants (``_block_kernel.CFG_*``; ``CFG_R_RIGHT`` and ``CFG_R_LEFT``
        the options' restitution, the default of each run), model scalars, event
        parameters.
    energy_tol : float
        A run whose end-of-run energy balance error exceeds it is "inaccurate".
    """

    cfg: np.ndarray
    mp: np.ndarray
    ep: np.ndarray
    energy_tol: float

    @classmethod
    def of(
        cls, st, options: dict, delay: float, retry: float, *, stop_when_safe: bool | None = True
    ) -> BlockRuns | None:
        """The batch for runs ``simulate_outcome(st, pulse, t_end=..., stop_when_safe=True,
        **options)``, or None if the batch cannot reproduce them (see the module docstring).

        Parameters
        ----------
        st : Structure
            A rigid block (N = 0).
        options : dict
            ``impact`` and the keyword options of `simulate_outcome`.
        delay : float
            The quiet guard after a restart (`multimass.engines._run.QUIET_DELAY`).
        retry : float
            A map's undecided cell is rerun with `retry` times the free rocking
            (`run_pulses`).
        stop_when_safe : bool or None, optional
            Replaces the options' ``stop_when_safe`` (default True, as a map runs);
            None keeps the options' (`of_runs`).
        """
        made = _options_and_model(st, options, stop_when_safe)
        if made is None:
            return None
        o, model = made
        if not (
            st.n == 0
            and o.integrator == "solve_ivp"
            and o.backend == "compiled"
            and isinstance(o.method, str)
            and o.method in METHOD_CODES
        ):
            return None
        r = _corner_pair(st, model)
        if r is None:
            return None
        cfg = np.zeros(bk.CFG_SIZE)
        cfg[bk.CFG_A_TH] = uplift_threshold(st)
        cfg[bk.CFG_ALPHA] = st.alpha_cg
        cfg[bk.CFG_SAFE] = kin.gravitational_energy(st, 1, np.zeros(0), st.alpha_cg)
        cfg[bk.CFG_FLOOR] = scale_floor(st, o.atol, o.energy_tol)
        cfg[bk.CFG_TDMIN], cfg[bk.CFG_WINDOW] = o.thetadot_min, o.chatter_window
        cfg[bk.CFG_R_RIGHT], cfg[bk.CFG_R_LEFT] = r
        cfg[bk.CFG_DELAY] = delay
        cfg[bk.CFG_RTOL] = max(float(o.rtol), 100 * np.finfo(float).eps)  # as FastPath
        cfg[bk.CFG_ATOL], cfg[bk.CFG_MAX_STEP] = o.atol, o.max_step
        cfg[bk.CFG_METHOD] = METHOD_CODES[o.method]
        cfg[bk.CFG_STOP_AT_REST] = float(o.stop_at_rest)
        cfg[bk.CFG_CHATTER], cfg[bk.CFG_RETRY] = o.chatter_count, retry
        cfg[bk.CFG_STOP_WHEN_SAFE] = float(o.stop_when_safe)
        ep = event_params(st, o.thetadot_min, o.overturn_angle)
        return cls(cfg, mx.model_params(st), ep, float(o.energy_tol))

    @classmethod
    def of_runs(cls, st, options: dict) -> BlockRuns | None:
        """The batch for runs ``simulate_outcome(st, excitation, t_end=..., **options)`` as
        the options say (``stop_when_safe`` off unless given; no rerun), or None.

        A suite's runs differ in their restitution only (``restitution``, ``k``):
        `restitution_pairs` gives each run's pair for `run_excitations`.
        """
        return cls.of(st, options, QUIET_DELAY, math.nan, stop_when_safe=None)

    @property
    def r_pair(self) -> tuple[float, float]:
        """The options' restitution of an impact onto the right and onto the left corner."""
        return float(self.cfg[bk.CFG_R_RIGHT]), float(self.cfg[bk.CFG_R_LEFT])


def restitution_pairs(st, options) -> np.ndarray | None:
    """Each run's restitution of an impact onto the right and the left corner, or None.

    Parameters
    ----------
    st : Structure
        A rigid block.
    options : sequence of dict
        The `simulate_outcome` options of each run (``impact`` included); they may
        differ in ``restitution``, ``k`` and ``seed`` only.

    Returns
    -------
    ndarray (n, 2) or None
        Row i is the (r_right, r_left) that ``simulate_outcome(st, ..., **options[i])``
        uses (as `PhaseLoop.draw` draws it; η_M(k) for ``restitution="modified"``).
        None if the runs differ in another option, or one's restitution is not fixed
        per corner (random, impact-indexed) or its impacts not classical: run those
        per run.
    """
    options = list(options)
    out = np.empty((len(options), 2))
    if not options:
        return out
    rest = lambda o: {k: v for k, v in o.items() if k not in _PER_RUN}
    common, pairs = rest(options[0]), {}
    for i, opts in enumerate(options):
        if rest(opts) != common:
            return None
        key = (repr(opts.get("restitution")), repr(opts.get("k")))
        if key not in pairs:
            made = _options_and_model(st, opts, None)
            pairs[key] = None if made is None else _corner_pair(st, made[1])
        if pairs[key] is None:
            return None
        out[i] = pairs[key]
    return out


@dataclass(frozen=True, eq=False)
class PulseRuns:
    """What `run_pulses` returns, one entry per pulse (of its last run).

    Attributes
    ----------
    outcome : ndarray of int
        Index into `OUTCOMES`, or -1: the batch could not run the cell as the
        per-cell path would (that path ends it with status "failed"); rerun it there.
    overturn_time, theta_max : ndarray
        Time of overturning (NaN if none) and max ``|θ|`` over the half-cycles (rad).
    n_impacts, n_rhs : ndarray of int
    accurate : ndarray of bool
        The end-of-run energy balance error is within ``energy_tol``.
    """

    outcome: np.ndarray
    overturn_time: np.ndarray
    theta_max: np.ndarray
    n_impacts: np.ndarray
    n_rhs: np.ndarray
    accurate: np.ndarray


def encode_pulses(pulse, amplitude, omega) -> tuple[int, np.ndarray, np.ndarray]:
    """Many pulses encoded at once, as `multimass.engines.fast.excitation.encode` encodes each.

    Parameters
    ----------
    pulse : {"sine", "cosine", "ricker", "mp"} or MPShape
        ``SineWave``, ``CosineWave``, ``Ricker`` (default t0) or an M&P pulse shape
        ("mp": ``MPShape()``), built from a peak acceleration and ω_p.
    amplitude, omega : array_like
        Amplitudes (m/s², the peak for an M&P pulse) and angular frequencies (rad/s),
        one per pulse.

    Returns
    -------
    kind : int
        The ``EXC_*`` code of `._maths`.
    durations : ndarray (n,)
        Each pulse's ``duration`` (s).
    params : ndarray (n, PAR_SIZE)
        Row i is ``encode(Pulse(amplitude=amplitude[i], omega=omega[i]))[1]``, the
        same floats (tests/multimass/sweeps/test_batched_maps.py).
    """
    a, w = np.asarray(amplitude, dtype=float), np.asarray(omega, dtype=float)
    par = np.zeros((a.size, mx.PAR_SIZE))
    if isinstance(pulse, MPShape) or pulse == "mp":
        shape = pulse if isinstance(pulse, MPShape) else MPShape()
        for i, (ai, wi) in enumerate(zip(a.tolist(), w.tolist())):
            e = shape(amplitude=ai, omega=wi)  # the MPPulse of map_cell, float for float
            par[i, :7] = (e.amplitude, e.fp, e.gamma, e.nu, e.t0, e.start, e.duration)
        return mx.EXC_MP, par[:, 6].copy(), par
    par[:, 0], par[:, 1] = a, w
    if pulse == "ricker":
        par[:, 2] = RICKER_X0 / w  # Ricker.t0
        par[:, 3] = 2.0 * par[:, 2]  # Ricker.duration
        return PULSE_KINDS[pulse], par[:, 3].copy(), par
    par[:, 2] = TWO_PI / w  # _SingleWave.duration
    return PULSE_KINDS[pulse], par[:, 2].copy(), par


def run_pulses(runs: BlockRuns, pulse: str, amplitude, omega, t_free: float) -> PulseRuns:
    """Run the block from rest under each pulse, all in one compiled call.

    Each run lasts the pulse and `t_free` seconds of free rocking and stops once the
    block cannot overturn (``stop_when_safe``); an undecided run is rerun once with
    ``retry · t_free`` (`BlockRuns.of`), as `multimass.sweeps.map_cells.map_cell` does.

    Parameters
    ----------
    runs : BlockRuns
        The block, its impacts and the options.
    pulse : {"sine", "cosine", "ricker", "mp"} or MPShape
    amplitude, omega : array_like
        Amplitude (m/s²) and angular frequency (rad/s) of each pulse.
    t_free : float
        Free rocking after the pulse (s).

    Returns
    -------
    PulseRuns
        One entry per pulse.

    Raises
    ------
    InputError
        For an unknown `pulse`.
    """
    if not isinstance(pulse, MPShape) and pulse not in PULSE_KINDS:
        raise InputError(f"`pulse` = {pulse!r}: use one of {', '.join(PULSE_KINDS)}")
    kind, durations, par = encode_pulses(pulse, amplitude, omega)
    n = durations.size
    bounds = np.zeros((n, 2))
    bounds[:, 0] = par[:, 5] if kind == mx.EXC_MP else 0.0  # MPPulse.start (0 for a shape)
    bounds[:, 1] = durations
    t_free = float(t_free)
    t_ends = np.empty((n, 2))  # map_cell's exc.duration + t_free, then with the retry's
    t_ends[:, 0] = durations + t_free
    t_ends[:, 1] = durations + runs.cfg[bk.CFG_RETRY] * t_free
    kinds = np.full(n, kind, dtype=np.int64)
    spans = np.zeros((n, 2), np.int64)
    pairs = np.tile(np.array(runs.r_pair), (n, 1))
    code, real, ints = _run_cells(runs, kinds, par, _NO_SAMPLES, spans, bounds, t_ends, pairs)
    return PulseRuns(
        outcome=code,
        overturn_time=real[:, 0],
        theta_max=real[:, 1],
        n_impacts=ints[:, 0],
        n_rhs=ints[:, 1],
        accurate=real[:, 2] <= runs.energy_tol,
    )


def _run_cells(runs, kinds, pars, smp, spans, bounds, t_ends, pairs):
    """`_block_kernel.run_cells` of these cells: (codes, real columns, integer columns)."""
    ensure_ready()
    n = kinds.size
    code, real, ints = np.empty(n, np.int64), np.empty((n, 3)), np.empty((n, 2), np.int64)
    names, codes, dirs, term, quiet, guarded = ROCKING_EVENTS
    events = (codes, dirs, term, quiet, guarded.astype(np.int64))
    bk.run_cells(
        kinds, pars, smp, spans, bounds, t_ends, pairs, runs.cfg, runs.mp, runs.ep, events,
        code, real, ints,
    )  # fmt: skip
    return code, real, ints


@dataclass(frozen=True, eq=False)
class ExcitationRuns:
    """What `run_excitations` and `simulate_outcomes` return, one entry per run.

    Entry i is what ``simulate_outcome(st, excitations[i], t_end=t_end[i], **options)``
    returns, as columns.

    Attributes
    ----------
    outcome : ndarray of int
        Index into `OUTCOMES` ("no_rocking", "rest": stopped at rest or safe,
        "overturned", "undecided": still rocking at t_end), or -1: `run_excitations`
        could not run it as the per-run path would (that path ends it with status
        "failed"); `multimass.sweeps.block_outcomes.simulate_outcomes` then has run it
        per run, and -1 stays for a failed run.
    status : ndarray of str
        The `Outcome`'s ``status``: "completed", "overturned", "inaccurate" (the
        energy balance check failed) or "failed".
    message : list of str
        The `Outcome`'s ``message`` (``"|θ| reached ... rad"`` for an overturned run, the
        solver's message for a failed one, else "").
    overturn_time : ndarray
        Time of the "overturn" event (s; NaN if none).
    theta_max : ndarray
        ``Outcome.theta_max``: max ``|θ|`` over the half-cycle peaks (rad; 0 if none).
    n_impacts, n_rhs : ndarray of int
    energy_balance_error : ndarray
        ``Outcome.energy_balance_error`` (0 for a failed run of the batch).
    accurate : ndarray of bool
        The energy balance check passed (``status != "inaccurate"``).
    batched : ndarray of bool
        The run's numbers come from the batch (False: from `simulate_outcome`).
    """

    outcome: np.ndarray
    status: np.ndarray
    message: list
    overturn_time: np.ndarray
    theta_max: np.ndarray
    n_impacts: np.ndarray
    n_rhs: np.ndarray
    energy_balance_error: np.ndarray
    accurate: np.ndarray
    batched: np.ndarray

    @property
    def overturned(self) -> np.ndarray:
        """``Outcome.outcome == "overturned"`` (accurate or not)."""
        return self.outcome == bk.OVERTURNED

    def __len__(self) -> int:
        return self.outcome.size


def _encoded(excitations):
    """(kinds, params, samples, spans, bounds) of the excitations, for `run_cells`."""
    n = len(excitations)
    kinds, pars = np.empty(n, np.int64), np.empty((n, mx.PAR_SIZE))
    bounds, spans = np.empty((n, 2)), np.zeros((n, 2), np.int64)
    chunks, at, seen = [], 0, {}
    for i, exc in enumerate(excitations):
        if type(exc) not in EXCITATIONS:
            name = type(exc).__name__
            raise InputError(
                f"excitation {i} is a {name}: the batch runs "
                f"{', '.join(e.__name__ for e in EXCITATIONS)} "
                "(use multimass.sweeps.block_outcomes.simulate_outcomes)"
            )
        kind, par, samples = encode(exc)
        kinds[i], pars[i] = kind, par
        bps = exc.breakpoints  # (start, duration): PhaseLoop's breakpoints
        bounds[i] = (float(bps[0]) if bps else 0.0), float(exc.duration)
        if kind == mx.EXC_RECORD:
            key = id(exc.accel)  # a record run at several draws: its samples once
            if key not in seen:
                seen[key] = (at, at + samples.size)
                chunks.append(samples)
                at += samples.size
            spans[i] = seen[key]
    smp = np.concatenate(chunks) if chunks else _NO_SAMPLES
    return kinds, pars, smp, spans, bounds


def run_excitations(runs: BlockRuns, excitations, t_end, r_pairs=None) -> ExcitationRuns:
    """Run the block from rest under each excitation, all in one compiled call.

    Run i is ``simulate_outcome(st, excitations[i], t_end=t_end[i], **options)`` with
    the options of `runs` (`BlockRuns.of_runs`) and the restitution pair ``r_pairs[i]``
    (`restitution_pairs`): the same numbers, bit for bit (no rerun of an undecided run).

    Parameters
    ----------
    runs : BlockRuns
        The block, its impacts and the options.
    excitations : sequence
        `EXCITATIONS` (pulses, M&P pulses and records, mixed as wished; a scaled
        record is a `Record`, ``record.scaled(f)``).
    t_end : float or array_like
        End time of each run (s).
    r_pairs : array_like (n, 2), optional
        Restitution of an impact onto the right and onto the left corner, per run
        (default: the options', `BlockRuns.r_pair`).

    Returns
    -------
    ExcitationRuns
        Outcome -1 (status "failed", ``batched``) for a run the batch could not finish
        as the per-run path would: run it with `simulate_outcome`
        (`multimass.sweeps.block_outcomes.simulate_outcomes` does).

    Raises
    ------
    InputError
        For an excitation not in `EXCITATIONS`, or a t_end not after the excitation's
        start (as `simulate_outcome`).
    """
    excitations = list(excitations)
    n = len(excitations)
    kinds, pars, smp, spans, bounds = _encoded(excitations)
    t_ends = np.empty((n, 1))
    t_ends[:, 0] = np.broadcast_to(np.asarray(t_end, dtype=float), (n,))
    bad = np.flatnonzero(~(t_ends[:, 0] > np.maximum(bounds[:, 0], 0.0)))
    if bad.size:
        i = int(bad[0])
        raise InputError(
            f"run {i}: t_end = {t_ends[i, 0]!r} s is not after the start of its excitation "
            f"({bounds[i, 0]:g} s)"
        )
    pairs = np.empty((n, 2))
    pairs[:] = runs.r_pair if r_pairs is None else np.asarray(r_pairs, dtype=float)
    code, real, ints = _run_cells(runs, kinds, pars, smp, spans, bounds, t_ends, pairs)
    err = real[:, 2]
    accurate = err <= runs.energy_tol  # multimass.checks.energy_check
    over = code == bk.OVERTURNED
    status = np.where(over, "overturned", "completed").astype("<U11")
    status[~accurate] = "inaccurate"  # multimass.result.status_of
    status[code == bk.FAILED] = "failed"
    reached = overturn_message(runs.ep[mx.EP_OVERTURN])
    return ExcitationRuns(
        outcome=code,
        status=status,
        message=[reached if o else "" for o in over.tolist()],
        overturn_time=real[:, 0],
        theta_max=real[:, 1],
        n_impacts=ints[:, 0],
        n_rhs=ints[:, 1],
        energy_balance_error=err,
        accurate=accurate | (code == bk.FAILED),
        batched=np.ones(n, bool),
    )


# ---------------------------------------------------------------------------- compile once
_READY: float | None = None
_REPORT = None  # the CompileReport of ensure_ready
_MODULES = (  # the sources of the batch kernels (with the tableaus `._rk` freezes into them)
    "_maths", "_tableaus", "_unowned", "_rk", "_kernel", "_block_uplift", "_block_segment",
    "_block_kernel",
)  # fmt: skip
_OWN = (
    "_block_uplift",
    "_block_segment",
    "_block_kernel",
)  # the cache files this module drops when stale
_STAMP = "multimass_fast_blocks.sources"


def _sources() -> list[Path]:
    """Every source the batch compiles (numba keys a cache on one file only)."""
    from multimass import checks
    from multimass.impact_models import gaussian_force, models
    from multimass.inputs import pulse_shapes
    from multimass.model import equations

    own = [Path(__file__).parent / f"{mod}.py" for mod in _MODULES]
    physics = (equations, gaussian_force, models, pulse_shapes, checks)
    return own + [Path(mod.__file__) for mod in physics]


def ensure_ready(progress: bool | None = None):
    """`warm_up_blocks` once per process, with the one-off compile notice of
    `multimass.engines.fast.compile` (``multimass warm-up`` does the same from the shell).

    Returns
    -------
    multimass.engines.fast.CompileReport
        Of the first call in this process.
    """
    global _REPORT
    if _REPORT is None:
        from .compile import compile_once

        _REPORT = compile_once(
            "the batched map kernels",
            warm_up_blocks,
            (
                f"{__package__}._block_uplift",
                f"{__package__}._block_segment",
                f"{__package__}._block_kernel",
            ),
            progress=progress,
            estimate=25.0,
            load=0.1,
        )
    return _REPORT


def batch_ready() -> bool:
    """Whether the batch kernels are ready without compiling them (~35 s on a 2-core machine):
    in this process's memory, or in numba's disk cache for the current sources (loaded in
    ~0.1 s; `multimass.engines.fast.compile.kernel_ready`). Compiles and loads nothing.

    `multimass.sweeps.map_cells.use_batch` asks it before batching a small map or suite.
    """
    return _READY is not None or kernel_ready(bk.run_cells, _STAMP, _sources)


def warm_up_blocks() -> float:
    """Compile (or load from numba's disk cache) the batch kernels once per process, silently.

    Drops this module's cached kernels first if any source they compile changed
    (as `multimass.engines.fast.warm_up` does for the per-segment kernels). Returns the
    seconds it took (0 once ready).
    """
    global _READY
    if _READY is not None:
        return 0.0
    start = time.perf_counter()
    cache_dir, stamp = Path(bk.run_cells.stats.cache_path), _fingerprint(_sources())
    _drop_stale_cache(cache_dir, _STAMP, stamp, _OWN)
    # one empty run (no time to run) with the argument types of every call
    names, codes, dirs, term, quiet, guarded = ROCKING_EVENTS
    events = (codes, dirs, term, quiet, guarded.astype(np.int64))
    cfg = np.zeros(bk.CFG_SIZE)
    cfg[bk.CFG_CHATTER], cfg[bk.CFG_A_TH] = 2.0, 1.0
    bk.run_cells(
        np.full(1, mx.EXC_SINE, np.int64),
        np.zeros((1, mx.PAR_SIZE)),
        _NO_SAMPLES,
        np.zeros((1, 2), np.int64),
        np.zeros((1, 2)),
        np.zeros((1, 1)),
        np.zeros((1, 2)),
        cfg,
        np.ones(mx.MP_SIZE),
        np.ones(mx.EP_SIZE),
        events,
        np.empty(1, np.int64),
        np.empty((1, 3)),
        np.empty((1, 2), np.int64),
    )
    try:
        (cache_dir / _STAMP).write_text(stamp)
    except OSError:
        pass
    _READY = time.perf_counter() - start
    return _READY
