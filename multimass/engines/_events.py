"""Event functions of each phase and what happens when one fires (paper 001, Eqs 8–17).

`phase_events` gives the terminal and non-terminal events of a state's phase;
`handle_event` applies the transition of the event that fired and returns the
next `multimass.engines._run.State` (the loop's record — events, recorder, draws — is
written through the loop `run`; the state itself is never changed in place).
"""

from __future__ import annotations

from multimass.impact_models import gaussian_force as gf
from multimass.impact_models.models import next_phase_is_rocking

from ..model import kinematics as kin
from ..model._phase import ActiveForce, guard
from ..result import Event

__all__ = [
    "phase_events", "handle_event", "overturn_message", "activation_detail", "chatter_detail",
    "DETAIL_AWAY", "DETAIL_AT_ZERO",
]  # fmt: skip


#: The details of a Dirac-delta force's deactivation (Eq 17): moving away from the impact,
#: or at θ = 0.
DETAIL_AWAY, DETAIL_AT_ZERO = "moved away from impact (Eq 17)", "θ = 0 (Eq 17)"


def activation_detail(width: float, theta_i: float) -> str:
    """The detail of a Dirac-delta force's activation: its width n and threshold θ_i."""
    return f"n = {width:.4g}, theta_i = {theta_i:.4g}"


def chatter_detail(count: int, window: float) -> str:
    """The detail of a run the chattering guard stopped."""
    return f"{count} transitions within {window:g} s"


def overturn_message(angle: float) -> str:
    """The message of a run that overturned at `angle` (rad)."""
    return f"|θ| reached {angle:.4g} rad"


def phase_events(run, s, delay: float) -> tuple[list[str], list]:
    """Names and solve_ivp event functions of the phase of state `s` in the loop `run`."""
    st, mdl, n, t0 = run.st, run.mdl, run.st.n, s.t
    names, events = [], []

    def add(name, fn, direction, terminal=True, quiet=None, hold=delay):
        if quiet is None:
            fn.terminal, fn.direction = terminal, direction
            events.append(fn)
        else:
            events.append(guard(fn, t0, hold, quiet, terminal, direction))
        names.append(name)

    if s.phase == 0:
        m_ref = st.m_t * st.g * st.B
        l_ref = st.J_p * run.thetadot_min
        hold = max(delay, s.hold_until - t0)
        for side, name in ((1, "uplift_right"), (-1, "uplift_left")):

            def uplift(t, y, side=side):
                u, ud = y[:n], y[n + 1 : 2 * n + 1]
                return kin.uplift_margin(st, side, u, ud, run.ag(t), m_ref, l_ref)

            add(name, uplift, +1.0, quiet=-1.0, hold=hold)
        return names, events

    side = s.phase
    add("zero", lambda t, y: side * y[n], -1.0, quiet=1.0)  # θ = 0
    add("overturn", lambda t, y: side * y[n] - run.overturn, +1.0, quiet=-1.0)
    add("peak", lambda t, y: y[2 * n + 1], 0.0, terminal=False)  # θ̇ = 0
    model = run.model
    if model.has_force and s.force is None:
        r = s.r_pending
        l_ref = st.J_p * run.thetadot_min

        def activate(t, y):
            u, th, ud, thd = mdl.split(y)
            E = kin.total_energy(st, side, u, th, ud, thd)
            theta_i = model.threshold(model.width(E, r, st.B, st.m_t, st.g, thd))
            L = kin.angular_momentum_new_pivot(st, u, ud, thd)
            return gf.activation_margin(th, theta_i, side, L, l_ref, thd, run.thetadot_min)

        add("activate", activate, -1.0, quiet=1.0)
    elif s.force is not None:
        limit = model.release_angle(s.force.theta_i)
        add("deactivate", lambda t, y: gf.deactivation_margin(side, y[n], limit), +1.0, quiet=-1.0)
    return names, events


def handle_event(run, s, name: str):
    """The state after the transition of the terminal event `name` at state `s`."""
    n = run.st.n
    u, th, ud, thd = run.mdl.split(s.y)
    if name in ("uplift_right", "uplift_left"):
        y = s.y.copy()
        y[n], y[2 * n + 1] = 0.0, 0.0  # θ̇⁺ = 0, u̇⁺ = u̇⁻ (paper 001, Sec 2.3)
        return run.start_rocking(s.but(y=y), 1 if name == "uplift_right" else -1, "uplift")
    if name == "overturn":
        run.events.append(
            Event("overturn", s.t, s.phase, s.phase, theta=float(th), thetadot_minus=float(thd))
        )
        run.recorder.end_phase(s.t, s.y, s.phase)
        # the run ends at the overturn: no row, no ground motion, is recorded past it
        return s.but(status="overturned", message=overturn_message(run.overturn))
    if name == "activate":
        return _activate(run, s, th, thd)
    if name == "deactivate":
        run.events.append(
            Event(
                "dd_deactivate",
                s.t,
                s.phase,
                s.phase,
                theta=float(th),
                thetadot_minus=float(thd),
                restitution=s.force.r,
                detail=DETAIL_AWAY,
            )
        )
        return s.but(force=None)
    if name == "zero":
        return _at_zero(run, s, u, ud, thd)
    raise RuntimeError(f"unhandled event {name!r}")  # pragma: no cover - every event has one


def _activate(run, s, th, thd):
    st, model, side = run.st, run.model, s.phase
    r = s.r_pending
    E = run.energy(side, s.y)
    width = model.width(E, r, st.B, st.m_t, st.g, thd)
    theta_i = side * model.threshold(width)
    run.events.append(
        Event(
            "dd_activate",
            s.t,
            side,
            side,
            theta=float(th),
            thetadot_minus=float(thd),
            restitution=r,
            detail=activation_detail(width, theta_i),
        )
    )
    force = ActiveForce(E_ini=E, r=r, n=width, theta_i=theta_i, thetadot_i=float(thd))
    return s.but(force=force)


def _at_zero(run, s, u, ud, thd):
    """End of a half-cycle: paper 001, Eq 9, then Eq 11/12 or Eq 10."""
    st, n, side_old = run.st, run.st.n, s.phase
    if s.force is not None:
        run.events.append(
            Event(
                "dd_deactivate",
                s.t,
                side_old,
                side_old,
                thetadot_minus=float(thd),
                restitution=s.force.r,
                detail=DETAIL_AT_ZERO,
            )
        )
    r_used = s.force.r if s.force is not None else None
    y = s.y.copy()
    y[n] = 0.0
    s = s.but(y=y, force=None)
    L_new = run.pivot_momentum(s.y)
    r = r_used
    if getattr(run.model, "resolves_impact", False):  # the Poisson LCP decides
        tr = run.model.impact_at_zero(st, side_old, u, ud, float(thd), run.thetadot_min)
        if tr.phase is None:
            run.recorder.end_phase(s.t, y, side_old)
            run.events.append(
                Event(
                    "failed",
                    s.t,
                    side_old,
                    side_old,
                    thetadot_minus=float(thd),
                    detail=f"the LCP predicts a bounce (flight); {tr.detail}",
                )
            )
            return s.but(
                status="failed",
                message=(
                    "the Poisson LCP predicts flight (the impacting corner bounces off); "
                    "the multi-mass engine has no flight phase: use eps_p = 0, or "
                    "multimass.engines.poisson_block for a rigid block"
                ),
            )
    else:
        if not run.model.has_force:
            side_new = -side_old
            will_rock = next_phase_is_rocking(side_new, L_new, float(thd), run.thetadot_min)
            r = run.draw(side_new, y) if will_rock else 1.0
        tr = run.model.at_zero(
            st.H, side_old, L_new, ud, float(thd), r if r is not None else 1.0, run.thetadot_min
        )
    before = run.energy(side_old, y)
    y_new = y.copy()
    y_new[n + 1 : 2 * n + 1] = tr.udot
    y_new[2 * n + 1] = tr.thetadot
    after = run.energy(tr.phase, y_new)
    run.recorder.end_phase(s.t, y, side_old)
    run.recorder.add_loss(before - after)
    run.events.append(
        Event(
            tr.kind,
            s.t,
            side_old,
            tr.phase,
            theta=0.0,
            thetadot_minus=float(thd),
            thetadot_plus=float(tr.thetadot),
            restitution=tr.restitution if tr.restitution is not None else r_used,
            energy_change=after - before,
            detail=tr.detail,
        )
    )
    run.recorder.start_phase(tr.phase, s.t, y_new)
    r_next = run.draw(-tr.phase, y_new) if tr.phase and run.model.has_force else s.r_pending
    s = s.but(phase=tr.phase, y=y_new, r_pending=r_next)
    return run.trip_guard(s) if run.note_transition(s.t) else s
