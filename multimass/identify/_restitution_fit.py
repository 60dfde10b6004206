"""The model-based estimate of `multimass.identify.restitution`, impact by impact.

The method and its measured figures are in `multimass.identify.impacts`. The pieces
come from calibration: the runs are `_calibration_model.Simulator`'s (recorded at
10 × the trace's rate through the trace's anti-alias filter, cached), each
least-squares window is a `_calibration_fit.Problem` solved by
`_calibration_fit.solve`, and the standard errors are `_calibration_stats.covariance`'s.
Here the unknowns are the coefficients of single impacts — by their index in the
simulation, matched to the trace's impacts by time — and the trace's nuisance
parameters (θ0, clock offset, θ bias).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ._calibration_fit import _T_MARGIN, Problem, Unknown, solve
from ._calibration_model import Simulator
from ._calibration_params import parameter_set
from ._calibration_setup import Case, cases
from ._calibration_stats import covariance

__all__ = ["Track", "ImpactFit", "track_of", "align", "fit_impacts"]

R_LOW = 0.05  # lowest coefficient tried (PerImpact's clip)
#: Trace samples: 99 % of the anti-alias filter's weight lies within ±12.6 of a jump, so
#: an impact reaches this far into the record on either side.
EDGE = 13
#: Added in quadrature to the standard error of each r from the noise (the figures are
#: in `multimass.identify.impacts`).
R_STD_FLOOR = 5e-4
#: … and where the run bounces after the impact (lands in full contact before the next).
R_STD_BOUNCE = 0.002
_PAST = 5  # trace samples past the next impact that show its step
_SCAN_STEP = 0.015  # an impact's r is scanned in these steps …
_SCAN_SPAN = 0.075  # … this far about its corner's mean so far (3 σ_r, paper 001 Table 1) …
_FINE_STEP = 0.002  # … and in these steps …
_FINE_SPAN = 0.03  # … this far about the best where its window's fit did not reach the noise:
_MISFIT = 2.0  # its mean square weighted residual above this
_PAIR_NFEV = 4  # evaluations of a window's least squares …
#: … and of the last one, over everything: with accelerations, and θ alone (its clock
#: and θ0 trade off with every r, a longer valley)
_GLOBAL_NFEV = {True: 5, False: 15}
_OVERSAMPLE = 10  # the recording rate of the runs, × the trace's (calibrate's default)
_MEAN = {"right": "r_er", "left": "r_el"}


@dataclass(eq=False)
class Track:
    """The fit so far: the runs, the trace's channel weights, the fitted values.

    Attributes
    ----------
    sim : Simulator
    case : Case
        The trace as calibration reads it (channels, segments, first guesses).
    phys : dict
        The model's parameters (`_calibration_params`): the specimen's corner means,
        damping and C_p.
    nuis : dict
        ``theta0`` (rad; 0 with table motion), ``t_offset`` (trace time of the model's
        t = 0, s), ``theta_bias`` (rad).
    scales : dict
        Channel → the residual scale that weights it (its residual RMS).
    values : dict
        Simulated impact index → r fitted (the others take the corner means).
    corners : dict
        Simulated impact index → "right" or "left".
    """

    sim: Simulator
    case: Case
    phys: dict
    nuis: dict
    scales: dict
    values: dict = field(default_factory=dict)
    corners: dict = field(default_factory=dict)

    @property
    def t(self) -> np.ndarray:
        return self.case.t

    def span(self, t0: float, t1: float) -> slice:
        a, b = np.searchsorted(self.t, [t0, t1])
        return slice(int(a), int(max(b, a + 1)))

    def deviations(self, values: dict, means: dict | None = None) -> tuple:
        """`values` as `PerImpact` deviations from the corner means (`phys` unless given)."""
        means = means or {"right": self.phys["r_er"], "left": self.phys["r_el"]}
        n = max(values, default=-1) + 1
        return tuple(values[k] - means[self.corners[k]] if k in values else 0.0 for k in range(n))

    def run(self, values: dict, t_stop: float, theta0: float | None = None, phys=None):
        """The recorded run to model time `t_stop` with `values` per impact."""
        phys = phys or self.phys
        means = {"right": phys["r_er"], "left": phys["r_el"]}
        th0 = self.nuis["theta0"] if theta0 is None else theta0
        return self.sim.run(phys, self.case, th0, self.deviations(values, means), float(t_stop))

    def residuals(self, rec, idx: slice, nuis: dict, weighted: bool = True) -> dict:
        """Channel → model minus trace over the samples `idx` (θ with its bias, each
        accelerometer less its mean there: its bias), divided by its scale if
        `weighted`."""
        tm = self.t[idx] - nuis["t_offset"]
        out = {}
        for ch in self.case.channels:
            e = rec.at(self.case.columns[ch], tm) - np.asarray(self.case.trace.channels[ch])[idx]
            e = e + nuis["theta_bias"] if ch == "theta" else e - e.mean()
            out[ch] = e / self.scales[ch] if weighted else e
        return out

    def rescale(self, idx: slice) -> None:
        """Each channel's scale: its residual RMS over `idx` with the values so far."""
        rec = self.run(self.values, self.t[idx.stop - 1] - self.nuis["t_offset"] + _T_MARGIN)
        for ch, e in self.residuals(rec, idx, self.nuis, weighted=False).items():
            self.scales[ch] = max(float(np.sqrt(np.mean(e * e))), 1e-12)


@dataclass(eq=False)
class _Window(Problem):
    """Least squares of some unknowns over the trace samples `idx`: ``r[k]`` (the k-th
    simulated impact's coefficient), ``theta_bias``, ``theta0``, ``t_offset``."""

    track: Track | None = None
    free: tuple = ()
    idx: slice | None = None
    t_stop: float = 0.0

    def _unknowns(self) -> list:
        tr, out = self.track, []
        th0, tau = tr.nuis["theta0"], tr.nuis["t_offset"]
        for lab in self.free:
            if lab.startswith("r["):
                x0 = tr.values[int(lab[2:-1])]
                # calibration's step and scale of a restitution (`_calibration_params`)
                out.append(Unknown(lab, x0, R_LOW, 1.0, 2e-4, 5e-3, kind="restitution"))
            elif lab == "theta0":  # the bounds, steps and scales of calibration's nuisance
                span = 0.3 * abs(th0)
                out.append(Unknown(lab, th0, th0 - span, th0 + span, 2e-5, 1e-3, kind=lab))
            elif lab == "t_offset":
                out.append(Unknown(lab, tau, tau - 0.2, tau + 0.2, 1e-4, 2e-3, kind=lab))
            else:
                out.append(Unknown(lab, tr.nuis[lab], -0.05, 0.05, 1e-5, 1e-3, kind=lab))
        return out

    def state(self, x: np.ndarray) -> tuple[dict, dict]:
        """(values per impact, nuisance parameters) at `x`."""
        values, nuis = dict(self.track.values), dict(self.track.nuis)
        for un, v in zip(self.unknowns, x):
            if un.kind == "restitution":
                values[int(un.label[2:-1])] = float(v)
            else:
                nuis[un.label] = float(v)
        return values, nuis

    def blocks(self, x: np.ndarray) -> dict:
        values, nuis = self.state(x)
        rec = self.track.run(values, self.t_stop, nuis["theta0"])
        res = self.track.residuals(rec, self.idx, nuis)
        return {(self.track.case.label, ch): e for ch, e in res.items()}

    def accept(self, x: np.ndarray) -> None:
        values, nuis = self.state(x)
        self.track.values.update(values)
        self.track.nuis.update(nuis)


def _window(track: Track, free, t0: float, t1: float) -> _Window:
    idx = track.span(t0, t1)
    t_stop = track.t[idx.stop - 1] - track.nuis["t_offset"] + _T_MARGIN
    free = tuple(f for f in free if f not in ("theta0", "t_offset") or track.case.free)
    return _Window(
        track.sim, None, [track.case], 2, False, math.inf, track=track, free=free, idx=idx,
        t_stop=t_stop,
    )  # fmt: skip


def track_of(trace, st, impact: str, accelerations: tuple, theta_min: float, options) -> Track:
    """The fit's start: the trace read as calibration reads it (`cases`: θ and the
    `accelerations` channels, segments, first guesses of θ0 and the clock offset), the
    specimen's corner means and damping, the model's C_p (``options["C_p"]`` if given)."""
    options = dict(options)
    cp = options.pop("C_p", None)
    start = {"cp": cp} if (cp is not None and impact != "CIM") else None
    phys = parameter_set(("r_er", "r_el"), impact, st.specimen, start).start
    case = cases([trace], st, (), tuple(accelerations), theta_min)[0]
    sim = Simulator(st, impact, _OVERSAMPLE, options)
    scales = {ch: (case.segments.noise if ch == "theta" else math.inf) for ch in case.channels}
    nuis = {"theta0": case.theta0, "t_offset": case.tau, "theta_bias": case.bias}
    return Track(sim, case, phys, nuis, scales)


def align(track: Track, t_first: float) -> None:
    """θ0 and the clock offset from the samples before the first impact (no restitution
    acts there), first on θ alone (weighted by its noise), then on every channel, each
    weighted by its residual RMS there (noise and model error together); the θ bias
    stays at the trace's rest value (on one half-cycle it trades off with θ0)."""
    seg = track.case.segments
    t0, t1 = track.t[0], t_first - EDGE / seg.fs
    if track.case.free:
        for _ in range(2):
            p = _window(track, ("theta0", "t_offset"), t0, t1)
            p.accept(solve(p, 20).x)
            track.rescale(p.idx)
    else:
        track.rescale(track.span(t0, t1))


@dataclass
class ImpactFit:
    """One trace impact fitted: its simulated impact, r, standard error, θ misfit."""

    model_impact: int
    r: float
    r_std: float = math.nan
    rms: float = math.nan
    bounce: bool = False  # the run lands in full contact before the next impact


def _match(track: Track, m, tol: float, t_stop: float = 0.0):
    """The index of the simulated impact nearest the trace's impact `m` (an `ImpactMark`)
    on its corner, or None if none is within `tol` (s) of it: in the run with the values
    so far to model time `t_stop` or past m.t + tol."""
    tau = track.nuis["t_offset"]
    rec = track.run(track.values, max(m.t - tau + tol, t_stop))
    found = [
        (e.time + tau, "right" if e.phase_after > 0 else "left")
        for e in rec.response.events
        if e.kind == "impact"
    ]
    if not found:
        return None
    k = int(np.argmin([abs(t - m.t) for t, _ in found]))
    t, corner = found[k]
    return k if abs(t - m.t) <= tol and corner == m.corner else None


def _bounces(rec, k: int) -> bool:
    """Whether the run `rec` lands in full contact between its impact `k` and the next:
    a bounce (CIM, small half-cycles), whose timing r_k sets in a narrow valley."""
    kinds = [e.kind for e in rec.response.events if e.kind in ("impact", "full_contact")]
    hits = [j for j, kind in enumerate(kinds) if kind == "impact"]
    if len(hits) <= k:
        return False
    nxt = hits[k + 1] if len(hits) > k + 1 else len(kinds)
    return "full_contact" in kinds[hits[k] + 1 : nxt]


def _scan(
    track: Track, k: int, idx: slice, t_stop: float, center=None, span=None, step=None
) -> float:
    """r of simulated impact `k` alone, the best of a scan over its own half-cycle `idx`
    on every channel: steps of `step` within `span` of `center` (default `_SCAN_STEP`,
    `_SCAN_SPAN`, its corner's mean so far: 3 σ_r of paper 001 Table 1), widened while
    the best is at an end.

    The misfit is a bowl 0.015–0.03 wide about the best r, with steps beyond, where the
    next impact's Dirac-delta force changes (S2 DD2, ±0.04 about the truth, the others
    at theirs); the scan lands in the bowl, least squares then finds its bottom. (Steps
    of 0.03 missed it: S1 CIM, seed 1, an impact 0.015 from two of them.)
    """
    corner = track.corners[k]
    same = [r for j, r in track.values.items() if track.corners.get(j) == corner and j != k]
    if center is None:
        center = float(np.mean(same)) if same else track.phys[_MEAN[corner]]
    span, step = span or _SCAN_SPAN, step or _SCAN_STEP
    costs: dict[float, float] = {}

    def cost(r: float) -> float:
        r = float(np.clip(r, R_LOW, 1.0))
        if r not in costs:
            rec = track.run(track.values | {k: r}, t_stop)
            e = np.concatenate(list(track.residuals(rec, idx, track.nuis).values()))
            costs[r] = float(e @ e)
        return costs[r]

    for r in center + np.arange(-span, span + 1e-9, step):
        cost(r)
    while True:  # widened while the best is at an end
        grid = sorted(costs)
        best = min(grid, key=costs.get)
        if best == grid[0] and best > R_LOW:
            cost(best - step)
        elif best == grid[-1] and best < 1.0:
            cost(best + step)
        else:
            return best


def fit_impacts(track: Track, n_fit: int, bar, warnings: list) -> dict:
    """Fit the first `n_fit` impacts of the trace, impact by impact, then all at once.

    Impact i is matched to a simulated impact (nearest in time on its corner; else the
    index after the last one's: at the corner mean the run may land in full contact
    and uplift instead), scanned alone (`_scan`) up to just past the next impact, then
    fitted by least squares with impact i − 1 from impact i − 1 up to the next impact —
    whose time is what r_{i−1} sets most precisely — on every channel (with the θ bias,
    θ0 and the clock offset while the window starts at the release). A window whose fit
    stays above the noise (`_MISFIT`) is scanned again in fine steps and refitted. Last,
    everything is refined together over the whole span, and the standard errors come
    from that fit's Jacobian (`covariance`), with `R_STD_FLOOR` (and `R_STD_BOUNCE`
    where the run bounces). Returns trace impact index → `ImpactFit`.
    """
    seg = track.case.segments
    half, impacts, t = seg.half_cycles, seg.impacts, track.t
    edge = EDGE / seg.fs
    fitted: dict[int, ImpactFit] = {}
    prev = None  # the trace index of the impact fitted last
    t_end = t[0]
    for i, m in enumerate(impacts[:n_fit]):
        before = half[m.before]
        tol = 0.5 * max(before.t_stop - before.t_start, 0.02)
        k = _match(track, m, tol)
        if k is None:  # e.g. full contact and uplift at the corner mean: the next index
            k = fitted[prev].model_impact + 1 if prev is not None else 0
        track.corners[k] = m.corner
        t_next = impacts[i + 1].t if i + 1 < len(impacts) else half[m.after].t_stop
        # a window ends before the next impact's force (Dirac-delta), or takes its step
        # (CIM: its r acts at θ = 0 only)
        t_end = t_next + (_PAST / seg.fs if track.sim.impact == "CIM" else -edge)
        own = track.span(m.t - edge, t_next + _PAST / seg.fs)  # the next impact's step too
        t_own = t[own.stop - 1] - track.nuis["t_offset"] + _T_MARGIN
        track.values[k] = coarse = _scan(track, k, own, t_own)
        ks = [k] if prev is None else [fitted[prev].model_impact, k]
        start = t[0] if len(fitted) < 2 else impacts[prev].t - edge
        free = [f"r[{j}]" for j in ks]
        if start == t[0]:  # the release in the window: the nuisance parameters too
            free += ["theta_bias", "theta0", "t_offset"]
        p = _window(track, free, start, t_end)
        sol = solve(p, _PAIR_NFEV)
        if 2.0 * sol.cost > _MISFIT * sol.fun.size:  # a narrow valley the scan stepped over
            held = dict(track.values)
            track.values[k] = _scan(track, k, own, t_own, coarse, _FINE_SPAN, _FINE_STEP)
            q = _window(track, free, start, t_end)
            again = solve(q, _PAIR_NFEV)
            track.values.clear()
            track.values.update(held)
            if again.cost < sol.cost:
                p, sol = q, again
        p.accept(sol.x)
        if _match(track, m, tol, p.t_stop) != k:  # in the fit's last run (cached)
            warnings.append(
                f"impact at t = {m.t:.4g} s: the simulation has no impact near it on the "
                f"{m.corner} corner; it and the later ones keep their energy estimates"
            )
            del track.values[k]
            break
        fitted[i] = ImpactFit(k, track.values[k])
        prev = i
        bar.update(i + 1)
    if not fitted:
        return fitted
    # everything together over the whole span: the sequential windows held the earlier
    # coefficients and the nuisance parameters
    whole = track.span(t[0], t_end)
    track.rescale(whole)
    free = [f"r[{f.model_impact}]" for f in fitted.values()] + ["theta_bias", "theta0", "t_offset"]
    p = _window(track, free, t[0], t_end)
    sol = solve(p, _GLOBAL_NFEV[len(track.case.channels) > 1])
    p.accept(sol.x)
    rows = p.blocks(sol.x)
    cov, _ = covariance(sol.jac, rows, np.array([un.scale for un in p.unknowns]))
    std = dict(zip((un.label for un in p.unknowns), np.sqrt(np.diag(cov))))
    rec = track.run(track.values, p.t_stop)
    for i, f in fitted.items():
        m = impacts[i]
        f.r = track.values[f.model_impact]
        f.bounce = _bounces(rec, f.model_impact)
        floor = math.hypot(R_STD_FLOOR, R_STD_BOUNCE) if f.bounce else R_STD_FLOOR
        f.r_std = math.hypot(float(std[f"r[{f.model_impact}]"]), floor)
        t_next = impacts[i + 1].t if i + 1 < len(impacts) else half[m.after].t_stop
        idx = track.span(m.t, t_next)
        e = track.residuals(rec, idx, track.nuis, weighted=False)["theta"]
        f.rms = float(np.sqrt(np.mean(e * e)))
    return fitted
