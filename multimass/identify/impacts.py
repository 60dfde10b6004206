"""Empirical coefficients of restitution from a recorded trace.

Paper 001 (Section 4.3) defines its CIM, DD1, DD3 and DD4 models (Table 2) with
impact-specific coefficients r_e estimated from the tests, and the per-corner means
r̄_er, r̄_el (with their spread σ_r) for half-cycles below 0.01 rad. `restitution`
gives both estimates of every impact of a trace:

**The energy estimate (the paper's).** During large rocking the total energy is
dominated by the gravitational potential (paper 001, Section 4.3). With
V(θ) = g (h (cos θ − 1) + ℓ sin θ) the potential of the undeformed column rocking by
θ about a pivot (paper 001, Eq 5's gravity term: h = Σ m_i H_i, ℓ = B m_t, for the
side of θ; `multimass.model.kinematics.gravitational_energy`), energy is conserved over a
half-cycle, so ½ J θ̇₋² = V(θ_k) before impact k and ½ J θ̇₊² = V(θ_{k+1}) after it;
with θ̇₊ = r θ̇₋,

    r_energy,k = sqrt( V(θ_{k+1}) / V(θ_k) ),

θ_k and θ_{k+1} the peaks of the half-cycles before and after the impact. Viscous
damping and the energy sent into vibration at the impact lower θ_{k+1} beyond the
restitution alone, so this estimate is biased low (by 0.002–0.012 on average and up
to 0.036 on single impacts on noiseless synthetic S1–S3 traces).

**The model-based estimate (`r`).** The impact model is simulated from the release
(compiled path) and recorded as the trace was — at 10 × its rate through its
anti-alias filter (`_calibration_model.Simulator`, shared with `calibrate`) — and the
coefficients are fitted so that θ and the accelerations (the channels of the
specimen's sensors the trace has; each weighted by its residual RMS, a sensor's bias
taken out as its mean) match the trace (`multimass.identify._restitution_fit`). The
model's parameters the user did not give — C_p of the Dirac-delta force (paper 001
Eq 15; not for CIM, which has none) and the Rayleigh damping ratios ζ1, ζ2 — are
unknowns too, estimated from the same trace; neither Table 2's C_p nor the specimen
file's damping stands in for them (they only start the search):

1. *Alignment*: the release time scanned on θ in steps of 10 ms (θ0 held at the first
   peak), then the release angle θ0 and the clock offset by least squares on the
   samples before the first impact (no restitution acts there), θ first, then every
   channel: the accelerations' step at the release fixes the clock (to 0.1 ms; θ alone
   left it 4 ms off on S2). (From the first guess alone, where θ leaves its held
   value, a noisy hold sent the fit 0.1 s early from an angle 0.025 rad too large.)
2. *Impact by impact*: impact k is matched to a simulated impact (nearest in time, on
   its corner); its r_k is scanned alone in steps of 0.015 within 0.075 of its corner's
   mean so far, on every channel from impact k to just past the next impact (whose
   time r_k sets); then r_{k−1} and r_k are fitted together by least squares
   (`_calibration_fit.solve`) from impact k − 1 to the next impact (for CIM just past
   it; for the Dirac-delta models up to 65 ms before it, where r_{k+1}'s force acts),
   with θ0, the clock offset and the θ bias while the window starts at the release.
   A window whose fit stays above the noise is scanned again in steps of 0.002.
   *The model's parameters* come first with the first impact: C_p is scanned on its
   spike (0.1 s after it, r_0 held: factors 0.5–2 of the start, then steps of 6 %),
   then C_p, ζ1 and ζ2 are fitted with r_0 over its half-cycle; after the first 4
   impacts, least squares of C_p, ζ, their r, θ0, the clock offset and the θ bias
   together, and those 4 impacts are fitted once more one by one with C_p and ζ held.
   (Held at Table 2's C_p, a trace made with 1.4 × it gave r up to 0.10 off, 200 of
   their own std; least squares alone from there stopped at C_p 2345 for 2450 with r
   0.03–0.13 off: each r has its own valley, which the scans find once C_p is near.)
3. *Everything together*: least squares on every fitted r, C_p, ζ1, ζ2, θ0, the clock
   offset and the θ bias over the whole span — the windows held the earlier values,
   and a clock 0.09 ms off shifted later coefficients by up to 0.006 (S2).

The fit goes two impacts past the last estimated one, so that the last ones are set
by the time of the impact after them. Each r_k is the coefficient the *chosen impact
model* needs to reproduce the test; CIM and the Dirac-delta models (with their C_p)
need different values for the same test.

Why not θ alone: at 2 % noise θ fixes a single r to 0.01–0.02 where the half-cycles
are 0.01–0.025 rad (the bound from the Jacobian of the whole trace, S2 DD2), the
accelerations to below 0.001 — the Dirac-delta force scales with E_ini (1 − r²)
(paper 001, Eq 14), which swings with r near 1 (S2's right corner, r̄ = 0.98), and
under CIM the accelerations' step at the next impact times it. Fitted impact by
impact on θ alone, each r_k also made up for r_{k−1}'s error: the errors alternated
in sign and grew (0.016–0.019 on S2 at 0.025–0.05 rad, 0.033 below; the run was not
recorded through the anti-alias filter, and its clock was 4 ms off).

**Standard errors (`r_std`).** From the Jacobian of the last fit
(`_calibration_stats.covariance`: each channel whitened by its residual RMS and
inflated by its residuals' lag-1 autocorrelation; every unknown free, so that the
r_std are marginal — they carry C_p's and ζ's uncertainty), with the model's error of
C_p and ζ (`_calibration_stats.MODEL_REL_FLOOR`, 1.5 % of each, which the noise's
covariance does not hold) carried into each r through its regression on them
(`_restitution_fit.consider_covariance`; the corner means' std take the same
covariance: on synthetic S2, r moves by 0.02–0.18 per unit of log C_p, 3e-4–2.6e-3
for 1.5 %, where the noise's covariance gave 4e-5–4e-4 and the errors were up to
0.0017; late half-cycles of 0.012–0.017 rad moved by 1.4–3 per unit of log ζ1, their
r_std above 0.02: not estimated), plus 5e-4 in quadrature (the fit's
error beyond the noise's — the clock and θ0 trade off with the coefficients, the runs
are recorded at 10 × the rate where the synthetic traces are at 40 × — measured up to
0.0013 where the noise alone gives 1e-5–5e-4), plus 0.002 where the simulation
*bounces* after the impact (lands in full contact before the next impact: CIM at
small half-cycles, whose misfit then has valleys ±0.002 wide in r; errors up to
0.0057, RMS 0.0018).

**Measured** (`benchmarks/identify_restitution.py`: synthetic S1, S2, S3
free-vibration traces, 0.11 rad release, 10 s, DD2 and CIM, noise 2 % of peak,
200 Hz, seeds 1–3; the model fitted is the trace's family, C_p and damping those of
the specimen file and Table 2 and given): for every impact whose half-cycles are both
≥ 0.01 rad (8–17 per trace) the model-based r is within 0.0057 of the truth (0.0013
for the Dirac-delta traces; 0.0057 at 0.03 rad where S2's CIM run bounces), the
corner means within 0.0009 of the mean truth of the impacts they average, and 207 of
208 estimated impacts within 2.5 r_std. The energy estimate is off by −0.007 … −0.039
on average and up to 0.23 on single impacts.

*Nothing given* (C_p, ζ1, ζ2 estimated; the same benchmark with ``--cp-factor``,
``--zeta-factors``, ``--fs``, ``--t-end``, ``--theta0``: nine synthetic DD2 traces of
S1, S2, S3 with C_p 0.6 and 1.4 × Table 2's 1750, four of them with ζ1, ζ2 0.5–1.5 ×
the specimen's, 4–6 s, 200–1000 Hz, noise 1–5 %, release 0.06–0.15 rad): all 73
estimated impacts within 0.0032 of the truth (within 7e-4 at noise ≤ 3 %), 72 within
1.96 r_std, C_p within 2.5 % (0.7 % at noise ≤ 3 %). Held at Table 2's C_p the same
fit was off by up to 0.10 on S1 at 1.4 × (14 % within 0.015, r_std covering 14 %). Run
time (CPU of the process, 5 s traces at 200 Hz): 10.3–10.8 s with nothing given
against 5.3–7.1 s with C_p and ζ given (the same fit, the specimen's values given); 47
s for S2 at 1000 Hz. θ alone (S1 DD2, 5 s, C_p and ζ given): errors up to 0.003 for
half-cycles ≥ 0.025 rad and 0.026 at 0.012 rad, with r_std 0.002–0.017 that covers
them; nothing given (3 s), the damping is ill-posed (ζ2's relative std 6.7) and C_p
2513 ± 356 for 2450, with every r within its r_std.

**What the result says** (`RestitutionEstimate.parameters`, in the JSON, the text and
the fragment's comments): each of C_p, ζ1, ζ2 is *given* (by the user: ``C_p=``,
``zeta1=``, ``zeta2=``; ``--cp``, ``--zeta1``, ``--zeta2``), *estimated* (value, std,
95 % interval; C_p's and ζ's std with `_calibration_stats.MODEL_REL_FLOOR`, 1.5 %, for
the model's error, measured) or *ill-posed* (std beyond 25 %, correlated beyond 0.98
with a named unknown, a direction along which the cost is rough — `slice_probe`'s
rise at ± max(3 std, 1 %) off the Jacobian's by more than 4× either way, one of nearby
minima — or a damping ratio ζ_j whose mode j the trace does not show below its
anti-alias passband, `_calibration_setup.unseen_damping`: S2 at 200 Hz shows its 20.5 Hz
mode alone: then no std and no 95 % interval, but the range its fit was allowed to explore, ``interval_kind``
"explored range", its value the best fit, not an estimate); θ0, the clock offset,
the θ bias and each accelerometer's bias are estimated (θ0's, the clock's and the θ
bias's std with the model parameters' floor carried through the joint covariance:
`_restitution_report.consider_std`; θ0 ill-posed where the cost is rough along it);
the column's geometry, masses and stiffnesses are *fixed by the specimen file*. The
status is ``ill-posed`` naming what the trace does not fix, else ``estimated``. The written specimen takes the
estimated damping (its ``[damping]``), and names C_p in its comment (a specimen file
holds no C_p).

**Does the fit reproduce the trace?** The covariance is a curvature at the point the
least squares stopped; where that point is not the trace's (a valley of C_p 10 % off
whose r make up for it), the r came out 0.02–0.04 off with r_std 6e-4, and nothing in
the covariance says so. Each impact is therefore tested over the two half-cycles that
set its r (`_restitution_fit.misfit_test`, probability 1e-3 of failing a fit that
reproduces the trace): θ's residual mean square against the trace's noise variance
(χ²), each accelerometer's against its own before the first impact (F). An impact
that fails is *not estimated* (``misfit`` above 1, the channel named, a warning); the
whole span fitted failing makes every estimated parameter *ill-posed*, saying why.
With table motion the model follows the recorded ``ag``, noise and all: the fitted model
is run again with ``ag`` re-noised by the noise it holds (five draws,
`multimass.identify._restitution_input`, calibrate's check), and an impact whose test
most draws fail is not estimated, the whole span's making C_p, ζ and the θ bias
ill-posed; the status says so, and what a cleaner record or a free-vibration test
would fix (on the coverage benchmark's 45 table-motion traces with an impact fitted it
decided every one: their estimates had held the truth 10 times in 32).

Impacts between half-cycles whose peaks are both ≥ `theta_min` (0.01 rad, the
paper's rule), whose r the trace fixes (r_std ≤ 0.02) and whose half-cycles the fit
reproduces are *estimated*; the per-corner means r̄_er, r̄_el and σ_r are taken over
them, σ_r with its 95 % interval (`RestitutionEstimate.sigma_r_interval`: χ² of their
scatter, their r_std's share removed). Smaller ones are fitted
while the simulation must stay on the trace, and reported, but the specimen fragment
gives them the corner means, as the paper did. A corner without an estimated impact has
no mean, and fewer than three estimated impacts no σ_r: the result says *not estimated*
(None, and why, in `RestitutionEstimate.not_estimated`), and the fragment says so
instead of passing the specimen's value off as measured.

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

from multimass.impact_models import CornerRestitution

from .. import validation as v
from ..analysis.trace_metrics import channel_columns
from ..errors import InputError
from ..inputs.traces import Trace
from ..model import kinematics
from ..model.structure import Structure, from_specimen
from ..progress import Progress
from ..result import json_ready
from . import _restitution_fit as fitting
from . import _restitution_input as table_noise
from . import _restitution_report as report
from ._calibration_model import TrialRejected
from ._calibration_params import PARAMETERS
from ._calibration_stats import LIMITS
from ._parameter_status import EXPLORED, ILL_POSED, Z95, overall
from ._trace_checks import check_ag, check_frozen, check_theta, no_rocking
from .segments import THETA_MIN, Segments, require_trace, segment_trace

__all__ = [
    "RestitutionEstimate", "restitution", "energy_restitution", "IMPACT_DEFAULT",
    "MIN_SIGMA_IMPACTS",
]  # fmt: skip

#: The impact model fitted unless another is named (paper 001, Table 2: DD1's family).
IMPACT_DEFAULT = "DD"
#: The fewest estimated impacts a spread σ_r is estimated from (two corner means take two
#: degrees of freedom: fewer leaves σ_r without one, or with one from two impacts).
MIN_SIGMA_IMPACTS = 3
# the [restitution] keys of a specimen file → the estimate's attribute they hold
_TABLE_KEYS = {"mean_right": "r_mean_right", "mean_left": "r_mean_left", "sigma": "sigma_r"}


@dataclass(frozen=True, eq=False)
class RestitutionEstimate:
    """The coefficients of restitution identified from a trace (`restitution`).

    Attributes
    ----------
    impacts : pandas.DataFrame
        One row per impact found: ``t`` (trace time, s), ``corner`` ("right" or
        "left": the corner it lands on), ``r`` (the model-based estimate, the best
        one; the energy estimate where the model was not fitted), ``r_energy`` (the
        paper's energy estimate), ``theta_before``, ``theta_after`` (the peaks around
        it, rad), ``estimated`` (both peaks ≥ `theta_min` and r fitted to a standard
        error ≤ 0.02), ``model_impact`` (the index of the simulated impact it matched,
        −1 if none), ``rms`` (the θ misfit over the half-cycle after it, rad),
        ``misfit`` (over the two half-cycles after it, which set its r, the worst
        channel's residual mean square over the most the noise leaves:
        `_restitution_fit.misfit_test`, θ against the trace's noise, each
        accelerometer against its residuals before the first impact; above 1 the fit
        does not reproduce the trace there, and the impact is not estimated),
        ``misfit_channel`` (that worst channel),
        ``r_std`` (the standard error of ``r``: see the module docstring).
    r_mean_right, r_mean_left : float or None
        Means of `r` over the estimated impacts on each corner (paper 001's r̄_er,
        r̄_el), each impact weighted by 1 / (σ_r² + r_std²); None where a corner has no
        estimated impact (`not_estimated` says why; `values_used` gives the specimen's).
    sigma_r : float or None
        Pooled standard deviation of the estimated `r` about their corner means; None
        from fewer than `MIN_SIGMA_IMPACTS` estimated impacts.
    energy_means : dict
        ``r_mean_right``, ``r_mean_left``, ``sigma_r`` of `r_energy`, over the same
        impacts (None where those are).
    alignment : dict
        ``t_offset`` (s: trace time of the release), ``theta_bias`` (rad), ``theta0``
        (rad, the fitted release angle; 0 for table motion).
    structure : Structure
    impact : str
        The impact model the model-based estimates are for.
    theta_min : float
    segments : Segments
    response : Response
        The simulation with the estimated impacts' r and the corner means for the
        others, as the specimen fragment has them (on the model's clock).
    warnings : tuple of str
    not_estimated : dict
        ``r_mean_right``, ``r_mean_left``, ``sigma_r`` → why the trace did not estimate
        it (absent when it did).
    parameters : dict
        Every other parameter of the fit → ``status`` (``given`` by the user,
        ``estimated`` from the trace, ``ill-posed`` where the trace does not fix it,
        ``fixed by the specimen file``, ``not used`` by the model), ``value``,
        ``std``, ``interval`` (95 %), ``what`` and the ``reason`` of an ill-posed one:
        ``cp``, ``zeta1``, ``zeta2``, ``theta0``, ``t_offset``, ``theta_bias``,
        ``sensor_bias`` and ``structure`` (`multimass.identify._parameter_status`).
    status, message : str
        ``estimated``, or ``ill-posed`` with the parameters the trace does not fix.
    r_mean_std : dict
        ``right``, ``left`` → ``std`` of the corner mean as the mean of the impacts it
        averages (from the fit's covariance, C_p's and ζ's uncertainty in it),
        ``interval`` (95 %), ``n``; None for a corner without an estimated impact.
    sigma_r_interval : list or None
        The 95 % interval [low, high] of the spread σ_r of the coefficients themselves
        (χ² of the estimated impacts' scatter, their r_std's share removed:
        `_restitution_report.sigma_interval`); None where `sigma_r` is.
    input_check : dict or None
        With table motion, the check of its noise (`_restitution_input.input_check`:
        the fitted model run with the recorded ``ag`` re-noised, through the fit's
        tests): ``noise``, the draws per impact (trace impact index) and over the whole
        span, what they decided, ``seconds``, ``simulations``; None for free vibration.
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
    not_estimated: dict = field(default_factory=dict)

    def values_used(self) -> dict:
        """``r_mean_right``, ``r_mean_left``, ``sigma_r`` as the fragment, `per_impact`
        and `response` use them: the estimates, the specimen's values where not
        estimated (`not_estimated`)."""
        spec = self.structure.specimen
        own = {"r_mean_right": spec.r_right, "r_mean_left": spec.r_left, "sigma_r": spec.sigma_r}
        got = {"r_mean_right": self.r_mean_right, "r_mean_left": self.r_mean_left,
               "sigma_r": self.sigma_r}  # fmt: skip
        return {k: float(own[k] if got[k] is None else got[k]) for k in own}

    parameters: dict = field(default_factory=dict)
    status: str = "estimated"
    message: str = ""
    r_mean_std: dict = field(default_factory=dict)
    sigma_r_interval: list | None = None
    input_check: dict | None = None

    def model_values(self) -> dict:
        """The values of C_p and the damping ratios the coefficients are for (given,
        estimated or the specimen's), for `multimass.simulate` with them."""
        return {
            n: p["value"] for n, p in self.parameters.items()
            if n in ("cp", "zeta1", "zeta2") and p["value"] is not None
        }  # fmt: skip

    def per_impact(self) -> list[float]:
        """The coefficients in the simulation's impact order, for `EmpiricalRestitution`:
        the estimated ones, the corner means for the rest, up to the last estimated one."""
        est = self.impacts[self.impacts["estimated"]]
        if est.empty:
            return []
        k_max = int(est["model_impact"].max())
        used = self.values_used()
        means = {"right": used["r_mean_right"], "left": used["r_mean_left"]}
        corner_of = dict(zip(self.impacts["model_impact"], self.impacts["corner"]))
        fitted = dict(zip(est["model_impact"], est["r"]))
        out = []
        for k in range(k_max + 1):
            corner = corner_of.get(k)
            out.append(float(fitted.get(k, means.get(corner, 0.5 * sum(means.values())))))
        return out

    def table(self) -> dict:
        """The specimen's ``[restitution]`` table with the identified values (the
        specimen's where not estimated: `comments` says which)."""
        used = self.values_used()
        return {
            "mean_right": round(used["r_mean_right"], 4),
            "mean_left": round(used["r_mean_left"], 4),
            "sigma": round(used["sigma_r"], 4),
            "empirical": [round(r, 4) for r in self.per_impact()],
        }

    def comments(self) -> dict:
        """Key of `table` → a comment: where its value came from."""
        out = {"empirical": "estimated impacts' r, the corner means between them"}
        for key, name in _TABLE_KEYS.items():
            why = self.not_estimated.get(name)
            out[key] = f"NOT ESTIMATED ({why}): the specimen's value" if why else "estimated"
        if self.sigma_r_interval is not None and "sigma_r" not in self.not_estimated:
            lo, hi = self.sigma_r_interval
            out["sigma"] = f"estimated (95 %: {lo:.4f} … {hi:.4f})"
        return out

    def fragment(self) -> str:
        """A specimen fragment: the ``[restitution]`` TOML table, with a comment; a value
        the trace did not estimate is a comment line that says why."""
        from multimass.specimens.toml_text import format_table

        head = (
            f"# Restitution identified from {self.segments.trace.source} for impact model "
            f"{self.impact}\n# (multimass.identify.restitution; `empirical` in impact order, "
            "then the corner means)\n"
        )
        skip = {k for k, name in _TABLE_KEYS.items() if name in self.not_estimated}
        table = {k: v for k, v in self.table().items() if k not in skip}
        text = self._parameter_comments() + format_table("restitution", table, self.comments())
        for key in sorted(skip):
            text += (
                f"# {key}: not estimated ({self.not_estimated[_TABLE_KEYS[key]]}); "
                "keep the specimen's value or give a test that estimates it\n"
            )
        return head + text

    def _parameter_comments(self) -> str:
        """Comment lines: the status, and each parameter's (`parameters`) but the
        structure's fields."""
        from ._parameter_status import lines

        shown = {k: p for k, p in self.parameters.items() if k not in ("structure", "sensor_bias")}
        body = [f"# status: {self.status}" + (f" ({self.message})" if self.message else "")]
        body += [f"#   {line}" for line in lines(shown)]
        body.append("#   structure  fixed by the specimen file (geometry, masses, stiffnesses)")
        return "\n".join(body) + "\n"

    def specimen_text(self, name: str | None = None, path=None) -> str:
        """The specimen's TOML file (`path`, default the bundled one of its name) with
        this ``[restitution]`` table and a new `name`; it loads back. A value the trace
        did not estimate keeps the specimen's, with a comment that says so."""
        from multimass.specimens.toml_text import specimen_text

        note = f"identified from {self.segments.trace.source} for {self.impact}"
        vals = self.model_values()
        if "cp" in vals and self.impact != "CIM":  # a specimen file holds no C_p
            note += (
                f" with C_p = {vals['cp']:.6g} kg m/rad/s "
                f"({_status_comment(self.parameters['cp'])})"
            )
        tables, comments = {"restitution": self.table()}, {"restitution": self.comments()}
        zs = [self.parameters.get(n, {}).get("status") for n in ("zeta1", "zeta2")]
        if any(z in ("estimated", "ill-posed") for z in zs):  # the damping the r are for
            tables["damping"] = {
                "zeta_1": float(f"{vals['zeta1']:.6g}"),
                "zeta_2": float(f"{vals['zeta2']:.6g}"),
            }
            comments["damping"] = {
                f"zeta_{n[-1]}": _status_comment(self.parameters.get(n, {}))
                for n in ("zeta1", "zeta2")
            }
        return specimen_text(
            self.structure.specimen, tables, note=note, comments=comments, name=name,
            path=path,
        )  # fmt: skip

    def restitution_source(self):
        """`EmpiricalRestitution` of `per_impact`, then these corner means."""
        from multimass.impact_models import EmpiricalRestitution

        used = self.values_used()
        return EmpiricalRestitution(
            tuple(self.per_impact()),
            CornerRestitution(used["r_mean_right"], used["r_mean_left"]),
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
                "sigma_r_interval": self.sigma_r_interval,
                "r_mean_std": self.r_mean_std,
                "energy": self.energy_means,
                "n_estimated": int(self.impacts["estimated"].sum()),
                "not_estimated": dict(self.not_estimated),
                "alignment": self.alignment,
                "status": self.status,
                "message": self.message,
                "parameters": self.parameters,
                "warnings": list(self.warnings),
                "input_check": _check_summary(self.input_check, self.impacts),
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


def restitution(
    trace: Trace,
    structure=None,
    impact: str = IMPACT_DEFAULT,
    *,
    theta_min: float = THETA_MIN,
    zeta1: float | None = None,
    zeta2: float | None = None,
    progress: bool | None = None,
    **options,
) -> RestitutionEstimate:
    """Estimate each impact's coefficient of restitution from a trace, two ways.

    Parameters
    ----------
    trace : Trace
        A free-vibration test (θ held at a release angle, then released) or a test
        with table motion (an ``ag`` channel: the excitation), with a θ channel and,
        best, the accelerometers' channels (``a_<sensor>``, ``a<node>``).
    structure : Structure, specimen or str, optional
        The column tested; default the trace's ``# specimen:`` line.
    impact : str, optional
        The impact model the model-based estimates are for: "DD" (the Dirac-delta
        model of paper 001, C_p of the specimen's Table 2 family, default), "CIM",
        "DD1" … "DD4" (their restitution is replaced by the fitted one).
    theta_min : float, optional
        Impacts between half-cycles both at least this large (rad) are estimated
        (paper 001, Section 4.3: 0.01), if the trace fixes their r (r_std ≤ 0.02).
    zeta1, zeta2 : float, optional
        The Rayleigh damping ratios of full-contact modes 1 and 2, if known; each one
        not given is estimated from the trace (as is C_p, ``C_p=`` in `options`, for
        a Dirac-delta model), and the coefficients' standard errors include its
        uncertainty.
    progress : bool, optional
        Show a progress bar over the impacts, then the table-motion check's draws
        (default: when more than 3 impacts are fitted).
    **options
        Options of `multimass.simulate` for the model runs (``C_p``: given, not
        estimated; ``rtol``, …); the compiled backend is used by default.

    Returns
    -------
    RestitutionEstimate

    Raises
    ------
    InputError
        No θ channel, no specimen, no rocking, no impact between half-cycles above
        `theta_min`, a sampling rate too low to segment θ, an ``ag`` column in an
        implausible unit (the message says what was found and the fix). Acceleration
        columns are not needed: the fit uses those the trace has (θ alone is looser).
    """
    st = _structure(require_trace(trace), structure)
    check_theta(trace, st)
    check_frozen(trace)
    seg = segment_trace(trace, theta_min=theta_min)
    if trace.ag is not None:  # the table motion drives the model: its unit must be plausible
        check_ag(trace, st, seg)
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
    if not any(not h.small for h in seg.half_cycles):
        raise no_rocking(
            trace, seg, theta_min, "restitution needs impacts between large half-cycles"
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
    if not seg.full_contact:
        warnings.append(
            "the trace never rests on its base: the θ sensor's bias is fitted on the rocking "
            "alone (its start, the median θ near zero, may be off)"
        )
    half = seg.half_cycles
    estimated = [
        not (half[m.before].small or half[m.after].small) for m in seg.impacts
    ]  # fmt: skip
    last = max((i for i, e in enumerate(estimated) if e), default=-1)
    # and the two after: the next impact's time is what sets an r best
    n_fit = min(last + 3, len(seg.impacts)) if last >= 0 else 0
    r_energy = energy_restitution(
        st, [half[m.before].peak for m in seg.impacts], [half[m.after].peak for m in seg.impacts]
    )
    cols = channel_columns(trace, st)  # checks the trace's sensors against the specimen
    accel = tuple(c for c in trace.names if cols[c].startswith("a") and cols[c] != "ag")
    options = dict(options)
    given = _given(st, impact, options.pop("C_p", None), zeta1, zeta2)
    track = fitting.track_of(trace, st, impact, accel, theta_min, options, given)
    shown = progress if progress is not None else n_fit > 3
    # with table motion, the check of its noise's draws after the impacts (`_restitution_input`)
    n_check = 0 if track.case.free else table_noise.DRAWS
    unit = "impacts" if track.case.free else "impacts, then ag draws"
    try:  # a fit's first point is the trace's own reading: a model that cannot run it is
        # the trace's mistake (the checks above name the known ones)
        fitting.align(track, seg.impacts[0].t)
        with Progress(n_fit + 1 + n_check, f"restitution {st.name}", show=shown, unit=unit) as bar:
            fitted = fitting.fit_impacts(track, n_fit, bar, warnings)
            bar.update(n_fit + 1)
            checked = table_noise.input_check(track, fitted, lambda k: bar.update(n_fit + 1 + k))
    except TrialRejected as err:
        raise InputError(
            f"{trace.source}: the model of {st.name!r} cannot run from what the trace "
            f"shows ({err}); check the trace's units and that it is a test of {st.name!r}"
        ) from None
    loose = [i for i, f in fitted.items() if estimated[i] and not f.r_std <= LIMITS["r_std"]]
    if loose:
        warnings.append(
            "impact(s) at t = " + ", ".join(f"{seg.impacts[i].t:.4g}" for i in loose) + " s: "
            f"the trace does not fix r to {LIMITS['r_std']:g} (r_std above it); not "
            "estimated (the fragment gives them the corner means)"
        )
    # a fit that does not reproduce the trace after an impact: its r is no estimate
    # (`_restitution_fit.theta_misfit`: the χ² test of θ against the trace's noise)
    off = [i for i, f in fitted.items() if estimated[i] and i not in loose and
           not f.misfit <= 1.0]  # fmt: skip
    if off:
        warnings.append(
            "impact(s) at t = " + ", ".join(f"{seg.impacts[i].t:.4g}" for i in off) + " s: "
            "the fit does not reproduce the trace after them (residual mean square "
            + ", ".join(f"{fitted[i].misfit:.3g} × ({fitted[i].misfit_channel})" for i in off)
            + " the most the noise leaves); not estimated"
        )
    # an r the fit holds only with the recorded ag's own noise: no estimate
    # (`_restitution_input`: most re-noised draws fail the test over its half-cycles)
    noisy = {i: why for i, why in table_noise.impact_reasons(checked).items()
             if estimated[i] and i not in loose + off}  # fmt: skip
    if noisy:
        warnings.append(
            "impact(s) at t = "
            + ", ".join(f"{seg.impacts[i].t:.4g}" for i in noisy)
            + " s: "
            + next(iter(noisy.values()))
            + "; not estimated"
        )
    rows = []
    for i, m in enumerate(seg.impacts):
        f = fitted.get(i)
        rows.append(
            {
                "t": m.t,
                "corner": m.corner,
                "r": f.r if f else float(r_energy[i]),
                "r_energy": float(r_energy[i]),
                "theta_before": half[m.before].peak,
                "theta_after": half[m.after].peak,
                "estimated": estimated[i] and f is not None and i not in [*loose, *off, *noisy],
                "model_impact": f.model_impact if f else -1,
                "rms": f.rms if f else math.nan,
                "misfit": f.misfit if f else math.nan,
                "misfit_channel": f.misfit_channel if f else "",
                "r_std": f.r_std if f else math.nan,
            }
        )
    table = pd.DataFrame(rows)
    means, missing, sigma_r_interval = _means(table, "r", st)
    energy, _, _ = _means(table, "r_energy", st)
    # the response of the specimen fragment: the estimated impacts' r, then the corner means
    # (the specimen's where a corner has none)
    est = table[table["estimated"]]
    spec = st.specimen
    phys = track.phys | {
        "r_er": spec.r_right if means[0] is None else means[0],
        "r_el": spec.r_left if means[1] is None else means[1],
    }
    values = dict(zip(est["model_impact"].astype(int), est["r"]))
    final = track.run(values, float(track.t[-1]) - track.nuis["t_offset"], phys=phys)
    align = {k: float(track.nuis[k]) for k in ("t_offset", "theta_bias", "theta0")}
    parameters = report.parameter_report(track, given, fitted, st.specimen, checked)
    status, message = _status(
        parameters, {seg.impacts[i].t: why for i, why in noisy.items()}, checked
    )
    mean_std = _mean_stds(table, means, track, st.specimen.sigma_r)
    return RestitutionEstimate(
        table, *means, energy_means=dict(zip(("r_mean_right", "r_mean_left", "sigma_r"), energy)),
        alignment=align, structure=st, impact=impact, theta_min=seg.theta_min, segments=seg,
        response=final.response, warnings=tuple(warnings), not_estimated=missing,
        parameters=parameters,
        status=status, message=message, r_mean_std=mean_std,
        sigma_r_interval=sigma_r_interval, input_check=checked,
    )  # fmt: skip


def _check_summary(checked, table: pd.DataFrame):
    """`RestitutionEstimate.input_check` for JSON: each impact by its trace time."""
    if not checked:
        return None
    key = {i: f"{table['t'].iloc[i]:.6g}" for i in checked["impacts"]}
    return {
        "noise": checked["noise"], "span": checked["span"],
        "span_decided": checked["span_decided"],
        "impacts": {key[i]: d for i, d in checked["impacts"].items()},
        "decided": {key[i]: d for i, d in checked["decided"].items()},
        "seconds": checked["seconds"], "simulations": checked["simulations"],
    }  # fmt: skip


def _status(parameters: dict, noisy: dict, checked) -> tuple[str, str]:
    """(status, message) of the result: `overall`'s, ill-posed too where the table
    motion's noise decides some impact's r (`noisy`: its time → why), with what the user
    can do where the noise decides anything (`checked`: `_restitution_input.input_check`'s
    answer)."""
    status, message = overall(parameters)
    if noisy:
        times = ", ".join(f"{t:.4g}" for t in noisy)
        why = f"r of the impact(s) at t = {times} s: {next(iter(noisy.values()))}"
        body = message if status == ILL_POSED else "not fixed by the trace(s)"
        status, message = ILL_POSED, f"{body}; {why}"
    if noisy or table_noise.span_reason(checked):
        message += (
            "; the fit follows the noise of the recorded table motion: a record of it with "
            "less noise, or a free-vibration test (no table motion to follow), fixes them"
        )
    return status, message


def _mean_stds(table: pd.DataFrame, means, track, sigma_r: float) -> dict:
    """Per corner: ``std`` of its mean as the mean of its estimated impacts (their joint
    covariance: `_restitution_report.mean_std`, with `_means`' weights, the specimen's
    `sigma_r` where the trace did not estimate σ), ``interval`` (95 %)
    and ``n``; None where the corner has no estimated impact. (As an estimate of the
    corner's mean over further impacts add σ_r / √n in quadrature.)"""
    est = table[table["estimated"]]
    out = {}
    for j, corner in enumerate(("right", "left")):
        rows = est[est["corner"] == corner]
        if rows.empty:
            out[corner] = None
            continue
        sigma = sigma_r if means[2] is None else means[2]
        w = 1.0 / (sigma**2 + rows["r_std"].to_numpy(dtype=float) ** 2 + 1e-12)
        sd = report.mean_std(track, rows, w)
        out[corner] = {
            "std": sd, "interval": [means[j] - Z95 * sd, means[j] + Z95 * sd], "n": len(rows)
        }  # fmt: skip
    return out


def _given(st, impact: str, cp, zeta1, zeta2) -> dict:
    """The model parameters the user gave, checked: C_p of a Dirac-delta model, damping
    ratios that make a Rayleigh damping (InputError naming the field otherwise)."""
    from dataclasses import replace

    from ..model.structure import column
    from ..specimens import SpecimenError

    out = {}
    if cp is not None:
        if impact == "CIM":
            raise InputError(
                f"`C_p` = {cp!r}: the classical impact model (CIM) has no C_p (paper 001 "
                "Table 2); remove it or choose a Dirac-delta model (DD, DD1 … DD4)"
            )
        out["cp"] = v.positive("C_p", cp, "kg m/rad/s, of the Dirac-delta force")
    for name, z in (("zeta1", zeta1), ("zeta2", zeta2)):
        if z is not None:
            out[name] = v.number(name, z, low=1e-6, high=1.0, what=PARAMETERS[name].what)
    if "zeta1" in out or "zeta2" in out:
        spec = st.specimen
        z1, z2 = out.get("zeta1", spec.zeta_1), out.get("zeta2", spec.zeta_2)
        try:
            column(replace(spec, zeta_1=z1, zeta_2=z2))
        except SpecimenError as err:
            raise InputError(
                f"`zeta1`, `zeta2` = {z1:g}, {z2:g}: not a Rayleigh damping of this column "
                f"({err}); give other damping ratios"
            ) from None
    return out


def _means(table: pd.DataFrame, column: str, st) -> tuple[list, dict, list | None]:
    """([right mean, left mean, pooled σ], reasons, σ's 95 % interval) of `column` over
    the estimated impacts (the interval: `_restitution_report.sigma_interval`, None
    where σ is).

    The coefficients vary from impact to impact (the spread σ, paper 001 Table 1's σ_r)
    and each is known to its r_std: the means weigh each impact by 1 / (σ² + r_std²),
    σ first from equal weights — nearly equal weights where r_std ≪ σ, a poorly
    determined impact counting less. σ is the pooled sample standard deviation about
    the corner means. A corner without an estimated impact has no mean, and fewer than
    `MIN_SIGMA_IMPACTS` impacts no σ: None, with the reason under its name in `reasons`
    (the specimen's σ_r then weighs the means).
    """
    est = table[table["estimated"]]
    groups = []
    for corner in ("right", "left"):
        rows = est[est["corner"] == corner]
        std = rows["r_std"].to_numpy(dtype=float) if column == "r" else np.zeros(len(rows))
        groups.append((rows[column].to_numpy(dtype=float), std))
    n = len(est)
    reasons = {
        f"r_mean_{corner}": f"no estimated impact on the {corner} corner"
        for corner, (x, _) in zip(("right", "left"), groups)
        if not x.size
    }
    if n < MIN_SIGMA_IMPACTS:
        reasons["sigma_r"] = (
            f"{n} estimated impact{'s' if n != 1 else ''}; σ_r needs at least {MIN_SIGMA_IMPACTS}"
        )

    def deviations(means) -> np.ndarray:
        return np.concatenate([x - m for (x, _), m in zip(groups, means) if x.size])

    def pooled(means) -> float:
        d = deviations(means)
        return float(math.sqrt(d @ d / (d.size - sum(1 for x, _ in groups if x.size))))

    means = [float(x.mean()) if x.size else None for x, _ in groups]
    sigma = pooled(means) if n >= MIN_SIGMA_IMPACTS else float(st.specimen.sigma_r)
    for j, (x, std) in enumerate(groups):
        w = np.where(np.isfinite(std), 1.0 / (sigma**2 + std**2 + 1e-12), 0.0)
        if x.size and w.sum() > 0.0:
            means[j] = float(np.average(x, weights=w))
    if n < MIN_SIGMA_IMPACTS:
        return [*means, None], reasons, None
    stds = np.concatenate([std for x, std in groups if x.size])
    n_corners = sum(1 for x, _ in groups if x.size)
    interval = report.sigma_interval(deviations(means), stds, n_corners)
    return [*means, pooled(means)], reasons, interval


def _status_comment(p: dict) -> str:
    """A parameter's status for a comment; an ill-posed one's value is its best fit, not
    an estimate, and its range the one its fit explored (`_parameter_status.explored`)."""
    status = p.get("status")
    if p.get("interval_kind") == EXPLORED:
        lo, hi = p["interval"]
        return (
            f"{status}: best fit, not an estimate; not fixed by the traces: anywhere in "
            f"{lo:.5g} … {hi:.5g}"
        )
    return str(status)
