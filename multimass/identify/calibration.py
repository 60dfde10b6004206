"""Calibration of a rocking-column model against shake-table traces.

`calibrate` fits a column's model parameters — the corner means of the coefficient of
restitution r̄_er, r̄_el (``r_er``, ``r_el``; paper 001 Table 1), the C_p of the
Dirac-delta impact force (``cp``; paper 001 Eq 15, not for CIM, which has none) and
the Rayleigh damping ratios (``zeta1``, ``zeta2``): by default every one the user did
not give (``given=``, ``--given``, ``--cp``, ``--zeta1``, ``--zeta2``), so that no
value of the specimen file or of Table 2 stands in for an unknown; a fit list named
explicitly (``fit=``) fixes the others at the specimen's values, and the result says
so (`Calibration.provenance`: given, estimated with std and 95 % interval, ill-posed
with the reason, fixed by the specimen file, not used) — to one or more recorded
traces (θ and the sensors' accelerations) by least squares
(`scipy.optimize.least_squares`, trust-region reflective, bounds), simulating with the
compiled backend. Each trace also has nuisance parameters, fitted and reported: its
clock offset (the trace time of the release, ``t_offset``), the bias of its θ sensor,
the release angle θ0 of a free vibration (a trace without ``ag``; with ``ag`` the
table motion is the excitation, from rest, on the trace's clock) and each
accelerometer's bias (eliminated in closed form: the mean residual).

The objective, and the measurements behind it
----------------------------------------------
Measured on synthetic traces of paper 001 Section 4.3's test (0.11 rad release, 10 s,
DD2, 200 Hz, noise 2 % of each channel's peak; `synthetic_trace`, seed 1):

* **Time histories with the corner means alone do not work.** The test's restitution
  varies from impact to impact (σ_r = 0.025 about the corner means on S1, paper 001
  Table 1). With S1's true means and C_p the accelerations' mean-square residual over
  the 10 s is 120–200 times the noise variance, θ's 9 times; the accelerations' cost
  jumps erratically with the means (r̄_er = 0.90 … 0.96: 106, 119, 122, 145, 110,
  127, 154, 108, 189, 202, 145) and θ's is least at r̄_er = 0.95, 0.02 above the
  truth. Given each impact's drawn r, the same run matches every channel to the
  noise (0.97–1.05 × its variance).
* **Even then, only the first half-cycles can be followed.** With each impact's r
  known, C_p 3 % off raises the accelerations' mean-square residual between 4 and 5 s
  (S1, θ < 0.005 rad: full-contact transitions and uplifts) from 1 to 160–660 ×
  the noise, while over the large half-cycles it is a bowl: 1 at the truth, 5 at
  ±3 %, 35–45 at ±9 %. Over long windows the fit stalls: a restitution near 1 (S2:
  0.9992) fitted 0.001 off changes that impact's force 2.4 times and the 47 Hz phase
  of every later half-cycle; fitted all at once, S2's and S3's windows of 13–16
  impacts stopped at 3–15 × the noise. Over the first 5 half-cycles all three
  specimens reach the noise (1.0 × in every channel) from a start 20 % off; over 9,
  S1 and S3 (three seeds each) still do, S2 stopped at 2–3 × on two seeds of three
  (C_p stuck at its start).
* **Peak ratios are smooth near the optimum but not far from it, nor late.** The log
  ratio of consecutive peaks depends mainly on one impact (≈ 2 log r_k); its cost
  falls from r̄ = 0.70 (507) to 0.93 (13) along a line of the means, but half-cycles
  that die out and the Dirac-delta force switching on before the first impact leave
  local minima (started 20 % low, least squares stopped at r̄_er = 0.71 until a
  coarse scan was added); late in S2's decay the simulated ratios jitter with the
  means (derivatives 49–51 for the first impact, −3983 … 1706 for a late one), and a
  mean set from the ratios of every large half-cycle depended on where it started
  (0.983 or 0.993).

Hence two stages (`multimass.identify._calibration_stages`), after aligning each free
trace's release (below):

1. **Rocking features** of the free traces: the θ samples of the release until θ has
   fallen to half its angle (release angle and clock offset: no restitution acts
   there) and the log peak ratios of the large half-cycles (peaks ≥ `theta_min`;
   peaks as `multimass.identify._calibration_peaks` finds them, the same estimator on
   the trace and the simulation), each ratio weighted by the restitution scatter
   2 σ_r / r̄ and the peaks' noise. A coarse scan of the means (×0.75 … ×1.35) starts
   the descent; C_p and the damping stay at their starts.
2. **Time histories** of θ and every accelerometer over each trace's first 5 large
   half-cycles, then over longer windows (2 half-cycles more at a time, up to
   `history`, 9), each stopping 13 samples (the anti-alias filter's reach) before the
   impact that ends its last half-cycle (`_calibration_stages.REACH`: ending at it
   put part of its filtered spike in the fit, cut where the noisy θ says, and moved
   ζ1 by up to its std per 10 ms), as long as the fit still follows the test — no
   channel's residual RMS up by more than 30 %, residuals white — each channel
   weighted by its residual RMS (re-estimated between passes), everything fitted,
   with **per-impact deviations** from the corner means as random effects: every
   impact in the window takes r̄_corner + δ_k,
   with a Gaussian prior δ_k ~ N(0, σ_r²) (the specimen's σ_r) as residuals δ_k / σ_r
   — the model of the tests (paper 001 Sec 4.3 used impact-specific values for the
   large half-cycles; DD5 draws them). Each δ_k is first seeded alone on θ. The data
   see r̄ + δ_k only, so the means are the centres of their impacts' fitted values
   and their uncertainty includes the scatter σ_r / √n of a corner mean over n
   impacts. The calibrated model (`Calibration.values`, the specimen file) is the
   means with C_p and the damping; the metrics "after" run it over the whole trace.

Forward-difference steps are small (2e-4 for a restitution, 0.2 % of C_p): a step of
2e-3 in r̄ shifts the impact times enough to move the 47 Hz vibration by tens of
degrees, and with it the least squares stopped at a cost 5 times the noise.

Uncertainties are those of the linearised fit, cov = (J̃ᵀJ̃)⁻¹ with each channel's
rows whitened by its residual RMS and down-weighted by the residuals' lag-1
autocorrelation (`multimass.identify._calibration_stats`); for the means the data
columns are replaced by the prior's (`_per_impact_means`). A fitted parameter whose
std exceeds 0.02 (restitution) or 25 % (C_p, ζ), that sits on a bound, or that is
correlated beyond 0.98 with another is reported as not constrained, and the status is
then "ill-posed" (C_p's and ζ's reported std have `MODEL_REL_FLOOR`, 1.5 %, added in
quadrature: the model's error, measured); residuals that are not white (lag-1
autocorrelation above 0.5 in a channel) make it "misfit" (see `STATUSES`).

**Does the fit reproduce the traces?** The covariance is a curvature at the point the
least squares stopped, and says nothing of the error where that point is not the
traces' (a valley of C_p 20 % off whose restitution makes up for it). Stage 2's fit is
therefore tested over its whole window with `restitution`'s test
(`multimass.identify._misfit`, probability 1e-3 of failing a fit that reproduces the
trace): θ's residual mean square against the trace's noise (χ²), each accelerometer's
against its own before the first impact (F). A fit that fails makes every fitted
parameter not constrained, saying why (``Calibration.residuals[...]["misfit"]``, the
ratio to the limit; a warning); the provenance, text, JSON and specimen file then
give the range explored and the best fit, not an estimate.

**Does the table motion's noise decide the fit?** With table motion the model is driven
by the recorded ``ag``, noise included. On the coverage benchmark's S1-004 (seed 0;
northridge_1994, 592 Hz, noise 4.3 %) the fit reproduced the trace (0.77–0.85 of the
limit above) at C_p = 1001 ± 2.3 % for a true 1365, ζ2 = 0.0182 ± 6.6 % for 0.0138: the
model at the true parameters, driven by the recorded ``ag``, misses a_A4 by 3.5 m/s² RMS
(noise 0.87), and driven by the noise-free ``ag`` matches every channel within 1.16 × its
noise, its fit staying at C_p = 1368. Not a second valley of equal cost: with C_p held at
1365 and the rest refitted the cost is 448 above the fit's where the 95 % interval allows
3.84, and the slice probe finds the cost smooth. After the fit,
`multimass.identify._calibration_input.input_check` therefore re-noises each
table-motion trace's ``ag`` by the noise it holds (estimated above fs/4), five draws, and
runs the fitted model with each through the test above; where most fail, every fitted
parameter is ill-posed, the reason naming the value fitted and a refit's with the draw
that failed most (S1-004: draws at 1.004–5.8 × the limit; C_p 1001 and 555). On the 18
table-motion draws of the benchmark's seeds 0–2 (S1–S3, indices 4 and 9) it decided on
every one, all 5 draws failing on each (the worst at 4.0–121 × the limit); before it, 3 of
the 12 C_p, ζ1, ζ2 they estimated covered the truth (C_p 27 % and 33 % off with stds of
2–4 %), now none is estimated. Its cost: 5 runs and, where it decides, a refit of 10
evaluations: 2.7 s of 9.3 s on S1-004, 1.9–30 s (43–154 runs) on the others on a shared
machine (107 s on S2-009 seed 2, a 112 s calibration before); free vibration runs nothing.

Before stage 1, each free trace's release angle and clock offset are aligned on the
samples before its first impact by `restitution`'s scan and fit
(`_calibration_stages.align_releases`): from the first guess alone (often the trace's
first sample on a noisy hold) stage 1 stopped in another valley on 8 of the coverage
benchmark's 15 free traces.

**Nothing given** (the default fit: r̄_er, r̄_el, C_p, ζ1, ζ2; synthetic DD2 traces,
4–5 s, 200 Hz, noise 2 %: S1 with C_p 1.4 × Table 2's and with 0.6 × and the damping
1.3 ×, S2 with 0.6 ×, S3 with 1.4 ×): C_p within 0.2 % of the trace's, each corner
mean within 0.0014 of the mean truth of the impacts it averages (its std, σ_r / √n
included, 0.009–0.0125), the damping ratios within 1.4 of their std; all "converged".
CPU time 10.5–14.9 s each (S1 at 1.4 ×: 13.7 s, and 9.5 s with ζ1, ζ2 given and r̄_er,
r̄_el, C_p fitted).

>>> from multimass import FreeRelease
>>> from multimass.identify import synthetic_trace
>>> syn = synthetic_trace("S1", FreeRelease(theta0=0.11), "DD2", 2.0, seed=3)
>>> cal = calibrate(syn.trace, "S1", "DD2", fit=("r_er", "r_el"), progress=False)
>>> cal.status in STATUSES
True
"""

from __future__ import annotations

import json
import math
import os
import time
from dataclasses import dataclass, field, replace

import pandas as pd

from .. import validation as v
from ..errors import InputError, SolverError
from ..model.structure import Structure
from ..progress import Progress
from ..result import json_ready
from . import _calibration_result as result
from ._calibration_fit import Problem
from ._calibration_input import DRAWS, INPUT_NFEV, input_check
from ._calibration_model import Simulator, TrialRejected
from ._calibration_params import (
    PARAMETERS,
    checked_given,
    default_fit,
    model_of,
    parameter_set,
)
from ._calibration_setup import cases, showable, structure_of
from ._calibration_stages import HISTORY, align_releases, stage1, stage2
from ._calibration_stats import LIMITS, STATUSES
from .impacts import MIN_SIGMA_IMPACTS
from .segments import THETA_MIN

__all__ = ["calibrate", "Calibration", "FITTABLE", "STATUSES", "LIMITS"]

#: The names `calibrate` can fit, and what each is.
FITTABLE = {name: p.what for name, p in PARAMETERS.items()}

_NOT_OPTIONS = ("restitution", "C_p", "k", "eps_p", "seed", "output_dt", "progress")
_MAX_NFEV = {1: 40, 2: 30}


@dataclass(frozen=True, eq=False)
class Calibration:
    """The result of `calibrate`.

    Attributes
    ----------
    parameters : dict
        Each fitted name → ``value``, ``std`` (one standard deviation; inf when the
        traces do not constrain it), ``start``, ``bounds``, ``bound_hit`` (None,
        "lower" or "upper"), ``constrained`` (bool) and ``reason`` (why not).
    fixed : dict
        The model parameters not fitted, at the values used.
    status, message : str
        One of `STATUSES` and what it means here.
    impact : str
        The impact model calibrated (paper 001, Table 2).
    structure : Structure
        The column with the start values.
    nuisance : dict
        Per trace label: ``source``, ``kind`` ("free" or "table"), ``t_offset`` (s;
        the trace's first time for table motion), ``theta0`` (rad; None with table
        motion), ``theta_bias`` (rad), ``sensor_bias`` (channel → m/s²), ``window``
        (trace times whose time histories were fitted, s), ``large_half_cycles``
        (start, end and number of the large half-cycles), ``channels`` and
        ``impacts`` (per impact in the window: ``index``, ``t``, ``corner``, ``r`` =
        corner mean + deviation, ``deviation``).
    metrics : dict
        ``before`` (start values) and ``after`` (the calibrated model: corner means,
        no deviations), over the trace's large half-cycles ("window") and the whole
        trace ("trace"); ``fit`` (with the fitted deviations) over the window fitted
        ("window"): per trace label, per span, per channel a
        `multimass.analysis.trace_metrics.ChannelMetrics`.
    features : dict
        ``before`` / ``after`` / ``fit``: per trace label the peak and impact-time
        errors over the large half-cycles (the window's for ``fit``).
    residuals : dict
        Per "label:channel": ``scale`` (residual RMS, SI), ``rho1`` (lag-1
        autocorrelation of the residuals), ``inflation`` (applied to the covariance),
        ``misfit`` (the residual mean square over the most a fit that reproduces the
        trace leaves, `_calibration_result.misfit`; above 1 in any channel no fitted
        parameter is estimated; None: an accelerometer not tested).
    covariance : pandas.DataFrame
        Of the fitted parameters, in their fitted units (log for C_p and ζ).
    stages : dict
        Per stage: least-squares status, evaluations, cost, simulations and seconds;
        with table motion ``input``, the check of its noise
        (`multimass.identify._calibration_input.input_check`).
    views : dict
        Per trace label: ``before``, ``after``, ``fit`` simulations recorded at the
        trace's times (`Response`, on the trace's clock: plot with t_offset = 0).
    traces : tuple
        The `Case` of each trace (its `Trace`, segments and window).
    n_simulations : int
    wall_time_s : float
    warnings : tuple of str
    specimen_file : str or None
        The specimen's TOML file when it was given as one (None: a bundled specimen).
    provenance : dict
        Every model parameter (``r_er``, ``r_el``, ``cp``, ``zeta1``, ``zeta2``), the
        traces' nuisance parameters and the structure → ``status``: ``given`` (by the
        user), ``estimated`` (``value``, ``std``, 95 % ``interval``), ``ill-posed``
        (with the ``reason``: its std beyond `LIMITS`, on a bound, correlated beyond
        0.98 with the named parameter), ``fixed by the specimen file`` (with a
        ``note`` why) or ``not used`` (C_p of CIM); see
        `multimass.identify._parameter_status`.
    """

    parameters: dict
    fixed: dict
    status: str
    message: str
    impact: str
    structure: Structure
    nuisance: dict
    metrics: dict
    features: dict
    residuals: dict
    covariance: pd.DataFrame
    stages: dict
    views: dict = field(repr=False, default_factory=dict)
    traces: tuple = field(repr=False, default=())
    n_simulations: int = 0
    wall_time_s: float = 0.0
    warnings: tuple = ()
    specimen_file: str | None = None
    provenance: dict = field(default_factory=dict)

    @property
    def values(self) -> dict:
        """Every model parameter's value: the fitted ones and the fixed ones."""
        return {**self.fixed, **{k: p["value"] for k, p in self.parameters.items()}}

    def to_pandas(self) -> pd.DataFrame:
        """One row per fitted parameter: value, std, start, bounds, flags."""
        rows = [
            {"parameter": k, **{f: p[f] for f in ("value", "std", "start")},
             "low": p["bounds"][0], "high": p["bounds"][1], "bound_hit": p["bound_hit"],
             "constrained": p["constrained"], "reason": p["reason"]}
            for k, p in self.parameters.items()
        ]  # fmt: skip
        return pd.DataFrame(rows).set_index("parameter")

    def summary(self) -> dict:
        """JSON-ready: parameters, status, nuisance, metrics, features, residuals, stages."""
        metrics = {
            which: {
                label: {span: {ch: m.to_dict() for ch, m in chans.items()} for span, chans in spans.items()}
                for label, spans in per.items()
            }
            for which, per in self.metrics.items()
        }  # fmt: skip
        return json_ready(
            {
                "specimen": self.structure.name,
                "impact": self.impact,
                "status": self.status,
                "message": self.message,
                "parameters": self.parameters,
                "fixed": self.fixed,
                "nuisance": self.nuisance,
                "metrics": metrics,
                "features": self.features,
                "residuals": self.residuals,
                "covariance": {
                    "names": list(self.covariance.index),
                    "values": self.covariance.to_numpy().tolist(),
                },
                "stages": self.stages,
                "n_simulations": self.n_simulations,
                "wall_time_s": self.wall_time_s,
                "provenance": self.provenance,
                "warnings": list(self.warnings),
            }
        )

    def to_json(self, **kw) -> str:
        """`summary` as JSON text (``json.dumps`` keywords pass through; NaN/inf as null)."""
        return json.dumps(self.summary(), **({"indent": 1} | kw))

    def specimen(self):
        """The column specimen with the fitted restitution means and damping ratios."""
        vals, spec = self.values, self.structure.specimen
        return replace(
            spec, r_right=vals["r_er"], r_left=vals["r_el"],
            zeta_1=vals["zeta1"], zeta_2=vals["zeta2"],
        )  # fmt: skip

    def specimen_text(self, name: str | None = None) -> str:
        """The specimen's TOML file with the fitted ``[restitution]`` (means, and σ_r as the
        spread of the fitted impacts) and ``[damping]`` tables, whichever were fitted
        (C_p, which a specimen file does not hold, in their comment); loads back with
        `multimass.specimens.load`."""
        from multimass.specimens.toml_text import specimen_text

        vals, spec = self.values, self.structure.specimen
        sources = ", ".join(n["source"] for n in self.nuisance.values())
        cp = f"; C_p = {vals['cp']:.6g} kg m/rad/s" if self.impact != "CIM" else ""
        note = f"calibrated ({self.impact}{cp}; status {self.status}) against {sources}"
        given = [n for n, p in self.provenance.items() if p["status"] == "given"]
        est = [n for n, p in self.provenance.items() if p["status"] == "estimated"]
        ill = [n for n, p in self.provenance.items() if p["status"] == "ill-posed"]
        spec_fixed = [
            n for n, p in self.provenance.items()
            if p["status"] == "fixed by the specimen file" and n != "structure"
        ]  # fmt: skip
        for label, names in (
            ("given", given), ("estimated", est),
            ("ill-posed (best fits, not estimates)", ill), ("fixed", spec_fixed),
        ):  # fmt: skip
            if names:
                note += f"; {label}: {', '.join(names)}"
        tables, comments = {}, {}
        if {"r_er", "r_el"} & set(self.parameters):
            n = sum(len(v["impacts"]) for v in self.nuisance.values())
            sigma = self._sigma_r()
            tables["restitution"] = {
                "mean_right": round(vals["r_er"], 6),
                "mean_left": round(vals["r_el"], 6),
                "sigma": round(spec.sigma_r if sigma is None else sigma, 6),
            }
            comments["restitution"] = {
                "mean_right": "r_er: mean coefficient of impacts on the right corner",
                "mean_left": "r_el: mean coefficient of impacts on the left corner",
                "sigma": (
                    f"sigma_r: spread of the {n} impacts fitted" if sigma is not None else
                    f"sigma_r NOT ESTIMATED ({n} impact{'s' if n != 1 else ''} fitted; σ_r "
                    f"needs at least {MIN_SIGMA_IMPACTS}): the specimen's value"
                ),
            }  # fmt: skip
        if {"zeta1", "zeta2"} & set(self.parameters):
            tables["damping"] = {
                "zeta_1": float(f"{vals['zeta1']:.6g}"),
                "zeta_2": float(f"{vals['zeta2']:.6g}"),
            }
            comments["damping"] = {
                "zeta_1": "fraction of critical, full-contact mode 1",
                "zeta_2": "fraction of critical, full-contact mode 2",
            }
        for table, keys in (
            ("restitution", {"mean_right": "r_er", "mean_left": "r_el"}),
            ("damping", {"zeta_1": "zeta1", "zeta_2": "zeta2"}),
        ):  # an ill-posed value is written, and said to be what the traces do not fix
            for key, par in keys.items():
                p = self.provenance.get(par, {})
                if table in comments and p.get("status") == "ill-posed" and p.get("interval"):
                    lo, hi = p["interval"]
                    comments[table][key] += (
                        f"; ILL-POSED, not fixed by the traces: anywhere in {lo:.4g} … {hi:.4g}"
                        " (best fit, not an estimate)"
                    )
        return specimen_text(
            spec, tables, note=note, comments=comments, name=name, path=self.specimen_file
        )

    def _sigma_r(self) -> float | None:
        """Pooled spread of the fitted per-impact values about their corner means; None
        (not estimated) from fewer than `MIN_SIGMA_IMPACTS` impacts, as `restitution`
        says."""
        dev = [i["deviation"] for n in self.nuisance.values() for i in n["impacts"]]
        if len(dev) < MIN_SIGMA_IMPACTS:
            return None
        return float(math.sqrt(sum(d * d for d in dev) / max(len(dev) - 2, 1)))

    def write_specimen(self, path, name: str | None = None):
        """Write `specimen_text` to `path` (a ``.toml`` file); return the path."""
        from pathlib import Path

        out = Path(path)
        if out.suffix.lower() != ".toml":
            raise InputError(f"`path` = {str(out)!r}: give a file name ending in .toml")
        out.write_text(self.specimen_text(name), encoding="utf-8")
        return out


# ---------------------------------------------------------------------------- the function
def _options(options: dict) -> dict:
    for key in _NOT_OPTIONS:
        if key in options:
            raise InputError(
                f"`{key}` is set by calibrate (the fitted values, the recording rate, its "
                "own progress); remove it"
            )
    if (
        options.get("backend", "compiled") != "compiled"
        or options.get("integrator", "solve_ivp") != "solve_ivp"
    ):
        raise InputError(
            "calibrate runs hundreds of simulations with the compiled backend; remove "
            "`backend` / `integrator`"
        )
    return options


def calibrate(
    traces,
    structure=None,
    impact: str = "DD2",
    fit=None,
    *,
    given=None,
    start=None,
    bounds=None,
    channels=None,
    per_impact: bool = True,
    theta_min: float = THETA_MIN,
    history: int = HISTORY,
    oversample: int = 10,
    progress: bool | None = None,
    **options,
) -> Calibration:
    """Fit a column model's restitution means, C_p and damping to recorded traces.

    Parameters
    ----------
    traces : Trace, path, or a sequence of them
        Free-vibration tests (no ``ag``: released at rest) and tests with table
        motion (``ag``), with θ and the accelerometers; fitted jointly.
    structure : Structure, specimen or str, optional
        The column tested; default the traces' ``# specimen:`` line.
    impact : str, optional
        The impact model: "CIM", "DD1" … "DD5" or "DD" (paper 001 Table 2; default
        "DD2"). Its restitution is the fitted corner means (with per-impact
        deviations in the window, see `per_impact`).
    fit : sequence of str or str, optional
        Some of `FITTABLE`: "r_er", "r_el", "cp", "zeta1", "zeta2" (or a comma list).
        "cp" needs a Dirac-delta model. Default: every parameter not `given` (C_p not
        for CIM), less those the traces cannot show (a corner mean without an impact on
        its corner, C_p without an impact: the specimen's value, said so in
        `provenance`); named explicitly, the others are fixed at the specimen's values.
    given : mapping, optional
        Parameters the user knows (name → value): used as they are, not fitted, and
        reported as given.
    start : mapping, optional
        Start values (default: the specimen's means and damping, Table 2's C_p).
    bounds : mapping, optional
        name → (low, high), replacing the defaults of `PARAMETERS`.
    channels : sequence of str, optional
        The acceleration channels to fit (θ always is); default every sensor the
        specimen names, which the traces must then have.
    per_impact : bool, optional
        Fit each large impact's deviation from its corner mean as a random effect
        (default; see the module docstring). False fits the means alone.
    theta_min : float, optional
        Half-cycles with peaks at least this large (rad) are the *large* ones whose
        peak ratios give the restitution means (paper 001 Section 4.3: 0.01).
    history : int, optional
        The time histories of each trace's first large half-cycles are fitted: 5, then
        the window grows while the model still follows the test, up to `history`
        half-cycles (default 9; see the module docstring).
    oversample : int, optional
        The simulation is recorded at this multiple of the trace's rate before the
        anti-alias filter (default 10: 2 kHz for 200 Hz traces; the recorded
        accelerations of S1–S3 then differ from a 8 kHz recording by at most 0.86 % of
        their peak, S1's a_A1, 0.06 % elsewhere; at 5× by up to 5 %).
    progress : bool, optional
        Show a progress bar over the simulations (default: when it takes long).
    **options
        Options of `multimass.simulate` for every run (``rtol``, ``thetadot_min`` ...).

    Returns
    -------
    Calibration

    Raises
    ------
    InputError
        Naming the field: an unknown fit name, "cp" with CIM, start or bounds out of
        range, a trace without θ, without the sensors the specimen names, with NaN
        samples (`read_trace`), sampled too slowly to segment θ, an ``ag`` in an
        implausible unit, or without rocking; a corner mean asked without an impact on
        its corner between two half-cycles ≥ `theta_min`, "cp" without an impact, more
        damping ratios than modes below the traces' anti-alias passbands.
    """
    wall = time.perf_counter()
    st, loaded = structure_of(traces, structure)
    impact = model_of(impact)
    given = checked_given(given, impact, st.specimen)
    if fit is None and not default_fit(impact, given):
        raise InputError(
            f"`given` gives every parameter ({', '.join(given)}): nothing is left to "
            "calibrate; give fewer"
        )
    pset = parameter_set(fit, impact, st.specimen, start, bounds, given)
    options = _options(dict(options))
    oversample = v.integer("oversample", oversample, low=4, high=200)
    theta_min = v.positive("theta_min", theta_min, "rad")
    history = v.integer("history", history, low=2, high=200)
    if not isinstance(per_impact, bool):
        raise InputError(f"`per_impact` = {per_impact!r}: expected True or False")
    if progress is not None and not isinstance(progress, bool):
        raise InputError(f"`progress` = {progress!r}: expected True, False or None")
    dropped = {}
    if fit is None:  # every parameter not given that the traces can show
        cs = cases(loaded, st, (), channels, theta_min)
        names, dropped = showable(cs, pset.fit, st, theta_min)
        if not names:
            raise InputError(
                "the traces show none of the parameters not given ("
                + "; ".join(f"{n}: {why}" for n, why in dropped.items())
                + "); give a test that rocks longer or lower theta_min (--theta-min)"
            )
        pset = parameter_set(names, impact, st.specimen, start, bounds, given)
    else:
        cs = cases(loaded, st, pset.fit, channels, theta_min)
    sim = Simulator(st, impact, oversample, options)
    sigma_r = float(st.specimen.sigma_r) if st.specimen.sigma_r > 0 else 0.025
    p0 = Problem(sim, pset, [c.upto(history) for c in cs], 2, False, sigma_r)
    before = result.views(sim, p0, p0.x0(), cs, st, full=True)
    n_est = sum(  # simulations: the scan, stage 1, the seeds, stage 2's Jacobians
        13 + 8 * (len(pset.fit) + 3) + 12 * min(c.n_impacts, history)
        + 12 * (len(pset.fit) + 2 + min(c.n_impacts, history))
        # with table motion, `input_check`: its draws and at most a refit's Jacobians
        + (0 if c.free else DRAWS + INPUT_NFEV * (len(pset.fit) + 2 + min(c.n_impacts, history)))
        for c in cs
    )  # fmt: skip
    show = progress if progress is not None else n_est * sim.seconds / max(sim.n_runs, 1) > 3.0
    with Progress(n_est, f"calibrate {st.name} ({impact})", show=show, unit="runs") as bar:
        sim.listener = bar.update
        try:
            cs = align_releases(sim, pset, cs)
            s1 = stage1(sim, pset, cs, sigma_r, _MAX_NFEV[1])
            s2 = stage2(sim, pset, cs, per_impact, sigma_r, s1.values, _MAX_NFEV[2], history)
            checked = input_check(sim, pset, s2.problem, s2.x, result.misfit)
        except (SolverError, TrialRejected) as err:
            fields = result.failed(st, impact, pset, cs, before, str(err), sim, wall)
            fields["provenance"] = result.provenance(
                fields, impact, given, dropped, st, pset.bounds
            )
            return Calibration(**fields, specimen_file=_specimen_file(structure, loaded))
        bar.update(n_est)
    fields = result.assemble(st, impact, pset, cs, before, (s1, s2), sim, wall, checked)
    fields["provenance"] = result.provenance(fields, impact, given, dropped, st, pset.bounds)
    return Calibration(**fields, specimen_file=_specimen_file(structure, loaded))


def _specimen_file(structure, traces) -> str | None:
    """The specimen's TOML file, if it was named by a path (the argument or the traces'
    ``# specimen:`` line), for `Calibration.specimen_text`."""
    from pathlib import Path

    name = structure if structure is not None else traces[0].specimen
    if isinstance(name, (str, os.PathLike)) and Path(name).suffix.lower() == ".toml":
        if Path(name).is_file():
            return str(Path(name).resolve())
    return None
