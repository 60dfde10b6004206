"""Accuracy checks of a finished run, and the status they decide.

A run ends with a physical *outcome* — "completed" (reached t_end, or came to rest),
"overturned", or "failed" (the solver could not go on). Its *status* is that outcome
unless an accuracy check failed, in which case the status is "inaccurate": the run
finished, but its numbers are not to be trusted, and `warnings` says why and what to
do. A result never passes as normal when its checks fail.

The energy ledger (kinetic + gravitational + elastic energy, cumulative damping and
impact losses, work of the ground) must close: its largest balance error, relative to
the run's energy scale, must not exceed ``energy_tol`` (default 1e-3, the limit at which
`multimass bench` reports "energy drift"). At the default tolerances the bundled
specimens close to ≤ 2e-8 (README, Energy ledger).

The energy scale is the largest of the initial energy, the work of the ground, the
energy (`energy_scale`) and a floor, `scale_floor` = `energy_floor` / ``energy_tol``:
`energy_floor` (m_t g B · atol, the work of the restoring moment over the solver's
absolute tolerance on θ) is the smallest energy the solver resolves, so a balance error
below it passes whatever the run's energies. Without it a block that barely lifts (B6M
under a sine at a0/(α g) = 1.018, θ_max = 3.9e-8 rad, ledger energies of 1e-8 J) was
judged on round-off: a balance error of 2.3e-13 J, a hundredth of the floor, against
an end-of-run scale of 2e-10 J. `balance_error` is the one rule every engine applies
(solve_ivp, the compiled paths and their batched kernels, Newmark).
"""

from __future__ import annotations

from .result import OUTCOMES, STATUSES, status_of, with_fields

__all__ = [
    "STATUSES",
    "OUTCOMES",
    "energy_floor",
    "scale_floor",
    "energy_scale",
    "balance_error",
    "energy_check",
    "judge",
]


def energy_floor(structure, atol: float) -> float:
    """The work of the restoring moment m_t g B over an angle of `atol` (J).

    Energy differences below it are below the solver's absolute tolerance on θ.
    """
    return float(atol) * structure.m_t * structure.g * structure.B


def scale_floor(structure, atol: float, energy_tol: float) -> float:
    """The smallest energy scale of a ledger (J): ``energy_floor / energy_tol``.

    With it, a balance error at most `energy_floor` (what the solver resolves) is at most
    `energy_tol` of the scale, so it passes; a larger one is judged on the run's energies.
    """
    return energy_floor(structure, atol) / float(energy_tol)


def energy_scale(e0, ground_work, energy, floor):
    """The energy scale of a ledger: ``max(|E(0)|, |W_g|, |E|, floor)`` (J, > 0).

    Plain arithmetic, so the compiled kernels run this source (`multimass.engines.fast._maths`).
    """
    return max(abs(e0), abs(ground_work), abs(energy), floor, 1e-300)


def balance_error(balance, e0, ground_work, energy, floor):
    """``|balance|`` over `energy_scale` (`floor`: `scale_floor`): the value that
    `energy_check` compares with ``energy_tol``."""
    return abs(balance) / energy_scale(e0, ground_work, energy, floor)


def energy_check(error: float, limit: float) -> dict:
    """The energy-ledger check: ``{"value", "limit", "passed"}``."""
    return {"value": float(error), "limit": float(limit), "passed": bool(error <= limit)}


def _energy_warning(check: dict) -> str:
    return (
        f"energy ledger does not close: balance error {check['value']:.3g} of the energy "
        f"scale (limit {check['limit']:.3g}); the solution is not accurate — tighten "
        "rtol/atol (e.g. rtol=1e-10, atol=1e-12) or shorten max_step"
    )


def judge(result, energy_tol: float):
    """`result` (a Response or an Outcome) with its checks, status, outcome and warnings.

    Parameters
    ----------
    result : Response or Outcome
        With ``status`` set to the physical outcome and ``energy_balance_error``.
    energy_tol : float
        Largest accepted energy balance error (share of the energy scale).

    Returns
    -------
    The same type, with ``outcome`` (the physical end), ``checks``, ``warnings``
    and ``status`` ("inaccurate" if a check failed and the run did not fail).
    """
    outcome = result.outcome or result.status
    checks = dict(result.checks)
    warnings = list(result.warnings)
    if outcome != "failed":
        checks["energy_balance"] = energy_check(result.energy_balance_error, energy_tol)
        if not checks["energy_balance"]["passed"]:
            warnings.append(_energy_warning(checks["energy_balance"]))
    status = status_of(outcome, all(c["passed"] for c in checks.values()))
    return with_fields(
        result, status=status, outcome=outcome, checks=checks, warnings=tuple(warnings)
    )
