"""Collects samples, peaks and the energy ledger while `simulate` runs."""

from __future__ import annotations

import math

import numpy as np

from multimass.impact_models import gaussian_force as gf

from ..checks import energy_scale
from ..model import equations as eq
from ..model._phase import ActiveForce, Model
from ..model.eom import phase_rows
from ..response import Response

__all__ = ["Recorder"]


class Recorder:
    """Blocks of rows (t, y) sharing a phase, a force and the transition loss so far;
    per-half-cycle peaks.

    Rows are kept as whole blocks (one per segment, hold or transition), not one
    Python object per sample: building the `Response` is then vectorised.
    """

    def __init__(self, st, mdl: Model, output_dt, ag):
        self.st, self.mdl, self.dt, self.ag = st, mdl, output_dt, ag
        self.blocks: list[tuple[np.ndarray, np.ndarray, int, ActiveForce | None, float]] = []
        self.last_t = None
        self.loss = 0.0
        self.peaks, self.peak_times = [], []
        self.cand = None  # (|θ|, t) of the current half-cycle

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

    def _block(self, t, Y, phase, force):
        """Rows at times `t` (k,) with states `Y` (k, dim)."""
        t = np.asarray(t, dtype=float).reshape(-1)
        if t.size:
            Y = np.array(Y, dtype=float).reshape(t.size, -1)
            self.blocks.append((t, Y, phase, force, self.loss))
            self.last_t = float(t[-1])

    def _row(self, t, y, phase, force):
        """One row: `_block` of ([t], [y]), without converting lists (a run makes many)."""
        t, row = float(t), np.array(y, dtype=float).reshape(1, -1)
        self.blocks.append((np.array([t]), row, phase, force, self.loss))
        self.last_t = t

    def segment(self, sol, rhs, phase, force, names):
        """Store one solve_ivp segment and its θ̇ = 0 (peak) events."""
        if len(sol.t):
            self._block(sol.t, np.asarray(sol.y).T, phase, force)
        if phase and "peak" in names:
            k = names.index("peak")
            n = self.st.n
            for t, y in zip(sol.t_events[k], sol.y_events[k]):
                self._candidate(abs(y[n]), t)

    def hold(self, t0, t1, y):
        """A rigid body at rest: constant rows on the output grid in (t0, t1]."""
        t = self.grid(t0, t1, with_end=False)
        self._block(t, np.broadcast_to(np.asarray(y, dtype=float), (t.size, len(y))), 0, None)

    def add_loss(self, loss: float):
        """Energy lost in an instantaneous transition (J)."""
        self.loss += loss

    # -- half-cycles -------------------------------------------------------------
    def _candidate(self, a, t):
        if self.cand is None or a > self.cand[0]:
            self.cand = (float(a), float(t))

    def free_peak(self, a, t):
        """The peak ``|θ|`` = `a` of the free swing under way when a run stops early
        (`PhaseLoop.run`, ``stop_when_safe``), a candidate of the current half-cycle.

        Its time is `t`, the stop time: the closed form gives the peak, not when the
        swing reaches it.
        """
        self._candidate(a, t)

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
        if self.last_t is not None and self.last_t == t and self.cand is None:
            return
        self.end_phase(t, y, phase)

    # -- results --------------------------------------------------------------------
    def _forces(self, th, phase, code, forces) -> np.ndarray:
        """F_i of each row (`gaussian_force.impact_force` of its force's parameters; 0
        where none acts): `code` numbers each row's force in `forces`."""
        F = np.zeros(th.size)
        on = np.array([f is not None for f in forces], dtype=bool)[code]
        if on.any():
            params = np.array(
                [(1.0, 0.0, 1.0) if f is None else (f.E_ini, f.r, f.n) for f in forces]
            )
            E_ini, r, n = params[code[on]].T
            F[on] = gf.impact_force(th[on], phase[on].astype(float), E_ini, r, n, self.st.B)
        return F

    def _derived(self, phase: int, F: np.ndarray, t: np.ndarray, Y: np.ndarray):
        """Vectorised ü_g, total accelerations (Eq 7) and energies for rows of one phase
        whose impact force is `F`."""
        st, n = self.st, self.st.n
        m, H, B = st.m, st.H, st.B
        U, th, Ud, thd = Y[:, :n], Y[:, n], Y[:, n + 1 : 2 * n + 1], Y[:, 2 * n + 1]
        ag = np.asarray(self.ag(t), dtype=float).reshape(t.shape)
        r = phase_rows(st, phase, U, th, Ud, thd, ag, F)
        elastic = 0.5 * np.einsum("ij,jk,ik->i", U, st.K, U) if n else np.zeros_like(t)
        ud_m_ud = (Ud * Ud) @ m
        col = lambda x: x[:, None]  # a per-row value against the nodes
        if phase == 0:
            acc = eq.total_acceleration(0, B, st.g, U, r.uddot, H, 0.0, 0.0, col(ag), 1.0, 0.0)
            kinetic = eq.kinetic_energy(ud_m_ud, 0.0, 0.0, 0.0)
            return ag, acc, kinetic, np.zeros_like(t), elastic
        acc = eq.total_acceleration(
            phase, B, st.g, U, r.uddot, H, col(r.thetaddot), col(thd), col(ag), col(r.c), col(r.sn)
        )
        kinetic = eq.kinetic_energy(ud_m_ud, Ud @ (m * H), r.a_tt, thd)
        grav = eq.gravitational_energy(st.g, st.static_moment, r.lever, r.c, r.sn)
        return ag, acc, kinetic, grav, elastic

    def response(
        self, name, status, message, events, wall, options, n_rhs, t_end, floor: float = 0.0
    ) -> Response:
        """The `Response`; `floor` is the smallest energy scale (`multimass.checks.scale_floor`)."""
        sizes = [b[0].size for b in self.blocks]
        t = np.concatenate([b[0] for b in self.blocks])
        Y = np.concatenate([b[1] for b in self.blocks])
        numbers: dict = {}  # id(force) -> its number in `forces`
        forces, codes = [], []  # the forces; the number of each block's
        for _, _, _, f, _ in self.blocks:
            k = numbers.setdefault(id(f), len(numbers))
            if k == len(forces):
                forces.append(f)
            codes.append(k)
        code = np.repeat(codes, sizes)
        phase = np.repeat([int(b[2]) for b in self.blocks], sizes)
        loss = np.repeat([b[4] for b in self.blocks], sizes)
        rows = (t, Y, phase, loss, code, forces)
        peaks = (self.peaks, self.peak_times)
        return self.response_of(rows, peaks, name, status, message, events, wall, options,
                                n_rhs, t_end, floor)  # fmt: skip

    def response_of(
        self, rows, peaks, name, status, message, events, wall, options, n_rhs, t_end, floor
    ) -> Response:
        """The `Response` of `rows` = (t, Y, phase, impact loss so far, force, forces): the
        recorded rows, in the order they were recorded, and per row the number of its
        force in `forces`, a list of ActiveForce or None; `peaks` = (|θ| peaks, their
        times). `response` gives its blocks' rows; the whole compiled column run
        (`multimass.engines.fast.column_trace`) the rows its kernel wrote."""
        n = self.st.n
        t, Y, phase, loss, code, forces = rows
        order = np.argsort(t, kind="stable")
        Y, t, phase, loss, code = Y[order], t[order], phase[order], loss[order], code[order]
        ag, T, V, U = (np.zeros(t.size) for _ in range(4))
        A = np.zeros((t.size, n))
        F = self._forces(Y[:, n], phase, code, forces)
        for p in np.unique(phase).tolist():  # rows of one phase share their equations
            rows = phase == p
            ag[rows], A[rows], T[rows], V[rows], U[rows] = self._derived(
                p, F[rows], t[rows], Y[rows]
            )
        D, Wg, WF = Y[:, -3], Y[:, -2], Y[:, -1]
        impact = WF + loss
        E = T + V + U
        balance = E + D + impact - Wg - E[0]
        ref = energy_scale(E[0], float(np.max(np.abs(Wg))), 0.0, floor)
        data = {"t": t, "phase": phase, "theta": Y[:, n], "thetadot": Y[:, 2 * n + 1]}
        for i in range(n):
            data[f"u{i + 1}"] = Y[:, i]
        for i in range(n):
            data[f"udot{i + 1}"] = Y[:, n + 1 + i]
        for i in range(n):
            data[f"a{i + 1}"] = A[:, i]
        data.update(
            F_i=F,
            ag=ag,
            kinetic=T,
            gravitational=V,
            elastic=U,
            damping=D,
            impact=impact,
            ground_work=Wg,
            balance_error=balance,
        )
        return Response(
            structure_name=name,
            status=status,
            message=message,
            series=data,  # a table when first read
            events=events,
            peaks=np.array(peaks[0]),
            peak_times=np.array(peaks[1]),
            energy_reference=ref,
            energy_balance_error=float(np.max(np.abs(balance)) / ref),
            wall_time_s=wall,
            options=options,
            n_rhs=n_rhs,
            t_end=t_end,
        )
