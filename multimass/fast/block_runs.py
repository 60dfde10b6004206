"""Batched runs of a rigid block under single pulses: many map cells per compiled call.

An overturning map runs the same block, impact law and options under thousands of
pulses. `BlockRuns.of` checks once that the compiled batch (`._block_kernel`) runs
these cells exactly as ``simulate_outcome(..., backend="compiled")`` would — a rigid
block, classical impacts with a restitution fixed per corner, an explicit method —
and lays out the block's constants and options; `run_pulses` then runs a whole list
of pulses in one call, with no Python per cell. Anything else (Dirac-delta or LCP
impacts, random or impact-indexed restitution, Newmark, backend "scipy") gets None
from `BlockRuns.of`: the caller runs those cells one `simulate_outcome` at a time.

The batch gives the per-cell path's results bit for bit: the same compiled
integrator and event code, the same transition rules and the same uplift search
(`._block_uplift`); `tests/multimass/sweeps/test_batched_maps.py` compares them cell
by cell.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import kinematics as kin
from .._rigid import uplift_threshold
from ..checks import energy_floor
from ..errors import InputError
from ..excitations import RICKER_X0, TWO_PI, MPShape
from ..impact_models import (
    AngularMomentumRestitution,
    Classical,
    CornerRestitution,
    FixedRestitution,
    HousnerRestitution,
    ImpactContext,
    ModifiedRestitution,
    impact_model,
)
from ..simulation_options import SimulationOptions
from . import _block_kernel as bk
from . import _maths as mx
from ._rk import METHOD_CODES
from .compile import _drop_stale_cache, _fingerprint
from .path import ROCKING_EVENTS, event_params

__all__ = [
    "BlockRuns",
    "PulseRuns",
    "run_pulses",
    "encode_pulses",
    "ensure_ready",
    "warm_up_blocks",
    "PULSE_KINDS",
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
_NO_SAMPLES = np.zeros(2)


@dataclass(frozen=True, eq=False)
class BlockRuns:
    """A rigid block, its classical impacts and the run options, laid out for `run_pulses`.

    Attributes
    ----------
    cfg, mp, ep : ndarray
        Options and constants (``_block_kernel.CFG_*``), model scalars, event parameters.
    energy_tol : float
        A run whose end-of-run energy balance error exceeds it is "inaccurate".
    """

    cfg: np.ndarray
    mp: np.ndarray
    ep: np.ndarray
    energy_tol: float

    @classmethod
    def of(cls, st, options: dict, delay: float, retry: float) -> BlockRuns | None:
        """The batch for runs ``simulate_outcome(st, pulse, t_end=..., stop_when_safe=True,
        **options)``, or None if the batch cannot reproduce them (see the module docstring).

        Parameters
        ----------
        st : Structure
            A rigid block (N = 0).
        options : dict
            ``impact`` and the keyword options of `simulate_outcome`.
        delay : float
            The quiet guard after a restart (`multimass._run.QUIET_DELAY`).
        retry : float
            An undecided cell is rerun with `retry` times the free rocking.
        """
        opts = dict(options)
        impact, base = opts.pop("impact", "DD2"), opts.pop("options", None)
        try:
            o = SimulationOptions.of(
                base, **({"progress": False} | opts | {"output_dt": None, "stop_when_safe": True})
            )
            model = impact_model(impact, st.specimen, o.restitution, o.k, o.C_p, o.eps_p)
        except (InputError, TypeError):
            return None  # the per-cell path reports it
        if not (
            st.n == 0
            and o.integrator == "solve_ivp"
            and o.backend == "compiled"
            and isinstance(o.method, str)
            and o.method in METHOD_CODES
            and type(model) is Classical
            and type(model.restitution) in _PER_CORNER
        ):
            return None
        r = {
            side: float(model.restitution.value(ImpactContext(st, side, np.zeros(0), 0, None, 0)))
            for side in (1, -1)
        }  # as PhaseLoop.draw
        cfg = np.zeros(bk.CFG_SIZE)
        cfg[bk.CFG_A_TH] = uplift_threshold(st)
        cfg[bk.CFG_ALPHA] = st.alpha_cg
        cfg[bk.CFG_SAFE] = kin.gravitational_energy(st, 1, np.zeros(0), st.alpha_cg)
        cfg[bk.CFG_FLOOR] = energy_floor(st, o.atol)
        cfg[bk.CFG_TDMIN], cfg[bk.CFG_WINDOW] = o.thetadot_min, o.chatter_window
        cfg[bk.CFG_R_RIGHT], cfg[bk.CFG_R_LEFT] = r[1], r[-1]
        cfg[bk.CFG_DELAY] = delay
        cfg[bk.CFG_RTOL] = max(float(o.rtol), 100 * np.finfo(float).eps)  # as FastPath
        cfg[bk.CFG_ATOL], cfg[bk.CFG_MAX_STEP] = o.atol, o.max_step
        cfg[bk.CFG_METHOD] = METHOD_CODES[o.method]
        cfg[bk.CFG_STOP_AT_REST] = float(o.stop_at_rest)
        cfg[bk.CFG_CHATTER], cfg[bk.CFG_RETRY] = o.chatter_count, retry
        ep = event_params(st, o.thetadot_min, o.overturn_angle)
        return cls(cfg, mx.model_params(st), ep, float(o.energy_tol))


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
    """Many pulses encoded at once, as `multimass.fast.excitation.encode` encodes each.

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
    ensure_ready()
    kind, durations, par = encode_pulses(pulse, amplitude, omega)
    n = durations.size
    code, real, ints = np.empty(n, np.int64), np.empty((n, 3)), np.empty((n, 2), np.int64)
    names, codes, dirs, term, quiet, guarded = ROCKING_EVENTS
    events = (codes, dirs, term, quiet, guarded.astype(np.int64))
    bk.run_cells(
        durations, kind, par, _NO_SAMPLES, float(t_free), runs.cfg, runs.mp, runs.ep, events,
        code, real, ints,
    )  # fmt: skip
    return PulseRuns(
        outcome=code,
        overturn_time=real[:, 0],
        theta_max=real[:, 1],
        n_impacts=ints[:, 0],
        n_rhs=ints[:, 1],
        accurate=real[:, 2] <= runs.energy_tol,
    )


# ---------------------------------------------------------------------------- compile once
_READY: float | None = None
_REPORT = None  # the CompileReport of ensure_ready
_MODULES = ("_maths", "_rk", "_kernel", "_block_uplift", "_block_kernel")
_OWN = ("_block_uplift", "_block_kernel")  # the cache files this module drops when stale
_STAMP = "multimass_fast_blocks.sources"


def _sources() -> list[Path]:
    """Every source the batch compiles (numba keys a cache on one file only)."""
    from multimass import equations, pulse_shapes
    from multimass.impact_models import gaussian_force, models

    own = [Path(__file__).parent / f"{mod}.py" for mod in _MODULES]
    physics = (equations, gaussian_force, models, pulse_shapes)
    return own + [Path(mod.__file__) for mod in physics]


def ensure_ready(progress: bool | None = None):
    """`warm_up_blocks` once per process, with the one-off compile notice of
    `multimass.fast.compile` (``multimass warm-up`` does the same from the shell).

    Returns
    -------
    multimass.fast.CompileReport
        Of the first call in this process.
    """
    global _REPORT
    if _REPORT is None:
        from .compile import compile_once

        _REPORT = compile_once(
            "the batched map kernels",
            warm_up_blocks,
            (f"{__package__}._block_uplift", f"{__package__}._block_kernel"),
            progress=progress,
            estimate=25.0,
            load=0.1,
        )
    return _REPORT


def warm_up_blocks() -> float:
    """Compile (or load from numba's disk cache) the batch kernels once per process, silently.

    Drops this module's cached kernels first if any source they compile changed
    (as `multimass.fast.warm_up` does for the per-segment kernels). Returns the
    seconds it took (0 once ready).
    """
    global _READY
    if _READY is not None:
        return 0.0
    start = time.perf_counter()
    cache_dir, stamp = Path(bk.run_cells.stats.cache_path), _fingerprint(_sources())
    _drop_stale_cache(cache_dir, _STAMP, stamp, _OWN)
    z = np.zeros(1)  # one empty run (no time to run) with the argument types of every call
    names, codes, dirs, term, quiet, guarded = ROCKING_EVENTS
    events = (codes, dirs, term, quiet, guarded.astype(np.int64))
    cfg = np.zeros(bk.CFG_SIZE)
    cfg[bk.CFG_CHATTER], cfg[bk.CFG_A_TH] = 2.0, 1.0
    bk.run_cells(
        z,
        mx.EXC_SINE,
        np.zeros((1, mx.PAR_SIZE)),
        _NO_SAMPLES,
        0.0,
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
