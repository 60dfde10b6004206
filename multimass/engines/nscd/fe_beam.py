"""Finite-element model of the simply supported beam base (paper 002, Section 3.1).

Two-dimensional Euler–Bernoulli frame elements: linear axial and cubic
(Hermite) bending interpolation, three degrees of freedom per node
``(u, v, ϑ)`` with ϑ = dv/dx; consistent mass; a pin at x = 0 (u = v = 0)
and a roller at x = L (v = 0). Element degrees of freedom are ordered
``[u1, v1, ϑ1, u2, v2, ϑ2]`` as ρ1..ρ6 of paper 002, Eq 52.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from multimass.errors import InputError
from multimass.model.damping import rayleigh_coefficients
from multimass.validation import integer, number, positive

from .cost import MAX_ELEMENTS

__all__ = [
    "BeamModel",
    "build_beam",
    "element_stiffness",
    "element_mass",
    "shape_functions",
    "static_deflection",
]


def element_stiffness(E: float, A: float, I: float, Le: float) -> np.ndarray:
    """Stiffness of a 2D Euler–Bernoulli frame element (6 × 6), [u1 v1 ϑ1 u2 v2 ϑ2]."""
    a = E * A / Le
    k = E * I / Le**3
    K = np.zeros((6, 6))
    K[np.ix_([0, 3], [0, 3])] = a * np.array([[1.0, -1.0], [-1.0, 1.0]])
    K[np.ix_([1, 2, 4, 5], [1, 2, 4, 5])] = k * np.array(
        [
            [12.0, 6 * Le, -12.0, 6 * Le],
            [6 * Le, 4 * Le**2, -6 * Le, 2 * Le**2],
            [-12.0, -6 * Le, 12.0, -6 * Le],
            [6 * Le, 2 * Le**2, -6 * Le, 4 * Le**2],
        ]
    )
    return K


def element_mass(m: float, Le: float) -> np.ndarray:
    """Consistent mass of a 2D frame element (6 × 6), m = ρA the mass per length."""
    M = np.zeros((6, 6))
    M[np.ix_([0, 3], [0, 3])] = m * Le / 6.0 * np.array([[2.0, 1.0], [1.0, 2.0]])
    M[np.ix_([1, 2, 4, 5], [1, 2, 4, 5])] = (
        m
        * Le
        / 420.0
        * np.array(
            [
                [156.0, 22 * Le, 54.0, -13 * Le],
                [22 * Le, 4 * Le**2, 13 * Le, -3 * Le**2],
                [54.0, 13 * Le, 156.0, -22 * Le],
                [-13 * Le, -3 * Le**2, -22 * Le, 4 * Le**2],
            ]
        )
    )
    return M


def shape_functions(s: float, Le: float) -> np.ndarray:
    """The six interpolation values [N_u1, N_v1, N_v2, N_u2, N_v3, N_v4] at s ∈ [0, Le].

    paper 002, Eqs 52 and 59: u = N_u1 ρ1 + N_u2 ρ4, v = N_v1 ρ2 + N_v2 ρ3 + N_v3 ρ5 + N_v4 ρ6.
    The order matches the element degrees of freedom, so ``v_b = N @ rho`` per row.
    """
    x = s / Le
    return np.array(
        [
            1.0 - x,
            1.0 - 3 * x**2 + 2 * x**3,
            Le * (x - 2 * x**2 + x**3),
            x,
            3 * x**2 - 2 * x**3,
            Le * (-(x**2) + x**3),
        ]
    )


@dataclass(frozen=True)
class BeamModel:
    """Assembled, constrained beam matrices (reduced to the free degrees of freedom).

    Attributes
    ----------
    L, E, A, I, m : float
        Span (m), Young's modulus (Pa), area (m²), second moment (m⁴), mass per length (kg/m).
    n_elements : int
    x_nodes : ndarray, shape (n_elements + 1,)
    edof : ndarray of int, shape (n_elements, 6)
        Reduced index of each element degree of freedom, −1 where constrained.
    M, K, C : ndarray, shape (n, n)
        Consistent mass, stiffness and Rayleigh damping (paper 002, Eq 15).
    p_self : ndarray, shape (n,)
        Consistent nodal loads of the self-weight.
    rayleigh : tuple of float
        (a0, a1) with C = a0 M + a1 K.
    omega : ndarray
        Undamped circular frequencies of the free beam (rad/s), ascending.
    """

    L: float
    E: float
    A: float
    I: float
    m: float
    n_elements: int
    x_nodes: np.ndarray
    edof: np.ndarray
    M: np.ndarray
    K: np.ndarray
    C: np.ndarray
    p_self: np.ndarray
    rayleigh: tuple[float, float]
    omega: np.ndarray

    @property
    def n_dof(self) -> int:
        return self.M.shape[0]

    @property
    def Le(self) -> float:
        return self.L / self.n_elements

    def point_load(self, x: float, fx: float, fy: float) -> np.ndarray:
        """Consistent reduced load vector of a point force (fx, fy) at abscissa x."""
        e = min(int(x / self.Le), self.n_elements - 1)
        N = shape_functions(x - self.x_nodes[e], self.Le)
        fe = np.array([N[0] * fx, N[1] * fy, N[2] * fy, N[3] * fx, N[4] * fy, N[5] * fy])
        p = np.zeros(self.n_dof)
        for a in range(6):
            if self.edof[e, a] >= 0:
                p[self.edof[e, a]] += fe[a]
        return p

    def deflection(self, q: np.ndarray, x: float) -> float:
        """Transverse displacement v(x) of the reduced displacement vector q (Eq 59)."""
        e = min(int(x / self.Le), self.n_elements - 1)
        rho = np.array([q[i] if i >= 0 else 0.0 for i in self.edof[e]])
        N = shape_functions(x - self.x_nodes[e], self.Le)
        return float(N[1] * rho[1] + N[2] * rho[2] + N[4] * rho[4] + N[5] * rho[5])


def build_beam(
    L: float,
    E: float,
    A: float,
    I: float,
    rho: float,
    n_elements: int,
    damping_ratios=(0.05, 0.2),
    damping_modes=(1, 3),
    g: float = 9.81,
) -> BeamModel:
    """Assemble the simply supported frame-element beam of paper 002, Section 6.

    Rayleigh damping C = a0 M + a1 K gives `damping_ratios` at the two
    `damping_modes` (1-based) of the beam's own undamped modes (paper 002,
    Section 6: 0.05 at mode 1 and 0.2 at mode 3).

    Raises
    ------
    InputError
        Fewer than 3 or more than `nscd.cost.MAX_ELEMENTS` elements, a property
        not a positive finite number, or a damping mode number beyond the
        number of modes of the mesh.
    """
    n_el = integer(
        "n_elements",
        n_elements,
        low=3,
        high=MAX_ELEMENTS,
        what="beam elements; paper 002 uses 3, 6 and 12",
    )
    for name, val in (("L", L), ("E", E), ("A", A), ("I", I), ("rho", rho)):
        positive(name, val)
    number("g", g, low=0.0, what="gravity in m/s²; 0 leaves the self-weight out")
    Le = L / n_el
    m = rho * A
    nfull = 3 * (n_el + 1)
    fixed = {0, 1, 3 * n_el + 1}  # pin at x = 0 (u, v), roller at x = L (v)
    free = [i for i in range(nfull) if i not in fixed]
    red = -np.ones(nfull, dtype=np.int64)
    red[free] = np.arange(len(free))
    Kf = np.zeros((nfull, nfull))
    Mf = np.zeros((nfull, nfull))
    pf = np.zeros(nfull)
    ke, me = element_stiffness(E, A, I, Le), element_mass(m, Le)
    q = -m * g  # self-weight per length
    pe = np.array([0.0, q * Le / 2, q * Le**2 / 12, 0.0, q * Le / 2, -q * Le**2 / 12])
    edof = np.zeros((n_el, 6), dtype=np.int64)
    for e in range(n_el):
        dofs = np.arange(3 * e, 3 * e + 6)
        Kf[np.ix_(dofs, dofs)] += ke
        Mf[np.ix_(dofs, dofs)] += me
        pf[dofs] += pe
        edof[e] = red[dofs]
    K = Kf[np.ix_(free, free)]
    M = Mf[np.ix_(free, free)]
    omega = np.sqrt(np.abs(sla.eigh(K, M, eigvals_only=True)))
    ia, ib = damping_modes
    if not (1 <= ia < ib <= omega.size):
        raise InputError(
            f"`damping_modes` = {damping_modes!r}: the mesh has {omega.size} modes; "
            "give two increasing 1-based mode numbers within them"
        )
    a0, a1 = rayleigh_coefficients(omega[ia - 1], omega[ib - 1], *damping_ratios)
    C = a0 * M + a1 * K
    return BeamModel(
        L=float(L),
        E=float(E),
        A=float(A),
        I=float(I),
        m=float(m),
        n_elements=n_el,
        x_nodes=np.linspace(0.0, L, n_el + 1),
        edof=edof,
        M=M,
        K=K,
        C=C,
        p_self=pf[free],
        rayleigh=(a0, a1),
        omega=omega,
    )


def static_deflection(beam: BeamModel, p: np.ndarray) -> np.ndarray:
    """Static displacements K⁻¹ p (Cholesky), the preload initial condition."""
    return sla.cho_solve(sla.cho_factor(beam.K), p)
