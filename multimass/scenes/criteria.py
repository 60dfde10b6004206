"""A-priori adequacy criteria: is a rung good enough for a scene, before running it?

Every criterion is cheap — from the specimen, a static deflection, the linearised
modal analysis of the full model (paper 001 §3) and a *linear* full-contact modal
response to the excitation — and is checked for each rung against a *budget*: the tolerance as a
fraction (relative tolerances as they are; absolute ones divided by a scale of the
answer: ``|θ0|`` for released rotations, α_cg for forced ones, g for released
accelerations, the peak linear acceleration for forced ones, the first uplifted
frequency for frequencies). `multimass.choose` picks the cheapest rung that passes
all its criteria; `verify` then measures the real difference.

Columns. φ_j, ω_j, ζ_j: full-contact modes (mass-normalised), L_j = φ_jᵀM1,
Lθ_j = φ_jᵀMH; a rung keeps n modes (rigid n = 0, SDOF n = 1, column n = N).

C1  rigid only: ω₁ / p_l ≥ 10. The superstructure's first period is short against
    rocking's time scale 1/p_l, so it moves as a rigid body between impacts. Source:
    paper 001 §4.2 (the rocking eigenvalue is ±p_l of the rigid body and "weakly
    coupled with elastic response"); the threshold 10 is this toolkit's judgement
    (S1–S3 have 14.5–18.7 and their released rigid equivalents come within 1.3–2 % of
    the flexible θ_max; S1 with E_s/100 has ω₁/p_l = 2.2, and there even the SDOF is
    57 % off the 2-node column).
C2  uplift demand (forced only): ``λ_n = max_t |S ü_g + Σ_{j≤n} Lθ_j q̈_j| / (m_t g B)``,
    the peak overturning moment of the linear full-contact response with n modes over
    the restoring moment (λ > 1: it uplifts; paper 001 Eq 8).
    ``κ_n = |λ_N − λ_n| / (λ_N − 1)`` is how much the neglected modes change the excess over uplift; 0 if
    neither uplifts, ∞ if only one does. Pass: κ_n ≤ budget (judgement; S1's pulse of
    paper 001 §4.4, 0.4 g against g tan α_cg = 0.36 g, has κ_0 = 0.88: its rigid
    equivalent barely rocks, 0.001 rad, while the column rocks to 0.025 rad).
C3  impact transfer: ε_n = (1 − r̄)² Σ_{j>n} Lθ_j² / J_p, the share of rocking
    energy that an impact's jump in θ̇ moves into the neglected modes (their modal
    velocity jumps are Lθ_j Δθ̇; paper 001 §4.3: impacts excite the coupled modes).
    Pass: ε_n ≤ budget (judgement, an order-of-magnitude estimate).
C4  coupling (every question, rungs with n ≥ 1): a mode is coupled with rocking when
    its uplifted frequency (undamped linearised rocking system, paper 001 Eqs 19–21;
    the damped Foss values of Eq 25 differ by < 0.002 % for S1–S3, and the undamped
    ones exist even when Rayleigh damping overdamps a high mode) differs from its
    full-contact one by more than 5 %; n_c is the number of coupled modes from mode 1
    up. Pass: n ≥ n_c. Source: paper 001 §4.2
    (S1: modes 1, 2 shift by 175 % and 12 % and "interact strongly"; mode 3 shifts by
    0.1 % and does not); the 5 % threshold is this toolkit's judgement.
C5  impact share at the node (accelerations, when it rocks): s_k(n) = Σ_{j>n} c_j /
    Σ_j c_j with ``c_j = |φ_kj Lθ_j| ω_j``, the neglected modes' share of the
    acceleration an impact's θ̇ jump excites at node k. Pass: s_k(n) ≤ 0.25
    (judgement: it ignores damping and the finite impact duration, which both lower
    the high modes, so it overestimates; under paper 001's pulse, S1's A2 with
    s = 0.21 came within 0.1 % of the full column, S2's A2 with s = 0.31 and 0.49
    within 7 % and 18 %).
C6  linear acceleration (accelerations, forced): ``γ_n = |A_n − A_N| / A_N`` with A_n the
    peak of ü_g + Σ_{j≤n} φ_kj q̈_j at node k. Pass: γ_n ≤ budget.

    Rotation questions use C1 (rigid), C4 (n ≥ 1), C2, C3; overturning the same with a
    budget of 5 %; accelerations C1 (rigid), C4, C5 (if it rocks), C6; uplifted
    frequencies C4. (C4 for rotations: S1 with E_s/100 released from 0.08 rad passes
    C2–C3 with its SDOF, whose peak is 57 % off the 2-node column's; under El Centro
    the SDOF of S1, which has two coupled modes, is 48 % off. Where the SDOF is enough
    after all, the verification's downward walk finds it.)

Blocks.

B1  beam flexibility: δ / L with δ = m g L³ / (48 E I), the midspan deflection of the
    simply supported beam under the block's weight (paper 002 §6.3 defines Ē by
    δ = L/2500). Pass for the rigid block: δ/L ≤ 1/250 000 = 4e-6, i.e. E ≥ Ē·10².
    Source: paper 002 §6.3 — rocking "qualitatively replicates rocking on a rigid
    base ... up to the stiffness corresponding to a deflection of 10⁻³·L/250", and
    convergence is lost at L/2500. (The abstract's "stiffer than L/2500 behaves as a
    rigid base" is the looser reading; at L/2500 this toolkit's NSCD runs give
    13–38 % different second peaks, so the stricter limit is used.)
B2  rigid ground: the rigid block with Housner's η is the rigid-base limit of the
    NSCD model (paper 002 §6.2 compares its first peaks with Housner's); always passes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from scipy import signal

import multimass.modal as modal

from ..model.structure import column
from .reduce import modes

__all__ = [
    "Verdict",
    "assess",
    "column_indicators",
    "block_indicators",
    "linear_modal_response",
    "RATIO_RIGID",
    "COUPLING_SHIFT",
    "IMPACT_SHARE",
    "OVERTURN_BUDGET",
    "BEAM_RIGID",
]

RATIO_RIGID = 10.0  # C1: ω₁/p_l
COUPLING_SHIFT = 0.05  # C4: relative frequency shift on uplift
IMPACT_SHARE = 0.25  # C5: neglected share of the impact-excited acceleration
OVERTURN_BUDGET = 0.05  # C2/C3 budget of an overturning question
BEAM_RIGID = 1.0 / 250000  # B1: δ/L (paper 002 §6.3: 10⁻³ L/250)


@dataclass(frozen=True)
class Verdict:
    """The a-priori assessment of one rung: passes, and the checks behind it."""

    rung: str
    passes: bool
    checks: tuple = ()  # (name, value, threshold, ok) per criterion

    def reason(self) -> str:
        """The checks as text, e.g. "C1 ω₁/p_l = 18.7 ≥ 10 ok; C2 κ = 0.88 > 0.05 FAILS"."""
        rel = {("max", True): "≤", ("max", False): ">", ("min", True): "≥", ("min", False): "<"}
        return "; ".join(
            f"{n} = {_fmt(v)} {rel[kind, ok]} {_fmt(t)} {'ok' if ok else 'FAILS'}"
            for n, v, t, kind, ok in self.checks
        )

    def to_dict(self) -> dict:
        return {
            "rung": self.rung,
            "passes": self.passes,
            "checks": [
                {"name": n, "value": _num(v), "threshold": _num(t), "kind": kind, "ok": ok}
                for n, v, t, kind, ok in self.checks
            ],
        }


def _fmt(x) -> str:
    return "inf" if x == math.inf else f"{x:.3g}"


def _num(x):
    return None if x is None or (isinstance(x, float) and not math.isfinite(x)) else float(x)


def _check(name, value, threshold, kind="max"):
    ok = value <= threshold if kind == "max" else value >= threshold
    return (name, float(value), float(threshold), kind, bool(ok))


# ---------------------------------------------------------------------------- linear response
def _grid(excitation, omega1: float) -> np.ndarray:
    dt_rec = getattr(excitation, "dt", None)
    T = float(excitation.duration)
    dt = dt_rec / 4.0 if dt_rec else T / 20000.0  # a pulse's end jumps are smeared over dt
    t_end = T + 3.0 * 2.0 * math.pi / omega1  # three periods of free vibration after it
    return np.arange(0.0, t_end + 0.5 * dt, dt)


def linear_modal_response(st, excitation, omega, zeta, L):
    """Relative modal accelerations q̈_j(t) of the full-contact column under ü_g.

    q̈_j + 2ζ_j ω_j q̇_j + ω_j² q_j = −L_j ü_g, from rest; each mode discretised
    exactly for a piecewise-linear ü_g (first-order hold) and filtered.

    Returns
    -------
    t : ndarray, shape (T,)
    ag : ndarray, shape (T,)
    qdd : ndarray, shape (T, n_modes)
    """
    t = _grid(excitation, float(omega[0]))
    ag = np.asarray(excitation.acceleration(t), dtype=float)
    dt = t[1] - t[0]
    qdd = np.empty((t.size, omega.size))
    for j, (w, z, lj) in enumerate(zip(omega, zeta, L)):
        num, den = [-lj, 0.0, 0.0], [1.0, 2.0 * z * w, w * w]  # q̈/ü_g = −L s²/(s² + 2ζωs + ω²)
        b, a, _ = signal.cont2discrete((num, den), dt, method="foh")
        qdd[:, j] = signal.lfilter(np.ravel(b), np.ravel(a), ag)
    return t, ag, qdd


# ---------------------------------------------------------------------------- columns
def _mean_restitution(scene) -> float:
    r = scene.restitution
    if isinstance(r, (int, float)) and not isinstance(r, bool):
        return float(r)
    return 0.5 * (scene.spec.r_right + scene.spec.r_left)


def column_indicators(scene) -> dict:
    """Everything the column criteria need (cheap: modal analysis + linear response)."""
    st = column(scene.spec)
    n = st.n
    omega, Phi = modes(st)
    a0, a1 = st.rayleigh
    zeta = a0 / (2.0 * omega) + a1 * omega / 2.0
    L, Lt = Phi.T @ st.m, Phi.T @ (st.m * st.H)
    fn, fu = _undamped_frequencies_hz(st)
    shift = np.abs(fu / fn - 1.0)
    try:  # the damped Foss analysis, for the MAC values
        mac = np.diag(modal.analyse(st).mac_full_vs_compound()).tolist()
    except modal.ModalError:  # a structure the modal analysis cannot take
        mac = None
    n_c = int(np.argmin(shift > COUPLING_SHIFT)) if not np.all(shift > COUPLING_SHIFT) else n
    r = _mean_restitution(scene)
    tail = np.r_[np.cumsum((Lt**2)[::-1])[::-1], 0.0]  # Σ_{j>n} Lθ_j², n = 0..N
    out = {
        "omega1_rad_s": float(omega[0]),
        "p_l_rad_s": st.p_l,
        "omega1_over_p_l": float(omega[0] / st.p_l),
        "full_contact_hz": fn.tolist(),
        "uplifted_hz": fu.tolist(),
        "frequency_shift": shift.tolist(),
        "mac_full_vs_compound": mac,
        "n_coupled": n_c,
        "restitution_mean": r,
        "epsilon": ((1.0 - r) ** 2 * tail / st.J_p).tolist(),
        "alpha_cg": st.alpha_cg,
        "first_uplifted_hz": float(fu[0]),
    }
    node = scene.node
    if node is not None:
        c = np.abs(Phi[node - 1] * Lt) * omega
        out["impact_share"] = (np.r_[np.cumsum(c[::-1])[::-1], 0.0] / c.sum()).tolist()
    if not scene.is_release:
        t, ag, qdd = linear_modal_response(st, scene.excitation, omega, zeta, L)
        cum = np.cumsum(qdd * Lt, axis=1)
        moment = st.static_moment * ag[:, None] + np.c_[np.zeros(t.size), cum]
        lam = np.abs(moment).max(axis=0) / (st.m_t * st.g * st.B)
        out["uplift_demand"] = lam.tolist()
        out["kappa"] = [_kappa(lam[k], lam[-1]) for k in range(n + 1)]
        if node is not None:
            acc = ag[:, None] + np.c_[np.zeros(t.size), np.cumsum(qdd * Phi[node - 1], axis=1)]
            peak = np.abs(acc).max(axis=0)
            out["linear_peak_acceleration"] = peak.tolist()
            out["gamma"] = (np.abs(peak - peak[-1]) / peak[-1]).tolist()
    return out


def _undamped_frequencies_hz(st) -> tuple[np.ndarray, np.ndarray]:
    """Full-contact and uplifted (rocking) vibration frequencies of the undamped linear
    systems (paper 001, Eqs 19–21 with C = 0; the eigenvectors of §4.2 are undamped too)."""
    from multimass.modal.linearisation import rocking

    rk = rocking(st)
    w2 = sla.eigh(rk.K, rk.M, eigvals_only=True)
    fu = np.sqrt(w2[w2 > 0.0]) / (2.0 * np.pi)  # the one negative value is rocking, −p_l²
    return st.full_contact_omega / (2.0 * np.pi), fu


def _kappa(lam_n: float, lam_full: float) -> float:
    if lam_n <= 1.0 and lam_full <= 1.0:
        return 0.0  # neither uplifts: both answer "no rocking"
    if (lam_n > 1.0) != (lam_full > 1.0):
        return math.inf
    return abs(lam_full - lam_n) / (lam_full - 1.0)


def _budget(scene, ind: dict) -> float:
    tol, q = scene.tol, scene.question
    if q.kind == "overturning":
        return OVERTURN_BUDGET
    if tol.relative:
        return tol.value
    if q.kind == "peak_rotation":
        scale = abs(scene.excitation.theta0) if scene.is_release else ind["alpha_cg"]
    elif q.kind == "peak_acceleration":
        scale = scene.spec.g if scene.is_release else ind["linear_peak_acceleration"][-1]
    else:
        scale = ind["first_uplifted_hz"]
    return tol.value / scale


def _column_verdict(rung, scene, ind: dict, budget: float) -> Verdict:
    k, N, q = rung.n_modes, len(scene.spec.heights), scene.question.kind
    if k == N:
        return Verdict(rung.name, True, (("top of the ladder", 0.0, 0.0, "max", True),))
    checks = []
    if k == 0:
        checks.append(_check("C1 ω₁/p_l", ind["omega1_over_p_l"], RATIO_RIGID, "min"))
    if q in ("peak_rotation", "overturning"):
        if k > 0:
            checks.append(_check("C4 n", k, ind["n_coupled"], "min"))
        if "kappa" in ind:
            checks.append(_check("C2 κ", ind["kappa"][k], budget))
        checks.append(_check("C3 ε", ind["epsilon"][k], budget))
    elif q == "peak_acceleration":
        rocks = scene.is_release or ind["uplift_demand"][-1] > 1.0 or ind["uplift_demand"][k] > 1.0
        if rocks:
            checks.append(_check("C4 n", k, ind["n_coupled"], "min"))
            checks.append(_check("C5 s_k", ind["impact_share"][k], IMPACT_SHARE))
        if "gamma" in ind:
            checks.append(_check("C6 γ", ind["gamma"][k], budget))
    else:
        checks.append(_check("C4 n", k, ind["n_coupled"], "min"))
    return Verdict(rung.name, all(c[-1] for c in checks), tuple(checks))


# ---------------------------------------------------------------------------- blocks
def block_indicators(scene) -> dict:
    """δ/L of the beam under the block (B1), or rigid ground (B2)."""
    spec = scene.spec
    if scene.beam is None:
        return {"beam": None, "deflection_over_span": 0.0}
    bm = scene.beam_spec
    E = bm.E if scene.E is None else scene.E
    delta = spec.mass * spec.g * bm.span**3 / (48.0 * E * bm.second_moment)  # paper 002 §6.3
    E_bar = spec.mass * spec.g * bm.span**2 * 2500.0 / (48.0 * bm.second_moment)
    return {
        "beam": bm.name,
        "E_Pa": E,
        "E_over_Ebar": E / E_bar,
        "deflection_m": delta,
        "deflection_over_span": delta / bm.span,
        "span_over_deflection": bm.span / delta,
        "threshold_deflection_over_span": BEAM_RIGID,
    }


def _block_verdict(rung, scene, ind: dict) -> Verdict:
    if rung.name != "rigid-block":
        return Verdict(rung.name, True, (("top of the ladder", 0.0, 0.0, "max", True),))
    if ind["beam"] is None:
        return Verdict(rung.name, True, (("B2 rigid ground", 0.0, 0.0, "max", True),))
    check = _check("B1 δ/L", ind["deflection_over_span"], BEAM_RIGID)
    return Verdict(rung.name, check[-1], (check,))


def assess(scene, rungs) -> tuple[list[Verdict], dict, float | None]:
    """A-priori verdicts for every rung, the indicators, and the budget (columns)."""
    if scene.kind == "column":
        ind = column_indicators(scene)
        budget = _budget(scene, ind)
        return [_column_verdict(r, scene, ind, budget) for r in rungs], ind, budget
    ind = block_indicators(scene)
    return [_block_verdict(r, scene, ind) for r in rungs], ind, None
