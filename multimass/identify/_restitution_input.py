"""Does the table motion's noise decide `multimass.identify.restitution`'s fit?

With table motion the model is driven by the recorded ``ag``, noise and all
(`multimass.identify._calibration_input` says why that can decide a fit, for
`calibrate`). Measured on the coverage benchmark's draw S3-064 (seed 0; S3 under a
Northridge window, 214 Hz, noise 2.3 % of each channel's peak: 0.110 m/s² on ``ag``,
whose bias is 0.023 m/s²): at the true parameters, driven by the recorded ``ag``, the
model fails the fit's own test (`_restitution_fit.reproduces`) at its first impact
(2.0 × the limit) and from the third on (14 × there; 13.5 × over the trace); driven by
the noise-free ``ag`` it passes at the second to the fifteenth impact, to 4.1 s
(0.56–0.96 ×; 1.13 × at the first). The fit with the recorded ``ag`` reported
r = 0.8548 ± 0.0035 at the left impact at 2.211 s, for a drawn 0.9246, an r that
passes its own test there; fitted with the noise-free ``ag`` instead, the r there fails
it (2.2 ×) and is not reported. Refitted over the whole span from the fit with
each of five re-noised copies of the recorded ``ag`` (`renoised_runs`), that r went to
0.839, 0.859, 0.891, 0.851 and 0.864 (C_p to 1317, 1393, 2242, 1037 and 482; the fit's
988, the truth 2071): a spread five times the std reported, none near the truth. On
S1-069 (Northridge, 0.186 m/s² of noise on ``ag``) the true parameters fail the test
by 47–307 × at every impact with the recorded ``ag``, 0.83–0.90 × with the noise-free
one, and the fit said *estimated*, six of its seven r off by 4.7–10 of their std. There
``ag``'s noise alone and its bias alone (0.017 m/s²) fail the truth by 78 and 80 × over
the trace: the check below draws the noise, not the bias, which the record does not
show.

`input_check` runs the fitted model — every r, C_p, ζ and the nuisance parameters as
fitted — with the trace's ``ag`` re-noised by the noise
`_calibration_input.input_noise` reads from it,
`DRAWS` times (`renoised_runs`, calibrate's draws: the same seeded noise), through the
tests the fit itself passed or failed: the one over the two half-cycles that set each
impact's r, and the one over the whole span fitted. What it decides, per quantity:

* an impact whose test most draws fail (`_calibration_input.decides`) is *not
  estimated*, as an impact whose test the fit itself fails (`impact_reasons`: the
  reason, a warning; the corner means and σ_r are taken without it). Its r is local:
  the draws fail at some impacts and pass at others (S3-064 at 2.211 s: 3.8, 0.99,
  0.82, 3.7 and 14.5 × the limit), so the test of its own half-cycles decides it;
* C_p, ζ1, ζ2 and the θ bias, set by the whole span, are *ill-posed* where most draws
  fail the test over it (`span_reason`), with the range their fit explored, as where
  the fit itself fails it (`_restitution_report`).

No refit: `calibrate` names a refit's values; here one costs a whole-span least
squares of every r (2–5 s each on S3-064) and is one draw of the input's effect, too
few to measure its spread; the decision is the draws' test. Measured on the 45
table-motion traces of the coverage run (seed 0, 100 per specimen) with an impact
fitted: the test over the whole span failed in every draw on 44 (1.37–929 × the limit),
in 3 of 5 on S2-069 (1.13–1.19 ×); every one of the 350 impacts fitted was decided.
Before the check 32 estimates were reported with an interval, 10 of which held the
truth (5 of 15 per-impact r, 4 of 10 corner means, 1 σ_r, none of 1 C_p, 3 ζ and 2 θ
biases); now none is. The check took 0.1–1.9 s (median 0.44 s; 5 runs of the span), at
most 3.8 % of restitution's time.

The check is stricter where the record has motion above fs/4, which it reads as noise,
and where the model's response branches on a small change of ``ag``: S3-064's noise-free
``ag`` reads as 7.2e-4 m/s² of noise, and three of five draws of that much failed the
test of its first impact, where the run lands in full contact for 6 ms instead of
uplifting at once (2.6 m/s² apart on a_A3 after it); low-passed at fs/5 (5.8e-5 m/s²
read) no draw fails (`tests/multimass/identify/test_restitution_input.py`). A
free-vibration trace has no ``ag``: nothing is run, and its result is the same bit for
bit.
"""

from __future__ import annotations

import time
from dataclasses import replace

from ._calibration_input import DRAWS, decides, noise_reason, renoised_runs
from ._restitution_fit import Track, reproduces

__all__ = ["input_check", "impact_reasons", "span_reason", "DRAWS"]


def input_check(track: Track, fitted: dict, progress=None) -> dict | None:
    """The fitted model run with the trace's ``ag`` re-noised (`renoised_runs`: `DRAWS`
    draws of the noise `_calibration_input.input_noise` reads from it) through the
    fit's own tests (`_restitution_fit.reproduces`); None for a free-vibration trace.

    Parameters
    ----------
    track : Track
        After `_restitution_fit.fit_impacts`.
    fitted : dict
        Its answer: trace impact index → `ImpactFit`.
    progress : callable, optional
        Called with the number of draws done.

    Returns
    -------
    dict or None
        ``noise`` (label → the ``ag`` noise's std, m/s²); ``impacts`` (trace impact index
        → per draw (channel, ratio) of the test over the two half-cycles that set its r,
        None where the run failed); ``span`` (per draw, the same over the whole span
        fitted); ``decided`` (trace impact index → bool: most draws fail its test);
        ``span_decided`` (bool); ``seconds``; ``simulations``.
    """
    if track.case.free or not fitted:
        return None
    wall, runs = time.perf_counter(), track.sim.n_runs

    def one(_k: int, cases: list):
        per, whole, _ = reproduces(replace(track, case=cases[0]), fitted)
        return per, whole

    noise, answers = renoised_runs([track.case], one, progress)
    impacts = {
        i: [None if a is None else (a[0][i][1], float(a[0][i][0])) for a in answers]
        for i in fitted
    }  # fmt: skip
    span = [None if a is None else (a[1][1], float(a[1][0])) for a in answers]
    return {
        "noise": noise,
        "impacts": impacts,
        "span": span,
        "decided": {i: decides(d) for i, d in impacts.items()},
        "span_decided": decides(span),
        "seconds": time.perf_counter() - wall,
        "simulations": track.sim.n_runs - runs,
    }


def impact_reasons(checked) -> dict:
    """Trace impact index → why its r is not estimated, for each impact whose test most
    re-noised draws fail; {} where none does (or `checked` is None)."""
    if not checked:
        return {}
    return {
        i: noise_reason(checked["noise"], checked["impacts"][i])
        for i, bad in checked["decided"].items()
        if bad
    }


def span_reason(checked) -> str:
    """Why every parameter estimated over the whole span is ill-posed, where most draws
    fail the test over it; "" where they do not (or `checked` is None)."""
    if not checked or not checked["span_decided"]:
        return ""
    return noise_reason(checked["noise"], checked["span"])
