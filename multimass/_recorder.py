"""Collects samples, peaks and the energy ledger while `simulate` runs."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ._phase import ActiveForce, Model
from .response import Response

__all__ = ["Recorder"]


class Recorder:
    """Rows of (t, phase, force, y, transition loss so far) and per-half-cycle peaks."""

    def __init__(self, st, mdl: Model, output_dt, ag):
        self.st, self.mdl, self.dt, self.ag = st, mdl, output_dt, ag
        self.rows_t, self.rows_y, self.rows_phase, self.rows_force, self.rows_loss = [], [], [], [], []
        self.loss = 0.0
        self.peaks, self.peak_times = [], []
        self.cand = None          # (|θ|, t) of the current half-cycle

    # -- sampling ---------------------------------------------------------------
    def grid(self, t0: float, t1: float, with_end: bool = True):
        """Output times in (t0, t1] on the output_dt grid, ending with t1 itself.

        Without recording (output_dt None) only t1, so a segment that reaches
        its stop time still returns its final state.
        """
        end = np.array([t1]) if with_end else np.empty(0)
        if self.dt is None:
            return end
        k0, k1 = math.floor(t0 / self.dt) + 1, math.floor(t1 / self.dt)
        pts = np.arange(k0, k1 + 1) * self.dt
        pts = pts[(pts > t0) & (pts < t1 - 1e-12 * max(1.0, abs(t1)))]
        return np.concatenate([pts, end])

    def _row(self, t, y, phase, force):
        self.rows_t.append(float(t))
        self.rows_y.append(np.array(y, dtype=float))
        self.rows_phase.append(phase)
        self.rows_force.append(force)
        self.rows_loss.append(self.loss)

    def segment(self, sol, rhs, phase, force, names):
        """Store one solve_ivp segment and its θ̇ = 0 (peak) events."""
        if np.size(sol.t):
            for t, y in zip(sol.t, np.asarray(sol.y).T):
                self._row(t, y, phase, force)
        if phase and "peak" in names:
            k = names.index("peak")
            n = self.st.n
            for t, y in zip(sol.t_events[k], sol.y_events[k]):
                self._candidate(abs(y[n]), t)

    def hold(self, t0, t1, y):
        """A rigid body at rest: constant rows on the output grid in (t0, t1]."""
        for t in self.grid(t0, t1, with_end=False):
            self._row(t, y, 0, None)

    def add_loss(self, loss: float):
        """Energy lost in an instantaneous transition (J)."""
        self.loss += loss

    # -- half-cycles -------------------------------------------------------------
    def _candidate(self, a, t):
        if self.cand is None or a > self.cand[0]:
            self.cand = (float(a), float(t))

    def start_phase(self, phase, t, y):
        self._row(t, y, phase, None)
        self.cand = None
        if phase:
            self._candidate(abs(y[self.st.n]), t)

    def end_phase(self, t, y, phase):
        self._row(t, y, phase, None)
        if phase:
            self._candidate(abs(y[self.st.n]), t)
            self.peaks.append(self.cand[0])
            self.peak_times.append(self.cand[1])
        self.cand = None

    def finish(self, t, y, phase):
        """Close the last half-cycle at the end of the run."""
        if self.rows_t and self.rows_t[-1] == t and self.cand is None:
            return
        self.end_phase(t, y, phase)

    # -- results --------------------------------------------------------------------
    def _derived(self, phase: int, force: ActiveForce | None, t: np.ndarray, Y: np.ndarray):
        """Vectorised ü_g, F_i, total accelerations (Eq 7) and energies for rows of one kind."""
        st, n = self.st, self.st.n
        m, H, B, g = st.m, st.H, st.B, st.g
        U, th, Ud, thd = Y[:, :n], Y[:, n], Y[:, n + 1:2 * n + 1], Y[:, 2 * n + 1]
        ag = np.asarray(self.ag(t), dtype=float).reshape(t.shape)
        F = np.zeros_like(t)
        elastic = 0.5 * np.einsum("ij,jk,ik->i", U, st.K, U) if n else np.zeros_like(t)
        if phase == 0:
            Udd = -(Ud @ st.C.T + U @ st.K.T) / m - ag[:, None] if n else U
            kinetic = 0.5 * (Ud * Ud) @ m if n else np.zeros_like(t)
            return ag, F, Udd + ag[:, None], kinetic, np.zeros_like(t), elastic
        s = float(phase)
        if force is not None:
            F = (-s * force.E_ini * (1 - force.r**2) / (B * force.n * math.sqrt(math.pi))
                 * np.exp(-(th / force.n) ** 2))                       # paper 001, Eq 14
        c, sn = np.cos(th), np.sin(th)
        mu = U * m
        smu = mu.sum(axis=1)
        height = float(m @ H) + st.m0 * st.h0
        lever = s * B * st.m_t - smu
        arm = s * B * m - mu
        bu = (-arm * (thd**2)[:, None] - Ud @ st.C.T - U @ st.K.T
              - m * (ag * c - g * sn)[:, None])                         # paper 001, Eq 4
        bt = (2.0 * thd * np.einsum("ij,ij->i", Ud, arm) - 2.0 * B * F
              - ag * (height * c + lever * sn) - g * (-height * sn + lever * c))   # Eq 5
        a_tt = st.J_p + np.einsum("ij,ij->i", U, mu) - 2.0 * s * B * smu
        thdd = (bt - bu @ H) / (a_tt - H @ (m * H))
        Udd = bu / m - np.outer(thdd, H) if n else bu
        acc = (Udd + np.outer(thdd, H) + (s * B - U) * (thd**2)[:, None]        # paper 001, Eq 7
               + (ag * c)[:, None] - g * sn[:, None])
        kinetic = (0.5 * (Ud * Ud) @ m + thd * (Ud @ (m * H)) + 0.5 * a_tt * thd**2
                   if n else 0.5 * a_tt * thd**2)
        grav = g * (height * (c - 1.0) + lever * sn)
        return ag, F, acc, kinetic, grav, elastic

    def response(self, name, status, message, events, wall, options, n_rhs, t_end) -> Response:
        n = self.st.n
        Y = np.array(self.rows_y)
        t = np.array(self.rows_t)
        order = np.argsort(t, kind="stable")
        Y, t = Y[order], t[order]
        phase = np.array(self.rows_phase)[order]
        force = [self.rows_force[i] for i in order]
        loss = np.array(self.rows_loss)[order]
        ag, F, T, V, U = (np.zeros(t.size) for _ in range(5))
        A = np.zeros((t.size, n))
        keys = [(int(p), id(f)) for p, f in zip(phase, force)]
        for key in set(keys):
            rows = np.array([k == key for k in keys])
            f = force[int(np.argmax(rows))]
            ag[rows], F[rows], A[rows], T[rows], V[rows], U[rows] = self._derived(key[0], f, t[rows], Y[rows])
        D, Wg, WF = Y[:, -3], Y[:, -2], Y[:, -1]
        impact = WF + loss
        E = T + V + U
        balance = E + D + impact - Wg - E[0]
        ref = max(abs(E[0]), float(np.max(np.abs(Wg))), 1e-300)
        data = {"t": t, "phase": phase, "theta": Y[:, n], "thetadot": Y[:, 2 * n + 1]}
        for i in range(n):
            data[f"u{i + 1}"] = Y[:, i]
        for i in range(n):
            data[f"udot{i + 1}"] = Y[:, n + 1 + i]
        for i in range(n):
            data[f"a{i + 1}"] = A[:, i]
        data.update(F_i=F, ag=ag, kinetic=T, gravitational=V, elastic=U, damping=D,
                    impact=impact, ground_work=Wg, balance_error=balance)
        return Response(structure_name=name, status=status, message=message,
                        series=pd.DataFrame(data), events=events,
                        peaks=np.array(self.peaks), peak_times=np.array(self.peak_times),
                        energy_reference=ref,
                        energy_balance_error=float(np.max(np.abs(balance)) / ref),
                        wall_time_s=wall, options=options, n_rhs=n_rhs, t_end=t_end)
