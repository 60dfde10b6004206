"""Free rocking of a rigid block on a beam by Moreau–Jean time stepping (paper 002).

>>> import math, nscd
>>> res = nscd.simulate("B6M", theta0=math.radians(11.268), dt=1e-4, t_end=0.6)
>>> round(res.first_peak_deg, 1)
7.8
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from multimass.errors import InputError

from .kernel import STAT_NAMES, STATUS, run_kernel
from .model import System, build_system, csr

__all__ = ["NSCDResult", "simulate", "run_system"]

#: at rest: |θ| stays below this fraction of |θ0| from rest_time_s to the end ...
REST_FRACTION = 0.01
#: ... for at least this long (s); otherwise the block is reported as still rocking
REST_HOLD = 0.1
#: smallest rest threshold (rad), used when θ0 = 0
REST_ANGLE_MIN = 1e-6
#: hysteresis on θ for counting half-cycles (rad)
CROSS_EPS = 1e-6
#: recorded samples of the time series (at most)
MAX_SAMPLES = 20000
#: room for half-cycle peaks and impacts
MAX_EVENTS = 100000


@dataclass(frozen=True)
class NSCDResult:
    """Outcome of one Moreau–Jean simulation.

    Angles follow the toolkit convention θ = −φ (θ > 0 rocks about the right
    corner); `peaks_deg` are magnitudes, as paper 002 reports them.

    Attributes
    ----------
    status : str
        "completed", "overturned", "fell_off_beam" or "failed".
    message : str
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
        below `rest_fraction` (default 1 %) of |θ0| (at least 0.1 s long
        before t_end); None if the block is still rocking.
    n_steps, max_gs_iterations, n_gs_cap_hits : int
        Steps taken; most Gauss–Seidel sweeps in one step; steps whose
        Gauss–Seidel stopped at the iteration cap without converging.
    n_slip_steps : int
        Steps with a sliding contact carrying load; max_slip_speed (m/s) their largest |U_t|.
    max_energy_increase_J : float
        Largest energy increase over one step (≤ 0 up to round-off for e = 0, θ = 1).
    wall_time_s, kernel_time_s, cost_per_step_us : float
    params : dict
    final_state : tuple of ndarray
        (q_k, q̇_k, q_e, q̇_e) at the last step: block [X, Y, φ] and beam (reduced).
    """

    status: str
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
    n_multi_contact_steps: int
    n_slip_steps: int
    max_slip_speed: float
    max_energy_increase_J: float
    energy_scale_J: float
    max_penetration_m: float
    wall_time_s: float
    kernel_time_s: float
    params: dict = field(default_factory=dict)
    final_state: tuple = ()

    @property
    def first_peak_deg(self) -> float | None:
        """Peak |θ| of the first half-cycle after the first impact (deg)."""
        return self.peaks_deg[0] if self.peaks_deg else None

    @property
    def cost_per_step_us(self) -> float:
        """Kernel time per step (µs)."""
        return 1e6 * self.kernel_time_s / max(self.n_steps, 1)

    def summary(self) -> dict:
        """JSON-ready scalars (no time series)."""
        return {
            "status": self.status, "message": self.message, **self.params,
            "first_peak_deg": self.first_peak_deg, "peaks_deg": list(self.peaks_deg),
            "peak_times_s": list(self.peak_times_s), "n_impacts": len(self.impact_times_s),
            "rest_time_s": self.rest_time_s, "n_steps": self.n_steps,
            "max_gs_iterations": self.max_gs_iterations, "n_gs_cap_hits": self.n_gs_cap_hits,
            "n_multi_contact_steps": self.n_multi_contact_steps,
            "n_slip_steps": self.n_slip_steps, "max_slip_speed_m_per_s": self.max_slip_speed,
            "max_energy_increase_J": self.max_energy_increase_J,
            "energy_scale_J": self.energy_scale_J, "max_penetration_m": self.max_penetration_m,
            "wall_time_s": self.wall_time_s, "kernel_time_s": self.kernel_time_s,
            "cost_per_step_us": self.cost_per_step_us,
        }


def _message(status: str, n_steps: int, n_cap: int, gs_max_iter: int, dt: float) -> str:
    msgs = {"completed": "reached t_end",
            "overturned": "the block overturned (|θ| > 90°)",
            "fell_off_beam": "the block left the beam",
            "failed": (f"the solution diverged at step {n_steps} (t = {n_steps * dt:g} s): "
                       "non-finite state or beam displacements beyond the span; "
                       "the θ-method is only conditionally stable for θ < 1/2: "
                       "use theta_method >= 0.5 or a smaller dt")}
    msg = msgs[status]
    if n_cap:
        msg += (f"; Gauss–Seidel hit its cap of {gs_max_iter} iterations in {n_cap} steps "
                "(raise gs_max_iter or loosen gs_tol)")
    return msg


def run_system(sys: System, t_end: float, *, gs_tol: float = 1e-8, gs_max_iter: int = 5000,
               record_every: int | None = None, rest_fraction: float = REST_FRACTION) -> NSCDResult:
    """Run the compiled time loop on an assembled `System` (see `simulate`)."""
    if not (isinstance(t_end, (int, float)) and math.isfinite(t_end) and t_end > 0):
        raise InputError(f"`t_end` = {t_end!r}: give a positive duration in s")
    if not (isinstance(gs_max_iter, int) and gs_max_iter >= 1):
        raise InputError(f"`gs_max_iter` = {gs_max_iter!r}: give an integer >= 1")
    if not (gs_tol > 0):
        raise InputError(f"`gs_tol` = {gs_tol!r}: give a positive relative tolerance, e.g. 1e-10")
    n_steps = int(round(t_end / sys.dt))
    if n_steps < 1:
        raise InputError(f"`dt` = {sys.dt!r} is longer than `t_end` = {t_end!r}; take dt < t_end")
    if not 0.0 < rest_fraction < 1.0:
        raise InputError(f"`rest_fraction` = {rest_fraction!r}: give a fraction of |θ0| in (0, 1), "
                         "e.g. 0.01")
    rest_angle = max(rest_fraction * abs(sys.theta0), REST_ANGLE_MIN)
    stride = record_every or max(1, -(-n_steps // MAX_SAMPLES))
    bm = sys.beam
    wall0 = time.perf_counter()
    out = run_kernel(sys.qk0, np.zeros(3), sys.qe0, np.zeros(bm.n_dof), sys.mass, sys.inertia,
                     sys.Fk, sys.verts, sys.Ainv, csr(bm.M), csr(bm.K), csr(bm.C),
                     bm.p_self, bm.edof, bm.x_nodes, bm.Le, bm.L, sys.dt, sys.theta_method,
                     sys.mu, sys.restitution, float(gs_tol), int(gs_max_iter), n_steps,
                     int(stride), rest_angle, np.inf, CROSS_EPS, sys.i_mid, MAX_EVENTS)
    kernel_time = time.perf_counter() - wall0
    code, last, series, peaks, impacts, stats = out[:6]
    st = dict(zip(STAT_NAMES, stats))
    status = STATUS[int(code)]
    t_rest = (int(st["last_moving_step"]) + 1) * sys.dt
    rest = t_rest if status == "completed" and n_steps * sys.dt - t_rest >= REST_HOLD else None
    post = peaks[1:] if len(peaks) and peaks[0, 0] == 0.0 else peaks   # drop the release
    return NSCDResult(
        status=status,
        message=_message(status, int(last), int(st["n_gs_cap_hits"]), gs_max_iter, sys.dt),
        t=series[:, 0].copy(), theta=-series[:, 1], theta_dot=-series[:, 2],
        X=series[:, 3].copy(), Y=series[:, 4].copy(), v_mid=series[:, 5].copy(),
        energy=series[:, 6].copy(), n_contacts=series[:, 7].astype(int),
        peaks_deg=tuple(float(math.degrees(p)) for p in post[:, 1]),
        peak_times_s=tuple(float(t) for t in post[:, 0]),
        impact_times_s=tuple(float(t) for t in impacts),
        rest_time_s=None if rest is None else float(rest),
        n_steps=int(last), max_gs_iterations=int(st["max_gs_iterations"]),
        n_gs_cap_hits=int(st["n_gs_cap_hits"]),
        n_multi_contact_steps=int(st["n_multi_contact_steps"]),
        n_slip_steps=int(st["n_slip_steps"]), max_slip_speed=float(st["max_slip_speed"]),
        max_energy_increase_J=float(st["max_energy_increase"]),
        energy_scale_J=float(st["energy_scale"]),
        max_penetration_m=float(st["max_penetration"]),
        wall_time_s=time.perf_counter() - wall0, kernel_time_s=kernel_time,
        params={"block": sys.block.name, "beam": sys.beam_spec.name, "E_Pa": bm.E,
                "n_elements": bm.n_elements, "dt_s": sys.dt, "t_end_s": n_steps * sys.dt,
                "theta_method": sys.theta_method, "mu": sys.mu, "restitution": sys.restitution,
                "theta0_deg": math.degrees(sys.theta0), "x_centre_m": sys.x_centre,
                "gs_tol": gs_tol, "gs_max_iter": gs_max_iter, "record_every": int(stride),
                "rest_fraction": rest_fraction},
        final_state=tuple(out[6:10]))


def simulate(block, beam="beam_mudric2024", *, theta0: float, dt: float, t_end: float,
             E: float | None = None, n_elements: int | None = None, theta_method: float = 1.0,
             mu: float | None = None, restitution: float = 0.0, x_centre: float | None = None,
             gs_tol: float = 1e-8, gs_max_iter: int = 5000,
             record_every: int | None = None, rest_fraction: float = REST_FRACTION) -> NSCDResult:
    """Free rocking of a rigid block released at rest on a simply supported beam.

    Moreau–Jean event-capturing time stepping (paper 002, Sections 3–4):
    θ-method (Eqs 21–34), velocity Signorini conditions with Newton
    restitution and Coulomb friction (Eqs 35–38) at the block's vertices,
    contact points on the deformed beam (Eqs 59–63), Gauss–Seidel over
    simultaneous contacts (Eq 44).

    Parameters
    ----------
    block : str, path or BlockSpecimen
        E.g. "B6M".
    beam : str, path or BeamSpecimen
        Default: paper 002's beam (rigid base, E = 1e24 Pa).
    theta0 : float
        Release angle (rad); > 0 rests on the right corner.
    dt, t_end : float
        Time step and duration (s).
    E : float, optional
        Young's modulus (Pa), overriding the beam's (see `flexible_modulus`).
    n_elements : int, optional
        Number of elements (>= 3), overriding the beam's default.
    theta_method : float
        θ of the θ-method in [0, 1] (paper 002: 1, backward Euler).
    mu, restitution : float
        Friction coefficient (default: the beam's) and Newton's e (default 0).
    x_centre : float, optional
        Abscissa of the block's centre when upright (default: midspan).
    gs_tol, gs_max_iter : float, int
        Gauss–Seidel tolerance (relative change of the impulses) and cap.
    record_every : int, optional
        Record the series every this many steps (default: at most 20 000 samples).
    rest_fraction : float
        The block is at rest once |θ| stays below this fraction of |θ0|.

    Returns
    -------
    NSCDResult

    Raises
    ------
    InputError
        For bad input (see `nscd.model.build_system`).
    """
    sys = build_system(block, beam, theta0=theta0, dt=dt, E=E, n_elements=n_elements,
                       theta_method=theta_method, mu=mu, restitution=restitution,
                       x_centre=x_centre)
    return run_system(sys, t_end, gs_tol=gs_tol, gs_max_iter=gs_max_iter,
                      record_every=record_every, rest_fraction=rest_fraction)
