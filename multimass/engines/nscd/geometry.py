"""Contact geometry: closest point on the deformed beam and the local frame
(paper 002, Sections 4.1–4.2, Eqs 45–63), written for numba.

The functions are compiled with ``numba.njit`` and take plain arrays; the
readable NumPy counterpart (with ``numpy.roots`` on the quintic) lives in
`nscd.reference`, and the tests compare the two.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = [
    "element_cubic",
    "closest_on_element",
    "closest_point",
    "contact_frame",
    "N_SUBINTERVALS",
]

#: sub-intervals scanned for sign changes of the quintic in each element
N_SUBINTERVALS = 8


@njit(cache=True)
def element_cubic(qe, edof, e, Le):
    """Coefficients (c0, c1, c2, c3) of v(s) = c0 + c1 s + c2 s² + c3 s³ on element e.

    paper 002, Eq 59 with the Hermite functions, s ∈ [0, Le] from the left node.
    """
    rho = np.zeros(6)
    for a in range(6):
        i = edof[e, a]
        if i >= 0:
            rho[a] = qe[i]
    v1, t1, v2, t2 = rho[1], rho[2], rho[4], rho[5]
    c2 = (3.0 * (v2 - v1) - (2.0 * t1 + t2) * Le) / (Le * Le)
    c3 = (2.0 * (v1 - v2) + (t1 + t2) * Le) / (Le * Le * Le)
    return v1, t1, c2, c3


@njit(cache=True)
def _g(s, c0, c1, c2, c3, x1, dx, dy):
    """Half the derivative of the squared distance, paper 002, Eq 62, and its derivative."""
    v = c0 + s * (c1 + s * (c2 + s * c3))
    dv = c1 + s * (2.0 * c2 + 3.0 * s * c3)
    ddv = 2.0 * c2 + 6.0 * s * c3
    g = (v - dy) * dv + (x1 + s) - dx  # paper 002, Eq 62
    dg = dv * dv + (v - dy) * ddv + 1.0
    return g, dg


@njit(cache=True)
def _refine(a, b, ga, c0, c1, c2, c3, x1, dx, dy, Le):
    """A root of g in [a, b] with g(a) < 0 < g(b): Newton safeguarded by bisection."""
    s = 0.5 * (a + b)
    for _ in range(100):
        g, dg = _g(s, c0, c1, c2, c3, x1, dx, dy)
        if g == 0.0:
            return s
        if (g < 0.0) == (ga < 0.0):
            a, ga = s, g
        else:
            b = s
        s_new = 0.5 * (a + b)
        if dg != 0.0:
            sn = s - g / dg
            if a < sn < b:
                s_new = sn
        if abs(s_new - s) <= 1e-15 * Le or b - a <= 1e-15 * Le:
            return s_new
        s = s_new
    return s


@njit(cache=True)
def closest_on_element(c0, c1, c2, c3, x1, Le, dx, dy):
    """Nearest point of element [x1, x1 + Le] to the vertex (dx, dy) (paper 002, Eqs 60–62).

    The quintic g(s) = (v − d_y) v' + x − d_x (Eq 62) is scanned on
    `N_SUBINTERVALS` sub-intervals; each change of sign from − to + (a minimum
    of the distance, Eq 61) is refined by safeguarded Newton. The element
    ends are candidates too.

    Returns
    -------
    s : float
        Local abscissa of the nearest point.
    move : int
        −1 (or +1) if the nearest point is the left (right) end and the
        distance still decreases beyond it: the root has left the element.
    """
    best_s, best_f2, move = 0.0, np.inf, 0
    h = Le / N_SUBINTERVALS
    ga, _ = _g(0.0, c0, c1, c2, c3, x1, dx, dy)
    g0 = ga
    for k in range(N_SUBINTERVALS):
        a, b = k * h, (k + 1) * h
        gb, _ = _g(b, c0, c1, c2, c3, x1, dx, dy)
        if ga < 0.0 <= gb:
            s = b if gb == 0.0 else _refine(a, b, ga, c0, c1, c2, c3, x1, dx, dy, Le)
            v = c0 + s * (c1 + s * (c2 + s * c3))
            f2 = (x1 + s - dx) ** 2 + (v - dy) ** 2  # paper 002, Eq 60 squared
            if f2 < best_f2:
                best_s, best_f2, move = s, f2, 0
        ga = gb
    f2 = (x1 - dx) ** 2 + (c0 - dy) ** 2  # left end
    if f2 < best_f2:
        best_s, best_f2, move = 0.0, f2, -1 if g0 > 0.0 else 0
    v = c0 + Le * (c1 + Le * (c2 + Le * c3))  # right end
    f2 = (x1 + Le - dx) ** 2 + (v - dy) ** 2
    if f2 < best_f2:
        best_s, best_f2, move = Le, f2, 1 if ga < 0.0 else 0
    return best_s, move


@njit(cache=True)
def closest_point(qe, edof, x_nodes, Le, dx, dy):
    """Element and local abscissa of the beam point nearest to (dx, dy) (paper 002, Sec 4.2).

    The search starts in the element under the vertex and moves to the
    neighbouring element while the root leaves the element through its end;
    it stops at a shared node if the neighbour sends it back, and at the
    supports.
    """
    n_el = edof.shape[0]
    e = int(dx / Le)
    e = min(max(e, 0), n_el - 1)
    came_from = 0
    s = 0.0
    for _ in range(n_el + 1):
        c0, c1, c2, c3 = element_cubic(qe, edof, e, Le)
        s, move = closest_on_element(c0, c1, c2, c3, x_nodes[e], Le, dx, dy)
        if move == 0 or move == -came_from:
            break
        if move < 0 and e == 0 or move > 0 and e == n_el - 1:
            break
        e += move
        came_from = move
    return e, s


@njit(cache=True)
def contact_frame(N, qe, edof, x_nodes, Le, e, s, dx, dy):
    """Contact point b, local frame and gap for the vertex (dx, dy) (paper 002, Eq 63).

    Fills N (6,) with [N_u1, N_v1, N_v2, N_u2, N_v3, N_v4] at b (Eq 52).

    Returns
    -------
    cpsi, spsi : float
        cos ψ and sin ψ, ψ = atan(v'(b_x)) + π/2 (Eq 63); n = (cos ψ, sin ψ)
        points towards the block and t = (−sin ψ, cos ψ) (Eq 48).
    gap : float
        Signed distance (d − b)·n, negative when the vertex overlaps the beam.
    """
    c0, c1, c2, c3 = element_cubic(qe, edof, e, Le)
    x = s / Le
    N[0] = 1.0 - x
    N[1] = 1.0 - 3.0 * x * x + 2.0 * x * x * x
    N[2] = Le * (x - 2.0 * x * x + x * x * x)
    N[3] = x
    N[4] = 3.0 * x * x - 2.0 * x * x * x
    N[5] = Le * (-x * x + x * x * x)
    v = c0 + s * (c1 + s * (c2 + s * c3))
    slope = c1 + s * (2.0 * c2 + 3.0 * s * c3)
    c = 1.0 / math.sqrt(1.0 + slope * slope)
    cpsi, spsi = -slope * c, c  # paper 002, Eq 63
    gap = (dx - (x_nodes[e] + s)) * cpsi + (dy - v) * spsi
    return cpsi, spsi, gap
