"""The result of a simulation: time series, event log, energy ledger, summary."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

__all__ = ["Event", "Response"]


@dataclass(frozen=True)
class Event:
    """One entry of the event log.

    Attributes
    ----------
    kind : str
        "release", "uplift", "impact" (a new half-cycle after θ = 0),
        "full_contact" (paper 001, Eq 10), "dd_activate", "dd_deactivate",
        "chatter_guard", "overturn", "rest" or "failed".
    time : float
    phase_before, phase_after : int
        0 full contact, +1 / −1 rocking about the right / left pivot.
    theta, thetadot_minus, thetadot_plus : float
    restitution : float or None
        The coefficient applied (classical impacts) or fixed at activation
        (Dirac-delta).
    energy_change : float
        Mechanical energy after minus before an instantaneous transition (J).
    detail : str
    """

    kind: str
    time: float
    phase_before: int
    phase_after: int
    theta: float = 0.0
    thetadot_minus: float = 0.0
    thetadot_plus: float = 0.0
    restitution: float | None = None
    energy_change: float = 0.0
    detail: str = ""


@dataclass(frozen=True, eq=False)
class Response:
    """Outcome of `multimass.simulate`.

    Attributes
    ----------
    structure_name : str
    status : {"completed", "overturned", "inaccurate", "failed"}
        The physical `outcome`, or "inaccurate" when the run finished but an
        accuracy check failed (see `multimass.checks`; `warnings` says which).
    message : str
        The solver's message when it failed, else a short summary.
    series : pandas.DataFrame
        Sampled time series: ``t``, ``phase``, ``theta``, ``thetadot``,
        ``u1..uN``, ``udot1..udotN``, ``a1..aN`` (total accelerations, paper
        001 Eq 7, m/s²), ``F_i`` (N), ``ag`` (m/s²) and the ledger columns
        ``kinetic``, ``gravitational``, ``elastic``, ``damping``, ``impact``,
        ``ground_work`` and ``balance_error`` (J). Empty if not recorded.
    events : list of Event
    peaks : ndarray
        Absolute peak ``|θ|`` of each half-cycle (rad), in order; for a free
        release the first is the release angle.
    peak_times : ndarray
    energy_reference : float
        The energy the balance error is measured against (J): the initial
        energy, or the largest ground work for forced runs.
    energy_balance_error : float
        max ``|balance error|`` / `energy_reference`.
    wall_time_s : float
        Time spent in the simulation proper.
    options : dict
        Solver and model options used.
    n_rhs : int
        Right-hand-side evaluations.
    t_end : float
    outcome : {"completed", "overturned", "failed"}
        How the run ended physically, whatever its checks say.
    warnings : tuple of str
        One line per failed check or caveat: what, how much, what to do.
    checks : dict
        name -> {"value", "limit", "passed"}, e.g. "energy_balance".
    """

    structure_name: str
    status: str
    message: str
    series: pd.DataFrame
    events: list[Event]
    peaks: np.ndarray
    peak_times: np.ndarray
    energy_reference: float
    energy_balance_error: float
    wall_time_s: float
    options: dict = field(default_factory=dict)
    n_rhs: int = 0
    t_end: float = 0.0
    outcome: str = ""
    warnings: tuple[str, ...] = ()
    checks: dict = field(default_factory=dict)

    @property
    def n_impacts(self) -> int:
        """Number of θ = 0 transitions into a new half-cycle."""
        return sum(e.kind == "impact" for e in self.events)

    @property
    def n_full_contact(self) -> int:
        """Number of transitions into full contact (paper 001, Eq 10)."""
        return sum(e.kind == "full_contact" for e in self.events)

    @property
    def theta_max(self) -> float:
        """Largest ``|θ|`` reached (rad)."""
        return float(self.peaks.max()) if self.peaks.size else 0.0

    @property
    def overturned(self) -> bool:
        """True if the run overturned and its checks passed (status "overturned")."""
        return self.status == "overturned"

    def events_frame(self) -> pd.DataFrame:
        """The event log as a table."""
        cols = list(Event.__dataclass_fields__)
        return pd.DataFrame([[getattr(e, c) for c in cols] for e in self.events], columns=cols)

    def consecutive_transitions(self, window: float = 0.02, t_max: float = math.inf) -> int:
        """Phase transitions inside one impact (paper 001, Section 4.3).

        Counts transitions (a new half-cycle, full contact or uplift) that
        follow the previous transition within `window` seconds — far shorter
        than a rocking half-cycle, so driven by the vibration the impact
        excited: the "several consecutive phase transitions within a single
        impact" of the classical model. Only transitions up to `t_max` count.
        """
        times = [
            e.time
            for e in self.events
            if e.kind in ("impact", "full_contact", "uplift") and e.time <= t_max
        ]
        return int(sum(b - a < window for a, b in zip(times, times[1:])))

    def summary(self) -> dict:
        """JSON-ready summary (SI units, radians)."""
        return {
            "structure": self.structure_name,
            "status": self.status,
            "outcome": self.outcome or self.status,
            "message": self.message,
            "warnings": list(self.warnings),
            "checks": self.checks,
            "n_impacts": self.n_impacts,
            "n_full_contact": self.n_full_contact,
            "n_uplifts": sum(e.kind == "uplift" for e in self.events),
            "consecutive_transitions": self.consecutive_transitions(),
            "theta_max": self.theta_max,
            "peaks": [float(p) for p in self.peaks],
            "peak_times": [float(t) for t in self.peak_times],
            "overturn_time": next((e.time for e in self.events if e.kind == "overturn"), None),
            "energy_balance_error": float(self.energy_balance_error),
            "energy_reference": float(self.energy_reference),
            "wall_time_s": float(self.wall_time_s),
            "n_rhs": int(self.n_rhs),
            "t_end": float(self.t_end),
            "options": self.options,
        }

    def to_json(self, **kw) -> str:
        """`summary` as a JSON string."""
        return json.dumps(self.summary(), **kw)
