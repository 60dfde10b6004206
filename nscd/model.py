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

import specimens
from multimass.errors import InputError
from specimens import BeamSpecimen, BlockSpecimen

from .fe_beam import BeamModel, build_beam, static_deflection

__all__ = ["System", "build_system", "flexible_modulus", "load_block", "load_beam", "csr"]


def _load(value, cls, field: str, examples: str):
    """A `cls` specimen from a specimen, a bundled name or a TOML path; `field` names it."""
    spec = value if isinstance(value, cls) else specimens.load(value)
    if not isinstance(spec, cls):
        raise InputError(f"`{field}` = {value!r}: is a {spec.kind} specimen; give a {field} "
                         f"(e.g. {examples})")
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
    blk, bm = load_block(block), load_beam(beam)
    P = blk.mass * blk.g
    return P * bm.span**3 / (48.0 * bm.second_moment * bm.span / ratio)


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


def _check(name: str, value, low: float, high: float | None = None, *, low_open=False,
           fix: str = "") -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InputError(f"`{name}` = {value!r}: expected a number; {fix}") from None
    if not math.isfinite(x):
        raise InputError(f"`{name}` = {value!r}: expected a finite number; {fix}")
    bad = (x <= low if low_open else x < low) or (high is not None and x > high)
    if bad:
        rng = f"{'(' if low_open else '['}{low:g}, {'inf)' if high is None else f'{high:g}]'}"
        raise InputError(f"`{name}` = {value!r}: must lie in {rng}; {fix}")
    return x


def _block_inputs(blk: BlockSpecimen, bm: BeamSpecimen, theta0: float, x_centre: float | None):
    if blk.b >= bm.span:
        raise InputError(f"`block` = {blk.name!r}: its width b = {blk.b:g} m is not smaller than "
                         f"the span L = {bm.span:g} m of `beam` {bm.name!r}; use a longer beam "
                         "or a narrower block")
    xc = 0.5 * bm.span if x_centre is None else _check(
        "x_centre", x_centre, 0.0, bm.span, fix="the block's centre abscissa on the span in m")
    if xc - 0.5 * blk.b < 0.0 or xc + 0.5 * blk.b > bm.span:
        raise InputError(f"`x_centre` = {xc:g}: the block's footprint [{xc - blk.b / 2:g}, "
                         f"{xc + blk.b / 2:g}] m does not rest on the beam [0, {bm.span:g}] m; "
                         f"put its centre within [{blk.b / 2:g}, {bm.span - blk.b / 2:g}] m")
    th0 = _check("theta0", theta0, -math.inf, fix="the release angle in rad")
    if abs(th0) >= blk.alpha:
        raise InputError(f"`theta0` = {theta0!r} rad: the block does not rest on its corner: "
                         f"|θ0| must be below the overturning angle α = {blk.alpha:.4f} rad "
                         f"({math.degrees(blk.alpha):.3f}°) of {blk.name}")
    return th0, xc


def _inverse_A(beam: BeamModel, dt: float, th: float) -> np.ndarray:
    """The beam block A⁻¹ of B (paper 002, Eqs 26, 33), dense and symmetric."""
    A = beam.M + dt * th * beam.C + (dt * th) ** 2 * beam.K          # paper 002, Eq 26
    Ainv = sla.cho_solve(sla.cho_factor(A), np.eye(A.shape[0]))
    return 0.5 * (Ainv + Ainv.T)


def csr(A: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(indptr, indices, data) of a banded matrix, for the kernel's sparse products."""
    S = sparse.csr_matrix(A)
    return S.indptr.astype(np.int64), S.indices.astype(np.int64), S.data.astype(float)


def build_system(block, beam="beam_mudric2024", *, theta0: float, dt: float,
                 E: float | None = None, n_elements: int | None = None,
                 theta_method: float = 1.0, mu: float | None = None,
                 restitution: float = 0.0, x_centre: float | None = None) -> System:
    """Validate the inputs, assemble the beam and set the preloaded initial state.

    The beam starts in static equilibrium under its self-weight and the
    block's weight at the resting corner (paper 002, Section 6); the block
    rests on that corner, placed on the deformed beam axis, tilted by
    `theta0` and at rest.

    Raises
    ------
    InputError
        dt ≤ 0, a block not narrower than the span, fewer than 3 elements,
        θ-method parameter outside [0, 1], a block not resting on the beam
        (footprint off the span, or |θ0| ≥ α), μ < 0, e outside [0, 1], E ≤ 0.
    """
    blk, bm = load_block(block), load_beam(beam)
    dt = _check("dt", dt, 0.0, low_open=True, fix="give a positive time step in s, e.g. 1e-5")
    th = _check("theta_method", theta_method, 0.0, 1.0,
                fix="the θ-method parameter (paper 002, Eqs 21–25; 1 = backward Euler)")
    mu = bm.mu if mu is None else _check("mu", mu, 0.0, fix="a friction coefficient >= 0")
    e = _check("restitution", restitution, 0.0, 1.0, fix="Newton's coefficient e (0 = plastic)")
    E = bm.E if E is None else _check("E", E, 0.0, low_open=True, fix="Young's modulus in Pa")
    n_el = bm.n_elements if n_elements is None else n_elements
    if isinstance(n_el, bool) or not isinstance(n_el, (int, np.integer)) or n_el < 3:
        raise InputError(f"`n_elements` = {n_el!r}: give an integer >= 3 (paper 002 uses 3, 6, 12)")
    th0, xc = _block_inputs(blk, bm, theta0, x_centre)
    model = build_beam(bm.span, E, bm.area, bm.second_moment, bm.rho, int(n_el),
                       bm.damping_ratios, bm.damping_modes, bm.g)
    b, h, m = blk.b, blk.h, blk.mass
    inertia = m * (b * b + h * h) / 12.0
    verts = np.array([[-b / 2, -h / 2], [b / 2, -h / 2], [b / 2, h / 2], [-b / 2, h / 2]])
    phi0 = -th0                                                    # paper 002 φ = −θ
    x_left, x_right = xc - b / 2, xc + b / 2
    pivot = 1 if th0 >= 0.0 else 0                # vertex 1 is the right corner, 0 the left
    if th0 == 0.0:   # upright on both corners: weight shared
        p_blk = (model.point_load(x_left, 0.0, -0.5 * m * blk.g)
                 + model.point_load(x_right, 0.0, -0.5 * m * blk.g))
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
    Ainv = _inverse_A(model, dt, th)
    return System(block=blk, beam_spec=bm, beam=model, dt=dt, theta_method=th, mu=mu,
                  restitution=e, theta0=th0, x_centre=xc, mass=m, inertia=inertia,
                  Fk=np.array([0.0, -m * blk.g, 0.0]), verts=verts, Ainv=Ainv,
                  qk0=np.array([G[0], G[1], phi0]), qe0=qe0)
