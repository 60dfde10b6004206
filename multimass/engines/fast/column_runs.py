"""`ColumnRun`: one column run laid out for `._column_kernel.column_run`.

A sweep of a column (a rocking spectrum) wants each run's outcome only. With
``backend="compiled"`` the whole run — every phase segment and every transition —
then goes to the compiled kernel in one call, and no Python runs between its
segments. `ColumnRun.of` says whether the kernel knows the run's parts:

* a column (N ≥ 1) on the compiled path (`multimass.engines.fast.FastPath`);
* the classical impact (CIM) or the Gaussian Dirac-delta force of paper 001 (their
  own classes, as `check_model` requires);
* restitution from a fixed value, per-corner means, Housner's or the modified
  coefficient (a value per corner), a random draw per impact (`RandomRestitution`;
  the run's generator's standard normals, drawn in advance) or impact-specific
  values followed by one of those (`EmpiricalRestitution`).

Anything else runs through `multimass.simulate_outcome`'s Python loop, as does a run
whose solver fails (for its message).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from multimass.impact_models import ImpactContext
from multimass.impact_models.models import Classical, DiracDelta
from multimass.impact_models.sources import (
    CornerRestitution,
    EmpiricalRestitution,
    FixedRestitution,
    HousnerRestitution,
    ModifiedRestitution,
    RandomRestitution,
)

from ...checks import scale_floor
from . import _column_kernel as ck
from .path import _EVENTS, _RTOL_MIN, event_params

__all__ = ["ColumnRun", "BROKEN", "NO_LOG"]

#: `run`'s code of a run the kernel could not finish (the Python loop says why).
BROKEN = ck.BROKEN
MORE_LOG = "more log"  # `_call`'s code of a run whose log did not fit
#: `column_run`'s log when it writes none: (rows, events, peaks) of no length
NO_LOG = (np.zeros((0, ck.ROW_Y + 1)), np.zeros((0, ck.EV_SIZE)), np.zeros((0, 2)))
_CORNER_SOURCES = (FixedRestitution, CornerRestitution, HousnerRestitution, ModifiedRestitution)
_FIRST_DRAWS = 256  # standard normals given to a random-restitution run; ×4 if short
# events and peaks a log has room for at first: _FIRST_LOG + _LOG_PER_S per second of the
# run (S1 released from 0.11 rad logs 7 events per second), rows twice that + the grid; ×4 if short
_FIRST_LOG, _LOG_PER_S = 256, 64
_KEYS = ("contact", "rocking", "activate", "deactivate")  # the order of ck.T_*


def _corners(source, st) -> tuple[float, float] | None:
    """(right, left) of a source whose value depends on the corner only, else None."""
    if type(source) not in _CORNER_SOURCES:
        return None
    u0 = np.zeros(st.n)
    ctx = lambda side: ImpactContext(st, side, u0, 0, None, 0)
    return float(source.value(ctx(1))), float(source.value(ctx(-1)))


def _restitution(source, st):
    """(kind, right, left, σ, floor, table) of a source `column_run` knows, else None."""
    if type(source) is RandomRestitution:
        return ck.R_RANDOM, source.right, source.left, source.sigma, source.floor, None
    if type(source) is EmpiricalRestitution:
        corners = _corners(source.fallback, st)
        if corners is None:
            return None
        return ck.R_TABLE, *corners, 0.0, 0.0, np.array(source.values, dtype=np.float64)
    corners = _corners(source, st)
    return None if corners is None else (ck.R_CORNERS, *corners, 0.0, 0.0, None)


def _tables():
    """The four event tables of `multimass.engines.fast.path` in `column_run`'s types."""
    return tuple(
        (
            codes,
            dirs,
            term,
            quiet,
            np.asarray(guarded, dtype=np.int64),
        )
        for codes, dirs, term, quiet, guarded in (_EVENTS[k][1:] for k in _KEYS)
    )


@dataclass(eq=False)
class ColumnRun:
    """The arguments of `column_run` for one run, and how to draw its restitution."""

    t_end: float
    phase: int
    y0: np.ndarray
    breakpoints: np.ndarray
    model: tuple
    ground: tuple
    modes: tuple
    rock: tuple
    ep: np.ndarray
    cfg: np.ndarray
    table: np.ndarray | None
    seed: int | None

    @classmethod
    def of(cls, st, model, fast, start, breakpoints, t_end, options) -> ColumnRun | None:
        """The run of `multimass.simulate_outcome`'s loop with these parts, or None if
        `column_run` does not know one of them (the module docstring lists what it knows).

        `fast` is the run's `FastPath`, `start` its (phase, y0), `breakpoints` the
        loop's segment ends (`multimass.engines._run.PhaseLoop.breakpoints`) and `options`
        its `SimulationOptions`.
        """
        if fast is None or st.n < 1 or type(model) not in (Classical, DiracDelta):
            return None
        restitution = _restitution(model.restitution, st)
        if restitution is None:
            return None
        r_kind, right, left, sigma, floor, table = restitution
        o = options
        cfg = np.zeros(ck.CF_SIZE)
        cfg[ck.CF_TDMIN], cfg[ck.CF_DELAY] = o.thetadot_min, fast.delay
        cfg[ck.CF_WINDOW], cfg[ck.CF_COUNT] = o.chatter_window, o.chatter_count
        cfg[ck.CF_METHOD], cfg[ck.CF_RTOL] = fast.code, max(float(o.rtol), _RTOL_MIN)
        cfg[ck.CF_ATOL], cfg[ck.CF_MAX_STEP] = float(o.atol), float(o.max_step)
        if model.has_force:
            cfg[ck.CF_FORCE] = 1.0
            cfg[ck.CF_CP], cfg[ck.CF_NMIN], cfg[ck.CF_Z] = fast.dd
            cfg[ck.CF_RELEASE] = model.release
        cfg[ck.CF_R_KIND], cfg[ck.CF_R_RIGHT], cfg[ck.CF_R_LEFT] = r_kind, right, left
        cfg[ck.CF_SIGMA], cfg[ck.CF_FLOOR] = sigma, floor
        cfg[ck.CF_FLOOR_E] = scale_floor(st, o.atol, o.energy_tol)
        cm = fast.contact
        if cm is not None:
            cfg[ck.CF_EXACT] = 1.0
            modes = (cm.phi, cm.w, cm.z, cm.gam, float(cm.h_max), cm.screen)
        else:  # unused; arrays of the same types
            e1, e2 = np.zeros(1), np.zeros((1, 1))
            modes = (e2, e1, e1, e1, 0.0, np.zeros((3, 1)))
        rm = fast.rocking
        if rm is not None:
            cfg[ck.CF_EXPONENTIAL] = 1.0
            rock = rm.arrays
        else:  # unused; arrays of the same types
            rock = _NO_ROCK
        phase, y0 = start
        return cls(
            t_end=float(t_end),
            phase=int(phase),
            y0=np.ascontiguousarray(y0, dtype=np.float64),
            breakpoints=np.asarray(breakpoints, dtype=np.float64),
            model=(fast.m, fast.H, fast.K, fast.C, fast.mp),
            ground=(fast.kind, fast.par, fast.samples),
            modes=modes,
            rock=rock,
            ep=event_params(st, o.thetadot_min, o.overturn_angle, fast.dd),
            cfg=cfg,
            table=table,
            seed=o.seed,
        )

    def run(self) -> tuple:
        """(code, overturn time, θ_max, impacts, RHS calls, energy balance error) of the
        run; `code` is ``"completed"``, ``"overturned"`` or `BROKEN`."""
        return self._call(self.cfg, NO_LOG)[:6]

    def trace(self, output_dt: float | None) -> tuple:
        """`run`'s tuple, then the run's log (rows, events, peaks; `._column_kernel`'s
        docstring lists their columns), rows sampled every `output_dt` s (None: at the
        segments' ends and transitions only, as `multimass.engines._recorder.Recorder`)."""
        cfg = self.cfg.copy()
        cfg[ck.CF_LOG] = 1.0
        cfg[ck.CF_OUTPUT_DT] = 0.0 if output_dt is None else float(output_dt)
        first = _FIRST_LOG + int(_LOG_PER_S * self.t_end)
        grid = 0 if output_dt is None else int(self.t_end / output_dt)
        sizes = [2 * first + 8 * self.breakpoints.size + grid, first, first]
        while True:
            log = (
                np.empty((sizes[0], ck.ROW_Y + self.y0.size)),
                np.empty((sizes[1], ck.EV_SIZE)),
                np.empty((sizes[2], 2)),
            )
            got = self._call(cfg, log)
            if got[0] != MORE_LOG:
                break
            sizes = [max(4 * a, int(b) + 1) for a, b in zip(sizes, got[6])]
        counts = got[6]
        return (*got[:6], *(a[: int(k)] for a, k in zip(log, counts)))

    def _call(self, cfg, log) -> tuple:
        """`column_run` with its draws made, and made again while they run short."""
        k = _FIRST_DRAWS
        while True:
            draws = self._draws(k)
            got = ck.column_run(
                self.t_end,
                self.phase,
                self.y0,
                self.breakpoints,
                *self.model,
                *self.ground,
                self.modes,
                self.rock,
                _TABLES,
                self.ep,
                cfg,
                draws,
                log,
            )
            if got[0] != ck.MORE_DRAWS:
                break
            k *= 4
        code, t_over, top, n_imp, n_rhs, err, n_log = got
        names = {ck.COMPLETED: "completed", ck.OVERTURNED: "overturned", ck.MORE_LOG: MORE_LOG}
        return names.get(code, BROKEN), t_over, top, n_imp, n_rhs, err, n_log

    def _draws(self, k: int) -> np.ndarray:
        """The restitution data: the first `k` standard normals of the run's generator
        (`multimass.engines._run.PhaseLoop.rng`), or the impact table."""
        if self.cfg[ck.CF_R_KIND] == ck.R_RANDOM:
            return np.random.default_rng(self.seed).standard_normal(k)
        return self.table if self.table is not None else np.zeros(0)


_TABLES = _tables()
_NO_ROCK = (
    np.zeros((1, 1)),
    np.zeros(1, np.complex128),
    np.zeros((1, 1), np.complex128),
    np.zeros((1, 1), np.complex128),
    np.zeros(1),
)
