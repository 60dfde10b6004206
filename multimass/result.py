"""The one result contract every engine of the toolkit follows.

Every engine returns a `Result`: `multimass.simulate` (solve_ivp, the compiled
path and Newmark) a `multimass.Response`, `simulate_outcome` an `Outcome`,
`multimass.newmark_block` a `NewmarkResult`, the paper-000 contact engine a
`ContactResponse` (and the block and oscillator views of it), Moreau–Jean an
`NSCDResult`. Whatever the engine, a result has

* ``status`` — one of `STATUSES`: the physical end, or "inaccurate" when the run
  finished but an accuracy check failed (`multimass.checks`); ``outcome`` — the
  physical end whatever the checks say, one of `OUTCOMES`; ``message``;
  ``warnings`` (one line per failed check: what, how much, what to do) and
  ``checks`` (name → {"value", "limit", "passed"});
* ``t`` (s) and ``theta`` (rad; θ > 0 rocks about the right pivot), ``series``
  (a pandas DataFrame with at least the columns ``t``, ``theta``, ``thetadot``)
  and ``ledger`` (a DataFrame of the energy ledger whose columns are named from
  `LEDGER_NAMES`; ``t`` and ``energy`` always);
* ``events`` — a list of `Event`, each ``kind`` one of `EVENT_KINDS`;
* ``peaks`` — the absolute peak ``|θ|`` of each half-cycle in order (rad), the
  unfinished last one included; a free release's first entry is ``|θ0|``, the
  release angle; ``peak_times`` (s);
* `summary` (JSON-ready: SI units and radians; a few ``*_deg`` keys beside the
  radian ones, for reading) and `to_json`.

Degrees appear only in display: CLI tables, plots and JSON keys ending ``_deg``.
"""

from __future__ import annotations

import copy
import dataclasses
import json
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import pandas as pd

__all__ = [
    "STATUSES",
    "OUTCOMES",
    "EVENT_KINDS",
    "LEDGER_NAMES",
    "Event",
    "Result",
    "status_of",
    "json_ready",
    "with_fields",
]


def with_fields(result, **changes):
    """A copy of the frozen dataclass `result` with `changes`, its other fields as stored
    (unlike `dataclasses.replace`, which reads every field: a `Response`'s table not yet
    read would be built).

    Raises
    ------
    TypeError
        If a name in `changes` is not a field of `result`.
    """
    names = {f.name for f in dataclasses.fields(result)}
    unknown = sorted(set(changes) - names)
    if unknown:
        raise TypeError(f"{type(result).__name__} has no field {', '.join(unknown)}")
    new = copy.copy(result)
    for name, value in changes.items():
        object.__setattr__(new, name, value)
    return new


#: What a run's status can be.
STATUSES = ("completed", "overturned", "inaccurate", "failed")

#: What a run's physical outcome can be, and the status it gives when every check passes:
#: "rest" (the run stopped early, the structure at rest after the excitation) completes;
#: "fell_off_beam" (Moreau–Jean: the block left its support) is lost like an overturn;
#: "max_events" (the contact engine's event budget ran out before t_end) fails.
OUTCOMES = {
    "completed": "completed",
    "rest": "completed",
    "overturned": "overturned",
    "fell_off_beam": "overturned",
    "max_events": "failed",
    "failed": "failed",
}

#: Every kind an `Event` can have.
EVENT_KINDS = frozenset(
    {
        "release",  # the state the run starts from
        "uplift",  # full contact → rocking (the uplift of paper 001, lift-off in paper 000)
        "impact",  # θ = 0 into a new half-cycle (or a corner striking, paper 000)
        "full_contact",  # θ = 0 into full contact
        "dd_activate",  # the Dirac-delta force switches on
        "dd_deactivate",  # ... and off
        "chatter_guard",  # chattering stopped by forcing full contact
        "overturn",  # |θ| reached the overturning angle
        "fell_off_beam",  # Moreau–Jean: the block left the beam
        "rest",  # the run stopped: excitation over and at rest (or a Zeno accumulation)
        "failed",  # the solver could not go on
        "stopped",  # a terminal event of a user's contact model
    }
)

#: Names of the energy-ledger columns (J; cumulative quantities from the start of the run).
LEDGER_NAMES = (
    "t",  # s
    "kinetic",
    "gravitational",  # above rest
    "elastic",
    "energy",  # mechanical energy: kinetic + gravitational + elastic
    "ground_work",  # work done on the structure by the ground motion
    "damping",  # dissipated by viscous damping
    "impact",  # lost at impacts
    "projection",  # removed by the contact engine's drift projections
    "balance_error",  # energy − energy(0) − ground_work + damping + impact + projection
)


@dataclass(frozen=True)
class Event:
    """One entry of a run's event log.

    Attributes
    ----------
    kind : str
        One of `EVENT_KINDS`.
    time : float
        Instant (s).
    phase_before, phase_after : int or None
        0 full contact, +1 / −1 rocking about the right / left pivot; None for a
        state that is none of these (flight, or a user's contact model).
    theta, thetadot_minus, thetadot_plus : float
        θ (rad) and θ̇ just before and after the event (rad/s).
    restitution : float or None
        The coefficient applied (classical impacts) or fixed at activation
        (Dirac-delta).
    energy_change : float
        Mechanical energy after minus before an instantaneous transition (J).
    detail : str
    """

    kind: str
    time: float
    phase_before: int | None
    phase_after: int | None
    theta: float = 0.0
    thetadot_minus: float = 0.0
    thetadot_plus: float = 0.0
    restitution: float | None = None
    energy_change: float = 0.0
    detail: str = ""


def status_of(outcome: str, passed: bool = True) -> str:
    """The status of a run that ended with `outcome`: its `OUTCOMES` entry, or
    "inaccurate" when it finished but a check failed (a failed run stays "failed")."""
    status = OUTCOMES[outcome]
    return status if passed or status == "failed" else "inaccurate"


def json_ready(x):
    """`x` with every non-finite float replaced by None (JSON has no NaN or inf)."""
    if isinstance(x, dict):
        return {k: json_ready(v) for k, v in x.items()}
    if isinstance(x, (list, tuple, np.ndarray)):
        return [json_ready(v) for v in x]
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(x) else None
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, np.integer):
        return int(x)
    return x


class Result:
    """Base of every engine's result: the shared contract (module docstring).

    A subclass provides ``status``, ``outcome``, ``message``, ``warnings``,
    ``checks``, ``events``, ``peaks``, ``peak_times``, ``t``, ``theta``,
    ``series`` and ``ledger`` (fields or properties) and may add engine-specific keys to `summary`
    through `_summary_extra`.
    """

    #: The engine's name in `summary` ("solve_ivp", "newmark", "contact", "nscd", ...).
    engine = ""

    @property
    def theta_max(self) -> float:
        """Largest ``|θ|`` of the run (rad), from the peaks."""
        return float(np.max(self.peaks)) if len(self.peaks) else 0.0

    @property
    def overturned(self) -> bool:
        """True if the run overturned and its checks passed (status "overturned")."""
        return self.status == "overturned"

    @property
    def n_impacts(self) -> int:
        """Number of impacts: transitions at θ = 0 into a new half-cycle."""
        return sum(e.kind == "impact" for e in self.events)

    def events_frame(self) -> pd.DataFrame:
        """The event log as a table (one row per event; the `Event` fields as columns)."""
        import pandas as pd  # here: a run summarised without tables needs no pandas

        cols = list(Event.__dataclass_fields__)
        return pd.DataFrame([[getattr(e, c) for c in cols] for e in self.events], columns=cols)

    def _summary_extra(self) -> dict:
        """Engine-specific keys of `summary` (SI units and radians)."""
        return {}

    def summary(self) -> dict:
        """JSON-ready summary: the shared keys, then the engine's own (SI units, radians).

        Non-finite numbers are given as None; degrees only in keys ending ``_deg``.
        """
        peaks = [float(p) for p in self.peaks]
        shared = {
            "engine": self.engine,
            "status": self.status,
            "outcome": self.outcome or self.status,
            "message": self.message,
            "warnings": list(self.warnings),
            "checks": self.checks,
            "n_impacts": self.n_impacts,
            "theta_max": self.theta_max,
            "theta_max_deg": math.degrees(self.theta_max),
            "peaks": peaks,
            "peaks_deg": [math.degrees(p) for p in peaks],
            "peak_times": [float(t) for t in self.peak_times],
        }
        return json_ready(shared | self._summary_extra())

    def to_json(self, **kw) -> str:
        """`summary` as a JSON string (``json.dumps`` keywords pass through)."""
        return json.dumps(self.summary(), **kw)
