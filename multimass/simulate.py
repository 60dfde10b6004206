"""Nonlinear time histories: `simulate` drives solve_ivp phase by phase (paper 001, Section 2).

Phases and transitions (paper 001, Sections 2.2–2.4):

* full contact (Eq 3) → rocking when uplift conditions hold (Eq 8): θ̇⁺ = 0,
  u̇⁺ = u̇⁻;
* rocking about either pivot (Eqs 4–5) until θ = 0, where Eq 9 chooses a new
  half-cycle (classical impact, Eq 11; Dirac-delta, Eq 12) or full contact
  (Eq 10);
* while rocking, the Dirac-delta force (Eqs 14–16) switches on and off at
  events (Eq 17), so no solver step straddles a switch;
* overturning ends the run; a chattering guard forces full contact after
  `chatter_count` transitions within `chatter_window` seconds.

Every switch is a terminal event of `scipy.integrate.solve_ivp` whose
direction is set per phase; event functions are held quiet for 1 ns after a
restart so a phase never re-triggers the event that started it.

Default solver options and why: DOP853 (explicit 8th order) with rtol = 1e-8,
atol = 1e-10 and max_step = 5 ms. The bundled columns have modes up to ~530 Hz
with ζ up to 0.19, which an explicit method resolves at about the step its
accuracy needs anyway; 5 ms resolves records sampled at 20 ms and keeps the
uplift and activation checks frequent. At these tolerances the energy ledger of
the bundled specimens closes to better than 1e-5 (tests/multimass/test_energy.py).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy.integrate._ivp.ivp import METHODS as _IVP_METHODS

from impact_models import impact_model

from ._run import QUIET_DELAY, _Run
from .errors import InputError
from .response import Response
from .structure import Structure, from_specimen

__all__ = ["simulate", "simulate_outcome", "Outcome", "DEFAULTS"]

#: Default options (see the module docstring for why).
DEFAULTS = dict(method="DOP853", rtol=1e-8, atol=1e-10, max_step=5e-3, theta_dot_min=0.01,
                output_dt=1e-3, chatter_window=5e-3, chatter_count=20)



def _positive(name, value, allow_inf=False):
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"`{name}` = {value!r}: expected a number") from None
    if not (v > 0.0 and (math.isfinite(v) or allow_inf)):
        raise InputError(f"`{name}` = {value!r}: must be a positive finite number")
    return v


def _initial_state(st: Structure, excitation) -> tuple[int, np.ndarray]:
    n = st.n
    y = np.zeros(2 * n + 5)
    theta0 = float(getattr(excitation, "theta0", 0.0) or 0.0)
    if not math.isfinite(theta0):
        raise InputError(f"`theta0` = {theta0!r}: must be finite")
    if abs(theta0) >= st.alpha_cg:
        raise InputError(f"`theta0` = {theta0!r} rad is beyond the slenderness α_cg = "
                         f"{st.alpha_cg:.4f} rad of {st.name!r}: the structure would overturn; "
                         "release it from a smaller angle")
    if hasattr(excitation, "initial_displacement"):
        y[:n] = excitation.initial_displacement(st)
    y[n] = theta0
    return (int(np.sign(theta0)), y)


def _check_excitation(excitation):
    if excitation is None or not callable(excitation):
        raise InputError(f"`excitation` = {excitation!r}: give an excitation, e.g. "
                         "FreeRelease(theta0=0.1) or SineWave(amplitude=a0, omega=omega)")
    duration = float(getattr(excitation, "duration", math.inf))
    acc = getattr(excitation, "acceleration", excitation)
    return acc, duration, tuple(float(b) for b in getattr(excitation, "breakpoints", ()))


def simulate(structure, excitation, impact="DD2", t_end: float = 10.0, *, restitution=None,
             k: float | None = None, C_p: float | None = None, eps_p: float | None = None,
             seed: int | None = None,
             method=DEFAULTS["method"], rtol: float = DEFAULTS["rtol"],
             atol: float = DEFAULTS["atol"], max_step: float = DEFAULTS["max_step"],
             theta_dot_min: float = DEFAULTS["theta_dot_min"],
             output_dt: float | None = DEFAULTS["output_dt"],
             overturn_angle: float = math.pi / 2,
             chatter_window: float = DEFAULTS["chatter_window"],
             chatter_count: int = DEFAULTS["chatter_count"],
             stop_at_rest: bool = True, stop_when_safe: bool = False,
             integrator: str = "solve_ivp", dt: float = 1e-3,
             backend: str = "scipy") -> Response:
    """Simulate the nonlinear response of a rocking structure (paper 001, Section 2).

    Parameters
    ----------
    structure : Structure, specimen or str
        A structure (`multimass.column`, `multimass.rigid_block`) or a specimen
        name / TOML path.
    excitation : Excitation
        A callable ü_g(t) in m/s² with ``duration`` and ``breakpoints``, e.g.
        `FreeRelease`, `SineWave`, `CosinePulse`, a `Record`.
    impact : str or ImpactModel
        "CIM", "DD1" … "DD5" (paper 001, Table 2), "DD", "LCP" (Poisson's law,
        paper 000: the elastic velocities change at impact too), or a model object.
    t_end : float
        End time (s).
    restitution, k, C_p : optional
        Override Table 2's restitution ("mean", "random", "housner",
        "modified", a number, ...), k of η_M, and C_p.
    eps_p : float, optional
        Poisson's ε_P of impact="LCP" (default 0; the engine has no flight
        phase, so a predicted bounce ends the run as "failed").
    seed : int, optional
        Seed of the random restitution (DD5): same seed, same response.
    method, rtol, atol, max_step :
        solve_ivp options (defaults in `DEFAULTS`).
    theta_dot_min : float
        θ̇_min of paper 001, Eqs 9 and 16 (rad/s).
    output_dt : float or None
        Sampling step of the recorded series (s); None records nothing but
        peaks, events and the ledger at transitions (fast sweeps).
    overturn_angle : float
        |θ| at which the structure has overturned (rad; default π/2).
    chatter_window, chatter_count :
        The chattering guard: `chatter_count` transitions within
        `chatter_window` seconds force full contact for one window.
    stop_at_rest : bool
        For a rigid block, stop once the excitation is over and the block
        rests in full contact (nothing can move it again).
    stop_when_safe : bool
        For a rigid block, also stop (event "rest") once the excitation is over
        and the block, with |θ| < α_cg and less energy than it needs to reach
        θ = α_cg, can never overturn in free rocking — the early stop that
        makes overturning maps cheap. Checked at the end of the excitation and
        at every impact after it.
    integrator : {"solve_ivp", "newmark"}
        "newmark": paper 004's Newmark trapezoidal rule with Newton–Raphson
        and exact impact location (rigid blocks, classical impacts only);
        `method`, `rtol`, `atol` and `max_step` then do not apply.
    dt : float
        Step of the Newmark integrator (s).
    backend : {"scipy", "compiled"}
        "scipy" (the reference): one solve_ivp call per phase segment.
        "compiled": the same explicit Runge–Kutta steps, events and output in
        numba kernels (`multimass.fast`), for RK23/RK45/DOP853 and the known
        excitations; compiled once per machine (disk cache), never timed in
        ``wall_time_s``.

    Returns
    -------
    Response
        With ``status`` "completed", "overturned" or "failed" (then
        ``message`` carries solve_ivp's message).

    Raises
    ------
    InputError
        For invalid arguments (named in the message).
    """
    prepared = _prepare(structure, excitation, impact, t_end, restitution=restitution, k=k,
                        C_p=C_p, eps_p=eps_p, seed=seed, method=method, rtol=rtol, atol=atol,
                        max_step=max_step, theta_dot_min=theta_dot_min, output_dt=output_dt,
                        overturn_angle=overturn_angle, chatter_window=chatter_window,
                        chatter_count=chatter_count, stop_at_rest=stop_at_rest,
                        stop_when_safe=stop_when_safe, integrator=integrator, dt=dt,
                        backend=backend)
    if not isinstance(prepared, _Run):            # the Newmark integrator ran to the end
        return prepared
    run = prepared
    wall = time.perf_counter()
    run.loop()
    wall = time.perf_counter() - wall
    return run.recorder.response(run.st.name, run.status, run.message, run.events, wall,
                                 run.options, run.n_rhs, run.t_end)


@dataclass(frozen=True)
class Outcome:
    """What `simulate_outcome` returns: the run without its series and ledger.

    Attributes
    ----------
    status, message : str
    events : list of Event
    peaks : ndarray
        Absolute peak |θ| of each half-cycle (rad).
    n_rhs : int
    wall_time_s : float
    """

    status: str
    message: str
    events: list
    peaks: np.ndarray
    n_rhs: int
    wall_time_s: float

    @property
    def theta_max(self) -> float:
        return float(self.peaks.max()) if self.peaks.size else 0.0

    @property
    def n_impacts(self) -> int:
        return sum(e.kind == "impact" for e in self.events)


def simulate_outcome(structure, excitation, impact="DD2", t_end: float = 10.0, **options) -> Outcome:
    """`simulate` without the time series and the energy ledger, for sweeps of many runs.

    Takes the same arguments as `simulate` (``output_dt`` is ignored: nothing
    is sampled) and returns an `Outcome`: status, events and peaks — what an
    overturning map or a spectrum needs, without building a DataFrame.
    """
    options["output_dt"] = None
    prepared = _prepare(structure, excitation, impact, t_end, **options)
    if not isinstance(prepared, _Run):
        r = prepared
        return Outcome(r.status, r.message, r.events, r.peaks, r.n_rhs, r.wall_time_s)
    run = prepared
    wall = time.perf_counter()
    run.loop()
    wall = time.perf_counter() - wall
    return Outcome(run.status, run.message, run.events, np.array(run.recorder.peaks), run.n_rhs, wall)


def _prepare(structure, excitation, impact, t_end, *, restitution=None, k=None, C_p=None,
             eps_p=None, seed=None, method=DEFAULTS["method"], rtol=DEFAULTS["rtol"],
             atol=DEFAULTS["atol"], max_step=DEFAULTS["max_step"],
             theta_dot_min=DEFAULTS["theta_dot_min"], output_dt=DEFAULTS["output_dt"],
             overturn_angle=math.pi / 2, chatter_window=DEFAULTS["chatter_window"],
             chatter_count=DEFAULTS["chatter_count"], stop_at_rest=True, stop_when_safe=False,
             integrator="solve_ivp", dt=1e-3, backend="scipy"):
    """Validate the arguments of `simulate` and set up a run (or run Newmark to the end)."""
    st = structure if isinstance(structure, Structure) else from_specimen(structure)
    t_end = _positive("t_end", t_end)
    rtol, atol = _positive("rtol", rtol), _positive("atol", atol)
    max_step = _positive("max_step", max_step, allow_inf=True)
    theta_dot_min = _positive("theta_dot_min", theta_dot_min)
    overturn_angle = _positive("overturn_angle", overturn_angle)
    if output_dt is not None:
        output_dt = _positive("output_dt", output_dt)
    if not (isinstance(method, str) and method in _IVP_METHODS) and not isinstance(method, type):
        raise InputError(f"`method` = {method!r}: use one of {', '.join(_IVP_METHODS)} "
                         "or an OdeSolver subclass")
    if int(chatter_count) < 2:
        raise InputError(f"`chatter_count` = {chatter_count!r}: must be ≥ 2")
    chatter_window = _positive("chatter_window", chatter_window)
    ag_fn, duration, bps = _check_excitation(excitation)
    model = impact_model(impact, st.specimen, restitution, k, C_p, eps_p)
    phase, y = _initial_state(st, excitation)
    if integrator not in ("solve_ivp", "newmark"):
        raise InputError(f"`integrator` = {integrator!r}: use 'solve_ivp' or 'newmark'")
    if integrator == "newmark":
        from ._newmark_response import simulate_newmark

        options = dict(impact=getattr(model, "name", type(model).__name__),
                       restitution=model.restitution.describe(), seed=seed,
                       theta_dot_min=theta_dot_min,
                       excitation=excitation.describe() if hasattr(excitation, "describe") else repr(excitation))
        return simulate_newmark(st, model, excitation, t_end, dt=_positive("dt", dt), seed=seed,
                                theta_dot_min=theta_dot_min, overturn_angle=overturn_angle,
                                stop_when_safe=stop_when_safe, options=options)

    if backend not in ("scipy", "compiled"):
        raise InputError(f"`backend` = {backend!r}: use 'scipy' or 'compiled'")
    run = _Run(st, model, ag_fn, duration, bps, t_end, phase, y, seed,
               dict(method=method, rtol=rtol, atol=atol, max_step=max_step),
               theta_dot_min, output_dt, overturn_angle, chatter_window, int(chatter_count),
               stop_at_rest, stop_when_safe)
    if backend == "compiled":
        from .fast import FastPath, warm_up

        run.fast = FastPath.of(st, model, excitation, method, QUIET_DELAY)
        warm_up()                       # compile or load once per process, before the clock
    run.options = dict(impact=getattr(model, "name", type(model).__name__),
                   restitution=model.restitution.describe(),
                   method=method if isinstance(method, str) else method.__name__, rtol=rtol,
                   atol=atol, max_step=max_step, theta_dot_min=theta_dot_min, seed=seed,
                   excitation=excitation.describe() if hasattr(excitation, "describe") else repr(excitation))
    run.options["backend"] = backend
    return run
