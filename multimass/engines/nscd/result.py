"""The result of a Moreau–Jean run and the accuracy checks that decide its status.

`NSCDResult` follows the toolkit's one result contract (`multimass.result`).
A run ends with a physical *outcome* ("completed", "overturned", "fell_off_beam"
or "failed": the solution diverged). Its *status* is that outcome's
(`multimass.result.OUTCOMES`: a block that fell off the beam is lost like an
overturned one, status "overturned") unless an accuracy check failed, then
"inaccurate" (the run-status contract of `multimass.checks`); `warnings` says why
and what to do, `checks` holds each check's value, limit and verdict:

* ``energy_gain_per_step`` — the largest energy increase over one step,
  relative to the energy scale ``|E₀| + m g L``. Free rocking on a damped beam has
  no energy input. With θ = 1 and e = 0 each step dissipates exactly,
  ``ΔE = −½|Δv|²_M − ½|Δq|²_K − Δt vᵀCv + U·P ≤ 0`` (U_n P_n = 0, U_t P_t ≤ 0 once
  the contact problem is solved), so any gain above round-off (limit 1e-9;
  ≤ 1e-13 measured) means the contact impulses are wrong; otherwise (θ < 1 or
  e > 0, where the scheme may gain a little: ≤ 4e-4 measured) the limit is
  1e-3, the energy drift `multimass bench` flags.
* ``gauss_seidel_residual`` — among the steps whose Gauss–Seidel stopped at
  `gs_max_iter` sweeps without meeting `gs_tol`, the largest change of the
  impulses in the last sweep, relative to their size (0 when the cap was never
  hit; limit `GS_RESIDUAL_TOL` = 1e-4). Slowly converging steps are common on
  stiff flexible beams and harmless once the impulses have settled to 1e-6.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from multimass.result import Event, Result

__all__ = [
    "NSCDResult",
    "accuracy_checks",
    "log_warnings",
    "outcome_message",
    "run_events",
    "SERIES_COLUMNS",
    "ENERGY_GAIN_TOL",
    "ENERGY_GAIN_TOL_DISSIPATIVE",
    "GS_RESIDUAL_TOL",
    "MAX_EVENTS",
]

#: The columns of `NSCDResult.series`.
SERIES_COLUMNS = ("t", "theta", "thetadot", "X", "Y", "v_mid", "energy", "n_contacts")
#: room for half-cycle peaks and impacts
MAX_EVENTS = 100000
#: largest energy gain over one step, share of the energy scale (θ < 1 or e > 0)
ENERGY_GAIN_TOL = 1e-3
#: the same for θ = 1 and e = 0, where every step dissipates (module docstring)
ENERGY_GAIN_TOL_DISSIPATIVE = 1e-9
#: Largest last-sweep relative change of the impulses accepted at the Gauss–Seidel cap.
#: Measured (B6M, E = Ē·10² at Δt = 1e-4 s, E = 10 Ē with μ = 0.02, E = Ē at Δt = 1e-5 s,
#: against runs converged to 1e-12): residuals ≤ 2.1e-4 moved θ(t) by ≤ 4.4e-6°, residuals
#: of 7.5e-3 to 0.32 by 1.7e-3° to 5.7e-3°, a quarter of the 0.02° first-peak tolerance of
#: the convergence studies.
GS_RESIDUAL_TOL = 1e-4


@dataclass(frozen=True, eq=False)
class NSCDResult(Result):
    """Outcome of one Moreau–Jean simulation, on the toolkit's result contract
    (`multimass.result.Result`, engine "nscd").

    Angles follow the toolkit convention θ = −φ (θ > 0 rocks about the right
    corner) and are in radians; degrees only in `summary`'s keys ending ``_deg``
    (paper 002 reports its peaks in degrees: ``math.degrees(res.first_peak)``).

    Attributes
    ----------
    status : str
        The physical outcome's status (`multimass.result.OUTCOMES`), or
        "inaccurate" when the run finished but an accuracy check failed:
        "completed", "overturned" (also when the block fell off the beam),
        "inaccurate" or "failed" (the solution diverged).
    outcome : str
        The physical end of the run whatever the checks say: "completed",
        "overturned", "fell_off_beam" or "failed".
    message : str
    warnings : tuple of str
        One line per failed check or truncated log: what, value, limit, what to do.
    checks : dict
        Check name -> {"value", "limit", "passed"} (see the module docstring);
        empty for a failed run, which is not judged.
    t, theta, thetadot, X, Y, v_mid, energy, n_contacts : ndarray
        Recorded series (every `record_every` steps): time (s), block angle
        (rad), angular velocity (rad/s), centre of gravity (m), beam deflection
        at the node nearest midspan (m), total energy (J), active contacts.
        `series` gives them as one DataFrame.
    peaks, peak_times : ndarray
        Absolute peak ``|θ|`` (rad) of each half-cycle in order, and its time (s),
        the unfinished last one included. The first is the release half-cycle:
        ``|θ0|`` at t = 0 (larger, later, only if the block tipped further before
        falling back); `first_peak` is the next one, the first after an impact.
    events : tuple of Event
        The release; one "impact" per time a vertex came into contact
        approaching faster than 10 g Δt; and, when the run ended so, a final
        "overturn", "fell_off_beam" or "failed". The impacts include the small
        second touch of a corner that the scheme stopped just above the beam
        (contact is activated on the predicted overlap), so they over-count the
        physical impacts. An impact's phases are the signs of θ at the recorded
        samples that bracket it (its θ̇⁻, θ̇⁺, θ and energy change come from them
        too: the impact step's own values when every step is recorded,
        ``record_every=1``, else up to `record_every` steps away; the energy
        change then includes the beam's damping between the samples), NaN
        where no sample follows.
    rest_time : float or None
        Start (s) of the final period during which the rocking amplitude stays
        below `rest_fraction` (default 1 %) of ``|θ0|`` (at least 0.1 s long
        before t_end); None if the block is still rocking.
    n_steps, max_gs_iterations, n_gs_cap_hits : int
        Steps taken; most Gauss–Seidel sweeps in one step; steps whose
        Gauss–Seidel stopped at the iteration cap without converging.
    max_gs_residual : float
        Largest last-sweep change of the impulses (relative) among the steps
        that hit the cap; 0 when none did.
    n_multi_contact_steps : int
        Steps with more than one active contact.
    n_slip_steps : int
        Steps with a sliding contact carrying load; max_slip_speed (m/s) their largest ``|U_t|``.
    max_energy_increase : float
        Largest energy increase over one step (J; ≤ 0 up to round-off for e = 0, θ = 1).
    energy_scale : float
        ``|E₀| + m g L`` (J), the scale of the energy check.
    max_penetration : float
        Largest overlap of a vertex into the beam (m).
    wall_time_s, kernel_time_s : float
        Wall time of the whole run and of the compiled loop (s).
    estimated_s : float
        The wall time estimated before the run (s, `nscd.cost`).
    params : dict
        The run's arguments, named as `nscd.simulate`'s (SI units, ``theta0`` in
        rad): block, beam, E, n_elements, dt, t_end, theta_method, mu,
        restitution, theta0, x_centre, gs_tol, gs_max_iter, record_every,
        rest_fraction.
    final_state : tuple of ndarray
        (q_k, q̇_k, q_e, q̇_e) at the last step: block [X, Y, φ] and beam (reduced).

    Notes
    -----
    `ledger` holds ``t`` and ``energy`` only: Moreau–Jean's steps dissipate
    through the impulses, the beam's damping and the θ-method together, and the
    engine does not separate them into damping and impact losses.
    """

    engine = "nscd"

    status: str
    outcome: str
    message: str
    t: np.ndarray
    theta: np.ndarray
    thetadot: np.ndarray
    X: np.ndarray
    Y: np.ndarray
    v_mid: np.ndarray
    energy: np.ndarray
    n_contacts: np.ndarray
    peaks: np.ndarray
    peak_times: np.ndarray
    events: tuple[Event, ...]
    rest_time: float | None
    n_steps: int
    max_gs_iterations: int
    n_gs_cap_hits: int
    max_gs_residual: float
    n_multi_contact_steps: int
    n_slip_steps: int
    max_slip_speed: float
    max_energy_increase: float
    energy_scale: float
    max_penetration: float
    wall_time_s: float
    kernel_time_s: float
    estimated_s: float = math.nan
    warnings: tuple[str, ...] = ()
    checks: dict = field(default_factory=dict)
    params: dict = field(default_factory=dict)
    final_state: tuple = ()

    @property
    def first_peak(self) -> float | None:
        """Peak ``|θ|`` (rad) of the first half-cycle after the first impact, ``peaks[1]``;
        None if the run ended before one began."""
        return float(self.peaks[1]) if len(self.peaks) > 1 else None

    @property
    def impact_times(self) -> np.ndarray:
        """Times of the "impact" events (s)."""
        return np.array([e.time for e in self.events if e.kind == "impact"], dtype=float)

    @property
    def cost_per_step_us(self) -> float:
        """Kernel time per step (µs)."""
        return 1e6 * self.kernel_time_s / max(self.n_steps, 1)

    @property
    def series(self) -> pd.DataFrame:
        """The recorded series as a table: ``t``, ``theta``, ``thetadot``, ``X``, ``Y``,
        ``v_mid``, ``energy``, ``n_contacts`` (units as in the class docstring)."""
        return pd.DataFrame({c: getattr(self, c) for c in SERIES_COLUMNS})

    @property
    def ledger(self) -> pd.DataFrame:
        """The energy ledger at the samples: ``t`` and the total ``energy`` (J) only (see
        Notes)."""
        return pd.DataFrame({"t": self.t, "energy": self.energy})

    def _summary_extra(self) -> dict:
        fp = self.first_peak
        params = {}
        for k, v in self.params.items():  # θ0 in degrees beside its radians, for reading
            params |= {k: v, "theta0_deg": math.degrees(v)} if k == "theta0" else {k: v}
        return {
            **params,
            "first_peak": fp,
            "first_peak_deg": None if fp is None else math.degrees(fp),
            "rest_time": self.rest_time,
            "n_steps": self.n_steps,
            "max_gs_iterations": self.max_gs_iterations,
            "n_gs_cap_hits": self.n_gs_cap_hits,
            "max_gs_residual": self.max_gs_residual,
            "n_multi_contact_steps": self.n_multi_contact_steps,
            "n_slip_steps": self.n_slip_steps,
            "max_slip_speed": self.max_slip_speed,
            "max_energy_increase": self.max_energy_increase,
            "energy_scale": self.energy_scale,
            "max_penetration": self.max_penetration,
            "wall_time_s": self.wall_time_s,
            "kernel_time_s": self.kernel_time_s,
            "estimated_s": self.estimated_s,
            "cost_per_step_us": self.cost_per_step_us,
        }


def _sign(x: float) -> int:
    return 1 if x > 0.0 else (-1 if x < 0.0 else 0)


def run_events(
    outcome: str,
    theta0: float,
    impacts,
    t,
    theta,
    thetadot,
    energy,
    t_last: float,
    final: tuple[float, float] | None = None,
    detail: str = "",
) -> tuple[Event, ...]:
    """The event log of a run (see `NSCDResult.events`).

    Parameters
    ----------
    outcome : str
        How the run ended (`kernel.STATUS`).
    theta0 : float
        Release angle (rad).
    impacts : array_like
        The kernel's impact times (s).
    t, theta, thetadot, energy : ndarray
        The recorded series (s, rad, rad/s, J).
    t_last : float
        Time of the last step (s): that of a final overturn, fall or failure.
    final : (float, float), optional
        θ and θ̇ at the last step (rad, rad/s) for an overturn or a fall.
    detail : str
        Detail of a final "failed" event (the run's message).
    """
    side = _sign(theta0)
    events = [Event("release", 0.0, side, side, theta=float(theta0))]
    after = np.searchsorted(t, impacts, side="left")  # first sample at or after each impact
    for ti, k in zip(impacts, after):
        b = max(int(k) - 1, 0)
        if k < len(t):
            a = int(k)
            ph_after, th_a, thd_a, e_a = _sign(theta[a]), theta[a], thetadot[a], energy[a]
        else:  # no sample after it (the run stopped between records)
            ph_after, th_a, thd_a, e_a = None, math.nan, math.nan, math.nan
        events.append(
            Event(
                "impact",
                float(ti),
                _sign(theta[b]),
                ph_after,
                theta=float(th_a),
                thetadot_minus=float(thetadot[b]),
                thetadot_plus=float(thd_a),
                energy_change=float(e_a - energy[b]),
                detail="vertex into contact",
            )
        )
    if outcome in ("overturned", "fell_off_beam"):
        th, thd = final if final is not None else (math.nan, math.nan)
        kind, ph = ("overturn", _sign(th)) if outcome == "overturned" else ("fell_off_beam", None)
        events.append(
            Event(kind, float(t_last), ph, ph, theta=th, thetadot_minus=thd, thetadot_plus=thd)
        )
    elif outcome == "failed":
        ph = _sign(theta[-1]) if len(theta) else None
        events.append(Event("failed", float(t_last), ph, ph, detail=detail))
    return tuple(events)


def outcome_message(outcome: str, step: int, dt: float, theta_method: float) -> str:
    """What the kernel's outcome means, and for a diverged run what to change."""
    if outcome != "failed":
        return {
            "completed": "reached t_end",
            "overturned": "the block overturned (|θ| > 90°)",
            "fell_off_beam": "the block left the beam",
        }[outcome]
    msg = (
        f"the solution diverged at step {step} (t = {step * dt:g} s): non-finite state or "
        "beam displacements beyond the span; "
    )
    if theta_method < 0.5:
        return msg + (
            "the θ-method is only conditionally stable for θ < 1/2: use "
            "theta_method >= 0.5 or a smaller dt"
        )
    return msg + "use a smaller dt, or check the beam and block data"


def accuracy_checks(sys, st: dict, gs_max_iter: int, gs_tol: float) -> tuple[dict, list[str]]:
    """The accuracy checks of a run (module docstring) and the warnings of those that fail."""
    dissipative = sys.theta_method == 1.0 and sys.restitution == 0.0
    limit = ENERGY_GAIN_TOL_DISSIPATIVE if dissipative else ENERGY_GAIN_TOL
    gain = float(st["max_energy_increase"] / st["energy_scale"])
    gain = gain if math.isfinite(gain) else math.inf
    residual, hits = float(st["max_gs_residual"]), int(st["n_gs_cap_hits"])
    checks = {
        "energy_gain_per_step": {"value": gain, "limit": limit, "passed": gain <= limit},
        "gauss_seidel_residual": {
            "value": residual,
            "limit": GS_RESIDUAL_TOL,
            "passed": residual <= GS_RESIDUAL_TOL,
        },
    }
    warnings = []
    if not checks["energy_gain_per_step"]["passed"]:
        why = (
            "θ = 1 and e = 0 dissipate at every step, so the contact impulses are wrong: "
            "tighten gs_tol or raise gs_max_iter"
            if dissipative
            else "not physical for free rocking: reduce dt, or use theta_method = 1 and "
            "restitution = 0"
        )
        warnings.append(
            f"energy gain over one step {gain:.3g} of the energy scale "
            f"{st['energy_scale']:.3g} J (limit {limit:g}): {why}"
        )
    if not checks["gauss_seidel_residual"]["passed"]:
        warnings.append(
            f"Gauss–Seidel stopped at its cap of {gs_max_iter} iterations in {hits} "
            f"steps with the impulses still changing by {residual:.3g} of their size "
            f"per sweep (limit {GS_RESIDUAL_TOL:g}): the contact impulses of those "
            "steps are not converged; raise gs_max_iter (--gs-max-iter)"
        )
    return checks, warnings


def log_warnings(peaks, impacts) -> list[str]:
    """A warning for each event log that filled up (later events are not listed)."""
    out = []
    for what, log in (("half-cycle peaks", peaks), ("impacts", impacts)):
        if len(log) >= MAX_EVENTS:
            last = log[-1, 0] if log.ndim == 2 else log[-1]
            out.append(
                f"the log of {what} is full ({MAX_EVENTS} entries, the last at "
                f"t = {last:.4g} s): later ones are not listed; shorten t_end"
            )
    return out
