"""Event-driven nonsmooth dynamics with unilateral sticking contacts and Poisson impacts.

The smooth motion between impacts (paper 000, Section 2.1) is
``M(q) q̈ = h(t, q, q̇) + W_N λ_N + W_T λ_T`` with the closed contacts held at
acceleration level (ġ_N = 0 and sticking ġ_T = 0, so g̈ = Wᵀq̈ + ŵ = 0) and the
open ones free. A phase is the set of closed contacts: for a block, both
corners (full contact), one corner (rocking) or none (free flight). A phase
ends when an open contact closes (gap g_N → 0: an impact, resolved by the
Poisson LCPs of `impact_models.poisson_impact`) or a closed one unloads
(λ_N → 0: lift-off). After each event the new phase is the largest subset of
the contacts with ġ_N = 0 whose contact forces are compressive while the
others accelerate apart (the acceleration-level Signorini condition), so
bouncing and flight happen exactly when the impact LCP and the force signs
say so.

Housekeeping: at each phase start the state is projected back onto the closed
contacts' constraints (integration drift), an impact is applied at g_N = 0,
and an accumulation of impacts (approach speed below ``zeno_velocity``) ends
with all touching contacts kept closed ("zeno_rest"). In a phase with no free
coordinate (a block in full contact) nothing is integrated: the contact forces
are scanned in time for the first sign change.

A model supplies ``n``, ``k``, ``mass(q)``, ``forces(t, q, v)``,
``contacts(q, v) -> (g, W_N, W_T, ŵ_N, ŵ_T)``, ``energy(q, v)`` (kinetic +
potential, J), ``powers(t, q, v) -> (ground power, damping power)`` and
optionally ``events`` (extra terminal events ``f(t, q, v)``, e.g. overturning).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from impact_models.poisson import PoissonImpact, poisson_impact

from .errors import InputError, SolverError

__all__ = ["ContactEvent", "ContactResponse", "simulate_contacts"]


@dataclass(frozen=True)
class ContactEvent:
    """One event: ``kind`` is "impact", "liftoff", "zeno_rest" or a model event name.

    ``closed_before`` / ``closed_after`` are the closed contact sets;
    ``contacts`` the contacts taking part in an impact (the columns of its
    W_N, in order); ``impact`` holds the Poisson impact result, else None.
    """

    time: float
    kind: str
    closed_before: tuple[int, ...]
    closed_after: tuple[int, ...]
    impact: PoissonImpact | None = None
    contacts: tuple[int, ...] = ()


@dataclass(frozen=True, eq=False)
class ContactResponse:
    """Sampled response and energy ledger of `simulate_contacts`.

    Attributes
    ----------
    t : ndarray, shape (m,)
        Sample times (event times appear twice: before and after).
    q, v : ndarray, shape (m, n)
    closed : ndarray of int, shape (m,)
        Bit mask of the closed contacts (bit i = contact i).
    energy, ground_work, damping, impact_loss : ndarray, shape (m,)
        Mechanical energy T + V, cumulative work of the ground excitation,
        cumulative damping dissipation and impact losses (J).
    events : tuple of ContactEvent
    status : {"completed", "overturned", "max_events"}
    message : str
    """

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    closed: np.ndarray
    energy: np.ndarray
    ground_work: np.ndarray
    damping: np.ndarray
    impact_loss: np.ndarray
    events: tuple[ContactEvent, ...]
    status: str
    message: str

    @property
    def ledger_error(self) -> np.ndarray:
        """E(t) − E(0) − W_ground + D + impact losses: zero if the ledger closes (J)."""
        return self.energy - self.energy[0] - self.ground_work + self.damping + self.impact_loss

    @property
    def impacts(self) -> tuple[ContactEvent, ...]:
        return tuple(e for e in self.events if e.impact is not None)


def _independent(cols: list[np.ndarray], start: np.ndarray, rtol: float = 1e-9) -> list[int]:
    """Indices of `cols` that raise the rank of [start, chosen...] (greedy)."""
    keep, basis = [], start
    for i, c in enumerate(cols):
        trial = np.column_stack([basis, c]) if basis.size else c[:, None]
        if trial.shape[1] > trial.shape[0]:
            break
        s = np.linalg.svd(trial, compute_uv=False)
        if s[-1] > rtol * s[0]:
            keep.append(i)
            basis = trial
    return keep


def _constraint_matrix(WN, WT, S):
    """[W_N,S | independent W_T,S] and the indices of the tangential columns kept."""
    n = WN.shape[0]
    N = WN[:, list(S)] if S else np.zeros((n, 0))
    tk = [S[i] for i in _independent([WT[:, j] for j in S], N)] if S else []
    return np.column_stack([N, WT[:, tk]]) if S else N, tk


class _Phase:
    """Dynamics of one phase (fixed set S of closed contacts)."""

    def __init__(self, model, S: tuple[int, ...], q, v):
        self.model, self.S = model, S
        _, WN, WT, _, _ = model.contacts(q, v)
        _, self.tk = _constraint_matrix(WN, WT, S)

    def solve(self, t, q, v):
        """Accelerations, normal contact forces of S and all normal accelerations."""
        m = self.model
        M, h = m.mass(q), m.forces(t, q, v)
        g, WN, WT, wN, wT = m.contacts(q, v)
        S = list(self.S)
        W = np.column_stack([WN[:, S], WT[:, self.tk]])
        what = np.concatenate([wN[S], wT[self.tk]])
        if W.shape[1]:
            Mi = np.linalg.solve(M, np.column_stack([h, W]))
            G = W.T @ Mi[:, 1:]
            lam = np.linalg.solve(G, -(W.T @ Mi[:, 0]) - what)
            a = Mi[:, 0] + Mi[:, 1:] @ lam
        else:
            a, lam = np.linalg.solve(M, h), np.zeros(0)
        return a, lam[:len(S)], WN.T @ a + wN, g

    def force_map(self, q, v):
        """(L, c) with λ_N,S(t) = L h(t) + c at a fixed state (for locked phases)."""
        m = self.model
        M = m.mass(q)
        _, WN, WT, wN, wT = m.contacts(q, v)
        S = list(self.S)
        W = np.column_stack([WN[:, S], WT[:, self.tk]])
        MiW = np.linalg.solve(M, W)
        Gi = np.linalg.inv(W.T @ MiW)
        L = -(Gi @ MiW.T)
        c = -(Gi @ np.concatenate([wN[S], wT[self.tk]]))
        return L[:len(S)], c[:len(S)]

    def rhs(self, t, y):
        n = self.model.n
        q, v = y[:n], y[n:2 * n]
        a = self.solve(t, q, v)[0]
        pg, pd = self.model.powers(t, q, v)
        return np.concatenate([v, a, [pg, pd]])


def _project_q(model, K, q, v) -> np.ndarray:
    """One Newton step of q onto g_N,K = 0 (minimal in the M metric)."""
    if not K:
        return q
    K = list(K)
    g, WN, _, _, _ = model.contacts(q, v)
    N = WN[:, K]
    MiN = np.linalg.solve(model.mass(q), N)
    return q - MiN @ np.linalg.solve(N.T @ MiN, g[K])


def _project(model, S, q, v) -> np.ndarray:
    """Remove integration drift: q onto g_N,S = 0, then q̇ onto Wᵀq̇ = 0."""
    if not S:
        return np.concatenate([q, v])
    q = _project_q(model, S, q, v)
    M = model.mass(q)
    g, WN, WT, _, _ = model.contacts(q, v)
    W, _ = _constraint_matrix(WN, WT, tuple(S))
    MiW = np.linalg.solve(M, W)
    v = v - MiW @ np.linalg.solve(W.T @ MiW, W.T @ v)
    return np.concatenate([q, v])


def _select(model, t, q, v, cands, ftol) -> tuple[int, ...]:
    """Largest subset of `cands` with λ_N ≥ 0 and g̈_N ≥ 0 on the rest (Signorini).

    When round-off leaves no subset exactly consistent (a grazing contact whose
    force or acceleration is zero to within ~1e-6 of the load scale), the subset
    with the smallest relative violation is taken; a larger violation raises.
    """
    cands = tuple(sorted(int(c) for c in cands))
    f_scale = ftol * 1e10
    best, best_viol = None, np.inf
    for size in range(len(cands), -1, -1):
        for S in itertools.combinations(cands, size):
            ph = _Phase(model, S, q, v)
            a, lam, gdd, _ = ph.solve(t, q, v)
            rest = [j for j in cands if j not in S]
            if np.all(lam >= -ftol) and np.all(gdd[rest] >= -ftol):
                return S
            a_scale = max(np.abs(a).max(), 1e-300)
            viol = max(np.max(-lam, initial=0.0) / f_scale,
                       np.max(-gdd[rest], initial=0.0) / a_scale)
            if viol < best_viol:
                best, best_viol = S, viol
    if best_viol <= 1e-5:
        return best
    raise SolverError(f"t = {t:.9g}: no consistent set of closed contacts among {cands} "
                      f"(smallest relative violation {best_viol:.3g})")


def _events(model, ph: _Phase, k: int, y0, gap_eps: float):
    """Terminal events of a phase: λ_N,i → 0 for closed contacts, g_N,j → 0 for open ones.

    Each gap event is shifted to start at ≥ `gap_eps` above zero, so a contact
    that has just bounced off (g = 0, ġ > 0) is caught when it comes back
    within the first step.
    """
    n = model.n
    g0 = model.contacts(y0[:n], y0[n:2 * n])[0]
    evs = []
    for j in range(k):
        if j in ph.S:
            i = ph.S.index(j)

            def f(t, y, i=i):
                return ph.solve(t, y[:n], y[n:2 * n])[1][i]
        else:
            def f(t, y, j=j, off=gap_eps - min(g0[j], 0.0)):
                return model.contacts(y[:n], y[n:2 * n])[0][j] + off
        f.terminal, f.direction = True, -1
        evs.append(f)
    for name, fn in getattr(model, "events", ()):
        def f(t, y, fn=fn):
            return fn(t, y[:n], y[n:2 * n])
        f.terminal, f.direction, f.name = True, 0, name
        evs.append(f)
    return evs


def _grid(t0, t1, dt_out):
    if dt_out is None:
        return np.array([t0, t1])
    k0, k1 = int(np.floor(t0 / dt_out)) + 1, int(np.ceil(t1 / dt_out))
    inner = dt_out * np.arange(k0, k1)
    return np.concatenate([[t0], inner[(inner > t0) & (inner < t1)], [t1]])


class _Driver:
    """State and bookkeeping of one `simulate_contacts` run."""

    def __init__(self, model, eps, opts):
        self.model, self.eps, self.o = model, eps, opts
        self.out, self.events, self.loss = [], [], 0.0

    def record(self, ts, ys, S):
        n = self.model.n
        qs, vs = ys[:n].T, ys[n:2 * n].T
        E = np.array([self.model.energy(a, b) for a, b in zip(qs, vs)])
        mask = sum(1 << j for j in S)
        self.out.append((ts, qs, vs, np.full(ts.size, mask), E, ys[2 * n], ys[2 * n + 1],
                         np.full(ts.size, self.loss)))

    def smooth(self, ph, t, t_stop, y):
        """Integrate a phase; returns (t1, y1, indices of the events that fired)."""
        o, k = self.o, self.model.k
        sol = solve_ivp(ph.rhs, (t, t_stop), y, method="DOP853", rtol=o["rtol"],
                        atol=o["atol"], max_step=o["max_step"], dense_output=True,
                        events=_events(self.model, ph, k, y, 1e-3 * o["gap_tol"]))
        if sol.status == -1:
            raise SolverError(f"solve_ivp failed at t = {sol.t[-1]:.6g}: {sol.message}")
        t1 = float(sol.t[-1])
        ts = _grid(t, t1, o["dt_out"])
        self.record(ts, sol.sol(ts), ph.S)
        hit = [i for i, te in enumerate(sol.t_events) if te.size] if sol.status == 1 else []
        return t1, sol.y[:, -1].copy(), hit

    def locked(self, ph, t, t_stop, y):
        """A phase without free coordinates: scan λ_N(t) for the first sign change."""
        n, dt = self.model.n, self.o["locked_dt"]
        q, v = y[:n], y[n:2 * n]
        L, c = ph.force_map(q, v)

        def lam(s):
            return L @ self.model.forces(s, q, v) + c

        quiet = max(getattr(self.model, "quiet_after", np.inf), t)
        ts = np.arange(t, min(t_stop, quiet), dt)
        ts = np.unique(np.concatenate([ts, [min(t_stop, quiet), t_stop]]))
        t1, hit, la = t_stop, [], lam(ts[0])
        for a, b in zip(ts[:-1], ts[1:]):
            lb = lam(b)
            neg = np.flatnonzero(lb < 0.0)
            if neg.size:
                roots = [brentq(lambda s, i=i: lam(s)[i], a, b, xtol=1e-14) if la[i] > 0 else a
                         for i in neg]
                t1, hit = min(roots), [int(neg[np.argmin(roots)])]
                break
            la = lb
        ts_out = _grid(t, t1, self.o["dt_out"])
        self.record(ts_out, np.repeat(y[:, None], ts_out.size, axis=1), ph.S)
        return t1, y, [ph.S[h] for h in hit]

    def transition(self, t, y, S, hit_contacts):
        """Impact or lift-off at time t; returns the new closed set (and updates y)."""
        m, n, k, o = self.model, self.model.n, self.model.k, self.o
        q, v = y[:n], y[n:2 * n]
        g = m.contacts(q, v)[0]
        closing = [j for j in hit_contacts if j not in S]
        if closing:
            K = tuple(sorted(int(j) for j in set(S) | set(closing)
                             | {j for j in range(k) if abs(g[j]) <= o["gap_tol"]}))
            y[:n] = q = _project_q(m, K, q, v)          # the impact happens at g_N = 0
            _, WN, WT, _, _ = m.contacts(q, v)
            _, tk = _constraint_matrix(WN, WT, K)
            approach = -(WN[:, closing].T @ v).min(initial=0.0)
            if approach < o["zeno_velocity"]:        # accumulation of impacts: come to rest
                res, kind = None, "zeno_rest"
                e_before = m.energy(q, v)
                y[:2 * n] = _project(m, K, q.copy(), v.copy())
                self.loss += e_before - m.energy(y[:n], y[n:2 * n])
                cands = list(K)
            else:
                res = poisson_impact(m.mass(q), WN[:, list(K)], WT[:, tk], v, self.eps[list(K)])
                y[n:2 * n] = res.u_plus
                self.loss += res.energy_loss
                cands = [K[i] for i, st in enumerate(res.final_states) if st == "closed"]
                kind = "impact"
        else:                                     # lift-off: the unloading contact leaves
            res, kind, K = None, "liftoff", tuple(hit_contacts)
            cands = [j for j in S if j not in hit_contacts]
        S_new = _select(m, t, y[:n], y[n:2 * n], cands, o["ftol"])
        self.events.append(ContactEvent(t, kind, tuple(S), S_new, res, tuple(int(j) for j in K)))
        self.record(np.array([t]), y[:, None], S_new)
        return S_new

    def run(self, y, S, t, t_end, breakpoints):
        m, n, k = self.model, self.model.n, self.model.k
        names = [name for name, _ in getattr(m, "events", ())]
        status, message = "completed", f"reached t_end = {t_end:g} s"
        while t < t_end:
            if len(self.events) >= self.o["max_events"]:
                status = "max_events"
                message = f"stopped after {len(self.events)} events at t = {t:.6g} s"
                break
            y[:2 * n] = _project(m, S, y[:n], y[n:2 * n])
            ph = _Phase(m, S, y[:n], y[n:2 * n])
            t_stop = next((b for b in breakpoints if b > t + 1e-12), t_end)
            if len(S) + len(ph.tk) >= n:
                t, y, hit = self.locked(ph, t, t_stop, y)
            else:
                t, y, idx = self.smooth(ph, t, t_stop, y)
                model_ev = [names[i - k] for i in idx if i >= k]
                if model_ev:
                    self.events.append(ContactEvent(t, model_ev[0], S, S))
                    status, message = model_ev[0], f"{model_ev[0]} at t = {t:.6g} s"
                    break
                hit = [i for i in idx if i < k]
            if hit:
                S = self.transition(t, y, S, hit)
        return status, message


def simulate_contacts(model, q0, v0, t_end: float, eps_p, *, t0: float = 0.0,
                      dt_out: float | None = None, rtol: float = 1e-10, atol: float = 1e-10,
                      gap_tol: float = 1e-8, zeno_velocity: float = 0.0,
                      max_events: int = 10_000, breakpoints=(), max_step: float = np.inf,
                      locked_dt: float = 0.005) -> ContactResponse:
    """Integrate a contact model phase by phase with Poisson impacts (paper 000).

    Parameters
    ----------
    model : object
        See the module docstring.
    q0, v0 : array_like, shape (n,)
        Initial state; contacts with |g_N| ≤ `gap_tol` are candidates to be closed.
    t_end : float
    eps_p : float or array_like, shape (k,)
        Poisson's coefficient per contact.
    dt_out : float, optional
        Sampling interval (default: segment ends only).
    rtol, atol : float
        `solve_ivp` tolerances (DOP853).
    gap_tol : float
        Gap below which a contact takes part in an impact or a phase (m).
    zeno_velocity : float
        An impact with an approach speed below this ends an accumulation of
        ever smaller impacts (bouncing, or rocking whose half-cycles shrink to
        zero): all contacts of the impact are kept closed, i.e. the velocity is
        projected onto their constraints, an event "zeno_rest" (m/s).
    max_events : int
    breakpoints : sequence of float
        Times where the excitation has a kink (integration restarts there).
    max_step : float
        Largest integration step of the smooth phases (s).
    locked_dt : float
        In a phase with no free coordinate (a block in full contact) the state
        does not move; the contact forces λ_N(t) are scanned on this grid (s)
        and a sign change is located by Brent's method.

    Returns
    -------
    ContactResponse
    """
    k = model.k
    eps = np.broadcast_to(np.asarray(eps_p, dtype=float), (k,)).copy()
    if not np.all((eps >= 0.0) & (eps <= 1.0)):
        raise InputError(f"`eps_p` = {eps_p!r}: Poisson's coefficient must lie in [0, 1]")
    if not t_end > t0:
        raise InputError(f"`t_end` = {t_end!r}: must exceed the start time {t0}")
    q, v = np.array(q0, dtype=float), np.array(v0, dtype=float)
    ftol = 1e-10 * max(np.abs(model.forces(t0, q, v)).max(), 1.0)
    opts = dict(rtol=rtol, atol=atol, gap_tol=gap_tol, zeno_velocity=zeno_velocity,
                max_events=max_events, max_step=max_step, locked_dt=locked_dt,
                dt_out=dt_out, ftol=ftol)
    g = model.contacts(q, v)[0]
    S = _select(model, t0, q, v, np.flatnonzero(np.abs(g) <= gap_tol), ftol)
    drv = _Driver(model, eps, opts)
    bps = sorted(b for b in breakpoints if t0 < b < t_end)
    status, message = drv.run(np.concatenate([q, v, [0.0, 0.0]]), S, float(t0), t_end, bps)
    cat = [np.concatenate([o[i] for o in drv.out]) for i in range(8)]
    return ContactResponse(t=cat[0], q=cat[1], v=cat[2], closed=cat[3].astype(int),
                           energy=cat[4], ground_work=cat[5], damping=cat[6],
                           impact_loss=cat[7], events=tuple(drv.events), status=status,
                           message=message)
