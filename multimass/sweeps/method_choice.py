"""``method="auto"``: the integrator of a sweep's column runs, chosen for the column at hand.

DOP853's steps are held by stability to h_s = c/ρ (c = 3.4, ρ the spectral radius of
the column's state matrix; `multimass.cost`), whatever the accuracy asked. The
exponential rocking integrator (`multimass.engines.fast._exp_kernel`) advances the
linear part of the rocking phase exactly and takes the steps its accuracy needs, h_e
(~2 ms for S1 at rtol 1e-8; `multimass.cost`), each ~6 right-hand sides. The ratio
S = min(h_e, max_step) / h_s is how many DOP853 steps stability forces per exponential
step. Work and precision measured on the compiled whole runs (benchmarks/exponential_rocking.py,
DOP853 cost / exponential cost at rtol 1e-6, 1e-8, 1e-10; max_step = inf; medians of 3
on a shared machine; the errors against DOP853 at rtol 1e-12 beside them in
docs/guide/speed.md):

==================  ======  ==================
column              S       DOP853 / exp.
==================  ======  ==================
S1 released         1.9     1.68, 1.13, 0.80
S1, El Centro       1.9     0.71, 0.76, 0.72
S2, S3              2–2.4   0.77 … 2.00
S1 × 100 stiffer    19.5    6.33, 3.59, 1.73
20-node column      88      45.4, 23.6, 13.0
==================  ======  ==================

`choose_method` therefore

1. keeps DOP853 where the exponential method does not apply (not a column on the
   compiled path, no diagonalisable rocking phase) or S < `STIFF` (the bundled columns,
   S ≈ 2–2.4: under a record DOP853 is faster for S1 and S3, the exponential method
   up to 1.25× for S2; released, the exponential method is up to 2.0× faster at rtol
   1e-6 and 1e-8 but further from the reference, its impact times up to 160× and its
   ledger 100–850× DOP853's errors at the same rtol);
2. otherwise runs the sweep's sample run (its longest) each way, and picks the
   exponential method only if it was faster *and* as accurate at the same tolerance: as
   many impacts as DOP853's run, θ_max and every impact time within `FLOOR` × rtol (of
   θ_max, of t_end) of DOP853's; where they differ more, a third run, DOP853 at the
   tolerances / `REFERENCE_FACTOR`, is the reference, and the exponential run must be
   no further from it than DOP853's (or than that floor).

The choice, its reason and the measurements are returned (`MethodChoice`); a sweep
records them in its options and JSON.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..cost import DOP853_STABILITY, EXPONENTIAL_STEP, STIFF, spectral_radius, stiffness
from ..simulation import simulate_outcome
from ..simulation_options import SimulationOptions

__all__ = [
    "MethodChoice",
    "choose_method",
    "resolve",
    "sweep_method",
    "stiffness",
    "STIFF",
    "AUTO",
]

#: The method name that asks for a choice.
AUTO = "auto"
#: The reference of the accuracy check: DOP853 at the sweep's tolerances divided by this.
REFERENCE_FACTOR = 100.0
#: Errors below FLOOR × rtol (of θ_max, of t_end for impact times) count as exact.
FLOOR = 10.0
_BOTH = ("DOP853", "exponential")


@dataclass(frozen=True)
class MethodChoice:
    """The method a sweep runs with, and why.

    Attributes
    ----------
    method : str
        "DOP853" or "exponential".
    reason : str
        In words, with the figures that decided.
    stiffness : float
        S = min(h_e, max_step) / h_s (NaN for a rigid block).
    measured : dict
        The sample runs (empty if none ran): per method its wall time (s), θ_max,
        impacts and errors against the reference.
    """

    method: str
    reason: str
    stiffness: float
    measured: dict = field(default_factory=dict)

    def describe(self) -> dict:
        """JSON-ready."""
        return {
            "method": self.method,
            "reason": self.reason,
            "stiffness": None if math.isnan(self.stiffness) else self.stiffness,
            "measured": self.measured,
        }


def _why_not(structure, options: SimulationOptions) -> str | None:
    """Why the exponential method cannot run this sweep, or None."""
    if options.backend != "compiled" or options.integrator != "solve_ivp":
        return "the exponential method runs on the compiled path only (backend='compiled')"
    if structure.n < 1:
        return "a rigid block has no elastic modes for the exponential method"
    from ..engines.fast.rocking_modes import RockingModes  # numba: "compiled" only

    modes = RockingModes.of(structure)
    return f"{structure.name}: {modes}" if isinstance(modes, str) else None


def choose_method(
    structure, excitation, t_end: float, impact, seed, options: dict, progress=None
) -> MethodChoice:
    """The method of a sweep whose runs are like this sample run (`method="auto"`).

    Parameters
    ----------
    structure : Structure
    excitation, t_end, impact, seed :
        The sample run: the sweep's longest.
    options : dict
        The sweep's other options (`multimass.simulate`'s keywords, without ``method``).
    progress : bool or None
        The sweep's: False shows no bar for the sample runs; else a bar if one is long.

    Returns
    -------
    MethodChoice
    """
    o = SimulationOptions.of(None, **options | {"seed": seed, "method": "DOP853"})
    s = stiffness(structure, o.max_step) if structure.n else math.nan
    why = _why_not(structure, o)
    if why is not None:
        return MethodChoice("DOP853", f"DOP853: {why}", s)
    h_s = DOP853_STABILITY / spectral_radius(structure)
    if s < STIFF:
        return MethodChoice(
            "DOP853",
            f"DOP853: {structure.name} is not stiff: S = {s:.3g} < {STIFF:g} (DOP853's stable "
            f"step {h_s:.3g} s against the exponential method's ~{min(EXPONENTIAL_STEP, o.max_step):.3g} "
            "s), where DOP853 was measured as fast or faster",
            s,
        )
    shown = False if progress is False else None
    return _by_sample(structure, excitation, t_end, impact, seed, options, s, o.rtol, shown)


def _by_sample(st, excitation, t_end, impact, seed, options, s, rtol, shown) -> MethodChoice:
    """The choice from the sample run each way (timed by `simulate_outcome`, kernels loaded
    before its clock), checked against each other and, if they differ, a reference."""
    run = dict(options) | {"seed": seed, "progress": shown}  # None: a bar if a run is long
    got = {m: simulate_outcome(st, excitation, impact, t_end, **run | {"method": m}) for m in _BOTH}
    wall = {m: float(got[m].wall_time_s) for m in _BOTH}
    dop, exp = got["DOP853"], got["exponential"]
    floor = {"theta": FLOOR * rtol * abs(dop.theta_max), "impact": FLOOR * rtol * t_end}
    apart = _errors(exp, dop)
    measured = {m: {"wall_time_s": wall[m]} for m in _BOTH}
    if _within(apart, floor):
        basis = f"it agrees with DOP853 to {FLOOR:g} × rtol"
        measured["exponential"] |= {"against_DOP853": apart}
        accurate = True
    else:  # which is right? DOP853 at tighter tolerances says
        tight = {
            "method": "DOP853",
            "rtol": rtol / REFERENCE_FACTOR,
            "atol": SimulationOptions.of(None, **options).atol / REFERENCE_FACTOR,
        }
        ref = simulate_outcome(st, excitation, impact, t_end, **run | tight)
        errors = {m: _errors(got[m], ref) for m in _BOTH}
        for m in _BOTH:
            measured[m] |= {"against_reference": errors[m]}
        bound = {
            k: max(floor[k], math.inf if errors["DOP853"][k] is None else errors["DOP853"][k])
            for k in floor
        }
        accurate = _within(errors["exponential"], bound)
        basis = f"as accurate as DOP853 against DOP853 at rtol/{REFERENCE_FACTOR:g}"
    ratio = wall["DOP853"] / wall["exponential"]
    head = (
        f"S = {s:.3g} ≥ {STIFF:g}; sample run DOP853 {wall['DOP853']:.3g} s, "
        f"exponential {wall['exponential']:.3g} s"
    )
    if not accurate:
        return MethodChoice(
            "DOP853", f"DOP853: {head}, but the exponential run was less accurate", s, measured
        )
    if ratio <= 1.0:
        return MethodChoice("DOP853", f"DOP853: {head} (not faster)", s, measured)
    return MethodChoice(
        "exponential", f"exponential: {head} ({ratio:.3g}× faster), {basis}", s, measured
    )


def _within(e: dict, bound: dict) -> bool:
    """As many impacts, and θ_max and the impact times within `bound`."""
    return e["same_impacts"] and e["theta"] <= bound["theta"] and e["impact"] <= bound["impact"]


def _errors(r, ref) -> dict:
    """θ_max and impact-time errors of outcome `r` against `ref` (None: not as many impacts)."""
    a = np.array([e.time for e in r.events if e.kind == "impact"])
    b = np.array([e.time for e in ref.events if e.kind == "impact"])
    same = a.size == b.size
    return {
        "theta_max": float(r.theta_max),
        "n_impacts": int(a.size),
        "same_impacts": bool(same),
        "theta": float(abs(r.theta_max - ref.theta_max)),
        "impact": (float(np.abs(a - b).max()) if a.size else 0.0) if same else None,
    }


def sweep_method(structure, options: dict) -> dict:
    """A sweep's options with its default method: ``method="auto"`` for a column on the
    compiled path that names none (its spectra and suites run the exponential method
    where their sample run shows it faster and as accurate; a bundled specimen keeps
    DOP853 without a run, S < `STIFF`), else the options as given (DOP853 by default)."""
    column = getattr(structure, "n", 0) > 0
    if column and "method" not in options and options.get("backend") == "compiled":
        return options | {"method": AUTO}
    return options


def resolve(
    structure, excitation, t_end: float, seed, options: dict, progress=None
) -> tuple[dict, dict]:
    """A sweep's options with ``method="auto"`` replaced by `choose_method`'s choice for
    its sample run (`progress`: the sweep's), and what to report
    (``{"method_choice": ...}``; empty if not "auto")."""
    if options.get("method") != AUTO:
        return options, {}
    rest = {k: x for k, x in options.items() if k not in ("method", "impact")}
    impact = options.get("impact", "DD2")
    choice = choose_method(structure, excitation, t_end, impact, seed, rest, progress)
    return options | {"method": choice.method}, {"method_choice": choice.describe()}
