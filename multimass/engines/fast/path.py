"""`FastPath`: the compiled replacement of `PhaseLoop.integrate` (one phase segment).

`multimass.simulate` keeps its Python phase loop — uplift, impacts, the
restitution draws, the chattering guard and the recorder are the reference
code — and, with ``backend="compiled"``, hands each phase segment to
`FastPath.integrate` (a column whose parts the whole-run kernel knows runs that loop
in one compiled call instead, `multimass.engines.fast.column_trace`), which builds the same events as
`multimass.engines._events.phase_events` (codes, directions, quiet guards), runs the
compiled kernel and feeds the recorder and the event handler exactly as the
solve_ivp segment would.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from multimass.impact_models.models import DiracDelta

from ...errors import InputError
from ...result import Event
from .._events import handle_event
from . import _maths as mx
from ._contact_kernel import contact_phase
from ._exp_kernel import exp_phase, new_cache
from ._kernel import integrate_phase
from ._rk import EVENT, FAILED, METHOD_CODES
from .contact_modes import ContactModes
from .excitation import encode
from .rocking_modes import RockingModes

__all__ = ["FastPath", "check_model", "event_params", "ROCKING_EVENTS", "EXPONENTIAL"]

#: The method name of the exponential integrator of the rocking phases (`._exp_kernel`);
#: full contact, where it is not solved in closed form, integrates with DOP853.
EXPONENTIAL = "exponential"

_FAIL_MESSAGE = "Required step size is less than spacing between numbers."
_NONE = np.empty(0)
_RTOL_MIN = 100 * np.finfo(float).eps  # as solve_ivp's floor on rtol


def _table(*rows):
    """(names, codes, directions, terminal, quiet values, guarded) of a list of events."""
    names, codes, dirs, term, quiet, guarded = zip(*rows)
    return (
        list(names),
        np.array(codes, dtype=np.int64),
        np.array(dirs, dtype=np.float64),
        np.array(term, dtype=np.int64),
        np.array(quiet, dtype=np.float64),
        np.array(guarded),
    )


# The events of each phase, in the order of multimass.engines._events.phase_events:
# name, code, direction, terminal, quiet value, held quiet after a restart
_ROCKING = [
    ("zero", mx.EV_ZERO, -1.0, 1, 1.0, True),  # θ = 0
    ("overturn", mx.EV_OVERTURN, 1.0, 1, -1.0, True),
    ("peak", mx.EV_PEAK, 0.0, 0, 0.0, False),
]  # θ̇ = 0
_PEAK = 2
#: (names, codes, directions, terminal, quiet values, guarded) of a rocking phase without a force
ROCKING_EVENTS = _table(*_ROCKING)
_EVENTS = {
    "contact": _table(
        ("uplift_right", mx.EV_UPLIFT_RIGHT, 1.0, 1, -1.0, True),  # equations.uplift_margin
        ("uplift_left", mx.EV_UPLIFT_LEFT, 1.0, 1, -1.0, True),
    ),
    "rocking": ROCKING_EVENTS,
    # gaussian_force.activation_margin, gaussian_force.deactivation_margin
    "activate": _table(*_ROCKING, ("activate", mx.EV_ACTIVATE, -1.0, 1, 1.0, True)),
    "deactivate": _table(*_ROCKING, ("deactivate", mx.EV_DEACTIVATE, 1.0, 1, -1.0, True)),
}
# 0 where an event is held quiet after a restart, −∞ where it never is: t_on + this are
# the guard ends (np.where(guarded, t_on, −∞) of a t_on > 0, in one addition)
_QUIET_OFFSETS = {key: np.where(table[5], 0.0, -math.inf) for key, table in _EVENTS.items()}


def event_params(st, thetadot_min: float, overturn: float, dd=(0.0, 0.0, 0.0)) -> np.ndarray:
    """`ep` of the event functions (`._maths` ``EP_*``) before the phase's own entries.

    `dd` is the Dirac-delta model's (C_p, n_min, z), zeros without a force.
    """
    ep = np.zeros(mx.EP_SIZE)
    ep[mx.EP_TDMIN], ep[mx.EP_OVERTURN] = thetadot_min, overturn
    ep[mx.EP_CP], ep[mx.EP_NMIN], ep[mx.EP_Z] = dd
    ep[mx.EP_MREF] = st.m_t * st.g * st.B
    ep[mx.EP_LREF] = st.J_p * thetadot_min
    return ep


def check_model(model) -> None:
    """Raise InputError unless the compiled kernels reproduce `model`'s force and events.

    Models without a force (the classical impact, any transition map) are
    fine: their transitions run in Python. A model with a force must be the
    Gaussian `DiracDelta` of paper 001 (Eqs 14–17) with its own formulas.
    """
    if not getattr(model, "has_force", False):
        return
    tp = type(model)
    if not (
        isinstance(model, DiracDelta)
        and tp.width is DiracDelta.width
        and tp.threshold is DiracDelta.threshold
        and tp.release_angle is DiracDelta.release_angle
    ):
        raise InputError(
            f"`impact` = {getattr(model, 'name', tp.__name__)!r}: backend='compiled' "
            "knows the Gaussian Dirac-delta force of paper 001 (Eqs 14–17) only; "
            "use backend='scipy' for this impact model"
        )


@dataclass(frozen=True, eq=False)
class _Segment:
    """What `Recorder.segment` reads from a solve_ivp result."""

    t: np.ndarray
    y: np.ndarray
    t_events: list
    y_events: list


@dataclass(eq=False)
class FastPath:
    """Arrays of one simulation laid out for the compiled kernels.

    Build it with `FastPath.of`; `integrate` replaces one solve_ivp call.
    """

    method: str
    code: int
    m: np.ndarray
    H: np.ndarray
    K: np.ndarray
    C: np.ndarray
    mp: np.ndarray
    kind: int
    par: np.ndarray
    samples: np.ndarray
    delay: float
    dd: tuple = field(default=(0.0, 0.0, 0.0))  # C_p, n_min, z
    contact: ContactModes | None = None  # full contact in closed form (`._contact_kernel`)
    rocking: RockingModes | None = None  # rocking by the exponential method (`._exp_kernel`)
    exp_cache: tuple | None = None  # its φ-tables and last step, kept between phases
    # the Runge–Kutta kernel's next step in full contact and while rocking, kept between
    # phases (`._kernel.integrate_phase`'s hint)
    rk_hints: tuple = field(default_factory=lambda: (np.zeros(2), np.zeros(2)))

    @classmethod
    def of(
        cls, st, model, excitation, method, delay: float, full_contact: str = "auto"
    ) -> FastPath:
        """Validate that the compiled path can run this case, and lay out its arrays.

        `method` is a key of `METHOD_CODES` or `EXPONENTIAL` (the rocking phases of a
        column by `._exp_kernel`, its full contact as with DOP853). `full_contact` is
        "exact" (`._contact_kernel`: a record or free vibration, a column with
        classical damping), "integrate" (the Runge–Kutta pair, as every other phase)
        or "auto" (exact where it applies).

        Raises
        ------
        InputError
            For an excitation, impact model or method the kernels do not know,
            ``full_contact="exact"`` where it does not apply, or the exponential method
            for a rigid block (no elastic modes).
        """
        if not (isinstance(method, str) and (method in METHOD_CODES or method == EXPONENTIAL)):
            raise InputError(
                f"`method` = {getattr(method, '__name__', method)!r}: backend='compiled' "
                f"integrates with the explicit pairs {', '.join(METHOD_CODES)} or "
                f"{EXPONENTIAL!r}; use backend='scipy' for implicit methods"
            )
        check_model(model)
        rocking = None
        if method == EXPONENTIAL:
            rocking = RockingModes.of(st)
            if isinstance(rocking, str):
                raise InputError(
                    f"`method` = {EXPONENTIAL!r}: {st.name} cannot use it: {rocking}; "
                    "use method='DOP853'"
                )
        kind, par, samples = encode(excitation)
        dd = (
            (float(model.C_p), float(model.n_min), float(model.z))
            if model.has_force
            else (0.0, 0.0, 0.0)
        )
        contact = None
        if full_contact != "integrate":
            contact = (
                ContactModes.of(st)
                if kind in (mx.EXC_RECORD, mx.EXC_NONE)
                else "its excitation is not a record or a free release (ü_g must be "
                "piecewise linear in time)"
            )
            if isinstance(contact, str):
                if full_contact == "exact":
                    raise InputError(
                        f"`full_contact` = 'exact': {st.name} cannot use it: {contact}; "
                        "use full_contact='auto' or 'integrate'"
                    )
                contact = None
        arr = lambda a: np.array(a, dtype=np.float64, order="C")  # writable C copies
        return cls(
            method=method,
            code=METHOD_CODES[method if rocking is None else "DOP853"],
            m=arr(st.m),
            H=arr(st.H),
            K=arr(st.K).reshape(st.n, st.n),
            C=arr(st.C).reshape(st.n, st.n),
            mp=mx.model_params(st),
            kind=int(kind),
            par=arr(par),
            samples=arr(samples),
            delay=float(delay),
            dd=dd,
            contact=contact,
            rocking=rocking,
        )

    def _hint(self, phase: int) -> np.ndarray:
        """`integrate_phase`'s hint: a column's segments start at the step the last one
        of the same kind ended with; a rigid block's start from their own guess, as
        solve_ivp's do (the same steps, to the right-hand side call)."""
        return self.rk_hints[0 if phase == 0 else 1] if self.m.size else np.zeros(1)

    # -- the run's energies and momenta, as the compiled whole runs form them --------------------
    def energy(self, phase: int, y: np.ndarray) -> float:
        """T + V_g + U of state `y` in `phase` (`multimass.model.kinematics.total_energy`, compiled:
        the sums of `._column_kernel`, so that a whole compiled run is this path's, bit for bit)."""
        return mx._total_energy(float(phase), y, self.m, self.H, self.K, self.mp)

    def pivot_momentum(self, y: np.ndarray) -> float:
        """L_p about the impending pivot (`multimass.model.kinematics.angular_momentum_new_pivot`,
        compiled, as `energy`)."""
        return mx._pivot_momentum(y, self.m, self.H, self.mp)

    # -- the events of the current phase (multimass.engines._events.phase_events) --------------------
    def events(self, run, s):
        """Names, codes, directions, terminal flags, quiet values, guard ends, ep, fp of the
        phase of state `s` in the loop `run`."""
        t0, d = s.t, self.delay
        ep = event_params(run.st, run.thetadot_min, run.overturn, self.dd)
        fp = np.zeros(mx.FP_SIZE)
        if s.phase == 0:
            key, t_on = "contact", t0 + max(d, s.hold_until - t0)
        else:
            key, t_on = "rocking", t0 + d
            if run.model.has_force and s.force is None:
                key = "activate"
                ep[mx.EP_R_PENDING] = s.r_pending
            elif s.force is not None:
                key = "deactivate"
                ep[mx.EP_LIMIT] = run.model.release_angle(s.force.theta_i)
                fp[:] = (1.0, s.force.E_ini, s.force.r, s.force.n)
        names, codes, dirs, term, quiet, _ = _EVENTS[key]
        return names, codes, dirs, term, quiet, _QUIET_OFFSETS[key] + t_on, ep, fp

    # -- one phase segment --------------------------------------------------------------------
    def integrate(self, run, s, t_stop: float):
        """The state of `s` integrated to `t_stop` or past its first terminal event
        (`multimass.engines._run.PhaseLoop.integrate`, compiled)."""
        names, codes, dirs, term, quiet, t_on, ep, fp = self.events(run, s)
        t_eval = np.ascontiguousarray(run.recorder.grid(s.t, t_stop), dtype=np.float64)
        ivp = run.ivp
        start = (float(s.t), float(t_stop), np.ascontiguousarray(s.y, dtype=np.float64), t_eval)
        model = (self.m, self.H, self.K, self.C, self.mp)
        ground = (self.kind, self.par, self.samples)
        if s.phase == 0 and self.contact is not None:
            cm = self.contact
            modes = (cm.phi, cm.w, cm.z, cm.gam, cm.h_max, cm.screen)
            out = contact_phase(*start, *model, codes, dirs, quiet, t_on, ep, *ground, *modes)
        elif s.phase != 0 and self.rocking is not None:
            tol = (max(float(ivp["rtol"]), _RTOL_MIN), float(ivp["atol"]), float(ivp["max_step"]))
            if self.exp_cache is None:
                self.exp_cache = new_cache(self.rocking.lam.size)
            out = exp_phase(*start, int(s.phase), *model, fp, codes, dirs, term, quiet, t_on, ep,
                            *ground, *self.rocking.arrays, self.exp_cache, *tol)  # fmt: skip
        else:
            out = integrate_phase(
                *start,
                int(s.phase),
                *model,
                fp,
                codes,
                dirs,
                term,
                quiet,
                t_on,
                ep,
                *ground,
                self.code,
                max(float(ivp["rtol"]), _RTOL_MIN),
                float(ivp["atol"]),
                float(ivp["max_step"]),
                self._hint(s.phase),
            )
        status, t, y, ev, nfev, samples, _, nt_t, nt_y = out
        run.n_rhs += int(nfev)
        k = len(samples)
        if status == FAILED:
            t_fail = float(t_eval[k - 1]) if k else s.t
            run.events.append(Event("failed", t_fail, s.phase, s.phase, detail=_FAIL_MESSAGE))
            return s.but(
                status="failed",
                message=f"compiled {self.method} failed at t = {t:.6g} s: {_FAIL_MESSAGE}",
            )
        if not (np.all(np.isfinite(samples)) and np.all(np.isfinite(y))):
            return run.fail(
                s,
                s.t,
                f"compiled {self.method} produced a non-finite state in the segment "
                f"starting at t = {s.t:.6g} s",
            )
        t_events, y_events = [_NONE] * len(names), [_NONE] * len(names)
        if s.phase:  # θ̇ = 0, the one non-terminal event (index 2 while rocking)
            t_events[_PEAK], y_events[_PEAK] = nt_t, nt_y
        run.recorder.segment(
            _Segment(t_eval[:k], samples.T, t_events, y_events), None, s.phase, s.force, names
        )
        if status == EVENT:
            return handle_event(run, s.but(t=float(t), y=y), names[ev])
        return s.but(t=t_stop, y=samples[-1].copy())
