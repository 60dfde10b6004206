"""How much one `simulate` run will cost, estimated from its inputs before it starts.

Explicit Runge–Kutta methods (DOP853, RK45, RK23; solve_ivp or the compiled path) take
steps no longer than c/ρ, where ρ is the spectral radius of the structure's linear
state matrix [[0, I], [−M⁻¹K, −M⁻¹C]] (its stiffest, or most heavily damped, mode) and c
the extent of the method's stability region; and no longer than ``max_step``. Measured
on this machine kind (2026-11-23; S1–S3 released from 0.1 rad, DD2, 2 s, E_s × 1, 20 and
2000, compiled path): DOP853 took t_end ρ/3.4 … t_end ρ/6.4 steps of 12 right-hand
sides, RK45 t_end ρ/1.7 … /2.8 steps of 6, RK23 (accuracy-limited at rtol 1e-8)
t_end ρ/0.2 … /2.5 steps of 3. A right-hand side cost 0.3–0.6 µs compiled and
44–62 µs through solve_ivp. The implicit methods (Radau, BDF, LSODA) are not limited
by ρ: S1 over 1 s took 31 631 (Radau), 9 342 (BDF) and 10 061 (LSODA) right-hand sides,
0.6–3.2 s. Paper 004's Newmark integrator costs ~1.3 µs per Newton iteration, a few
per step of ``dt``.

Each output sample costs its recording, its accelerations (paper 001, Eq 7) and its
ledger: 7–15 µs per row (2026-11-28; B6M and S1 released, output_dt = 1e-5 s, compiled
and SciPy paths). An output larger than `OUTPUT_BUDGET` is refused (`check_output`): a
run of 10⁷ rows was silent for minutes, and its CSV would take 10 more (22–77 µs per row).

The constants below take the slow end of each range, so a run is never estimated
cheaper than it is by more than the spread of the measurements.
"""

from __future__ import annotations

import math

import numpy as np

from .errors import InputError
from .model.structure import derived_once
from .progress import RunCost, format_bytes

__all__ = [
    "spectral_radius",
    "stiffness",
    "stable_step",
    "STIFF",
    "DOP853_STABILITY",
    "EXPLICIT_METHODS",
    "EXPONENTIAL_STEP",
    "simulation_cost",
    "series_columns",
    "check_output",
    "OUTPUT_BUDGET",
]

#: Largest output a run may produce (bytes of float64 samples): 1 GiB, some 10⁶ rows of a
#: column's series or 7·10⁶ of a block's — minutes to write as CSV, more than any plot or
#: comparison needs (a 10 s test sampled at 100 kHz).
OUTPUT_BUDGET = float(2**30)

# method -> (stability extent c, right-hand sides per step), see the module docstring
_EXPLICIT = {"DOP853": (3.4, 12), "RK45": (1.7, 6), "RK23": (0.2, 3)}
#: The explicit Runge–Kutta methods, whose steps stability holds to c/ρ (`stable_step`).
EXPLICIT_METHODS = tuple(_EXPLICIT)
#: DOP853's stability extent c along the negative real axis: its steps stay ≤ c/ρ.
DOP853_STABILITY = _EXPLICIT["DOP853"][0]
_RHS_SECONDS = {"compiled": 0.6e-6, "scipy": 60e-6}  # per right-hand side, N ≈ 5
_IMPLICIT_RHS_SECONDS = 200e-6  # solve_ivp Radau/BDF/LSODA
_NEWMARK_STEP_SECONDS = 5e-6  # a few Newton iterations
_IMPLICIT_STEPS_PER_CAP = 3.0  # steps per max_step (≤ 5 ms)
_ACCURACY_STEP = 5e-3  # s, a smooth motion's step
# the exponential rocking integrator (multimass.engines.fast._exp_kernel): a step's cost in
# right-hand sides (6 calls and the modal transforms: 4.8 µs a step for S1 released,
# 5.7 µs under El Centro, in whole runs) and its typical step (S1 released, rtol 1e-8:
# 2 ms; benchmarks/exponential_rocking.py)
_EXPONENTIAL_RHS_PER_STEP = 8
#: The exponential method's typical step (s), set by accuracy alone.
EXPONENTIAL_STEP = 2e-3

_ROW_SECONDS = 20e-6  # per output row, see the module docstring

#: The stiffness ratio (`stiffness`) from which the exponential method is worth running
#: (`multimass.sweeps.method_choice`: the bundled columns have S ≈ 2–2.4, where DOP853
#: is as fast; the 20-node column S ≈ 88, where it is 13–45× slower).
STIFF = 10.0


def series_columns(n: int) -> int:
    """Columns of a run's series for a structure of `n` elastic nodes: the states, the
    accelerations and the ledger, float64 (an upper bound on `Response.series`)."""
    return 6 * int(n) + 19


def check_output(field: str, value, rows: float, columns: int, fix: str) -> float:
    """The output's size (bytes, rows × columns × 8); `InputError` past `OUTPUT_BUDGET`.

    Parameters
    ----------
    field : str
        What sets the size, as the user gave it (e.g. "`output_dt` (--output-dt)").
    value :
        Its value, shown in the message.
    rows, columns :
        The output's rows and float64 columns.
    fix : str
        What to change.
    """
    size = float(rows) * int(columns) * 8.0
    if not size <= OUTPUT_BUDGET:
        raise InputError(
            f"{field} = {value:g}: the output would hold {rows:.3g} rows × {columns} "
            f"columns ({format_bytes(size)}), more than the {format_bytes(OUTPUT_BUDGET)} an "
            f"output may use; {fix}"
        )
    return size


def spectral_radius(structure) -> float:
    """Largest ``|λ|`` of the full-contact state matrix (rad/s); 0 for a rigid body.

    The rocking phase couples θ to u but leaves the stiffest modes nearly
    unchanged (S1: 280.7 Hz in full contact, 281.0 Hz uplifted), so the
    full-contact value sets the explicit step of both phases.
    """
    return derived_once(structure, "spectral_radius", _spectral_radius)


def stable_step(structure, method: str) -> float:
    """The longest step (s) stability allows explicit Runge–Kutta `method` (DOP853, RK45,
    RK23) on `structure`: c/ρ (`spectral_radius`); inf for a rigid body."""
    rho = spectral_radius(structure)
    return _EXPLICIT[method][0] / rho if rho > 0.0 else math.inf


def stiffness(structure, max_step: float = math.inf) -> float:
    """S = min(h_e, max_step) / h_s: the DOP853 steps that stability forces per step of the
    exponential method (h_s = 3.4/ρ, `spectral_radius`; h_e ≈ 2 ms, what accuracy needs);
    NaN for a rigid body."""
    rho = spectral_radius(structure)
    if rho == 0.0:
        return math.nan
    return min(EXPONENTIAL_STEP, float(max_step)) * rho / DOP853_STABILITY


def _spectral_radius(structure) -> float:
    n = int(structure.n)
    if n == 0:
        return 0.0
    minv = 1.0 / np.asarray(structure.m, dtype=float)
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -minv[:, None] * np.asarray(structure.K, dtype=float)
    A[n:, n:] = -minv[:, None] * np.asarray(structure.C, dtype=float)
    lam = np.linalg.eigvals(A)
    return float(np.max(np.abs(lam))) if np.all(np.isfinite(lam)) else math.inf


def _explicit_steps(t_end, rho, method, max_step) -> tuple[float, int, str]:
    c, per_step = _EXPLICIT[method]
    stiff = t_end * rho / c
    # without a cap, smooth rocking still takes steps of a few ms (B6M: 4.8 ms at rtol 1e-8)
    cap = min(max_step, _ACCURACY_STEP)
    capped = t_end / cap
    if stiff >= capped:
        basis = (
            f"{method} steps ≤ {c / rho:.2g} s, set by the stiffest mode of the structure "
            f"(|λ| = {rho:.3g} rad/s, {rho / (2 * math.pi):.3g} Hz)"
        )
        return stiff, per_step, basis
    return capped, per_step, f"steps of ≤ {cap:g} s over t_end = {t_end:g} s"


def simulation_cost(
    structure,
    t_end: float,
    *,
    method: str,
    max_step: float,
    output_dt: float | None,
    backend: str,
    integrator: str,
    dt: float | None = None,
) -> RunCost:
    """Estimated steps, wall time and output memory of one `simulate` run.

    Parameters
    ----------
    structure : Structure
    t_end : float
        End time (s).
    method, max_step, output_dt, backend, integrator, dt :
        As in `multimass.simulate` (a `method` that is an OdeSolver class counts
        as implicit).

    Returns
    -------
    RunCost
    """
    n = int(structure.n)
    size = 1.0 + (n / 20.0) ** 2  # matrix-vector work grows with N²
    if integrator == "newmark":
        steps = t_end / dt
        seconds = steps * _NEWMARK_STEP_SECONDS
        basis = f"Newmark steps of dt = {dt:g} s over t_end = {t_end:g} s"
    elif method == "exponential":  # no mode limits its step: accuracy does (S1: ~2 ms)
        cap = min(max_step, EXPONENTIAL_STEP)
        steps = t_end / cap
        seconds = steps * _EXPONENTIAL_RHS_PER_STEP * _RHS_SECONDS[backend] * size
        basis = f"exponential steps of ~{cap:g} s over t_end = {t_end:g} s"
    elif isinstance(method, str) and method in _EXPLICIT:
        rho = spectral_radius(structure)
        steps, per_step, basis = _explicit_steps(t_end, rho, method, max_step)
        seconds = steps * per_step * _RHS_SECONDS[backend] * size
    else:
        cap = min(max_step, _ACCURACY_STEP)
        steps = _IMPLICIT_STEPS_PER_CAP * t_end / cap
        seconds = steps * (2 * n + 5) * _IMPLICIT_RHS_SECONDS * size
        basis = f"implicit steps of ~{cap / _IMPLICIT_STEPS_PER_CAP:.2g} s over t_end = {t_end:g} s"
    rows = 0.0 if output_dt is None else t_end / output_dt
    memory = rows * 8.0 * series_columns(n)  # states + the series' columns, float64
    seconds += rows * _ROW_SECONDS
    if rows:
        basis += f"; {rows:.3g} output samples (t_end / output_dt)"
    return RunCost(steps=steps, seconds=seconds, memory=memory, basis=basis)
