"""Empirical coefficients of restitution from a recorded trace (issue 14, item 1).

Paper 001 (Section 4.3) defines its CIM, DD1, DD3 and DD4 models (Table 2) with
impact-specific coefficients r_e estimated from the tests, and the per-corner means
r̄_er, r̄_el (with their spread σ_r) for half-cycles below 0.01 rad. `restitution`
gives both estimates of every impact of a trace:

**The energy estimate (the paper's).** During large rocking the total energy is
dominated by the gravitational potential (paper 001, Section 4.3). With
V(θ) = g (h (cos θ − 1) + ℓ sin θ) the potential of the undeformed column rocking by
θ about a pivot (paper 001, Eq 5's gravity term: h = Σ m_i H_i, ℓ = B m_t, for the
side of θ; `multimass.kinematics.gravitational_energy`), energy is conserved over a
half-cycle, so ½ J θ̇₋² = V(θ_k) before impact k and ½ J θ̇₊² = V(θ_{k+1}) after it;
with θ̇₊ = r θ̇₋,

    r_energy,k = sqrt( V(θ_{k+1}) / V(θ_k) ),

θ_k and θ_{k+1} the peaks of the half-cycles before and after the impact. Viscous
damping and the energy sent into vibration at the impact lower θ_{k+1} beyond the
restitution alone, so this estimate is biased low (by 0.002–0.012 on average and up
to 0.036 on single impacts on noiseless synthetic S1–S3 traces).

**The model-based estimate (`r`).** The impact model is simulated (compiled path)
from the release, impact by impact: r_k is the value that makes the simulated θ
match the trace over the half-cycle after impact k (least squares over its samples,
the next impact time included), with r_0 … r_{k−1} already fitted. The clock offset
of the trace, the θ sensor's bias and the release angle are fitted first on the
half-cycle before the first impact (no restitution involved). Each r_k is thus the
coefficient the *chosen impact model* needs to reproduce the test; CIM and the
Dirac-delta models (with their C_p) need different values for the same test.

Impacts between half-cycles whose peaks are both ≥ `theta_min` (0.01 rad, the
paper's rule) are *estimated*; the per-corner means r̄_er, r̄_el and σ_r are taken
over them. Smaller ones are fitted while the simulation must stay on the trace, and
reported, but the specimen fragment gives them the corner means, as the paper did.

>>> from multimass import FreeRelease
>>> from multimass.identify import synthetic_trace
>>> syn = synthetic_trace("S1", FreeRelease(theta0=0.11), "DD2", 2.0, seed=3, noise=0.0)
>>> est = restitution(syn.trace, "S1", "DD2", progress=False)
>>> est.impacts.loc[0, "corner"]
'left'
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy import optimize

from multimass.impact_models import CornerRestitution, Restitution

from .. import kinematics
from ..errors import InputError, SolverError
from ..excitations import FreeRelease
from ..progress import Progress
from ..records import Record
from ..result import json_ready
from ..simulation import simulate
from ..structure import Structure, from_specimen
from ..trace_metrics import channel_columns
from ..traces import Trace
from ._trace_checks import check_ag
from .segments import THETA_MIN, Segments, require_trace, segment_trace

__all__ = ["RestitutionEstimate", "restitution", "energy_restitution", "IMPACT_DEFAULT"]

#: The impact model fitted unless another is named (paper 001, Table 2: DD1's family).
IMPACT_DEFAULT = "DD"
_R_GRID = np.linspace(0.30, 1.0, 15)  # the coarse scan of each impact's r
_R_TOL = 2e-4  # the fine search stops when r is known to this


class _ByImpact(Restitution):
    """r of the k-th impact from `values` (a dict), else the corner means (`fallback`)."""

    def __init__(self, values: dict, fallback: Restitution):
        self.values, self.fallback = dict(values), fallback

    def value(self, ctx) -> float:
        r = self.values.get(ctx.impact)
        return float(r) if r is not None else self.fallback.value(ctx)


@dataclass(frozen=True, eq=False)
class RestitutionEstimate:
    """The coefficients of restitution identified from a trace (`restitution`).

    Attributes
    ----------
    impacts : pandas.DataFrame
        One row per impact found: ``t`` (trace time, s), ``corner`` ("right" or
        "left": the corner it lands on), ``r`` (the model-based estimate, the best
        one), ``r_energy`` (the paper's energy estimate), ``theta_before``,
        ``theta_after`` (the peaks around it, rad), ``estimated`` (both peaks ≥
        `theta_min`), ``model_impact`` (the index of the simulated impact it matched),
        ``rms`` (the θ misfit over its half-cycle, rad).
    r_mean_right, r_mean_left : float
        Means of `r` over the estimated impacts on each corner (paper 001's r̄_er,
        r̄_el); the specimen's value where a corner has none.
    sigma_r : float
        Pooled standard deviation of the estimated `r` about their corner means.
    energy_means : dict
        ``r_mean_right``, ``r_mean_left``, ``sigma_r`` of `r_energy`.
    alignment : dict
        ``t_offset`` (s: trace time of the release), ``theta_bias`` (rad), ``theta0``
        (rad, the fitted release angle; 0 for table motion).
    structure : Structure
    impact : str
        The impact model the model-based estimates are for.
    theta_min : float
    segments : Segments
    response : Response
        The simulation with every fitted coefficient (on the model's clock).
    warnings : tuple of str
    """

    impacts: pd.DataFrame
    r_mean_right: float
    r_mean_left: float
    sigma_r: float
    energy_means: dict
    alignment: dict
    structure: Structure
    impact: str
    theta_min: float
    segments: Segments
    response: object
    warnings: tuple = field(default=())

    def per_impact(self) -> list[float]:
        """The coefficients in the simulation's impact order, for `EmpiricalRestitution`:
        the estimated ones, the corner means for the rest, up to the last estimated one."""
        est = self.impacts[self.impacts["estimated"]]
        if est.empty:
            return []
        k_max = int(est["model_impact"].max())
        means = {"right": self.r_mean_right, "left": self.r_mean_left}
        corner_of = dict(zip(self.impacts["model_impact"], self.impacts["corner"]))
        fitted = dict(zip(est["model_impact"], est["r"]))
        out = []
        for k in range(k_max + 1):
            corner = corner_of.get(k)
            out.append(float(fitted.get(k, means.get(corner, 0.5 * sum(means.values())))))
        return out

    def table(self) -> dict:
        """The specimen's ``[restitution]`` table with the identified values."""
        return {
            "mean_right": round(self.r_mean_right, 4),
            "mean_left": round(self.r_mean_left, 4),
            "sigma": round(self.sigma_r, 4),
            "empirical": [round(r, 4) for r in self.per_impact()],
        }

    def fragment(self) -> str:
        """A specimen fragment: the ``[restitution]`` TOML table, with a comment."""
        from multimass.specimens.toml_text import format_table

        head = (
            f"# Restitution identified from {self.segments.trace.source} for impact model "
            f"{self.impact}\n# (multimass.identify.restitution; `empirical` in impact order, "
            "then the corner means)\n"
        )
        return head + format_table("restitution", self.table())

    def specimen_text(self, name: str | None = None, path=None) -> str:
        """The specimen's TOML file (`path`, default the bundled one of its name) with
        this ``[restitution]`` table and a new `name`; it loads back."""
        from multimass.specimens.toml_text import specimen_text

        note = f"identified from {self.segments.trace.source} for {self.impact}"
        return specimen_text(
            self.structure.specimen, {"restitution": self.table()}, note=note, name=name,
            path=path,
        )  # fmt: skip

    def restitution_source(self):
        """`EmpiricalRestitution` of `per_impact`, then these corner means."""
        from multimass.impact_models import EmpiricalRestitution

        return EmpiricalRestitution(
            tuple(self.per_impact()), CornerRestitution(self.r_mean_right, self.r_mean_left)
        )

    def summary(self) -> dict:
        """JSON-ready: ``impacts`` (t, corner, r, r_energy, …), the means, σ_r, alignment."""
        rows = [
            {k: (bool(v) if k == "estimated" else v) for k, v in row.items()}
            for row in self.impacts.to_dict(orient="records")
        ]
        return json_ready(
            {
                "specimen": self.structure.name,
                "impact": self.impact,
                "trace": self.segments.trace.source,
                "theta_min": self.theta_min,
                "impacts": rows,
                "r_mean_right": self.r_mean_right,
                "r_mean_left": self.r_mean_left,
                "sigma_r": self.sigma_r,
                "energy": self.energy_means,
                "n_estimated": int(self.impacts["estimated"].sum()),
                "alignment": self.alignment,
                "warnings": list(self.warnings),
            }
        )


def energy_restitution(structure, theta_before, theta_after) -> np.ndarray:
    """The paper's estimate r = sqrt(V(θ_after) / V(θ_before)) (paper 001, Section 4.3).

    Parameters
    ----------
    structure : Structure
    theta_before, theta_after : array_like
        Peaks ``|θ|`` (rad) of the half-cycles before and after each impact.
    """
    st = structure
    u0 = np.zeros(st.n)

    def V(theta):  # the potential of the undeformed structure rocking by |θ|
        return np.array([kinematics.gravitational_energy(st, 1, u0, abs(x)) for x in theta])

    a = np.atleast_1d(np.asarray(theta_before, dtype=float))
    b = np.atleast_1d(np.asarray(theta_after, dtype=float))
    return np.sqrt(V(b) / V(a))


def _structure(trace: Trace, structure) -> Structure:
    if structure is None:
        if not trace.specimen:
            raise InputError(
                f"{trace.source}: no specimen given and the trace has no `# specimen: NAME` "
                "line; give the specimen (e.g. --specimen S1)"
            )
        structure = trace.specimen
    st = structure if isinstance(structure, Structure) else from_specimen(structure)
    if st.n == 0:
        raise InputError(
            f"`structure` = {st.name!r}: a rigid block; restitution identification is "
            "for the multi-mass columns (their specimens carry corner means)"
        )
    return st


class _Fitter:
    """Simulations of the trace's test, compared with its θ and accelerations.

    The misfit of a trial is the vector of every channel's residuals over a window
    of samples, each channel divided by its weight σ: θ's noise at first; after the
    alignment, each channel's RMS misfit over the first half-cycle (noise and model
    error together), so that no channel dominates by its unit.
    """

    def __init__(self, st, trace, seg, impact, options):
        self.st, self.trace, self.seg, self.impact = st, trace, seg, impact
        self.t = np.asarray(trace.time, dtype=float)
        cols = channel_columns(trace, st)  # checks the trace's sensors against the specimen
        self.channels = [(name, col) for name, col in cols.items() if col == "theta"]
        self.data = {
            name: np.asarray(trace.channels[name], dtype=float) for name, _ in self.channels
        }
        self.sigma = {
            name: (seg.noise if col == "theta" else math.inf) for name, col in self.channels
        }
        self.ag = trace.ag
        self.options = {"progress": False, "backend": "compiled"} | options
        self.output_dt = 1.0 / (8.0 * seg.fs)
        spec = st.specimen
        self.means = CornerRestitution(spec.r_right, spec.r_left)
        self.n_sims = 0

    def excitation(self, theta0: float):
        if self.ag is None:
            return FreeRelease(theta0=theta0)
        return Record(self.t - self.t[0], self.ag, name="trace ag", source=self.trace.source)

    def run(self, theta0: float, values: dict, t_end: float):
        """The simulated response to model time `t_end` with `values` per impact."""
        self.n_sims += 1
        src = _ByImpact(values, self.means)
        resp = simulate(
            self.st, self.excitation(theta0), self.impact, max(t_end, 1e-3),
            restitution=src, output_dt=self.output_dt, **self.options,
        )  # fmt: skip
        if resp.status == "failed":
            raise SolverError(f"the simulation of the trace failed: {resp.message}")
        return resp

    def model(self, resp, col: str, theta0: float, tau: float, idx: slice) -> np.ndarray:
        """Model channel `col` at the trace samples `idx` (trace t ↔ model t − τ)."""
        df = resp.series
        tm = self.t[idx] - tau
        out = np.interp(tm, df["t"].to_numpy(), df[col].to_numpy())
        held = theta0 if (col == "theta" and self.ag is None) else 0.0
        return np.where(tm < 0.0, held, out)

    def residuals(self, resp, align: dict, idx: slice, weighted: bool = True) -> dict:
        """Channel → trace minus model over `idx` (divided by σ if `weighted`)."""
        out = {}
        for name, col in self.channels:
            e = (
                self.model(resp, col, align["theta0"], align["t_offset"], idx)
                - self.data[name][idx]
            )
            if col == "theta":
                e = e + align["theta_bias"]
            out[name] = e / self.sigma[name] if weighted else e
        return out

    def misfit(self, resp, align: dict, idx: slice) -> np.ndarray:
        return np.concatenate(list(self.residuals(resp, align, idx).values()))


def _samples(t: np.ndarray, t0: float, t1: float) -> slice:
    a, b = np.searchsorted(t, [t0, t1])
    return slice(int(a), int(b))


def _align(fit: _Fitter, seg: Segments, warnings: list) -> dict:
    """(θ0, τ) from the half-cycle before the first impact (no restitution in it), first
    on θ, then on every channel weighted by its misfit. The θ bias b is the trace's θ
    at rest (`Segments.bias`): on one half-cycle b and θ0 trade off."""
    b = seg.bias
    if fit.ag is not None:
        return {"t_offset": 0.0, "theta_bias": b, "theta0": 0.0}
    if not seg.full_contact:
        warnings.append(
            "the trace never rests on its base, so the θ sensor's bias is unknown and taken as 0"
        )
    first = seg.half_cycles[0]
    idx = _samples(fit.t, fit.t[0], first.t_stop)

    def resid(x):
        align = {"theta0": x[0], "t_offset": x[1], "theta_bias": b}
        resp = fit.run(x[0], {}, fit.t[idx][-1] - x[1] + 0.01)
        return fit.misfit(resp, align, idx)

    x = np.array([first.peak * first.sign, _release_time(fit, seg, first)])
    span = 0.2 * abs(x[0])
    for _ in range(2):  # θ alone, then every channel
        sol = optimize.least_squares(
            resid, x,
            bounds=([x[0] - span, x[1] - 0.1], [x[0] + span, x[1] + 0.1]),
            x_scale=[0.01, 0.01], diff_step=[1e-4, 1e-3],
        )  # fmt: skip
        x = sol.x
        align = {"theta0": float(x[0]), "t_offset": float(x[1]), "theta_bias": b}
        resp = fit.run(x[0], {}, fit.t[idx][-1] - x[1] + 0.01)
        for name, e in fit.residuals(resp, align, idx, weighted=False).items():
            fit.sigma[name] = max(float(np.sqrt(np.mean(e * e))), 1e-12)
    if not sol.success:
        warnings.append(f"the alignment on the first half-cycle did not converge ({sol.message})")
    return align


def _release_time(fit: _Fitter, seg: Segments, first) -> float:
    """A first guess of the release time: where θ leaves its held value by a band."""
    x = seg.smooth[first.start : first.stop] * first.sign
    k = int(np.argmax(x < x.max() - seg.band))
    # rocking from rest: θ0 − θ ≈ (α − θ0)(cosh p t − 1) ≈ ½ (α − θ0) p² t²
    st = fit.st
    drop = max(seg.band, 1e-9)
    t_drop = math.sqrt(2.0 * drop / max((st.alpha_cg - first.peak) * st.p**2, 1e-9))
    return float(max(fit.t[first.start + k] - t_drop, fit.t[0]))


def _fit_impact(fit, align, values, k_model, window):
    """(r, rms, std): the r of simulated impact `k_model` that best matches the trace in
    `window` (a scan of `_R_GRID`, then a bounded Brent search around its best), the
    RMS misfit in units of θ's noise, and r's standard error from the misfit's
    curvature."""
    idx = window
    t_end = fit.t[idx][-1] - align["t_offset"] + 0.02

    def sse(r):
        resp = fit.run(align["theta0"], values | {k_model: float(r)}, t_end)
        e = fit.misfit(resp, align, idx)
        return float(e @ e)

    grid = _R_GRID
    costs = np.array([sse(r) for r in grid])
    j = int(np.argmin(costs))
    lo, hi = grid[max(j - 1, 0)], grid[min(j + 1, grid.size - 1)]
    res = optimize.minimize_scalar(
        sse, bounds=(lo, hi), method="bounded", options={"xatol": _R_TOL}
    )
    best = min(res.fun, costs[j])
    r = float(res.x) if res.fun <= costs[j] else float(grid[j])
    n = max(idx.stop - idx.start, 1) * len(fit.channels)
    # residuals in units of their σ: var(r) = 2 / (d²SSE/dr²) at the optimum
    h = 0.01
    curv = (sse(min(r + h, 1.0)) - 2.0 * best + sse(max(r - h, 0.0))) / h**2
    std = math.sqrt(2.0 / curv) if curv > 0.0 else math.inf
    return r, math.sqrt(best / n), std


def _model_impacts(resp, tau: float) -> np.ndarray:
    """Trace times of the simulated impacts (events of kind "impact")."""
    return np.array([e.time + tau for e in resp.events if e.kind == "impact"])


def restitution(
    trace: Trace,
    structure=None,
    impact: str = IMPACT_DEFAULT,
    *,
    theta_min: float = THETA_MIN,
    progress: bool | None = None,
    **options,
) -> RestitutionEstimate:
    """Estimate each impact's coefficient of restitution from a trace, two ways.

    Parameters
    ----------
    trace : Trace
        A free-vibration test (θ held at a release angle, then released) or a test
        with table motion (an ``ag`` channel: the excitation), with a θ channel.
    structure : Structure, specimen or str, optional
        The column tested; default the trace's ``# specimen:`` line.
    impact : str, optional
        The impact model the model-based estimates are for: "DD" (the Dirac-delta
        model of paper 001, C_p of the specimen's Table 2 family, default), "CIM",
        "DD1" … "DD4" (their restitution is replaced by the fitted one).
    theta_min : float, optional
        Impacts between half-cycles both at least this large (rad) are estimated
        (paper 001, Section 4.3: 0.01).
    progress : bool, optional
        Show a progress bar over the impacts (default: when there are more than 3).
    **options
        Options of `multimass.simulate` for the model runs (``C_p``, ``rtol``, …);
        the compiled backend is used by default.

    Returns
    -------
    RestitutionEstimate

    Raises
    ------
    InputError
        No θ channel, no specimen, no rocking, no impact between half-cycles above
        `theta_min`, a sampling rate too low to segment θ, an ``ag`` column in an
        implausible unit (the message says what was found and the fix). Acceleration
        columns are not needed: the fit is on θ.
    """
    st = _structure(require_trace(trace), structure)
    if trace.ag is not None:  # the table motion drives the model: its unit must be plausible
        check_ag(trace, st, segment_trace(trace, theta_min=theta_min))
    if not isinstance(impact, str) or impact.strip().upper() not in (
        "DD", "CIM", "DD1", "DD2", "DD3", "DD4",
    ):  # fmt: skip
        raise InputError(
            f"`impact` = {impact!r}: give the model the coefficients are for: DD, CIM, "
            "DD1, DD2, DD3 or DD4 (paper 001, Table 2)"
        )
    impact = impact.strip().upper()
    for key in ("restitution", "output_dt", "k", "eps_p"):
        if key in options:
            raise InputError(f"`{key}` is set by restitution(); remove it")
    seg = segment_trace(trace, theta_min=theta_min)
    big = [h for h in seg.half_cycles if not h.small]
    if not big:
        top = max((h.peak for h in seg.half_cycles), default=0.0)
        raise InputError(
            f"{trace.source}: no rocking half-cycle reaches theta_min = {theta_min:g} rad "
            f"(largest {top:.3g} rad, θ noise {seg.noise:.2g} rad); restitution needs a "
            "test that rocks: give a trace with rocking, or lower theta_min"
        )
    if not seg.impacts:
        raise InputError(
            f"{trace.source}: no impact found (the trace rocks on one side only, "
            f"{len(seg.half_cycles)} half-cycle(s)); give a test with impacts"
        )
    if seg.half_cycles[0].begins not in ("release", "uplift") and trace.ag is None:
        raise InputError(
            f"{trace.source}: the trace starts while rocking and has no `ag` channel; "
            "a free-vibration trace must start held at its release angle (record from "
            "before the release), a forced test needs its table motion as `ag`"
        )
    warnings: list[str] = []
    fit = _Fitter(st, trace, seg, impact, options)
    align = _align(fit, seg, warnings)
    tau = align["t_offset"]
    half = seg.half_cycles
    estimated = [
        not (half[m.before].small or half[m.after].small) for m in seg.impacts
    ]  # fmt: skip
    last = max((i for i, e in enumerate(estimated) if e), default=-1)
    r_energy = energy_restitution(
        st, [half[m.before].peak for m in seg.impacts], [half[m.after].peak for m in seg.impacts]
    )
    values: dict[int, float] = {}
    rows = []
    shown = progress if progress is not None else last >= 3
    with Progress(last + 1, f"restitution {st.name}", show=shown, unit="impacts") as bar:
        resp = fit.run(align["theta0"], values, seg.impacts[0].t - tau + 0.05)
        for i, m in enumerate(seg.impacts):
            after = half[m.after]
            row = {
                "t": m.t,
                "corner": m.corner,
                "r": float(r_energy[i]),
                "r_energy": float(r_energy[i]),
                "theta_before": half[m.before].peak,
                "theta_after": after.peak,
                "estimated": estimated[i],
                "model_impact": -1,
                "rms": math.nan,
                "r_std": math.nan,
            }
            if i <= last:
                k_model = _match(resp, tau, m.t, half[m.before], values)
                if k_model is None:
                    warnings.append(
                        f"impact at t = {m.t:.4g} s: the simulation has no impact near it; "
                        "its r is the energy estimate"
                    )
                    row["estimated"] = False
                else:
                    t1 = after.t_stop
                    window = _samples(fit.t, m.t, t1)
                    r, rms, std = _fit_impact(fit, align, values, k_model, window)
                    values[k_model] = r
                    row.update(r=r, model_impact=k_model, rms=rms, r_std=std)
                    resp = fit.run(align["theta0"], values, t1 - tau + 0.05)
                bar.update(i + 1)
            rows.append(row)
    final = fit.run(align["theta0"], values, float(fit.t[-1]) - tau)
    table = pd.DataFrame(rows)
    means = _means(table, "r", st)
    energy = _means(table, "r_energy", st)
    return RestitutionEstimate(
        table, *means, energy_means=dict(zip(("r_mean_right", "r_mean_left", "sigma_r"), energy)),
        alignment=align, structure=st, impact=impact, theta_min=seg.theta_min, segments=seg,
        response=final, warnings=tuple(warnings),
    )  # fmt: skip


def _match(resp, tau: float, t_trace: float, before, values: dict):
    """The index of the simulated impact nearest trace time `t_trace`, or None if none is
    within half the duration of the half-cycle before it."""
    times = _model_impacts(resp, tau)
    if times.size == 0:
        return None
    k = int(np.argmin(np.abs(times - t_trace)))
    tol = 0.5 * max(before.t_stop - before.t_start, 0.02)
    return k if abs(times[k] - t_trace) <= tol else None


def _means(table: pd.DataFrame, column: str, st) -> tuple[float, float, float]:
    """(right mean, left mean, pooled σ) of `column` over the estimated impacts.

    The means weigh each impact by 1 / r_std² where the model-based standard errors
    are known (small half-cycles are noisier), else equally; σ is the pooled sample
    standard deviation about the corner means.
    """
    est = table[table["estimated"]]
    spec = st.specimen
    out, dev, n_groups = [], [], 0
    for corner, default in (("right", spec.r_right), ("left", spec.r_left)):
        rows = est[est["corner"] == corner]
        x = rows[column].to_numpy(dtype=float)
        if x.size:
            std = rows["r_std"].to_numpy(dtype=float) if column == "r" else np.ones(x.size)
            w = np.where(np.isfinite(std) & (std > 0.0), 1.0 / np.maximum(std, 1e-6) ** 2, 0.0)
            mean = float(np.average(x, weights=w)) if w.sum() > 0.0 else float(x.mean())
            out.append(mean)
            dev.append(x - mean)
            n_groups += 1
        else:
            out.append(float(default))
    d = np.concatenate(dev) if dev else np.zeros(0)
    dof = d.size - n_groups
    sigma = float(math.sqrt(d @ d / dof)) if dof > 0 else float(spec.sigma_r)
    return out[0], out[1], sigma
