"""The phase loop of one simulation: it owns the run's state and passes it by value.

`multimass.simulate` validates its options (`SimulationOptions`) and builds a
`PhaseLoop`. The loop carries a `State` (time, phase, state vector, the active
Dirac-delta force, the pending restitution, the guard's hold, the status)
from one phase segment to the next: a segment (solve_ivp, or the compiled kernels
of `multimass.engines.fast`) returns the state at its end, and a terminal event's handler
(`multimass.engines._events.handle_event`) returns the state after the transition. What
the loop keeps besides is the run's record — the event log, the `Recorder` of
samples, peaks and ledger, the restitution draws, the chattering guard's window.
"""

from __future__ import annotations

import bisect
import dataclasses
import itertools
import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from multimass.impact_models import ImpactContext
from multimass.impact_models.models import full_contact_velocities

from ..checks import balance_error, scale_floor
from ..model import equations as eq
from ..model import kinematics as kin
from ..model._phase import ActiveForce, Model, full_contact_rhs, rocking_rhs
from ..result import Event
from ._events import chatter_detail, handle_event, phase_events
from ._recorder import Recorder
from ._rigid import next_uplift

__all__ = ["PhaseLoop", "State", "QUIET_DELAY", "segment_ends"]

QUIET_DELAY = 1e-9  # s: events are held quiet this long after a restart


def segment_ends(breakpoints, duration: float, t_end: float) -> list[float]:
    """The ends of a run's segments: the excitation's breakpoints and its end inside
    (0, t_end), in order, then t_end (a segment never straddles a change of ü_g's form)."""
    ends = [b for b in breakpoints if 0.0 < b < t_end]
    ends += [duration] if 0 < duration < t_end else []
    return sorted(set(ends)) + [t_end]


@dataclass(frozen=True, eq=False)
class State:
    """The state of a run between two segments; handlers return a new one.

    Attributes
    ----------
    t : float
    phase : int
        0 full contact, +1 / −1 rocking about the right / left pivot.
    y : ndarray
        [u, θ, u̇, θ̇, damping, ground work, impact-force work]; never changed in
        place once in a State (transitions copy it).
    force : ActiveForce or None
        The active Dirac-delta force (paper 001, Eqs 14–16).
    r_pending : float or None
        The restitution drawn for the coming impact (Dirac-delta models).
    hold_until : float
        Uplift is held off until this time after the chattering guard tripped.
    status, message : str
        "completed" while the run goes on; "overturned" or "failed" end it.
    """

    t: float
    phase: int
    y: np.ndarray
    force: ActiveForce | None = None
    r_pending: float | None = None
    hold_until: float = 0.0
    status: str = "completed"
    message: str = ""

    def but(self, **changes) -> State:
        """This state with `changes` (fields only; a shallow copy, as dataclasses.replace
        makes, without its per-call overhead: a run makes one per transition)."""
        if not _STATE_FIELDS.issuperset(changes):
            unknown = changes.keys() - _STATE_FIELDS
            raise TypeError(f"State has no field {sorted(unknown)[0]!r}")
        new = object.__new__(State)
        new.__dict__.update(self.__dict__, **changes)
        return new


_STATE_FIELDS = frozenset(f.name for f in dataclasses.fields(State))


def _zero_between(sol, names, events, side: int, n: int, atol: float) -> float | None:
    """The time of a θ̇ = 0 root of a column's rocking segment at which θ is past zero by
    more than `atol` (less is within a step's own error; a segment that starts at an
    uplift has θ = θ̇ = 0 there) before any terminal event, None if none: θ crossed zero
    and back inside one step, and the sign test of its ends missed the impact (a grazing
    approach under the Dirac-delta force). The compiled kernels locate that crossing on
    the step's dense output (`multimass.engines.fast._kernel._zero_between`); here the
    segment is integrated again up to that root, where its last step ends past zero."""
    if side == 0 or n == 0 or "peak" not in names:
        return None
    t_end = math.inf
    if sol.status == 1:
        t_end = min(float(t[0]) for t, ev in zip(sol.t_events, events) if ev.terminal and t.size)
    i = names.index("peak")
    for t, y in zip(sol.t_events[i], sol.y_events[i]):
        if t < t_end and side * y[n] < -atol:
            return float(t)
    return None


def solve_ivp(*args, **kwargs):
    """``scipy.integrate.solve_ivp``, imported at its first call: the compiled path and
    Newmark never call it, and a command that runs only them starts without SciPy."""
    from scipy.integrate import solve_ivp as scipy_solve_ivp

    return scipy_solve_ivp(*args, **kwargs)


def _reporting(rhs, progress, every: int = 2000):
    """`rhs` that tells `progress` the time every `every` calls (long segments show progress)."""
    count = [0]

    def wrapped(t, y):
        count[0] += 1
        if count[0] % every == 0:
            progress(t)
        return rhs(t, y)

    return wrapped


class PhaseLoop:
    """One simulation while it runs: the fixed context, the record, and the loop.

    Parameters
    ----------
    st : Structure
    model : ImpactModel
    ground : tuple
        (ü_g, duration, breakpoints) of the excitation.
    t_end : float
    phase : int
    y : ndarray
        The initial state vector.
    options : SimulationOptions
    fast : FastPath, optional
        The compiled path (backend "compiled"); None integrates with solve_ivp.
    """

    def __init__(self, st, model, ground, t_end, phase, y, options, fast=None):
        o = options
        self.st, self.mdl, self.model, self.fast = st, Model.of(st), model, fast
        self.ag, self.duration, bps = ground
        self.t_end = t_end
        self.breakpoints = segment_ends(bps, self.duration, t_end)
        self.ivp, self.thetadot_min, self.overturn = o.ivp, o.thetadot_min, o.overturn_angle
        self.rng = np.random.default_rng(o.seed)
        self.n_draws = 0
        self.n_impacts, self.n_counted = 0, 0  # impacts among the first n_counted events
        self.chatter = deque(maxlen=o.chatter_count)
        self.chatter_window, self.stop_at_rest = o.chatter_window, o.stop_at_rest
        self.safe_energy = None
        if o.stop_when_safe and st.n == 0 and math.isfinite(self.duration):
            # energy to lift the centre of gravity over a pivot, m g R (1 − cos α)
            self.safe_energy = kin.gravitational_energy(st, 1, np.zeros(0), st.alpha_cg)
        self.events: list[Event] = [Event("release", 0.0, phase, phase, theta=float(y[st.n]))]
        self.n_rhs = 0
        self.recorder = Recorder(st, self.mdl, o.output_dt, self.ag)
        self.recorder.start_phase(phase, 0.0, y)
        self.energy_floor = scale_floor(st, o.atol, o.energy_tol)
        self.e0 = self.energy(phase, y)  # the ledger starts from the given state
        self.progress = None  # a callback progress(t), see `run`
        r = self.draw(-phase, y) if phase and model.has_force else None
        self.start = State(0.0, phase, y, r_pending=r)

    # -- restitution draws -------------------------------------------------
    def draw(self, side_new: int, y: np.ndarray) -> float:
        """The restitution of the next impact onto pivot `side_new` at state `y` (one draw)."""
        ctx = ImpactContext(
            self.st, side_new, y[: self.st.n].copy(), self.n_draws, self.rng, self.impacts_so_far()
        )
        self.n_draws += 1
        return float(self.model.restitution.value(ctx))

    def impacts_so_far(self) -> int:
        """Events of kind "impact" logged so far (the log only grows: each is counted once)."""
        for e in itertools.islice(self.events, self.n_counted, None):
            self.n_impacts += e.kind == "impact"
        self.n_counted = len(self.events)
        return self.n_impacts

    # -- main loop -----------------------------------------------------------
    def run(self, progress=None) -> State:
        """Integrate to t_end (or the end of the run); `progress(t)` is told the time.

        Returns the final state (its status and message say how the run ended).
        """
        self.progress = progress
        s = self.start
        while s.t < self.t_end and s.status == "completed":
            t_stop = self.breakpoints[bisect.bisect_right(self.breakpoints, s.t)]  # first > s.t
            if s.phase == 0 and self.st.n == 0:
                s, go_on = self.rest_until_uplift(s, t_stop)
                if not go_on:
                    break
                continue
            s = self.integrate(s, t_stop)
            peak = self.safe_peak(s) if s.status == "completed" else None
            if peak is not None:
                if s.phase:  # the free swing's peak, timed at the stop (Recorder.free_peak)
                    self.recorder.free_peak(peak, s.t)
                self.events.append(
                    Event(
                        "rest",
                        s.t,
                        s.phase,
                        s.phase,
                        theta=float(s.y[self.st.n]),
                        detail="excitation over; too little energy to overturn",
                    )
                )
                break
            if progress is not None:
                progress(s.t)
        self.recorder.finish(s.t, s.y, s.phase)
        return s

    def end_balance_error(self, s: State) -> float:
        """|ledger balance| at the end of the run over its energy scale (`multimass.checks`)."""
        E = self.energy(s.phase, s.y)
        D, Wg, WF = (float(x) for x in s.y[-3:])
        balance = E + D + WF + self.recorder.loss - Wg - self.e0
        return balance_error(balance, self.e0, Wg, E, self.energy_floor)

    def safe_peak(self, s: State) -> float | None:
        """May this rigid body's run stop now? (`stop_when_safe`) None if not, else the
        largest ``|θ|`` the rest of the run can reach.

        After the excitation, with ``|θ|`` < α and the energy E below m g R (1 − cos α),
        the block can no longer overturn. It stops when it rests in full contact (bound
        0), or rocks free (no impact force on) moving away from θ = 0 or at a turning
        point, ±θ̇ ≥ 0 on pivot ±1 (θ = 0 right after an impact included): the swing
        under way then peaks at `equations.free_rocking_peak` of E and every later one
        lower (energy is conserved in flight and lost at impacts). Moving toward θ = 0
        it goes on to the impact. The rule of `multimass.engines.fast._block_kernel._run` and
        `multimass.engines._newmark_events.Run.energy_stop`.
        """
        if self.safe_energy is None or s.t < self.duration or s.t >= self.t_end:
            return None
        n = self.st.n
        th, thd = float(s.y[n]), float(s.y[2 * n + 1])
        if s.phase and (s.force is not None or s.phase * thd < 0.0):
            return None
        if not abs(th) < self.st.alpha_cg:
            return None
        E = self.energy(s.phase, s.y)
        if not E < self.safe_energy:
            return None
        return eq.free_rocking_peak(self.st.alpha_cg, E / self.safe_energy) if s.phase else 0.0

    def energy(self, phase, y) -> float:
        """T + V_g + U of state `y` in `phase` (`multimass.model.kinematics.total_energy`; on
        the compiled path its compiled sums, `FastPath.energy`)."""
        if self.fast is not None:
            return self.fast.energy(phase, y)
        u, th, ud, thd = self.mdl.split(y)
        return kin.total_energy(self.st, phase, u, th, ud, thd)

    def pivot_momentum(self, y) -> float:
        """L_p of state `y` about the impending pivot (paper 001, Eq 9;
        `multimass.model.kinematics.angular_momentum_new_pivot`, compiled as `energy`)."""
        if self.fast is not None:
            return self.fast.pivot_momentum(y)
        u, _, ud, thd = self.mdl.split(y)
        return kin.angular_momentum_new_pivot(self.st, u, ud, thd)

    def note_transition(self, t: float) -> bool:
        """Record a transition time; True if the chattering guard trips."""
        self.chatter.append(t)
        return (
            len(self.chatter) == self.chatter.maxlen and t - self.chatter[0] < self.chatter_window
        )

    # -- rigid bodies at rest --------------------------------------------------
    def rest_until_uplift(self, s: State, t_stop: float) -> tuple[State, bool]:
        """A rigid body in full contact: find the next uplift (paper 001, Eq 8) or rest.

        Returns the next state and False when the run ends at rest.
        """
        t0 = max(s.t, s.hold_until)
        found = next_uplift(self.st, self.ag, t0, t_stop) if t0 < t_stop else None
        if found is None:
            self.recorder.hold(s.t, t_stop, s.y)
            if self.stop_at_rest and t_stop >= self.duration:
                self.events.append(Event("rest", t_stop, 0, 0, detail="excitation over, at rest"))
                self.recorder.hold(t_stop, self.t_end, s.y)
                return s.but(t=self.t_end), False
            return s.but(t=t_stop), True
        t_up, side = found
        self.recorder.hold(s.t, t_up, s.y)
        return self.start_rocking(s.but(t=t_up), side, "uplift"), True

    def start_rocking(self, s: State, side: int, kind: str, detail: str = "") -> State:
        """The state rocking about `side` from `s` (θ̇ and u̇ as in `s`), logged."""
        self.events.append(Event(kind, s.t, s.phase, side, detail=detail))
        self.recorder.end_phase(s.t, s.y, s.phase)
        self.recorder.start_phase(side, s.t, s.y)
        r = self.draw(-side, s.y) if self.model.has_force else None
        s = s.but(phase=side, r_pending=r)
        return self.trip_guard(s) if self.note_transition(s.t) else s

    # -- one phase segment ------------------------------------------------------------
    def integrate(self, s: State, t_stop: float, recheck: bool = True) -> State:
        """The state at `t_stop` or after the segment's first terminal event (with
        `recheck`, a θ = 0 crossing pair inside one step is looked for: `_zero_between`)."""
        if self.fast is not None:
            return self.fast.integrate(self, s, t_stop)

        rhs = (
            full_contact_rhs(self.mdl, self.ag)
            if s.phase == 0
            else rocking_rhs(self.mdl, s.phase, self.ag, s.force)
        )
        if self.progress is not None:
            rhs = _reporting(rhs, self.progress)
        names, events = phase_events(self, s, QUIET_DELAY)
        t_eval = self.recorder.grid(s.t, t_stop)
        method = self.ivp["method"]
        try:
            sol = solve_ivp(rhs, (s.t, t_stop), s.y, t_eval=t_eval, events=events, **self.ivp)
        except ValueError as exc:  # e.g. LSODA's interpolant defeats the event root search
            return self.fail(
                s,
                s.t,
                f"solve_ivp ({method}) raised in the segment starting at t = {s.t:.6g} s: {exc}",
            )
        self.n_rhs += sol.nfev
        if sol.status == -1:  # with t_eval and no sample reached, sol.t is an empty list
            t_fail = float(np.asarray(sol.t)[-1]) if np.size(sol.t) else s.t
            return self.fail(
                s, t_fail, f"solve_ivp ({method}) failed at t = {t_fail:.6g} s: {sol.message}"
            )
        if not np.all(np.isfinite(sol.y)):
            return self.fail(
                s,
                s.t,
                f"solve_ivp ({method}) produced a non-finite state in the segment "
                f"starting at t = {s.t:.6g} s",
            )
        t_past = None
        if recheck:
            t_past = _zero_between(sol, names, events, s.phase, self.st.n, self.ivp["atol"])
        if t_past is not None:  # again to θ̇'s root: its last step ends past θ = 0
            return self.integrate(s, t_past, recheck=False)
        self.recorder.segment(sol, rhs, s.phase, s.force, names)
        if sol.status == 1:
            i = next(
                i for i, name in enumerate(names) if events[i].terminal and sol.t_events[i].size
            )
            at = s.but(t=float(sol.t_events[i][0]), y=sol.y_events[i][0].copy())
            return handle_event(self, at, names[i])
        return s.but(t=t_stop, y=np.asarray(sol.y)[:, -1].copy())  # the grid ends at t_stop

    def fail(self, s: State, t: float, message: str) -> State:
        """The state `s` ended with status "failed" and the solver's message (never data)."""
        self.events.append(Event("failed", t, s.phase, s.phase, detail=message))
        return s.but(status="failed", message=message)

    # -- the chattering guard --------------------------------------------------------
    def trip_guard(self, s: State) -> State:
        """Chattering: force full contact for one window (logged)."""
        n = self.st.n
        u, th, ud, thd = self.mdl.split(s.y)
        y = s.y.copy()
        if s.phase:
            y[n + 1 : 2 * n + 1] = full_contact_velocities(self.st.H, ud, thd)
        y[n] = 0.0
        y[2 * n + 1] = 0.0
        loss = self.energy(s.phase, s.y) - self.energy(0, y)
        self.recorder.end_phase(s.t, s.y, s.phase)
        self.recorder.add_loss(loss)
        self.events.append(
            Event(
                "chatter_guard",
                s.t,
                s.phase,
                0,
                theta=float(th),
                thetadot_minus=float(thd),
                energy_change=-loss,
                detail=chatter_detail(self.chatter.maxlen, self.chatter_window),
            )
        )
        self.recorder.start_phase(0, s.t, y)
        self.chatter.clear()
        return s.but(phase=0, y=y, force=None, hold_until=s.t + self.chatter_window)
