"""Free rocking of a rigid block on a beam by Moreau–Jean time stepping (paper 002).

Before it starts, a run checks its arguments and estimates its cost
(`nscd.cost`): a run over the time budget (one hour unless ``max_hours`` says
more) or the memory is refused with the cause and the fix, and a run estimated
above a few seconds shows a progress bar (the compiled loop runs in chunks
between which the bar moves). After it ends, its accuracy checks decide its
status (`nscd.result`: "inaccurate" when a check fails).

>>> import math
>>> from multimass import nscd
>>> res = nscd.simulate("B6M", theta0=math.radians(11.268), dt=1e-4, t_end=0.6)
>>> round(math.degrees(res.first_peak), 1), res.status
(7.8, 'completed')
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from multimass.errors import InputError
from multimass.progress import PROGRESS_AFTER_S, Progress, RunCost, budget_seconds
from multimass.result import status_of
from multimass.validation import integer, number

from . import cost
from .kernel import STAT_NAMES, STATUS, run_kernel
from .model import System, assemble, check_inputs, csr
from .result import (
    GS_RESIDUAL_TOL,
    MAX_EVENTS,
    NSCDResult,
    accuracy_checks,
    log_warnings,
    outcome_message,
    run_events,
)

__all__ = [
    "NSCDResult",
    "RunOptions",
    "simulate",
    "run_system",
    "check_run",
    "estimate_cost",
    "execute",
    "REST_FRACTION",
    "GS_TOL_RANGE",
    "GS_MAX_ITER_MAX",
]

#: at rest: ``|θ|`` stays below this fraction of ``|θ0|`` from rest_time to the end ...
REST_FRACTION = 0.01
#: ... for at least this long (s); otherwise the block is reported as still rocking
REST_HOLD = 0.1
#: smallest rest threshold (rad), used when θ0 = 0
REST_ANGLE_MIN = 1e-6
#: hysteresis on θ for counting half-cycles (rad)
CROSS_EPS = 1e-6
#: recorded samples of the time series (at most, unless record_every says otherwise)
MAX_SAMPLES = 20000
#: Gauss–Seidel tolerance range: below ~1e-15 a relative change cannot be resolved in
#: double precision (only the cap would stop the sweeps); above 1e-2 the impulses are
#: accepted with percent errors
GS_TOL_RANGE = (1e-15, 1e-2)
#: most Gauss–Seidel sweeps per step: it converges linearly, so a problem not solved in
#: 1e6 sweeps over at most four contacts has a contraction ratio above 1 − 1e-5 and more
#: sweeps will not solve it; each would cost ~10 ms of a single step
GS_MAX_ITER_MAX = 1_000_000
#: most steps of one run: the step counter t = k Δt stays exact below 2**53
MAX_STEPS = 2.0**53


@dataclass(frozen=True)
class RunOptions:
    """The validated options of the time loop."""

    t_end: float
    n_steps: int
    stride: int
    gs_tol: float
    gs_max_iter: int
    rest_fraction: float


def _name(names, key):
    return (names or {}).get(key, key)


def check_run(
    t_end,
    dt: float,
    *,
    gs_tol=1e-8,
    gs_max_iter=5000,
    record_every=None,
    rest_fraction=REST_FRACTION,
    names: dict | None = None,
) -> RunOptions:
    """Validate the options of the time loop (`dt` already validated).

    `names` maps an argument to the name shown in messages (e.g. ``"--t-end"``).

    Raises
    ------
    InputError
        t_end not a positive number or shorter than dt; more than 2**53 steps;
        gs_tol outside `GS_TOL_RANGE`; gs_max_iter not in 1..`GS_MAX_ITER_MAX`;
        record_every not a whole number ≥ 1; rest_fraction outside (0, 1).
    """
    t_end = number(_name(names, "t_end"), t_end, low=0.0, low_open=True, what="the duration in s")
    steps = t_end / dt
    if steps > MAX_STEPS:
        raise InputError(
            f"`{_name(names, 't_end')}` = {t_end:g} s at `{_name(names, 'dt')}` = "
            f"{dt:g} s is {steps:.3g} steps, beyond the exact step counter (2**53); "
            f"raise {_name(names, 'dt')} or shorten {_name(names, 't_end')}"
        )
    n_steps = int(round(steps))
    if n_steps < 1:
        raise InputError(
            f"`{_name(names, 'dt')}` = {dt!r} s is longer than "
            f"`{_name(names, 't_end')}` = {t_end!r} s; take dt < t_end"
        )
    gs_tol = number(
        _name(names, "gs_tol"),
        gs_tol,
        low=GS_TOL_RANGE[0],
        high=GS_TOL_RANGE[1],
        what="the Gauss–Seidel relative tolerance, e.g. 1e-8",
    )
    gs_max_iter = integer(
        _name(names, "gs_max_iter"),
        gs_max_iter,
        low=1,
        high=GS_MAX_ITER_MAX,
        what="the Gauss–Seidel iteration cap, e.g. 5000",
    )
    rest_fraction = number(
        _name(names, "rest_fraction"),
        rest_fraction,
        low=0.0,
        high=1.0,
        low_open=True,
        high_open=True,
        what="a fraction of |θ0|, e.g. 0.01",
    )
    stride = (
        max(1, -(-n_steps // MAX_SAMPLES))
        if record_every is None
        else integer(
            _name(names, "record_every"), record_every, low=1, what="record every this many steps"
        )
    )
    return RunOptions(t_end, n_steps, stride, gs_tol, gs_max_iter, rest_fraction)


def estimate_cost(
    n_elements: int, dt: float, t_end: float, record_every: int | None = None, *, setup: bool = True
) -> RunCost:
    """Estimated wall time and memory of a run (`nscd.cost`), before anything is built.

    With ``setup=False`` the assembly (already done) is left out.
    """
    steps = t_end / dt  # a float: may be huge, never overflows
    rows = steps / record_every + 1 if record_every else min(steps, MAX_SAMPLES) + 1
    c = cost.estimate(n_elements, steps, rows)
    if setup:
        return c
    return RunCost(
        c.steps,
        c.seconds - cost.setup_seconds(n_elements),
        c.memory - cost.assembly_memory(n_elements),
        c.basis,
    )


def _check_cost(c: RunCost, what: str, max_hours) -> RunCost:
    return c.check(
        what, "raise dt, shorten t_end or use fewer elements", max_seconds=budget_seconds(max_hours)
    )


def _check_progress(progress):
    if progress is not None and not isinstance(progress, bool):
        raise InputError(
            f"`progress` = {progress!r}: expected True, False or None (automatic: "
            f"for runs estimated above {PROGRESS_AFTER_S:g} s)"
        )
    return progress


def _kernel(sys: System, o: RunOptions, bar: Progress | None):
    """Run the compiled loop in chunks of about `cost.CHUNK_SECONDS`, moving `bar`."""
    bm = sys.beam
    rest_angle = max(o.rest_fraction * abs(sys.theta0), REST_ANGLE_MIN)
    on_chunk = None if bar is None or not bar.shown else (lambda step: bar.update(step * sys.dt))
    return run_kernel(
        sys.qk0,
        np.zeros(3),
        sys.qe0,
        np.zeros(bm.n_dof),
        sys.mass,
        sys.inertia,
        sys.Fk,
        sys.verts,
        sys.Ainv,
        csr(bm.M),
        csr(bm.K),
        csr(bm.C),
        bm.p_self,
        bm.edof,
        bm.x_nodes,
        bm.Le,
        bm.L,
        sys.dt,
        sys.theta_method,
        sys.mu,
        sys.restitution,
        float(o.gs_tol),
        int(o.gs_max_iter),
        o.n_steps,
        int(o.stride),
        rest_angle,
        np.inf,
        CROSS_EPS,
        sys.i_mid,
        MAX_EVENTS,
        chunk=cost.chunk_steps(bm.n_elements, o.n_steps),
        on_chunk=on_chunk,
    )


def _run(sys: System, o: RunOptions, bar: Progress | None, estimated: float) -> NSCDResult:
    """The time loop on a validated system, and the result with its checks."""
    wall0 = time.perf_counter()
    out = _kernel(sys, o, bar)
    kernel_time = time.perf_counter() - wall0
    code, last, series, peaks, impacts, stats = out[:6]
    st = dict(zip(STAT_NAMES, stats))
    outcome = STATUS[int(code)]
    # a failed run is not judged: its numbers stop where the solution diverged
    checks, warnings = (
        ({}, []) if outcome == "failed" else accuracy_checks(sys, st, o.gs_max_iter, o.gs_tol)
    )
    warnings += log_warnings(peaks, impacts)
    failed = [k for k, c in checks.items() if not c["passed"]]
    status = status_of(outcome, not failed)
    message = outcome_message(outcome, int(last), sys.dt, sys.theta_method)
    if failed:
        message += f"; accuracy check failed: {', '.join(failed)} (see warnings)"
    elif st["n_gs_cap_hits"]:
        message += (
            f"; Gauss–Seidel hit its cap of {o.gs_max_iter} iterations in "
            f"{int(st['n_gs_cap_hits'])} steps, its impulses settled to "
            f"{st['max_gs_residual']:.2g} (within {GS_RESIDUAL_TOL:g})"
        )
    t_rest = (int(st["last_moving_step"]) + 1) * sys.dt
    rest = t_rest if outcome == "completed" and o.n_steps * sys.dt - t_rest >= REST_HOLD else None
    # the kernel logs the release half-cycle (peak |θ0| at t = 0) once |θ0| > CROSS_EPS;
    # below, the block starts (and stays) at rest and its release is added here
    if not (len(peaks) and abs(sys.theta0) > CROSS_EPS):
        peaks = np.vstack([[0.0, abs(sys.theta0)], peaks.reshape(-1, 2)])
    t_s, theta, thetadot, energy = series[:, 0].copy(), -series[:, 1], -series[:, 2], series[:, 6]
    qk, vk = out[6], out[7]
    events = run_events(
        outcome,
        sys.theta0,
        impacts,
        t_s,
        theta,
        thetadot,
        energy,
        int(last) * sys.dt,
        final=(float(-qk[2]), float(-vk[2])),
        detail=message,
    )
    bm = sys.beam
    return NSCDResult(
        status=status,
        outcome=outcome,
        message=message,
        t=t_s,
        theta=theta,
        thetadot=thetadot,
        X=series[:, 3].copy(),
        Y=series[:, 4].copy(),
        v_mid=series[:, 5].copy(),
        energy=energy.copy(),
        n_contacts=series[:, 7].astype(int),
        peaks=peaks[:, 1].copy(),
        peak_times=peaks[:, 0].copy(),
        events=events,
        rest_time=None if rest is None else float(rest),
        n_steps=int(last),
        max_gs_iterations=int(st["max_gs_iterations"]),
        n_gs_cap_hits=int(st["n_gs_cap_hits"]),
        max_gs_residual=float(st["max_gs_residual"]),
        n_multi_contact_steps=int(st["n_multi_contact_steps"]),
        n_slip_steps=int(st["n_slip_steps"]),
        max_slip_speed=float(st["max_slip_speed"]),
        max_energy_increase=float(st["max_energy_increase"]),
        energy_scale=float(st["energy_scale"]),
        max_penetration=float(st["max_penetration"]),
        wall_time_s=time.perf_counter() - wall0,
        kernel_time_s=kernel_time,
        estimated_s=float(estimated),
        warnings=tuple(warnings),
        checks=checks,
        params={
            "block": sys.block.name,
            "beam": sys.beam_spec.name,
            "E": bm.E,
            "n_elements": bm.n_elements,
            "dt": sys.dt,
            "t_end": o.n_steps * sys.dt,
            "theta_method": sys.theta_method,
            "mu": sys.mu,
            "restitution": sys.restitution,
            "theta0": sys.theta0,
            "x_centre": sys.x_centre,
            "gs_tol": o.gs_tol,
            "gs_max_iter": o.gs_max_iter,
            "record_every": int(o.stride),
            "rest_fraction": o.rest_fraction,
        },
        final_state=tuple(out[6:10]),
    )


def _what(block: str, dt: float, t_end: float, n_el: int) -> str:
    return f"nscd run of {block} (dt = {dt:g} s, t_end = {t_end:g} s, {n_el} elements)"


def run_system(
    sys: System,
    t_end: float,
    *,
    gs_tol: float = 1e-8,
    gs_max_iter: int = 5000,
    record_every: int | None = None,
    rest_fraction: float = REST_FRACTION,
    max_hours: float | None = None,
    progress: bool | None = None,
) -> NSCDResult:
    """Run the compiled time loop on an assembled `System` (see `simulate`)."""
    o = check_run(
        t_end,
        sys.dt,
        gs_tol=gs_tol,
        gs_max_iter=gs_max_iter,
        record_every=record_every,
        rest_fraction=rest_fraction,
    )
    progress = _check_progress(progress)
    n_el = sys.beam.n_elements
    c = _check_cost(
        estimate_cost(n_el, sys.dt, o.t_end, o.stride, setup=False),
        _what(sys.block.name, sys.dt, o.t_end, n_el),
        max_hours,
    )
    with Progress(
        o.n_steps * sys.dt, f"nscd {sys.block.name}", show=progress, estimate=c.seconds
    ) as bar:
        return _run(sys, o, bar, c.seconds)


def simulate(
    block,
    beam="beam_mudric2024",
    *,
    theta0: float,
    dt: float,
    t_end: float,
    E: float | None = None,
    n_elements: int | None = None,
    theta_method: float = 1.0,
    mu: float | None = None,
    restitution: float = 0.0,
    x_centre: float | None = None,
    gs_tol: float = 1e-8,
    gs_max_iter: int = 5000,
    record_every: int | None = None,
    rest_fraction: float = REST_FRACTION,
    max_hours: float | None = None,
    progress: bool | None = None,
) -> NSCDResult:
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
        Release angle (rad); > 0 rests on the right corner; ``|θ0|`` < the block's α.
    dt, t_end : float
        Time step and duration (s).
    E : float, optional
        Young's modulus (Pa), overriding the beam's (see `flexible_modulus`);
        from `nscd.min_modulus` (midspan deflection L/30) to `nscd.model.E_MAX`.
    n_elements : int, optional
        Number of elements, 3 to `nscd.cost.MAX_ELEMENTS`, overriding the beam's default.
    theta_method : float
        θ of the θ-method in [0, 1] (paper 002: 1, backward Euler).
    mu, restitution : float
        Friction coefficient ≥ 0 (default: the beam's) and Newton's e in [0, 1] (default 0).
    x_centre : float, optional
        Abscissa of the block's centre when upright (default: midspan).
    gs_tol, gs_max_iter : float, int
        Gauss–Seidel tolerance (relative change of the impulses, 1e-15 to
        1e-2) and cap (1 to 1e6).
    record_every : int, optional
        Record the series every this many steps (default: at most 20 000 samples).
    rest_fraction : float
        The block is at rest once ``|θ|`` stays below this fraction of ``|θ0|``.
    max_hours : float, optional
        The budget: a run estimated to take longer (`nscd.cost`) is refused
        (default one hour; ``math.inf`` for none).
    progress : bool, optional
        Progress bar on stderr: True, False, or None (default) for runs
        estimated above a few seconds.

    Returns
    -------
    NSCDResult
        With `status` "inaccurate" when an accuracy check failed (module docstring).

    Raises
    ------
    InputError
        For bad input (see `nscd.model.check_inputs` and `check_run`), and for
        a run over the budget or the memory.
    """
    inp = check_inputs(
        block,
        beam,
        theta0=theta0,
        dt=dt,
        E=E,
        n_elements=n_elements,
        theta_method=theta_method,
        mu=mu,
        restitution=restitution,
        x_centre=x_centre,
    )
    o = check_run(
        t_end,
        inp.dt,
        gs_tol=gs_tol,
        gs_max_iter=gs_max_iter,
        record_every=record_every,
        rest_fraction=rest_fraction,
    )
    progress = _check_progress(progress)
    c = _check_cost(
        estimate_cost(inp.n_elements, inp.dt, o.t_end, o.stride),
        _what(inp.block.name, inp.dt, o.t_end, inp.n_elements),
        max_hours,
    )
    return execute(inp, o, progress=progress, desc=f"nscd {inp.block.name}", estimated=c.seconds)


def execute(
    inp, o: RunOptions, *, progress: bool | None, desc: str, estimated: float
) -> NSCDResult:
    """Assemble and run validated, costed inputs, with a progress bar labelled `desc`."""
    with Progress(o.n_steps * inp.dt, desc, show=progress, estimate=estimated) as bar:
        return _run(assemble(inp), o, bar, estimated)
