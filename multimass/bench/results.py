"""One record per run, whatever the solver: `RunResult` and the adapters that build it.

The benchmarks compare four kinds of result — `multimass.Response` (solve_ivp,
compiled path, Newmark), the paper-000 block's `BlockResponse`, and
`nscd.NSCDResult` — through one frozen record holding what the error measures
and the failure detectors read: events (kind, time), half-cycle peaks, final
energy, energy-balance error, transitions inside one impact, cost.

Conventions: angles in rad; the peaks of a free release start with the release
angle (as `Response.peaks` does); energies are mechanical energies above the
rest state (J); `n_rhs` counts right-hand-side evaluations (Newton iterations
for Newmark, time steps for Moreau–Jean).
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass

import numpy as np

from multimass.engines.contact_dynamics import half_cycle_peaks
from multimass.errors import InputError
from multimass.result import status_of

__all__ = [
    "RunResult",
    "failed_run",
    "from_response",
    "from_block",
    "from_nscd",
    "timed",
    "CHATTER_WINDOW",
    "TRANSITIONS",
]

#: transitions closer than this follow one impact (paper 001, Section 4.3; Response default)
CHATTER_WINDOW = 0.02
#: event kinds that are phase transitions (what chattering counts)
TRANSITIONS = ("impact", "full_contact", "uplift")


@dataclass(frozen=True)
class RunResult:
    """What one run left for the error measures and the failure detectors.

    Attributes
    ----------
    status : str
        "completed", "overturned" or "failed".
    message : str
    events : tuple of (str, float)
        (kind, time) of the phase transitions: "uplift", "impact",
        "full_contact", "overturn".
    peaks, peak_times : tuple of float
        Peak ``|θ|`` of each half-cycle (rad) and its time (s; NaN if unknown).
    final_energy : float
        Mechanical energy above rest at the end of the run (J).
    energy_scale : float
        Scale of the energy ledger (initial energy or largest ground work, J).
    balance_error : float
        Largest energy-balance error over the run / `energy_scale`.
    chatter : int
        Transitions that follow the previous one within `CHATTER_WINDOW`.
    n_rhs : int
    wall_time_s : float
        Median wall time of the whole call (s).
    """

    status: str
    message: str
    events: tuple = ()
    peaks: tuple = ()
    peak_times: tuple = ()
    final_energy: float = math.nan
    energy_scale: float = math.nan
    balance_error: float = math.nan
    chatter: int = 0
    n_rhs: int = 0
    wall_time_s: float = math.nan


def failed_run(exc: BaseException, wall: float) -> RunResult:
    """A run that raised (e.g. SciPy's LSODA event location): status "failed"."""
    return RunResult("failed", f"{type(exc).__name__}: {exc}", wall_time_s=wall)


def timed(fn, min_time_s: float = 0.0, max_repeat: int = 1):
    """(median wall time, last result) of `fn()`; repeated while the runs are short.

    A run that raises is not repeated: returns (its time, the exception).
    InputError (a benchmark bug, not a solver failure) propagates.
    """
    times, out = [], None
    while True:
        t0 = time.perf_counter()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)  # numjac overflows on stiff columns
                out = fn()
        except InputError:
            raise
        except Exception as exc:  # noqa: BLE001 - recorded as a failure
            return time.perf_counter() - t0, exc
        times.append(time.perf_counter() - t0)
        if len(times) >= max_repeat or sum(times) >= min_time_s:
            return float(np.median(times)), out


def _chatter(times) -> int:
    return int(sum(b - a < CHATTER_WINDOW for a, b in zip(times, times[1:])))


def from_response(resp, wall: float) -> RunResult:
    """From a `multimass.Response` (any integrator or backend)."""
    events = tuple(
        (e.kind, float(e.time)) for e in resp.events if e.kind in TRANSITIONS + ("overturn",)
    )
    df = resp.series
    final = (
        float(df.kinetic.iloc[-1] + df.gravitational.iloc[-1] + df.elastic.iloc[-1])
        if len(df)
        else math.nan
    )
    return RunResult(
        resp.outcome or resp.status,
        resp.message,
        events,
        tuple(map(float, resp.peaks)),
        tuple(map(float, resp.peak_times)),
        final,
        float(resp.energy_reference),
        float(resp.energy_balance_error),
        resp.consecutive_transitions(window=CHATTER_WINDOW),
        int(resp.n_rhs),
        wall,
    )


def _block_event(e) -> tuple[str, float] | None:
    """A paper-000 contact event in the engine's words (None: no engine counterpart).

    Its phases (`multimass.result.Event`): an impact or a Zeno rest ("rest") into full
    contact (phase 0) is "full_contact", an uplift from full contact to one pivot is
    "uplift", one into flight (no phase) is "flight".
    """
    if e.kind == "overturn":
        return "overturn", float(e.time)
    if e.kind in ("rest", "impact") and e.phase_after == 0:
        return "full_contact", float(e.time)
    if e.kind == "impact":
        return "impact", float(e.time)
    if e.kind == "uplift" and e.phase_before == 0 and e.phase_after in (-1, 1):
        return "uplift", float(e.time)
    return ("flight", float(e.time)) if e.kind == "uplift" and e.phase_after is None else None


def sampled_peaks(t: np.ndarray, theta: np.ndarray) -> tuple[list, list]:
    """Peak ``|θ|`` of each half-cycle (a run of samples of one sign), refined by a parabola
    (`multimass.engines.contact_dynamics.half_cycle_peaks`, which `BlockResponse.peaks` uses)."""
    peaks, times = half_cycle_peaks(t, theta)
    return peaks.tolist(), times.tolist()


def from_block(resp, wall: float, n_rhs: int) -> RunResult:
    """From the paper-000 block (`multimass.engines.poisson_block.BlockResponse`)."""
    raw = resp.raw
    events = tuple(x for x in map(_block_event, raw.events) if x is not None)
    scale = max(abs(float(raw.energy[0])), float(np.max(np.abs(raw.ground_work))), 1e-300)
    trans = [t for k, t in events if k in TRANSITIONS]
    # the physical outcome: an "inaccurate" run is judged by its errors here, not as a failure
    status = status_of(raw.outcome)
    return RunResult(
        status,
        raw.message,
        events,
        tuple(map(float, resp.peaks)),
        tuple(map(float, resp.peak_times)),
        float(raw.energy[-1]),
        scale,
        float(np.max(np.abs(raw.ledger_error)) / scale),
        _chatter(trans),
        n_rhs,
        wall,
    )


def _crossings(t: np.ndarray, theta: np.ndarray) -> list[float]:
    """Times where θ changes sign (linear interpolation between samples): the impacts."""
    i = np.flatnonzero(theta[:-1] * theta[1:] < 0.0)
    return list(t[i] - theta[i] * (t[i + 1] - t[i]) / (theta[i + 1] - theta[i]))


def from_nscd(res, wall: float, block) -> RunResult:
    """From `nscd.NSCDResult` of a free release; `block` is the rigid-block Structure.

    Impacts are the sign changes of θ (the kernel's own impact log also holds
    the small second touches of an event-capturing scheme: those are counted
    as chattering). The energy is the block's rocking energy
    ``½ J_p θ̇² + g (m h0 (cos θ − 1) + B m_t |sin θ|)``, the beam's left out.
    """
    th0 = float(res.params.get("theta0", res.theta[0]))
    events = tuple(("impact", float(x)) for x in _crossings(res.t, res.theta))
    th, thd = float(res.theta[-1]), float(res.thetadot[-1])
    energy = lambda a, w: (
        0.5 * block.J_p * w * w  # noqa: E731
        + block.g
        * (block.static_moment * (math.cos(a) - 1.0) + block.B * block.m_t * abs(math.sin(a)))
    )
    e0 = energy(th0, 0.0)
    outcome = getattr(res, "outcome", None) or res.status
    status = outcome if outcome in ("completed", "overturned") else "failed"
    return RunResult(
        status,
        res.message,
        events,
        tuple(float(p) for p in res.peaks),  # the release angle first
        tuple(float(t) for t in res.peak_times),
        energy(th, thd),
        e0,
        max(res.max_energy_increase, 0.0) / res.energy_scale,
        _chatter(list(res.impact_times)),
        int(res.n_steps),
        wall,
    )
