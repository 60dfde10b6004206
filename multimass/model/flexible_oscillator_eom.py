"""Equations of motion of the flexible rocking oscillator, derived with SymPy (paper 000, Sec 4).

The printed Eq 30 of paper 000 is garbled, so the equations are derived here
from the Lagrangian L = T − V (paper 000, Eq 30) instead of being transcribed.

Model (paper 000, Fig 2b): a rigid base of mass m_b and width 2b (height
negligible, I_b = m_b b²/3), a column of height h with mass m_c uniformly
distributed, deflecting as u(t) ψ(ξ) with ψ(ξ) = α3 ξ³/h³ + α2 ξ²/h² + α1 ξ/h + α0
(Eq 26), and a lumped mass m at the top (no rotary inertia). Coordinates
q = (u, x, y, φ): column-top deflection u (along the base's own x axis), base
centre translation (x, y) relative to the moving ground, and rotation φ
(counter-clockwise positive, as paper 000). A point of the column at height ξ
sits at (x + uψ cos φ − ξ sin φ, y + uψ sin φ + ξ cos φ).

Forces: gravity, the column's strain energy ½ k̃ u² (Eq 27), viscous damping
−c u̇ with c = 2ζ√(m̃ k̃) (Eq 28), and the d'Alembert load of a horizontal ground
acceleration a_g on every mass (relative coordinates).

`symbolic()` returns the SymPy expressions; `numeric()` lambdifies them once
per process and per shape (cached).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import sympy as sp

__all__ = ["OscillatorSymbols", "symbolic", "numeric"]

PARAMS = ("m", "m_c", "m_b", "h", "b", "g", "k", "c")


@dataclass(frozen=True)
class OscillatorSymbols:
    """SymPy objects of the derivation.

    Attributes
    ----------
    q, qd : tuple of Symbol
        (u, x, y, φ) and their rates.
    params : dict of str → Symbol
        m, m_c, m_b, h, b, g, k (= k̃), c (damping coefficient).
    ag : Symbol
        Horizontal ground acceleration.
    T, V : Expr
        Kinetic and potential energy (V = 0 at rest: u = 0, y = 0, φ = 0).
    M : Matrix (4×4)
        Mass matrix ∂²T/∂q̇∂q̇.
    forcing : Matrix (4×1)
        Everything else: M q̈ = forcing (no contact forces).
    ground_power, damping_power : Expr
        Power of the ground load, and the damping dissipation rate c u̇².
    m_tilde, k_tilde_factor : Expr
        m̃ = m + (m_c/h)∫ψ² dξ and k̃ h³/EI = h³ ∫ψ''² dξ (Eq 27).
    L0, L1 : Expr
        (m_c/h)∫ψ dξ and (m_c/h²)∫ψ ξ dξ: the column's participation in the
        horizontal force and in the moment about the base.
    """

    q: tuple
    qd: tuple
    params: dict
    ag: sp.Symbol
    T: sp.Expr
    V: sp.Expr
    M: sp.Matrix
    forcing: sp.Matrix
    ground_power: sp.Expr
    damping_power: sp.Expr
    m_tilde: sp.Expr
    k_tilde_factor: sp.Expr
    L0: sp.Expr
    L1: sp.Expr


def _tidy(e: sp.Expr) -> sp.Expr:
    """Cheap canonical form: expand, then collect sin²+cos² (full simplify is slow)."""
    return sp.expand(
        sp.expand(e).subs(
            sp.sin(sp.Symbol("phi", real=True)) ** 2, 1 - sp.cos(sp.Symbol("phi", real=True)) ** 2
        )
    )


@cache
def symbolic(
    shape: tuple[float, float, float, float] = (0, 0, sp.Rational(3, 2), -sp.Rational(1, 2)),
) -> OscillatorSymbols:
    """Derive T, V, M and the forcing from the Lagrangian (paper 000, Eqs 26, 27, 30).

    Parameters
    ----------
    shape : tuple
        (α0, α1, α2, α3) of Eq 26; default (0, 0, 3/2, −1/2), paper 000 Sec 4.
    """
    u, x, y, ph = q = sp.symbols("u x y phi", real=True)
    ud, xd, yd, phd = qd = sp.symbols("ud xd yd phid", real=True)
    P = {name: sp.Symbol(name, positive=True) for name in PARAMS}
    m, mc, mb, h, b, g, k, c = (P[n] for n in PARAMS)
    ag, xi = sp.Symbol("a_g", real=True), sp.Symbol("xi", nonnegative=True)
    a0, a1, a2, a3 = (sp.nsimplify(a) for a in shape)
    psi = a3 * xi**3 / h**3 + a2 * xi**2 / h**2 + a1 * xi / h + a0  # paper 000, Eq 26
    cs, sn = sp.cos(ph), sp.sin(ph)

    def pos(w, z):  # point at height z deflected by w, base frame
        return sp.Matrix([x + w * cs - z * sn, y + w * sn + z * cs])

    def vel(r):
        return r.jacobian(q) * sp.Matrix(qd)

    r_m, r_c = pos(u * psi.subs(xi, h), h), pos(u * psi, xi)
    v_m, v_c = vel(r_m), vel(r_c)
    T = (
        m * v_m.dot(v_m) / 2
        + mb * (xd**2 + yd**2) / 2
        + mb * b**2 / 3 * phd**2 / 2
        + sp.integrate(sp.expand(mc / h * v_c.dot(v_c) / 2), (xi, 0, h))
    )
    V = (
        g * (m * (r_m[1] - h) + mb * y + sp.integrate(mc / h * (r_c[1] - xi), (xi, 0, h)))
        + k * u**2 / 2
    )
    X_tot = m * r_m[0] + mb * x + sp.integrate(mc / h * r_c[0], (xi, 0, h))
    Q = -ag * sp.Matrix([sp.diff(X_tot, s) for s in q]) - sp.Matrix([c * ud, 0, 0, 0])
    T, V = _tidy(T), _tidy(V)
    M = sp.hessian(T, qd).applyfunc(_tidy)
    p = sp.Matrix([sp.diff(T, s) for s in qd])
    convective = p.jacobian(q) * sp.Matrix(qd) - sp.Matrix([sp.diff(T, s) for s in q])
    dV = sp.Matrix([sp.diff(V, s) for s in q])
    forcing = (Q - dV - convective).applyfunc(_tidy)  # paper 000, Eq 30
    m_tilde = m + sp.integrate(mc / h * psi**2, (xi, 0, h))  # paper 000, Eq 27
    k_fac = sp.simplify(h**3 * sp.integrate(sp.diff(psi, xi, 2) ** 2, (xi, 0, h)))  # Eq 27
    return OscillatorSymbols(
        q=q,
        qd=qd,
        params=P,
        ag=ag,
        T=T,
        V=V,
        M=M,
        forcing=forcing,
        ground_power=_tidy((-ag * sp.Matrix([sp.diff(X_tot, s) for s in q])).dot(sp.Matrix(qd))),
        damping_power=c * ud**2,
        m_tilde=sp.simplify(m_tilde),
        k_tilde_factor=k_fac,
        L0=sp.simplify(sp.integrate(mc / h * psi, (xi, 0, h))),
        L1=sp.simplify(sp.integrate(mc / h**2 * psi * xi, (xi, 0, h))),
    )


@cache
def numeric(shape: tuple[float, float, float, float] = (0.0, 0.0, 1.5, -0.5)):
    """Lambdified functions, built once per process and shape.

    Returns
    -------
    dict
        ``M(q, p)``, ``forcing(q, qd, ag, p)``, ``energy(q, qd, p)`` (T + V),
        ``ground_power(q, qd, ag, p)``, with ``p`` the tuple
        (m, m_c, m_b, h, b, g, k, c).
    """
    s = symbolic(tuple(sp.nsimplify(a) for a in shape))
    P = [s.params[n] for n in PARAMS]
    args_q, args_qd = list(s.q), list(s.qd)
    return {
        "M": sp.lambdify([args_q, P], s.M, "numpy", cse=True),
        "forcing": sp.lambdify([args_q, args_qd, s.ag, P], list(s.forcing), "math", cse=True),
        "energy": sp.lambdify([args_q, args_qd, P], s.T + s.V, "math", cse=True),
        "ground_power": sp.lambdify([args_q, args_qd, s.ag, P], s.ground_power, "math", cse=True),
    }
