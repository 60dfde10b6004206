"""The two least-squares stages of `multimass.identify.calibrate` (see its module docstring).

`Problem` lays the unknowns of one stage out in a vector (the fitted model parameters,
then each trace's nuisance parameters and per-impact deviations), returns the weighted
residuals of that vector and their Jacobian by forward differences with a step per
unknown, and `solve` runs `scipy.optimize.least_squares` (trust-region reflective,
bounds) on it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize

from ._calibration_model import TrialRejected
from ._calibration_params import PARAMETERS
from ._calibration_peaks import measured_peaks, model_peaks

__all__ = ["Problem", "solve", "scan", "Unknown"]

_T_MARGIN = 0.3  # model time simulated beyond a trace's window (s): the filter's reach
_RELEASE_SHARE = 0.5  # the release rows end when θ has fallen to this share of θ0
_REJECTED = 1e3  # residual of a trial the model cannot run


@dataclass(frozen=True)
class Unknown:
    """One entry of the vector fitted: its label, start, bounds, step and scale."""

    label: str
    x0: float
    low: float
    high: float
    step: float
    scale: float
    case: str | None = None  # the trace it belongs to (None: a model parameter)
    kind: str = "parameter"  # parameter, theta0, t_offset, theta_bias, deviation
    corner: str | None = None  # a deviation's corner ("right", "left")


def release_rows(case) -> int:
    """The samples of a free trace that fit its release: until θ has fallen to
    `_RELEASE_SHARE` of the release angle — long before the first impact, so that no
    restitution acts on them (the Dirac-delta force switches on up to 0.01 rad before
    θ = 0, paper 001 Sec 4.3; rows up to 30 ms before the impact made a 20 %-low
    restitution fit the release better than the true one)."""
    x = np.abs(case.segments.smooth)
    first = case.large[0]
    k = first.start + int(np.argmax(x[first.start : first.stop] < _RELEASE_SHARE * first.peak))
    return max(k, 3)


@dataclass(eq=False)
class Problem:
    """One stage's unknowns, residuals and Jacobian.

    Parameters
    ----------
    sim : Simulator
    pset : ParameterSet
    cases : list of Case
    stage : int
        1: release rows and peak ratios of the free traces, fitting the restitution
        means and each release (θ0, t_offset); 2: the time histories of θ and the
        accelerations over each trace's window, fitting everything.
    per_impact : bool
        Stage 2: a deviation from the corner mean for every impact between two large
        half-cycles, with a Gaussian prior N(0, σ_r²).
    sigma_r : float
        σ_r of that prior (the specimen's).
    start : dict
        Label → start value, replacing the default starts (the specimen's, the first
        guesses of each case).
    scales : dict
        Stage 2: (case label, channel) → the residual scale that weights it.
    frozen : frozenset
        Labels held at their start values (not fitted).
    only : tuple, optional
        Stage 2: the channels compared (default each case's).
    """

    sim: object
    pset: object
    cases: list
    stage: int
    per_impact: bool
    sigma_r: float
    start: dict = field(default_factory=dict)  # label -> value replacing a default start
    scales: dict = field(default_factory=dict)  # (case, channel) -> residual scale
    frozen: frozenset = frozenset()  # labels held at their start values
    only: tuple | None = None  # stage 2: the channels used (None: each case's)
    unknowns: list = field(default_factory=list)
    n_evals: int = 0

    def __post_init__(self):
        every = self._unknowns()
        self.held = {un.label: un.x0 for un in every if un.label in self.frozen}
        self.unknowns = [un for un in every if un.label not in self.frozen]
        self.index = {un.label: i for i, un in enumerate(self.unknowns)}

    def _unknowns(self) -> list:
        fit = [n for n in self.pset.fit if self.stage == 2 or n in ("r_er", "r_el")]
        self.fitted = fit
        lo, hi = self.pset.x_bounds()
        box = dict(zip(self.pset.fit, zip(lo, hi)))
        x_start = dict(zip(self.pset.fit, self.pset.x0()))
        u = []
        coarse = 10.0 if self.stage == 1 else 1.0  # stage 1's features move in steps
        for n in fit:
            p = PARAMETERS[n]
            x0 = self.start.get(n, x_start[n])
            u.append(Unknown(n, x0, *box[n], coarse * p.step, p.scale))
        for c in self.used_cases:
            if c.free:
                th = abs(c.theta0)
                u.append(
                    Unknown(f"{c.label}:theta0", self.start.get(f"{c.label}:theta0", c.theta0),
                            c.theta0 - 0.3 * th, c.theta0 + 0.3 * th, coarse * 2e-5, 1e-3,
                            c.label, "theta0")
                )  # fmt: skip
                u.append(
                    Unknown(f"{c.label}:t_offset", self.start.get(f"{c.label}:t_offset", c.tau),
                            c.tau - 0.2, c.tau + 0.2, coarse * 1e-4, 2e-3, c.label, "t_offset")
                )  # fmt: skip
            if self.stage == 2:
                u.append(
                    Unknown(f"{c.label}:theta_bias",
                            self.start.get(f"{c.label}:theta_bias", c.bias),
                            -0.05, 0.05, 1e-5, 1e-3, c.label, "theta_bias")
                )  # fmt: skip
                if self.per_impact:
                    for k in range(c.n_impacts):
                        lab = f"{c.label}:r[{c.first_impact + k}]"
                        corner = c.segments.impacts[c.first_impact + k].corner
                        u.append(
                            Unknown(lab, self.start.get(lab, 0.0), -0.4, 0.4, 2e-4, 5e-3,
                                    c.label, "deviation", corner)
                        )  # fmt: skip
        return u

    # -- layout ------------------------------------------------------------------------
    def channels(self, case) -> tuple:
        return (
            case.channels
            if self.only is None
            else tuple(c for c in case.channels if c in self.only)
        )

    @property
    def used_cases(self) -> list:
        return [c for c in self.cases if self.stage == 2 or c.free]

    def x0(self) -> np.ndarray:
        return np.array([un.x0 for un in self.unknowns])

    def bounds(self):
        lo = np.array([un.low for un in self.unknowns])
        hi = np.array([un.high for un in self.unknowns])
        return lo, hi

    def value(self, x: np.ndarray, label: str, default: float) -> float:
        """An unknown's value in `x`, or its held value, or `default`."""
        i = self.index.get(label)
        if i is not None:
            return float(x[i])
        return float(self.held.get(label, default))

    def decode(self, x: np.ndarray) -> tuple[dict, dict]:
        """(physical model parameters, per-case {theta0, tau, bias, deviations})."""
        phys = dict(self.pset.start)
        for n in self.fitted:
            phys[n] = PARAMETERS[n].to_value(self.value(x, n, PARAMETERS[n].to_x(phys[n])))
        per = {}
        for c in self.used_cases:
            devs = ()
            if self.stage == 2 and self.per_impact:
                devs = (0.0,) * c.first_impact + tuple(
                    self.value(x, f"{c.label}:r[{c.first_impact + k}]", 0.0)
                    for k in range(c.n_impacts)
                )
            per[c.label] = {
                "theta0": self.value(x, f"{c.label}:theta0", c.theta0 if c.free else 0.0),
                "tau": self.value(x, f"{c.label}:t_offset", c.tau),
                "bias": self.value(x, f"{c.label}:theta_bias", c.bias),
                "deviations": devs,
            }
        return phys, per

    @staticmethod
    def t_end(case) -> float:
        return float(case.window[1] - case.t[0] + _T_MARGIN)

    # -- residuals ---------------------------------------------------------------------
    def run(self, phys, case, nuis):
        return self.sim.run(phys, case, nuis["theta0"], nuis["deviations"], self.t_end(case))

    def residuals(self, x: np.ndarray) -> np.ndarray:
        self.n_evals += 1
        try:
            return np.concatenate(list(self.blocks(x).values()))
        except TrialRejected:
            return np.full(self.size, _REJECTED)

    @property
    def size(self) -> int:
        if not hasattr(self, "_size"):
            self._size = self.residuals_of_start().size
        return self._size

    def residuals_of_start(self) -> np.ndarray:
        return np.concatenate(list(self.blocks(self.x0()).values()))

    def blocks(self, x: np.ndarray) -> dict:
        """Weighted residuals by (case, group): ``theta``, channel names, ``release``,
        ``ratios``, ``prior``."""
        phys, per = self.decode(x)
        out = {}
        for c in self.used_cases:
            nuis = per[c.label]
            rec = self.run(phys, c, nuis)
            if self.stage == 1:
                out.update(self._stage1(c, rec, nuis, phys))
            else:
                out.update(self._stage2(c, rec, nuis))
        return out

    def raw(self, x: np.ndarray) -> dict:
        """Stage 2: unweighted residuals (SI units) and fitted channel biases by (case,
        channel)."""
        phys, per = self.decode(x)
        out = {}
        for c in self.used_cases:
            nuis = per[c.label]
            rec = self.run(phys, c, nuis)
            for ch in self.channels(c):
                meas = np.asarray(c.trace.channels[ch])[c.idx]
                e = rec.at(c.columns[ch], c.t[c.idx] - nuis["tau"]) - meas
                b = nuis["bias"] if ch == "theta" else -float(np.mean(e))
                out[(c.label, ch)] = (e + b, b)
        return out

    def _stage2(self, c, rec, nuis) -> dict:
        out = {}
        for ch in self.channels(c):
            meas = np.asarray(c.trace.channels[ch])[c.idx]
            e = rec.at(c.columns[ch], c.t[c.idx] - nuis["tau"]) - meas
            e = e + nuis["bias"] if ch == "theta" else e - np.mean(e)  # a sensor's bias
            out[(c.label, ch)] = e / self.scales.get((c.label, ch), 1.0)
        if self.per_impact and c.n_impacts:
            devs = np.array(nuis["deviations"][c.first_impact :])
            out[(c.label, "prior")] = devs / self.sigma_r
        return out

    def _stage1(self, c, rec, nuis, phys) -> dict:
        seg, t = c.segments, c.t
        theta = np.asarray(c.trace.channels["theta"])
        a = slice(0, release_rows(c))
        sim_a = rec.at("theta", t[a] - nuis["tau"])
        noise = max(seg.noise, 1e-6)
        release = (sim_a + seg.bias - theta[a]) / noise
        k = len(c.large)
        p_sim = model_peaks(c, rec, k, seg.band)
        p_meas = np.maximum(measured_peaks(c).copy(), seg.band)
        p_sim[0] = p_meas[0] = abs(nuis["theta0"])  # the release: the fitted θ0 on both sides
        lr_sim, lr_meas = np.diff(np.log(p_sim)), np.diff(np.log(p_meas))
        out = {(c.label, "release"): release}
        if k > 1:
            out[(c.label, "ratios")] = (lr_sim - lr_meas) / self.ratio_sigma(c, phys)
        return out

    def ratio_sigma(self, c, phys) -> np.ndarray:
        """Standard deviation of each measured log peak ratio: the scatter of the
        restitution about its corner mean (log P_k+1/P_k ≈ 2 log r_k, so 2 σ_r / r̄) and
        the peaks' own noise (σ_θ over the samples of the parabola, about half the
        half-cycle's)."""
        seg = c.segments
        r_bar = 0.5 * (phys["r_er"] + phys["r_el"])
        scatter = 2.0 * self.sigma_r / r_bar
        n = np.array([max(0.5 * (h.stop - h.start), 3.0) for h in c.large])
        rel = seg.noise / np.sqrt(n) / np.array([h.peak for h in c.large])
        rel[0] = 0.0  # the release angle is fitted on the release rows
        return np.sqrt(scatter**2 + rel[:-1] ** 2 + rel[1:] ** 2)

    # -- Jacobian ----------------------------------------------------------------------
    def jacobian(self, x: np.ndarray, f0: np.ndarray | None = None) -> np.ndarray:
        """Forward differences, one step per unknown (backwards at an upper bound)."""
        f0 = self.residuals(x) if f0 is None else f0
        J = np.zeros((f0.size, x.size))
        for j, un in enumerate(self.unknowns):
            h = un.step if x[j] + un.step <= un.high else -un.step
            xj = x.copy()
            xj[j] += h
            fj = self.residuals(xj)
            if fj[0] == _REJECTED and np.all(fj == _REJECTED):
                xj[j] = x[j] - h
                fj = self.residuals(xj)
                h = -h
                if np.all(fj == _REJECTED):
                    continue
            J[:, j] = (fj - f0) / h
        return J


#: The coarse scan of stage 1: common factors applied to the restitution means' start.
SCAN_FACTORS = np.geomspace(0.75, 1.35, 13)


def scan(problem: Problem) -> dict:
    """Stage 1's start: the restitution means' start values times the best of
    `SCAN_FACTORS` (clipped to their bounds), by the stage's cost.

    Far from the optimum (the means 20 % low, say) the stage-1 cost has shallow
    local minima (half-cycles that die out, the Dirac-delta force switching on
    within the release rows); the scan, 13 runs per free trace, starts the descent
    in the right valley.
    """
    idx = [problem.index[n] for n in ("r_er", "r_el") if n in problem.index]
    if not idx:
        return {}
    x0 = problem.x0()
    lo, hi = problem.bounds()
    best, best_cost = None, math.inf
    for f in SCAN_FACTORS:
        x = x0.copy()
        x[idx] = np.clip(x0[idx] * f, lo[idx], hi[idx])
        cost = float(np.sum(problem.residuals(x) ** 2))
        if cost < best_cost:
            best, best_cost = x, cost
    return {problem.unknowns[i].label: float(best[i]) for i in idx}


def solve(problem: Problem, max_nfev: int):
    """`least_squares` on `problem` from its start; the result and its last Jacobian."""
    lo, hi = problem.bounds()
    x0 = np.clip(problem.x0(), lo, hi)
    scale = np.array([un.scale for un in problem.unknowns])
    memo = {}

    def fun(x):
        f = problem.residuals(x)
        memo["x"], memo["f"] = x.copy(), f
        return f

    def jac(x):
        f0 = memo["f"] if "x" in memo and np.array_equal(memo["x"], x) else None
        J = problem.jacobian(x, f0)
        memo["J"] = J
        return J

    sol = optimize.least_squares(
        fun, x0, jac=jac, bounds=(lo, hi), method="trf", x_scale=scale,
        ftol=1e-4, xtol=1e-5, gtol=1e-8, max_nfev=max_nfev,
    )  # fmt: skip
    return sol
