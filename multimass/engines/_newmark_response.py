"""Run paper 004's Newmark integrator for `simulate` and return the engine's `Response`."""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING

import numpy as np

from multimass.impact_models import Classical, ImpactContext

from ..checks import energy_scale
from ..errors import InputError
from ..model import equations as eq
from ..response import Response
from ..result import status_of
from .newmark import newmark_block

if TYPE_CHECKING:
    pass

__all__ = ["simulate_newmark"]


def _restitution(st, model, rng):
    """The impact model's restitution source as newmark_block's callable."""
    count = [0]

    def r(thetadot_minus, side_new):
        ctx = ImpactContext(
            st, int(side_new), np.zeros(0), count[0], rng, count[0]
        )  # a draw per impact
        count[0] += 1
        return float(model.restitution.value(ctx))

    return r


def check_newmark(st, model) -> None:
    """Raise InputError unless paper 004's Newmark integrator applies (rigid block, classical)."""
    if st.n != 0:
        raise InputError(
            f"`integrator` = 'newmark' integrates rigid blocks only; {st.name!r} has "
            f"{st.n} elastic nodes: use integrator='solve_ivp'"
        )
    if not isinstance(model, Classical):
        raise InputError(
            f"`integrator` = 'newmark' implements classical impacts (paper 004); "
            f"impact {getattr(model, 'name', model)!r} needs integrator='solve_ivp'"
        )


def simulate_newmark(
    st,
    model,
    excitation,
    t_end,
    *,
    dt,
    seed,
    thetadot_min,
    overturn_angle,
    stop_when_safe,
    options,
    floor: float = 0.0,
) -> Response:
    """Rigid block by Newmark + Newton–Raphson (paper 004, Eqs 3–8) as a `Response`.

    `floor` is the smallest energy scale of the ledger (`multimass.checks.scale_floor`).
    """
    check_newmark(st, model)
    theta0 = float(getattr(excitation, "theta0", 0.0) or 0.0)
    duration = float(getattr(excitation, "duration", math.inf))
    ag = getattr(excitation, "acceleration", excitation)
    wall = time.perf_counter()
    res = newmark_block(
        st,
        ag,
        t_end,
        dt=dt,
        restitution=_restitution(st, model, np.random.default_rng(seed)),
        theta0=theta0,
        overturn_angle=overturn_angle,
        thetadot_min=thetadot_min,
        rest_after=duration if stop_when_safe and math.isfinite(duration) else None,
    )
    wall = time.perf_counter() - wall
    return _to_response(st, res, wall, options, t_end, floor)


def _to_response(st, res, wall, options, t_end, floor) -> Response:
    """The `Response` of a `NewmarkResult`: its events (`multimass.result.Event` already,
    a "release" first, with their energy changes); the ledger as the
    engine's (`multimass.model.equations` with no elastic nodes). The status is the physical
    one: `simulate` judges the ledger with its own `energy_tol` (`multimass.checks.judge`)."""
    t, th, thd = res.t, res.theta, res.thetadot
    events = list(res.events)
    # phase of each row: the side of θ, or of the pivot just taken at θ = 0
    phase = np.sign(th).astype(int)
    for e in res.events:
        if e.kind in ("uplift", "impact", "full_contact"):
            phase[t == e.time] = e.phase_after
    ag = res.ag
    # the rigid body's ledger: multimass.model.equations with no elastic nodes (u = 0)
    h, lever = st.static_moment, eq.lever_arm(phase, st.B, st.m_t, 0.0)
    c, sn = np.cos(th), np.sin(th)
    T = eq.kinetic_energy(0.0, 0.0, eq.rocking_inertia(st.J_p, 0.0, phase, st.B, 0.0), thd)
    V = np.where(phase == 0, 0.0, eq.gravitational_energy(st.g, h, lever, c, sn))
    P = np.where(phase == 0, 0.0, eq.ground_power(ag, 0.0, thd, h, lever, c, sn))
    Wg = np.concatenate([[0.0], np.cumsum(0.5 * (P[1:] + P[:-1]) * np.diff(t))])
    losses = np.zeros_like(t)
    for e in events:
        if e.kind in ("impact", "full_contact"):
            losses[t >= e.time] -= e.energy_change
    E = T + V
    balance = E + losses - Wg - E[0]
    ref = energy_scale(E[0], float(np.max(np.abs(Wg))), 0.0, floor)
    import pandas as pd  # here: a run summarised without tables needs no pandas

    series = pd.DataFrame(
        {
            "t": t,
            "phase": phase,
            "theta": th,
            "thetadot": thd,
            "F_i": 0.0,
            "ag": ag,
            "kinetic": T,
            "gravitational": V,
            "elastic": 0.0,
            "damping": 0.0,
            "impact": losses,
            "ground_work": Wg,
            "balance_error": balance,
        }
    )
    return Response(
        structure_name=st.name,
        status=status_of(res.outcome),
        message=res.message,
        series=series,
        events=events,
        peaks=np.asarray(res.peaks, dtype=float),
        peak_times=np.asarray(res.peak_times, dtype=float),
        energy_reference=ref,
        energy_balance_error=float(np.max(np.abs(balance)) / ref),
        wall_time_s=wall,
        options=options
        | {
            "integrator": "newmark",
            "dt": res.dt,
            "n_steps": res.n_steps,
            "max_newton_iterations": res.max_newton_iterations,
        },
        n_rhs=res.n_newton_iterations,
        t_end=t_end,
        outcome=res.outcome,
    )
