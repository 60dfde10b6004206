"""`exp_phase`: a rocking phase advanced by an exponential integrator.

**The split.** While a column rocks, y' = f(t, y) (paper 001, Eqs 4–5, the compiled
right-hand side `._maths.rhs`, unchanged) is written over its mechanical part
x = [u, θ, u̇, θ̇] as x' = L x + N(t, y), with L the Jacobian at rest
(`multimass.engines.fast.rocking_modes`: the uplifted modal analysis' state matrix, Eqs 19–21)
and N = f − L x everything else: the constant restoring moment, the ground motion, the
nonlinear part of sin θ and cos θ, the θ̇² and θ̇ u̇ terms, the dependence of the mass
matrix on u, the Dirac-delta force of Eqs 14–17. The ledger's integrals
[D, W_g, W_F] are part of y with a zero linear part: N is their integrand. The stiff
elastic modes (41 Hz and 527 Hz in S1) sit in L, which is advanced exactly; N varies
on the time scales of the rocking and of the record. L is diagonal in its
eigenvectors, so every φ-function, φ_0 = e^z, φ_{j+1}(z) = (φ_j(z) − 1/j!)/z, is a
scalar per mode: z = V⁻¹ x, the combinations are formed mode by mode, and
x = Σ wt Re(V z) (`RockingModes`).

**A step** from (t, x), of size h:

1. *predictor*, a polynomial of N over the step in θ = τ/h:

   a. after an accepted step of the same phase segment with no record sample between
      the two (`._maths.piece_end`: N is smooth across), that step's polynomial P_old
      (step 2) continued: P̂(θ) = P_old(1 + rθ), r = h/h_old. Its error at the nodes
      is that of extrapolating a degree-4 interpolant, O(h⁵);
   b. otherwise (a segment's first step, a step that starts at a record sample)
      Krogstad's fourth-order exponential Runge–Kutta method (S. Krogstad,
      "Generalized integrating factor methods for stiff PDEs", J. Comput. Phys. 203
      (2005) 72–88; tableau as in M. Hochbruck & A. Ostermann, "Exponential
      integrators", Acta Numerica 19 (2010) 209–286, Sec. 2), nodes c = (0, ½, ½, 1),
      φ_{j,i} = φ_j(c_i hL), N_n = N(t, x)::

          U_a = e^{hL/2} x + h ½φ_{1,2} N_n
          U_b = e^{hL/2} x + h [(½φ_{1,3} − φ_{2,3}) N_n + φ_{2,3} N_a]
          U_c = e^{hL} x + h [(φ_1 − 2φ_2) N_n + 2φ_2 N_b]

      and P̂ the quadratic through N_n, (N_a + N_b)/2 and N_c at θ = 0, ½, 1 (its
      exponential quadrature below at θ = 1 is Krogstad's solution);
2. *one collocation sweep*: N at the predicted states x̃(θ_q) (the formula below with
   P̂) on the five Gauss–Legendre nodes θ_q of [0, 1], the polynomial P of degree 4
   through those values, P(θ) = Σ_k e_k θ^k, and the exact integral of the
   variation-of-constants formula with N replaced by P:

       x(t + θh) = e^{θhL} x + θh Σ_k k! θ^k φ_{k+1}(θhL) e_k

   (∫_0^τ e^{(τ−s)L} (s/h)^k ds = τ k! (τ/h)^k φ_{k+1}(τL)). This is the step's solution
   (θ = 1) and its dense output (any θ; continuous at both ends); the ledger's
   integrals are the same quadrature with L = 0 (Gauss–Legendre, exact for degree 9:
   their integrands u̇ᵀCu̇ and ü_g 1ᵀMu̇ oscillate with the elastic modes, which the
   stages alone would not resolve). It is the exponential quadrature rule of
   Hochbruck & Ostermann's Sec. 2 on Gauss nodes, with the stage values taken from
   the predictor: one Picard sweep of exponential collocation. Where N is a
   polynomial of degree ≤ 4 in t alone — the linear system under ü_g linear in t,
   between two samples of a record — the step is exact to round-off. Otherwise its
   error is the predictor's at the nodes times h and the Lipschitz constant of N
   (small: N holds no stiff term): O(h⁶) per step after 1a, O(h⁵) after 1b
   (tests/multimass/engines/test_fast_exponential.py measures the order).

A step costs 5 + 1 evaluations of f after 1a, 3 + 5 + 1 after 1b (the last, at the new
state, is the error estimate's and the next 1b's N_n) and, per evaluation, a
transform into and out of the modes (O(N²) each).

**Error estimate.** est = h 4! φ_5(hL) (N(t + h, x⁺) − P(1)): the defect of the
polynomial at the step's end — where the predictor's error is largest — against N at
the new state, weighted as a defect growing like θ⁴ (the weight of e_4 above; 1/5 for
the ledger). It is O(h⁵); the step size is controlled as in SciPy's RK45 (`._kernel`:
RMS norm with atol + rtol·max(|y|, |y⁺|), safety 0.9, growth in [0.2, 10],
exponent −1/5). Against the collocation converged by Picard iteration (S1 under El
Centro, 700 steps), the estimate is 0.95× the sweep's error (median; below 0.53× in
10 % of the steps) under the Dirac-delta force and 16× it in free rocking; with
Krogstad's predictor on every step it was 0.4× under the force. (The sweep's state
against the predicted polynomial's, the predictor's error, over-estimates it
1 000–10 000 times: as an estimate it made the method as accurate as DOP853 at the
same rtol, at 2.7× the steps.)

**Steps.** Under a record a step never crosses a sample of ü_g (ü_g is linear
between samples, `multimass.inputs.records`; a kink inside a step would cost the order): the
rest of each sample interval is split into equal steps. Elsewhere step sizes are
powers of 2^(1/4). So few distinct sizes occur, and their φ-tables (per mode: the
predictor's, the nodes', the quadrature's) are kept and reused (`_table`, the last
`_SLOTS` sizes: a record interval is split into n equal steps for several n; and
`_SPARE` tables put out of those, for a size that recurs to the bit). No step
passes `max_step` or `t_stop`.

**Arithmetic.** The transforms and L x run over real arrays laid out so that their
inner loops are contiguous (`_layout`), each sum in the order of the plain
complex product's, and a real factor multiplies a complex one without the products
with its zero imaginary part (`_times`): the same numbers to the bit (but the sign of
a zero), at 0.84× the time per run of S1 (2026-11-28).

**Events** are located on the dense output with the same event functions
(`._maths.event_value`) and the same root finder (`._rk.zeroin_next`) as the
Runge–Kutta kernel `._kernel`; the output grid is filled from it.

**Compilation.** numba links every compiled callee's machine-level code into its
caller and optimises and emits the whole again, once per level of calls. The parts
of a step called once per accepted step or attempt (`_step`, `_predictor`,
`_extrapolate`, `_sweep`, `_activation_scan`, `_brent`) are therefore inlined into the
step loop `_exp_steps` in numba's IR (``inline="always"``), not compiled as functions
of their own: the same arithmetic in the same order, about 3 s less of a cold compile.
`_exp_steps` itself stays a call: its arrays are views without an owner
(`._unowned.unowned`), which `exp_phase` must hold through the call.
"""

from __future__ import annotations

import cmath
import math

import numpy as np
from numba import njit

from ._maths import (
    EV_ACTIVATE,
    EV_PEAK,
    EV_ZERO,
    EXC_RECORD,
    activation_angle_at,
    event_value,
    piece_end,
    rhs_call,
)
from ._rk import (
    _MAX_BRENT,
    _MAX_FACTOR,
    _MIN_FACTOR,
    _SAFETY,
    EVENT,
    FAILED,
    OK,
    crosses,
    zeroin_next,
)
from ._unowned import unowned

__all__ = ["exp_phase", "new_cache", "phi_functions", "ERROR_EXPONENT"]

#: Step-size exponent: the error estimate is O(h⁵).
ERROR_EXPONENT = -0.2
#: |z| below which φ_j(z) is summed as its Taylor series (20 terms: < 1e-20 relative);
#: above it the recurrence's cancellation costs φ_5 at most ~1e-13 of its value.
_TAYLOR = 1.0
_TERMS = 20
#: Step sizes are powers of 2^(1/_QUANTA) (or a record interval split in equal parts), so
#: that few distinct sizes occur and their φ-functions are reused from `_SLOTS` tables.
_QUANTA = 4
_SLOTS = 16
#: Tables put out of the `_SLOTS` are kept in as many spares, taken back for a size
#: that is the same to the bit (`_table`): S1 under El Centro computes 208 tables in
#: place of 351.
_SPARE = 16
#: Two step sizes closer than this many ulps of the time are the same size.
_SAME_H = 64 * 2.220446049250313e-16
#: Gauss–Legendre nodes on [0, 1] of the collocation sweep, and the matrix that turns
#: values there into the coefficients of their interpolating polynomial in θ = τ/h.
_GAUSS = 5
_NODES = 0.5 * (np.polynomial.legendre.leggauss(_GAUSS)[0] + 1.0)
_TO_POLY = np.ascontiguousarray(np.linalg.inv(np.vander(_NODES, increasing=True)))
#: The Gauss nodes at which an accepted step's dense output is tested for the activation
#: of the Dirac-delta force (`_exp_steps`): the middle three (c = 0.23, 0.5, 0.77), whose
#: pieces are no longer (0.27 h at most) than those of all five.
_SCAN = np.arange(1, _GAUSS - 1)
#: Rows of the step's coefficient table (`_coefficients`).
_R_KROG = 0  # 7 rows: e^{hL/2}, ½φ_1(hL/2), φ_2(hL/2), e^{hL}, φ_1, φ_2, φ_3 (of hL)
_R_GAUSS = 7  # 5 rows: k! φ_{k+1}(hL), k = 0 … 4
_R_NODES = 12  # 6 rows per node: e^{c hL}, then c k! c^k φ_{k+1}(c hL), k = 0 … 4 (c = c_q)
_R_HGAUSS = _R_NODES + 6 * _GAUSS  # 5 rows: h times the rows of _R_GAUSS
_ROWS = _R_HGAUSS + _GAUSS
#: Binomial coefficients C(k, j), k, j ≤ 4: the shift of a polynomial in θ to the next step.
_BINOM = np.array([[math.comb(k, j) for j in range(_GAUSS)] for k in range(_GAUSS)], np.float64)
#: 1/(k + 5)!, k = 0 … _TERMS − 1: the Taylor coefficients of φ_5.
_INV_FACT5 = np.array([1.0 / math.factorial(k + 5) for k in range(_TERMS)])


@njit(cache=True, error_model="numpy")
def _times(a, z):
    """a z for a real a: the real and imaginary parts of numba's complex product
    (a + 0i) z without its products with the zero imaginary part (the same value)."""
    return complex(a * z.real, a * z.imag)


@njit(cache=True, error_model="numpy")
def _small(z):
    """abs(z) < `_TAYLOR` (= 1), by |z|² away from 1 (no hypot), by abs(z) near it."""
    s = z.real * z.real + z.imag * z.imag
    if s < 0.999999:
        return True
    if s > 1.000001:
        return False
    return abs(z) < _TAYLOR


@njit(cache=True, error_model="numpy")
def phi_functions(z):
    """(φ_0, …, φ_5)(z) of a complex scalar z.

    φ_0 = e^z, φ_{j+1}(z) = (φ_j(z) − 1/j!)/z (the recurrence of Hochbruck & Ostermann 2010, Sec. 2);
    for small |z| the recurrence cancels and the series Σ_k z^k/(k+j)! is summed.
    """
    if _small(z):
        # Horner from the top: φ_5 = Σ z^k/(k+5)!, then φ_{j} = 1/j! + z φ_{j+1}
        p5 = 0j
        for k in range(_TERMS - 1, -1, -1):
            p5 = p5 * z + _INV_FACT5[k]
        p4 = 1.0 / 24.0 + z * p5
        p3 = 1.0 / 6.0 + z * p4
        p2 = 0.5 + z * p3
        p1 = 1.0 + z * p2
        p0 = 1.0 + z * p1
        return p0, p1, p2, p3, p4, p5
    p0 = cmath.exp(z)
    p1 = (p0 - 1.0) / z
    p2 = (p1 - 1.0) / z
    p3 = (p2 - 0.5) / z
    p4 = (p3 - 1.0 / 6.0) / z
    p5 = (p4 - 1.0 / 24.0) / z
    return p0, p1, p2, p3, p4, p5


@njit(cache=True, error_model="numpy")
def _coefficients(h, lam, co):
    """The step's φ-functions per mode into co (rows: `_R_KROG`, `_R_GAUSS`, `_R_NODES`)."""
    for j in range(lam.size):
        a0, a1, a2, _, _, _ = phi_functions(0.5 * h * lam[j])
        b0, b1, b2, b3, b4, b5 = phi_functions(h * lam[j])
        co[0, j], co[1, j], co[2, j] = a0, 0.5 * a1, a2
        co[3, j], co[4, j], co[5, j], co[6, j] = b0, b1, b2, b3
        co[7, j], co[8, j], co[9, j], co[10, j], co[11, j] = b1, b2, 2.0 * b3, 6.0 * b4, 24.0 * b5
        for q in range(_GAUSS):
            c = _NODES[q]
            c0, c1, c2, c3, c4, c5 = phi_functions(c * h * lam[j])
            r = _R_NODES + 6 * q
            co[r, j], co[r + 1, j], co[r + 2, j] = c0, c * c1, c * c * c2
            co[r + 3, j], co[r + 4, j] = 2.0 * c**3 * c3, 6.0 * c**4 * c4
            co[r + 5, j] = 24.0 * c**5 * c5
    _h_rows(h, co)


@njit(cache=True, error_model="numpy")
def _h_rows(h, co):
    """The rows `_R_HGAUSS`: h times the quadrature's φ-rows, for the step size h."""
    for p in range(_GAUSS):
        for j in range(co.shape[1]):
            co[_R_HGAUSS + p, j] = _times(h, co[_R_GAUSS + p, j])


@njit(cache=True, error_model="numpy")
def _to_modes(W2, x, z):
    """z = W x over the mechanical part of x, with W2 = `_layout`'s Wᵀ (real and
    imaginary parts interleaved, as z's): the real products of W_ji x_i (x real),
    summed in the order of i for each component of z, one vector loop over them per
    i; x_i = 0 is skipped (N's rows of u are u̇ − u̇ = 0; adding W_ji · 0 changes a
    sum in no bit but a zero's sign)."""
    zf = z.view(np.float64)
    for m in range(zf.size):
        zf[m] = 0.0
    for i in range(W2.shape[0]):
        xi = x[i]
        if xi == 0.0:
            continue
        for m in range(zf.size):
            zf[m] += W2[i, m] * xi


@njit(cache=True, error_model="numpy")
def _from_modes(V2, wt, z, x):
    """x[:2N+2] = Σ_j wt_j Re(V_j z_j), with V2 = `_layout`'s rows Re V_j, Im V_j: each
    x_i summed in the order of j, one vector loop over i per j."""
    nm = V2.shape[1]
    for i in range(nm):
        x[i] = 0.0
    for j in range(z.size):
        zr, zi, w = z[j].real, z[j].imag, wt[j]
        vr, vi = V2[2 * j], V2[2 * j + 1]
        for i in range(nm):
            x[i] += w * (vr[i] * zr - vi[i] * zi)


@njit(cache=True, error_model="numpy")
def _nonlinear(t, y, out, LT, lx, model):
    """N = f(t, y) − L x (ledger rows: f), into out; LT = Lᵀ. L x goes into the
    scratch lx column by column — each row's sum in the order of its columns, as a
    row-by-row product would, one vector loop over the rows per column."""
    side, m, H, K, C_, mp, fp, kind, par, smp = model
    rhs_call(t, y, out, side, m, H, K, C_, mp, fp, kind, par, smp)
    nm = LT.shape[0]
    for i in range(nm):
        lx[i] = 0.0
    for j in range(nm):
        yj = y[j]
        for i in range(nm):
            lx[i] += LT[j, i] * yj
    for i in range(nm):
        out[i] -= lx[i]


@njit(cache=True, error_model="numpy")
def _layout(Lm, V, W):
    """(Lᵀ, scratch, V2, W2): L transposed, 2N+2 floats of scratch for `_nonlinear`;
    V2 of shape (2k, 2N+2), rows Re V_j and Im V_j; W2 = Wᵀ of shape (2N+2, 2k),
    each complex entry's real and imaginary parts side by side — the layouts whose
    inner loops run over contiguous memory (`_to_modes`, `_from_modes`,
    `_nonlinear`)."""
    nm, k = V.shape
    V2, W2 = np.empty((2 * k, nm)), np.empty((nm, 2 * k))
    for j in range(k):
        for i in range(nm):
            V2[2 * j, i], V2[2 * j + 1, i] = V[i, j].real, V[i, j].imag
            W2[i, 2 * j], W2[i, 2 * j + 1] = W[j, i].real, W[j, i].imag
    return np.ascontiguousarray(Lm.T), np.empty(nm), V2, W2


@njit(cache=True, error_model="numpy")
def _stage(y, zy, co_e, h, ca, za, cb, zb, V, wt, out, la, na, lb, nb, z):
    """out = state from modes e·zy + h (ca·za + cb·zb) (per-mode coefficients) and ledger
    y + h (la·na + lb·nb); z is scratch."""
    for j in range(zy.size):
        z[j] = co_e[j] * zy[j] + _times(h, ca[j] * za[j] + cb[j] * zb[j])
    _from_modes(V, wt, z, out)
    nm = V.shape[1]
    for i in range(nm, y.size):
        out[i] = y[i] + h * (la * na[i] + lb * nb[i])


@njit(cache=True, error_model="numpy", inline="always")
def _predictor(t, y, Nn, h, co, modes, model, work):
    """Krogstad's stages from (t, y) with N_n = N(t, y), and the quadratic p of N through
    them as the predicted polynomial in modes, E[5:10] (module docstring, step 1b)."""
    Lm, lam, V, W, wt, lx = modes
    ya, yb, yc, _, Na, Nb, Nc, _, _, zs, E, _, _, _ = work[:14]
    zy, zn, za, zb, zc, zt, zz, cn, cb = (
        zs[0], zs[1], zs[2], zs[3], zs[4], zs[5], zs[6], zs[7], zs[8]
    )  # fmt: skip
    k = lam.size
    _to_modes(W, y, zy)
    _to_modes(W, Nn, zn)
    half, one, c2 = co[0], co[3], co[1]
    for j in range(k):
        zt[j] = 0j
    _stage(y, zy, half, h, c2, zn, c2, zt, V, wt, ya, 0.5, Nn, 0.0, Nn, zz)
    _nonlinear(t + 0.5 * h, ya, Na, Lm, lx, model)
    _to_modes(W, Na, za)
    for j in range(k):
        cn[j] = co[1, j] - co[2, j]
    _stage(y, zy, half, h, cn, zn, co[2], za, V, wt, yb, 0.0, Nn, 0.5, Na, zz)
    _nonlinear(t + 0.5 * h, yb, Nb, Lm, lx, model)
    _to_modes(W, Nb, zb)
    for j in range(k):
        cb[j] = _times(2.0, co[5, j])
        cn[j] = co[4, j] - cb[j]
    _stage(y, zy, one, h, cn, zn, cb, zb, V, wt, yc, 0.0, Nn, 1.0, Nb, zz)
    _nonlinear(t + h, yc, Nc, Lm, lx, model)
    _to_modes(W, Nc, zc)
    for j in range(k):
        E[5, j] = zn[j]
        E[6, j] = _times(-3.0, zn[j]) + _times(2.0, za[j] + zb[j]) - zc[j]
        E[7, j] = _times(2.0, zn[j] - za[j] - zb[j] + zc[j])
        E[8, j] = 0j
        E[9, j] = 0j


@njit(cache=True, error_model="numpy", inline="always")
def _extrapolate(r, y, modes, work):
    """The previous step's polynomial of N continued over the next step (module
    docstring, step 1a): P_old(1 + r θ) = Σ_j θ^j r^j Σ_{k≥j} C(k, j) e_k, r = h/h_old,
    in modes into E[5:10]; zy = W x."""
    _, lam, _, W, _, _ = modes
    zs, E, Ep = work[9], work[10], work[14]
    _to_modes(W, y, zs[0])
    for j in range(lam.size):
        rj = 1.0
        for jj in range(_GAUSS):
            acc = 0j
            for kk in range(jj, _GAUSS):
                acc += _times(_BINOM[kk, jj], Ep[kk, j])
            E[5 + jj, j] = _times(rj, acc)
            rj *= r


@njit(cache=True, error_model="numpy", inline="always")
def _sweep(t, y, h, co, modes, model, work):
    """The collocation sweep on the predicted polynomial (module docstring, step 2): N at
    the Gauss nodes, the polynomial of degree 4 through them (E[:5], ledger dl[:5]) and
    its quadrature to the new state (ynew) and N there (Nnew)."""
    Lm, lam, V, W, wt, lx = modes
    _, _, _, ynew, _, _, _, Nnew, _, zs, E, dl, Zq, ytmp = work[:14]
    zy, zz = zs[0], zs[6]
    k, nm, ny = lam.size, V.shape[1], y.size
    one = co[3]
    for q in range(_GAUSS):  # N on the predictor's dense output at the nodes
        cq = _NODES[q]
        r = _R_NODES + 6 * q
        for j in range(k):
            acc = co[r + 1, j] * E[5, j] + co[r + 2, j] * E[6, j] + co[r + 3, j] * E[7, j]
            acc += co[r + 4, j] * E[8, j] + co[r + 5, j] * E[9, j]
            zz[j] = co[r, j] * zy[j] + _times(h, acc)
        _from_modes(V, wt, zz, ytmp)
        for i in range(nm, ny):
            ytmp[i] = y[i]  # (f does not depend on the ledger)
        _nonlinear(t + cq * h, ytmp, Nnew, Lm, lx, model)
        _to_modes(W, Nnew, Zq[q])
        for i in range(nm, ny):
            dl[_GAUSS + q, i] = Nnew[i]
    # the interpolating polynomial, E[p] = Σ_q T_pq Zq[q] (real T: `_times`), each sum
    # in the order of q, one vector loop over the real components per term
    Ef, Zf = E.view(np.float64), Zq.view(np.float64)
    for p in range(_GAUSS):
        for m in range(2 * k):
            Ef[p, m] = 0.0
        for q in range(_GAUSS):
            tpq = _TO_POLY[p, q]
            for m in range(2 * k):
                Ef[p, m] += tpq * Zf[q, m]
    for j in range(k):  # and its exponential quadrature
        acc = one[j] * zy[j]
        for p in range(_GAUSS):
            acc += co[_R_HGAUSS + p, j] * E[p, j]  # (h φ-row: cached with the table)
        zz[j] = acc
    _from_modes(V, wt, zz, ynew)
    for i in range(nm, ny):  # the ledger: the same with L = 0 (Gauss–Legendre)
        acc = 0.0
        for p in range(_GAUSS):
            c = 0.0
            for q in range(_GAUSS):
                c += _TO_POLY[p, q] * dl[_GAUSS + q, i]
            dl[p, i] = c
            acc += c / (p + 1)
        ynew[i] = y[i] + h * acc
    _nonlinear(t + h, ynew, Nnew, Lm, lx, model)


@njit(cache=True, error_model="numpy", inline="always")
def _step(t, y, Nn, h, co, modes, model, work, r):
    """One step of size h from (t, y) (module docstring): predicted by the previous
    step's polynomial if r > 0 (r = h/h_old), else by Krogstad's stages from
    N_n = N(t, y); the new state in ynew, the error estimate in est, the dense output's
    coefficients in E[:5] (modes) and dl[:5] (ledger)."""
    _, lam, V, W, wt, _ = modes
    Nnew, est, zs, E, dl = work[7], work[8], work[9], work[10], work[11]
    zt = zs[5]
    k, nm, ny = lam.size, V.shape[1], y.size
    if r > 0.0:
        _extrapolate(r, y, modes, work)
    else:
        _predictor(t, y, Nn, h, co, modes, model, work)
    _sweep(t, y, h, co, modes, model, work)
    # the estimate: N at the new state against the polynomial's value there, weighted
    # as a defect growing like θ⁴: h 4! φ_5(hL)
    zz = zs[6]
    _to_modes(W, Nnew, zz)
    for j in range(k):
        d = zz[j]
        for p in range(_GAUSS):
            d -= E[p, j]
        zt[j] = co[_R_HGAUSS + 4, j] * d
    _from_modes(V, wt, zt, est)
    for i in range(nm, ny):
        d = Nnew[i]
        for p in range(_GAUSS):
            d -= dl[p, i]
        est[i] = h * d / 5.0


@njit(cache=True, error_model="numpy")
def _dense_eval(t, t_old, h, y_old, zy, E, dl, lam, V, wt, out):
    """The dense output at t in the step [t_old, t_old + h] (module docstring); E's last
    row is scratch."""
    th = (t - t_old) / h
    tau = th * h
    z = E[2 * _GAUSS]
    t2 = th * th
    if th == 0.0:  # the step's start: φ_0(0) = 1 and τ = 0 leave z = zy, y = y_old
        for j in range(zy.size):
            z[j] = zy[j]
        _from_modes(V, wt, z, out)
        for i in range(V.shape[1], y_old.size):
            out[i] = y_old[i]
        return
    for j in range(zy.size):
        p0, p1, p2, p3, p4, p5 = phi_functions(tau * lam[j])
        acc = p1 * E[0, j] + _times(th, p2) * E[1, j] + _times(2.0 * t2, p3) * E[2, j]
        acc += _times(6.0 * t2 * th, p4) * E[3, j] + _times(24.0 * t2 * t2, p5) * E[4, j]
        z[j] = p0 * zy[j] + _times(tau, acc)
    _from_modes(V, wt, z, out)
    for i in range(V.shape[1], y_old.size):
        acc = 0.0
        p = 1.0
        for k in range(_GAUSS):
            acc += dl[k, i] * p / (k + 1)
            p *= th
        out[i] = y_old[i] + tau * acc


@njit(cache=True, error_model="numpy", inline="always")
def _activation_scan(
    t_old,
    t,
    h,
    co,
    zy_old,
    E,
    y_old,
    y,
    g,
    g_new,
    active,
    n_act,
    z,
    ytmp,
    model,
    events,
    ep,
    modes,
):
    """`_exp_steps`' test of an accepted step [t_old, t] for the Dirac-delta activation
    between its ends (see there): (active events, the piece [a, b] holding its first sign
    change)."""
    side, m, H, K, C_, mp, fp, kind, par, smp = model
    ev_code, ev_dir, ev_term, ev_quiet, ev_ton = events
    V, wt = modes[2], modes[4]
    ne, n_ends = ev_code.size, n_act
    a_t, b_t = t_old, t
    for i in range(ne):  # (a rocking phase has one activation event)
        if ev_code[i] != EV_ACTIVATE or n_act > n_ends or not (t > ev_ton[i]):
            continue
        n, s = m.size, float(side)  # (a float side, as event_value passes it: one compile)
        near = side * y_old[n] < 2.0 * activation_angle_at(s, y_old, m, H, K, mp, ep)
        near = near or side * y[n] < 2.0 * activation_angle_at(s, y, m, H, K, mp, ep)
        if not near and not crosses(g[i], g_new[i], ev_dir[i]):
            continue
        g_a = g[i]
        a_t = t_old
        for q in range(_SCAN.size + 1):
            b_t = t if q == _SCAN.size else t_old + _NODES[_SCAN[q]] * h
            if q == _SCAN.size:
                g_b = g_new[i]
            elif not (b_t > ev_ton[i]):
                g_b = ev_quiet[i]
            else:
                _node_state(_SCAN[q], co, zy_old, E, h, y_old, V, wt, z, ytmp)
                g_b = event_value(
                    ev_code[i], b_t, ytmp, ev_ton[i], ev_quiet[i], side, m, H, K, C_, mp,
                    ep, kind, par, smp,
                )  # fmt: skip
            if crosses(g_a, g_b, ev_dir[i]):
                active[n_act] = i
                n_act += 1
                break
            g_a, a_t = g_b, b_t
    return n_act, a_t, b_t


@njit(cache=True, error_model="numpy")
def _node_state(q, co, zy, E, h, y_old, V, wt, z, out):
    """The accepted step's dense output at its Gauss node q, t_old + c_q h, from the
    step's φ-table (the node rows of `_coefficients`, no new φ-function): the formula of
    `_dense_eval` with θ = c_q; the ledger rows (which no event reads) are y_old's."""
    r = _R_NODES + 6 * q
    for j in range(zy.size):
        acc = co[r + 1, j] * E[0, j] + co[r + 2, j] * E[1, j] + co[r + 3, j] * E[2, j]
        acc += co[r + 4, j] * E[3, j] + co[r + 5, j] * E[4, j]
        z[j] = co[r, j] * zy[j] + _times(h, acc)
    _from_modes(V, wt, z, out)
    for i in range(V.shape[1], y_old.size):
        out[i] = y_old[i]


@njit(cache=True, error_model="numpy", inline="always")
def _brent(code, a, b, t_on, quiet, dense, model, ep, ytmp):
    """Root of event `code` on the dense output in [a, b] (`._rk._brent`, same zeroin)."""
    t_old, h, y_old, zy, D, dl, lam, V, wt = dense
    side, m, H, K, C_, mp, _, kind, par, smp = model
    _dense_eval(a, t_old, h, y_old, zy, D, dl, lam, V, wt, ytmp)
    fa = event_value(code, a, ytmp, t_on, quiet, side, m, H, K, C_, mp, ep, kind, par, smp)
    _dense_eval(b, t_old, h, y_old, zy, D, dl, lam, V, wt, ytmp)
    fb = event_value(code, b, ytmp, t_on, quiet, side, m, H, K, C_, mp, ep, kind, par, smp)
    if fa == 0.0:
        return a
    if fb == 0.0 or (fa > 0.0) == (fb > 0.0):
        return b
    c, fc, d, e = b, fb, b - a, b - a
    for _ in range(_MAX_BRENT):
        done, a, fa, b, c, fc, d, e = zeroin_next(a, fa, b, fb, c, fc, d, e)
        if done:
            return b
        _dense_eval(b, t_old, h, y_old, zy, D, dl, lam, V, wt, ytmp)
        fb = event_value(code, b, ytmp, t_on, quiet, side, m, H, K, C_, mp, ep, kind, par, smp)
    return b


@njit(cache=True, error_model="numpy")
def _quantised(h_abs, level, t, t_end, piece, span):
    """(step size to try, its level) for a proposed `h_abs`: the level is the power of
    2^(1/_QUANTA) below it, or the current `level` if that is at most twice as long
    (a new size costs a new φ-table: grow by doubling or not at all); within a
    record's interval (of length `span`) ending at `piece`, the interval split into
    equal steps no longer than the level, span/n, a size that recurs from one interval
    to the next, and the rest of an interval entered between those steps in two equal
    ones once it is shorter than two; never past `t_end`."""
    q = 2.0 ** (math.floor(_QUANTA * math.log2(h_abs)) / _QUANTA)
    if level <= q < 2.0 * level:
        q = level
    rest = t_end - t
    if t_end == piece:
        s = span / max(math.ceil(span / q * (1.0 - 1e-12)), 1)
        if rest <= s * (1.0 + 1e-9):
            return rest, q
        if rest < 2.0 * s:
            return 0.5 * rest, q
        return s, q
    return min(q, rest), q


@njit(cache=True, error_model="numpy")
def new_cache(k):
    """What `exp_phase` keeps from one call to the next of a run, for `k` modes: the
    φ-tables of the last step sizes (`_table`) and the last accepted step size (the
    next phase's first try).

    (tables, sizes, slots, last): `_SLOTS` + `_SPARE` tables; sizes[p] the step size
    of table p's φ-functions and sizes[P + p] that of its rows `_R_HGAUSS` (P tables);
    slots[:_SLOTS] the slots' ages, slots[_SLOTS:2 _SLOTS] their tables, then the
    spares' tables and the next spare to reuse.
    """
    n_tab = _SLOTS + _SPARE
    tables = np.empty((n_tab, _ROWS, k), np.complex128)
    slots = np.zeros(2 * _SLOTS + _SPARE + 1, np.int64)
    for p in range(n_tab):
        slots[_SLOTS + p] = p
    return tables, np.full(2 * n_tab, -1.0), slots, np.zeros(1)


@njit(cache=True, error_model="numpy")
def _table(h, t, lam, tables, sizes, slots):
    """The φ-function table of step size h (`new_cache`'s arrays).

    A slot's table of a size within `_SAME_H` of h, the least recently used of the
    `_SLOTS` (its rows `_R_HGAUSS` made again for h if they were made for another
    size: the step multiplies by h itself); else the oldest slot takes the table of
    h: a spare made for h to the bit — the same table as computed — or the oldest
    spare, computed. The table the slot held becomes a spare.
    """
    n, n_tab = _SLOTS, tables.shape[0]
    tol = _SAME_H * (abs(t) + h)
    best = 0
    for i in range(n):
        slots[i] += 1
        p = slots[n + i]
        if abs(sizes[p] - h) <= tol:
            slots[i] = 0
            if sizes[n_tab + p] != h:
                _h_rows(h, tables[p])
                sizes[n_tab + p] = h
            return tables[p]
        if slots[i] > slots[best]:
            best = i
    out = slots[n + best]
    slots[best] = 0
    for s in range(2 * n, 2 * n + _SPARE):
        p = slots[s]
        if sizes[p] == h:
            slots[s], slots[n + best] = out, p
            if sizes[n_tab + p] != h:
                _h_rows(h, tables[p])
                sizes[n_tab + p] = h
            return tables[p]
    c = 2 * n + slots[2 * n + _SPARE]
    p = slots[c]
    slots[c], slots[n + best] = out, p
    slots[2 * n + _SPARE] = (slots[2 * n + _SPARE] + 1) % _SPARE
    _coefficients(h, lam, tables[p])
    sizes[p] = sizes[n_tab + p] = h
    return tables[p]


@njit(cache=True, error_model="numpy")
def _rms(v, y, ynew, rtol, atol):
    acc = 0.0
    for j in range(v.size):
        x = v[j] / (atol + max(abs(y[j]), abs(ynew[j])) * rtol)
        acc += x * x
    return math.sqrt(acc / v.size)


@njit(cache=True, error_model="numpy")
def _first_step(y, Nn, span, max_step, rtol, atol):
    """A first step from the size of N against y (Hairer, Nørsett & Wanner I, II.4's
    h0 = 0.01 ‖y‖/‖y'‖ with y' → N: L is exact at any step); control takes over."""
    d0 = 0.0
    d1 = 0.0
    for j in range(y.size):
        sc = atol + abs(y[j]) * rtol
        d0 += (y[j] / sc) ** 2
        d1 += (Nn[j] / sc) ** 2
    h0 = 1e-6 if (d0 < 1e-10 or d1 < 1e-10) else 0.01 * math.sqrt(d0 / d1)
    return min(max(h0, 1e-6), span, max_step)


@njit(cache=True, error_model="numpy")
def exp_phase(
    t0,
    t_stop,
    y0,
    t_eval,
    side,
    m,
    H,
    K,
    C_,
    mp,
    fp,
    ev_code,
    ev_dir,
    ev_term,
    ev_quiet,
    ev_ton,
    ep,
    kind,
    par,
    smp,
    Lm,
    lam,
    V,
    W,
    wt,
    cache,
    rtol,
    atol,
    max_step,
):
    """Integrate the rocking phase `side` from (t0, y0) towards t_stop with events.

    Arguments and returns as `._kernel.integrate_phase`, with the method code replaced
    by `RockingModes.arrays` (L, lam, V, W, wt) and the run's `new_cache`. The first
    step tries the last accepted step of the previous call (the Hairer–Nørsett–Wanner
    guess of `_first_step` in the first call).
    """
    ny, ne, k = y0.size, ev_code.size, lam.size
    work = (
        np.empty(ny), np.empty(ny), np.empty(ny), np.empty(ny), np.empty(ny),
        np.empty(ny), np.empty(ny), np.empty(ny), np.empty(ny),
        np.empty((9, k), np.complex128), np.empty((2 * _GAUSS + 1, k), np.complex128),
        np.zeros((2 * _GAUSS, ny)), np.empty((_GAUSS, k), np.complex128), np.empty(ny),
        np.empty((_GAUSS, k), np.complex128),
    )  # fmt: skip
    state = (y0.copy(), np.empty(ny), np.empty(ny), np.empty(ne), np.empty(ne), np.empty(ne))
    active, samples = np.empty(ne, np.int64), np.empty((t_eval.size, ny))
    nt = (np.empty(8, np.int64), np.empty(8), np.empty((8, ny)))
    LT, lx, V2, W2 = _layout(Lm, V, W)
    status, t, terminal, nfev, i_eval, nt, n_nt = _exp_steps(
        t0, t_stop, t_eval, samples, (side, m, H, K, C_, mp, fp, kind, par, smp),
        (ev_code, ev_dir, ev_term, ev_quiet, ev_ton), ep, (LT, lam, V2, W2, wt, lx), cache,
        (rtol, atol, max_step), work, state, active, nt,
    )  # fmt: skip
    nt_i, nt_t, nt_y = nt
    return (
        status, t, state[0], terminal, nfev, samples[:i_eval], nt_i[:n_nt], nt_t[:n_nt],
        nt_y[:n_nt],
    )  # fmt: skip


@njit(cache=True, error_model="numpy")
def _exp_steps(
    t0, t_stop, t_eval, samples, model, events, ep, modes, cache, tol, work, state, active, nt
):
    """The step loop of `exp_phase` on its arrays (the state in state[0], y0 on entry;
    `work`, the rest of `state` and `active` its buffers): (status, t, terminal event,
    RHS calls, samples filled, nt, non-terminal roots in nt).

    Every array but the non-terminal roots' buffers `nt` (grown here) is taken as a view
    without an owner (`._unowned.unowned`): `exp_phase` and the run hold them through
    the call, and numba then counts no references to them in the loop.
    """
    side, m, H, K, C_, mp, fp, kind, par, smp = model
    ev_code, ev_dir, ev_term, ev_quiet, ev_ton = events
    Lm, lam, V, W, wt, lx = modes
    tables, sizes, slots, last = cache
    rtol, atol, max_step = tol
    ya, yb, yc, ynew, Na, Nb, Nc, Nnew, est, zs, E, dl, Zq, ytmp, Ep = work
    y, y_old, Nn, g, g_new, roots = state
    nt_i, nt_t, nt_y = nt
    m, H, K, C_, mp = unowned(m), unowned(H), unowned(K), unowned(C_), unowned(mp)
    fp, par, smp, ep = unowned(fp), unowned(par), unowned(smp), unowned(ep)
    ev_code, ev_dir, ev_term = unowned(ev_code), unowned(ev_dir), unowned(ev_term)
    ev_quiet, ev_ton, t_eval = unowned(ev_quiet), unowned(ev_ton), unowned(t_eval)
    Lm, lam, V, W, wt = unowned(Lm), unowned(lam), unowned(V), unowned(W), unowned(wt)
    lx = unowned(lx)
    tables, sizes, slots, last = unowned(tables), unowned(sizes), unowned(slots), unowned(last)
    ya, yb, yc, ynew = unowned(ya), unowned(yb), unowned(yc), unowned(ynew)
    Na, Nb, Nc, Nnew, est = unowned(Na), unowned(Nb), unowned(Nc), unowned(Nnew), unowned(est)
    zs, E, dl, Zq = unowned(zs), unowned(E), unowned(dl), unowned(Zq)
    ytmp, Ep, samples, active = unowned(ytmp), unowned(Ep), unowned(samples), unowned(active)
    y, y_old, Nn, g = unowned(y), unowned(y_old), unowned(Nn), unowned(g)
    g_new, roots = unowned(g_new), unowned(roots)
    ny, ne, k = y.size, ev_code.size, lam.size
    model = (side, m, H, K, C_, mp, fp, kind, par, smp)
    modes = (Lm, lam, V, W, wt, lx)
    work = (ya, yb, yc, ynew, Na, Nb, Nc, Nnew, est, zs, E, dl, Zq, ytmp, Ep)
    t, i_eval, n_nt = t0, 0, 0
    _nonlinear(t, y, Nn, Lm, lx, model)
    nfev = 1
    h_abs = last[0] if last[0] > 0.0 else _first_step(y, Nn, t_stop - t0, max_step, rtol, atol)
    level = 0.0
    # the last accepted step's polynomial of N predicts the next step while N is smooth
    # from one to the next: no record sample between them (`piece_end`)
    h_prev, piece_prev = 0.0, -1.0
    span = 1.0 / par[2] if kind == EXC_RECORD else 0.0  # a record's sample interval
    for i in range(ne):
        g[i] = event_value(
            ev_code[i], t, y, ev_ton[i], ev_quiet[i], side, m, H, K, C_, mp, ep, kind, par, smp
        )
    while True:
        # one accepted step (SciPy's RK45 control, exponent −1/5)
        min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
        if h_abs > max_step:
            h_abs = max_step
        rejected = False
        piece = piece_end(t, kind, par)
        t_end = min(t_stop, piece)
        smooth = h_prev > 0.0 and piece == piece_prev
        while True:
            if h_abs < min_step:
                return FAILED, t, -1, nfev, i_eval, (nt_i, nt_t, nt_y), 0
            h, level = _quantised(h_abs, level, t, t_end, piece, span)
            t_new = t + h if t + h < t_end else t_end
            co = _table(h, t, lam, tables, sizes, slots)
            _step(t, y, Nn, h, co, modes, model, work, h / h_prev if smooth else 0.0)
            nfev += 1 + _GAUSS if smooth else 4 + _GAUSS
            err = _rms(est, y, ynew, rtol, atol)
            if err < 1.0:
                factor = _MAX_FACTOR if err == 0.0 else _SAFETY * err**ERROR_EXPONENT
                if not (factor < _MAX_FACTOR):
                    factor = _MAX_FACTOR
                if rejected and factor > 1.0:
                    factor = 1.0
                h_abs = level * factor  # (h is shorter only at the end of a piece)
                last[0] = h_abs
                break
            factor = _SAFETY * err**ERROR_EXPONENT
            if not (factor > _MIN_FACTOR):
                factor = _MIN_FACTOR
            h_abs = abs(h) * factor
            rejected = True
        t_old, t = t, t_new
        zy_old = zs[0]
        dense = (t_old, h, y_old, zy_old, E, dl, lam, V, wt)
        for j in range(ny):
            y_old[j] = y[j]
            y[j] = ynew[j]
            Nn[j] = Nnew[j]
        for p in range(_GAUSS):  # the next step's predictor
            for j in range(k):
                Ep[p, j] = E[p, j]
        h_prev, piece_prev = h, piece
        finished = t - t_stop >= 0.0
        terminal = -1
        for i in range(ne):
            g_new[i] = event_value(
                ev_code[i], t, y, ev_ton[i], ev_quiet[i], side, m, H, K, C_, mp, ep, kind, par, smp
            )
        n_act = 0
        for i in range(ne):  # a sign change over the step
            if ev_code[i] != EV_ACTIVATE and crosses(g[i], g_new[i], ev_dir[i]):
                active[n_act] = i
                n_act += 1
        n_ends = n_act
        # the Dirac-delta activation: the first sign change over the step's pieces between
        # the dense output at its Gauss nodes (`_node_state`). Its margin holds the pivot
        # momentum and θ̇, which swing with the elastic modes that the step follows
        # exactly: within one step it can dip below zero and back (measured on a 20-node
        # column under El Centro, DD5: a 9 ms window missed at 5 ms steps). Only where θ
        # comes within twice its activation angle at either end (`._maths.activation_angle_at`,
        # Eq 15's width at that state's energy and θ̇): elsewhere the margin's angle term
        # holds it positive (away from a turning point θ moves one way over a step; near
        # one θ̇ ≈ 0 and the angle is at its widest at the ends too).
        n_act, a_t, b_t = _activation_scan(
            t_old, t, h, co, zy_old, E, y_old, y, g, g_new, active, n_act, zs[6], ytmp,
            model, events, ep, modes,
        )  # fmt: skip
        # roots on the dense output; a step whose θ̇ root has θ past zero by more than
        # atol, with θ on the rocking side at its start and the zero event's ends both
        # positive, crossed θ = 0 twice (`._kernel._zero_between`): that crossing joins
        # the roots, found in [t_old, θ̇'s root] by the same root finder (one call site:
        # `_brent` is inlined)
        k_zero, t_p = -1, 0.0
        i = 0
        while i < n_act:
            if active[i] == k_zero:
                lo, hi = t_old, t_p
            elif i < n_ends:
                lo, hi = t_old, t
            else:
                lo, hi = a_t, b_t
            roots[i] = _brent(
                ev_code[active[i]], lo, hi, ev_ton[active[i]], ev_quiet[active[i]], dense,
                model, ep, ytmp,
            )  # fmt: skip
            if ev_code[active[i]] == EV_PEAK and k_zero < 0 and side * y_old[m.size] > 0.0:
                for kz in range(ne):  # (not k: the loop's count of mechanical states)
                    if ev_code[kz] == EV_ZERO and g[kz] > 0.0 and g_new[kz] > 0.0:
                        _dense_eval(roots[i], t_old, h, y_old, zy_old, E, dl, lam, V, wt, ytmp)
                        z = event_value(
                            ev_code[kz], roots[i], ytmp, ev_ton[kz], ev_quiet[kz], side, m, H,
                            K, C_, mp, ep, kind, par, smp,
                        )  # fmt: skip
                        if z < -atol:
                            k_zero, t_p = kz, roots[i]
                            active[n_act] = kz
                            n_act += 1
            i += 1
        for i in range(1, n_act):  # sort by time, stable (`._kernel._sorted_roots`)
            a_i, r = active[i], roots[i]
            j = i - 1
            while j >= 0 and roots[j] > r:
                active[j + 1] = active[j]
                roots[j + 1] = roots[j]
                j -= 1
            active[j + 1] = a_i
            roots[j + 1] = r
        for i in range(n_act):
            if ev_term[active[i]]:
                terminal, t = active[i], roots[i]
                _dense_eval(t, t_old, h, y_old, zy_old, E, dl, lam, V, wt, y)
                break
            if n_nt == nt_i.size:  # grow the non-terminal roots' buffer
                nt_i = np.concatenate((nt_i, np.empty(n_nt, np.int64)))
                nt_t = np.concatenate((nt_t, np.empty(n_nt)))
                nt_y = np.concatenate((nt_y, np.empty((n_nt, ny))))
            nt_i[n_nt], nt_t[n_nt] = active[i], roots[i]
            _dense_eval(roots[i], t_old, h, y_old, zy_old, E, dl, lam, V, wt, nt_y[n_nt])
            n_nt += 1
        for i in range(ne):
            g[i] = g_new[i]
        while i_eval < t_eval.size and t_eval[i_eval] <= t:
            _dense_eval(t_eval[i_eval], t_old, h, y_old, zy_old, E, dl, lam, V, wt, samples[i_eval])
            i_eval += 1
        if terminal >= 0:
            return EVENT, t, terminal, nfev, i_eval, (nt_i, nt_t, nt_y), n_nt
        if finished:
            return OK, t, -1, nfev, i_eval, (nt_i, nt_t, nt_y), n_nt
