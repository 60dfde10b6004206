"""A calibration's result assembled (`multimass.identify.calibrate`): the parameters with
their uncertainties and flags, the nuisance, the metrics and features before and after."""

from __future__ import annotations

import math
import time

import numpy as np
import pandas as pd

from . import _parameter_status as ps
from ._calibration_fit import Problem
from ._calibration_input import reasons as input_reasons
from ._calibration_params import PARAMETERS
from ._calibration_setup import unseen_damping
from ._calibration_stats import (
    MODEL_REL_FLOOR,
    SLICE,
    covariance,
    flags,
    rough_reason,
    rough_std,
    slice_probe,
    status_of,
)  # fmt: skip
from ._calibration_views import channel_metrics, feature_errors, view
from ._misfit import REF_MIN, misfit_test, theta_misfit
from ._restitution_fit import EDGE

__all__ = ["assemble", "failed", "views", "provenance", "misfit"]


def views(sim, p: Problem, x, cases, st, full: bool) -> dict:
    """Per trace label: view, nuisance, biases, metrics and features of the runs at `x` of
    `p`; `full`: the calibrated model (no deviations) to the trace's end, else `p`'s
    window with its deviations."""
    phys, per = p.decode(x)
    raw = p.raw(x)
    out = {}
    for c in cases:
        nuis = dict(per[c.label])
        biases = {ch: raw[(c.label, ch)][1] for ch in c.channels if ch != "theta"}
        short = next(s for s in p.cases if s.label == c.label)
        if full:
            nuis["deviations"] = ()
            t_end = float(c.t[-1] - min(c.t[0], nuis["tau"]) + 0.3)
        else:
            t_end = p.t_end(short)
        rec = sim.run(phys, short, nuis["theta0"], nuis["deviations"], t_end)
        resp = view(c, rec, nuis, biases)
        out[c.label] = {
            "view": resp,
            "nuisance": nuis,
            "biases": biases,
            "metrics": channel_metrics(short if not full else c, resp, st,
                                       ("window", "trace") if full else ("window",)),
            "features": feature_errors(c if full else short, rec, nuis["tau"]),
        }  # fmt: skip
    return out


def roughness(p, x, f0, J, cov, pset) -> dict:
    """`slice_probe` along each log-fitted parameter (C_p, ζ), h = max(3 σ, `SLICE`):
    on S2 (seed 1, 9 half-cycles) C_p's local std was 0.08 kg m/rad/s while the cost
    rose by 1.6e5 at +1 % and by only 282 at −1 % (4.1e6 predicted), and the truth was
    1.7 % away."""
    out = {}
    for name in pset.fit:
        if not PARAMETERS[name].log or name not in p.index:
            continue
        j = p.index[name]
        h = max(3.0 * math.sqrt(max(cov[j, j], 0.0)), SLICE)
        out[name] = slice_probe(p.residuals, x, f0, J, j, h)
    return out


def misfit(p: Problem, x) -> dict:
    """(case label, channel) → `misfit_test` of stage 2's fit over its window, as the
    residual mean square over the most a fit that reproduces the trace leaves (above 1:
    it does not) — `restitution`'s test (`_misfit`), over the whole window fitted.

    Each accelerometer is tested against its own residuals before the first impact less
    the anti-alias filter's reach (F; not tested with fewer than `REF_MIN` samples
    there), θ against the trace's noise (`theta_misfit`, χ²) — or, where its residuals
    before the first impact pass that test yet exceed the noise, against them (F):
    `Segments.noise` can be low, 0.00189 rad on the 2 % noise (0.00220 rad) of a
    synthetic S1 trace (0.11 rad, DD2, 2.6 s, seed 11), and a fit at the truth (every
    impact's r within 0.0014, C_p within 0.3 %) then failed at 1.02 × the limit.
    """
    out = {}
    for (label, ch), (e, _) in p.raw(x).items():
        c = next(s for s in p.cases if s.label == label)
        impacts = c.segments.impacts
        t_ref = impacts[0].t - EDGE / c.segments.fs if impacts else -math.inf
        n_ref = int(np.searchsorted(c.t[c.idx], t_ref))
        ref = e[:n_ref] if ch == "theta" else e[:n_ref] - np.mean(e[:n_ref])
        ms_ref = max(float(np.mean(ref * ref)), 1e-300) if n_ref else math.nan
        if ch == "theta":
            ratio, limit = theta_misfit(e, c.segments.noise)
            if n_ref >= REF_MIN:
                r0, l0 = theta_misfit(ref, c.segments.noise)
                if r0 > l0:  # the release itself is not reproduced
                    ratio, limit = max((ratio, limit), (r0, l0), key=lambda q: q[0] / q[1])
                elif r0 > 1.0:  # the noise is larger than its estimate
                    ratio, limit = misfit_test(e, ms_ref, n_ref)
        elif n_ref >= REF_MIN:
            ratio, limit = misfit_test(e, ms_ref, n_ref)
        else:
            continue
        out[(label, ch)] = ratio / limit
    return out


def _not_reproduced(flagged: dict, tested: dict) -> None:
    """Every fitted parameter not constrained where the fit does not reproduce a trace
    (`misfit` above 1 in some channel): the least squares stopped away from the traces'
    parameters (or the model cannot follow them), and the covariance at that point does
    not bound their error."""
    worst = max(tested.items(), key=lambda kv: kv[1], default=(None, 0.0))
    if not worst[1] > 1.0:
        return
    (label, ch) = worst[0]
    why = (
        f"the fit does not reproduce the trace over the window fitted ({label}:{ch}'s "
        f"residual mean square {worst[1]:.3g} × the most its noise leaves)"
    )
    for f in flagged.values():
        f["constrained"] = False
        f["reason"] = "; ".join(x for x in (f["reason"], why) if x)


def _parameters(
    pset, p2, x, cov, rough, tested=None, unseen=None, checked=None
) -> tuple[dict, dict]:
    n = len(pset.fit)
    std = np.sqrt(np.clip(np.diag(cov)[:n], 0.0, np.inf))
    for i, name in enumerate(pset.fit):  # a rough cost: at least the probe's distance
        r = rough.get(name)
        if r and not r["trusted"]:
            std[i] = rough_std(std[i], r)
    for i, name in enumerate(pset.fit):  # C_p, ζ: the model's error, beyond the noise's
        if PARAMETERS[name].log and math.isfinite(std[i]):
            std[i] = math.hypot(std[i], MODEL_REL_FLOOR)
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov[:n, :n] / np.outer(np.sqrt(np.diag(cov)[:n]), np.sqrt(np.diag(cov)[:n]))
    flagged = flags(pset.fit, x[:n], std, corr, pset.bounds)
    for name, r in rough.items():
        if not r["trusted"]:
            f = flagged[name]
            why = rough_reason(r)
            f["constrained"] = False
            f["reason"] = "; ".join(x for x in (f["reason"], why) if x)
    x_fit = {name: float(x[i]) for i, name in enumerate(pset.fit)}
    for name, why in input_reasons(pset.fit, x_fit, checked).items():  # `_calibration_input`
        f = flagged[name]
        f["constrained"] = False
        f["reason"] = "; ".join(r for r in (f["reason"], why) if r)
    for name, why in (unseen or {}).items():  # a damping ratio whose mode is not shown
        if name in flagged:
            flagged[name]["constrained"] = False
            flagged[name]["reason"] = "; ".join(x for x in (flagged[name]["reason"], why) if x)
    _not_reproduced(flagged, tested or {})
    out = {}
    for i, name in enumerate(pset.fit):
        p = PARAMETERS[name]
        value = p.to_value(float(x[i]))
        s = float(std[i]) * (value if p.log else 1.0)  # a log's std → the value's
        out[name] = {
            "value": value,
            "std": s if math.isfinite(s) else math.inf,
            "start": pset.start[name],
            "bounds": list(pset.bounds[name]),
            **flagged[name],
        }
    return out, flagged


def _per_impact_means(p, J: np.ndarray, blocks: dict) -> np.ndarray:
    """The Jacobian for the covariance, with each impact's r_k = r̄ + δ_k as the unknown
    in place of δ_k.

    The data depend on the r_k alone (the window ends at the last impact with a
    deviation), the corner means only through the prior rows (r_k − r̄)/σ_r: their
    data columns are set to zero and their prior entries to −1/σ_r. Computed by
    differences instead, a mean's column differs from the sum of its impacts' by the
    nonlinearity of a joint step (4 % on S1 at a step of 2e-4), enough to make it
    look known to 3e-4 where the prior says σ_r / √n.
    """
    if not p.per_impact:
        return J
    J = J.copy()
    rows, start = {}, 0
    for key, r in blocks.items():
        rows[key] = slice(start, start + r.size)
        start += r.size
    data = [sl for key, sl in rows.items() if key[1] != "prior"]
    for corner, name in (("right", "r_er"), ("left", "r_el")):
        if name not in p.index:
            continue
        j = p.index[name]
        for sl in data:
            J[sl, j] = 0.0
        for c in p.used_cases:
            block = rows.get((c.label, "prior"))
            if block is None:
                continue
            for k in range(c.n_impacts):
                un = p.unknowns[p.index[f"{c.label}:r[{c.first_impact + k}]"]]
                if un.corner == corner:
                    J[block.start + k, j] = -1.0 / p.sigma_r
    return J


def _nuisance(cs, p2, x, fit_views) -> dict:
    phys, per = p2.decode(x)
    means = {"right": phys["r_er"], "left": phys["r_el"]}
    out = {}
    for full in cs:
        c = next(s for s in p2.cases if s.label == full.label)  # the window fitted
        nuis = per[c.label]
        devs = nuis["deviations"]
        impacts = []
        for k in range(c.n_impacts if devs else 0):
            j = c.first_impact + k
            m = c.segments.impacts[j]
            if m.t > c.window[1]:  # past the window's end (`REACH` before it): not fitted
                continue
            d = devs[j] if j < len(devs) else 0.0
            impacts.append({"index": j, "t": m.t, "corner": m.corner,
                            "r": min(max(means[m.corner] + d, 0.05), 1.0), "deviation": d})  # fmt: skip
        out[c.label] = {
            "source": c.trace.source,
            "kind": "free" if c.free else "table",
            "t_offset": nuis["tau"],
            "theta0": nuis["theta0"] if c.free else None,
            "theta_bias": nuis["bias"],
            "sensor_bias": fit_views[c.label]["biases"],
            "window": list(c.window),
            "large_half_cycles": [full.window[0], full.window[1], len(full.large)],
            "channels": list(c.channels),
            "impacts": impacts,
        }
    return out


def assemble(st, impact, pset, cs, before, stages, sim, wall, checked=None) -> dict:
    """The fields of a `Calibration` from the stages' results (`checked`:
    `_calibration_input.input_check`'s, None without table motion)."""
    s1, s2 = stages
    p2, x = s2.problem, s2.x
    blocks = p2.blocks(x)
    f0 = np.concatenate(list(blocks.values()))
    J0 = p2.jacobian(x, f0)
    J = _per_impact_means(p2, J0, blocks)
    scales = np.array([un.scale for un in p2.unknowns])
    cov, info = covariance(J, blocks, scales)
    rough = roughness(p2, x, f0, J0, cov, pset)
    tested = misfit(p2, x)
    params, flagged = _parameters(pset, p2, x, cov, rough, tested, unseen_damping(cs, st), checked)
    rho = {key: i["rho1"] for key, i in info.items() if key[1] != "prior"}
    status, message = status_of(s2.ok, flagged, rho)
    fit_views = views(sim, p2, x, cs, st, full=False)
    after = views(sim, p2, x, cs, st, full=True)
    n = len(pset.fit)
    names = list(pset.fit)
    residuals = {
        f"{label}:{ch}": {
            "scale": p2.scales[(label, ch)],
            **info[(label, ch)],
            "misfit": tested.get((label, ch)),
        }
        for (label, ch) in p2.scales
    }
    phys, _ = p2.decode(x)
    return dict(
        parameters=params,
        fixed={k: val for k, val in phys.items() if k not in pset.fit},
        status=status,
        message=message,
        impact=impact,
        structure=st,
        nuisance=_nuisance(cs, p2, x, fit_views),
        metrics={w: {k: d["metrics"] for k, d in vs.items()}
                 for w, vs in (("before", before), ("after", after), ("fit", fit_views))},
        features={w: {k: d["features"] for k, d in vs.items()}
                  for w, vs in (("before", before), ("after", after), ("fit", fit_views))},
        residuals=residuals,
        covariance=pd.DataFrame(cov[:n, :n], index=names, columns=names),
        stages={"1": s1.info, "2": s2.info, **({"input": checked} if checked else {})},
        views={c.label: {w: vs[c.label]["view"] for w, vs in
                         (("before", before), ("after", after), ("fit", fit_views))} for c in cs},
        traces=tuple(cs),
        n_simulations=sim.n_runs,
        wall_time_s=time.perf_counter() - wall,
        warnings=tuple(_warnings(cs, status) + _misfit_warnings(tested)),
    )  # fmt: skip


def _warnings(cs, status) -> list[str]:
    out = []
    for c in cs:
        if c.segments.full_contact == () and c.free:
            out.append(
                f"{c.label}: the trace never rests on its base; θ's bias is fitted from "
                "the rocking alone"
            )
        if c.n_impacts < 2:
            out.append(f"{c.label}: fewer than 2 impacts between large half-cycles")
    return out


def _misfit_warnings(tested: dict) -> list[str]:
    off = sorted((k for k, r in tested.items() if r > 1.0), key=lambda k: -tested[k])
    if not off:
        return []
    return [
        "the fit does not reproduce the trace over the window fitted (residual mean square "
        + ", ".join(f"{tested[k]:.3g} × ({k[0]}:{k[1]})" for k in off)
        + " the most the noise leaves): every fitted parameter is ill-posed, its value the "
        "best fit, not an estimate"
    ]


def failed(st, impact, pset, cs, before, message, sim, wall) -> dict:
    """The fields of a failed `Calibration`: the start values, no covariance."""
    params = {
        name: {"value": pset.start[name], "std": math.inf, "start": pset.start[name],
               "bounds": list(pset.bounds[name]), "bound_hit": None, "constrained": False,
               "reason": "the calibration failed"}
        for name in pset.fit
    }  # fmt: skip
    return dict(
        parameters=params,
        fixed={k: val for k, val in pset.start.items() if k not in pset.fit},
        status="failed",
        message=message,
        impact=impact,
        structure=st,
        nuisance={},
        metrics={"before": {k: d["metrics"] for k, d in before.items()}},
        features={"before": {k: d["features"] for k, d in before.items()}},
        residuals={},
        covariance=pd.DataFrame(),
        stages={},
        views={k: {"before": d["view"]} for k, d in before.items()},
        traces=tuple(cs),
        n_simulations=sim.n_runs,
        wall_time_s=time.perf_counter() - wall,
    )


def provenance(fields: dict, impact: str, given: dict, dropped: dict, st, bounds=None) -> dict:
    """Where each parameter's value came from (`_parameter_status`): the fitted ones
    estimated (their std, 95 % interval) or ill-posed (the reason, and instead of an
    interval the range the fit was allowed to explore, its `bounds`: name → (low, high);
    the value then the best fit, not an estimate), the `given` ones, those
    the traces could not show (`dropped`: fixed by the specimen file, with why), those
    left out of an explicit fit list, C_p of CIM (not used), the traces' nuisance
    parameters (estimated, per trace in `Calibration.nuisance`) and the structure."""
    out = {}
    fitted = fields["parameters"]
    for name, par in PARAMETERS.items():
        if name == "cp" and impact == "CIM":
            out[name] = ps.not_used("the classical impact model has no C_p (paper 001 Table 2)",
                                    par.what)  # fmt: skip
        elif name in given:
            out[name] = ps.given(given[name], par.what)
        elif name in fitted:
            f = fitted[name]
            std = f["std"] / f["value"] if par.log and f["value"] > 0 else f["std"]
            entry = ps.estimated(f["value"], std, log=par.log, what=par.what)
            if not f["constrained"]:
                entry["status"] = ps.ILL_POSED
                entry["reason"] = f["reason"]
                if bounds and name in bounds:
                    entry = ps.explored(entry, *bounds[name])
            out[name] = entry
        else:
            note = dropped.get(name, "not in the fit list")
            out[name] = ps.fixed(fields["fixed"].get(name), par.what, note)
    out["nuisance"] = {
        "status": ps.ESTIMATED, "value": None, "std": None, "interval": None,
        "what": "each trace's clock offset, θ bias, release angle and accelerometer biases",
        "note": "per trace in `nuisance`",
    }  # fmt: skip
    out["structure"] = ps.fixed(
        ps.structure_fixed(st.specimen), "the column's geometry, masses, stiffnesses and sensors"
    )
    return out
