"""Events and phases of paper 004's Newmark integrator (`multimass.engines.newmark`).

`Run` drives one simulation: full contact (uplift test on ü_g), rocking flights
through the step kernel (`multimass.engines._newmark_kernel.advance`), and the transitions
between them — impact location with an unknown step Δt' and θ_{n+1} := 0, pre-impact
rates (paper 004, Eqs 7–8), restitution, full contact (paper 001, Eq 9), overturning
and the optional early stop. Its rows and events (`multimass.result.Event`) become a
`NewmarkResult`.
"""

from __future__ import annotations

import math

import numpy as np

from multimass.impact_models.models import next_phase_is_rocking

from ..errors import InputError
from ..model import equations as eq
from ..result import Event
from . import _newmark_kernel as kern

__all__ = ["Run", "peak_times"]

_SNAP = 1e-9  # an event within _SNAP·Δt of a grid point is put on it
_AT_REST = "excitation over and the block at rest in full contact"


def _checked_r(fn, thd_minus: float, side: int) -> float:
    r = fn(thd_minus, side)
    try:
        rf = float(r)
    except (TypeError, ValueError):
        rf = float("nan")
    if not 0.0 < rf <= 1.0:
        raise InputError(
            f"`restitution` returned {r!r} for thetadot_minus = {thd_minus!r}, "
            f"new_side = {side}: r must lie in (0, 1]"
        )
    return rf


def _locate_impact(ag, t_a, th, thd, thdd, h, s, th_cross, p2, alpha, g, max_iter):
    """Δt' with θ_{n+1} := 0 in Eq 5/6 (paper 004, Sec 2.2): root of
    K(τ) = −θ_n/τ − θ̇_n − τ/4 (θ̈_n + f(0, ü_g(t_n + τ))) on (0, h], i.e. Eq 5 × τ²/4
    divided by τ (which removes the root τ = 0 when θ_n = 0, just after an impact).

    Newton (ü_g' by central difference) inside a shrinking bracket, bisection when an
    iterate leaves it. Returns (τ, iterations); τ = h when K has no sign change on
    (0, h] (the crossing then lies within O(p²h²|θ_{n+1}|) of the step end).
    """
    ca = math.cos(alpha)

    def f0(tau):
        return kern.rhs(0.0, s, float(ag(t_a + tau)), p2, alpha, g)

    def K(tau):
        return -th / tau - thd - 0.25 * tau * (thdd + f0(tau))

    k_hi = K(h)
    if s * k_hi <= 0.0:
        return h, 1
    lo, hi = 0.0, h  # s·K < 0 at lo (limit τ → 0+), > 0 at hi
    if th != 0.0:
        tau = h * th / (th - th_cross)  # linear interpolation of θ
    else:
        den = thdd + f0(h)
        tau = -4.0 * thd / den if den != 0.0 else 0.5 * h
    if not 0.0 < tau < h:
        tau = 0.5 * h
    delta = 1e-6 * h
    for it in range(1, max_iter + 1):
        k_val = K(tau)
        if k_val == 0.0:
            return tau, it
        if s * k_val < 0.0:
            lo = tau
        else:
            hi = tau
        dag = (float(ag(t_a + tau + delta)) - float(ag(t_a + tau - delta))) / (2.0 * delta)
        dk = th / tau**2 - 0.25 * (thdd + f0(tau)) + 0.25 * tau * p2 * ca * dag / g
        new = tau - k_val / dk if dk != 0.0 else -1.0
        if lo <= new <= hi and abs(new - tau) <= 1e-13 * h:
            return new, it
        if not lo < new < hi:
            new = 0.5 * (lo + hi)
        if hi - lo <= 1e-13 * h:
            return new, it
        tau = new
    return tau, max_iter


def _locate_uplift(ag, lo, hi, thr):
    """First instant in (lo, hi] where ü_g crosses the uplift threshold ±g tan α.

    Brent's method (inverse quadratic interpolation with bisection safeguard) on
    ü_g(t) − thr; it also converges to a jump of ü_g.
    """
    from scipy.optimize import brentq  # here: a command that runs no Newmark needs no SciPy

    fn = lambda t: float(ag(t)) - thr  # noqa: E731
    if fn(lo) * fn(hi) > 0.0:
        return hi
    return brentq(fn, lo, hi, xtol=1e-15, rtol=8.9e-16, maxiter=200)


def _locate_overturn(t_a, th, thd, thdd, thdd1, h, s, angle):
    """Instant where s θ = angle inside a step, on Newmark's quadratic interpolant."""
    abar = 0.5 * (thdd + thdd1)
    fn = lambda tau: s * (th + tau * thd + 0.5 * tau * tau * abar) - angle  # noqa: E731
    if fn(0.0) >= 0.0:
        return 0.0
    if fn(h) <= 0.0:
        return h
    from scipy.optimize import brentq

    return brentq(fn, 0.0, h, xtol=1e-15 * max(h, 1.0), rtol=8.9e-16)


# ---------------------------------------------------------------------------- driver
class Run:
    """Mutable state of one run: output grid, inserted event rows, events, counters."""

    def __init__(self, st, ag, t_grid, ag_grid, r_fn, opts, advance):
        self.ag, self.t, self.agg, self.r_fn = ag, t_grid, ag_grid, r_fn
        self.o, self.advance = opts, advance
        self.N = t_grid.size - 1
        self.dt = opts["dt"]
        self.alpha, self.g, self.p2 = st.alpha_cg, st.g, st.p**2
        self.j_new = (st.J_p, st.m_t, st.B)  # L about the impending pivot, per θ̇
        self.J_p = st.J_p
        self.thr = st.g * math.tan(st.alpha_cg)  # uplift: |ü_g| > g tan α
        self.barrier = 1.0 - math.cos(st.alpha_cg)  # energy to reach θ = α, / m g R
        self.out = np.zeros((3, self.N + 1))
        self.inserts: list[tuple] = []  # (grid position, t, θ, θ̇, θ̈)
        self.events: list[Event] = []
        self.peaks: list[float] = []
        self.spans: list[tuple[float, float]] = []  # (start, end) of each peak's half-cycle
        self.t_half = 0.0  # start of the current half-cycle
        self.si = np.zeros(3, dtype=np.int64)
        self.sf = np.zeros(2)
        self.written = 0
        self.outcome, self.message, self.t_over = "completed", "", None
        ra = opts["rest_after"]
        kc = -1 if ra is None else int(np.searchsorted(t_grid, ra, side="left"))
        self.k_check = kc if 0 < kc <= self.N else -1

    # -- helpers
    def f(self, theta, side, t):
        return kern.rhs(theta, side, float(self.ag(t)), self.p2, self.alpha, self.g)

    def energy(self, th, thd) -> float:
        """Energy above rest / (m g R)."""
        return 0.5 * thd * thd / self.p2 + math.cos(self.alpha - abs(th)) - math.cos(self.alpha)

    def close_half(self, t, peak=None):
        """End the current half-cycle at t: keep its peak (default: the kernel's) and span."""
        self.peaks.append(float(self.sf[0]) if peak is None else float(peak))
        self.spans.append((self.t_half, t))

    def energy_stop(self, t, th, thd, side) -> bool:
        """The early stop of `newmark_block` (rest_after) in flight or at an impact.

        After `rest_after`, with ``|θ|`` < α and the energy E below m g R (1 − cos α),
        rocking away from θ = 0 or at a turning point (±θ̇ ≥ 0 on pivot ±1, θ = 0 after
        an impact included): the swing under way peaks at `equations.free_rocking_peak`
        of E, which closes the half-cycle (at t), and no later swing peaks higher
        (`multimass.engines._run.PhaseLoop.safe_peak`). Toward θ = 0 the run goes on.
        """
        ra = self.o["rest_after"]
        if ra is None or t < ra or not abs(th) < self.alpha or side * thd < 0.0:
            return False
        E = self.energy(th, thd)
        if not E < self.barrier:  # beyond α it falls: no early stop
            return False
        peak = eq.free_rocking_peak(self.alpha, E / self.barrier)  # energy of free rocking
        self.close_half(t, max(float(self.sf[0]), abs(th), peak))
        self.stop(
            "rest",
            t,
            th,
            thd,
            "excitation over and energy below the overturning "
            "barrier m g R (1 − cos α): the block can no longer overturn",
            side,
        )
        return True

    def stop(self, outcome, t, th, thd, message, side, kind="rest"):
        """End the run with `outcome`: an event `kind` at t, the block on `side` (0: at rest)."""
        self.outcome, self.message = outcome, message
        self.events.append(Event(kind, t, side, side, th, thd, thd, detail=message))

    def row(self, k, t, th, thd, thdd) -> tuple[float, int]:
        """Write the state of an event at t; returns (start time, next grid point)."""
        if self.t[k] - t <= _SNAP * self.dt:  # on the grid point: snap
            self.out[:, k] = (th, thd, thdd)
            self.written = k
            return float(self.t[k]), k + 1
        self.inserts.append((k, t, th, thd, thdd))
        return t, k

    def count(self, its):
        self.si[1] += its
        self.si[2] = max(self.si[2], its)

    # -- phases
    def rest(self, t_a, k):
        """Full contact from t_a (grid point k next). Returns the uplift start or None."""
        ra = self.o["rest_after"]
        if ra is not None and t_a >= ra:
            self.stop("rest", t_a, 0.0, 0.0, _AT_REST, 0)
            return None
        a0 = float(self.ag(t_a))
        if abs(a0) > self.thr:  # uplift at once (at t_a)
            side = 1 if a0 < 0.0 else -1
            return self.uplift(t_a, k, side, at_start=True)
        over = np.flatnonzero(np.abs(self.agg[k:]) > self.thr)
        j = k + int(over[0]) if over.size else None
        kc = self.k_check
        if kc >= k and (j is None or j >= kc):  # rests until the excitation ends
            self.written = kc
            self.stop("rest", float(self.t[kc]), 0.0, 0.0, _AT_REST, 0)
            return None
        if j is None:  # rests to t_end
            self.written = self.N
            return None
        self.written = j - 1  # rows k..j-1 stay 0 (full contact)
        side = 1 if self.agg[j] < 0.0 else -1  # ü_g < −g tan α: right pivot
        lo = t_a if j == k else float(self.t[j - 1])
        t_u = _locate_uplift(self.ag, lo, float(self.t[j]), -side * self.thr)
        return self.uplift(t_u, j, side, at_start=False)

    def uplift(self, t_u, k, side, at_start):
        """Start rocking at t_u about `side` with θ = θ̇ = 0 (paper 004, Eq 1 at θ = 0)."""
        thdd = self.f(0.0, side, t_u)
        if at_start:  # the row at t_u exists already
            if self.inserts and self.inserts[-1][1] == t_u:
                self.inserts[-1] = self.inserts[-1][:4] + (thdd,)
            else:
                self.out[2, k - 1] = thdd
            t_a = t_u
        else:
            t_a, k = self.row(k, t_u, 0.0, 0.0, thdd)
        self.events.append(Event("uplift", t_u, 0, side))
        self.sf[0], self.t_half = 0.0, t_u
        return t_a, k, 0.0, 0.0, thdd, side

    def fly(self, t_a, k, th, thd, thdd, side):
        """Rocking half-cycles from t_a; returns the full-contact start or None (stop)."""
        o = self.o
        while True:
            kc = self.k_check if self.k_check >= k else -1
            code, kk = self.advance(
                self.t,
                self.agg,
                k,
                self.N,
                t_a,
                th,
                thd,
                thdd,
                side,
                self.p2,
                self.alpha,
                self.g,
                o["tol"],
                o["max_iter"],
                o["overturn_angle"],
                kc,
                self.out,
                self.si,
                self.sf,
            )
            code, kk = int(code), int(kk)
            pre = (
                (t_a, th, thd, thdd)
                if kk == k
                else (float(self.t[kk - 1]), *(float(x) for x in self.out[:, kk - 1]))
            )
            if code in (kern.END, kern.OVERTURN, kern.CHECK):
                self.written = kk
            else:
                self.written = kk - 1
            if code == kern.END:
                self.close_half(float(self.t[kk]))
                return None
            if code == kern.FAIL:
                return self.fail(pre, kk, side)
            if code == kern.OVERTURN:
                return self.overturn(pre, kk, side)
            if code == kern.CHECK:
                self.k_check = -1
                t_a, k = float(self.t[kk]), kk + 1
                th, thd, thdd = (float(x) for x in self.out[:, kk])
                if self.energy_stop(t_a, th, thd, side):
                    return None
                continue
            nxt = self.impact(pre, kk, side)  # code == CROSS
            if nxt is None or nxt[5] == 0:
                return nxt
            t_a, k, th, thd, thdd, side = nxt

    # -- events
    def impact(self, pre, kk, side):
        """θ crossed 0 in the step to grid point kk: locate, restitute, switch side."""
        t_p, th, thd, thdd = pre
        h = float(self.t[kk]) - t_p
        tau, its = _locate_impact(
            self.ag,
            t_p,
            th,
            thd,
            thdd,
            h,
            side,
            float(self.sf[1]),
            self.p2,
            self.alpha,
            self.g,
            self.o["max_iter"],
        )
        self.count(its)
        t_i = t_p + tau
        thdd_m = self.f(0.0, side, t_i)  # paper 004, Eq 8
        thd_m = thd + 0.5 * tau * (thdd + thdd_m)  # paper 004, Eq 7
        self.close_half(t_i)
        self.sf[0], self.t_half = 0.0, t_i
        new = -side
        L_new = eq.pivot_momentum(0.0, thd_m, *self.j_new, 0.0)
        if not next_phase_is_rocking(new, L_new, thd_m, self.o["thetadot_min"]):
            loss = 0.5 * self.J_p * thd_m * thd_m
            self.events.append(Event("full_contact", t_i, side, 0, 0.0, thd_m, 0.0, None, -loss))
            t_a, k = self.row(kk, t_i, 0.0, 0.0, 0.0)
            return t_a, k, 0.0, 0.0, 0.0, 0
        r = _checked_r(self.r_fn, thd_m, new)
        thd_p = r * thd_m  # θ̇+ = r θ̇− (paper 004, Sec 2.3)
        thdd_p = self.f(0.0, new, t_i)
        change = 0.5 * self.J_p * (thd_p * thd_p - thd_m * thd_m)
        self.events.append(Event("impact", t_i, side, new, 0.0, thd_m, thd_p, r, change))
        t_a, k = self.row(kk, t_i, 0.0, thd_p, thdd_p)
        if self.energy_stop(t_i, 0.0, thd_p, new):
            return None
        return t_a, k, 0.0, thd_p, thdd_p, new

    def overturn(self, pre, kk, side):
        t_p, th, thd, thdd = pre
        h = float(self.t[kk]) - t_p
        ang = self.o["overturn_angle"]
        tau = _locate_overturn(t_p, th, thd, thdd, float(self.out[2, kk]), h, side, ang)
        t_o = t_p + tau
        thd_o = thd + 0.5 * tau * (thdd + float(self.out[2, kk]))
        self.out[:, kk] = (side * ang, thd_o, self.f(side * ang, side, t_o))
        self.t_over = t_o
        self.close_half(t_o, ang)
        msg = f"|θ| reached overturn_angle = {ang:.6g} rad at t = {t_o:.6g} s"
        self.stop("overturned", t_o, side * ang, thd_o, msg, side, kind="overturn")
        return None

    def fail(self, pre, kk, side):
        t_p, th, thd, _ = pre
        self.close_half(t_p)
        msg = (
            f"Newton–Raphson did not converge in max_iter = {self.o['max_iter']} "
            f"iterations in the step from t = {t_p:.6g} s (θ = {th:.6g} rad, "
            f"θ̇ = {thd:.6g} rad/s) to t = {float(self.t[kk]):.6g} s; reduce `dt` "
            "or raise `max_iter`"
        )
        self.stop("failed", t_p, th, thd, msg, side, kind="failed")
        return None

    def fields(self) -> dict:
        """The rows, events and counters of the run (`multimass.engines.newmark.NewmarkResult`)."""
        n = self.written + 1
        t = self.t[:n].copy()
        ag = self.agg[:n].copy()
        if self.t_over is not None:
            t[-1] = self.t_over
            ag[-1] = float(self.ag(self.t_over))
        cols = [t, self.out[0, :n].copy(), self.out[1, :n].copy(), self.out[2, :n].copy(), ag]
        ins = [r for r in self.inserts if r[0] <= n]
        if ins:
            pos = [r[0] for r in ins]
            vals = [[*r[1:5], float(self.ag(r[1]))] for r in ins]
            cols = [np.insert(c, pos, [v[i] for v in vals]) for i, c in enumerate(cols)]
        return dict(
            t=cols[0],
            theta=cols[1],
            thetadot=cols[2],
            thetaddot=cols[3],
            ag=cols[4],
            events=tuple(self.events),
            outcome=self.outcome,
            message=self.message or "reached t_end",
            overturn_time=self.t_over,
            peaks=np.asarray(self.peaks, dtype=float),
            peak_times=peak_times(*cols[:4], self.spans),
            n_steps=int(self.si[0]),
            n_newton_iterations=int(self.si[1]),
            max_newton_iterations=int(self.si[2]),
            dt=self.dt,
        )


def peak_times(t, theta, thetadot, thetaddot, spans) -> np.ndarray:
    """Instant of each half-cycle's peak ``|θ|`` (s); `spans` holds (start, end) per half-cycle.

    The largest ``|θ|`` among the rows of the span, or inside a step where θ̇ changes sign:
    Newmark's constant average acceleration makes θ quadratic in the step, with its
    extremum at τ = −θ̇_n / ā, ā = (θ̈_n + θ̈_{n+1}) / 2 (as the kernel refines the peak).
    """
    th0, th1, thd0, thd1 = theta[:-1], theta[1:], thetadot[:-1], thetadot[1:]
    s = np.sign(np.where(th1 != 0.0, th1, th0))
    abar = 0.5 * (thetaddot[:-1] + thetaddot[1:])
    turn = (s * thd0 > 0.0) & (s * thd1 <= 0.0) & (abar != 0.0)
    safe = np.where(turn, abar, 1.0)
    pk = np.where(turn, s * (th0 - 0.5 * thd0 * thd0 / safe), -np.inf)
    t_pk = t[:-1] - thd0 / safe
    out = np.zeros(len(spans))
    for j, (a, b) in enumerate(spans):
        i0 = int(np.searchsorted(t, a, side="left"))
        i1 = int(np.searchsorted(t, b, side="right"))
        if i1 <= i0:
            out[j] = a
            continue
        best = i0 + int(np.argmax(np.abs(theta[i0:i1])))
        out[j] = t[best]
        if i1 - 1 > i0:  # steps i0 → i0+1, …, i1−2 → i1−1
            k = i0 + int(np.argmax(pk[i0 : i1 - 1]))
            if pk[k] > abs(theta[best]):
                out[j] = t_pk[k]
    return out
