"""Assembly of the block-on-beam system and its preloaded initial state
(paper 002, Sections 2, 3 and 6), with the input checks.

Angles: the public ``theta0`` follows the toolkit convention (paper 001,
Fig 1): θ > 0 rocks about the RIGHT corner. Paper 002 measures the block
rotation φ counter-clockwise (Fig 3), so φ = −θ; it reports magnitudes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
from scipy import sparse

import multimass.specimens as specimens
from multimass.errors import InputError
from multimass.progress import RunCost, format_bytes
from multimass.specimens import BeamSpecimen, BlockSpecimen
from multimass.validation import integer, number, positive

from . import cost
from .fe_beam import BeamModel, build_beam, static_deflection

__all__ = [
    "System",
    "Inputs",
    "build_system",
    "check_inputs",
    "flexible_modulus",
    "min_modulus",
    "load_block",
    "load_beam",
    "csr",
    "assemble",
    "E_MAX",
    "MIN_DEFLECTION_RATIO",
    "check_elements",
    "flex_range",
    "check_exponent",
]

#: Largest Young's modulus accepted (Pa). Paper 002's rigid base is 1e24 Pa; at
#: 1e30 Pa its beam is rigid to round-off (B6M's first peak equals the 1e24 Pa
#: run's to 4e-11° and the 1e200 Pa run's exactly, at Δt = 1e-4 s), while near
#: 1e300 Pa the Rayleigh fit overflows (a0 ∝ ω₁ω₃ ∝ E).
E_MAX = 1e30
#: The softest beam accepted deflects L/MIN_DEFLECTION_RATIO at midspan (see `min_modulus`).
MIN_DEFLECTION_RATIO = 30.0


def _load(value, cls, field: str, examples: str):
    """A `cls` specimen from a specimen, a bundled name or a TOML path; `field` names it."""
    spec = value if isinstance(value, cls) else specimens.load(value)
    if not isinstance(spec, cls):
        raise InputError(
            f"`{field}` = {value!r}: is a {spec.kind} specimen; give a {field} (e.g. {examples})"
        )
    return spec


def load_block(block) -> BlockSpecimen:
    """A `BlockSpecimen` from a specimen, a bundled name or a TOML path."""
    return _load(block, BlockSpecimen, "block", "B4M, B6M, B8M")


def load_beam(beam) -> BeamSpecimen:
    """A `BeamSpecimen` from a specimen, a bundled name or a TOML path."""
    return _load(beam, BeamSpecimen, "beam", "beam_mudric2024")


def flexible_modulus(block, beam="beam_mudric2024", ratio: float = 2500.0) -> float:
    """Ē: the Young's modulus giving a midspan deflection L/`ratio` under the block's weight.

    Closed form δ = P L³ / (48 E I) of a simply supported beam with a central
    point load P = m g (paper 002, Section 6.3: Ē for L/2500).
    """
    ratio = positive("ratio", ratio, "the midspan deflection is L/ratio, e.g. 2500")
    blk, bm = load_block(block), load_beam(beam)
    P = blk.mass * blk.g
    E = P * bm.span**3 / (48.0 * bm.second_moment * bm.span / ratio)
    if not math.isfinite(E) or E <= 0.0:
        raise InputError(
            f"`ratio` = {ratio!r}: the modulus for a midspan deflection L/ratio "
            f"is {E!r} Pa; give a ratio such as 2500 (paper 002, Section 6.3)"
        )
    return E


def min_modulus(block, beam="beam_mudric2024") -> float:
    """The smallest Young's modulus accepted: midspan deflection L/`MIN_DEFLECTION_RATIO`.

    Closed forms of a simply supported beam: the block's weight P at midspan,
    δ = P L³ / (48 E I), plus the self-weight w = ρ A g, δ = 5 w L⁴ / (384 E I).
    At δ = L/30 the end slope of the point-load line is 3δ/L = 0.1 rad, and
    the curvature v'' of linear (small-deflection) beam theory, which the FE
    beam uses (paper 002, Section 3.1), errs by (1 + v'²)^(3/2) − 1 ≈ 1.5 %;
    a softer beam is outside the model (paper 002 goes down to L/2500).
    """
    blk, bm = load_block(block), load_beam(beam)
    w = bm.rho * bm.area * bm.g
    load = blk.mass * blk.g * bm.span**3 / 48.0 + 5.0 * w * bm.span**4 / 384.0
    return load / (bm.second_moment * bm.span / MIN_DEFLECTION_RATIO)


def flex_range(block, beam="beam_mudric2024") -> tuple[float, float]:
    """The exponents n of E = Ē·10ⁿ accepted: from `min_modulus` to `E_MAX`."""
    Ebar = flexible_modulus(block, beam)
    return math.log10(min_modulus(block, beam) / Ebar), math.log10(E_MAX / Ebar)


def check_exponent(n, block, beam="beam_mudric2024", name: str = "exponent") -> float:
    """An exponent n of E = Ē·10ⁿ within `flex_range` (checked before 10ⁿ is computed)."""
    low, high = flex_range(block, beam)
    return number(
        name,
        n,
        low=low,
        high=high,
        what=f"E = Ē·10^n: from {low:.3g} (midspan deflection L/"
        f"{MIN_DEFLECTION_RATIO:g}) to {high:.3g} (E = {E_MAX:g} Pa)",
    )


@dataclass(frozen=True)
class System:
    """Everything the time loop needs, validated (SI units, paper 002 notation)."""

    block: BlockSpecimen
    beam_spec: BeamSpecimen
    beam: BeamModel
    dt: float
    theta_method: float
    mu: float
    restitution: float
    theta0: float
    x_centre: float
    mass: float
    inertia: float
    Fk: np.ndarray
    verts: np.ndarray
    Ainv: np.ndarray
    qk0: np.ndarray
    qe0: np.ndarray

    @property
    def i_mid(self) -> int:
        """Reduced index of v at node n_elements // 2 (midspan for an even mesh)."""
        return int(self.beam.edof[self.beam.n_elements // 2, 1])

    @property
    def x_mid(self) -> float:
        """Abscissa of that node (m)."""
        return float(self.beam.x_nodes[self.beam.n_elements // 2])


@dataclass(frozen=True)
class Inputs:
    """The validated inputs of one simulation (SI units, radians), before assembly."""

    block: BlockSpecimen
    beam: BeamSpecimen
    theta0: float
    dt: float
    E: float
    n_elements: int
    theta_method: float
    mu: float
    restitution: float
    x_centre: float


def _name(names, key: str) -> str:
    return (names or {}).get(key, key)


def check_elements(n_elements, name: str = "n_elements") -> int:
    """An element count in 3..`cost.MAX_ELEMENTS`; the message of a larger one gives its cost."""
    n = integer(name, n_elements, low=3, what="beam elements; paper 002 uses 3, 6, 12 and 24")
    if n > cost.MAX_ELEMENTS:
        per_step = cost.step_seconds(n)
        raise InputError(
            f"`{name}` = {n_elements!r}: at most {cost.MAX_ELEMENTS} elements: the "
            f"beam's matrices are dense, so {n} elements would need "
            f"{format_bytes(cost.assembly_memory(n))} of memory and ~{per_step:.2g} s "
            "per step, and the stiffness matrix would be too ill-conditioned to "
            "solve; paper 002's responses agree from 12 elements (Fig 11): use 6–24"
        )
    return n


def _check_modulus(E, blk: BlockSpecimen, bm: BeamSpecimen, name: str) -> float:
    E = positive(name, E, "Young's modulus in Pa; 1e24 = paper 002's rigid base")
    e_min = min_modulus(blk, bm)
    if E < e_min:
        raise InputError(
            f"`{name}` = {E:g} Pa: too soft for {bm.name!r} under {blk.name}: the "
            f"block and the self-weight would deflect midspan by more than "
            f"L/{MIN_DEFLECTION_RATIO:g}, beyond the linear beam theory of the "
            f"model; give E >= {e_min:.3g} Pa (nscd.min_modulus)"
        )
    if E > E_MAX:
        raise InputError(
            f"`{name}` = {E:g} Pa: above {E_MAX:g} Pa; the beam is already rigid "
            "to round-off at 1e24 Pa (paper 002's rigid base): give E <= "
            f"{E_MAX:g} Pa"
        )
    return E


def _block_inputs(blk: BlockSpecimen, bm: BeamSpecimen, theta0, x_centre, names):
    if blk.b >= bm.span:
        raise InputError(
            f"`block` = {blk.name!r}: its width b = {blk.b:g} m is not smaller than "
            f"the span L = {bm.span:g} m of `beam` {bm.name!r}; use a longer beam "
            "or a narrower block"
        )
    xc = (
        0.5 * bm.span
        if x_centre is None
        else number(
            _name(names, "x_centre"),
            x_centre,
            low=0.0,
            high=bm.span,
            what="the block's centre abscissa on the span in m",
        )
    )
    if xc - 0.5 * blk.b < 0.0 or xc + 0.5 * blk.b > bm.span:
        raise InputError(
            f"`{_name(names, 'x_centre')}` = {xc:g}: the block's footprint "
            f"[{xc - blk.b / 2:g}, {xc + blk.b / 2:g}] m does not rest on the beam "
            f"[0, {bm.span:g}] m; put its centre within [{blk.b / 2:g}, "
            f"{bm.span - blk.b / 2:g}] m"
        )
    th0 = number(_name(names, "theta0"), theta0, what="the release angle in rad")
    if abs(th0) >= blk.alpha:
        raise InputError(
            f"`{_name(names, 'theta0')}` = {theta0!r} rad: the block does not rest "
            f"on its corner: |θ0| must be below the overturning angle "
            f"α = {blk.alpha:.4f} rad ({math.degrees(blk.alpha):.3f}°) of {blk.name}"
        )
    return th0, xc


def check_inputs(
    block,
    beam="beam_mudric2024",
    *,
    theta0,
    dt,
    E=None,
    n_elements=None,
    theta_method=1.0,
    mu=None,
    restitution=0.0,
    x_centre=None,
    names: dict | None = None,
) -> Inputs:
    """Validate the inputs of `build_system` without assembling anything (cheap).

    `names` maps an argument to the name shown in messages (e.g.
    ``{"n_elements": "--elements"}`` for the command line).

    Raises
    ------
    InputError
        dt ≤ 0; a block not narrower than the span; fewer than 3 or more than
        `cost.MAX_ELEMENTS` elements; θ-method parameter outside [0, 1]; a
        block not resting on the beam (footprint off the span, or ``|θ0| ≥ α``);
        μ < 0; e outside [0, 1]; E outside [`min_modulus`, `E_MAX`]; a bool,
        a string or a non-finite number anywhere.
    """
    blk, bm = load_block(block), load_beam(beam)
    dt = positive(_name(names, "dt"), dt, "the time step in s, e.g. 1e-5")
    th = number(
        _name(names, "theta_method"),
        theta_method,
        low=0.0,
        high=1.0,
        what="the θ-method parameter, paper 002 Eqs 21–25; 1 = backward Euler",
    )
    mu = (
        bm.mu
        if mu is None
        else number(_name(names, "mu"), mu, low=0.0, what="a friction coefficient >= 0")
    )
    e = number(
        _name(names, "restitution"),
        restitution,
        low=0.0,
        high=1.0,
        what="Newton's coefficient e; 0 = plastic",
    )
    E = _check_modulus(
        bm.E if E is None else E,
        blk,
        bm,
        _name(names, "E") if E is not None else f"material.youngs_modulus_Pa` of beam `{bm.name}",
    )
    n_el = (
        bm.n_elements
        if n_elements is None
        else check_elements(n_elements, _name(names, "n_elements"))
    )
    th0, xc = _block_inputs(blk, bm, theta0, x_centre, names)
    return Inputs(blk, bm, th0, dt, E, int(n_el), th, mu, e, xc)


def _inverse_A(beam: BeamModel, dt: float, th: float) -> np.ndarray:
    """The beam block A⁻¹ of B (paper 002, Eqs 26, 33), dense and symmetric."""
    A = beam.M + dt * th * beam.C + (dt * th) ** 2 * beam.K  # paper 002, Eq 26
    Ainv = sla.cho_solve(sla.cho_factor(A), np.eye(A.shape[0]))
    return 0.5 * (Ainv + Ainv.T)


def csr(A: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(indptr, indices, data) of a banded matrix, for the kernel's sparse products."""
    S = sparse.csr_matrix(A)
    return S.indptr.astype(np.int64), S.indices.astype(np.int64), S.data.astype(float)


def build_system(
    block,
    beam="beam_mudric2024",
    *,
    theta0: float,
    dt: float,
    E: float | None = None,
    n_elements: int | None = None,
    theta_method: float = 1.0,
    mu: float | None = None,
    restitution: float = 0.0,
    x_centre: float | None = None,
) -> System:
    """Validate the inputs, assemble the beam and set the preloaded initial state.

    The beam starts in static equilibrium under its self-weight and the
    block's weight at the resting corner (paper 002, Section 6); the block
    rests on that corner, placed on the deformed beam axis, tilted by
    `theta0` and at rest.

    Raises
    ------
    InputError
        Bad input (see `check_inputs`), or an assembly whose dense matrices
        would not fit in memory.
    """
    return assemble(
        check_inputs(
            block,
            beam,
            theta0=theta0,
            dt=dt,
            E=E,
            n_elements=n_elements,
            theta_method=theta_method,
            mu=mu,
            restitution=restitution,
            x_centre=x_centre,
        )
    )


def assemble(inp: Inputs) -> System:
    """The `System` of validated inputs (see `build_system`); checks its memory first."""
    blk, bm, n_el = inp.block, inp.beam, inp.n_elements
    RunCost(
        0.0,
        cost.setup_seconds(n_el),
        cost.assembly_memory(n_el),
        f"dense beam matrices of {n_el} elements",
    ).check(f"the beam of {n_el} elements", "use fewer elements (paper 002: 6–24)")
    model = build_beam(
        bm.span,
        inp.E,
        bm.area,
        bm.second_moment,
        bm.rho,
        n_el,
        bm.damping_ratios,
        bm.damping_modes,
        bm.g,
    )
    b, h, m = blk.b, blk.h, blk.mass
    inertia = m * (b * b + h * h) / 12.0
    verts = np.array([[-b / 2, -h / 2], [b / 2, -h / 2], [b / 2, h / 2], [-b / 2, h / 2]])
    th0, xc = inp.theta0, inp.x_centre
    phi0 = -th0  # paper 002 φ = −θ
    x_left, x_right = xc - b / 2, xc + b / 2
    pivot = 1 if th0 >= 0.0 else 0  # vertex 1 is the right corner, 0 the left
    if th0 == 0.0:  # upright on both corners: weight shared
        p_blk = model.point_load(x_left, 0.0, -0.5 * m * blk.g) + model.point_load(
            x_right, 0.0, -0.5 * m * blk.g
        )
    else:
        p_blk = model.point_load(x_right if pivot else x_left, 0.0, -m * blk.g)
    qe0 = static_deflection(model, model.p_self + p_blk)
    v_left, v_right = model.deflection(qe0, x_left), model.deflection(qe0, x_right)
    if th0 == 0.0:
        phi0 = math.atan2(v_right - v_left, b)
    corner = np.array([x_right, v_right]) if pivot else np.array([x_left, v_left])
    c, s = math.cos(phi0), math.sin(phi0)
    r = verts[pivot]
    G = corner - np.array([c * r[0] - s * r[1], s * r[0] + c * r[1]])
    Ainv = _inverse_A(model, inp.dt, inp.theta_method)
    return System(
        block=blk,
        beam_spec=bm,
        beam=model,
        dt=inp.dt,
        theta_method=inp.theta_method,
        mu=inp.mu,
        restitution=inp.restitution,
        theta0=th0,
        x_centre=xc,
        mass=m,
        inertia=inertia,
        Fk=np.array([0.0, -m * blk.g, 0.0]),
        verts=verts,
        Ainv=Ainv,
        qk0=np.array([G[0], G[1], phi0]),
        qe0=qe0,
    )
