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

import dataclasses
import math
import time
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from multimass.impact_models import impact_model

from . import validation as v
from .checks import energy_check, judge, scale_floor
from .cost import (
    EXPLICIT_METHODS,
    OUTPUT_BUDGET,
    STIFF,
    check_output,
    series_columns,
    simulation_cost,
    stable_step,
    stiffness,
)
from .engines._events import overturn_message
from .engines._recorder import Recorder
from .engines._run import QUIET_DELAY, PhaseLoop, segment_ends
from .errors import InputError
from .inputs.excitations import FreeRelease, plausible_amplitude
from .model._phase import Model
from .model.structure import Structure, from_specimen
from .progress import PROGRESS_AFTER_S, Progress, format_duration
from .response import Outcome, Response
from .result import status_of
from .simulation_options import DEFAULTS, SimulationOptions

__all__ = [
    "simulate",
    "simulate_outcome",
    "outcome_summary",
    "outcome_summaries",
    "RunSummary",
    "estimate",
    "SimulationOptions",
    "DEFAULTS",
]


def simulate(
    structure, excitation, impact="DD2", t_end: float = 10.0, *, options=None, **kw
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
    options : SimulationOptions, optional
        The options as one validated object; keywords in `kw` replace its fields.
    **kw
        Any field of `SimulationOptions`, by keyword: ``restitution``, ``k``, ``C_p``,
        ``eps_p``, ``seed``, ``method``, ``rtol``, ``atol``, ``max_step``,
        ``thetadot_min``, ``output_dt``, ``overturn_angle``, ``chatter_window``,
        ``chatter_count``, ``stop_at_rest``, ``stop_when_safe``, ``integrator``
        (a key of `INTEGRATORS`), ``dt``, ``backend`` (a key of `BACKENDS`),
        ``energy_tol``, ``max_hours``, ``progress`` — each documented there, with
        its default and why.

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
    plan = _prepare(structure, excitation, impact, t_end, SimulationOptions.of(options, **kw))
    return judge(plan.run(lean=False), plan.options.energy_tol)


def simulate_outcome(
    structure, excitation, impact="DD2", t_end: float = 10.0, *, options=None, **kw
) -> Outcome:
    """`simulate` without the time series, for sweeps of many runs.

    Takes the same arguments as `simulate` (``output_dt`` is ignored: nothing
    is sampled; ``progress`` defaults to False) and returns an `Outcome`:
    status, events, peaks and the end-of-run energy check — what an overturning
    map or a spectrum needs, without building a DataFrame.
    """
    kw = {"progress": False} | kw | {"output_dt": None}
    plan = _prepare(structure, excitation, impact, t_end, SimulationOptions.of(options, **kw))
    return judge(plan.run(lean=True), plan.options.energy_tol)


class RunSummary(NamedTuple):
    """What a sweep keeps of a run (`outcome_summary`): `simulate_outcome`'s ``theta_max``
    (rad), ``outcome``, ``status``, ``n_impacts``, the time of its "overturn" event (s,
    NaN if none) and ``message``."""

    theta_max: float
    outcome: str
    status: str
    n_impacts: int
    overturn_time: float
    message: str


def outcome_summary(
    structure, excitation, impact="DD2", t_end: float = 10.0, *, options=None, **kw
) -> RunSummary:
    """What a sweep keeps of `simulate_outcome` with the same arguments.

    A column on the compiled path (``backend="compiled"``) whose impact model and
    restitution the whole-run kernel knows (`multimass.engines.fast.column_runs`: CIM or the
    Dirac-delta force; fixed, per-corner, Housner's, modified, random or
    impact-specific restitution) runs in one compiled call — the same run as
    `simulate_outcome`'s, bit for bit, without Python between its phases. Any other
    run, and one whose solver fails, runs through `simulate_outcome`.
    """
    kw = {"progress": False} | kw | {"output_dt": None}
    return _summary(
        _prepare(structure, excitation, impact, t_end, SimulationOptions.of(options, **kw))
    )


def _summary(plan: _Plan) -> RunSummary:
    """`outcome_summary` of a prepared run."""
    got = plan.whole_run()
    if got is not None:
        return got
    # the whole-run kernel does not apply or could not finish: the phase loop
    r = judge(plan.run_phase_loop(lean=True), plan.options.energy_tol)
    t_over = next((e.time for e in r.events if e.kind == "overturn"), math.nan)
    return RunSummary(r.theta_max, r.outcome, r.status, r.n_impacts, t_over, r.message)


def outcome_summaries(structure, runs, impact="DD2", **kw) -> list[RunSummary]:
    """`outcome_summary` of each run of a sweep's batch, what the runs share prepared once.

    ``runs`` holds ``(excitation, t_end, seed)`` triples; every run takes `impact` and
    the options `kw`. The first run is prepared as `outcome_summary` prepares it (its
    validation, its cost, the structure's modes, the compiled kernels loaded); a later run
    of a column on the compiled path whose excitation is of the same kind and no longer
    than a prepared one reuses those parts and changes only its ground motion, end time and
    seed: the same `multimass.engines.fast.column_runs.ColumnRun`, so the same result,
    bit for bit, as `outcome_summary` of that run alone. Any other run is `outcome_summary`.
    """
    st = _structure(structure)
    kw = {"progress": False} | kw | {"output_dt": None}
    out, first = [], None
    for excitation, t_end, seed in runs:
        got = None if first is None else first.again(excitation, t_end, seed)
        if got is None:
            plan = _prepare(
                st, excitation, impact, t_end, SimulationOptions.of(None, **kw | {"seed": seed})
            )
            got = _summary(plan)
            if first is None or t_end > first.t_end:
                first = _WholeRuns.of(plan) or first
        out.append(got)
    return out


def estimate(structure, excitation, impact="DD2", t_end: float = 10.0, *, options=None, **kw):
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
    return _prepare(structure, excitation, impact, t_end, SimulationOptions.of(options, **kw)).cost


# ---------------------------------------------------------------------------- validation
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
    samples = getattr(excitation, "accel", None)  # a record, as scaled
    if samples is not None and np.size(samples):
        name = getattr(excitation, "name", "record")
        plausible_amplitude(
            f"{name}: peak",
            float(np.max(np.abs(samples))),
            "a ground motion's peak",
            "check its units (--units) and its scale factor (--scale, Record.scaled)",
        )
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


def _stop_at_kinks(ground: tuple, excitation, t_end: float) -> tuple:
    """The solve_ivp path's ground with the excitation's kinks (a record's samples, where
    ü_g's slope jumps) among its breakpoints, so that no solve_ivp step crosses one: a
    step across a kink loses its order unseen by DOP853's error estimate (S2 under El
    Centro 1940, DD5, rtol 1e-10: peaks 1.9e-7 rad from DOP853 at rtol 1e-12 across them,
    1.2e-10 rad stopping at each, with 12 % fewer right-hand sides). The compiled path
    ends its steps at the samples inside its kernel (`engines.fast._maths.piece_end`)."""
    kinks = getattr(excitation, "kinks", None)
    if kinks is None:
        return ground
    ag, duration, bps = ground
    k = np.asarray(kinks, dtype=float)
    k = k[(k > 0.0) & (k < min(t_end, duration))]
    return ag, duration, tuple(sorted(set(bps).union(k.tolist())))


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
    options: SimulationOptions
    cost: object
    ground: tuple  # (ü_g, duration, breakpoints)
    start: tuple  # (phase, y0)
    fast: object = None  # a multimass.engines.fast.FastPath with backend="compiled"

    def describe(self) -> dict:
        o, model, exc = self.options, self.model, self.excitation
        return dict(
            impact=getattr(model, "name", type(model).__name__),
            restitution=model.restitution.describe(),
            method=o.method if isinstance(o.method, str) else o.method.__name__,
            rtol=o.rtol,
            atol=o.atol,
            max_step=o.max_step,
            thetadot_min=o.thetadot_min,
            seed=o.seed,
            excitation=exc.describe() if hasattr(exc, "describe") else repr(exc),
            backend=o.backend,
            engine=o.engine,
        ) | ({"full_contact": self.full_contact} if self.fast is not None else {})

    @property
    def full_contact(self) -> str:
        """How the compiled path advances full contact in this run: "exact" or "integrate"."""
        return "integrate" if self.fast is None or self.fast.contact is None else "exact"

    def run(self, lean: bool):
        """Integrate; a `Response` (or an `Outcome` if `lean`) with the raw status.

        A column run the whole-run kernel knows runs in one compiled call
        (`_whole_traced`), any other in the phase loop (`run_phase_loop`): the same
        result, bit for bit."""
        whole = self._whole_traced(lean)
        return whole if whole is not None else self.run_phase_loop(lean)

    def shows_progress(self) -> bool:
        """Whether the run shows a progress bar: as asked, else if estimated at
        `PROGRESS_AFTER_S` or more."""
        o = self.options
        return o.progress if o.progress is not None else self.cost.seconds >= PROGRESS_AFTER_S

    def run_phase_loop(self, lean: bool):
        """`run` in the Python phase loop (`multimass.engines._run.PhaseLoop`), whose
        segments go to solve_ivp or, on the compiled path, to the segment kernels."""
        o, show = self.options, self.shows_progress()
        with Progress(
            self.t_end,
            f"simulate {self.st.name}",
            show=show,
            estimate=self.cost.seconds,
            note=_stiff_hint(self.st, self.t_end, o, self.cost.seconds) if show else "",
        ) as bar:
            if o.integrator == "newmark":
                return self._newmark(lean)
            loop = self._phase_loop()
            wall = time.perf_counter()
            end = loop.run(bar.update)
            wall = time.perf_counter() - wall
        rec = loop.recorder
        if lean:
            return Outcome(
                end.status,
                end.message,
                loop.events,
                np.array(rec.peaks),
                loop.n_rhs,
                wall,
                energy_balance_error=loop.end_balance_error(end),
                peak_times=np.array(rec.peak_times),
                engine=o.engine,
            )
        return rec.response(
            self.st.name,
            end.status,
            end.message,
            loop.events,
            wall,
            self.describe(),
            loop.n_rhs,
            self.t_end,
            loop.energy_floor,
        )

    def _whole_traced(self, lean: bool):
        """`run` by the whole-run kernel with its log (`multimass.engines.fast.column_trace`):
        the phase loop's result from the same numbers, without Python between the phases.
        None where the kernel does not apply, where its kernels are not compiled yet
        (`_columns_ready`: their compile is a sweep's to pay, or `multimass warm-up`'s),
        where a progress bar is to be shown (the kernel reports none) or where the kernel
        could not finish the run."""
        o = self.options
        if self.shows_progress() or self.fast is None or not _columns_ready():
            return None
        run = self.column_run()
        if run is None:
            return None
        from .engines.fast.column_trace import trace  # numba: "compiled" only

        got = trace(run, None if lean else o.output_dt, (o.chatter_count, o.chatter_window))
        if got is None:
            return None
        message = overturn_message(o.overturn_angle) if got.outcome == "overturned" else ""
        if lean:
            return Outcome(
                got.outcome,
                message,
                got.events,
                got.peaks[0],
                got.n_rhs,
                got.wall_time_s,
                energy_balance_error=got.energy_balance_error,
                peak_times=got.peaks[1],
                engine=o.engine,
            )
        recorder = Recorder(self.st, Model.of(self.st), o.output_dt, self.ground[0])
        return recorder.response_of(
            got.rows,
            got.peaks,
            self.st.name,
            got.outcome,
            message,
            got.events,
            got.wall_time_s,
            self.describe(),
            got.n_rhs,
            self.t_end,
            scale_floor(self.st, o.atol, o.energy_tol),
        )

    def whole_run(self) -> RunSummary | None:
        """`outcome_summary` of this run from `multimass.engines.fast.column_runs` (one compiled
        call), or None where that does not apply or the kernel could not finish it."""
        run = self.column_run()
        return None if run is None else _whole_summary(run, self.options)

    def column_run(self):
        """This run as a `multimass.engines.fast.column_runs.ColumnRun`, its kernels loaded;
        None where the whole-run kernel does not apply."""
        if self.fast is None or self.st.n < 1 or self.options.integrator != "solve_ivp":
            return None
        from .engines.fast import warm_up_contact, warm_up_exponential  # numba: "compiled"
        from .engines.fast.column_runs import ColumnRun
        from .engines.fast.compile import warm_up_columns

        o, (_, duration, bps) = self.options, self.ground
        ends = segment_ends(bps, duration, self.t_end)
        run = ColumnRun.of(self.st, self.model, self.fast, self.start, ends, self.t_end, o)
        if run is None:
            return None
        # the whole run calls the column kernel only (its group covers the sources it
        # compiles); the per-phase kernels load when a run falls back to the phase loop
        if self.fast.contact is not None:
            warm_up_contact()
        if self.fast.rocking is not None:
            warm_up_exponential()
        warm_up_columns()
        return run

    def _phase_loop(self) -> PhaseLoop:
        if self.fast is not None:
            from .engines.fast import (  # numba loads only for "compiled"
                warm_up,
                warm_up_contact,
                warm_up_exponential,
            )  # "compiled" only

            warm_up()  # compile or load once per process, before the clock
            if self.fast.contact is not None:
                warm_up_contact()
            if self.fast.rocking is not None:
                warm_up_exponential()
        phase, y = self.start
        return PhaseLoop(
            self.st, self.model, self.ground, self.t_end, phase, y.copy(), self.options, self.fast
        )

    def _newmark(self, lean: bool):
        from .engines._newmark_response import simulate_newmark  # ~10 ms: Newmark runs only

        o, model = self.options, self.model
        options = self.describe() | {"backend": None}
        for key in ("method", "rtol", "atol", "max_step"):
            options.pop(key)
        r = simulate_newmark(
            self.st,
            model,
            self.excitation,
            self.t_end,
            dt=o.dt,
            seed=o.seed,
            thetadot_min=o.thetadot_min,
            overturn_angle=o.overturn_angle,
            stop_when_safe=o.stop_when_safe,
            options=options,
            floor=scale_floor(self.st, DEFAULTS["atol"], o.energy_tol),
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
                peak_times=r.peak_times,
                engine="newmark",
            )
        return r


def _columns_ready() -> bool:
    """Whether the whole column runs are compiled (`multimass.engines.fast.columns_ready`):
    `simulate` takes its one-call path only then, not to compile them for one run."""
    from .engines.fast.compile import columns_ready  # numba: "compiled" only

    return columns_ready()


def _whole_summary(run, o: SimulationOptions) -> RunSummary | None:
    """The `RunSummary` of a `ColumnRun` (as `judge` would judge it), None if it broke."""
    from .engines.fast.column_runs import BROKEN

    outcome, t_over, top, n_impacts, _, err = run.run()
    if outcome == BROKEN:
        return None
    status = status_of(outcome, energy_check(err, o.energy_tol)["passed"])  # as judge
    message = overturn_message(o.overturn_angle) if outcome == "overturned" else ""
    return RunSummary(float(top), outcome, status, int(n_impacts), float(t_over), message)


@dataclass(frozen=True, eq=False)
class _WholeRuns:
    """A prepared whole column run (`outcome_summaries`) that later runs of a batch reuse."""

    st: Structure
    run: object  # multimass.engines.fast.column_runs.ColumnRun
    options: SimulationOptions
    kind: int  # the excitation's code (`multimass.engines.fast.excitation.encode`)
    t_end: float  # its cost was checked: a run no longer than this costs no more

    @classmethod
    def of(cls, plan: _Plan) -> _WholeRuns | None:
        run = plan.column_run()
        if run is None:
            return None
        return cls(plan.st, run, plan.options, plan.fast.kind, plan.t_end)

    def again(self, excitation, t_end: float, seed) -> RunSummary | None:
        """The summary of the run with this excitation, end and seed; None if this prepared
        run does not apply to it (another kind of excitation, a longer run) or it broke."""
        from .engines.fast.excitation import encode

        t_end = v.positive("t_end", t_end, "the end time in s")
        if t_end > self.t_end:
            return None
        _, duration, bps = _excitation(excitation, t_end)
        kind, par, samples = encode(excitation)
        if kind != self.kind:
            return None
        phase, y0 = _initial_state(self.st, excitation)
        o = SimulationOptions.of(self.options, seed=seed)
        arr = lambda a: np.array(a, dtype=np.float64, order="C")  # as FastPath.of
        run = dataclasses.replace(
            self.run,
            t_end=float(t_end),
            phase=int(phase),
            y0=np.ascontiguousarray(y0, dtype=np.float64),
            breakpoints=np.asarray(segment_ends(bps, duration, t_end), dtype=np.float64),
            ground=(int(kind), arr(par), arr(samples)),
            seed=o.seed,
        )
        return _whole_summary(run, o)


def _prepare(structure, excitation, impact, t_end, o: SimulationOptions) -> _Plan:
    """Validate a run and estimate its cost; refuse it if over the budget or the memory."""
    st = _structure(structure)
    t_end = v.positive("t_end", t_end, "the end time in s")
    ground = _excitation(excitation, t_end)
    model = impact_model(impact, st.specimen, o.restitution, o.k, o.C_p, o.eps_p)
    start = _initial_state(st, excitation)
    fast = None
    if o.integrator == "newmark":
        from .engines._newmark_response import check_newmark

        check_newmark(st, model)
    elif o.backend == "compiled":
        from .engines.fast import FastPath  # numba loads only for backend="compiled"

        fast = FastPath.of(st, model, excitation, o.method, QUIET_DELAY, o.full_contact)
    elif o.integrator == "solve_ivp":
        ground = _stop_at_kinks(ground, excitation, t_end)
    cost = simulation_cost(
        st,
        t_end,
        method=o.method,
        max_step=o.max_step,
        output_dt=o.output_dt,
        backend=o.backend,
        integrator=o.integrator,
        dt=o.dt,
    )
    duration = ground[1]
    long_pulse = (
        f"; the excitation lasts {duration:.3g} s"
        if math.isfinite(duration) and duration > 0.5 * t_end
        else ""
    )
    over = not cost.seconds <= o.budget_s  # (the hint's modes only for a run refused)
    hint = _stiff_hint(st, t_end, o, cost.seconds) if over else ""
    cost.check(
        f"simulate({st.name}, t_end = {t_end:g} s)",
        (f"{hint}; or " if hint else "")
        + "shorten t_end, raise output_dt (or pass output_dt=None), or check the "
        f"structure's stiffness and the excitation{long_pulse}",
        max_seconds=o.budget_s,
    )
    if o.output_dt is not None and o.integrator != "newmark":
        check_output(
            "`output_dt` (--output-dt)",
            o.output_dt,
            t_end / o.output_dt,
            series_columns(st.n),
            f"raise output_dt (to ≥ {t_end * series_columns(st.n) * 8.0 / OUTPUT_BUDGET:.2g} s for "
            f"t_end = {t_end:g} s), shorten t_end, or pass output_dt=None for the outcome only",
        )
    return _Plan(st, model, excitation, t_end, o, cost, ground, start, fast)


#: How much cheaper the exponential method must be estimated for `_stiff_hint` to speak.
HINT_GAIN = 10.0


def _stiff_hint(st: Structure, t_end: float, o: SimulationOptions, seconds: float) -> str:
    """Where an explicit Runge–Kutta run of a stiff column is long (estimated `seconds` ≥
    `PROGRESS_AFTER_S`, stiffness ≥ `STIFF`) and the exponential method is estimated at
    least `HINT_GAIN` times cheaper: the options that run it and their estimate; else "".

    Its stiffest mode holds an explicit method's steps to c/ρ whatever the accuracy
    asked, while the exponential method advances the elastic modes exactly (a 40-node
    column released for 10 s: 35 s with compiled DOP853, 0.16 s with it)."""
    explicit = isinstance(o.method, str) and o.method in EXPLICIT_METHODS
    if st.n < 1 or o.integrator != "solve_ivp" or not explicit or seconds < PROGRESS_AFTER_S:
        return ""
    s = stiffness(st, o.max_step)
    if not s >= STIFF:
        return ""
    alt = simulation_cost(
        st, t_end, method="exponential", max_step=o.max_step, output_dt=o.output_dt,
        backend="compiled", integrator="solve_ivp",
    ).seconds  # fmt: skip
    if not alt * HINT_GAIN <= seconds:
        return ""
    from .engines.fast.rocking_modes import RockingModes  # numba: a long run only

    if isinstance(RockingModes.of(st), str):  # no diagonalisable rocking phase
        return ""
    compiled = o.backend == "compiled"
    how = "method='exponential'" + ("" if compiled else ", backend='compiled'")
    flags = "--method exponential" + ("" if compiled else " --backend compiled")
    return (
        f"the column is stiff (S = {s:.3g}: its stiffest mode holds {o.method}'s steps to "
        f"{stable_step(st, o.method):.2g} s): {how} ({flags}) advances its elastic modes "
        f"exactly, estimated {format_duration(alt)}"
    )
