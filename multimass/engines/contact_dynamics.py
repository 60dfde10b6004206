"""Event-driven nonsmooth dynamics with unilateral sticking contacts and Poisson impacts.

The smooth motion between impacts (paper 000, Section 2.1) is
``M(q) q̈ = h(t, q, q̇) + W_N λ_N + W_T λ_T`` with the closed contacts held at
acceleration level (ġ_N = 0 and sticking ġ_T = 0, so g̈ = Wᵀq̈ + ŵ = 0) and the
open ones free. A phase is the set of closed contacts: for a block, both
corners (full contact), one corner (rocking) or none (free flight). A phase
ends when an open contact closes (gap g_N → 0: an impact, resolved by the
Poisson LCPs of `impact_models.poisson_impact`) or a closed one unloads
(λ_N → 0: lift-off). After each event the new phase is the largest subset of
the contacts with ġ_N = 0 whose contact forces are compressive while the
others accelerate apart (the acceleration-level Signorini condition), so
bouncing and flight happen exactly when the impact LCP and the force signs
say so.

A run that starts on the ground starts from the given state: a touching
contact (``|g_N| ≤ gap_tol``) that separates (ġ_N > 0) is open; one that
approaches (ġ_N < 0), or a closed one that slips (ġ_T ≠ 0, which sticking
stops), makes an impact at t0, resolved by the Poisson LCPs like any other;
only contacts with ġ_N ≈ 0 are closed or opened by the force signs.

A run the solvers cannot continue (no consistent set of closed contacts, a
failed integration or LCP) ends with status "failed" and its message; the
history up to there is returned.

Housekeeping: at each phase start the state is projected back onto the closed
contacts' constraints (integration drift), an impact is applied at g_N = 0,
and an accumulation of impacts (approach speed below ``zeno_velocity``) ends
with all touching contacts kept closed ("zeno_rest"). In a phase with no free
coordinate (a block in full contact) nothing is integrated: the contact forces
are scanned in time for the first sign change.

The energy ledger starts from the given state (q0, v0): its first sample is
that state, and every change of the state outside the equations of motion is
booked — impacts and "zeno_rest" in ``impact_loss``, drift projections in
``projection_loss`` — so a loss never hides. The run reports its checks
(`multimass.engines._contact_checks`): the ledger's balance error, the housekeeping
energy, and the friction demand ``|λ_T|/λ_N`` of the sticking contacts against a
friction coefficient ``mu`` when one is given.

A model supplies ``n``, ``k``, ``mass(q)``, ``forces(t, q, v)``,
``contacts(q, v) -> (g, W_N, W_T, ŵ_N, ŵ_T)``, ``energy(q, v)`` (kinetic +
potential, J), ``powers(t, q, v) -> (ground power, damping power)`` and
optionally

* ``events``: extra terminal events, a sequence of ``(name, f(t, q, v))``, e.g.
  ``("overturn", ...)``. A run stopped by one ends with an event and an outcome
  named after it (`model_stop`): "overturn" or "overturned" give the event kind
  "overturn" and the outcome "overturned"; another name that is one of
  `multimass.result.EVENT_KINDS` keeps it as the kind (with its outcome when it
  is one of `multimass.result.OUTCOMES`, e.g. "rest", else "completed"); any
  other name gives the kind "stopped" and the outcome "completed". The event's
  ``detail`` holds the model's name either way.
* ``rotation``: the index in q of a rotation φ, counter-clockwise positive (paper
  000); the response then gives the toolkit's θ = −φ (θ > 0 rocks about the right
  pivot), its half-cycle peaks, and θ in the events. Without it θ is NaN and there
  are no peaks.
* ``pivots``: the indices (left, right) of the two contacts a body rocks on; the
  events' and the series' phases are then 0 (both closed: full contact), +1 (the
  right one only: rocking about the right pivot), −1 (the left one only) and None
  (neither: flight). Without it the phases are None.

The result follows the toolkit's one result contract (`multimass.result`): a
`ContactResponse` is a `multimass.result.Result` (engine "contact") whose events are
`ContactEvent`, a `multimass.result.Event` with the contact sets: the kinds are
"release" (the given state, first; its phases those of the resting contacts and of the
closed set chosen from them), "impact", "uplift" (a closed contact lifts off, paper
000's lift-off: into rocking or flight), "rest" (the "zeno_rest" above, ``detail``
"zeno_rest"), the model events' kinds, and "failed". The "release" does not count
towards ``max_events``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import pandas as pd
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar

from multimass.impact_models.complementarity import LCPError
from multimass.impact_models.poisson import PoissonImpact, poisson_impact

from ..errors import InputError, SolverError
from ..result import EVENT_KINDS, OUTCOMES, Event, Result, status_of
from ._contact_checks import (
    FrictionDemand,
    _number,
    _options,
    _state,
    friction_ratio,
    impact_ratio,
    run_checks,
    tangential_groups,
    validate_mu,
)
from ._contact_phase import (
    _constraint_matrix,
    _events,
    _grid,
    _Phase,
    _project,
    _project_q,
    _select,
)

__all__ = [
    "ContactView",
    "ContactEvent",
    "ContactResponse",
    "FrictionDemand",
    "simulate_contacts",
    "model_stop",
    "half_cycle_peaks",
]

#: θ closer to 0 than this (rad) counts as upright between half-cycles (`half_cycle_peaks`)
THETA_ZERO = 1e-12


@dataclass(frozen=True, eq=False)
class ContactEvent(Event):
    """One event of `simulate_contacts`: a `multimass.result.Event` with the contact sets.

    ``kind`` is "release" (the given state at t0, first), "impact", "uplift" (a closed
    contact lifts off), "rest" (an accumulation of impacts ended, ``detail``
    "zeno_rest"), "failed", or the kind of a model's terminal event (`model_stop`;
    ``detail`` holds the model's name).
    ``phase_before`` / ``phase_after`` follow the model's ``pivots`` (module
    docstring), θ and θ̇ its ``rotation`` (0 without one); ``restitution`` is the
    Poisson coefficient ε_P of an impact's contacts (None if they differ) and
    ``energy_change`` the energy the event took (J: the impact loss with a minus sign).

    Attributes
    ----------
    closed_before, closed_after : tuple of int
        The closed contact sets.
    impact : PoissonImpact or None
        The Poisson impact result of an impact, else None.
    contacts : tuple of int
        The contacts taking part in an impact (the columns of its W_N, in order).
    """

    closed_before: tuple[int, ...] = ()
    closed_after: tuple[int, ...] = ()
    impact: PoissonImpact | None = None
    contacts: tuple[int, ...] = ()


def model_stop(name: str) -> tuple[str, str]:
    """(event kind, outcome) of a run stopped by the model's terminal event `name`.

    "overturn" / "overturned" → ("overturn", "overturned"); a name in
    `multimass.result.EVENT_KINDS` is kept, its outcome the name if it is one of
    `multimass.result.OUTCOMES` (e.g. "rest"), else "completed"; any other name →
    ("stopped", "completed").
    """
    if name in ("overturn", "overturned"):
        return "overturn", "overturned"
    if name in EVENT_KINDS:
        return name, name if name in OUTCOMES else "completed"
    return "stopped", "completed"


def phase_of(closed, pivots) -> int | None:
    """Phase of a closed contact set: 0 both pivots, +1 the right only, −1 the left only,
    None neither (flight) or no ``pivots`` = (left, right)."""
    if pivots is None:
        return None
    left, right = (p in closed for p in pivots)
    return 0 if left and right else 1 if right else -1 if left else None


def _bits(mask: int) -> tuple[int, ...]:
    """The contacts of a closed-set bit mask."""
    return tuple(j for j in range(int(mask).bit_length()) if mask >> j & 1)


def half_cycle_peaks(t, theta) -> tuple[np.ndarray, np.ndarray]:
    """(peaks, times): the largest ``|θ|`` of each half-cycle of sampled θ, and its time.

    A half-cycle is a run of samples of one sign (``|θ|`` ≤ `THETA_ZERO` counts as 0 and
    belongs to none: full contact), the unfinished last one included; its largest
    sample is refined by the parabola through it and its neighbours when that
    parabola peaks between them. A release from rest at θ0 ≠ 0 gives ``|θ0|`` first.
    Repeated times (an event's before and after samples) keep the last sample.
    """
    t, theta = np.asarray(t, dtype=float), np.asarray(theta, dtype=float)
    if t.size == 0:
        return np.zeros(0), np.zeros(0)
    keep = np.r_[np.diff(t) > 0, True]
    t, theta = t[keep], theta[keep]
    peaks, times = [], []
    sign = np.sign(np.where(np.abs(theta) > THETA_ZERO, theta, 0.0))
    edges = np.flatnonzero(np.diff(sign) != 0) + 1
    for a, b in zip(np.r_[0, edges], np.r_[edges, sign.size]):
        if sign[a] == 0:
            continue
        i = a + int(np.argmax(np.abs(theta[a:b])))
        pk, tp = abs(float(theta[i])), float(t[i])
        if a < i < b - 1:
            c = np.polyfit(t[i - 1 : i + 2] - t[i], np.abs(theta[i - 1 : i + 2]), 2)
            if c[0] < 0 and abs(c[1] / (2 * c[0])) < t[i + 1] - t[i - 1]:
                tv = -c[1] / (2 * c[0])
                pk, tp = float(np.polyval(c, tv)), float(t[i] + tv)
        peaks.append(pk)
        times.append(tp)
    return np.asarray(peaks, dtype=float), np.asarray(times, dtype=float)


@dataclass(frozen=True, eq=False)
class ContactResponse(Result):
    """Sampled response, energy ledger and checks of `simulate_contacts`.

    A `multimass.result.Result` (engine "contact"); the views `BlockResponse`
    (`multimass.engines.poisson_block`) and `OscillatorResponse`
    (`multimass.engines.flexible_oscillator`) name its coordinates.

    Attributes
    ----------
    t : ndarray, shape (m,)
        Sample times (s); the first sample is the given initial state, and event
        times (and t0) appear twice: before and after.
    q, v : ndarray, shape (m, n)
    closed : ndarray of int, shape (m,)
        Bit mask of the closed contacts (bit i = contact i).
    energy, ground_work, damping, impact_loss, projection_loss : ndarray, shape (m,)
        Mechanical energy T + V, cumulative work of the ground excitation,
        cumulative damping dissipation, impact losses (Poisson impacts and
        "zeno_rest") and the energy removed by drift projections (J).
    events : tuple of ContactEvent
    status : {"completed", "overturned", "inaccurate", "failed"}
        ``outcome`` through `multimass.result.status_of` when every check passed,
        else "inaccurate"; "failed" when the solvers could not go on (the history
        up to there is kept) or the event budget ran out ("max_events").
    message : str
    outcome : str
        How the run ended, whatever the checks say: "completed", "max_events",
        "failed", or the outcome of a model's terminal event (`model_stop`, e.g.
        "overturned"); one of `multimass.result.OUTCOMES`.
    checks : dict
        name → {"value": float, "limit": float, "passed": bool}:
        ``energy_balance``, ``projection`` and, with ``mu``, ``friction_smooth``
        and ``friction_impact`` (`multimass.engines._contact_checks`).
    warnings : tuple of str
        One line per failed check: what, value, limit, what to do.
    friction : FrictionDemand
        Largest friction demand ``|λ_T|/λ_N`` over the smooth phases and the
        impacts, with their times (always reported, `mu` or not).
    rotation : int or None
        Index in q of the model's rotation φ (counter-clockwise positive), which
        gives θ = −φ; None: the model has none (θ is NaN, no peaks).
    pivots : tuple of int or None
        The model's (left, right) contacts, which give the phases.

    Notes
    -----
    ``theta``, ``thetadot`` (rad, rad/s), ``peaks`` and ``peak_times``
    (`half_cycle_peaks` of the samples), ``series`` and ``ledger`` are derived from
    these; ``summary()`` adds the friction demand (an unbounded demand becomes None
    in JSON, see ``friction``).
    """

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    closed: np.ndarray
    energy: np.ndarray
    ground_work: np.ndarray
    damping: np.ndarray
    impact_loss: np.ndarray
    projection_loss: np.ndarray
    events: tuple[ContactEvent, ...]
    status: str
    message: str
    outcome: str
    checks: dict
    warnings: tuple[str, ...]
    friction: FrictionDemand
    rotation: int | None = None
    pivots: tuple[int, int] | None = None

    engine = "contact"

    @property
    def ledger_error(self) -> np.ndarray:
        """E(t) − E(t0) − W_ground + D + impact and projection losses: zero if the ledger
        closes (J); E(t0) is the energy of the given initial state."""
        return (
            self.energy
            - self.energy[0]
            - self.ground_work
            + self.damping
            + self.impact_loss
            + self.projection_loss
        )

    @property
    def impacts(self) -> tuple[ContactEvent, ...]:
        """The events that hold a Poisson impact (kind "impact")."""
        return tuple(e for e in self.events if e.impact is not None)

    @property
    def theta(self) -> np.ndarray:
        """θ = −φ at the samples (rad; θ > 0 rocks about the right pivot); NaN without
        a ``rotation``."""
        if self.rotation is None:
            return np.full(self.t.size, np.nan)
        return -self.q[:, self.rotation]

    @property
    def thetadot(self) -> np.ndarray:
        """θ̇ = −φ̇ at the samples (rad/s); NaN without a ``rotation``."""
        if self.rotation is None:
            return np.full(self.t.size, np.nan)
        return -self.v[:, self.rotation]

    @cached_property
    def _peaks(self) -> tuple[np.ndarray, np.ndarray]:
        if self.rotation is None:
            return np.zeros(0), np.zeros(0)
        return half_cycle_peaks(self.t, self.theta)

    @property
    def peaks(self) -> np.ndarray:
        """Largest ``|θ|`` of each half-cycle in order (rad), the unfinished last one
        included; a release from rest at θ0 ≠ 0 starts with ``|θ0|`` (`half_cycle_peaks`)."""
        return self._peaks[0]

    @property
    def peak_times(self) -> np.ndarray:
        """Instants of `peaks` (s)."""
        return self._peaks[1]

    @property
    def phase(self) -> pd.Series:
        """Phase at the samples (pandas Int64): 0 full contact, +1 / −1 rocking about the
        right / left pivot, <NA> in flight or without ``pivots``."""
        masks = self.closed.tolist()
        codes = {m: phase_of(_bits(m), self.pivots) for m in set(masks)}
        return pd.Series([codes[m] for m in masks], dtype="Int64")

    @property
    def series(self) -> pd.DataFrame:
        """The samples: ``t``, ``theta``, ``thetadot``, ``phase`` (see `phase`), ``closed``
        (bit mask), ``q0``…, ``v0``… (the model's coordinates and rates)."""
        cols = {"t": self.t, "theta": self.theta, "thetadot": self.thetadot}
        df = pd.DataFrame(cols)
        df["phase"] = self.phase.array
        df["closed"] = self.closed
        for j in range(self.q.shape[1] if self.q.ndim == 2 else 0):
            df[f"q{j}"] = self.q[:, j]
        for j in range(self.v.shape[1] if self.v.ndim == 2 else 0):
            df[f"v{j}"] = self.v[:, j]
        return df

    @property
    def ledger(self) -> pd.DataFrame:
        """The energy ledger at the samples (J; `multimass.result.LEDGER_NAMES`): ``t``,
        ``energy``, ``ground_work``, ``damping``, ``impact`` (`impact_loss`),
        ``projection`` (`projection_loss`) and ``balance_error`` (`ledger_error`)."""
        return pd.DataFrame(
            {
                "t": self.t,
                "energy": self.energy,
                "ground_work": self.ground_work,
                "damping": self.damping,
                "impact": self.impact_loss,
                "projection": self.projection_loss,
                "balance_error": self.ledger_error,
            }
        )

    def _summary_extra(self) -> dict:
        fr = self.friction
        return {
            "n_events": len(self.events),
            "n_uplifts": sum(e.kind == "uplift" for e in self.events),
            "overturn_time": next((e.time for e in self.events if e.kind == "overturn"), None),
            "energy_balance_error": self.checks.get("energy_balance", {}).get("value"),
            "friction_demand": {
                "smooth": fr.smooth,
                "smooth_time": fr.smooth_time,
                "impact": fr.impact,
                "impact_time": fr.impact_time,
            },
            "t_end": float(self.t[-1]) if self.t.size else None,
            "final_energy": float(self.energy[-1]) if self.energy.size else None,
        }


class ContactView(Result):
    """A model's view of a `ContactResponse` (`raw`): the shared contract passed through,
    and the samples named after the model's coordinates (`COORDINATES`).

    ``status``, ``outcome``, ``message``, ``checks``, ``warnings``, ``friction``,
    ``events``, ``peaks``, ``peak_times``, ``t``, ``theta``, ``thetadot`` and ``ledger``
    are those of `raw`; a subclass holds ``raw`` and names its coordinates.
    """

    #: Names of the generalized coordinates q, in order (their rates get a "dot").
    COORDINATES: tuple[str, ...] = ()
    engine = "contact"

    t = property(lambda self: self.raw.t, doc="Sample times (s); event times appear twice.")
    theta = property(lambda self: self.raw.theta, doc="θ = −φ (rad; θ > 0 on the right pivot).")
    thetadot = property(lambda self: self.raw.thetadot, doc="θ̇ = −φ̇ (rad/s).")
    status = property(
        lambda self: self.raw.status,
        doc='``outcome``\'s status when every check passed, else "inaccurate".',
    )
    outcome = property(
        lambda self: self.raw.outcome,
        doc='How the run ended: "completed", "overturned", "max_events" or "failed".',
    )
    message = property(lambda self: self.raw.message)
    checks = property(
        lambda self: self.raw.checks,
        doc="Energy balance, housekeeping and (with ``mu``) friction checks.",
    )
    warnings = property(lambda self: self.raw.warnings)
    friction = property(
        lambda self: self.raw.friction,
        doc="Largest friction demand ``|λ_T|/λ_N``, smooth phases and impacts (`FrictionDemand`).",
    )
    events = property(
        lambda self: self.raw.events,
        doc='The `ContactEvent` log (kinds "impact", "uplift", "rest", "overturn", "failed").',
    )
    peaks = property(
        lambda self: self.raw.peaks,
        doc="Largest ``|θ|`` of each half-cycle (rad); a release from rest gives ``|θ0|`` first.",
    )
    peak_times = property(lambda self: self.raw.peak_times)
    ledger = property(lambda self: self.raw.ledger, doc="The energy ledger (J).")

    def coordinate(self, name: str) -> np.ndarray:
        """The samples of coordinate `name` (one of `COORDINATES`)."""
        return self.raw.q[:, self.COORDINATES.index(name)]

    @property
    def phase(self) -> np.ndarray:
        """Per sample: "full", "rock_left", "rock_right" or "flight" (the series' ``phase``
        column holds the same as 0, −1, +1, <NA>)."""
        return _PHASE_NAMES[self.raw.closed]

    @property
    def series(self) -> pd.DataFrame:
        """The samples: ``t``, ``theta``, ``thetadot``, ``phase`` (0, ±1, <NA> in flight),
        then each of `COORDINATES` and its rate (``<name>dot``)."""
        raw = self.raw
        df = pd.DataFrame({"t": raw.t, "theta": self.theta, "thetadot": self.thetadot})
        df["phase"] = raw.phase.array
        for j, name in enumerate(self.COORDINATES):
            df[name] = raw.q[:, j]
        for j, name in enumerate(self.COORDINATES):
            df[f"{name}dot"] = raw.v[:, j]
        return df


_PHASE_NAMES = np.array(["flight", "rock_left", "rock_right", "full"])  # by closed-set mask


class _Driver:
    """State and bookkeeping of one `simulate_contacts` run."""

    def __init__(self, model, eps, opts):
        self.model, self.eps, self.o = model, eps, opts
        self.out, self.events, self.loss = [], [], 0.0
        self.proj, self.proj_abs = 0.0, 0.0
        self.fd = dict(smooth=0.0, smooth_time=None, impact=0.0, impact_time=None)
        self.release = None  # the "release" event: the given state (`start`)
        self.rot = getattr(model, "rotation", None)
        self.pivots = getattr(model, "pivots", None)

    def angles(self, y) -> tuple[float, float]:
        """(θ, θ̇) = (−φ, −φ̇) of a state y (0, 0 without a model ``rotation``)."""
        if self.rot is None:
            return 0.0, 0.0
        return -float(y[self.rot]), -float(y[self.model.n + self.rot])

    def event(self, kind, t, y, S, S_new, *, y_minus=None, **kw) -> ContactEvent:
        """A `ContactEvent` at t: closed sets S → S_new, state y after (y_minus before)."""
        th, thd_plus = self.angles(y)
        thd_minus = thd_plus if y_minus is None else self.angles(y_minus)[1]
        return ContactEvent(
            kind,
            float(t),
            phase_of(S, self.pivots),
            phase_of(S_new, self.pivots),
            th,
            thd_minus,
            thd_plus,
            closed_before=tuple(S),
            closed_after=tuple(S_new),
            **kw,
        )

    def record(self, ts, ys, S):
        n = self.model.n
        qs, vs = ys[:n].T, ys[n : 2 * n].T
        E = np.array([self.model.energy(a, b) for a, b in zip(qs, vs)])
        mask = sum(1 << j for j in S)
        self.out.append(
            (
                ts,
                qs,
                vs,
                np.full(ts.size, mask),
                E,
                ys[2 * n],
                ys[2 * n + 1],
                np.full(ts.size, self.loss),
                np.full(ts.size, self.proj),
            )
        )

    def note(self, kind: str, value: float, t: float):
        """Keep the largest friction demand of `kind` ("smooth" or "impact") and its time."""
        if self.fd[f"{kind}_time"] is None or value > self.fd[kind]:
            self.fd[kind], self.fd[f"{kind}_time"] = float(value), float(t)

    def book_projection(self, y_new, y_old):
        """Book the energy change of a housekeeping correction y_old → y_new."""
        n, m = self.model.n, self.model
        dE = m.energy(y_old[:n], y_old[n : 2 * n]) - m.energy(y_new[:n], y_new[n : 2 * n])
        self.proj += dE
        self.proj_abs += abs(dE)

    def project(self, S, y):
        """Remove integration drift at a phase start (booked as projection loss)."""
        if S:
            n = self.model.n
            old = y[: 2 * n].copy()
            y[: 2 * n] = _project(self.model, S, y[:n], y[n : 2 * n])
            self.book_projection(y, old)

    def peak_demand(self, ph, ts, lams, lam_at):
        """Largest demand over samples `lams` at `ts`, refined between the neighbours."""
        ns, ftol = len(ph.S), self.o["ftol"]

        def dem(lam):
            return friction_ratio(lam[:ns], lam[ns:], ph.groups, ftol)

        vals = np.array([dem(lam) for lam in lams])
        i = int(np.argmax(vals))
        best = [float(vals[i]), float(ts[i])]

        def neg(s):  # −demand, kept finite for Brent's arithmetic
            d = dem(lam_at(s))
            if d > best[0]:
                best[:] = [d, float(s)]
            return -min(d, 1e300)

        if 0 < i < vals.size - 1 and math.isfinite(best[0]) and ts[i + 1] > ts[i - 1]:
            minimize_scalar(
                neg,
                bounds=(ts[i - 1], ts[i + 1]),
                method="bounded",
                options={"xatol": 1e-12 * max(1.0, ts[i])},
            )
        self.note("smooth", best[0], best[1])

    def smooth(self, ph, t, t_stop, y):
        """Integrate a phase; returns (t1, y1, indices of the events that fired)."""
        o, k, n = self.o, self.model.k, self.model.n
        sol = solve_ivp(
            ph.rhs,
            (t, t_stop),
            y,
            method="DOP853",
            rtol=o["rtol"],
            atol=o["atol"],
            max_step=o["max_step"],
            dense_output=True,
            events=_events(self.model, ph, k, y, 1e-3 * o["gap_tol"]),
        )
        if sol.status == -1:
            raise SolverError(f"solve_ivp failed at t = {sol.t[-1]:.6g}: {sol.message}")
        t1 = float(sol.t[-1])
        ts = _grid(t, t1, o["dt_out"])
        self.record(ts, sol.sol(ts), ph.S)
        if ph.tk:  # sticking contacts carry tangential forces

            def lam_at(s, yy=None):
                yy = sol.sol(s) if yy is None else yy
                return ph.multipliers(s, yy[:n], yy[n : 2 * n])[1]

            self.peak_demand(ph, sol.t, [lam_at(s, yy) for s, yy in zip(sol.t, sol.y.T)], lam_at)
        hit = [i for i, te in enumerate(sol.t_events) if te.size] if sol.status == 1 else []
        return t1, sol.y[:, -1].copy(), hit

    def locked(self, ph, t, t_stop, y):
        """A phase without free coordinates: scan λ_N(t) for the first sign change."""
        n, dt, ns = self.model.n, self.o["locked_dt"], len(ph.S)
        q, v = y[:n], y[n : 2 * n]
        L, c = ph.force_map(q, v)

        def lam(s):
            return L @ self.model.forces(s, q, v) + c

        quiet = max(getattr(self.model, "quiet_after", np.inf), t)
        ts = np.arange(t, min(t_stop, quiet), dt)
        ts = np.unique(np.concatenate([ts, [min(t_stop, quiet), t_stop]]))
        t1, hit, la = t_stop, [], lam(ts[0])
        seen_t, seen = [ts[0]], [la]
        for a, b in zip(ts[:-1], ts[1:]):
            lb = lam(b)
            neg = np.flatnonzero(lb[:ns] < 0.0)
            if neg.size:
                roots = [
                    brentq(lambda s, i=i: lam(s)[i], a, b, xtol=1e-14) if la[i] > 0 else a
                    for i in neg
                ]
                t1, hit = min(roots), [int(neg[np.argmin(roots)])]
                seen_t.append(t1)
                seen.append(lam(t1))
                break
            seen_t.append(b)
            seen.append(lb)
            la = lb
        if ph.tk:
            self.peak_demand(ph, np.array(seen_t), seen, lam)
        ts_out = _grid(t, t1, self.o["dt_out"])
        self.record(ts_out, np.repeat(y[:, None], ts_out.size, axis=1), ph.S)
        return t1, y, [ph.S[h] for h in hit]

    def impact(self, t, y, S, closing):
        """Impact at time t of the `closing` contacts (or a slip stopped by sticking)."""
        m, n, k, o = self.model, self.model.n, self.model.k, self.o
        q, v = y[:n], y[n : 2 * n]
        g = m.contacts(q, v)[0]
        K = tuple(
            sorted(
                int(j)
                for j in set(S) | set(closing) | {j for j in range(k) if abs(g[j]) <= o["gap_tol"]}
            )
        )
        y_minus, old = y.copy(), y[: 2 * n].copy()
        y[:n] = q = _project_q(m, K, q, v)  # the impact happens at g_N = 0
        self.book_projection(y, old)
        _, WN, WT, _, _ = m.contacts(q, v)
        _, tk = _constraint_matrix(WN, WT, K)
        approach = -(WN[:, list(closing)].T @ v).min(initial=0.0)
        if closing and approach < o["zeno_velocity"]:  # accumulation of impacts: come to rest
            e_before = m.energy(q, v)
            y[: 2 * n] = _project(m, K, q.copy(), v.copy())
            lost = e_before - m.energy(y[:n], y[n : 2 * n])
            kw = dict(energy_change=-lost, detail="zeno_rest")
            res, kind, cands = None, "rest", list(K)
        else:
            res = poisson_impact(m.mass(q), WN[:, list(K)], WT[:, tk], v, self.eps[list(K)])
            y[n : 2 * n] = res.u_plus
            lost = res.energy_loss
            eps = set(self.eps[list(K)].tolist())
            kw = dict(energy_change=-lost, restitution=eps.pop() if len(eps) == 1 else None)
            cands = [K[i] for i, st in enumerate(res.final_states) if st == "closed"]
            kind = "impact"
            self.note("impact", impact_ratio(res, tangential_groups(WT, K, tk)), t)
        self.loss += lost
        return self.after(t, y, S, cands, kind, res, K, y_minus=y_minus, **kw)

    def after(self, t, y, S, cands, kind, res, K, **kw):
        """Log the event, choose the new closed set among `cands` and record the state."""
        n = self.model.n
        S_new = _select(self.model, t, y[:n], y[n : 2 * n], cands, self.o["ftol"])
        contacts = tuple(int(j) for j in K)
        self.events.append(self.event(kind, t, y, S, S_new, impact=res, contacts=contacts, **kw))
        self.record(np.array([t]), y[:, None], S_new)
        return S_new

    def transition(self, t, y, S, hit_contacts):
        """Impact or lift-off at time t; returns the new closed set (and updates y)."""
        closing = [j for j in hit_contacts if j not in S]
        if closing:
            return self.impact(t, y, S, closing)
        cands = [j for j in S if j not in hit_contacts]  # lift-off: the unloading contact leaves
        return self.after(t, y, S, cands, "uplift", None, tuple(hit_contacts))

    def start(self, t, y):
        """Closed set at t0 from the given state; records it, applies an impact at t0 if due.

        Touching contacts (``|g_N| ≤ gap_tol``) that separate are open; approaching
        ones, or a resting one that slips, make an impact at t0; the resting
        ones (``|ġ_N|`` ≤ 1e-9 of the largest contact speed) are chosen by force signs.
        """
        m, n, o = self.model, self.model.n, self.o
        q, v = y[:n], y[n : 2 * n]
        g, WN, WT, _, _ = m.contacts(q, v)
        touch = [int(j) for j in np.flatnonzero(np.abs(g) <= o["gap_tol"])]
        gn, gt = WN[:, touch].T @ v, WT[:, touch].T @ v
        vtol = 1e-9 * max(np.abs(gn).max(initial=0.0), np.abs(gt).max(initial=0.0))
        rest = tuple(j for j, x in zip(touch, gn) if abs(x) <= vtol)
        closing = [j for j, x in zip(touch, gn) if x < -vtol]
        slip = any(abs(x) > vtol for j, x in zip(touch, gt) if j in rest)
        self.record(np.array([t]), y[:, None], rest)  # the given state
        self.release = self.event("release", t, y, rest, rest)
        if closing or slip:
            return self.impact(t, y, rest, closing)
        S = _select(m, t, q, v, rest, o["ftol"])
        self.release = self.event("release", t, y, rest, S)  # resting contacts may open
        return S

    def run(self, y, t, t_end, breakpoints):
        """Run to `t_end`: (outcome, message); a failure of the solvers ends the run with
        the outcome "failed" and an event "failed" at the last recorded state."""
        try:
            return self.loop(y, t, t_end, breakpoints)
        except (SolverError, LCPError, np.linalg.LinAlgError) as err:  # keep the history
            message = f"{type(err).__name__}: {err}"
            if self.out:
                ts, qs, vs, masks = self.out[-1][:4]
                S = _bits(int(masks[-1]))
                y_last = np.concatenate([qs[-1], vs[-1]])
                self.events.append(self.event("failed", ts[-1], y_last, S, S, detail=message))
            return "failed", message

    def loop(self, y, t, t_end, breakpoints):
        m, n, k = self.model, self.model.n, self.model.k
        names = [name for name, _ in getattr(m, "events", ())]
        outcome, message = "completed", f"reached t_end = {t_end:g} s"
        S = self.start(t, y)
        while t < t_end:
            if len(self.events) >= self.o["max_events"]:
                outcome = "max_events"
                message = f"stopped after {len(self.events)} events at t = {t:.6g} s"
                break
            self.project(S, y)
            ph = _Phase(m, S, y[:n], y[n : 2 * n])
            t_stop = next((b for b in breakpoints if b > t + 1e-12), t_end)
            if len(S) + len(ph.tk) >= n:
                t, y, hit = self.locked(ph, t, t_stop, y)
            else:
                t, y, idx = self.smooth(ph, t, t_stop, y)
                model_ev = [names[i - k] for i in idx if i >= k]
                if model_ev:
                    kind, outcome = model_stop(model_ev[0])
                    self.events.append(self.event(kind, t, y, S, S, detail=model_ev[0]))
                    message = f"{model_ev[0]} at t = {t:.6g} s"
                    break
                hit = [i for i in idx if i < k]
            if hit:
                S = self.transition(t, y, S, hit)
        return outcome, message

    def response(self, outcome, message, mu) -> ContactResponse:
        cat = [np.concatenate([o[i] for o in self.out]) for i in range(9)]
        demand = FrictionDemand(**self.fd)
        ledger = cat[4] - cat[4][0] - cat[5] + cat[6] + cat[7] + cat[8]
        checks, warnings = run_checks(
            cat[4], ledger, cat[5], self.proj_abs, demand, mu, self.o["e_floor"]
        )
        passed = all(c["passed"] for c in checks.values())
        if not passed:
            message = f"{message}; checks failed: " + "; ".join(warnings)
        return ContactResponse(
            t=cat[0],
            q=cat[1],
            v=cat[2],
            closed=cat[3].astype(int),
            energy=cat[4],
            ground_work=cat[5],
            damping=cat[6],
            impact_loss=cat[7],
            projection_loss=cat[8],
            events=tuple(self.events if self.release is None else [self.release, *self.events]),
            status=status_of(outcome, passed),
            message=message,
            outcome=outcome,
            checks=checks,
            warnings=warnings,
            friction=demand,
            rotation=self.rot,
            pivots=None if self.pivots is None else tuple(self.pivots),
        )


def simulate_contacts(
    model,
    q0,
    v0,
    t_end: float,
    eps_p,
    *,
    t0: float = 0.0,
    dt_out: float | None = None,
    rtol: float = 1e-10,
    atol: float = 1e-10,
    gap_tol: float = 1e-8,
    zeno_velocity: float = 0.0,
    max_events: int = 10_000,
    breakpoints=(),
    max_step: float = np.inf,
    locked_dt: float = 0.005,
    mu: float | None = None,
) -> ContactResponse:
    """Integrate a contact model phase by phase with Poisson impacts (paper 000).

    Parameters
    ----------
    model : object
        See the module docstring.
    q0, v0 : array_like, shape (n,)
        Initial state. Contacts with ``|g_N| ≤ gap_tol`` touch: a separating one
        is open, an approaching one impacts at t0, a resting one is closed or
        opened by the force signs (module docstring). No gap may be below
        −`gap_tol` (penetration).
    t_end : float
    eps_p : float or array_like, shape (k,)
        Poisson's coefficient per contact.
    dt_out : float, optional
        Sampling interval (default: segment ends only).
    rtol, atol : float
        `solve_ivp` tolerances (DOP853).
    gap_tol : float
        Gap below which a contact takes part in an impact or a phase (m).
    zeno_velocity : float
        An impact with an approach speed below this ends an accumulation of
        ever smaller impacts (bouncing, or rocking whose half-cycles shrink to
        zero): all contacts of the impact are kept closed, i.e. the velocity is
        projected onto their constraints: an event "rest" with ``detail``
        "zeno_rest" (m/s).
    max_events : int
        Event budget: a run that uses it up before `t_end` ends with the outcome
        "max_events" (status "failed").
    breakpoints : sequence of float
        Times where the excitation has a kink (integration restarts there).
    max_step : float
        Largest integration step of the smooth phases (s).
    locked_dt : float
        In a phase with no free coordinate (a block in full contact) the state
        does not move; the contact forces λ_N(t) are scanned on this grid (s)
        and a sign change is located by Brent's method.
    mu : float, optional
        Friction coefficient of the contacts. The sticking model needs
        ``|λ_T| ≤ μ λ_N``; a run whose friction demand exceeds it gets status
        "inaccurate" and a warning. The demand is reported either way
        (``ContactResponse.friction``); None (default) checks nothing.

    Returns
    -------
    ContactResponse
        ``status`` is `multimass.result.status_of` of the ``outcome``
        ("completed", "overturned", "max_events" → "failed", ...), or
        "inaccurate" when a check fails; ``checks`` and ``warnings`` say which
        (`multimass.engines._contact_checks`). A run the solvers cannot continue
        (integrator or LCP failure, no consistent set of closed contacts)
        returns its history with status and outcome "failed", an event
        "failed" and the cause in ``message``.

    Raises
    ------
    InputError
        An argument out of range, or an initial state that penetrates a contact.
    """
    n, k = model.n, model.k
    opts = dict(
        rtol=rtol,
        atol=atol,
        gap_tol=gap_tol,
        zeno_velocity=zeno_velocity,
        max_events=max_events,
        max_step=max_step,
        locked_dt=locked_dt,
        dt_out=dt_out,
    )
    eps, t0, t_end, opts = _options(k, eps_p, t0, t_end, opts)
    mu = validate_mu(mu)
    q, v = _state("q0", q0, n), _state("v0", v0, n)
    bps = sorted(_number("breakpoints", b) for b in breakpoints)
    g = model.contacts(q, v)[0]
    if g.min() < -opts["gap_tol"]:
        j = int(np.argmin(g))
        raise InputError(
            f"`q0` = {q.tolist()!r}: contact {j} penetrates by {-g[j]:.3g} m "
            f"(more than gap_tol = {opts['gap_tol']:.3g} m); start with every "
            "gap g_N ≥ 0"
        )
    h0 = np.abs(model.forces(t0, q, v)).max()
    opts["ftol"] = 1e-10 * max(h0, 1.0)
    opts["e_floor"] = h0 * opts["gap_tol"]  # energy resolved by the contact geometry
    drv = _Driver(model, eps, opts)
    outcome, message = drv.run(
        np.concatenate([q, v, [0.0, 0.0]]), t0, t_end, [b for b in bps if t0 < b < t_end]
    )
    return drv.response(outcome, message, mu)
