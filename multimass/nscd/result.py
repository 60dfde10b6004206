"""The result of a Moreau–Jean run and the accuracy checks that decide its status.

A run ends with a physical *outcome* ("completed", "overturned", "fell_off_beam"
or "failed": the solution diverged). Its *status* is that outcome unless an
accuracy check failed, then "inaccurate" (the run-status contract of
`multimass.checks`); `warnings` says why and what to do, `checks` holds each
check's value, limit and verdict:

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

__all__ = [
    "NSCDResult",
    "accuracy_checks",
    "log_warnings",
    "outcome_message",
    "json_ready",
    "ENERGY_GAIN_TOL",
    "ENERGY_GAIN_TOL_DISSIPATIVE",
    "GS_RESIDUAL_TOL",
    "MAX_EVENTS",
]

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


@dataclass(frozen=True)
class NSCDResult:
    """Outcome of one Moreau–Jean simulation.

    Angles follow the toolkit convention θ = −φ (θ > 0 rocks about the right
    corner); `peaks_deg` are magnitudes, as paper 002 reports them.

    Attributes
    ----------
    status : str
        The physical outcome, or "inaccurate" when the run finished but an
        accuracy check failed: "completed", "overturned", "fell_off_beam",
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
    t, theta, theta_dot, X, Y, v_mid, energy, n_contacts : ndarray
        Recorded series (every `record_every` steps): time (s), block angle
        (rad), angular velocity (rad/s), centre of gravity (m), beam deflection
        at the node nearest midspan (m), total energy (J), active contacts.
    peaks_deg, peak_times_s : tuple of float
        Absolute peak angle (deg) and its time of each half-cycle after the
        first impact (the release at `theta0_deg` is not listed).
    impact_times_s : tuple of float
        Times at which a vertex comes into contact approaching faster than
        10 g Δt. They include the small second touch of a corner that the
        scheme stopped just above the beam (contact is activated on the
        predicted overlap), so they over-count the physical impacts.
    rest_time_s : float or None
        Start of the final period during which the rocking amplitude stays
        below `rest_fraction` (default 1 %) of ``|θ0|`` (at least 0.1 s long
        before t_end); None if the block is still rocking.
    n_steps, max_gs_iterations, n_gs_cap_hits : int
        Steps taken; most Gauss–Seidel sweeps in one step; steps whose
        Gauss–Seidel stopped at the iteration cap without converging.
    max_gs_residual : float
        Largest last-sweep change of the impulses (relative) among the steps
        that hit the cap; 0 when none did.
    n_slip_steps : int
        Steps with a sliding contact carrying load; max_slip_speed (m/s) their largest ``|U_t|``.
    max_energy_increase_J : float
        Largest energy increase over one step (≤ 0 up to round-off for e = 0, θ = 1).
    wall_time_s, kernel_time_s, cost_per_step_us : float
    estimated_s : float
        The wall time estimated before the run (`nscd.cost`).
    params : dict
    final_state : tuple of ndarray
        (q_k, q̇_k, q_e, q̇_e) at the last step: block [X, Y, φ] and beam (reduced).
    """

    status: str
    outcome: str
    message: str
    t: np.ndarray
    theta: np.ndarray
    theta_dot: np.ndarray
    X: np.ndarray
    Y: np.ndarray
    v_mid: np.ndarray
    energy: np.ndarray
    n_contacts: np.ndarray
    peaks_deg: tuple[float, ...]
    peak_times_s: tuple[float, ...]
    impact_times_s: tuple[float, ...]
    rest_time_s: float | None
    n_steps: int
    max_gs_iterations: int
    n_gs_cap_hits: int
    max_gs_residual: float
    n_multi_contact_steps: int
    n_slip_steps: int
    max_slip_speed: float
    max_energy_increase_J: float
    energy_scale_J: float
    max_penetration_m: float
    wall_time_s: float
    kernel_time_s: float
    estimated_s: float = math.nan
    warnings: tuple[str, ...] = ()
    checks: dict = field(default_factory=dict)
    params: dict = field(default_factory=dict)
    final_state: tuple = ()

    @property
    def first_peak_deg(self) -> float | None:
        """Peak ``|θ|`` of the first half-cycle after the first impact (deg)."""
        return self.peaks_deg[0] if self.peaks_deg else None

    @property
    def cost_per_step_us(self) -> float:
        """Kernel time per step (µs)."""
        return 1e6 * self.kernel_time_s / max(self.n_steps, 1)

    def summary(self) -> dict:
        """JSON-ready scalars (no time series); a non-finite number is given as None."""
        return json_ready(
            {
                "status": self.status,
                "outcome": self.outcome,
                "message": self.message,
                "warnings": list(self.warnings),
                "checks": self.checks,
                **self.params,
                "first_peak_deg": self.first_peak_deg,
                "peaks_deg": list(self.peaks_deg),
                "peak_times_s": list(self.peak_times_s),
                "n_impacts": len(self.impact_times_s),
                "rest_time_s": self.rest_time_s,
                "n_steps": self.n_steps,
                "max_gs_iterations": self.max_gs_iterations,
                "n_gs_cap_hits": self.n_gs_cap_hits,
                "max_gs_residual": self.max_gs_residual,
                "n_multi_contact_steps": self.n_multi_contact_steps,
                "n_slip_steps": self.n_slip_steps,
                "max_slip_speed_m_per_s": self.max_slip_speed,
                "max_energy_increase_J": self.max_energy_increase_J,
                "energy_scale_J": self.energy_scale_J,
                "max_penetration_m": self.max_penetration_m,
                "wall_time_s": self.wall_time_s,
                "kernel_time_s": self.kernel_time_s,
                "estimated_s": self.estimated_s,
                "cost_per_step_us": self.cost_per_step_us,
            }
        )


def json_ready(x):
    """`x` with every non-finite float replaced by None (JSON has no NaN or inf)."""
    if isinstance(x, dict):
        return {k: json_ready(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [json_ready(v) for v in x]
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(x) else None
    if isinstance(x, np.integer):
        return int(x)
    return x


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
