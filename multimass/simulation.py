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
the bundled specimens closes to better than 1e-5 (tests/multimass/test_simulate.py).

Before it starts, a run checks its arguments, that the excitation acts before
t_end, and what it will cost (`multimass.cost`): a run estimated beyond the budget
(one hour unless ``max_hours`` says more) or beyond the memory is refused with the
cause and the fix; a run estimated beyond a few seconds shows a progress bar. After
it ends, its accuracy checks decide its status (`multimass.checks`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
import scipy.integrate

from multimass.impact_models import impact_model

from . import validation as v
from ._newmark_response import check_newmark, simulate_newmark
from ._run import QUIET_DELAY, _Run
from .checks import energy_floor, judge
from .cost import simulation_cost
from .errors import InputError
from .excitations import FreeRelease
from .progress import Progress, budget_seconds
from .response import Response
from .structure import Structure, from_specimen

__all__ = ["simulate", "simulate_outcome", "estimate", "Outcome", "DEFAULTS"]

#: Default options (see the module docstring for why).
DEFAULTS = dict(
    method="DOP853",
    rtol=1e-8,
    atol=1e-10,
    max_step=5e-3,
    theta_dot_min=0.01,
    output_dt=1e-3,
    chatter_window=5e-3,
    chatter_count=20,
    energy_tol=1e-3,
)

#: Every option of `simulate` and its default (the validated set; see `_options`).
_OPTIONS = dict(
    restitution=None,
    k=None,
    C_p=None,
    eps_p=None,
    seed=None,
    overturn_angle=math.pi / 2,
    stop_at_rest=True,
    stop_when_safe=False,
    integrator="solve_ivp",
    dt=1e-3,
    backend="scipy",
    max_hours=None,
    progress=None,
    **DEFAULTS,
)

_METHODS = ("RK23", "RK45", "DOP853", "Radau", "BDF", "LSODA")


def simulate(
    structure,
    excitation,
    impact="DD2",
    t_end: float = 10.0,
    *,
    restitution=None,
    k: float | None = None,
    C_p: float | None = None,
    eps_p: float | None = None,
    seed: int | None = None,
    method=DEFAULTS["method"],
    rtol: float = DEFAULTS["rtol"],
    atol: float = DEFAULTS["atol"],
    max_step: float = DEFAULTS["max_step"],
    theta_dot_min: float = DEFAULTS["theta_dot_min"],
    output_dt: float | None = DEFAULTS["output_dt"],
    overturn_angle: float = math.pi / 2,
    chatter_window: float = DEFAULTS["chatter_window"],
    chatter_count: int = DEFAULTS["chatter_count"],
    stop_at_rest: bool = True,
    stop_when_safe: bool = False,
    integrator: str = "solve_ivp",
    dt: float = 1e-3,
    backend: str = "scipy",
    energy_tol: float = DEFAULTS["energy_tol"],
    max_hours: float | None = None,
    progress: bool | None = None,
) -> Response:
    """Simulate the nonlinear response of a rocking structure (paper 001, Section 2).

    Parameters
    ----------
    structure : Structure, specimen or str
        A structure (`multimass.column`, `multimass.rigid_block`) or a specimen
        name / TOML path.
    excitation : Excitation
        A callable ü_g(t) in m/s² with ``duration`` and ``breakpoints``, e.g.
        `FreeRelease`, `SineWave`, `CosinePulse`, a `Record`. It must act before
        `t_end` (a record whose first sample is after `t_end` is refused).
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
        Seed (≥ 0) of the random restitution (DD5): same seed, same response.
    method, rtol, atol, max_step :
        solve_ivp options (defaults in `DEFAULTS`); `method` is one of RK23,
        RK45, DOP853, Radau, BDF, LSODA or an ``scipy.integrate.OdeSolver`` subclass.
    theta_dot_min : float
        θ̇_min of paper 001, Eqs 9 and 16 (rad/s).
    output_dt : float or None
        Sampling step of the recorded series (s); None records nothing but
        peaks, events and the ledger at transitions (fast sweeps).
    overturn_angle : float
        ``|θ|`` at which the structure has overturned (rad, in (0, π/2]; default π/2).
    chatter_window, chatter_count :
        The chattering guard: `chatter_count` transitions within
        `chatter_window` seconds force full contact for one window.
    stop_at_rest : bool
        For a rigid block, stop once the excitation is over and the block
        rests in full contact (nothing can move it again).
    stop_when_safe : bool
        For a rigid block, also stop (event "rest") once the excitation is over
        and the block, with ``|θ|`` < α_cg and less energy than it needs to reach
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
    energy_tol : float
        The accuracy check: a run whose energy ledger's balance error exceeds
        this share of its energy scale gets status "inaccurate" (default 1e-3;
        see `multimass.checks`).
    max_hours : float, optional
        The budget: a run estimated to take longer (`multimass.cost`) is refused
        before it starts (default 1 h; ``math.inf`` for none).
    progress : bool, optional
        Show a progress bar on stderr: True, False, or None (default) for runs
        estimated to take more than a few seconds.

    Returns
    -------
    Response
        ``status`` "completed", "overturned", "inaccurate" (finished, but an
        accuracy check failed: see ``warnings``) or "failed" (``message``
        carries the solver's message); ``outcome`` is the physical end.

    Raises
    ------
    InputError
        For invalid arguments (named in the message), an excitation that starts
        after `t_end`, and a run over the budget or the memory.
    """
    plan = _prepare(
        structure,
        excitation,
        impact,
        t_end,
        _options({name: value for name, value in locals().items() if name in _OPTIONS}),
    )
    return judge(plan.run(lean=False), plan.options["energy_tol"])


@dataclass(frozen=True)
class Outcome:
    """What `simulate_outcome` returns: the run without its series.

    Attributes
    ----------
    status, message : str
        As in `Response` ("completed", "overturned", "inaccurate", "failed").
    events : list of Event
    peaks : ndarray
        Absolute peak ``|θ|`` of each half-cycle (rad).
    n_rhs : int
    wall_time_s : float
    energy_balance_error : float
        Balance error of the ledger at the end of the run, relative to its
        energy scale (the Response's is the largest over the whole run).
    outcome, warnings, checks :
        As in `Response`.
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

    @property
    def theta_max(self) -> float:
        return float(self.peaks.max()) if self.peaks.size else 0.0

    @property
    def n_impacts(self) -> int:
        return sum(e.kind == "impact" for e in self.events)


def simulate_outcome(
    structure, excitation, impact="DD2", t_end: float = 10.0, **options
) -> Outcome:
    """`simulate` without the time series, for sweeps of many runs.

    Takes the same arguments as `simulate` (``output_dt`` is ignored: nothing
    is sampled; ``progress`` defaults to False) and returns an `Outcome`:
    status, events, peaks and the end-of-run energy check — what an overturning
    map or a spectrum needs, without building a DataFrame.
    """
    options = {"progress": False} | options | {"output_dt": None}
    plan = _prepare(structure, excitation, impact, t_end, _options(options))
    return judge(plan.run(lean=True), plan.options["energy_tol"])


def estimate(structure, excitation, impact="DD2", t_end: float = 10.0, **options):
    """Validate the arguments of `simulate` and estimate the run's cost, without running it.

    Sweeps call it in the parent process on their most expensive job, so a bad
    option is reported before any worker starts.

    Returns
    -------
    multimass.progress.RunCost
        Steps, wall time (s), output memory (bytes) and the basis of the estimate.

    Raises
    ------
    InputError
        As `simulate` would, before it starts.
    """
    return _prepare(structure, excitation, impact, t_end, _options(options)).cost


# ---------------------------------------------------------------------------- validation
def _options(given: dict) -> dict:
    """Every option of `simulate`, validated (strict numbers: no bools or strings)."""
    unknown = sorted(set(given) - set(_OPTIONS))
    if unknown:
        raise InputError(
            f"`{unknown[0]}` is not an option of simulate; the options are "
            f"{', '.join(sorted(_OPTIONS))}"
        )
    o = _OPTIONS | given
    for name in ("rtol", "atol", "theta_dot_min", "chatter_window", "dt", "energy_tol"):
        o[name] = v.positive(name, o[name])
    o["max_step"] = v.positive("max_step", o["max_step"], "s", allow_inf=True)
    if o["output_dt"] is not None:
        o["output_dt"] = v.positive("output_dt", o["output_dt"], "the sampling step in s")
    o["overturn_angle"] = v.number(
        "overturn_angle", o["overturn_angle"], low=0.0, low_open=True, high=math.pi / 2, what="rad"
    )
    o["chatter_count"] = v.integer("chatter_count", o["chatter_count"], low=2)
    if o["seed"] is not None:
        o["seed"] = v.integer("seed", o["seed"], low=0, what="the seed of random restitution")
    for name in ("stop_at_rest", "stop_when_safe"):
        if not isinstance(o[name], bool):
            raise InputError(f"`{name}` = {o[name]!r}: expected True or False")
    if o["progress"] is not None and not isinstance(o["progress"], bool):
        raise InputError(f"`progress` = {o['progress']!r}: expected True, False or None")
    o["integrator"] = v.choice("integrator", o["integrator"], ("solve_ivp", "newmark"))
    o["backend"] = v.choice("backend", o["backend"], ("scipy", "compiled"))
    method = o["method"]
    if not (
        (isinstance(method, str) and method in _METHODS)
        or (isinstance(method, type) and issubclass(method, scipy.integrate.OdeSolver))
    ):
        raise InputError(
            f"`method` = {method!r}: use one of {', '.join(_METHODS)} or an OdeSolver subclass"
        )
    o["budget_s"] = budget_seconds(o.pop("max_hours"))
    return o


def _structure(structure) -> Structure:
    return structure if isinstance(structure, Structure) else from_specimen(structure)


def _excitation(excitation, t_end: float):
    """(ü_g, duration, breakpoints) of a valid excitation that acts before `t_end`."""
    if excitation is None or not callable(excitation):
        raise InputError(
            f"`excitation` = {excitation!r}: give an excitation, e.g. "
            "FreeRelease(theta0=0.1) or SineWave(amplitude=0.4 * G, omega=15.0)"
        )
    duration = float(getattr(excitation, "duration", math.inf))
    if math.isnan(duration) or duration < 0.0:
        raise InputError(f"`excitation.duration` = {duration!r}: must be ≥ 0 (s) or inf")
    bps = tuple(float(b) for b in getattr(excitation, "breakpoints", ()))
    start = bps[0] if bps else 0.0
    if not isinstance(excitation, FreeRelease) and duration > 0.0 and start >= t_end:
        name = getattr(excitation, "name", getattr(excitation, "kind", "excitation"))
        raise InputError(
            f"`excitation` {name!r} starts at t = {start:.6g} s, at or after t_end = {t_end:g} s: "
            "the structure would see no ground motion. Shift the record's time column so that it "
            "starts near 0, or raise t_end beyond the start of the motion"
        )
    return getattr(excitation, "acceleration", excitation), duration, bps


def _initial_state(st: Structure, excitation) -> tuple[int, np.ndarray]:
    n = st.n
    y = np.zeros(2 * n + 5)
    theta0 = float(getattr(excitation, "theta0", 0.0) or 0.0)
    if not math.isfinite(theta0):
        raise InputError(f"`theta0` = {theta0!r}: must be finite")
    if abs(theta0) >= st.alpha_cg:
        raise InputError(
            f"`theta0` = {theta0!r} rad is beyond the slenderness α_cg = "
            f"{st.alpha_cg:.4f} rad of {st.name!r}: the structure would overturn; "
            "release it from a smaller angle"
        )
    if hasattr(excitation, "initial_displacement"):
        y[:n] = excitation.initial_displacement(st)
    y[n] = theta0
    return (int(np.sign(theta0)), y)


# ---------------------------------------------------------------------------- the run
@dataclass(frozen=True, eq=False)
class _Plan:
    """A validated run, ready to go: `run` integrates it and returns its raw result."""

    st: Structure
    model: object
    excitation: object
    t_end: float
    options: dict
    cost: object
    ground: tuple  # (ü_g, duration, breakpoints)
    start: tuple  # (phase, y0)
    fast: object = None  # a multimass.fast.FastPath with backend="compiled"

    def describe(self) -> dict:
        o, model, exc = self.options, self.model, self.excitation
        method = o["method"]
        return dict(
            impact=getattr(model, "name", type(model).__name__),
            restitution=model.restitution.describe(),
            method=method if isinstance(method, str) else method.__name__,
            rtol=o["rtol"],
            atol=o["atol"],
            max_step=o["max_step"],
            theta_dot_min=o["theta_dot_min"],
            seed=o["seed"],
            excitation=exc.describe() if hasattr(exc, "describe") else repr(exc),
            backend=o["backend"],
        )

    def run(self, lean: bool):
        """Integrate; a `Response` (or an `Outcome` if `lean`) with the raw status."""
        o = self.options
        with Progress(
            self.t_end, f"simulate {self.st.name}", show=o["progress"], estimate=self.cost.seconds
        ) as bar:
            if o["integrator"] == "newmark":
                return self._newmark(lean)
            run = self._solve_ivp_run()
            wall = time.perf_counter()
            run.loop(bar.update)
            wall = time.perf_counter() - wall
        if lean:
            return Outcome(
                run.status,
                run.message,
                run.events,
                np.array(run.recorder.peaks),
                run.n_rhs,
                wall,
                energy_balance_error=run.end_balance_error(),
            )
        return run.recorder.response(
            run.st.name,
            run.status,
            run.message,
            run.events,
            wall,
            self.describe(),
            run.n_rhs,
            run.t_end,
            run.energy_floor,
        )

    def _solve_ivp_run(self) -> _Run:
        o, st = self.options, self.st
        ag_fn, duration, bps = self.ground
        phase, y = self.start
        run = _Run(
            st,
            self.model,
            ag_fn,
            duration,
            bps,
            self.t_end,
            phase,
            y.copy(),
            o["seed"],
            dict(method=o["method"], rtol=o["rtol"], atol=o["atol"], max_step=o["max_step"]),
            o["theta_dot_min"],
            o["output_dt"],
            o["overturn_angle"],
            o["chatter_window"],
            o["chatter_count"],
            o["stop_at_rest"],
            o["stop_when_safe"],
            energy_floor(st, o["atol"]),
        )
        if self.fast is not None:
            from .fast import warm_up

            run.fast = self.fast
            warm_up()  # compile or load once per process, before the clock
        return run

    def _newmark(self, lean: bool):
        o, model = self.options, self.model
        options = self.describe() | {"backend": None}
        for key in ("method", "rtol", "atol", "max_step"):
            options.pop(key)
        r = simulate_newmark(
            self.st,
            model,
            self.excitation,
            self.t_end,
            dt=o["dt"],
            seed=o["seed"],
            theta_dot_min=o["theta_dot_min"],
            overturn_angle=o["overturn_angle"],
            stop_when_safe=o["stop_when_safe"],
            options=options,
            floor=energy_floor(self.st, DEFAULTS["atol"]),
        )
        if lean:
            return Outcome(
                r.status,
                r.message,
                r.events,
                r.peaks,
                r.n_rhs,
                r.wall_time_s,
                energy_balance_error=r.energy_balance_error,
            )
        return r


def _prepare(structure, excitation, impact, t_end, o: dict) -> _Plan:
    """Validate a run and estimate its cost; refuse it if over the budget or the memory."""
    st = _structure(structure)
    t_end = v.positive("t_end", t_end, "the end time in s")
    ground = _excitation(excitation, t_end)
    model = impact_model(impact, st.specimen, o["restitution"], o["k"], o["C_p"], o["eps_p"])
    start = _initial_state(st, excitation)
    fast = None
    if o["integrator"] == "newmark":
        check_newmark(st, model)
    elif o["backend"] == "compiled":
        from .fast import FastPath

        fast = FastPath.of(st, model, excitation, o["method"], QUIET_DELAY)
    cost = simulation_cost(
        st,
        t_end,
        method=o["method"],
        max_step=o["max_step"],
        output_dt=o["output_dt"],
        backend=o["backend"],
        integrator=o["integrator"],
        dt=o["dt"],
    )
    duration = ground[1]
    long_pulse = (
        f"; the excitation lasts {duration:.3g} s"
        if math.isfinite(duration) and duration > 0.5 * t_end
        else ""
    )
    cost.check(
        f"simulate({st.name}, t_end = {t_end:g} s)",
        "shorten t_end, raise output_dt (or pass output_dt=None), or check the "
        f"structure's stiffness and the excitation{long_pulse}",
        max_seconds=o["budget_s"],
    )
    return _Plan(st, model, excitation, t_end, o, cost, ground, start, fast)
