"""`SimulationOptions`: every option of `multimass.simulate`, validated once, and the registries
of integrators, backends and solve_ivp methods they are chosen from.

`simulate`, `simulate_outcome` and `estimate` take these options by keyword (or
a `SimulationOptions` as ``options=``); the sweeps pass them through. The defaults and
why they were chosen are in `multimass.simulation`'s module docstring.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from . import validation as v
from .errors import InputError
from .progress import budget_seconds

__all__ = [
    "SimulationOptions",
    "INTEGRATORS",
    "BACKENDS",
    "METHODS",
    "COMPILED_METHODS",
    "FULL_CONTACT",
    "DEFAULTS",
]

#: Integrators of `simulate`: name → what it is.
INTEGRATORS = {
    "solve_ivp": "explicit or implicit Runge–Kutta with exact event location (paper 001, Sec 2)",
    "newmark": "paper 004's Newmark trapezoidal rule with Newton–Raphson (rigid blocks, "
    "classical impacts)",
}
#: Backends of the solve_ivp integrator: name → what it is.
BACKENDS = {
    "scipy": "scipy.integrate.solve_ivp, one call per phase segment (the reference)",
    "compiled": "the same Runge–Kutta steps, events and output in numba kernels (multimass.engines.fast)",
}
#: How the compiled path may advance full contact (`SimulationOptions.full_contact`).
FULL_CONTACT = ("auto", "exact", "integrate")
#: The solve_ivp methods by name (an ``scipy.integrate.OdeSolver`` subclass is accepted too).
METHODS = ("RK23", "RK45", "DOP853", "Radau", "BDF", "LSODA")
#: Methods of backend "compiled" only: name → what it is.
COMPILED_METHODS = {
    "exponential": "rocking phases by an exponential Runge–Kutta method that advances the "
    "linearised column exactly (multimass.engines.fast._exp_kernel); full contact as with DOP853",
}


def _is_ode_solver(method) -> bool:
    """`method` is a ``scipy.integrate.OdeSolver`` subclass (SciPy imported only then)."""
    if not isinstance(method, type):
        return False
    import scipy.integrate

    return issubclass(method, scipy.integrate.OdeSolver)


@dataclass(frozen=True)
class SimulationOptions:
    """The options of one simulation, checked when built (strict: no bools or strings
    for numbers, no NaN), so every engine trusts them.

    Attributes
    ----------
    restitution, k, C_p : optional
        Override paper 001 Table 2's restitution ("mean", "random", "housner",
        "modified", a number, ...), k of η_M, and C_p.
    eps_p : float, optional
        Poisson's ε_P of impact="LCP" (default 0).
    seed : int, optional
        Seed (≥ 0) of the random restitution (DD5): same seed, same response.
    method : str or OdeSolver subclass
        One of `METHODS` (default DOP853), an ``scipy.integrate.OdeSolver`` subclass, or,
        with backend "compiled", "exponential" (`COMPILED_METHODS`: the rocking phases of a
        column by an exponential integrator, its elastic modes advanced exactly; full
        contact as with DOP853, or in closed form per `full_contact`).
    rtol, atol, max_step : float
        solve_ivp tolerances and longest step (s; inf for none).
    thetadot_min : float
        θ̇_min of paper 001, Eqs 9 and 16 (rad/s).
    output_dt : float or None
        Sampling step of the recorded series (s); None records nothing but peaks,
        events and the ledger at transitions (fast sweeps).
    overturn_angle : float
        ``|θ|`` at which the structure has overturned (rad, in (0, π/2]).
    chatter_window, chatter_count :
        The chattering guard: `chatter_count` transitions within `chatter_window`
        seconds force full contact for one window.
    stop_at_rest : bool
        For a rigid block, stop once the excitation is over and the block rests
        in full contact.
    stop_when_safe : bool
        For a rigid block, also stop (event "rest") once the excitation is over and
        the block has too little energy to overturn in free rocking, and rests in
        full contact or rocks away from θ = 0 (θ θ̇ ≥ 0; toward it, the run goes on to
        the impact). The swing under way then peaks at
        `multimass.model.equations.free_rocking_peak` of its energy (energy is conserved in
        free rocking and lost at impacts, so no later swing peaks higher): that peak
        enters `Response.peaks`, timed at the stop, and θ_max is that of the run
        continued to t_end (to the integrator's accuracy).
    integrator : str
        A key of `INTEGRATORS`: "solve_ivp" or "newmark" (`method`, `rtol`, `atol`
        and `max_step` then do not apply).
    dt : float
        Step of the Newmark integrator (s).
    backend : str
        A key of `BACKENDS`: "scipy" (the reference) or "compiled" (RK23/RK45/DOP853
        and the known excitations; compiled once per machine, never timed in
        ``wall_time_s``).
    full_contact : str
        How backend "compiled" advances a column's full contact (paper 001, Eq 3):
        "exact" in closed form between the samples of a record or in free vibration
        (classical damping; `multimass.engines.fast.contact_modes`), "integrate"
        with the Runge–Kutta pair like every other phase, or "auto" (the default:
        exact where it applies). Backend "scipy" always integrates.
    energy_tol : float
        A run whose energy ledger's balance error exceeds this share of its energy
        scale gets status "inaccurate" (`multimass.checks`).
    max_hours : float, optional
        The budget: a run estimated to take longer is refused before it starts
        (None: 1 h; ``math.inf`` for none).
    progress : bool, optional
        Show a progress bar on stderr: True, False, or None for runs estimated to
        take more than a few seconds.
    """

    restitution: object = None
    k: float | None = None
    C_p: float | None = None
    eps_p: float | None = None
    seed: int | None = None
    method: object = "DOP853"
    rtol: float = 1e-8
    atol: float = 1e-10
    max_step: float = 5e-3
    thetadot_min: float = 0.01
    output_dt: float | None = 1e-3
    overturn_angle: float = math.pi / 2
    chatter_window: float = 5e-3
    chatter_count: int = 20
    stop_at_rest: bool = True
    stop_when_safe: bool = False
    integrator: str = "solve_ivp"
    dt: float = 1e-3
    backend: str = "scipy"
    full_contact: str = "auto"
    energy_tol: float = 1e-3
    max_hours: float | None = None
    progress: bool | None = None

    def __post_init__(self):
        put = lambda name, value: object.__setattr__(self, name, value)  # noqa: E731
        for name in ("rtol", "atol", "thetadot_min", "chatter_window", "dt", "energy_tol"):
            put(name, v.positive(name, getattr(self, name)))
        put("max_step", v.positive("max_step", self.max_step, "s", allow_inf=True))
        if self.output_dt is not None:
            put("output_dt", v.positive("output_dt", self.output_dt, "the sampling step in s"))
        put(
            "overturn_angle",
            v.number(
                "overturn_angle",
                self.overturn_angle,
                low=0.0,
                low_open=True,
                high=math.pi / 2,
                what="rad",
            ),
        )
        put("chatter_count", v.integer("chatter_count", self.chatter_count, low=2))
        if self.seed is not None:
            put("seed", v.integer("seed", self.seed, low=0, what="the seed of random restitution"))
        for name in ("stop_at_rest", "stop_when_safe"):
            if not isinstance(getattr(self, name), bool):
                raise InputError(f"`{name}` = {getattr(self, name)!r}: expected True or False")
        if self.progress is not None and not isinstance(self.progress, bool):
            raise InputError(f"`progress` = {self.progress!r}: expected True, False or None")
        put("integrator", v.choice("integrator", self.integrator, tuple(INTEGRATORS)))
        put("backend", v.choice("backend", self.backend, tuple(BACKENDS)))
        put("full_contact", v.choice("full_contact", self.full_contact, FULL_CONTACT))
        if self.full_contact == "exact" and self.backend != "compiled":
            raise InputError(
                "`full_contact` = 'exact' needs backend='compiled' (backend "
                f"{self.backend!r} integrates full contact); drop full_contact or pass "
                "backend='compiled'"
            )
        method = self.method
        if isinstance(method, str) and method in COMPILED_METHODS:
            if self.backend != "compiled" or self.integrator != "solve_ivp":
                raise InputError(
                    f"`method` = {method!r} needs backend='compiled' (backend "
                    f"{self.backend!r}, integrator {self.integrator!r}); pass "
                    "backend='compiled' or use one of " + ", ".join(METHODS)
                )
        elif not ((isinstance(method, str) and method in METHODS) or _is_ode_solver(method)):
            raise InputError(
                f"`method` = {method!r}: use one of {', '.join(METHODS)}, an OdeSolver "
                f"subclass, or with backend='compiled' {', '.join(COMPILED_METHODS)}"
            )
        budget_seconds(self.max_hours)  # checks it

    @classmethod
    def of(cls, options=None, **given) -> SimulationOptions:
        """`options` (a SimulationOptions, or None for the defaults) with `given` replacing fields;
        an unknown name is an InputError that lists the options."""
        unknown = sorted(set(given) - set(FIELDS))
        if unknown:
            raise InputError(
                f"`{unknown[0]}` is not an option of simulate; the options are "
                f"{', '.join(sorted(FIELDS))}"
            )
        if options is None:
            return cls(**given)
        if not isinstance(options, SimulationOptions):
            raise InputError(f"`options` = {options!r}: expected a multimass.SimulationOptions")
        return dataclasses.replace(options, **given) if given else options

    @property
    def budget_s(self) -> float:
        """The budget in seconds (`max_hours`; one hour by default)."""
        return budget_seconds(self.max_hours)

    @property
    def ivp(self) -> dict:
        """The keyword arguments of solve_ivp: method, rtol, atol, max_step."""
        return dict(method=self.method, rtol=self.rtol, atol=self.atol, max_step=self.max_step)

    @property
    def engine(self) -> str:
        """ "newmark", "compiled" or "solve_ivp": what integrates the run."""
        if self.integrator == "newmark":
            return "newmark"
        return "compiled" if self.backend == "compiled" else "solve_ivp"


#: The option names.
FIELDS = tuple(f.name for f in dataclasses.fields(SimulationOptions))

#: The solver defaults (method, tolerances, sampling, guard, accuracy check).
DEFAULTS = {
    name: getattr(SimulationOptions, name)
    for name in (
        "method",
        "rtol",
        "atol",
        "max_step",
        "thetadot_min",
        "output_dt",
        "chatter_window",
        "chatter_count",
        "energy_tol",
    )
}
