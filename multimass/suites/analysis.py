"""Fragility analysis of a suite's runs table: counts, lognormal fits, IDA, IM efficiency.

The input is the *runs table* of a suite (`multimass.suites.runs`): a pandas DataFrame
with one row per simulation. The columns used here are

* ``structure``, ``motion``, ``motion_kind`` (``"record"`` | ``"pulse"``);
* ``im_name`` and ``im`` — the suite's intensity measure and its value (SI units, > 0);
* ``level`` (intensity level index), ``draw`` (Monte-Carlo draw index);
* ``theta_max_over_alpha`` (≥ 0, ≥ 1 when overturned), ``overturned`` (bool),
  ``status`` (``"completed"``, ``"overturned"``, ``"inaccurate"``, ``"failed"``);
* IM columns computed on the scaled motion: ``pga``, ``pgv``, ``pgd``, ``arias`` and
  ``sa_<T>s``;
* for pulse runs, ``omega_p_over_p`` (ω_p/p) and ``amp_over_g_tan_alpha``
  (a_p/(g tan α)).

A *damage state* (a "measure") is overturning, ``"overturned"``, or a threshold ``x`` of
the normalised rotation, exceeded when θ_max/α ≥ x; an overturned run exceeds every
threshold. Runs whose status is ``"inaccurate"`` or ``"failed"`` are left out of every
count and fit, and are counted (``n_excluded``) wherever they are left out.

Fragility curves are the lognormal model ``P(exceed | IM = x) = Φ(ln(x/θ)/β)`` fitted by
maximum likelihood to binomial counts (Baker 2015), by `multimass.analysis.fragility.fit_lognormal`;
nothing of that fit is re-implemented here. The counts are taken per intensity level when
every run at a level has the same IM value (e.g. records scaled to a common PGA and
fitted in PGA), and per run otherwise (e.g. records scaled by a common factor but fitted
in PGA; each run is then its own level with one run) — the likelihood is the same either
way, only the table differs. A damage state the data cannot fit (no run exceeds it, all
runs exceed it, separated data, …) is reported by the fit's ``status`` and ``message``
with NaN numbers; it never raises.

For pulses, the fragility is dimensionless (Dimitrakopoulos & Paraskeva 2015): for each
ω_p/p a lognormal curve in a_p/(g tan α), whose median θ is the pulse amplitude, in units
of the uplift acceleration g tan α, that overturns the structure half the time.

References
----------
J. W. Baker (2015), Efficient analytical fragility function fitting using dynamic
structural analysis, Earthquake Spectra 31(1), 579–599.
E. G. Dimitrakopoulos and T. S. Paraskeva (2015), Dimensionless fragility curves for
rocking response to near-fault excitations, Earthquake Engineering and Structural
Dynamics 44(12), 2015–2033.
"""

from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..analysis.fragility import FragilityFit, fit_lognormal
from ..errors import InputError

__all__ = [
    "DAMAGE_STATES",
    "RUN_STATUSES",
    "EXCLUDED_STATUSES",
    "BASE_IMS",
    "im_unit",
    "im_label",
    "measure_label",
    "im_columns",
    "exceedance_counts",
    "fragility_curves",
    "im_efficiency",
    "ida_curves",
    "ida_summary",
    "PulseFragility",
    "pulse_fragility",
    "summary_dict",
    "summary_tables",
    "as_json",
    "json_ready",
]

#: Default damage states: overturning, θ_max/α ≥ 0.5 and θ_max/α ≥ 0.8.
DAMAGE_STATES = ("overturned", 0.5, 0.8)

#: The statuses a run can have.
RUN_STATUSES = ("completed", "overturned", "inaccurate", "failed")

#: Statuses left out of every count and fit (and counted as ``n_excluded``).
EXCLUDED_STATUSES = ("inaccurate", "failed")

#: The IM columns every run carries (besides the ``sa_<T>s`` columns).
BASE_IMS = ("pga", "pgv", "pgd", "arias")

_UNITS = {
    "pga": "m/s²",
    "pgv": "m/s",
    "pgd": "m",
    "arias": "m/s",
    "scale": "-",
    "amp_over_g_tan_alpha": "-",
    "omega_p_over_p": "-",
}
_NAMES = {
    "pga": "PGA",
    "pgv": "PGV",
    "pgd": "PGD",
    "arias": "Arias intensity",
    "scale": "scale factor",
    "amp_over_g_tan_alpha": "a_p/(g tan α)",
    "omega_p_over_p": "ω_p/p",
}
_SA = re.compile(r"^sa_(\d+(?:\.\d*)?)s$")
_CORE = ("status", "theta_max_over_alpha", "overturned", "level")


# ------------------------------------------------------------------------ names, units
def im_unit(name: str) -> str:
    """SI unit of an IM column or IM name (``"-"`` for dimensionless, ``""`` if unknown)."""
    if _SA.match(name):
        return "m/s²"
    return _UNITS.get(name, "")


def im_label(name: str) -> str:
    """Axis label of an IM, with its unit: ``"PGA (m/s²)"``, ``"Sa(1.000 s) (m/s²)"``."""
    m = _SA.match(name)
    base = f"Sa({m.group(1)} s)" if m else _NAMES.get(name, name)
    unit = im_unit(name)
    return f"{base} ({unit})" if unit else base


def im_columns(runs: pd.DataFrame) -> list[str]:
    """The IM columns present in `runs`: PGA, PGV, PGD, Arias, then Sa by period."""
    sa = sorted((c for c in runs.columns if _SA.match(str(c))), key=lambda c: _period(c))
    return [c for c in BASE_IMS if c in runs.columns] + sa


def _period(col: str) -> float:
    return float(_SA.match(col).group(1))


@dataclass(frozen=True)
class _Measure:
    label: str
    threshold: float | None  # None: overturning

    def exceeds(self, runs: pd.DataFrame) -> np.ndarray:
        over = runs["overturned"].to_numpy(dtype=bool)
        if self.threshold is None:
            return over
        return over | (runs["theta_max_over_alpha"].to_numpy(dtype=float) >= self.threshold)


def _measure(m) -> _Measure:
    if isinstance(m, _Measure):
        return m
    if isinstance(m, str):
        s = m.strip().lower().replace(" ", "")
        if s in ("overturned", "overturning", "overturn"):
            return _Measure("overturned", None)
        for prefix in ("theta_over_alpha>=", "theta_max_over_alpha>=", "theta/alpha>=", "θ/α≥"):
            if s.startswith(prefix):
                s = s[len(prefix) :]
                break
        try:
            x = float(s)
        except ValueError:
            x = None
    elif isinstance(m, (int, float, np.integer, np.floating)) and not isinstance(m, bool):
        x = float(m)
    else:
        x = None
    if x is None or not math.isfinite(x) or x <= 0:
        raise InputError(
            f"unknown damage state {m!r}: use 'overturned', or a threshold x > 0 of "
            "θ_max/α (a number, or 'theta_over_alpha>=x')."
        )
    return _Measure(f"theta_over_alpha>={x:g}", x)


def measure_label(m) -> str:
    """The label of a damage state: ``"overturned"`` or ``"theta_over_alpha>=0.5"``."""
    return _measure(m).label


def _measures(measures) -> list[_Measure]:
    if isinstance(measures, (str, int, float, _Measure)):
        measures = [measures]
    out = [_measure(m) for m in measures]
    if not out:
        raise InputError("`measures` is empty; give at least one damage state, e.g. 'overturned'.")
    labels = [m.label for m in out]
    if len(set(labels)) != len(labels):
        raise InputError(f"`measures` repeats a damage state: {labels}.")
    return out


# ----------------------------------------------------------------------- validation
@dataclass
class _Runs:
    """A validated runs table, split into the runs kept and those excluded."""

    kept: pd.DataFrame
    excluded: pd.DataFrame
    structure: str | None
    im: str
    im_name: str

    @property
    def excluded_by_status(self) -> dict:
        counts = self.excluded["status"].value_counts()
        return {s: int(counts.get(s, 0)) for s in EXCLUDED_STATUSES}


def _prepare(runs, im: str = "im", needed=_CORE, structure=None) -> _Runs:
    if not isinstance(runs, pd.DataFrame):
        raise InputError(
            f"`runs` must be a pandas DataFrame (a suite's runs table); got {type(runs).__name__}."
        )
    if runs.empty:
        raise InputError(
            "the runs table is empty: no simulation to analyse. Run the suite first "
            "(multimass.suites.runs), or check the filter that emptied it."
        )
    need = list(dict.fromkeys([*needed, im] + (["im_name"] if im == "im" else [])))
    missing = [c for c in need if c not in runs.columns]
    if missing:
        raise InputError(
            f"the runs table lacks the column(s) {missing}; a suite's runs table has them "
            f"(multimass.suites.runs). Columns present: {list(runs.columns)}."
        )
    if "structure" in runs.columns:
        names = list(pd.unique(runs["structure"].astype(str)))
        if structure is not None:
            if str(structure) not in names:
                raise InputError(f"structure {structure!r} is not in the runs table: {names}.")
            runs = runs[runs["structure"].astype(str) == str(structure)]
        elif len(names) > 1:
            raise InputError(
                f"the runs table holds {len(names)} structures {names}; pass "
                "`structure=` to analyse one of them."
            )
        structure = names[0] if structure is None else str(structure)
    status = runs["status"].astype(str)
    unknown = sorted(set(status) - set(RUN_STATUSES))
    if unknown:
        raise InputError(f"unknown run status {unknown}; a run's status is one of {RUN_STATUSES}.")
    out = status.isin(EXCLUDED_STATUSES).to_numpy()
    kept = runs[~out]
    excluded = runs[out]
    if kept.empty:
        raise InputError(
            f"no run to analyse: all {len(runs)} runs are {'/'.join(EXCLUDED_STATUSES)} "
            f"({dict(status.value_counts())}). Tighten the solver tolerances or drop the "
            "motions that fail."
        )
    _check_values(kept, im)
    if im == "im":
        names = list(pd.unique(kept["im_name"].astype(str)))
        if len(names) > 1:
            raise InputError(
                f"the runs mix intensity measures {names} in column 'im'; analyse one suite "
                "at a time, or pass an IM column (im='pga', …) that all runs share."
            )
        im_name = names[0]
    else:
        im_name = im
    return _Runs(kept, excluded, structure, im, im_name)


def _check_values(kept: pd.DataFrame, im: str) -> None:
    x = pd.to_numeric(kept[im], errors="coerce").to_numpy(dtype=float)
    bad = np.flatnonzero(~np.isfinite(x) | (x <= 0))
    if bad.size:
        raise InputError(
            f"column {im!r} must be finite and > 0 for every run analysed (the fragility is "
            f"lognormal in the IM); {bad.size} run(s) are not, e.g. row {kept.index[bad[0]]!r} "
            f"with {im} = {x[bad[0]]}. Drop those runs or choose another IM."
        )
    r = pd.to_numeric(kept["theta_max_over_alpha"], errors="coerce").to_numpy(dtype=float)
    bad = np.flatnonzero(~(r >= 0))
    if bad.size:
        raise InputError(
            f"column 'theta_max_over_alpha' must be ≥ 0 for every completed or overturned run; "
            f"row {kept.index[bad[0]]!r} has {r[bad[0]]}. Mark that run 'failed' or fix it."
        )
    o = kept["overturned"]
    if o.isna().any() or not set(pd.unique(o)) <= {True, False}:
        raise InputError(
            "column 'overturned' must be True/False for every completed or overturned run; "
            f"found {sorted(map(repr, set(pd.unique(o))))}."
        )


def _same(x: np.ndarray) -> bool:
    return bool(np.all(np.abs(x - x[0]) <= 1e-9 * np.abs(x[0])))


# ----------------------------------------------------------------------- the counts
def _counts(r: _Runs, measures: list[_Measure]) -> pd.DataFrame:
    kept, excl, im = r.kept, r.excluded, r.im
    x = kept[im].to_numpy(dtype=float)
    level = kept["level"].to_numpy()
    per_level = all(_same(x[level == lv]) for lv in pd.unique(level))
    hits = {m.label: m.exceeds(kept).astype(np.int64) for m in measures}
    if per_level:
        levels = np.array(sorted(set(pd.unique(level)) | set(pd.unique(excl["level"]))))
        rows = []
        for lv in levels:
            sel = level == lv
            n = int(sel.sum())
            row = {
                "level": lv,
                "im": float(np.median(x[sel])) if n else float("nan"),
                "n_runs": n,
                "n_excluded": int((excl["level"].to_numpy() == lv).sum()),
            }
            for lab, h in hits.items():
                row[f"n_exceed[{lab}]"] = int(h[sel].sum())
            rows.append(row)
        table = pd.DataFrame(rows)
        if table["im"].isna().any():  # a level whose runs were all excluded
            xe = pd.to_numeric(excl[im], errors="coerce")
            for j in np.flatnonzero(table["im"].isna()):
                v = xe[excl["level"].to_numpy() == table.at[j, "level"]].dropna()
                table.at[j, "im"] = float(v.median()) if len(v) else float("nan")
        grouping = "level"
    else:
        ident = [c for c in ("motion", "draw", "level") if c in kept.columns]
        keep = kept[ident].copy()
        keep["im"] = x
        keep["n_runs"] = 1
        keep["n_excluded"] = 0
        for lab, h in hits.items():
            keep[f"n_exceed[{lab}]"] = h
        drop = excl[ident].copy()
        drop["im"] = pd.to_numeric(excl[im], errors="coerce").to_numpy(dtype=float)
        drop["n_runs"] = 0
        drop["n_excluded"] = 1
        for lab in hits:
            drop[f"n_exceed[{lab}]"] = 0
        table = pd.concat([keep, drop]) if len(drop) else keep
        table = table.rename_axis("run").reset_index()
        table = table.sort_values(["im", "run"], kind="stable", na_position="last")
        table = table.reset_index(drop=True)
        grouping = "run"
    table.attrs.update(
        {
            "grouping": grouping,
            "im": r.im,
            "im_name": r.im_name,
            "structure": r.structure,
            "measures": [m.label for m in measures],
            "n_runs": len(kept),
            "n_excluded": len(excl),
            "excluded": r.excluded_by_status,
        }
    )
    return table


def exceedance_counts(runs, im: str = "im", measures=DAMAGE_STATES, structure=None):
    """Runs and exceedances of each damage state, per intensity level (or per run).

    Parameters
    ----------
    runs : pandas.DataFrame
        A suite's runs table (see the module docstring).
    im : str
        The IM column to count in: ``"im"`` (the suite's own IM, named by ``im_name``)
        or an IM column such as ``"pga"`` or ``"sa_1.000s"``.
    measures : sequence
        Damage states: ``"overturned"`` and/or thresholds x of θ_max/α (numbers, or
        ``"theta_over_alpha>=x"``). Default `DAMAGE_STATES`.
    structure : str, optional
        Which structure to analyse when the table holds several.

    Returns
    -------
    pandas.DataFrame
        Per level (``grouping == "level"``, when every run at a level has the same value
        of `im`): ``level``, ``im`` (the level's value), ``n_runs``, ``n_excluded`` and
        one ``n_exceed[<label>]`` column per damage state. Per run otherwise
        (``grouping == "run"``): ``run`` (the runs-table index), ``motion``, ``draw``,
        ``level``, ``im`` (the run's value), ``n_runs`` = 1 and ``n_exceed[...]`` ∈ {0, 1};
        excluded runs appear as rows with ``n_runs`` = 0 and ``n_excluded`` = 1, sorted
        last. ``attrs`` holds ``grouping``, ``im``, ``im_name``, ``structure``,
        ``measures`` (labels), ``n_runs``, ``n_excluded`` and ``excluded`` (per status).

    Raises
    ------
    multimass.errors.InputError
        Empty table, missing columns, unknown statuses or damage states, IM values not
        finite and > 0, several IMs or structures mixed, or every run excluded.
    """
    ms = _measures(measures)
    return _counts(_prepare(runs, im, structure=structure), ms)


# ------------------------------------------------------------------------- the fits
@dataclass
class _FitResult:
    measure: _Measure
    fit: FragilityFit
    band: object  # multimass.analysis.fragility.Band or None
    n_degenerate: int = 0


def _case_bootstrap(fit: FragilityFit, n_resamples: int, level: float, seed: int, x=None):
    """Percentile band from resampling the runs themselves (per-run data, one run a level).

    Resampling within each level (`FragilityFit.bootstrap`) cannot vary a level that
    holds one run, so per-run data are resampled as cases: N runs drawn with replacement
    from the N runs, each resample refitted by `fit_lognormal`. Separated resamples enter
    with β = 0 and θ at the geometric middle of their bounds, the others without a
    maximum are left out (the convention of `FragilityFit.bootstrap`).
    """
    if int(n_resamples) < 10:
        raise InputError(f"`bootstrap` must be 0 or ≥ 10 resamples; got {n_resamples!r}.")
    base = fit.confidence(level, x)  # validates level, gives the grid
    rng = np.random.default_rng(seed)
    levels, n, k = fit.levels, fit.n_runs, fit.n_exceed
    # expand to one entry per run (n may exceed 1 when several runs share an IM value)
    xs = np.repeat(levels, n)
    ys = np.concatenate([np.r_[np.ones(kk, int), np.zeros(nn - kk, int)] for nn, kk in zip(n, k)])
    thetas, betas, curves, degenerate = [], [], [], 0
    for _ in range(int(n_resamples)):
        idx = rng.integers(0, xs.size, xs.size)
        f = fit_lognormal(xs[idx], 1, ys[idx])
        if f.status != 0:
            degenerate += 1
        if f.status == 3:
            lo, hi = f.theta_bounds
            f = dataclasses.replace(f, theta=math.sqrt(lo * hi), beta=0.0)
        elif f.status != 0:
            continue
        thetas.append(f.theta)
        betas.append(f.beta)
        curves.append(f.probability(base.x))
    if not thetas:
        return dataclasses.replace(
            base,
            method="bootstrap",
            theta=(math.nan, math.nan),
            beta=(math.nan, math.nan),
            lower=np.full(base.x.shape, np.nan),
            upper=np.full(base.x.shape, np.nan),
            n_resamples=int(n_resamples),
            n_degenerate=degenerate,
        )
    q = [(1 - level) / 2, (1 + level) / 2]
    th = np.quantile(thetas, q, method="inverted_cdf")
    be = np.quantile(betas, q, method="inverted_cdf")
    band = np.quantile(np.array(curves), q, axis=0, method="inverted_cdf")
    return dataclasses.replace(
        base,
        method="bootstrap",
        theta=(float(th[0]), float(th[1])),
        beta=(float(be[0]), float(be[1])),
        lower=band[0],
        upper=band[1],
        n_resamples=int(n_resamples),
        n_degenerate=degenerate,
    )


def _fit_counts(x, n, k, grouping, bootstrap, seed, level, grid=None):
    fit = fit_lognormal(x, n, k)
    band = None
    if fit.converged:
        if bootstrap and grouping == "run":
            band = _case_bootstrap(fit, bootstrap, level, seed, grid)
        elif bootstrap:
            band = fit.bootstrap(int(bootstrap), level, seed, grid)
        else:
            band = fit.confidence(level, grid)
    return fit, band


def _check_band_args(bootstrap, level):
    if isinstance(bootstrap, bool) or not isinstance(bootstrap, (int, np.integer)):
        raise InputError(f"`bootstrap` is a number of resamples (0 for Fisher); got {bootstrap!r}.")
    if bootstrap != 0 and bootstrap < 10:
        raise InputError(f"`bootstrap` must be 0 (Fisher band) or ≥ 10 resamples; got {bootstrap}.")
    if not (0 < float(level) < 1):
        raise InputError(f"`level` is a confidence level in (0, 1), e.g. 0.95; got {level!r}.")


def _fits(runs, im, measures, bootstrap, seed, level, structure, grid=None):
    _check_band_args(bootstrap, level)
    ms = _measures(measures)
    r = _prepare(runs, im, structure=structure)
    counts = _counts(r, ms)
    used = counts[counts["n_runs"] > 0]
    x = used["im"].to_numpy(dtype=float)
    n = used["n_runs"].to_numpy()
    results = []
    for m in ms:
        k = used[f"n_exceed[{m.label}]"].to_numpy()
        fit, band = _fit_counts(x, n, k, counts.attrs["grouping"], bootstrap, seed, level, grid)
        results.append(_FitResult(m, fit, band, band.n_degenerate if band is not None else 0))
    return counts, results


def _fit_row(fit: FragilityFit, band, level) -> dict:
    nan = float("nan")
    lo_b, hi_b = fit.theta_bounds
    return {
        "theta": fit.theta,
        "beta": fit.beta,
        "converged": fit.converged,
        "status": fit.status,
        "message": fit.message,
        "theta_low": band.theta[0] if band is not None else nan,
        "theta_high": band.theta[1] if band is not None else nan,
        "beta_low": band.beta[0] if band is not None else nan,
        "beta_high": band.beta[1] if band is not None else nan,
        "band": band.method if band is not None else None,
        "band_level": float(level),
        "theta_bound_low": float(lo_b),
        "theta_bound_high": float(hi_b),
        "loglik": fit.loglik,
    }


def fragility_curves(
    runs,
    im: str = "im",
    measures=DAMAGE_STATES,
    bootstrap: int = 0,
    seed: int = 0,
    level: float = 0.95,
    structure=None,
) -> pd.DataFrame:
    """Lognormal fragility curves, one per damage state, by maximum likelihood (Baker 2015).

    Parameters
    ----------
    runs : pandas.DataFrame
        A suite's runs table.
    im : str
        IM column to fit in (``"im"``, the suite's own, or ``"pga"``, ``"sa_1.000s"``, …).
        θ comes in its units (`im_unit`).
    measures : sequence
        Damage states (see `exceedance_counts`). Default `DAMAGE_STATES`.
    bootstrap : int
        0 for the asymptotic (Fisher) band, else a number (≥ 10) of seeded bootstrap
        resamples for percentile bands: within each level for per-level counts
        (`multimass.analysis.fragility.FragilityFit.bootstrap`), of the runs themselves for
        per-run data.
    seed : int
        Seed of the bootstrap.
    level : float
        Two-sided confidence level of the bands.
    structure : str, optional
        Which structure, when the table holds several.

    Returns
    -------
    pandas.DataFrame
        One row per damage state: ``measure`` (label), ``im`` (column), ``im_name``,
        ``unit``, ``structure``, ``theta``, ``beta``, ``converged``, ``status``,
        ``message``, ``theta_low``/``theta_high`` and ``beta_low``/``beta_high`` (the
        band; NaN when the fit has no maximum), ``band`` (``"fisher"``/``"bootstrap"``),
        ``band_level``, ``n_resamples``, ``n_degenerate``, ``band_seed``,
        ``theta_bound_low``/``theta_bound_high`` (what the data say about θ, also for
        degenerate fits), ``loglik``, ``n_runs``, ``n_exceed``, ``n_excluded``,
        ``n_levels`` (levels or runs fitted) and ``grouping`` (``"level"`` or ``"run"``).
        A damage state without a maximum-likelihood estimate keeps the fit's ``status``
        and ``message`` (`multimass.analysis.fragility.STATUS`) and NaN numbers.

    Raises
    ------
    multimass.errors.InputError
        Invalid runs table (see `exceedance_counts`) or band arguments.
    """
    counts, results = _fits(runs, im, measures, bootstrap, seed, level, structure)
    a = counts.attrs
    rows = []
    for res in results:
        row = {
            "measure": res.measure.label,
            "im": a["im"],
            "im_name": a["im_name"],
            "unit": im_unit(a["im_name"]),
            "structure": a["structure"],
        }
        row.update(_fit_row(res.fit, res.band, level))
        row.update(
            {
                "n_resamples": int(bootstrap) if res.band is not None else 0,
                "n_degenerate": res.n_degenerate,
                "band_seed": int(seed),
                "n_runs": int(res.fit.n_runs.sum()),
                "n_exceed": int(res.fit.n_exceed.sum()),
                "n_excluded": a["n_excluded"],
                "n_levels": int(res.fit.levels.size),
                "grouping": a["grouping"],
            }
        )
        rows.append(row)
    out = pd.DataFrame(rows)
    out.attrs.update({k: a[k] for k in ("grouping", "n_runs", "n_excluded", "excluded")})
    return out


def im_efficiency(runs, ims=None, measure="overturned", structure=None) -> pd.DataFrame:
    """Compare intensity measures by the dispersion β of their fragility curves.

    The same runs are fitted in each IM column (Baker 2015's lognormal model, by
    `fragility_curves`); the IM whose curve has the smaller β separates the runs that
    exceed from those that do not with less scatter — it is the more *efficient* IM.

    Parameters
    ----------
    runs : pandas.DataFrame
        A suite's runs table.
    ims : sequence of str, optional
        IM columns to compare; default every one present (`im_columns`: ``pga``,
        ``pgv``, ``pgd``, ``arias``, then the ``sa_<T>s`` columns).
    measure : str or float
        The damage state (default overturning).
    structure : str, optional
        Which structure, when the table holds several.

    Returns
    -------
    pandas.DataFrame
        One row per IM, sorted by ``beta`` (smallest first; fits without a maximum, NaN,
        last): ``im``, ``unit``, ``beta``, ``beta_low``, ``beta_high`` (Fisher 95 %),
        ``theta``, ``converged``, ``status``, ``message``, ``n_runs``, ``grouping``.
        A separated fit (status 3) has β = 0: that IM splits the runs perfectly.
    """
    if ims is None:
        ims = im_columns(runs) if isinstance(runs, pd.DataFrame) else []
        if not ims:
            raise InputError(
                "no IM column in the runs table (pga, pgv, pgd, arias, sa_<T>s); pass `ims=`."
            )
    elif isinstance(ims, str):
        ims = [ims]
    label = _measure(measure).label
    rows = []
    for col in ims:
        c = fragility_curves(runs, im=col, measures=[measure], structure=structure).iloc[0]
        rows.append(
            {
                "im": col,
                "unit": im_unit(col),
                "beta": c["beta"],
                "beta_low": c["beta_low"],
                "beta_high": c["beta_high"],
                "theta": c["theta"],
                "converged": c["converged"],
                "status": c["status"],
                "message": c["message"],
                "n_runs": c["n_runs"],
                "grouping": c["grouping"],
            }
        )
    out = pd.DataFrame(rows).sort_values("beta", kind="stable", na_position="last")
    out = out.reset_index(drop=True)
    out.attrs["measure"] = label
    return out


# ------------------------------------------------------------------------------ IDA
def ida_curves(runs, im: str = "im", structure=None) -> pd.DataFrame:
    """IDA curves: θ_max/α of each motion and draw against the intensity, level by level.

    Returns
    -------
    pandas.DataFrame
        One row per (motion, draw, level), sorted so: ``motion``, ``draw``, ``level``,
        ``im``, ``theta_max_over_alpha``, ``overturned``, ``status`` and ``included``
        (False for inaccurate/failed runs, which are listed but belong to no summary).

    Raises
    ------
    multimass.errors.InputError
        Invalid runs table, or two runs with the same (motion, draw, level).
    """
    r = _prepare(runs, im, needed=(*_CORE, "motion", "draw"), structure=structure)
    cols = ["motion", "draw", "level", im, "theta_max_over_alpha", "overturned", "status"]
    both = pd.concat([r.kept[cols], r.excluded[cols]]).rename(columns={im: "im"})
    dup = both.duplicated(["motion", "draw", "level"], keep=False)
    if dup.any():
        first = both[dup].iloc[0]
        raise InputError(
            f"{int(dup.sum())} runs share a (motion, draw, level), e.g. ({first['motion']!r}, "
            f"{first['draw']}, {first['level']}); an IDA curve needs one run per draw and "
            "level — filter the table to one suite and structure."
        )
    both["included"] = ~both["status"].astype(str).isin(EXCLUDED_STATUSES)
    both["im"] = pd.to_numeric(both["im"], errors="coerce").astype(float)
    out = both.sort_values(["motion", "draw", "level"], kind="stable").reset_index(drop=True)
    out.attrs.update({"im": im, "im_name": r.im_name, "structure": r.structure})
    return out


def ida_summary(runs, im: str = "im", structure=None) -> pd.DataFrame:
    """Per motion: the median IDA curve over the draws, and where half the draws overturn.

    Overturned runs enter the median with their recorded θ_max/α (≥ 1), so a median ≥ 1
    means at least half of the draws overturned at that level.

    Returns
    -------
    pandas.DataFrame
        One row per motion: ``motion``, ``n_draws`` (distinct draws), ``n_excluded``
        (inaccurate/failed runs left out), and, one entry per level (in level order) as
        lists, ``levels``, ``im`` (the level's median IM over the draws),
        ``median_theta_over_alpha``, ``fraction_overturned``, ``n_runs``; then
        ``im_overturn_50`` — the lowest IM at which ≥ 50 % of the draws analysed
        overturned (NaN if none) — and its ``level_overturn_50`` (−1 if none).
    """
    curves = ida_curves(runs, im=im, structure=structure)
    rows = []
    for motion, g in curves.groupby("motion", sort=True):
        ok = g[g["included"]]
        per = (
            ok.groupby("level", sort=True)
            .agg(
                im=("im", "median"),
                median=("theta_max_over_alpha", "median"),
                frac=("overturned", "mean"),
                n=("draw", "size"),
            )
            .reset_index()
        )
        hit = per[per["frac"] >= 0.5]
        if len(hit):
            j = hit["im"].idxmin()
            im50, lv50 = float(hit.at[j, "im"]), int(hit.at[j, "level"])
        else:
            im50, lv50 = float("nan"), -1
        rows.append(
            {
                "motion": motion,
                "n_draws": int(g["draw"].nunique()),
                "n_excluded": int((~g["included"]).sum()),
                "levels": [int(v) for v in per["level"]],
                "im": [float(v) for v in per["im"]],
                "median_theta_over_alpha": [float(v) for v in per["median"]],
                "fraction_overturned": [float(v) for v in per["frac"]],
                "n_runs": [int(v) for v in per["n"]],
                "im_overturn_50": im50,
                "level_overturn_50": lv50,
            }
        )
    out = pd.DataFrame(rows)
    out.attrs.update(curves.attrs)
    return out


# ------------------------------------------------------------------ pulse fragility
@dataclass
class PulseFragility:
    """Dimensionless fragility of pulse runs (Dimitrakopoulos & Paraskeva 2015).

    Attributes
    ----------
    measure : str
        The damage state (label).
    curves : pandas.DataFrame
        One row per ω_p/p: ``omega_p_over_p``, ``theta`` (median a_p/(g tan α) to exceed),
        ``beta``, the Fisher band (``theta_low`` … ``beta_high``), ``converged``,
        ``status``, ``message``, ``theta_bound_low``/``theta_bound_high``, ``n_runs``,
        ``n_exceed``, ``n_excluded``, ``n_amplitudes``.
    counts : pandas.DataFrame
        One row per (ω_p/p, a_p/(g tan α)): ``n_runs``, ``n_exceed``, ``n_excluded`` and
        ``fraction`` (n_exceed / n_runs, NaN when every run there was excluded).
    probabilities : pandas.DataFrame
        The empirical table: index ω_p/p, columns a_p/(g tan α), values the fraction.
    """

    measure: str
    curves: pd.DataFrame
    counts: pd.DataFrame
    probabilities: pd.DataFrame

    def as_dict(self) -> dict:
        """JSON-ready: the curves and the counts as lists of records (NaN → None)."""
        return {
            "measure": self.measure,
            "curves": json_ready(self.curves),
            "counts": json_ready(self.counts),
        }


def _key(v) -> np.ndarray:
    """Float values rounded to 12 significant digits, to group equal grid values."""
    v = np.asarray(v, dtype=float)
    return np.array([float(f"{x:.12g}") if math.isfinite(x) else x for x in v])


def pulse_fragility(runs, measure="overturned", level: float = 0.95, structure=None):
    """Dimensionless pulse fragility: per ω_p/p, a lognormal curve in a_p/(g tan α).

    For each distinct ω_p/p the runs are counted per distinct amplitude a_p/(g tan α)
    and ``P(exceed) = Φ(ln(A/θ)/β)``, A = a_p/(g tan α), is fitted by
    `multimass.analysis.fragility.fit_lognormal` (Baker 2015): θ is the median normalised pulse
    amplitude that makes the structure exceed the damage state, the dimensionless
    fragility of Dimitrakopoulos & Paraskeva (2015).

    Parameters
    ----------
    runs : pandas.DataFrame
        A runs table with pulse runs (``motion_kind == "pulse"``; other runs are ignored).
    measure : str or float
        The damage state (default overturning).
    level : float
        Confidence level of the Fisher bands.
    structure : str, optional
        Which structure, when the table holds several.

    Returns
    -------
    PulseFragility

    Raises
    ------
    multimass.errors.InputError
        The table lacks ``omega_p_over_p`` or ``amp_over_g_tan_alpha`` (not pulse runs),
        has no pulse run, or a pulse run has no finite value of them.
    """
    _check_band_args(0, level)
    m = _measure(measure)
    pulse_cols = ["omega_p_over_p", "amp_over_g_tan_alpha"]
    if isinstance(runs, pd.DataFrame):
        missing = [c for c in pulse_cols if c not in runs.columns]
        if missing:
            raise InputError(
                f"the runs table lacks the pulse column(s) {missing}: these are not pulse runs. "
                "The dimensionless fragility needs a pulse suite (ω_p/p and a_p/(g tan α) "
                "per run)."
            )
        if "motion_kind" in runs.columns:
            runs = runs[runs["motion_kind"].astype(str) == "pulse"]
            if runs.empty:
                raise InputError(
                    "no pulse run in the runs table (motion_kind == 'pulse'); the "
                    "dimensionless fragility needs a pulse suite."
                )
    r = _prepare(runs, "amp_over_g_tan_alpha", needed=(*_CORE, *pulse_cols), structure=structure)
    if not np.all(np.isfinite(r.kept["omega_p_over_p"].to_numpy(dtype=float))):
        raise InputError("column 'omega_p_over_p' must be finite for every pulse run analysed.")
    kept = pd.DataFrame(
        {
            "omega_p_over_p": _key(r.kept["omega_p_over_p"]),
            "amp_over_g_tan_alpha": _key(r.kept["amp_over_g_tan_alpha"]),
            "n_runs": 1,
            "n_exceed": m.exceeds(r.kept).astype(np.int64),
            "n_excluded": 0,
        }
    )
    excl = pd.DataFrame(
        {
            "omega_p_over_p": _key(pd.to_numeric(r.excluded["omega_p_over_p"], errors="coerce")),
            "amp_over_g_tan_alpha": _key(
                pd.to_numeric(r.excluded["amp_over_g_tan_alpha"], errors="coerce")
            ),
            "n_runs": 0,
            "n_exceed": 0,
            "n_excluded": 1,
        }
    )
    both = pd.concat([kept, excl]) if len(excl) else kept
    counts = (
        both.groupby(["omega_p_over_p", "amp_over_g_tan_alpha"], sort=True, dropna=False)[
            ["n_runs", "n_exceed", "n_excluded"]
        ]
        .sum()
        .reset_index()
    )
    with np.errstate(invalid="ignore", divide="ignore"):
        counts["fraction"] = np.where(
            counts["n_runs"] > 0, counts["n_exceed"] / counts["n_runs"].clip(lower=1), np.nan
        )
    rows = []
    for w, g in counts.groupby("omega_p_over_p", sort=True):
        if not math.isfinite(w):
            continue
        used = g[g["n_runs"] > 0]
        row = {"omega_p_over_p": float(w)}
        if used.empty:
            row.update(
                {
                    "theta": math.nan,
                    "beta": math.nan,
                    "converged": False,
                    "status": -1,
                    "message": "every run at this ω_p/p was inaccurate or failed",
                }
            )
        else:
            fit, band = _fit_counts(
                used["amp_over_g_tan_alpha"].to_numpy(),
                used["n_runs"].to_numpy(),
                used["n_exceed"].to_numpy(),
                "level",
                0,
                0,
                level,
            )
            row.update(_fit_row(fit, band, level))
        row.update(
            {
                "n_runs": int(g["n_runs"].sum()),
                "n_exceed": int(g["n_exceed"].sum()),
                "n_excluded": int(g["n_excluded"].sum()),
                "n_amplitudes": int(len(used)),
            }
        )
        rows.append(row)
    curves = pd.DataFrame(rows)
    probabilities = counts.pivot(
        index="omega_p_over_p", columns="amp_over_g_tan_alpha", values="fraction"
    )
    for df in (curves, counts):
        df.attrs.update(
            {
                "measure": m.label,
                "structure": r.structure,
                "n_excluded": len(r.excluded),
                "excluded": r.excluded_by_status,
            }
        )
    return PulseFragility(m.label, curves, counts, probabilities)


# --------------------------------------------------------------------------- JSON
def json_ready(obj):
    """Plain Python values for ``json.dumps``: DataFrames become lists of records,
    numpy scalars become int/float/bool, NaN and ±inf become None."""
    if isinstance(obj, pd.DataFrame):
        return [json_ready(rec) for rec in obj.to_dict(orient="records")]
    if isinstance(obj, pd.Series):
        return json_ready(obj.to_dict())
    if isinstance(obj, dict):
        return {str(k): json_ready(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, np.ndarray)):
        return [json_ready(v) for v in obj]
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        v = float(obj)
        return v if math.isfinite(v) else None
    if obj is None or obj is pd.NA or obj is pd.NaT:
        return None
    return obj if isinstance(obj, str) else str(obj)


def summary_tables(
    runs,
    im: str = "im",
    measures=DAMAGE_STATES,
    bootstrap: int = 0,
    seed: int = 0,
    level: float = 0.95,
    structure=None,
) -> dict:
    """Everything the analysis has to say about a runs table, each piece computed once.

    Keys: ``structure``, ``im``, ``im_name``, ``unit``, ``n_runs`` (analysed),
    ``n_excluded``, ``excluded`` (per status), ``grouping``, ``fragility``
    (`fragility_curves`), ``exceedance`` (`exceedance_counts`), ``im_efficiency``
    (`im_efficiency` for overturning, or None when the table has no IM column), ``ida``
    (`ida_summary` of the record runs, or None when there are none) and ``pulse``
    (`pulse_fragility`, or None when there are no pulse runs). `summary_dict` is its
    JSON-ready form.
    """
    curves = fragility_curves(runs, im, measures, bootstrap, seed, level, structure)
    counts = exceedance_counts(runs, im, measures, structure)
    a = counts.attrs
    out = {
        "structure": a["structure"],
        "im": im,
        "im_name": a["im_name"],
        "unit": im_unit(a["im_name"]),
        "n_runs": a["n_runs"],
        "n_excluded": a["n_excluded"],
        "excluded": a["excluded"],
        "grouping": a["grouping"],
        "fragility": curves,
        "exceedance": counts,
        "im_efficiency": None,
        "ida": None,
        "pulse": None,
    }
    if im_columns(runs):
        out["im_efficiency"] = im_efficiency(runs, structure=structure)
    kind = runs["motion_kind"].astype(str) if "motion_kind" in runs.columns else None
    if kind is not None and (kind == "record").any():
        out["ida"] = ida_summary(runs[kind == "record"], im=im, structure=structure)
    if (
        kind is not None
        and (kind == "pulse").any()
        and {"omega_p_over_p", "amp_over_g_tan_alpha"} <= set(runs.columns)
    ):
        out["pulse"] = pulse_fragility(runs, structure=structure)
    return out


def summary_dict(
    runs,
    im: str = "im",
    measures=DAMAGE_STATES,
    bootstrap: int = 0,
    seed: int = 0,
    level: float = 0.95,
    structure=None,
) -> dict:
    """`summary_tables`, JSON-ready (`json_ready`; ``pulse`` as `PulseFragility.as_dict`)."""
    return as_json(summary_tables(runs, im, measures, bootstrap, seed, level, structure))


def as_json(tables: dict) -> dict:
    """The JSON-ready form of a `summary_tables` dict."""
    out = dict(tables)
    if out.get("pulse") is not None:
        out["pulse"] = out["pulse"].as_dict()
    return json_ready(out)
