"""Checks of an event-driven contact run (`multimass.engines.contact_dynamics`), and its validators.

Three checks, reported per the package's run-status contract (a ``checks``
dict name → {"value", "limit", "passed"} and one warning line per failure):

* ``energy_balance`` — the ledger's largest balance error
  ``|E(t) − E(t0) − W_ground + D + losses|`` over the run, relative to the run's
  energy scale max(``|E(t0)|``, max ``|W_ground|``) (the scale of `multimass bench`);
  limit 1e-3, the project's energy-drift limit. The scale is floored at
  ``|h(t0)|`` · gap_tol, the work of the initial forces over the gap tolerance
  (the energy the contact geometry resolves), so that a run at rest is not
  judged on the round-off of its potential energy.
* ``projection`` — the energy changed by housekeeping outside the physics
  (drift projections of q and q̇ onto the closed contacts at phase starts),
  summed in absolute value, relative to the same scale; limit 1e-3. The
  ledger books it (``projection_loss``), so it cannot hide a loss; this check
  says when it is large enough to matter.
* ``friction_smooth`` / ``friction_impact`` — only when the user gives a
  friction coefficient μ: the largest friction demand ``|λ_T|``/λ_N of the run
  (`FrictionDemand`) against μ.

Why sticking contacts demand friction
-------------------------------------
Paper 000 assumes that closed contacts stick (ġ_T = 0, Section 2.1 and
Eq 5): the tangential force or impulse is whatever sticking needs, however
large. A real interface with Coulomb friction μ sticks only while
``|λ_T|`` ≤ μ λ_N. The demand grows

* in smooth rocking when the pivot's normal force drops: the centripetal
  acceleration R φ̇² of the centre of mass points from the centre of mass to
  the pivot, nearly horizontally for a squat block (h < b), so it loads the
  pivot tangentially while it unloads it normally; the ratio → ∞ as the pivot
  lifts off into flight with a tangential force still acting (reported as
  ``inf``);
* at impacts: for the block of paper 000 the closed forms give
  ``|Λ_T|``/Λ_N = cot α = h/b for a stocky block (full contact, Eqs 14–15, 20–21)
  and 3 sin α cos α / (4 − 3 sin² α) for a slender one (Eqs 17–18, 22–23),
  in both the compression and the expansion phase; a squat block therefore
  needs μ ≥ h/b at every impact, a slender one little;
* in full contact under a ground acceleration a_g: ``|T|``/N = ``|a_g|``/g for a
  rigid block, the classical sliding condition;
* when a corner lands while slipping (after a flight): sticking stops the
  slip with a tangential impulse even when the normal impulse is small.

Where several closed contacts share one tangential direction (both corners
of a block in full contact: paper 000, Eq 13 uses one resultant W_T) the
split of the tangential force between them is indeterminate; the demand is
that of the resultant, ``|Σλ_T|`` / Σλ_N, the smallest μ that any split can
satisfy. A closed contact whose tangential direction is dependent on the
others without being parallel to one of them is given no tangential force,
so the demand reported is then an upper bound.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..validation import number

__all__ = [
    "ENERGY_LIMIT",
    "PROJECTION_LIMIT",
    "FrictionDemand",
    "tangential_groups",
    "friction_ratio",
    "impact_ratio",
    "run_checks",
    "validate_mu",
    "checked_ground",
    "ground_excitation",
]

ENERGY_LIMIT = 1e-3  # the project's energy-drift limit (benchmarks/failures.py)
PROJECTION_LIMIT = 1e-3  # housekeeping energy, same fraction of the energy scale
FRICTION_RTOL = 1e-9  # a demand equal to μ to round-off (e.g. h/b = μ) passes


@dataclass(frozen=True)
class FrictionDemand:
    """Largest friction ratio ``|λ_T|``/λ_N that sticking needs during a run.

    Attributes
    ----------
    smooth : float
        Over the smooth phases (contact forces of the closed, sticking
        contacts, sampled at every integration step and refined around the
        largest); ``inf`` when a contact unloads while carrying a tangential
        force (a lift-off into flight).
    smooth_time : float or None
        Time of that maximum (s); None when no phase had a sticking contact.
    impact : float
        Over the Poisson impacts: the largest ratio of tangential to normal
        impulse, compression and expansion phases taken apart (paper 000,
        Eqs 5 and 10). A "zeno_rest" (velocity projection ending an
        accumulation of vanishing impacts) is not counted.
    impact_time : float or None
        Time of that impact (s); None without impacts.
    """

    smooth: float = 0.0
    smooth_time: float | None = None
    impact: float = 0.0
    impact_time: float | None = None

    @property
    def largest(self) -> float:
        return max(self.smooth, self.impact)


def validate_mu(mu) -> float | None:
    """`mu` as a float (None stays None); finite and positive, else InputError."""
    if mu is None:
        return None
    try:
        x = float(mu)
    except (TypeError, ValueError):
        raise InputError(
            f"`mu` = {mu!r}: expected a friction coefficient, a positive "
            "number such as 0.7, or None not to check friction"
        ) from None
    if not (math.isfinite(x) and x > 0.0):
        raise InputError(
            f"`mu` = {mu!r}: the friction coefficient must be finite and > 0 "
            "(e.g. 0.7); pass None not to check friction"
        )
    return x


def tangential_groups(WT: np.ndarray, S, tk, rtol: float = 1e-9) -> tuple[tuple[int, ...], ...]:
    """For each kept tangential column `tk[i]`, the positions in `S` of the contacts
    whose tangential direction is parallel (or antiparallel) to it."""
    out = []
    for j in tk:
        w = WT[:, j]
        nw = np.linalg.norm(w)
        out.append(
            tuple(
                p
                for p, i in enumerate(S)
                if abs(WT[:, i] @ w) >= (1.0 - rtol) * np.linalg.norm(WT[:, i]) * nw
            )
        )
    return tuple(out)


def friction_ratio(lam_N: np.ndarray, lam_T: np.ndarray, groups, tol: float) -> float:
    """Largest ``|Σλ_T|`` / Σλ_N over the groups (module docstring).

    ``inf`` when a group carries a tangential force with no normal force
    (Σλ_N ≤ `tol` < ``|λ_T|``); a group carrying neither counts 0.
    """
    worst = 0.0
    for T, grp in zip(lam_T, groups):
        N = float(sum(lam_N[p] for p in grp))
        if N > tol:
            worst = max(worst, abs(T) / N)
        elif abs(T) > tol:
            return math.inf
    return worst


def impact_ratio(res, groups) -> float:
    """Largest tangential/normal impulse ratio of a `PoissonImpact`, per phase (Eqs 5, 10)."""
    parts = (
        (res.impulse_compression, res.tangential_impulse_compression),
        (res.impulse_expansion, res.tangential_impulse_expansion),
    )
    scale = max(max(np.abs(a).max(initial=0.0), np.abs(b).max(initial=0.0)) for a, b in parts)
    if scale == 0.0:
        return 0.0
    return max(friction_ratio(N, T, groups, 1e-9 * scale) for N, T in parts)


def _check(value: float, limit: float, rtol: float = 0.0) -> dict:
    return {
        "value": float(value),
        "limit": float(limit),
        "passed": bool(value <= limit * (1.0 + rtol)),
    }


def _friction_warning(kind: str, value: float, t, mu: float) -> str:
    need = (
        "unbounded friction (a contact unloads while it carries a tangential force)"
        if math.isinf(value)
        else f"a friction coefficient |T/N| = {value:.3g}"
    )
    where = "in a smooth phase" if kind == "smooth" else "at an impact"
    return (
        f"sticking contacts need {need} {where} at t = {t:.6g} s, above mu = {mu:g}: "
        "the contact would slide there and the sticking model (paper 000) does not hold "
        "after it; treat the response as unreliable from that time"
    )


def run_checks(
    energy,
    ledger_error,
    ground_work,
    projection_abs: float,
    demand: FrictionDemand,
    mu: float | None,
    floor: float = 0.0,
) -> tuple[dict, tuple[str, ...]]:
    """The ``checks`` dict and the warnings of a contact run (module docstring).

    `floor` is the smallest energy scale (J), ``|h(t0)|`` · gap_tol in `simulate_contacts`.
    """
    scale = max(abs(float(energy[0])), float(np.max(np.abs(ground_work))), floor, 1e-300)
    err = float(np.max(np.abs(ledger_error))) / scale
    proj = projection_abs / scale
    checks = {
        "energy_balance": _check(err, ENERGY_LIMIT),
        "projection": _check(proj, PROJECTION_LIMIT),
    }
    warnings = []
    if not checks["energy_balance"]["passed"]:
        warnings.append(
            f"energy balance error {err:.3g} of the energy scale {scale:.4g} J "
            f"exceeds {ENERGY_LIMIT:g}: tighten rtol/atol"
        )
    if not checks["projection"]["passed"]:
        warnings.append(
            f"drift projections changed the energy by {proj:.3g} of the energy "
            f"scale {scale:.4g} J (limit {PROJECTION_LIMIT:g}): tighten rtol/atol, "
            "or check that the initial state satisfies the closed contacts"
        )
    if mu is not None:
        for kind in ("smooth", "impact"):
            value, t = getattr(demand, kind), getattr(demand, f"{kind}_time")
            checks[f"friction_{kind}"] = _check(value, mu, FRICTION_RTOL)
            if not checks[f"friction_{kind}"]["passed"]:
                warnings.append(_friction_warning(kind, value, t, mu))
    return checks, tuple(warnings)


# ------------------------------------------------------------------ argument validation


def _number(name, value, *, low=None, strict=True, finite=True) -> float:
    """`value` as a float, finite (unless `finite` is False) and above `low`, else InputError."""
    return number(name, value, low=low, low_open=strict, allow_inf=not finite)


def _state(name, value, n) -> np.ndarray:
    try:
        a = np.array(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"`{name}` = {value!r}: expected {n} numbers") from None
    if a.shape != (n,) or not np.all(np.isfinite(a)):
        raise InputError(f"`{name}` = {value!r}: expected {n} finite numbers (shape ({n},))")
    return a


def _options(k, eps_p, t0, t_end, kw) -> tuple[np.ndarray, float, float, dict]:
    """Validate the scalar arguments of `simulate_contacts`."""
    try:
        eps = np.broadcast_to(np.asarray(eps_p, dtype=float), (k,)).copy()
    except (TypeError, ValueError, OverflowError):
        raise InputError(
            f"`eps_p` = {eps_p!r}: expected one Poisson coefficient in [0, 1], "
            f"or {k}, one per contact"
        ) from None
    if not np.all((eps >= 0.0) & (eps <= 1.0)):
        raise InputError(f"`eps_p` = {eps_p!r}: Poisson's coefficient must lie in [0, 1]")
    t0 = _number("t0", t0)
    t_end = _number("t_end", t_end)
    if not t_end > t0:
        raise InputError(f"`t_end` = {t_end!r}: must exceed the start time {t0}")
    for name in ("rtol", "atol", "gap_tol", "locked_dt"):
        kw[name] = _number(name, kw[name], low=0.0)
    kw["zeno_velocity"] = _number("zeno_velocity", kw["zeno_velocity"], low=0.0, strict=False)
    kw["max_step"] = _number("max_step", kw["max_step"], low=0.0, finite=False)
    if kw["dt_out"] is not None:
        kw["dt_out"] = _number("dt_out", kw["dt_out"], low=0.0)
    me = kw["max_events"]
    if isinstance(me, bool) or not (isinstance(me, (int, np.integer)) and me >= 1):
        raise InputError(f"`max_events` = {kw['max_events']!r}: expected an integer ≥ 1")
    return eps, t0, t_end, kw


def checked_ground(ag):
    """Wrap a ground acceleration ag(t) (m/s²) so that a value that is not a finite number
    raises InputError naming the time, instead of turning the run into NaN."""

    def wrapped(t):
        a = ag(t)
        try:
            x = float(a)
        except (TypeError, ValueError, OverflowError):
            x = math.nan
        if not math.isfinite(x):
            raise InputError(
                f"`ag` returned {a!r} at t = {t:.6g} s: the ground acceleration "
                "must be a finite number (m/s²) at every time of the run"
            )
        return x

    return wrapped


def ground_excitation(ag):
    """(checked ag(t), time after which ag = 0, breakpoints) of an optional excitation."""
    if ag is None:
        return (lambda t: 0.0), 0.0, ()
    if not callable(ag):
        raise InputError(
            f"`ag` = {ag!r}: expected a callable ag(t) in m/s², e.g. "
            "SineWave(amplitude=..., omega=...)"
        )
    quiet = _number(
        "ag.duration", getattr(ag, "duration", math.inf), low=0.0, strict=False, finite=False
    )
    bps = tuple(getattr(ag, "breakpoints", ()))
    checked = checked_ground(ag)
    checked(0.0)  # fail at the entry, not mid-run
    return checked, quiet, bps
