"""The model side of `multimass.identify.calibrate`: runs recorded as the trace was.

`Simulator.run` simulates one trace's test for a set of model parameters (compiled
backend) and keeps the run in a small cache, so that the Jacobian columns of the
nuisance parameters that need no new run (the clock offset, the biases) cost none.
A run is *recorded* as a data-acquisition card would record it (`Recorded`): the
response on a uniform grid at ``oversample × fs``, held still before the release,
low-passed by the anti-alias filter of `multimass.identify.sampling` (flat to
0.4 fs, ≥ 80 dB from fs/2) and evaluated at any trace time by a cubic spline.
Without that filter the higher modes (up to 638 Hz in S1) alias into the record:
sampled at 1 kHz instead of 8 kHz, S1's a_A1 differs by 10 % of its peak, at
2 kHz by 2.3 %, at 4 kHz (the default, 20 × 200 Hz) by 0.7 % (measured for this
module; the sensor noise of the synthetic traces is 2 %).
"""

from __future__ import annotations

import math
import time
from collections import OrderedDict
from dataclasses import dataclass, replace

import numpy as np
import scipy.signal

from multimass.impact_models import CornerRestitution, Restitution
from multimass.impact_models.table2 import impact_model

from ..errors import InputError, SolverError
from ..model.structure import Structure, column
from ..simulation import simulate
from ..specimens import SpecimenError
from .sampling import anti_alias_fir

__all__ = ["PerImpact", "Simulator", "Recorded", "TrialRejected"]

_PAD_S = 0.3  # model time recorded before the release (s): room for clock offsets
_CACHE = 48


class TrialRejected(Exception):
    """A trial point the model cannot run (e.g. damping ratios whose Rayleigh fit is < 0)."""


@dataclass(frozen=True)
class PerImpact(Restitution):
    """The corner means, plus a deviation for some impacts (by their index in the run).

    The k-th impact of a run (`ImpactContext.impact`, the index among the impacts
    logged) takes its corner's mean plus ``deviations[k]`` (clipped to [0.05, 1]);
    the others take the mean (paper 001, Section 4.3: impact-specific values where the
    half-cycles are large, the corner means elsewhere).
    """

    means: CornerRestitution
    deviations: tuple = ()

    def value(self, ctx) -> float:
        r = self.means.value(ctx)
        k = getattr(ctx, "impact", ctx.index)
        if 0 <= k < len(self.deviations):
            r = min(max(r + self.deviations[k], 0.05), 1.0)
        return r


@dataclass(eq=False)
class Recorded:
    """One simulated run as the acquisition records it, on the model's clock.

    Attributes
    ----------
    response : Response
    values : dict
        Response column (``theta``, ``a3``, ...) → the filtered signal on a uniform
        grid of step `h` from `t0`, read between samples by 4-point Lagrange
        interpolation (error below 1e-4 of the amplitude at 100 Hz and 2 kHz).
    t0, h : float
    """

    response: object
    values: dict
    t0: float
    h: float

    @property
    def span(self) -> tuple[float, float]:
        n = next(iter(self.values.values())).size
        return self.t0 + self.h, self.t0 + (n - 3) * self.h

    def at(self, column: str, t_model: np.ndarray) -> np.ndarray:
        y = self.values[column]
        u = (np.asarray(t_model, dtype=float) - self.t0) / self.h
        i = np.clip(np.floor(u).astype(int), 1, y.size - 3)
        s = np.clip(u - i, 0.0, 1.0)  # outside the span: its end values
        ym, y0, y1, y2 = y[i - 1], y[i], y[i + 1], y[i + 2]
        return (
            -s * (s - 1.0) * (s - 2.0) / 6.0 * ym
            + (s + 1.0) * (s - 1.0) * (s - 2.0) / 2.0 * y0
            - (s + 1.0) * s * (s - 2.0) / 2.0 * y1
            + (s + 1.0) * s * (s - 1.0) / 6.0 * y2
        )


def _uniform(t: np.ndarray, y: np.ndarray, grid: np.ndarray, held: float) -> np.ndarray:
    """Samples (t, y) of a run from t = 0, whose t repeats at events (a jump), on the
    uniform `grid` (held at `held` before 0).

    A grid sample stands for its cell: where the response jumps inside a cell (an
    impact, the release) the sample takes the cell's mean, so the jump keeps its
    place between samples (as `multimass.identify.synthetic` records it).
    """
    h = grid[1] - grid[0]
    x = np.maximum(grid, 0.0)
    i = np.clip(np.searchsorted(t, x, side="right"), 1, t.size - 1)
    t0, t1 = t[i - 1], t[i]
    span = t1 - t0
    w = np.where(span > 0.0, (x - t0) / np.where(span > 0.0, span, 1.0), 1.0)
    values = np.where(grid < 0.0, held, y[i - 1] + w * (y[i] - y[i - 1]))
    same = np.flatnonzero(np.diff(t) == 0.0)
    t_jump = np.concatenate([[0.0], t[same]])
    size = np.concatenate([[y[0] - held], y[same + 1] - y[same]])
    cell = np.clip(np.rint((t_jump - grid[0]) / h).astype(int), 0, values.size - 1)
    before = np.clip((t_jump - (grid[cell] - 0.5 * h)) / h, 0.0, 1.0)
    took_after = t_jump <= grid[cell]
    np.add.at(values, cell, size * (1.0 - before - took_after))
    return values


class Simulator:
    """Runs of the calibrated model for the traces, recorded and cached.

    Parameters
    ----------
    st : Structure
    impact : str
        A Table 2 name (CIM, DD1 … DD5, DD).
    oversample : int
        A trace sampled at fs is matched by the response recorded at ``oversample × fs``
        and put through the anti-alias filter for fs.
    options : dict
        Options of `multimass.simulate`.
    """

    def __init__(self, st: Structure, impact: str, oversample: int, options: dict):
        self.st, self.impact = st, impact
        self.oversample = int(oversample)
        self._taps: dict = {}
        self.options = {"progress": False, "backend": "compiled"} | dict(options)
        self._structures: dict = {}
        self._cache: OrderedDict = OrderedDict()
        self.n_runs = 0
        self.seconds = 0.0
        self.listener = None  # called after each new run

    def structure(self, zeta1: float, zeta2: float) -> Structure:
        key = (zeta1, zeta2)
        st = self._structures.get(key)
        if st is None:
            spec = self.st.specimen
            if (zeta1, zeta2) == (spec.zeta_1, spec.zeta_2):
                st = self.st
            else:
                try:
                    st = column(replace(spec, zeta_1=zeta1, zeta_2=zeta2))
                except SpecimenError as err:
                    raise TrialRejected(str(err)) from None
            self._structures[key] = st
        return st

    def model(self, phys: dict, deviations: tuple = ()):
        """The impact model with the means of `phys` (and per-impact deviations)."""
        src = PerImpact(CornerRestitution(phys["r_er"], phys["r_el"]), tuple(deviations))
        cp = None if self.impact == "CIM" else phys["cp"]
        return impact_model(self.impact, self.st.specimen, restitution=src, C_p=cp)

    def run(self, phys: dict, case, theta0: float, deviations: tuple, t_end: float) -> Recorded:
        """The recorded run of `case`'s test (cached on every argument)."""
        key = (
            tuple(sorted(phys.items())), case.label, case.input_tag, float(theta0),
            tuple(deviations), t_end,
        )  # fmt: skip
        hit = self._cache.get(key)
        if hit is not None:
            self._cache.move_to_end(key)
            return hit
        st = self.structure(phys["zeta1"], phys["zeta2"])
        model = self.model(phys, deviations)
        wall = time.perf_counter()
        try:
            resp = simulate(
                st, case.excitation(theta0), model, t_end, output_dt=1.0 / self.fs_in(case),
                **self.options,
            )  # fmt: skip
        except InputError as err:
            raise TrialRejected(str(err)) from None
        self.seconds += time.perf_counter() - wall
        self.n_runs += 1
        if resp.status == "failed":
            raise SolverError(
                f"the simulation of {case.label} failed at parameters "
                f"{ {k: round(x, 6) for k, x in phys.items()} }: {resp.message}"
            )
        out = self._record(resp, case, theta0)
        self._cache[key] = out
        if len(self._cache) > _CACHE:
            self._cache.popitem(last=False)
        if self.listener is not None:
            self.listener(self.n_runs)
        return out

    def fs_in(self, case) -> float:
        return self.oversample * case.fs

    def taps(self, case) -> np.ndarray:
        """The anti-alias filter of `case`'s sampling rate, at the recording rate."""
        taps = self._taps.get(case.fs)
        if taps is None:
            taps = self._taps[case.fs] = anti_alias_fir(self.fs_in(case), case.fs)
        return taps

    def _record(self, resp, case, theta0: float) -> Recorded:
        df = resp.series
        t = df["t"].to_numpy(dtype=float)
        h = 1.0 / self.fs_in(case)
        taps = self.taps(case)
        half = (taps.size - 1) // 2
        n_pad = int(math.ceil(_PAD_S / h)) + half + 2
        grid = (np.arange(-n_pad, int(math.floor(t[-1] / h)) + 1)) * h
        values = {}
        for col in {*case.columns.values(), "theta"}:
            if col not in df.columns:
                continue
            y = df[col].to_numpy(dtype=float)
            held = theta0 if (col == "theta" and case.free) else 0.0
            sampled = _uniform(t, y, grid, held)
            values[col] = scipy.signal.fftconvolve(sampled, taps, mode="valid")
        return Recorded(resp, values, float(grid[half]), h)
