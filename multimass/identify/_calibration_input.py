"""Does the table motion's noise decide the calibration? (`multimass.identify.calibrate`)

With table motion the model is driven by the recorded ``ag``, noise and all, as if it were
the table's motion; the covariance of the fit knows the sensors' noise only. Where the
response is sensitive to its input — an uplift or an impact whose time a small change of
``ag`` moves — the fit follows the response to the *recorded* ``ag``, and C_p, ζ and the
restitution means move to wherever that response is matched, a valley of the cost the
table's true motion does not have.

Measured on the coverage benchmark's draw S1-004 (seed 0; northridge_1994, 592 Hz,
noise 4.3 % of each channel's peak, ``ag``'s 0.36 m/s²): driven by the recorded ``ag``,
the model at the true parameters misses the trace by 1.6, 1.5, 0.90 and 3.5 m/s² RMS on
a_A1 … a_A4 (noise 0.46, 0.63, 0.46, 0.87) and the fit lands at C_p = 1001 with std
2.3 % (truth 1365), ζ2 = 0.0182 ± 6.6 % (truth 0.0138); driven by the noise-free ``ag``
the same parameters match every channel within 0.98–1.16 × its noise and the fit from
the truth stays at C_p = 1368, ζ1 = 0.0047, ζ2 = 0.0135. The simulated responses to the
two ``ag`` differ by 0.2–1.2 × the fit's residual RMS until the impact at 1.52 s and by
3–7 × after it. Profiled with C_p held (everything else refitted, the fit's channel
weights), the cost rises from the fit's by 47, 142, 448 and 767 at C_p = 1100, 1200,
1365 and 1500, in units where the fit's 95 % interval is a rise of 3.84 (χ²₁): not a
second valley of equal cost, and the Jacobian's slice probe finds the cost smooth there
(rise 88 / 39 at ± 5.3 % where 69 is predicted). What the fit does not know is how far
another ``ag`` within the recorded one's noise would move it.

`input_check` asks that: it re-noises each table-motion trace's ``ag`` with white noise
of the level `input_noise` estimates from it (a copy as far from the recorded ``ag`` as
the recorded one is, in distribution, from the table's motion), `DRAWS` times, and runs
the fitted model with each, everything else as fitted, through the test the fit itself
passed (`_calibration_result.misfit`: each channel's residual mean square over the most
a fit at the traces' parameters leaves, probability 1e-3 of exceeding it). Where most
draws fail it (`decides`), the fit reproduces the traces only with the recorded ``ag``'s
own noise: every fitted parameter is ill-posed (`reasons`), and a refit with the draw
that failed most (from the fit, the same window and channel weights) gives the other
values the reason names. On S1-004 the draws failed at 1.004, 1.5, 1.6, 2.4 and
5.8 × the limit (the fit: 0.85; ``ag``'s noise read as 0.352 m/s²), a run of
0.06–0.13 s each, and the refit from the worst moved C_p to 555, ζ1 to 0.0038, ζ2 to
0.046: the check took 2.7 s (49 runs) of the calibration's 9.3 s. Refits from four
other draws moved C_p to 867, 1023, 1003, 967, ζ1 to 0.0053, 0.0027, 0.0050, 0.0024
and ζ2 to 0.028, 0.026, 0.018, 0.20. Hence the
majority of several draws, not one, and ill-posed rather than widened: a few refits are
draws of the input's effect, too few to measure its spread, and one need not leave the
fit's interval where the test of the runs fails on most draws. A free-vibration trace
has no ``ag``: nothing is run.

`renoised_runs` draws the copies and `noise_reason` words the reason for this check and
for `restitution`'s (`multimass.identify._restitution_input`): the same noise for the
same trace.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
from scipy import signal

from ..errors import SolverError
from ..inputs.records import Record
from ._calibration_fit import Problem, solve
from ._calibration_model import TrialRejected
from ._calibration_params import PARAMETERS

__all__ = ["input_noise", "perturbed", "renoised_runs", "input_check", "decides", "reasons",
           "noise_reason", "DRAWS", "INPUT_SEED", "INPUT_NFEV", "NOISE_SHARE"]  # fmt: skip

#: Re-noised copies of ``ag`` tested (a majority failing decides).
DRAWS = 5
#: Seed of the white noise added to ``ag`` (the check is reproducible).
INPUT_SEED = 20_061
#: Evaluations of the refit with the draw that failed most, whose values the reasons name
#: (from the fit, refits on S1-004 took 9–14 to converge: these show where it goes).
INPUT_NFEV = 10
#: ``ag``'s noise is measured above this share of the sampling rate.
NOISE_SHARE = 0.25


def input_noise(ag, fs: float) -> float:
    """Standard deviation of white noise in a recorded table acceleration (its unit).

    The record less its zero-phase low-pass at `NOISE_SHARE` × `fs` (4th-order
    Butterworth, forwards and backwards) is the noise above that frequency; its robust
    spread (1.4826 × MAD) divided by the share of white noise's standard deviation the
    high-pass keeps (`_passed`, 0.679; an ideal filter's √(1 − 2 × `NOISE_SHARE`) = 0.707
    read 4 % low) is the noise's. A table's own motion above fs/4 counts as noise: the
    check is then stricter.
    """
    a = np.asarray(ag, dtype=float)
    if a.size < 16:
        return 0.0
    sos = signal.butter(4, NOISE_SHARE * fs, fs=fs, output="sos")
    high = a - signal.sosfiltfilt(sos, a)
    mad = float(np.median(np.abs(high - np.median(high))))
    return 1.4826 * mad / _passed()


def _passed() -> float:
    """Share of white noise's standard deviation that `input_noise`'s high-pass keeps:
    √(mean over 0 … fs/2 of (1 − |H|²)²), H the low-pass (|H|² forwards and backwards);
    the same at every fs (the cut-off is a share of it)."""
    sos = signal.butter(4, NOISE_SHARE, fs=1.0, output="sos")
    _, h = signal.sosfreqz(sos, worN=1 << 16, fs=1.0)
    return math.sqrt(float(np.mean((1.0 - np.abs(h) ** 2) ** 2)))


def perturbed(case, sigma: float, rng: np.random.Generator, tag: str):
    """`case` driven by its recorded ``ag`` plus white noise of std `sigma`, tagged `tag`
    (runs are cached by it: one tag per draw)."""
    t = np.asarray(case.trace.time, dtype=float)
    ag = np.asarray(case.trace.ag, dtype=float)
    noisy = ag + rng.normal(0.0, sigma, ag.size)
    rec = Record(t - t[0], noisy, name=f"table (ag) {tag}", source=case.trace.source)
    return replace(case, excitation_record=rec, input_tag=tag)


def renoised_runs(cases, run, progress=None) -> tuple[dict, list]:
    """(label → the ``ag`` noise's std, m/s², of each table-motion case of `cases`;
    `run`'s answer per draw): `run`(k, cases) for k = 0 … `DRAWS` − 1, with every
    table-motion case of `cases` driven by its recorded ``ag`` re-noised by that std
    (`perturbed`; the free ones as they are), None where a run was rejected or failed.
    One seeded stream (`INPUT_SEED`) for every draw, case after case: `calibrate`'s and
    `restitution`'s checks draw the same noise for the same trace. `progress`, if
    given, is called with the number of draws done after each."""
    rng = np.random.default_rng(INPUT_SEED)
    noise = {c.label: input_noise(c.trace.ag, c.fs) for c in cases if not c.free}
    out = []
    for k in range(DRAWS):
        drawn = [c if c.free else perturbed(c, noise[c.label], rng, f"ag re-noised {k}")
                 for c in cases]  # fmt: skip
        try:
            out.append(run(k, drawn))
        except (TrialRejected, SolverError):
            out.append(None)
        if progress is not None:
            progress(k + 1)
    return noise, out


def input_check(sim, pset, problem: Problem, x: np.ndarray, test, max_nfev: int = INPUT_NFEV):
    """Whether the fit still reproduces the traces with every table-motion trace's ``ag``
    re-noised (see the module docstring); None without table motion.

    Parameters
    ----------
    sim : Simulator
    pset : ParameterSet
    problem : Problem
        Stage 2's last problem (its window, channel weights and prior).
    x : ndarray
        Its solution.
    test : callable
        (problem, x) → {(label, channel): residual mean square over the most a fit that
        reproduces the trace leaves} (`_calibration_result.misfit`, the test of the fit).
    max_nfev : int, optional
        Evaluations of the refit made where most draws fail that test.

    Returns
    -------
    dict or None
        ``noise`` (label → the ``ag`` noise's std, m/s²), ``draws`` (per draw: the
        channel failing the test most, "label:channel", and its ratio; None where a run
        failed), ``decided`` (bool: most draws fail), ``x`` (then: the refit's model
        parameters in fitted units; else None), ``nfev``, ``message``, ``seconds``,
        ``simulations``.
    """
    if not any(not c.free for c in problem.cases):
        return None
    wall, runs = time.perf_counter(), sim.n_runs
    start = {un.label: float(v) for un, v in zip(problem.unknowns, x)}
    problems = []

    def one(k: int, cases: list):
        q = Problem(sim, pset, cases, 2, problem.per_impact, problem.sigma_r, start=start,
                    frozen=problem.frozen)  # fmt: skip
        q.scales = dict(problem.scales)
        tested = test(q, q.x0())
        worst = max(tested.items(), key=lambda kv: kv[1], default=None)
        draw = None if worst is None else (f"{worst[0][0]}:{worst[0][1]}", float(worst[1]))
        problems.append((draw[1] if draw is not None else -math.inf, k, q))
        return draw

    noise, draws = renoised_runs(problem.cases, one)
    info = {"noise": noise, "draws": draws, "decided": decides(draws), "x": None, "nfev": 0,
            "message": ""}  # fmt: skip
    if info["decided"] and problems:
        _, _, q = max(problems, key=lambda item: item[:2])
        try:
            sol = solve(q, max_nfev)
        except (TrialRejected, SolverError) as err:
            info["message"] = f"the refit with the re-noised ag failed: {err}"
        else:
            info["x"] = {n: float(sol.x[q.index[n]]) for n in pset.fit if n in q.index}
            info["nfev"] = int(sol.nfev)
            info["message"] = str(sol.message)
    info["seconds"] = time.perf_counter() - wall
    info["simulations"] = sim.n_runs - runs
    return info


def decides(draws) -> bool:
    """The decision: the fitted model driven by most of the re-noised ``ag`` fails the
    fit's own test in some channel (ratio above 1: the probability 1e-3 a fit at the
    traces' parameters has of exceeding it). `draws`: per draw (channel, ratio) of its
    worst channel, or None where its run failed (not a failure of the test)."""
    ratios = [d[1] for d in draws if d is not None]
    return bool(ratios) and sum(r > 1.0 for r in ratios) > len(draws) / 2


def reasons(names, x_fit: dict, checked) -> dict:
    """name → why it is ill-posed, for each of `names`, where `input_check` found the fit
    decided by the table motion's noise; {} where it did not (or `checked` is None). The
    reason gives the value fitted and the refit's with the re-noised ``ag`` (fitted units
    in `x_fit` and ``checked["x"]``: log for C_p and ζ)."""
    if not checked or not checked.get("decided"):
        return {}
    why = noise_reason(checked["noise"], checked["draws"])
    other = checked.get("x") or {}
    out = {}
    for name in names:
        p = PARAMETERS[name]
        refit = f", {p.to_value(other[name]):.4g} refitted with it" if name in other else ""
        out[name] = f"{why}; {p.to_value(x_fit[name]):.4g} with the recorded ag{refit}"
    return out


def noise_reason(noise: dict, draws: list) -> str:
    """Why a value is ill-posed where most of the re-noised ``ag`` `draws` (per draw:
    (channel, ratio) of its worst channel, or None) fail the fit's test: the noise's
    levels (`noise`: label → std, m/s²), how many draws failed and the worst."""
    levels = ", ".join(f"{s:.3g} m/s² on {lab}" for lab, s in noise.items())
    failing = [d[1] for d in draws if d is not None and d[1] > 1.0]
    worst = max((d for d in draws if d is not None), key=lambda d: d[1])
    return (
        f"the table motion's noise decides the fit: driven by the recorded ag re-noised "
        f"by as much as it holds ({levels}), the fitted model no longer reproduces the "
        f"trace in {len(failing)} of {len(draws)} draws (residual mean square "
        f"up to {worst[1]:.3g} × the most the noise leaves, {worst[0]})"
    )
