"""Event functions of each phase and what happens when one fires (paper 001, Eqs 8–17)."""

from __future__ import annotations

from multimass.impact_models.models import next_phase_is_rocking

from . import kinematics as kin
from ._phase import ActiveForce, guard
from .response import Event

__all__ = ["phase_events", "handle_event"]


def phase_events(run, delay: float) -> tuple[list[str], list]:
    """Names and solve_ivp event functions of the current phase of `run`."""
    st, mdl, n, t0 = run.st, run.mdl, run.st.n, run.t
    names, events = [], []

    def add(name, fn, direction, terminal=True, quiet=None, hold=delay):
        if quiet is None:
            fn.terminal, fn.direction = terminal, direction
            events.append(fn)
        else:
            events.append(guard(fn, t0, hold, quiet, terminal, direction))
        names.append(name)

    if run.phase == 0:
        m_ref = st.m_t * st.g * st.B
        l_ref = st.J_p * run.theta_dot_min
        hold = max(delay, run.hold_until - t0)
        for side, name in ((1, "uplift_right"), (-1, "uplift_left")):

            def uplift(t, y, side=side):
                u, ud = y[:n], y[n + 1 : 2 * n + 1]
                M_o, res_r, res_l = kin.full_contact_moments(st, u, ud, run.ag(t))
                L = float(st.H @ (st.m * ud))  # L_p^fc
                moment = (-side * M_o - (res_r if side > 0 else res_l)) / m_ref
                return min(moment, side * L / l_ref)  # paper 001, Eq 8

            add(name, uplift, +1.0, quiet=-1.0, hold=hold)
        return names, events

    s = run.phase
    add("zero", lambda t, y: s * y[n], -1.0, quiet=1.0)  # θ = 0
    add("overturn", lambda t, y: s * y[n] - run.overturn, +1.0, quiet=-1.0)
    add("peak", lambda t, y: y[2 * n + 1], 0.0, terminal=False)  # θ̇ = 0
    model = run.model
    if model.has_force and run.force is None:
        side_imp, r = -s, run.r_pending
        l_ref = st.J_p * run.theta_dot_min

        def activate(t, y):
            u, th, ud, thd = mdl.split(y)
            E = kin.total_energy(st, s, u, th, ud, thd)
            width = model.width(E, r, st.B, st.m_t, st.g, thd)  # paper 001, Eq 15
            theta_th = model.threshold(width)
            L = kin.angular_momentum_new_pivot(st, u, ud, thd)
            return max(
                abs(th) / theta_th - 1.0,  # paper 001, Eq 16
                -side_imp * L / l_ref,
                (run.theta_dot_min - side_imp * thd) / run.theta_dot_min,
            )

        add("activate", activate, -1.0, quiet=1.0)
    elif run.force is not None:
        limit = model.release * abs(run.force.theta_i)
        add("deactivate", lambda t, y: s * y[n] - limit, +1.0, quiet=-1.0)  # paper 001, Eq 17
    return names, events


def handle_event(run, name: str) -> None:
    """Apply the transition of the terminal event `name` at (run.t, run.y)."""
    n = run.st.n
    u, th, ud, thd = run.mdl.split(run.y)
    if name in ("uplift_right", "uplift_left"):
        run.y[n], run.y[2 * n + 1] = 0.0, 0.0  # paper 001, Eq 8: θ̇⁺ = 0, u̇⁺ = u̇⁻
        run.start_rocking(1 if name == "uplift_right" else -1, "uplift")
    elif name == "overturn":
        run.events.append(
            Event(
                "overturn", run.t, run.phase, run.phase, theta=float(th), thetadot_minus=float(thd)
            )
        )
        run.status, run.message = "overturned", f"|θ| reached {run.overturn:.4g} rad"
        run.recorder.end_phase(run.t, run.y, run.phase)
        run.t = run.t_end
    elif name == "activate":
        _activate(run, u, th, ud, thd)
    elif name == "deactivate":
        run.events.append(
            Event(
                "dd_deactivate",
                run.t,
                run.phase,
                run.phase,
                theta=float(th),
                thetadot_minus=float(thd),
                restitution=run.force.r,
                detail="moved away from impact (Eq 17)",
            )
        )
        run.force = None
    elif name == "zero":
        _at_zero(run, u, ud, thd)
    else:  # pragma: no cover - every terminal event has a handler
        raise RuntimeError(f"unhandled event {name!r}")


def _activate(run, u, th, ud, thd):
    st, model, s = run.st, run.model, run.phase
    r = run.r_pending
    E = kin.total_energy(st, s, u, th, ud, thd)
    width = model.width(E, r, st.B, st.m_t, st.g, thd)  # paper 001, Eq 15
    theta_i = s * model.threshold(width)  # paper 001, Eq 16
    run.force = ActiveForce(E_ini=E, r=r, n=width, theta_i=theta_i, thetadot_i=float(thd))
    run.events.append(
        Event(
            "dd_activate",
            run.t,
            s,
            s,
            theta=float(th),
            thetadot_minus=float(thd),
            restitution=r,
            detail=f"n = {width:.4g}, theta_i = {theta_i:.4g}",
        )
    )


def _at_zero(run, u, ud, thd):
    """End of a half-cycle: paper 001, Eq 9, then Eq 11/12 or Eq 10."""
    st, n, side_old = run.st, run.st.n, run.phase
    if run.force is not None:
        run.events.append(
            Event(
                "dd_deactivate",
                run.t,
                side_old,
                side_old,
                thetadot_minus=float(thd),
                restitution=run.force.r,
                detail="θ = 0 (Eq 17)",
            )
        )
    r_used = run.force.r if run.force is not None else None
    run.force = None
    run.y[n] = 0.0
    L_new = kin.angular_momentum_new_pivot(st, u, ud, thd)
    r = r_used
    if getattr(run.model, "resolves_impact", False):  # the Poisson LCP decides
        tr = run.model.impact_at_zero(st, side_old, u, ud, float(thd), run.theta_dot_min)
        if tr.phase is None:
            run.recorder.end_phase(run.t, run.y, side_old)
            run.events.append(
                Event(
                    "failed",
                    run.t,
                    side_old,
                    side_old,
                    thetadot_minus=float(thd),
                    detail=f"the LCP predicts a bounce (flight); {tr.detail}",
                )
            )
            run.status = "failed"
            run.message = (
                "the Poisson LCP predicts flight (the impacting corner bounces off); "
                "the multi-mass engine has no flight phase: use eps_p = 0, or "
                "multimass.poisson_block for a rigid block"
            )
            return
    else:
        if not run.model.has_force:
            side_new = -side_old
            will_rock = next_phase_is_rocking(side_new, L_new, float(thd), run.theta_dot_min)
            r = run.draw(side_new) if will_rock else 1.0
        tr = run.model.at_zero(
            st.H, side_old, L_new, ud, float(thd), r if r is not None else 1.0, run.theta_dot_min
        )
    before = run.energy(side_old, run.y)
    y_new = run.y.copy()
    y_new[n + 1 : 2 * n + 1] = tr.udot
    y_new[2 * n + 1] = tr.thetadot
    after = run.energy(tr.phase, y_new)
    run.recorder.end_phase(run.t, run.y, side_old)
    run.recorder.add_loss(before - after)
    run.events.append(
        Event(
            tr.kind,
            run.t,
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
    run.phase, run.y = tr.phase, y_new
    run.recorder.start_phase(tr.phase, run.t, y_new)
    if tr.phase and run.model.has_force:
        run.r_pending = run.draw(-tr.phase)
    if run.note_transition(run.t):
        run.trip_guard()
