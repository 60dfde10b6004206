"""The result of `multimass.simulate`: time series, event log, energy ledger, summary.

`Response` (with its series) and `Outcome` (without, for sweeps) follow the one
result contract of `multimass.result`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from .result import Event, Result

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["Event", "Response", "Outcome", "ENERGY_COLUMNS"]


def _empty(columns: list) -> pd.DataFrame:
    """An empty table with these columns (pandas imported here, at the first table: a run
    read only through its summary needs none)."""
    import pandas as pd

    return pd.DataFrame(columns=columns)


class _Table:
    """A `Response` field that holds a table: given as a pandas DataFrame, or as a mapping
    of column name -> array that becomes one when the field is first read (pandas then
    imported and the table built once; a run read through its summary, peaks and events
    needs none: 1 ms of a 12 ms compiled release of S1)."""

    def __set_name__(self, owner, name):
        self.key = name  # the instance's own entry: a data descriptor is looked up first

    def __get__(self, obj, objtype=None):
        if obj is None:  # dataclasses ask the class for a default: there is none
            raise AttributeError("series")
        value = obj.__dict__[self.key]
        if not hasattr(value, "columns"):
            import pandas as pd

            value = pd.DataFrame(value)
            obj.__dict__[self.key] = value
        return value

    def __set__(self, obj, value):
        obj.__dict__[self.key] = value


#: The energy-ledger columns of a `Response`'s series (J; `multimass.result.LEDGER_NAMES`).
ENERGY_COLUMNS = (
    "kinetic",
    "gravitational",
    "elastic",
    "damping",
    "impact",
    "ground_work",
    "balance_error",
)


@dataclass(frozen=True, eq=False)
class Response(Result):
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
        ``ground_work`` and ``balance_error`` (J). Empty if not recorded. It ends
        where the run ended: at `t_end`, or at the overturning instant (its last row,
        ``|θ|`` = the overturning angle) — nothing after an overturn is computed.
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
        The end of the run asked for (s); an overturn ends `series` before it.
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
    series: pd.DataFrame = _Table()
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
    def n_full_contact(self) -> int:
        """Number of transitions into full contact (paper 001, Eq 10)."""
        return sum(e.kind == "full_contact" for e in self.events)

    @property
    def engine(self) -> str:
        """ "solve_ivp", "compiled" or "newmark": what integrated the run."""
        return self.options.get("engine", "solve_ivp")

    @property
    def t(self) -> np.ndarray:
        """Sample times (s); empty if nothing was recorded."""
        return self.series["t"].to_numpy() if "t" in self.series else np.zeros(0)

    @property
    def theta(self) -> np.ndarray:
        """θ at the samples (rad)."""
        return self.series["theta"].to_numpy() if "theta" in self.series else np.zeros(0)

    @property
    def ledger(self) -> pd.DataFrame:
        """The energy ledger at the samples: ``t``, `ENERGY_COLUMNS` and their ``energy``
        = kinetic + gravitational + elastic (J)."""
        if "kinetic" not in self.series:
            return _empty(["t", "energy", *ENERGY_COLUMNS])
        led = self.series[["t", *ENERGY_COLUMNS]].copy()
        led.insert(1, "energy", led["kinetic"] + led["gravitational"] + led["elastic"])
        return led

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

    def _summary_extra(self) -> dict:
        return {
            "structure": self.structure_name,
            "n_full_contact": self.n_full_contact,
            "n_uplifts": sum(e.kind == "uplift" for e in self.events),
            "consecutive_transitions": self.consecutive_transitions(),
            "overturn_time": next((e.time for e in self.events if e.kind == "overturn"), None),
            "energy_balance_error": float(self.energy_balance_error),
            "energy_reference": float(self.energy_reference),
            "wall_time_s": float(self.wall_time_s),
            "n_rhs": int(self.n_rhs),
            "t_end": float(self.t_end),
            "options": self.options,
        }


@dataclass(frozen=True, eq=False)
class Outcome(Result):
    """What `multimass.simulate_outcome` returns: the run without its series.

    Attributes
    ----------
    status, message : str
        As in `Response` ("completed", "overturned", "inaccurate", "failed").
    events : list of Event
    peaks : ndarray
        Absolute peak ``|θ|`` of each half-cycle (rad), as in `Response`.
    n_rhs : int
    wall_time_s : float
    energy_balance_error : float
        Balance error of the ledger at the end of the run, relative to its
        energy scale (the Response's is the largest over the whole run).
    outcome, warnings, checks :
        As in `Response`.
    peak_times : ndarray
    engine : str
        "solve_ivp", "compiled" or "newmark".

    ``t``, ``theta``, ``series`` and ``ledger`` are empty: nothing is sampled.
    """

    status: str
    message: str
    events: list
    peaks: np.ndarray
    n_rhs: int
    wall_time_s: float
    energy_balance_error: float = 0.0
    outcome: str = ""
    warnings: tuple[str, ...] = ()
    checks: dict = field(default_factory=dict)
    peak_times: np.ndarray = field(default_factory=lambda: np.zeros(0))
    engine: str = "solve_ivp"

    t = property(lambda self: np.zeros(0), doc="Empty: an Outcome holds no samples.")
    theta = property(lambda self: np.zeros(0), doc="Empty: an Outcome holds no samples.")
    series = property(lambda self: _empty(["t", "theta", "thetadot"]), doc="Empty (no samples).")
    ledger = property(
        lambda self: _empty(["t", "energy", *ENERGY_COLUMNS]),
        doc="Empty (no samples); `energy_balance_error` holds the end-of-run balance.",
    )

    def _summary_extra(self) -> dict:
        return {
            "energy_balance_error": float(self.energy_balance_error),
            "wall_time_s": float(self.wall_time_s),
            "n_rhs": int(self.n_rhs),
        }
