"""The state of one simulation while it runs: phase loop, transitions, draws, guard.

`multimass.simulate` validates its arguments and builds a `_Run`; the run
integrates one phase segment at a time (solve_ivp, or the compiled kernels of
`multimass.fast`), hands terminal events to `multimass._events` and records
samples, peaks and the ledger in a `Recorder`.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np
from scipy.integrate import solve_ivp

from multimass.impact_models import ImpactContext

from . import kinematics as kin
from ._events import handle_event, phase_events
from ._phase import ActiveForce, Model, full_contact_rhs, rocking_rhs
from ._recorder import Recorder
from ._rigid import next_uplift
from .response import Event

__all__ = ["_Run", "QUIET_DELAY"]

QUIET_DELAY = 1e-9  # s: events are held quiet this long after a restart


def _reporting(rhs, progress, every: int = 2000):
    """`rhs` that tells `progress` the time every `every` calls (long segments show progress)."""
    count = [0]

    def wrapped(t, y):
        count[0] += 1
        if count[0] % every == 0:
            progress(t)
        return rhs(t, y)

    return wrapped


class _Run:
    """State of one simulation while it runs (phase, force, draws, log)."""

    def __init__(
        self,
        st,
        model,
        ag_fn,
        duration,
        bps,
        t_end,
        phase,
        y,
        seed,
        ivp,
        theta_dot_min,
        output_dt,
        overturn_angle,
        chatter_window,
        chatter_count,
        stop_at_rest,
        stop_when_safe,
        energy_floor=0.0,
    ):
        self.st, self.mdl, self.model = st, Model.of(st), model
        self.ag, self.duration, self.t_end = ag_fn, duration, t_end
        ends = [b for b in bps if 0.0 < b < t_end] + ([duration] if 0 < duration < t_end else [])
        self.breakpoints = sorted(set(ends)) + [t_end]
        self.t, self.phase, self.y = 0.0, phase, y
        self.ivp, self.theta_dot_min, self.overturn = ivp, theta_dot_min, overturn_angle
        self.rng = np.random.default_rng(seed)
        self.n_draws, self.r_pending = 0, None
        self.force: ActiveForce | None = None
        self.hold_until = 0.0
        self.chatter = deque(maxlen=chatter_count)
        self.chatter_window, self.stop_at_rest = chatter_window, stop_at_rest
        self.safe_energy = None
        if stop_when_safe and st.n == 0 and math.isfinite(duration):
            # energy to lift the centre of gravity over a pivot, m g R (1 − cos α)
            self.safe_energy = kin.gravitational_energy(st, 1, np.zeros(0), st.alpha_cg)
        self.events: list[Event] = [Event("release", 0.0, phase, phase, theta=float(y[st.n]))]
        self.status, self.message, self.n_rhs = "completed", "", 0
        self.recorder = Recorder(st, self.mdl, output_dt, ag_fn)
        self.recorder.start_phase(phase, 0.0, y)
        self.energy_floor = float(energy_floor)
        self.e0 = self.energy(phase, y)  # the ledger starts from the given state
        self.progress = None  # a callback progress(t), see `loop`
        if phase and model.has_force:
            self.r_pending = self.draw(-phase)

    # -- restitution draws -------------------------------------------------
    def draw(self, side_new: int) -> float:
        ctx = ImpactContext(self.st, side_new, self.y[: self.st.n].copy(), self.n_draws, self.rng)
        self.n_draws += 1
        return float(self.model.restitution.value(ctx))

    # -- main loop -----------------------------------------------------------
    def loop(self, progress=None):
        """Integrate to t_end (or the end of the run); `progress(t)` is told the time."""
        self.progress = progress
        while self.t < self.t_end and self.status == "completed":
            t_stop = next(b for b in self.breakpoints if b > self.t)
            if self.phase == 0 and self.st.n == 0:
                if not self.rest_until_uplift(t_stop):
                    break
                continue
            self.integrate(t_stop)
            if self.status == "completed" and self.is_safe():
                self.events.append(
                    Event(
                        "rest",
                        self.t,
                        self.phase,
                        self.phase,
                        theta=float(self.y[self.st.n]),
                        detail="excitation over; too little energy to overturn",
                    )
                )
                break
            if progress is not None:
                progress(self.t)
        self.recorder.finish(self.t, self.y, self.phase)

    def end_balance_error(self) -> float:
        """|ledger balance| at the end of the run over its energy scale (`multimass.checks`)."""
        E = self.energy(self.phase, self.y)
        D, Wg, WF = (float(x) for x in self.y[-3:])
        balance = E + D + WF + self.recorder.loss - Wg - self.e0
        return abs(balance) / max(abs(self.e0), abs(Wg), abs(E), self.energy_floor, 1e-300)

    def is_safe(self) -> bool:
        """After the excitation, can this rigid body still overturn? (`stop_when_safe`)"""
        if self.safe_energy is None or self.t < self.duration or self.t >= self.t_end:
            return False
        th = float(self.y[self.st.n])
        return abs(th) < self.st.alpha_cg and self.energy(self.phase, self.y) < self.safe_energy

    def energy(self, phase, y) -> float:
        u, th, ud, thd = self.mdl.split(y)
        return kin.total_energy(self.st, phase, u, th, ud, thd)

    def note_transition(self, t: float) -> bool:
        """Record a transition time; True if the chattering guard trips."""
        self.chatter.append(t)
        return (
            len(self.chatter) == self.chatter.maxlen and t - self.chatter[0] < self.chatter_window
        )

    # -- rigid bodies at rest --------------------------------------------------
    def rest_until_uplift(self, t_stop: float) -> bool:
        """A rigid body in full contact: find the next uplift (paper 001, Eq 8) or rest."""

        t0 = max(self.t, self.hold_until)
        found = next_uplift(self.st, self.ag, t0, t_stop) if t0 < t_stop else None
        if found is None:
            self.recorder.hold(self.t, t_stop, self.y)
            self.t = t_stop
            if self.stop_at_rest and self.t >= self.duration:
                self.events.append(Event("rest", self.t, 0, 0, detail="excitation over, at rest"))
                self.recorder.hold(self.t, self.t_end, self.y)
                self.t = self.t_end
                return False
            return True
        t_up, side = found
        self.recorder.hold(self.t, t_up, self.y)
        self.t = t_up
        self.start_rocking(side, "uplift")
        return True

    def start_rocking(self, side: int, kind: str, detail: str = ""):
        self.events.append(Event(kind, self.t, self.phase, side, detail=detail))
        self.recorder.end_phase(self.t, self.y, self.phase)
        self.phase = side
        self.recorder.start_phase(side, self.t, self.y)
        self.r_pending = self.draw(-side) if self.model.has_force else None
        if self.note_transition(self.t):
            self.trip_guard()

    # -- one solve_ivp call ------------------------------------------------------
    fast = None  # a multimass.fast.FastPath with backend="compiled"

    def integrate(self, t_stop: float):
        if self.fast is not None:
            return self.fast.integrate(self, t_stop)

        rhs = (
            full_contact_rhs(self.mdl, self.ag)
            if self.phase == 0
            else rocking_rhs(self.mdl, self.phase, self.ag, self.force)
        )
        if self.progress is not None:
            rhs = _reporting(rhs, self.progress)
        names, events = phase_events(self, QUIET_DELAY)
        t_eval = self.recorder.grid(self.t, t_stop)
        try:
            sol = solve_ivp(rhs, (self.t, t_stop), self.y, t_eval=t_eval, events=events, **self.ivp)
        except ValueError as exc:  # e.g. LSODA's interpolant defeats the event root search
            self.fail(
                self.t,
                f"solve_ivp ({self.ivp['method']}) raised in the segment starting "
                f"at t = {self.t:.6g} s: {exc}",
            )
            return
        self.n_rhs += sol.nfev
        if sol.status == -1:
            self.fail(
                float(sol.t[-1]) if sol.t.size else self.t,
                f"solve_ivp failed at t = {sol.t[-1]:.6g} s: {sol.message}",
            )
            return
        if not np.all(np.isfinite(sol.y)):
            self.fail(
                self.t,
                f"solve_ivp ({self.ivp['method']}) produced a non-finite state in "
                f"the segment starting at t = {self.t:.6g} s",
            )
            return
        self.recorder.segment(sol, rhs, self.phase, self.force, names)
        if sol.status == 1:
            i = next(
                i for i, name in enumerate(names) if events[i].terminal and sol.t_events[i].size
            )
            self.t, self.y = float(sol.t_events[i][0]), sol.y_events[i][0].copy()
            self.handle(names[i])
        else:
            self.t, self.y = t_stop, self._last(sol)

    @staticmethod
    def _last(sol) -> np.ndarray:
        """State at the stop time of a segment (the grid always ends there)."""
        return np.asarray(sol.y)[:, -1].copy()

    def fail(self, t: float, message: str) -> None:
        """End the run with status "failed" and the solver's message (never data)."""
        self.status, self.message = "failed", message
        self.events.append(Event("failed", t, self.phase, self.phase, detail=message))

    # -- transitions ------------------------------------------------------------------
    def handle(self, name: str):
        handle_event(self, name)

    def trip_guard(self):
        """Chattering: force full contact for one window (logged)."""
        u, th, ud, thd = self.mdl.split(self.y)
        y = self.y.copy()
        if self.phase:
            y[self.st.n + 1 : 2 * self.st.n + 1] = ud + self.st.H * thd  # paper 001, Eq 10
        y[self.st.n] = 0.0
        y[2 * self.st.n + 1] = 0.0
        loss = self.energy(self.phase, self.y) - self.energy(0, y)
        self.recorder.end_phase(self.t, self.y, self.phase)
        self.recorder.add_loss(loss)
        self.events.append(
            Event(
                "chatter_guard",
                self.t,
                self.phase,
                0,
                theta=float(th),
                thetadot_minus=float(thd),
                energy_change=-loss,
                detail=f"{self.chatter.maxlen} transitions within {self.chatter_window:g} s",
            )
        )
        self.phase, self.y, self.force = 0, y, None
        self.recorder.start_phase(0, self.t, y)
        self.hold_until = self.t + self.chatter_window
        self.chatter.clear()
