"""One case of the identification coverage benchmark: a synthetic trace, the
estimators run on it with nothing of its hidden parameters given (only the specimen's
name and the impact model family), and every estimate beside its truth.

An estimate row holds ``estimator`` ("restitution" or "calibrate"), ``quantity`` (a
key of `multimass.bench.coverage_stats.QUANTITIES`), ``item`` (the impact's trace time
for a per-impact ``r``), ``value``, ``std`` (one standard deviation as reported; NaN
when none is), ``lo``/``hi`` (the reported 95 % interval; NaN when the estimator
reports none, then value ± 1.96 std is used), ``truth`` and ``truth_nominal``.

The truths (from the truth file of `multimass.identify.synthetic_trace`):

* per-impact ``r``: the coefficient the run drew for the simulated impact nearest in
  time on the same corner (1 where the Dirac-delta force never switched on: no energy
  was lost), within `MATCH_S`;
* corner means ``r_mean_right``/``r_mean_left``: the mean of the drawn coefficients of
  the impacts the estimate averages (restitution: the estimated impacts; calibrate:
  the impacts of its fitted window); ``truth_nominal`` the corner mean they were
  drawn about;
* ``sigma_r``: the pooled standard deviation of those drawn coefficients about their
  corner means; ``truth_nominal`` the σ_r drawn;
* ``cp``, ``zeta1``, ``zeta2``: the values simulated; ``theta0``, ``t_offset`` (trace
  time of the release), ``theta_bias``: the release angle, clock offset and θ
  sensor's bias of the trace.
"""

from __future__ import annotations

import inspect
import math
import time

import numpy as np

from ..errors import InputError, SolverError
from ..identify.calibration import FITTABLE, calibrate
from ..identify.impacts import restitution
from .coverage_draws import Draw, make_trace

__all__ = ["MATCH_S", "run_case", "restitution_rows", "calibration_rows", "truth_impacts"]

MATCH_S = 0.1  # s: an estimated impact is matched to a simulated one within this time
_NAN = math.nan
#: calibrate's parameter names → the benchmark's quantities
_CAL_NAMES = {"r_er": "r_mean_right", "r_el": "r_mean_left", "cp": "cp", "zeta1": "zeta1",
              "zeta2": "zeta2"}  # fmt: skip


def truth_impacts(truth: dict) -> list[dict]:
    """The truth's impacts: ``t`` (trace clock), ``corner``, ``r`` (1 where the
    Dirac-delta force never switched on)."""
    return [
        {"t": e["t"], "corner": e["corner"], "r": 1.0 if e["r"] is None else float(e["r"])}
        for e in truth["impacts"]
    ]


def _match(impacts: list[dict], t: float, corner: str) -> dict | None:
    same = [e for e in impacts if e["corner"] == corner]
    if not same:
        return None
    best = min(same, key=lambda e: abs(e["t"] - t))
    return best if abs(best["t"] - t) <= MATCH_S else None


def _pooled(matched: list[dict]) -> tuple[float, float, float]:
    """(right mean, left mean, pooled σ about them) of the matched truths' r; NaN where
    undefined."""
    by = {c: np.array([e["r"] for e in matched if e["corner"] == c]) for c in ("right", "left")}
    means = {c: float(r.mean()) if r.size else _NAN for c, r in by.items()}
    dof = sum(r.size - 1 for r in by.values() if r.size)
    ss = sum(float(np.sum((r - means[c]) ** 2)) for c, r in by.items() if r.size)
    return means["right"], means["left"], math.sqrt(ss / dof) if dof > 0 else _NAN


def _row(quantity, value, truth, std=_NAN, lo=_NAN, hi=_NAN, item=_NAN, nominal=_NAN, **kw):
    f = lambda x: _NAN if x is None else float(x)  # noqa: E731
    return {"quantity": quantity, "item": f(item), "value": f(value), "std": f(std),
            "lo": f(lo), "hi": f(hi), "truth": f(truth), "truth_nominal": f(nominal), **kw}  # fmt: skip


def _getter(obj, *names):
    """The first of `names` that `obj` has (attribute or mapping key), else None."""
    for name in names:
        if isinstance(obj, dict) and name in obj:
            return obj[name]
        if hasattr(obj, name):
            return getattr(obj, name)
    return None


def restitution_rows(est, truth: dict) -> list[dict]:
    """Every estimate of a `RestitutionEstimate` beside its truth."""
    impacts = truth_impacts(truth)
    table = est.impacts
    rows, matched = [], []
    lo_col = next((c for c in ("r_lo", "r_low", "r_lower") if c in table.columns), None)
    hi_col = next((c for c in ("r_hi", "r_high", "r_upper") if c in table.columns), None)
    for _, imp in table[table["estimated"]].iterrows():
        tr = _match(impacts, float(imp["t"]), imp["corner"])
        if tr is not None:
            matched.append(tr)
        rows.append(
            _row(
                "r",
                imp["r"],
                tr["r"] if tr else None,
                std=imp["r_std"],
                lo=imp[lo_col] if lo_col else None,
                hi=imp[hi_col] if hi_col else None,
                item=imp["t"],
                corner=imp["corner"],
                theta_small=min(imp["theta_before"], imp["theta_after"]),
            )  # fmt: skip
        )
    mean_r, mean_l, sigma = _pooled(matched)
    means = truth["restitution"]["means"]
    uncert = _uncertainties(est)
    for q, value, tr, nom in (
        ("r_mean_right", est.r_mean_right, mean_r, means["right"]),
        ("r_mean_left", est.r_mean_left, mean_l, means["left"]),
        ("sigma_r", est.sigma_r, sigma, truth["restitution"]["spread"]),
    ):
        rows.append(_row(q, value, tr, nominal=nom, **uncert.get(q, {})))
    for q, value in _extra_parameters(est).items():
        rows.append(_row(q, value["value"], _truth_of(q, truth), **_interval(value)))
    align = dict(est.alignment)
    for q, p in _reported(est).items():  # the nuisance parameters' std and interval
        if q in ("theta0", "t_offset", "theta_bias"):
            uncert[q] = _interval(p)
            align[q] = p["value"]
    rows += _nuisance_rows(align, truth, uncert)
    return rows


def _uncertainties(est) -> dict:
    """quantity → {std, lo, hi} for the means and σ_r, where the estimate reports them."""
    out = {}
    for q in ("r_mean_right", "r_mean_left", "sigma_r", "theta0", "t_offset", "theta_bias"):
        std = _getter(est, f"{q}_std")
        if std is None:
            std = _getter(getattr(est, "alignment", {}) or {}, f"{q}_std")
        lo, hi = _getter(est, f"{q}_lo"), _getter(est, f"{q}_hi")
        if std is not None or lo is not None:
            out[q] = {"std": std, "lo": lo, "hi": hi}
    iv = getattr(est, "sigma_r_interval", None)  # [lo, hi] of σ_r, or None
    if isinstance(iv, (list, tuple)) and len(iv) == 2:
        out["sigma_r"] = {"std": None, "lo": iv[0], "hi": iv[1]}
    per_corner = getattr(est, "r_mean_std", None)  # corner → {std, interval, n} or None
    if isinstance(per_corner, dict):
        for corner in ("right", "left"):
            entry = per_corner.get(corner)
            if isinstance(entry, dict) and entry.get("std") is not None:
                out[f"r_mean_{corner}"] = _interval(entry)
    return out


def _extra_parameters(est) -> dict:
    """Model parameters the estimate reports as estimated or ill-posed (C_p, ζ1, ζ2):
    quantity → {value, std, interval, status}; none for an estimate that assumes them
    (or was given them)."""
    return {
        q: p for q, p in _reported(est).items() if q in ("cp", "zeta1", "zeta2")
    }  # fmt: skip


def _reported(est) -> dict:
    """quantity → the parameter entry of ``est.parameters`` (value, std, interval,
    status) of every parameter it estimated (status "estimated" or "ill-posed")."""
    params = getattr(est, "parameters", None)
    out = {}
    if isinstance(params, dict):
        for name, p in params.items():
            q = _CAL_NAMES.get(name, name)
            if isinstance(p, dict) and p.get("status", "estimated") in ("estimated", "ill-posed"):
                if isinstance(p.get("value"), (int, float)):
                    out[q] = p
    return out


def _interval(p: dict) -> dict:
    """std, lo, hi (and the status) of a parameter entry."""
    lo = hi = None
    if isinstance(p.get("interval"), (list, tuple)) and len(p["interval"]) == 2:
        lo, hi = p["interval"]
    out = {"std": p.get("std"), "lo": lo, "hi": hi}
    if "status" in p:
        out["status"] = p["status"]
    return out


def _truth_of(q: str, truth: dict) -> float:
    if q == "cp":
        return truth["impact"].get("C_p", _NAN)
    if q in ("zeta1", "zeta2"):
        return truth["damping"][f"zeta_{q[-1]}"]
    raise KeyError(q)


def _nuisance_rows(align: dict, truth: dict, uncert: dict) -> list[dict]:
    """θ0 and the clock offset (free vibration only: with table motion the recorded
    ``ag`` drives the model on the trace's own clock) and the θ bias beside their truths."""
    rows = []
    theta0 = _theta0(truth)
    for q, tr in (("theta0", theta0), ("t_offset", truth["t_offset"]),
                  ("theta_bias", truth["bias"]["values"]["theta"])):  # fmt: skip
        value = align.get(q)
        if value is None or (q in ("theta0", "t_offset") and theta0 is None):
            continue  # table motion: no release; the model runs on the trace's clock
        unc = dict(uncert.get(q, {}))
        if f"{q}_std" in align:
            unc["std"] = align[f"{q}_std"]
        rows.append(_row(q, value, tr, **unc))
    return rows


def _theta0(truth: dict) -> float | None:
    """The release angle of a free-vibration truth; None for table motion."""
    exc = truth["excitation"]
    if isinstance(exc, dict) and "theta0" in exc:
        return float(exc["theta0"])
    return None


def calibration_rows(cal, truth: dict) -> list[dict]:
    """Every estimate of a `Calibration` beside its truth."""
    impacts = truth_impacts(truth)
    label = next(iter(cal.nuisance))
    nuis = cal.nuisance[label]
    matched, rows = [], []
    for imp in nuis["impacts"]:
        tr = _match(impacts, float(imp["t"]), imp["corner"])
        if tr is not None:
            matched.append(tr)
        rows.append(_row("r", imp["r"], tr["r"] if tr else None, item=imp["t"],
                         std=imp.get("r_std"), corner=imp["corner"]))  # fmt: skip
    mean_r, mean_l, _ = _pooled(matched)
    means = truth["restitution"]["means"]
    sample = {"r_mean_right": (mean_r, means["right"]), "r_mean_left": (mean_l, means["left"])}
    prov = getattr(cal, "provenance", None) or {}
    for name, p in cal.parameters.items():
        q = _CAL_NAMES.get(name, name)
        if prov.get(name, {}).get("status") in ("estimated", "ill-posed"):
            p = prov[name]  # the std and interval the result reports for it
        tr, nom = sample[q] if q in sample else (_truth_of(q, truth), _NAN)
        unc = _interval(p)
        if "status" not in unc:
            unc["status"] = "estimated" if p.get("constrained", True) else "ill-posed"
        rows.append(_row(q, p["value"], tr, nominal=nom, **unc))
    align = {"t_offset": nuis["t_offset"], "theta0": nuis.get("theta0"),
             "theta_bias": nuis.get("theta_bias")}  # fmt: skip
    for key in ("t_offset_std", "theta0_std", "theta_bias_std"):
        if key in nuis:
            align[key] = nuis[key]
    rows += _nuisance_rows(align, truth, {})
    return rows


def run_case(draw: Draw, records_dir=None, with_calibrate: bool = False) -> dict:
    """Generate the trace of `draw`, run the estimators, and return ``case`` (the draw,
    the statuses and times) and ``rows`` (every estimate with its truth).

    An estimator that refuses the trace (`InputError`) or fails (`SolverError`) gives
    no rows; its message is kept in the case's ``*_status``.
    """
    case = draw.to_dict()
    t0 = time.perf_counter()
    syn, shrunk = make_trace(draw, records_dir)
    case.update(generate_s=time.perf_counter() - t0, record_shrunk=shrunk,
                n_impacts_true=len(syn.truth["impacts"]))  # fmt: skip
    rows = []
    runs = [("restitution", lambda: restitution(syn.trace, draw.specimen, draw.family,
                                                 progress=False), restitution_rows)]  # fmt: skip
    if with_calibrate:
        kw = {"fit": _everything(draw)}
        if inspect.signature(calibrate).parameters["fit"].default is None:
            kw = {}  # its default: every parameter not given (those the traces show)
        runs.append(("calibrate", lambda: calibrate(syn.trace, draw.specimen, _cal_model(draw),
                                                    progress=False, **kw), calibration_rows))  # fmt: skip
    for name, call, extract in runs:
        t0 = time.perf_counter()
        try:
            res = call()
        except (InputError, SolverError) as err:
            case[f"{name}_status"] = f"error: {str(err).splitlines()[0][:300]}"
            case[f"{name}_s"] = time.perf_counter() - t0
            continue
        case[f"{name}_s"] = time.perf_counter() - t0
        case[f"{name}_status"] = getattr(res, "status", "ok")
        for row in extract(res, syn.truth):
            rows.append({"case": draw.case, "specimen": draw.specimen, "kind": draw.kind,
                         "estimator": name, **row})  # fmt: skip
    return {"case": case, "rows": rows}


def _everything(draw: Draw) -> tuple:
    """Every parameter `calibrate` can fit for the family (C_p only for Dirac-delta)."""
    return tuple(n for n in FITTABLE if draw.family == "DD" or n != "cp")


def _cal_model(draw: Draw) -> str:
    """calibrate's name of the family: the Dirac-delta model with the corner means (DD)."""
    return "DD" if draw.family == "DD" else "CIM"
