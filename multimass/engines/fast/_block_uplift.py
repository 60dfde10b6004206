"""When does a rigid block at rest uplift: `multimass.engines._rigid.next_uplift` in machine code.

The same search, step for step, so that the batched runs of `._block_kernel` start
rocking at the very instants the Python phase loop finds:

* ``|ü_g|`` sampled on NumPy's ``linspace`` grid of the interval (the same points:
  ``i · step + t0``, the last point ``t1``), scanned up to the first sample above
  the threshold ``a_th`` (paper 001, Eq 8 with no elastic motion; paper 004, Sec 2);
* each local maximum of the samples within 5 % below ``a_th`` refined by SciPy's
  bounded scalar minimiser (`_fminbound`: the algorithm of
  ``scipy.optimize.minimize_scalar(method="bounded")``, Brent's golden section with
  parabolic steps, Forsythe, Malcolm & Moler 1977);
* the crossing located by SciPy's ``brentq`` (`_brentq`: Brent 1973, as in SciPy's
  ``Zeros/brentq.c``), with the same tolerances.

ü_g is `._maths.ground_acc`, evaluated in the order of operations of the
excitation's ``_scalar`` method. The one difference from the Python search: NumPy
may evaluate the *sampled* ``|ü_g|`` with SIMD functions that differ from ``libm`` in
the last bit (``np.exp`` for a Ricker wavelet; ``np.sin`` and ``np.cos`` agree here),
which can matter only for a sample within one ulp of a comparison.
"""

from __future__ import annotations

import math

from numba import njit

from ._maths import ground_acc

__all__ = ["next_uplift"]

_EPS = 2.220446049250313e-16  # np.finfo(float).eps
_SQRT_EPS = math.sqrt(2.2e-16)  # scipy.optimize._optimize._minimize_scalar_bounded
_GOLDEN = 0.5 * (3.0 - math.sqrt(5.0))
_STEP, _MARGIN = 1e-3, 0.05  # the defaults of multimass.engines._rigid.next_uplift
_XATOL = 1e-12  # its minimize_scalar options
_XTOL, _RTOL, _MAXITER = 1e-13, 4.0 * _EPS, 100  # its brentq options (maxiter: SciPy's default)
_MAXFUN = 500  # minimize_scalar's default maxiter


@njit(cache=True, error_model="numpy")
def _sign(x):
    """np.sign of a float (0 for 0)."""
    return 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)


@njit(cache=True, error_model="numpy")
def _fminbound(lo, hi, kind, par, smp):
    """(x, f(x)) minimising f = −|ü_g| on [lo, hi]: SciPy's bounded Brent method, xatol 1e-12."""
    a, b = lo, hi
    fulc = a + _GOLDEN * (b - a)
    nfc, xf = fulc, fulc
    rat = e = 0.0
    x = xf
    fx = -abs(ground_acc(x, kind, par, smp))
    num = 1
    ffulc = fnfc = fx
    xm = 0.5 * (a + b)
    tol1 = _SQRT_EPS * abs(xf) + _XATOL / 3.0
    tol2 = 2.0 * tol1
    while abs(xf - xm) > (tol2 - 0.5 * (b - a)):
        golden = True
        if abs(e) > tol1:  # a parabolic fit
            golden = False
            r = (xf - nfc) * (fx - ffulc)
            q = (xf - fulc) * (fx - fnfc)
            p = (xf - fulc) * q - (xf - nfc) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = abs(q)
            r = e
            e = rat
            if (abs(p) < abs(0.5 * q * r)) and (p > q * (a - xf)) and (p < q * (b - xf)):
                rat = (p + 0.0) / q
                x = xf + rat
                if ((x - a) < tol2) or ((b - x) < tol2):
                    rat = tol1 * (_sign(xm - xf) + (1.0 if xm - xf == 0.0 else 0.0))
            else:
                golden = True
        if golden:  # a golden-section step
            e = (a - xf) if xf >= xm else (b - xf)
            rat = _GOLDEN * e
        si = _sign(rat) + (1.0 if rat == 0.0 else 0.0)
        x = xf + si * max(abs(rat), tol1)
        fu = -abs(ground_acc(x, kind, par, smp))
        num += 1
        if fu <= fx:
            if x >= xf:
                a = xf
            else:
                b = xf
            fulc, ffulc = nfc, fnfc
            nfc, fnfc = xf, fx
            xf, fx = x, fu
        else:
            if x < xf:
                a = x
            else:
                b = x
            if (fu <= fnfc) or (nfc == xf):
                fulc, ffulc = nfc, fnfc
                nfc, fnfc = x, fu
            elif (fu <= ffulc) or (fulc == xf) or (fulc == nfc):
                fulc, ffulc = x, fu
        xm = 0.5 * (a + b)
        tol1 = _SQRT_EPS * abs(xf) + _XATOL / 3.0
        tol2 = 2.0 * tol1
        if num >= _MAXFUN:
            break
    return xf, fx


@njit(cache=True, error_model="numpy", inline="always")
def _margin(t, side, a_th, kind, par, smp):
    """> 0 once the block uplifts about `side` (as `multimass.engines._rigid._crossing`'s f)."""
    return side * -ground_acc(t, kind, par, smp) - a_th


@njit(cache=True, error_model="numpy")
def _brentq(xa, xb, side, a_th, kind, par, smp):
    """(root, ok) of `_margin` in [xa, xb]: SciPy's brentq, xtol 1e-13, rtol 4 ε, 100 iterations.

    ok is False where brentq would raise (no sign change, or no convergence).
    """
    xpre, xcur = xa, xb
    xblk = fblk = spre = scur = 0.0
    fpre = _margin(xpre, side, a_th, kind, par, smp)
    fcur = _margin(xcur, side, a_th, kind, par, smp)
    if fpre * fcur > 0.0:
        return 0.0, False
    if fpre == 0.0:
        return xpre, True
    if fcur == 0.0:
        return xcur, True
    for _ in range(_MAXITER):
        if fpre * fcur < 0.0:
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = (_XTOL + _RTOL * abs(xcur)) / 2.0
        sbis = (xblk - xcur) / 2.0
        if fcur == 0.0 or abs(sbis) < delta:
            return xcur, True
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:  # interpolate
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:  # extrapolate
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2.0 * abs(stry) < min(abs(spre), 3.0 * abs(sbis) - delta):
                spre, scur = scur, stry  # a good short step
            else:
                spre = scur = sbis  # bisect
        else:
            spre = scur = sbis  # bisect
        xpre, fpre = xcur, fcur
        if abs(scur) > delta:
            xcur += scur
        else:
            xcur += delta if sbis > 0.0 else -delta
        fcur = _margin(xcur, side, a_th, kind, par, smp)
    return xcur, False


@njit(cache=True, error_model="numpy")
def _crossing(lo, hi, a_th, kind, par, smp):
    """(t, side, ok): where ``|ü_g|`` rises through a_th in [lo, hi], and the pivot."""
    side = -1 if ground_acc(hi, kind, par, smp) > 0.0 else 1
    t, ok = _brentq(lo, hi, side, a_th, kind, par, smp)
    return t, side, ok


@njit(cache=True, error_model="numpy", inline="always")
def _sample(i, num, t0, t1, step, kind, par, smp):
    """``|ü_g|`` at point i of ``np.linspace(t0, t1, num)`` (and the point)."""
    t = t1 if i == num - 1 else i * step + t0
    return abs(ground_acc(t, kind, par, smp)), t


@njit(cache=True, error_model="numpy")
def next_uplift(t0, t1, a_th, kind, par, smp):
    """(found, t, side, ok): the first uplift of a rigid block at rest in [t0, t1].

    As `multimass.engines._rigid.next_uplift` (see the module docstring); `ok` is False
    where SciPy's brentq would have raised.
    """
    if t1 <= t0:
        return False, 0.0, 0, True
    num = max(3, int(math.ceil((t1 - t0) / _STEP)) + 1)
    step = (t1 - t0) / (num - 1)
    near = (1.0 - _MARGIN) * a_th
    a_prev, t_prev = _sample(0, num, t0, t1, step, kind, par, smp)
    if a_prev > a_th:
        return True, t_prev, (-1 if ground_acc(t_prev, kind, par, smp) > 0.0 else 1), True
    a_cur, t_cur = _sample(1, num, t0, t1, step, kind, par, smp)
    for j in range(1, num):
        if a_cur > a_th:  # the first sampled exceedance: j
            t, side, ok = _crossing(t_prev, t_cur, a_th, kind, par, smp)
            return True, t, side, ok
        if j == num - 1:
            break
        a_next, t_next = _sample(j + 1, num, t0, t1, step, kind, par, smp)
        if a_cur >= a_prev and a_cur >= a_next and a_cur > near:  # a maximum close below
            x, fx = _fminbound(t_prev, t_next, kind, par, smp)
            if -fx > a_th:
                t, side, ok = _crossing(t_prev, x, a_th, kind, par, smp)
                return True, t, side, ok
        a_prev, t_prev, a_cur, t_cur = a_cur, t_cur, a_next, t_next
    return False, 0.0, 0, True
