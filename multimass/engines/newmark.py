"""Paper 004's own integrator for a rigid rocking block (paper 004, Section 2, Eqs 1–10).

Newmark's trapezoidal rule with Newton–Raphson on the discrete nonlinear equation of
motion of Housner's block (large rotations), exact location of every impact by solving
the step for an unknown length Δt' with θ_{n+1} := 0, and restitution applied to the
first post-impact step. Phases: full contact (at rest) → uplift → rocking half-cycles
separated by impacts → full contact again, or overturning.

Sign convention (paper 004 Eqs 1–2, paper 001 Fig 1): θ > 0 rocks about the right pivot;
a positive ground acceleration ü_g pushes the block towards θ < 0.

Time grid. Steps end on the fixed grid t_k = k Δt (the last step is shortened to end at
`t_end`). An event inside a step (uplift, impact) is inserted at its exact instant and the
step is completed from there to the next grid point, so every run shares one grid and the
event rows are the only extra rows. (Paper 004 restores the full Δt after an impact,
which shifts the grid; both are second order.)

The result follows the toolkit's one result contract (`multimass.result`): a
`NewmarkResult` is a `multimass.result.Result` with ``status``/``outcome``, ``events``
(`multimass.result.Event`), ``peaks`` in rad, ``series``, an energy ``ledger`` and the
ledger's check.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from .. import validation as v
from ..checks import balance_error, energy_check, scale_floor
from ..errors import InputError
from ..model import equations as eq
from ..model.structure import Structure
from ..result import Event, Result, status_of
from . import _newmark_kernel as kern
from ._newmark_events import Run

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["newmark_block", "NewmarkResult", "rocking_energy"]

_MAX_PHASES = 10_000_000


@dataclass(frozen=True, eq=False)
class NewmarkResult(Result):
    """Response of `newmark_block` (a `multimass.result.Result`, engine "newmark_block").

    Attributes
    ----------
    t, theta, thetadot, thetaddot : ndarray
        Every grid point reached plus the event instants (uplift, impact, full contact:
        one row each, holding the state *after* the event; the last row of an overturned
        run is the overturning instant). t is strictly increasing (s, rad, rad/s, rad/s²).
    ag : ndarray
        Ground acceleration ü_g at the rows (m/s²).
    events : tuple of Event
        `multimass.result.Event`: a "release" (the initial state, at t = 0), then
        "uplift", "impact", "full_contact" and a last "overturn", "rest" or "failed";
        ``phase_before`` / ``phase_after`` are the pivot (+1 right, −1 left) or 0 (full
        contact); ``restitution`` the r of an impact and ``energy_change`` its
        ½ J_p (θ̇+² − θ̇−²) (J).
    outcome : {"completed", "overturned", "rest", "failed"}
        "completed": `t_end` reached; "overturned": ``|θ|`` reached `overturn_angle`;
        "rest": stopped early after `rest_after` (see `newmark_block`); "failed": a
        Newton iteration did not converge (arrays end at the last converged step).
    message : str
    overturn_time : float or None
        Instant ``|θ|`` reached `overturn_angle` (s).
    peaks : ndarray
        max ``|θ|`` of each rocking half-cycle in order (rad), the unfinished last one
        included; a free release's first entry is ``|θ0|``.
    peak_times : ndarray
        Instant of each peak (s), refined inside the step as the peak is.
    n_steps : int
        Newmark steps solved (full and partial).
    n_newton_iterations, max_newton_iterations : int
        Newton iterations in all, and the most in one solve (steps and impact location).
    dt : float
    energy, ground_work, impact_loss : ndarray
        The energy ledger at the rows (J): `rocking_energy`, the work of ü_g on the block
        (trapezoidal rule on the rows) and the energy lost at impacts and at the
        transitions into full contact, cumulative; `ledger` tabulates them.
    status : {"completed", "overturned", "inaccurate", "failed"}
        `outcome` through `multimass.result.status_of` ("rest" completes), or
        "inaccurate" when the energy check failed.
    checks : dict
        ``energy_balance``: max ``|balance_error|`` over the energy scale (the initial
        energy, the largest ground work or the floor m_t g B · tol / energy_tol,
        `multimass.checks.balance_error`) against `energy_tol`.
        Empty for a failed run.
    warnings : tuple of str
        One line per failed check.
    """

    t: np.ndarray
    theta: np.ndarray
    thetadot: np.ndarray
    thetaddot: np.ndarray
    ag: np.ndarray
    events: tuple
    outcome: str
    message: str
    overturn_time: float | None
    peaks: np.ndarray
    peak_times: np.ndarray
    n_steps: int
    n_newton_iterations: int
    max_newton_iterations: int
    dt: float
    energy: np.ndarray = field(default_factory=lambda: np.zeros(0))
    ground_work: np.ndarray = field(default_factory=lambda: np.zeros(0))
    impact_loss: np.ndarray = field(default_factory=lambda: np.zeros(0))
    status: str = ""
    checks: dict = field(default_factory=dict)
    warnings: tuple[str, ...] = ()

    engine = "newmark_block"

    @property
    def series(self) -> pd.DataFrame:
        """The rows as a table: ``t``, ``theta``, ``thetadot``, ``thetaddot``, ``ag``."""
        import pandas as pd  # here: a run summarised without tables needs no pandas

        return pd.DataFrame(
            {
                "t": self.t,
                "theta": self.theta,
                "thetadot": self.thetadot,
                "thetaddot": self.thetaddot,
                "ag": self.ag,
            }
        )

    @property
    def ledger(self) -> pd.DataFrame:
        """The energy ledger at the rows (J; `multimass.result.LEDGER_NAMES`): ``t``,
        ``energy``, ``ground_work``, ``impact`` (`impact_loss`) and ``balance_error`` =
        energy − energy(0) − ground_work + impact."""
        import pandas as pd

        e = self.energy
        return pd.DataFrame(
            {
                "t": self.t,
                "energy": e,
                "ground_work": self.ground_work,
                "impact": self.impact_loss,
                "balance_error": e - e[:1] - self.ground_work + self.impact_loss,
            }
        )

    def _summary_extra(self) -> dict:
        bal = self.checks.get("energy_balance", {}).get("value")
        return {
            "overturn_time": self.overturn_time,
            "energy_balance_error": bal,
            "n_steps": self.n_steps,
            "n_newton_iterations": self.n_newton_iterations,
            "max_newton_iterations": self.max_newton_iterations,
            "dt": self.dt,
            "t_end": float(self.t[-1]) if self.t.size else 0.0,
        }


def rocking_energy(structure: Structure, theta, thetadot):
    """Total energy above rest, ½ J_p θ̇² + m g R [cos(α − ``|θ|``) − cos α] (J).

    Kinetic plus gravitational energy of a rigid block rocking on a pivot (the
    first integral of paper 004, Eqs 1–2 without ground motion).
    """
    st = structure
    th = np.abs(np.asarray(theta, dtype=float))
    return 0.5 * st.J_p * np.asarray(thetadot, dtype=float) ** 2 + st.m_t * st.g * st.R_cg * (
        np.cos(st.alpha_cg - th) - np.cos(st.alpha_cg)
    )


def _ledger(st: Structure, t, theta, thetadot, ag, events) -> dict:
    """The energy ledger of the rows (J): the `NewmarkResult` fields ``energy``,
    ``ground_work`` and ``impact_loss``."""
    energy = rocking_energy(st, theta, thetadot)
    lever = eq.lever_arm(np.sign(theta), st.B, st.m_t, 0.0)  # the pivot is on θ's side
    power = eq.ground_power(
        ag, 0.0, thetadot, st.static_moment, lever, np.cos(theta), np.sin(theta)
    )
    work = np.zeros_like(t)
    np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t), out=work[1:])
    # lost at impacts and into full contact, cumulative from each event's row on
    steps = np.zeros(t.size + 1)
    at = np.searchsorted(t, [e.time for e in events], side="left")
    np.add.at(steps, at, [-e.energy_change for e in events])
    lost = np.cumsum(steps[:-1])
    return {"energy": energy, "ground_work": work, "impact_loss": lost}


def _judged(st: Structure, fields: dict, energy_tol: float, tol: float) -> NewmarkResult:
    """`NewmarkResult` of a run's fields, with its ledger, energy check and status."""
    led = _ledger(
        st, fields["t"], fields["theta"], fields["thetadot"], fields["ag"], fields["events"]
    )
    checks, warnings = {}, ()
    if fields["outcome"] != "failed":
        e, w = led["energy"], led["ground_work"]
        balance = e - e[0] - w + led["impact_loss"]
        floor = scale_floor(st, tol, energy_tol)
        err = balance_error(
            float(np.max(np.abs(balance))), e[0], float(np.max(np.abs(w))), 0.0, floor
        )
        checks["energy_balance"] = energy_check(err, energy_tol)
        if not checks["energy_balance"]["passed"]:
            warnings = (
                f"energy ledger does not close: balance error {err:.3g} of the energy scale "
                f"(limit {energy_tol:.3g}); the solution is not accurate — reduce `dt`",
            )
    status = status_of(fields["outcome"], all(c["passed"] for c in checks.values()))
    return NewmarkResult(**fields, **led, status=status, checks=checks, warnings=warnings)


# ---------------------------------------------------------------------------- validation
def _restitution_fn(restitution) -> Callable[[float, int], float]:
    if callable(restitution):
        return restitution
    r = v.number(
        "restitution",
        restitution,
        what="coefficient r in (0, 1], or a callable (thetadot_minus, new_side) -> r",
    )
    if not 0.0 < r <= 1.0:
        raise InputError(
            f"`restitution` = {restitution!r}: r must lie in (0, 1] "
            "(θ̇+ = r θ̇−; e.g. impact_models.housner_eta(alpha))"
        )
    return lambda *_: r


def _sample(ag, t: np.ndarray) -> np.ndarray:
    """ü_g on the grid: one vectorised call when `ag` accepts arrays and agrees with
    its scalar calls at a few points, else one call per point."""
    vals = None
    try:
        v = np.asarray(ag(t), dtype=float)
        if v.shape == t.shape:
            probe = np.unique(np.linspace(0, t.size - 1, 7).astype(int))
            if all(
                float(ag(float(t[i]))) == v[i]
                or math.isclose(float(ag(float(t[i]))), v[i], rel_tol=1e-12, abs_tol=1e-12)
                for i in probe
            ):
                vals = v
    except Exception:  # noqa: BLE001 - any failure means "scalar only"
        vals = None
    if vals is None:
        vals = np.fromiter((float(ag(float(x))) for x in t), dtype=float, count=t.size)
    if not np.all(np.isfinite(vals)):
        bad = int(np.flatnonzero(~np.isfinite(vals))[0])
        raise InputError(
            f"`ag` returned {vals[bad]!r} at t = {t[bad]!r}: the ground "
            "acceleration must be finite (m/s²)"
        )
    return vals


# ---------------------------------------------------------------------------- public
def _validate(
    structure,
    ag,
    t_end,
    dt,
    tol,
    max_iter,
    overturn_angle,
    rest_after,
    theta0,
    thetadot0,
    thetadot_min,
    engine,
    energy_tol,
) -> dict:
    if not isinstance(structure, Structure):
        raise InputError(
            f"`structure` = {structure!r}: expected a multimass.Structure "
            '(e.g. multimass.rigid_block("B6M"))'
        )
    if not structure.is_rigid:
        raise InputError(
            f"`structure` = {structure.name!r} has n = {structure.n} elastic "
            "nodes: `newmark_block` integrates a rigid block only (n == 0); build "
            "one with multimass.rigid_block(...)"
        )
    if not callable(ag):
        raise InputError(
            f"`ag` = {ag!r}: expected a callable ü_g(t) in m/s² "
            "(a function or an object with __call__)"
        )
    o = {
        "t_end": v.positive("t_end", t_end, "duration of the run in s"),
        "dt": v.positive("dt", dt, "time step in s"),
        "tol": v.positive("tol", tol, "Newton tolerance on θ in rad"),
        "thetadot_min": v.number("thetadot_min", thetadot_min, low=0.0, what="rad/s"),
        "max_iter": v.integer("max_iter", max_iter, low=1),
        "energy_tol": v.positive("energy_tol", energy_tol, "largest energy balance error"),
    }
    ang = (
        math.pi / 2
        if overturn_angle is None
        else v.number(
            "overturn_angle", overturn_angle, low=0.0, low_open=True, high=math.pi / 2, what="rad"
        )
    )
    o["overturn_angle"] = ang
    o["rest_after"] = (
        None
        if rest_after is None
        else v.number("rest_after", rest_after, low=0.0, what="time in s after which ü_g ≡ 0")
    )
    o["theta0"] = v.number("theta0", theta0, what="initial angle in rad")
    o["thetadot0"] = v.number("thetadot0", thetadot0, what="initial rate in rad/s")
    if abs(o["theta0"]) >= ang:
        raise InputError(
            f"`theta0` = {theta0!r}: |θ0| must be below overturn_angle = {ang:.6g} rad"
        )
    if engine not in ("auto", "numba", "python"):
        raise InputError(f'`engine` = {engine!r}: expected "auto", "numba" or "python"')
    return o


def _kernel(engine):
    if engine == "python":
        return kern.advance
    try:
        return kern.compiled_advance()
    except ImportError:
        if engine == "numba":
            raise
        return kern.advance


def newmark_block(
    structure: Structure,
    ag,
    t_end: float,
    *,
    dt: float = 1e-3,
    restitution,
    theta0: float = 0.0,
    thetadot0: float = 0.0,
    tol: float = 1e-9,
    max_iter: int = 50,
    overturn_angle: float | None = None,
    rest_after: float | None = None,
    thetadot_min: float = 0.01,
    engine: str = "auto",
    energy_tol: float = 1e-3,
) -> NewmarkResult:
    """Rocking of a rigid block by paper 004's Newmark scheme (Section 2, Eqs 1–8).

    Parameters
    ----------
    structure : Structure
        A rigid block, ``structure.n == 0`` (`multimass.rigid_block`). Its J_p, m_t,
        R_cg, α_cg and g give p² = m g R / J_p (= 3g / 4R for a uniform block).
    ag : callable
        Ground acceleration ü_g(t) in m/s²; a positive value pushes the block to θ < 0.
        Called on the time grid (one vectorised call when it accepts arrays) and at
        event instants.
    t_end : float
        End time (s), > 0.
    dt : float
        Step (s), > 0. Steps end on t_k = k dt; events are inserted exactly.
    restitution : float or callable
        r in (0, 1], or ``restitution(thetadot_minus, new_side) -> r``, e.g.
        ``lambda *_: impact_models.housner_eta(alpha)``. θ̇+ = r θ̇− at each impact.
    theta0, thetadot0 : float
        Initial state (rad, rad/s). Both zero: the block starts at rest in full contact.
    tol, max_iter : float, int
        Newton–Raphson stops when the θ correction is ≤ `tol` (rad); more than
        `max_iter` iterations gives outcome and status "failed" with a message.
    overturn_angle : float, optional
        Stop with outcome "overturned" when ``|θ|`` reaches it (rad, in (0, π/2]; default π/2).
    rest_after : float, optional
        Time (s) after which the caller guarantees ü_g ≡ 0 (e.g. the pulse duration).
        From then on the run stops with outcome "rest" (status "completed") as soon as
        the block is at rest in full contact, or ``|θ|`` < α and its energy
        ½J_pθ̇² + mgR[cos(α − ``|θ|``) − cos α] is below mgR(1 − cos α), the energy
        needed to reach θ = α — it then can never overturn in free rocking (energy is
        conserved in flight and lost at impacts) — and it rocks away from θ = 0 or is at
        a turning point (θ = 0 right after an impact included): the swing under way then
        peaks at `multimass.model.equations.free_rocking_peak` of that energy, the last
        entry of `peaks` (its time is the stop time), and no later one is higher, so
        θ_max is that of the run continued to `t_end` (to the integrator's accuracy).
        Checked at `rest_after`, at every impact after it and in full contact.
        None: run to `t_end`.
        Overturning maps rely on it; for time histories leave it None.
    thetadot_min : float
        An impact with ``|θ̇−|`` ≤ thetadot_min (rad/s) ends in full contact, as does one
        whose angular momentum about the new pivot opposes θ̇ (J_p < 2 m B², a block
        wider than √2 × its height) (paper 001, Eq 9, θ̇_min = 0.01 rad/s).
    engine : {"auto", "numba", "python"}
        Step kernel: numba-compiled (auto, when numba imports) or the pure-Python
        reference; both run the same source.
    energy_tol : float
        Largest accepted energy balance error of the ledger, as a share of the run's
        energy scale (`NewmarkResult.checks`); beyond it the status is "inaccurate".

    Returns
    -------
    NewmarkResult

    Notes
    -----
    Full contact lasts while ``|ü_g|`` ≤ g tan α: at θ = 0 Eq 1 gives θ̈ > 0 (right pivot)
    iff ü_g < −g tan α, and Eq 2 gives θ̈ < 0 (left pivot) iff ü_g > g tan α. The uplift
    instant is located inside the step by Brent's method on ü_g(t) ∓ g tan α. In flight,
    each step solves Eq 5 (θ > 0) or Eq 6 (θ < 0) by Newton–Raphson with the analytic
    tangent. When θ changes sign in a step, the step is solved again for its length Δt'
    with θ_{n+1} := 0 (Newton, bracketed), θ̇− and θ̈− follow from Eqs 7–8, θ̇+ = r θ̇−,
    the other equation takes over, and the step is completed to the grid point.
    """
    o = _validate(
        structure,
        ag,
        t_end,
        dt,
        tol,
        max_iter,
        overturn_angle,
        rest_after,
        theta0,
        thetadot0,
        thetadot_min,
        engine,
        energy_tol,
    )
    r_fn = _restitution_fn(restitution)
    n = max(int(math.ceil(o["t_end"] / o["dt"] - 1e-9)), 1)
    t_grid = np.arange(n + 1, dtype=float) * o["dt"]
    t_grid[-1] = o["t_end"]
    run = Run(structure, ag, t_grid, _sample(ag, t_grid), r_fn, o, _kernel(engine))
    th, thd = o["theta0"], o["thetadot0"]
    side = 0 if th == 0.0 and thd == 0.0 else 1 if (th > 0.0 or (th == 0.0 and thd > 0.0)) else -1
    run.events.append(Event("release", 0.0, side, side, th, thd, thd))
    if side == 0:
        nxt = run.rest(0.0, 1)
    else:
        thdd = run.f(th, side, 0.0)
        run.out[:, 0] = (th, thd, thdd)
        run.sf[0] = abs(th)
        nxt = None if run.energy_stop(0.0, th, thd, side) else (0.0, 1, th, thd, thdd, side)
    for _ in range(_MAX_PHASES):  # guard against endless chattering
        if nxt is None:
            break
        nxt = run.rest(nxt[0], nxt[1]) if nxt[5] == 0 else run.fly(*nxt)
    else:
        run.outcome = "failed"
        run.message = (
            f"more than {_MAX_PHASES} phase changes before t_end (chattering); raise `thetadot_min`"
        )
    return _judged(structure, run.fields(), o["energy_tol"], o["tol"])
