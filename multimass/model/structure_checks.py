"""Checks of a column's assembled model: finite, positive definite, plausible frequencies.

`multimass.column` runs them after assembling the condensed stiffness (paper 001,
Eq 2) and before anything is computed with it. The specimen loader has already
refused implausible single values (`specimens.ranges`); these checks need the
matrices: the first full-contact frequency must keep the model's deformations small,
the highest must keep an explicit integrator's step sane, and Rayleigh damping must
stay positive at every mode. Each message names the input to fix.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from multimass.specimens import ColumnSpecimen, SpecimenError
from multimass.specimens.column import MAX_NODES
from multimass.specimens.ranges import fmt

from .beam import column_stiffness, condense

__all__ = [
    "MAX_DRIFT_1G",
    "MAX_FREQ_HZ",
    "check_fields",
    "full_contact",
    "check_frequencies",
    "check_damping",
    "check_derived",
]

#: Largest static drift under 1 g, g/ω1², as a fraction of the top node's height.
#: Paper 001 linearises the elastic deformation (small u). A drift of the full height
#: under a lateral 1 g (a chord rotation of 45°; ~14° at S1's uplift acceleration
#: g tan α_cg = 0.36 g) is far beyond that. S1 has 0.0023, the example S1_soft
#: (E_s / 100) 0.17; unit slips of Young's modulus or of the second moment (10³ and
#: more) give 2 and more.
MAX_DRIFT_1G = 1.0

#: Highest full-contact frequency (Hz). No rocking structure has a structural mode near
#: it: S1's highest is 527 Hz, S1 lumped into 100 even nodes reaches 1.7e5 Hz, the
#: benchmarks' stiffest column (S1 x 10 000) 5.3e4 Hz. Above it the mode is a unit slip
#: or a lumping artifact, and an explicit integrator, which must follow it, takes steps
#: of ~0.16 us: measured on S1 x 1, x 100, x 10 000, DOP853 through solve_ivp spends
#: ~17 right-hand sides (~45 us each) per hertz of f_max per simulated second, so a
#: 10 s run at 1e6 Hz would take ~2 h.
MAX_FREQ_HZ = 1e6


def _real(x) -> bool:
    return isinstance(x, numbers.Real) and not isinstance(x, bool) and math.isfinite(x)


def _sequence(x) -> tuple:
    """x as a tuple, or () if it is not a sequence."""
    return tuple(x) if isinstance(x, (list, tuple, np.ndarray)) else ()


def check_fields(spec: ColumnSpecimen, where: str) -> None:
    """A column object (perhaps built with dataclasses.replace) must hold finite, positive values."""
    bad = []
    H, m = _sequence(spec.heights), _sequence(spec.masses)
    if not (0 < len(H) <= MAX_NODES and len(H) == len(m) and all(map(_real, H + m))):
        bad.append(f"heights/masses (one finite mass per finite height, 1..{MAX_NODES} nodes)")
    elif not (H[0] > 0 and all(b > a for a, b in zip(H, H[1:])) and min(m) > 0):
        bad.append("heights (> 0, strictly increasing) and masses (> 0)")
    for name in ("B", "E_s", "I_s", "K_rot", "K_fp", "g"):
        x = getattr(spec, name)
        if not (_real(x) and x > 0):
            bad.append(f"{name} = {_cut(x)} (a finite number > 0)")
    for name, high in (("m0", math.inf), ("J0", math.inf), ("zeta_1", 1.0), ("zeta_2", 1.0)):
        x = getattr(spec, name)
        if not (_real(x) and 0 <= x < high):
            bad.append(
                f"{name} = {_cut(x)} (a finite number >= 0" + (", < 1)" if high == 1.0 else ")")
            )
    if bad:
        raise SpecimenError(
            f"{where}: invalid field(s): {'; '.join(bad)}; load the specimen "
            "with specimens.load, which names the TOML field to fix"
        )


def full_contact(spec: ColumnSpecimen, E: float, where: str):
    """K_s, condensed K and the full-contact ω (rad/s), each finite and positive definite."""
    fix = (
        "check `stiffness.youngs_modulus_Pa`, `stiffness.second_moment_m4`, the springs "
        "and `geometry.heights_m`"
    )
    H, m = np.asarray(spec.heights, dtype=float), np.asarray(spec.masses, dtype=float)
    with np.errstate(over="ignore", invalid="ignore", under="ignore"):
        Ks = column_stiffness(H, E * spec.I_s, spec.K_fp, spec.K_rot)
        try:
            K = condense(Ks) if np.all(np.isfinite(Ks)) else None
            L = np.linalg.cholesky(K) if K is not None and np.all(np.isfinite(K)) else None
        except (np.linalg.LinAlgError, ValueError):
            L = None
        if L is None or not np.allclose(K, K.T, rtol=1e-12, atol=0.0):
            raise SpecimenError(
                f"{where}: the full-contact stiffness (paper 001, Eqs 1–2) is not "
                f"a finite, symmetric positive-definite matrix; {fix}"
            )
        import scipy.linalg as sla  # here: a rigid block's runs need no SciPy

        w2 = sla.eigh(K, np.diag(m), eigvals_only=True)
    if not (np.all(np.isfinite(w2)) and w2[0] > 0.0):
        raise SpecimenError(
            f"{where}: the full-contact eigenproblem K v = ω² M v has a "
            f"non-positive or non-finite ω² ({w2[0]:.3g}); {fix}"
        )
    return Ks, K, np.sqrt(w2)


def check_frequencies(spec: ColumnSpecimen, E: float, omega: np.ndarray, where: str) -> None:
    """Refuse a first frequency that breaks small deformations, a last that breaks the step."""
    H, m = np.asarray(spec.heights, dtype=float), np.asarray(spec.masses, dtype=float)
    f1, f_max = omega[0] / (2 * np.pi), omega[-1] / (2 * np.pi)
    drift = spec.g / omega[0] ** 2
    e_field = "`E_s`" if E != spec.E_s else "`stiffness.youngs_modulus_Pa`"
    if drift > MAX_DRIFT_1G * H[-1]:
        raise SpecimenError(
            f"{where}: full-contact first frequency f1 = {f1:.4g} Hz: the static drift under a "
            f"lateral 1 g, g/ω1² = {drift:.4g} m, exceeds {MAX_DRIFT_1G:g} x the height "
            f"{H[-1]:g} m, far beyond the small deformations of the model (paper 001, Section 2); "
            f"{_culprit_soft(spec, E, e_field)}"
        )
    if f_max > MAX_FREQ_HZ:
        raise SpecimenError(
            f"{where}: highest full-contact frequency {f_max:.4g} Hz > {fmt(MAX_FREQ_HZ)} Hz: an "
            f"explicit integrator would need steps of ~{1 / omega[-1]:.2g} s (hours for a "
            f"10 s run); {_culprit_stiff(spec, E, e_field, H, m)}"
        )


def _culprit_soft(spec, E, e_field) -> str:
    """The most flexible part under a lateral 1 g (all mass at the top: an upper bound)."""
    H, W = spec.heights, spec.g * sum(spec.masses)
    L = H[-1] - H[0]
    terms = {
        f"`stiffness.horizontal_spring_N_per_m` = {spec.K_fp:g} N/m": W / spec.K_fp,
        f"`stiffness.rotational_spring_Nm_per_rad` = {spec.K_rot:g} N m/rad": W
        * L
        * L
        / spec.K_rot,
        f"{e_field} = {E:g} Pa (steel is 200e9) with `stiffness.second_moment_m4` = "
        f"{spec.I_s:g} m^4 (183.3 cm^4 is 183.3e-8)": W * L**3 / (3.0 * E * spec.I_s),
    }
    return (
        f"the most flexible part is {max(terms, key=terms.get)}: check the value(s) and "
        "unit(s), and the masses `mass.nodal_kg` (kg)"
    )


def _culprit_stiff(spec, E, e_field, H, m) -> str:
    """The stiffest local part: the base spring on node 1 or the shortest element."""
    lengths = np.diff(H)
    k = int(np.argmin(lengths)) if lengths.size else -1
    terms = {
        f"`stiffness.horizontal_spring_N_per_m` = {spec.K_fp:g} N/m on node 1 "
        f"({m[0]:g} kg)": spec.K_fp / m[0]
    }
    if k >= 0:
        terms[
            f"the element between nodes {k + 1} and {k + 2}, {lengths[k]:.3g} m long "
            f"({e_field}, `stiffness.second_moment_m4`, `mass.nodal_kg`)"
        ] = 12.0 * E * spec.I_s / lengths[k] ** 3 / min(m[k], m[k + 1])
    return (
        f"the stiffest part is {max(terms, key=terms.get)}: check the values and units; a "
        "structure this stiff rocks like a rigid body (model it with multimass.rigid_block)"
    )


def check_damping(spec: ColumnSpecimen, omega: np.ndarray, coeffs, C, where: str) -> None:
    """Rayleigh damping must stay ≥ 0 at every full-contact mode (else energy grows)."""
    a0, a1 = coeffs
    zeta = 0.5 * (a0 / omega + a1 * omega)  # modal damping of C = a0 M + a1 K
    if not (np.all(np.isfinite(C)) and np.all(np.isfinite(zeta))):
        raise SpecimenError(
            f"{where}: Rayleigh damping is not finite (first two full-contact "
            f"frequencies {omega[:2] / (2 * np.pi)} Hz coincide?); separate them "
            "or check `damping.zeta_1`, `damping.zeta_2`"
        )
    k = int(np.argmin(zeta))
    if zeta[k] < -1e-12:
        ratio = omega[0] / omega[1]
        raise SpecimenError(
            f"{where}: Rayleigh damping fitted to `damping.zeta_1` = {spec.zeta_1:g} and "
            f"`damping.zeta_2` = {spec.zeta_2:g} gives ζ = {zeta[k]:.3g} < 0 at full-contact mode "
            f"{k + 1} ({omega[k] / (2 * np.pi):.4g} Hz): its vibration would grow instead of "
            f"decay; make zeta_2 / zeta_1 >= f1 / f2 = {ratio:.3g}"
        )


def check_derived(st, where: str):
    """The structure, once its derived quantities (Table 1 of paper 001) are finite and > 0."""
    values = {"m_t": st.m_t, "J_p": st.J_p, "H_cg": st.H_cg, "p_l": st.p_l, "p": st.p}
    bad = {k: v for k, v in values.items() if not (math.isfinite(v) and v > 0.0)}
    if bad:
        raise SpecimenError(
            f"{where}: derived quantities {bad} are not finite and positive; "
            "check the specimen's masses, heights and widths"
        )
    return st


def _cut(value, limit: int = 80) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 1] + "…"
