"""Run paper 004's Newmark integrator for `simulate` and return the engine's `Response`."""

from __future__ import annotations

import math
import time

import numpy as np
import pandas as pd

from multimass.impact_models import Classical, ImpactContext

from .errors import InputError
from .newmark import newmark_block
from .response import Event, Response

__all__ = ["simulate_newmark"]

_KINDS = {
    "uplift": "uplift",
    "impact": "impact",
    "full_contact": "full_contact",
    "overturn": "overturn",
    "rest": "rest",
}


def _restitution(st, model, rng):
    """The impact model's restitution source as newmark_block's callable."""
    count = [0]

    def r(thetadot_minus, side_new):
        ctx = ImpactContext(st, int(side_new), np.zeros(0), count[0], rng)
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
    theta_dot_min,
    overturn_angle,
    stop_when_safe,
    options,
    floor: float = 0.0,
) -> Response:
    """Rigid block by Newmark + Newton–Raphson (paper 004, Eqs 3–8) as a `Response`.

    `floor` is the smallest energy scale of the ledger (`multimass.checks.energy_floor`).
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
        thetadot_min=theta_dot_min,
        rest_after=duration if stop_when_safe and math.isfinite(duration) else None,
    )
    wall = time.perf_counter() - wall
    return _to_response(st, res, ag, wall, options, t_end, floor)


def _to_response(st, res, ag_fn, wall, options, t_end, floor) -> Response:
    t, th, thd = res.t, res.theta, res.thetadot
    events = [Event("release", 0.0, int(np.sign(th[0])), int(np.sign(th[0])), theta=float(th[0]))]
    side = int(np.sign(th[0]))
    for e in res.events:
        kind = _KINDS.get(e.kind, e.kind)
        loss = (
            0.5 * st.J_p * (e.thetadot_minus**2 - e.thetadot_plus**2)
            if kind in ("impact", "full_contact")
            else 0.0
        )
        events.append(
            Event(
                kind,
                e.time,
                side,
                e.side,
                theta=e.theta,
                thetadot_minus=e.thetadot_minus,
                thetadot_plus=e.thetadot_plus,
                restitution=e.restitution,
                energy_change=-loss,
            )
        )
        side = e.side
    # phase of each row: the side of θ, or of the pivot just taken at θ = 0
    phase = np.sign(th).astype(int)
    for e in res.events:
        if e.kind in ("uplift", "impact", "full_contact"):
            phase[t == e.time] = e.side
    ag = np.asarray(ag_fn(t), dtype=float)
    # rigid body (kinematics.py with u = 0): T = ½ J_p θ̇², V = g (h (cos θ − 1) + s B m_t sin θ),
    # ground power −ü_g θ̇ (h cos θ + s B m_t sin θ), with h = m0 h0 the static moment
    height, lever = st.static_moment, phase * st.B * st.m_t
    c, sn = np.cos(th), np.sin(th)
    T = 0.5 * st.J_p * thd**2
    V = np.where(phase == 0, 0.0, st.g * (height * (c - 1.0) + lever * sn))
    P = np.where(phase == 0, 0.0, -ag * thd * (height * c + lever * sn))
    Wg = np.concatenate([[0.0], np.cumsum(0.5 * (P[1:] + P[:-1]) * np.diff(t))])
    losses = np.zeros_like(t)
    for e in events:
        if e.kind in ("impact", "full_contact"):
            losses[t >= e.time] -= e.energy_change
    E = T + V
    balance = E + losses - Wg - E[0]
    ref = max(abs(E[0]), float(np.max(np.abs(Wg))), floor, 1e-300)
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
    status = {"rest": "completed"}.get(res.status, res.status)
    return Response(
        structure_name=st.name,
        status=status,
        message=res.message,
        series=series,
        events=events,
        peaks=np.asarray(res.peaks, dtype=float),
        peak_times=np.full(len(res.peaks), np.nan),
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
    )
