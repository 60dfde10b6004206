"""The model-based estimate of `multimass.identify.restitution`, impact by impact.

The method and its measured figures are in `multimass.identify.impacts`. The pieces
come from calibration: the runs are `_calibration_model.Simulator`'s (recorded at
10 × the trace's rate through the trace's anti-alias filter, cached), each
least-squares window is a `_calibration_fit.Problem` solved by
`_calibration_fit.solve`, and the standard errors are `_calibration_stats.covariance`'s.
Here the unknowns are the coefficients of single impacts — by their index in the
simulation, matched to the trace's impacts by time —, the model's parameters not
given (C_p, ζ1, ζ2 as their logarithms, with calibration's bounds and steps:
`Track.estimate`) and the trace's nuisance parameters (θ0, clock offset, θ bias);
`multimass.identify._restitution_report` says, for each, whether it was given,
estimated or ill-posed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ._calibration_fit import _T_MARGIN, Problem, Unknown, solve
from ._calibration_model import Simulator, TrialRejected
from ._calibration_params import PARAMETERS, parameter_set
from ._calibration_setup import Case, cases
from ._calibration_stats import LIMITS, MODEL_REL_FLOOR, SLICE, covariance, slice_probe
from ._misfit import MISFIT_P, NOISE_TOL, REF_MIN, THETA_MODEL_FLOOR, misfit_test, theta_misfit

__all__ = [
    "Track",
    "ImpactFit",
    "track_of",
    "align",
    "fit_impacts",
    "MODEL_PARAMETERS",
    "theta_misfit",
    "misfit_test",
    "MISFIT_P",
    "THETA_MODEL_FLOOR",
    "NOISE_TOL",
    "consider_covariance",
    "reproduces",
]

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
_RELEASE_STEP = 0.01  # s: the release time is scanned in these steps (`_scan_release`)
_OVERSAMPLE = 10  # the recording rate of the runs, × the trace's (calibrate's default)
#: The model parameters a trace can show besides the coefficients: the Dirac-delta
#: force's C_p (paper 001 Eq 15) and the Rayleigh damping ratios.
MODEL_PARAMETERS = ("cp", "zeta1", "zeta2")
#: Impacts fitted one by one before the model parameters are first estimated with them …
MODEL_IMPACTS = 4
#: The scan of C_p on the first impact (`_scan_cp`): factors of its start, 19 % apart
_CP_FACTORS = tuple(np.geomspace(0.5, 2.0, 9))
#: … then, r_k scanned again, about the best in steps of 6 %
_CP_FINE = tuple(np.geomspace(0.84, 1.19, 7))
#: … over this long after the impact (s; at least the anti-alias filter's reach). On S2
#: (C_p 1050, ζ1 × 0.5, ζ2 × 1.5, 200 Hz) with the specimen's damping held, the scan's
#: best was 1523 over the whole half-cycle after the impact, 1005 over 0.1 s of it
#: (1005 with the true damping too)
_CP_WINDOW = 0.1
_FIRST_NFEV = 8  # evaluations of that impact's least squares with the model parameters
#: … in passes of least squares (each re-weighting the channels) of this many evaluations
_MODEL_NFEV = (6, 6)
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
    estimate : tuple
        The model parameters estimated from the trace (some of "cp", "zeta1",
        "zeta2": those not given), fitted as their logarithms.
    std : dict
        After `fit_impacts`: each unknown of the last fit (``r[k]``, the model
        parameters, θ0, ``t_offset``, ``theta_bias``) → its standard error (marginal:
        from the covariance of every unknown together), in fitted units (log for the
        model parameters).
    correlation : dict
        After `fit_impacts`: (label, label) → correlation of the pairs of unknowns
        correlated beyond `LIMITS["correlation"]`.
    covariance : dict
        After `fit_impacts`: (label, label) → covariance of the last fit's unknowns.
    explored : dict
        After `fit_impacts`: each unknown of the last fit → (low, high), the bounds its
        least squares was allowed to explore, in the parameter's own units (C_p and ζ:
        calibration's bounds, which `_scan_cp` keeps to as well): what the data say of
        an ill-posed one.
    misfit : tuple
        After `fit_impacts`: (the worst channel's residual mean square over its limit,
        the channel) of `misfit_test` over the whole span fitted; above 1 the fit does
        not reproduce the trace.
    """

    sim: Simulator
    case: Case
    phys: dict
    nuis: dict
    scales: dict
    values: dict = field(default_factory=dict)
    corners: dict = field(default_factory=dict)
    estimate: tuple = ()
    std: dict = field(default_factory=dict)
    correlation: dict = field(default_factory=dict)
    covariance: dict = field(default_factory=dict)  # (label, label) → of the last fit
    explored: dict = field(default_factory=dict)  # label → (low, high) of the last fit
    #: After `fit_impacts`: (label, label) → the last fit's covariance with the model's
    #: error of the parameters estimated carried into every unknown
    #: (`consider_covariance`, `MODEL_REL_FLOOR`)
    consider: dict = field(default_factory=dict)
    #: After `fit_impacts`: `misfit_test` over the whole span fitted: (the worst
    #: channel's mean square over its limit, that channel)
    misfit: tuple = (math.nan, "")
    #: After `fit_impacts`: the model parameters estimated and θ0 → the slice check of the
    #: last fit's linearisation along it (`_calibration_stats.slice_probe`)
    rough: dict = field(default_factory=dict)
    #: After `fit_impacts`: the last fit's (trace samples, model time its runs stop at,
    #: trace time of the last window's end): what `reproduces` tests
    fitted_span: tuple = ()

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
    simulated impact's coefficient), the model parameters ``cp``, ``zeta1``, ``zeta2``
    (as logarithms, with calibration's bounds and steps), ``theta_bias``, ``theta0``,
    ``t_offset``."""

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
            elif lab in PARAMETERS:  # C_p, ζ: calibration's log units, bounds and steps
                p = PARAMETERS[lab]
                lo, hi = p.to_x(p.low), p.to_x(p.high)
                x0 = float(np.clip(p.to_x(tr.phys[lab]), lo, hi))
                out.append(Unknown(lab, x0, lo, hi, p.step, p.scale, kind="model"))
            elif lab == "theta0":  # the bounds, steps and scales of calibration's nuisance
                span = 0.3 * abs(th0)
                out.append(Unknown(lab, th0, th0 - span, th0 + span, 2e-5, 1e-3, kind=lab))
            elif lab == "t_offset":
                out.append(Unknown(lab, tau, tau - 0.2, tau + 0.2, 1e-4, 2e-3, kind=lab))
            else:
                out.append(Unknown(lab, tr.nuis[lab], -0.05, 0.05, 1e-5, 1e-3, kind=lab))
        return out

    def state(self, x: np.ndarray) -> tuple[dict, dict, dict]:
        """(values per impact, nuisance parameters, model parameters) at `x`."""
        values, nuis = dict(self.track.values), dict(self.track.nuis)
        phys = dict(self.track.phys)
        for un, v in zip(self.unknowns, x):
            if un.kind == "restitution":
                values[int(un.label[2:-1])] = float(v)
            elif un.kind == "model":
                phys[un.label] = PARAMETERS[un.label].to_value(float(v))
            else:
                nuis[un.label] = float(v)
        return values, nuis, phys

    def blocks(self, x: np.ndarray) -> dict:
        values, nuis, phys = self.state(x)
        rec = self.track.run(values, self.t_stop, nuis["theta0"], phys=phys)
        res = self.track.residuals(rec, self.idx, nuis)
        return {(self.track.case.label, ch): e for ch, e in res.items()}

    def accept(self, x: np.ndarray) -> None:
        values, nuis, phys = self.state(x)
        self.track.values.update(values)
        self.track.nuis.update(nuis)
        self.track.phys.update(phys)


def _window(track: Track, free, t0: float, t1: float) -> _Window:
    idx = track.span(t0, t1)
    t_stop = track.t[idx.stop - 1] - track.nuis["t_offset"] + _T_MARGIN
    free = tuple(f for f in free if f not in ("theta0", "t_offset") or track.case.free)
    return _Window(
        track.sim, None, [track.case], 2, False, math.inf, track=track, free=free, idx=idx,
        t_stop=t_stop,
    )  # fmt: skip


def track_of(
    trace, st, impact: str, accelerations: tuple, theta_min: float, options, given=None
) -> Track:
    """The fit's start: the trace read as calibration reads it (`cases`: θ and the
    `accelerations` channels, segments, first guesses of θ0 and the clock offset), the
    specimen's corner means, the model parameters `given` (name → value: some of
    "cp", "zeta1", "zeta2") and, for the others, the specimen's damping and Table 2's
    C_p as starts: those are estimated (`Track.estimate`; C_p not for CIM, which has
    none)."""
    given = dict(given or {})
    start = {k: float(x) for k, x in given.items() if not (k == "cp" and impact == "CIM")}
    phys = parameter_set(("r_er", "r_el"), impact, st.specimen, start or None).start
    estimate = tuple(
        n for n in MODEL_PARAMETERS if n not in given and not (n == "cp" and impact == "CIM")
    )
    case = cases([trace], st, (), tuple(accelerations), theta_min)[0]
    sim = Simulator(st, impact, _OVERSAMPLE, dict(options))
    scales = {ch: (case.segments.noise if ch == "theta" else math.inf) for ch in case.channels}
    nuis = {"theta0": case.theta0, "t_offset": case.tau, "theta_bias": case.bias}
    return Track(sim, case, phys, nuis, scales, estimate=estimate)


def align(track: Track, t_first: float) -> None:
    """θ0 and the clock offset from the samples before the first impact (no restitution
    acts there), first on θ alone (weighted by its noise), then on every channel, each
    weighted by its residual RMS there (noise and model error together); the θ bias
    stays at the trace's rest value (on one half-cycle it trades off with θ0)."""
    seg = track.case.segments
    t0, t1 = track.t[0], t_first - EDGE / seg.fs
    if track.case.free:
        _scan_release(track, track.span(t0, t1))
        for _ in range(2):
            p = _window(track, ("theta0", "t_offset"), t0, t1)
            p.accept(solve(p, 20).x)
            track.rescale(p.idx)
    else:
        track.rescale(track.span(t0, t1))


def _scan_release(track: Track, idx: slice) -> None:
    """The clock offset (`Track.nuis`) the best of a scan over the trace's samples `idx`
    before the first impact, on θ, in steps of `_RELEASE_STEP` from the first sample to
    the last (and the start's guess), θ0 held at its start (the first half-cycle's peak).

    The least squares of θ0 and the clock from the first guess alone (where θ leaves
    its held value, less the time to fall by the quiet band) stopped in another valley
    where the hold is noisy: synthetic S3, θ0 0.0767 rad, released at 0.284 s, 4.6 %
    noise, 263 Hz: the guess was the trace's first sample (0 s) and the fit released
    the model from 0.091 rad at 0.19 s, its θ held 0.014 rad off the trace's (4 × the
    noise) before; the later coefficients then made up for it.
    """
    t = track.t
    taus = [*np.arange(t[idx.start], t[idx.stop - 1], _RELEASE_STEP), track.nuis["t_offset"]]
    costs = {}
    for tau in taus:
        nuis = track.nuis | {"t_offset": float(tau)}
        try:
            rec = track.run({}, t[idx.stop - 1] - tau + _T_MARGIN)
        except TrialRejected:
            continue
        e = track.residuals(rec, idx, nuis)["theta"]
        costs[float(tau)] = float(e @ e)
    if costs:
        track.nuis["t_offset"] = min(costs, key=costs.get)


@dataclass
class ImpactFit:
    """One trace impact fitted: its simulated impact, r, standard error, θ misfit."""

    model_impact: int
    r: float
    r_std: float = math.nan
    rms: float = math.nan
    bounce: bool = False  # the run lands in full contact before the next impact
    #: `misfit_test` over the two half-cycles after the impact (they set its r: the
    #: next impact's time): the worst channel's mean square over its limit (above 1 the
    #: fit does not reproduce the trace there), and that channel
    misfit: float = math.nan
    misfit_channel: str = ""


def _misfit(track: Track, rec, idx: slice, ref: dict) -> tuple[float, str]:
    """(worst ratio / limit, its channel) of `misfit_test` over the samples `idx`: θ
    against the trace's noise, each accelerometer against its residuals `ref` (channel
    → (mean square, count)) before the first impact."""
    res = track.residuals(rec, idx, track.nuis, weighted=False)
    worst = (0.0, "")
    for ch, e in res.items():
        if ch == "theta":
            ratio, limit = theta_misfit(e, track.case.segments.noise)
        elif ch in ref:
            ratio, limit = misfit_test(e, *ref[ch])
        else:
            continue
        worst = max(worst, (ratio / limit, ch))
    return worst


def _reference(track: Track, rec, t_first: float) -> dict:
    """Accelerometer → (residual mean square, count) over the samples before the first
    impact less the filter's reach (none where fewer than `REF_MIN` samples): the
    fit's noise there, where no restitution and no C_p act."""
    seg = track.case.segments
    idx = track.span(track.t[0], t_first - EDGE / seg.fs)
    n = idx.stop - idx.start
    if n < REF_MIN:
        return {}
    res = track.residuals(rec, idx, track.nuis, weighted=False)
    return {ch: (max(float(np.mean(e * e)), 1e-300), n) for ch, e in res.items() if ch != "theta"}


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


@dataclass(eq=False)
class _Sequence:
    """The impact-by-impact pass so far: the impacts fitted, the last one, the window's end."""

    fitted: dict = field(default_factory=dict)  # trace impact index → ImpactFit
    prev: int | None = None  # the trace index of the impact fitted last
    t_end: float = 0.0  # the end of the last window (trace time)
    broken: bool = False  # an impact the simulation did not reproduce: stop
    scan_cp: bool = True  # scan C_p on the first impact (if estimated)


def _fit_one(track: Track, i: int, seq: _Sequence, warnings: list) -> None:
    """Trace impact `i` matched, scanned and fitted with the one before (`fit_impacts`)."""
    seg = track.case.segments
    half, impacts, t = seg.half_cycles, seg.impacts, track.t
    edge = EDGE / seg.fs
    fitted, prev, m = seq.fitted, seq.prev, impacts[i]
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
    if k in track.values and not seq.scan_cp:  # refitted after the model stage: from there
        coarse = track.values[k]
    else:
        track.values[k] = coarse = _scan(track, k, own, t_own)
    if (
        not fitted and seq.scan_cp and "cp" in track.estimate
    ):  # C_p's valley first, then r_k's again
        # the impact's spike alone: later, the damping's decay, not yet estimated, and the
        # next impact's force (its r near 1 on S2 swings it) move the scan's best C_p
        mine = track.span(m.t - edge, min(m.t + max(_CP_WINDOW, edge), t_next - edge))
        t_mine = t[mine.stop - 1] - track.nuis["t_offset"] + _T_MARGIN
        _scan_cp(track, k, mine, t_mine)
        track.values[k] = _scan(track, k, own, t_own)
        _scan_cp(track, k, mine, t_mine, _CP_FINE)
        track.values[k] = coarse = _scan(track, k, own, t_own)
        # then the damping with them, over the half-cycle after the impact (its decay):
        # held at the specimen's through the first impacts (S2, C_p 1050, ζ1 × 0.5, ζ2 ×
        # 1.5), their r came out up to 0.07 off and the model stage stopped at C_p = 50
        p = _window(track, [f"r[{k}]", *track.estimate], m.t - edge, t_next - edge)
        sol = solve(p, _FIRST_NFEV)
        p.accept(sol.x)
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
        seq.broken = True
        return
    fitted[i] = ImpactFit(k, track.values[k])
    seq.prev, seq.t_end = i, t_end


def _free(track: Track, seq: _Sequence) -> list:
    """Every unknown of a fit over the whole span: the coefficients fitted so far, the
    model parameters estimated, the θ bias, θ0 and the clock offset."""
    rs = [f"r[{f.model_impact}]" for f in seq.fitted.values()]
    return rs + list(track.estimate) + ["theta_bias", "theta0", "t_offset"]


def _model_stage(track: Track, seq: _Sequence) -> None:
    """The model parameters (`Track.estimate`) with every unknown fitted so far, by least
    squares over the span from the release to the last window's end, in passes that
    re-weight the channels by their residual RMS (at the start values the model's
    misfit, not the noise, sets it)."""
    t = track.t
    for nfev in _MODEL_NFEV:
        track.rescale(track.span(t[0], seq.t_end))
        p = _window(track, _free(track, seq), t[0], seq.t_end)
        p.accept(solve(p, nfev).x)


def _scan_cp(track: Track, k: int, idx: slice, t_stop: float, factors=None) -> None:
    """C_p (`Track.phys`) the best of a scan over the first impact's half-cycle `idx` on
    every channel, with r_k held: `factors` of its start (default `_CP_FACTORS`),
    widened while the best is at an end (within calibration's bounds).

    The Dirac-delta force's width sets the accelerations' spike at the impact (paper
    001 Eq 14–15): on S1 (C_p 2450, 2 % noise, 200 Hz) the first impact's misfit over
    its half-cycle, r_k scanned at each C_p, is one valley in log C_p — 4987 at 2475,
    1.3e4 at 2081 and 2943, 2.4e4 at 1750, 5.7e4 at 3500 — where least squares from
    Table 2's 1750 with r_k and the damping free stopped at 2345 with r 0.03–0.13 off
    on the next impacts (each r's own valley; the scan of `_fit_one` finds them once
    C_p is near). The window `idx` is the spike's (`_CP_WINDOW`).
    """
    bounds = PARAMETERS["cp"].low, PARAMETERS["cp"].high
    start = track.phys["cp"]
    costs: dict[float, float] = {}

    def cost(f: float) -> float:
        if f not in costs:
            phys = track.phys | {"cp": float(np.clip(start * f, *bounds))}
            try:
                rec = track.run(track.values, t_stop, phys=phys)
            except TrialRejected:
                costs[f] = math.inf
                return costs[f]
            e = np.concatenate(list(track.residuals(rec, idx, track.nuis).values()))
            costs[f] = float(e @ e)
        return costs[f]

    factors = factors or _CP_FACTORS
    for f in factors:
        cost(f)
    step = factors[1] / factors[0]
    while True:  # widened while the best is at an end
        grid = sorted(costs)
        best = min(grid, key=costs.get)
        if best == grid[0] and start * best > bounds[0]:
            cost(best / step)
        elif best == grid[-1] and start * best < bounds[1]:
            cost(best * step)
        else:
            break
    track.phys["cp"] = float(np.clip(start * best, *bounds))


def _bounds(un: Unknown) -> tuple[float, float]:
    """An unknown's bounds in its parameter's own units (C_p, ζ are fitted as logs)."""
    if un.kind == "model":
        to = PARAMETERS[un.label].to_value
        return float(to(un.low)), float(to(un.high))
    return float(un.low), float(un.high)


def consider_covariance(cov: np.ndarray, considered, floor: float = MODEL_REL_FLOOR) -> np.ndarray:
    """The covariance `cov` of a fit's unknowns with an error of standard deviation
    `floor` of each unknown `considered` (indices) that the noise does not explain,
    carried into every unknown.

    The fit leaves every unknown at its best for the considered ones it found; an
    error δ of theirs (independent, each of variance `floor`²) moves the unknowns by
    B δ, B = Σ_·p Σ_pp⁻¹ the regression of all on them (from the joint covariance), so
    the covariance is Σ + F B Bᵀ, F = `floor`²: the "consider" covariance of
    parameters held at uncertain values (Schmidt's consider filter; Tapley, Schutz &
    Born, Statistical Orbit Determination, 2004, §6.3). A considered unknown itself
    gets Σ_pp + F (B's row of it is its unit vector). Considered unknowns whose
    covariance with the others is not finite (directions the data do not see) are
    left out: their marginal variance is infinite already.
    """
    cov = np.asarray(cov, dtype=float)
    seen = np.flatnonzero(np.isfinite(np.diag(cov)))  # `covariance`'s unseen rows: inf
    ok = [int(np.searchsorted(seen, j)) for j in considered if j in seen and cov[j, j] > 0.0]
    out = cov.copy()
    if not ok or floor == 0.0:
        return out
    sub = cov[np.ix_(seen, seen)]
    # Σ_pp symmetric: Bᵀ = Σ_pp⁻¹ Σ_p· (least squares: Σ_pp may be near singular)
    B = np.linalg.lstsq(sub[np.ix_(ok, ok)], sub[ok, :], rcond=None)[0].T
    out[np.ix_(seen, seen)] = sub + floor**2 * (B @ B.T)
    return out


def _roughness(p: _Window, sol, sd: np.ndarray) -> dict:
    """`slice_probe` of the whole-span fit along each model parameter (log units, h =
    max(3 σ, `SLICE`)) and θ0 (h = max(3 σ, `SLICE` × θ0)), as `calibrate` probes its
    C_p and ζ. On S2 (coverage draw 35 of seed 0, 145 Hz, 3.8 % noise) θ0's std was
    1e-6 rad while the cost rose 47 times the predicted amount at −6e-6 rad and 1/53 of
    it at ±6e-4 rad, and the truth was 3e-5 rad away: a neighbouring minimum."""
    out = {}
    for j, un in enumerate(p.unknowns):
        if not (un.kind == "model" or un.label == "theta0") or not math.isfinite(sd[j]):
            continue
        rel = SLICE * (abs(float(sol.x[j])) if un.label == "theta0" else 1.0)
        out[un.label] = slice_probe(p.residuals, sol.x, sol.fun, sol.jac, j, max(3.0 * sd[j], rel))
    return out


def fit_impacts(track: Track, n_fit: int, bar, warnings: list) -> dict:
    """Fit the first `n_fit` impacts of the trace, impact by impact, then all at once.

    Impact i is matched to a simulated impact (nearest in time on its corner; else the
    index after the last one's: at the corner mean the run may land in full contact
    and uplift instead), scanned alone (`_scan`) up to just past the next impact, then
    fitted by least squares with impact i − 1 from impact i − 1 up to the next impact —
    whose time is what r_{i−1} sets most precisely — on every channel (with the θ bias,
    θ0 and the clock offset while the window starts at the release). A window whose fit
    stays above the noise (`_MISFIT`) is scanned again in fine steps and refitted.

    The model parameters not given (`Track.estimate`: C_p, ζ1, ζ2) start at the
    specimen's and Table 2's values; after the first `MODEL_IMPACTS` impacts they are
    fitted with those impacts' coefficients and the nuisance parameters
    (`_model_stage`), and held while the later impacts are fitted one by one. Last,
    everything — every coefficient, the model parameters, θ0, the clock offset, the θ
    bias — is refined together over the whole span, and the standard errors come from
    that fit's Jacobian (`covariance`: marginal, every unknown free), each r's with
    the model's error of the parameters estimated carried into it
    (`consider_covariance`, `Track.consider`) and `R_STD_FLOOR` (and `R_STD_BOUNCE`
    where the run bounces). Returns trace impact index → `ImpactFit`; `Track.std` and
    `Track.correlation` hold the last fit's.
    """
    seg = track.case.segments
    half, impacts, t = seg.half_cycles, seg.impacts, track.t
    seq = _Sequence(t_end=t[0])
    n_first = min(n_fit, MODEL_IMPACTS) if track.estimate else n_fit
    i = 0
    while i < n_fit:
        if i == n_first and seq.fitted and seq.scan_cp:
            _model_stage(track, seq)
            # the first impacts again, one by one with the model parameters held: the
            # stage's joint least squares leaves their r less precise than the pairs do
            # (S2, C_p 0.6 × Table 2's: r 2e-3 off at 0.999, and the next impact's scan
            # then landed 0.03 off)
            seq, i = _Sequence(t_end=t[0], scan_cp=False), 0
        _fit_one(track, i, seq, warnings)
        if seq.broken:
            break
        bar.update(i + 1)
        i += 1
    fitted = seq.fitted
    if not fitted:
        return fitted
    if n_first == n_fit and track.estimate and not seq.broken:
        _model_stage(track, seq)  # every impact fitted before the model parameters
    # everything together over the whole span: the sequential windows held the earlier
    # coefficients, the model and the nuisance parameters
    track.rescale(track.span(t[0], seq.t_end))
    p = _window(track, _free(track, seq), t[0], seq.t_end)
    sol = solve(p, _GLOBAL_NFEV[len(track.case.channels) > 1])
    p.accept(sol.x)
    rows = p.blocks(sol.x)
    cov, _ = covariance(sol.jac, rows, np.array([un.scale for un in p.unknowns]))
    labels = [un.label for un in p.unknowns]
    track.explored = {un.label: _bounds(un) for un in p.unknowns}
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, np.inf))
    track.std = {lab: float(x) for lab, x in zip(labels, sd)}
    track.covariance = {
        (a, b): float(cov[i, j]) for i, a in enumerate(labels) for j, b in enumerate(labels)
    }
    con = consider_covariance(cov, [labels.index(n) for n in track.estimate if n in labels])
    track.consider = {
        (a, b): float(con[i, j]) for i, a in enumerate(labels) for j, b in enumerate(labels)
    }
    track.rough = _roughness(p, sol, sd)
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(sd, sd)
    track.correlation = {
        (a, b): float(corr[i, j])
        for i, a in enumerate(labels)
        for j, b in enumerate(labels)
        if i < j and math.isfinite(corr[i, j]) and abs(corr[i, j]) > LIMITS["correlation"]
    }
    track.fitted_span = (p.idx, p.t_stop, seq.t_end)
    per, track.misfit, rec = reproduces(track, fitted)
    for i, f in fitted.items():
        m = impacts[i]
        f.r = track.values[f.model_impact]
        f.bounce = _bounces(rec, f.model_impact)
        floor = math.hypot(R_STD_FLOOR, R_STD_BOUNCE) if f.bounce else R_STD_FLOOR
        lab = f"r[{f.model_impact}]"
        f.r_std = math.hypot(math.sqrt(max(track.consider[(lab, lab)], 0.0)), floor)
        t_next = impacts[i + 1].t if i + 1 < len(impacts) else half[m.after].t_stop
        idx = track.span(m.t, t_next)
        e = track.residuals(rec, idx, track.nuis, weighted=False)["theta"]
        f.rms = float(np.sqrt(np.mean(e * e)))
        f.misfit, f.misfit_channel = per[i]
    return fitted


def reproduces(track: Track, fitted: dict) -> tuple[dict, tuple, object]:
    """The test of the fit (`misfit_test` via `_misfit`) with `track`'s values, run over
    the span fitted (`Track.fitted_span`): (trace impact i of `fitted` → (the worst
    channel's ratio to its limit, the channel) over what sets its r — its half-cycle
    and the next one, the next impact's time, within the span fitted —; the same over
    the whole span fitted, the test of the model parameters and the nuisance ones; the
    run). The accelerometers' reference is the run's own residuals before the first
    impact (`_reference`). `_restitution_input` runs it with the table motion's
    ``ag`` re-noised."""
    seg = track.case.segments
    half, impacts = seg.half_cycles, seg.impacts
    idx, t_stop, t_end = track.fitted_span
    rec = track.run(track.values, t_stop)
    ref = _reference(track, rec, impacts[0].t)
    per = {}
    for i in fitted:
        m = impacts[i]
        t_next = impacts[i + 1].t if i + 1 < len(impacts) else half[m.after].t_stop
        t_two = impacts[i + 2].t if i + 2 < len(impacts) else half[impacts[-1].after].t_stop
        two = track.span(m.t, max(min(t_two, t_end), t_next))
        per[i] = _misfit(track, rec, two, ref)
    return per, _misfit(track, rec, idx, ref), rec
