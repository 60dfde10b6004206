"""Compiled explicit Runge–Kutta steps, dense output, event roots and first step.

These are the pieces of `._kernel.integrate_phase`, the compiled counterpart of
one ``solve_ivp`` call of `multimass.engines._run._Run.integrate`. They follow the
algorithm of SciPy's explicit Runge–Kutta solvers so that, at the same `rtol`,
`atol` and `max_step`, the kernel takes essentially the same steps and finds
the same events:

* the Butcher tableaus are SciPy's (RK23, RK45 = Dormand–Prince 5(4), DOP853 with
  its 7th-order dense output), the same floats written out in `._tableaus` with
  their sources;
* the first step is chosen as in Hairer, Nørsett & Wanner, *Solving ODEs I*,
  Sec. II.4 (also SciPy's choice), and the step size is controlled with the
  RMS error norm, safety factor 0.9 and growth bounded to [0.2, 10] (10 is
  not allowed straight after a rejection); DOP853 uses its combined 5th/3rd
  order error estimate (Hairer's DOP853);
* after each accepted step every event function is evaluated; an event is
  active when its sign changes in its `direction` (0: either way); its root
  is found on the dense output by Brent's method to 4 ε in t; the earliest
  terminal root ends the phase, and non-terminal roots before it (θ̇ = 0
  peaks) are returned;
* the output grid `t_eval` is filled from the dense output of the step
  that covers each time.

Three departures: under a record no step crosses one of its samples (ü_g has a
kink there; solve_ivp steps across it; `._kernel`); a column's phase segment starts
at the step the previous one proposed (solve_ivp guesses anew each call; `._kernel`);
and a column's DOP853 steps are set by a PI controller (`step_control`, `PI_BETA`: a
quarter of SciPy's attempts in free rocking were rejected), except under a record. A rigid block's segments
keep SciPy's guess and control, so its steps stay solve_ivp's.

Differences from the reference start at round-off (sums are accumulated in
loops, not by BLAS). A rigid block then takes the very same steps (states agree
to ~1e-15). The bundled columns are integrated near the stability limit of the
explicit pair, where a round-off difference can flip one accept/reject
decision; from there the two step sequences differ and so do the results, by
the integrator's own error: for S1, DD2, 10 s, event times within 1e-9 s and
peaks within 1e-11 rad of each other and of a tight reference
(benchmarks/fast_path.py; the tests allow 1e-7 s and 1e-6 rad).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from . import _tableaus as tab
from ._maths import event_value, rhs, rhs_call

__all__ = [
    "METHOD_CODES",
    "OK",
    "EVENT",
    "FAILED",
    "PI_BETA",
    "PI_KAPPA",
    "PI_ERR_FLOOR",
    "zeroin_next",
    "crosses",
    "trial_step",
    "step_control",
]

#: Methods the compiled path supports, by solve_ivp name.
METHOD_CODES = {"RK23": 0, "RK45": 1, "DOP853": 2}
_DOP = 2

# return status of integrate_phase
OK = 0  # reached t_stop
EVENT = 1  # a terminal event ended the phase
FAILED = -1  # the step size fell below the spacing of floats near t

_SAFETY, _MIN_FACTOR, _MAX_FACTOR = 0.9, 0.2, 10.0
_EPS = float(np.finfo(float).eps)
_MAX_BRENT = 100


@njit(cache=True, error_model="numpy", inline="always")
def trial_step(t, h_abs, t_end, piece):
    """(h, t_new): the step tried from t at the proposed size `h_abs` towards `t_end`
    (the segment's stop, or a record's next sample `piece` if sooner): the rest when it
    fits; equal steps to the sample when `t_end` is it (ü_g has a kink there, which an
    explicit pair answers with a rejection and a run of short steps); else `h_abs`."""
    rest = t_end - t
    if h_abs >= rest:
        return rest, t_end
    if t_end == piece:
        h = rest / math.ceil(rest / h_abs)
        return h, t + h
    return h_abs, t + h_abs


#: A column's DOP853 steps are set by a PI controller (`step_control`): β and κ of the
#: factor 0.9 err_n^−(1/8 − κβ) err_{n−1}^β. Gustafsson's controller (Hairer & Wanner,
#: *Solving ODEs II*, Sec. IV.2); κ = 0.75 as in Hairer's DOPRI5 (α = 1/5 − 0.75 β). β
#: from S1–S3's whole runs released and under El Centro and an S1 spectrum
#: (docs/guide/speed.md, "Where a whole column run's steps go"): 0.03 takes 13–14 %
#: fewer right-hand sides released (8–11 % less CPU time for S1) and 0.2–4 % fewer under
#: the record (but 3 % more CPU time for S1: more accepted steps, each with its events);
#: 0.02 gains half as much released at the same cost under the record; 0.04 takes more
#: right-hand sides under the record. A rigid block's steps keep SciPy's controller (β = 0).
PI_BETA, PI_KAPPA = 0.03, 0.75
#: the floor of err_{n−1} (Hairer's DOP853: facold = max(err, 1e-4)): an error norm of 0
#: would otherwise stop the steps
PI_ERR_FLOOR = 1e-4
_LOG_FLOOR = math.log(PI_ERR_FLOOR)


@njit(cache=True, error_model="numpy", inline="always")
def step_control(err, exponent, rejected, h, h_abs, log_prev, beta, kappa):
    """Step-size control after a step `h` tried at the proposed size `h_abs` with error
    norm `err`: (accepted, next proposed size, ln err_n for the next call).

    `exponent` is −1/(q + 1) for the error estimate's order q; `log_prev` is ln err_{n−1},
    the error norm of the last accepted step floored at `PI_ERR_FLOOR` (0: none, a
    factor 1). Accepted: grow by the factor 0.9 err^(exponent + κβ) err_{n−1}^β
    (Gustafsson's PI controller, Hairer & Wanner II, Sec. IV.2; formed as one exp of
    the logarithms, the cost of SciPy's one power), up to 10× (not at all after a
    rejection in the same step), and a step shortened to fit a sample or the stop does
    not shorten the next proposal; β = 0 is SciPy's RungeKutta control, bit for bit.
    Rejected: SciPy's, whatever β: shrink by 0.9 err^exponent, at least to 0.2 h."""
    if err < 1.0:
        log_err = _LOG_FLOOR
        if err == 0.0:
            factor = _MAX_FACTOR
        elif beta == 0.0:
            factor = _SAFETY * err**exponent
        else:
            log_err = math.log(err)
            factor = _SAFETY * math.exp((exponent + kappa * beta) * log_err + beta * log_prev)
            log_err = max(log_err, _LOG_FLOOR)
        if not (factor < _MAX_FACTOR):
            factor = _MAX_FACTOR
        if rejected and factor > 1.0:
            factor = 1.0
        return True, max(h * factor, h_abs * min(factor, 1.0)), log_err
    factor = _SAFETY * err**exponent
    if not (factor > _MIN_FACTOR):
        factor = _MIN_FACTOR
    return False, h * factor, log_prev


# tableaus (`._tableaus`, SciPy's floats; numba freezes module-level arrays as constants)
_A3, _B3, _C3, _E3, _P3 = tab.RK23_A, tab.RK23_B, tab.RK23_C, tab.RK23_E, tab.RK23_P
_A5, _B5, _C5, _E5, _P5 = tab.RK45_A, tab.RK45_B, tab.RK45_C, tab.RK45_E, tab.RK45_P
_NS8 = tab.DOP853_N_STAGES
_A8 = tab.DOP853_A  # 16 × 16, extra stages below
_B8 = tab.DOP853_B
_C8 = tab.DOP853_C
_E8_3 = tab.DOP853_E3
_E8_5 = tab.DOP853_E5
_D8 = tab.DOP853_D  # 4 × 16
_NEXT8 = tab.DOP853_N_STAGES_EXTENDED


@njit(cache=True, error_model="numpy")
def _rms(v, scale):
    acc = 0.0
    for j in range(v.size):
        x = v[j] / scale[j]
        acc += x * x
    return math.sqrt(acc) / math.sqrt(v.size)


@njit(cache=True, error_model="numpy")
def _rk_step(t, y, f, h, A, Bw, C, ns, Kst, ynew, ytmp, side, m, H, K, C_, mp, fp, kind, par, smp):
    """One explicit RK step of size h: stages in Kst[0..ns], solution in ynew."""
    ny = y.size
    for j in range(ny):
        Kst[0, j] = f[j]
    # stages 1 … ns-1, then (s = ns) the solution and its slope: one call site of the
    # inlined rhs (each inlined copy costs seconds of compile time)
    # Each sum runs over k in order, as scipy's dot products; the loop over the components
    # j is the inner one, so the components' sums advance together (vectorised).
    for s in range(1, ns + 1):
        if s < ns:
            for j in range(ny):
                ytmp[j] = 0.0
            for k in range(s):
                a = A[s, k]
                for j in range(ny):
                    ytmp[j] += Kst[k, j] * a
            for j in range(ny):
                ytmp[j] = y[j] + ytmp[j] * h
            ts, ys = t + C[s] * h, ytmp
        else:
            for j in range(ny):
                ynew[j] = 0.0
            for k in range(ns):
                b = Bw[k]
                for j in range(ny):
                    ynew[j] += Kst[k, j] * b
            for j in range(ny):
                ynew[j] = y[j] + h * ynew[j]
            ts, ys = t + h, ynew
        rhs(ts, ys, Kst[s], side, m, H, K, C_, mp, fp, kind, par, smp)


@njit(cache=True, error_model="numpy")
def _error_norm(method, Kst, h, scale, ns, ytmp):
    ny = scale.size
    if method == _DOP:
        e5 = 0.0
        e3 = 0.0
        for j in range(ny):
            a5 = 0.0
            a3 = 0.0
            for k in range(ns + 1):
                a5 += Kst[k, j] * _E8_5[k]
                a3 += Kst[k, j] * _E8_3[k]
            a5 /= scale[j]
            a3 /= scale[j]
            e5 += a5 * a5
            e3 += a3 * a3
        if e5 == 0.0 and e3 == 0.0:
            return 0.0
        return abs(h) * e5 / math.sqrt((e5 + 0.01 * e3) * ny)
    E = _E3 if method == 0 else _E5
    for j in range(ny):
        acc = 0.0
        for k in range(ns + 1):
            acc += Kst[k, j] * E[k]
        ytmp[j] = acc * h
    return _rms(ytmp, scale)


@njit(cache=True, error_model="numpy")
def _dense_prepare(
    method, t_old, h, y_old, ynew, Kst, ns, Q, ytmp, side, m, H, K, C_, mp, fp, kind, par, smp
):
    """Coefficients Q of the interpolant over the last step; returns RHS calls made."""
    ny = y_old.size
    if method != _DOP:
        P = _P3 if method == 0 else _P5
        for j in range(ny):
            for p in range(P.shape[1]):
                acc = 0.0
                for k in range(ns + 1):
                    acc += Kst[k, j] * P[k, p]
                Q[p, j] = acc
        return 0
    for s in range(ns + 1, _NEXT8):  # DOP853's extra stages
        for j in range(ny):
            acc = 0.0
            for k in range(s):
                acc += Kst[k, j] * _A8[s, k]
            ytmp[j] = y_old[j] + acc * h
        rhs_call(t_old + _C8[s] * h, ytmp, Kst[s], side, m, H, K, C_, mp, fp, kind, par, smp)
    for j in range(ny):
        dy = ynew[j] - y_old[j]
        Q[0, j] = dy
        Q[1, j] = h * Kst[0, j] - dy
        Q[2, j] = 2.0 * dy - h * (Kst[ns, j] + Kst[0, j])
        for i in range(4):
            acc = 0.0
            for k in range(_NEXT8):
                acc += _D8[i, k] * Kst[k, j]
            Q[3 + i, j] = h * acc
    return _NEXT8 - ns - 1


@njit(cache=True, error_model="numpy")
def _dense_eval(method, t, t_old, h, y_old, Q, out):
    """The interpolant at t (SciPy's RkDenseOutput / Dop853DenseOutput)."""
    x = (t - t_old) / h
    ny = y_old.size
    if method != _DOP:
        q = 3 if method == 0 else 4
        for j in range(ny):
            acc = 0.0
            p = 1.0
            for i in range(q):
                p *= x
                acc += Q[i, j] * p
            out[j] = y_old[j] + h * acc
        return
    for j in range(ny):
        v = 0.0
        for i in range(7):
            v += Q[6 - i, j]
            v *= x if i % 2 == 0 else 1.0 - x
        out[j] = v + y_old[j]


@njit(cache=True, error_model="numpy")
def crosses(g_old, g_new, d):
    """Whether an event function crosses zero from g_old to g_new in direction d (> 0:
    upwards, < 0: downwards, 0: either): the test of every compiled step, as solve_ivp's
    event handling makes it (`scipy.integrate._ivp.ivp.find_active_events`)."""
    up = g_old <= 0.0 and g_new >= 0.0
    down = g_old >= 0.0 and g_new <= 0.0
    return (up and d > 0.0) or (down and d < 0.0) or ((up or down) and d == 0.0)


@njit(cache=True, error_model="numpy")
def zeroin_next(a, fa, b, fb, c, fc, d, e):
    """One iteration of Brent's zeroin (tolerance 4 ε in t), without the evaluation.

    The caller holds the state (a, fa, b, fb, c, fc, d, e), starting from
    ``c, fc, d, e = b, fb, b - a, b - a`` with f(a), f(b) of opposite signs, and
    evaluates f at the point proposed. Returns (done, a, fa, b, c, fc, d, e): when
    `done`, `b` is the root; otherwise f is wanted at the new `b` (and `a`, `fa`
    are the previous `b`, `fb`). Brent's method, as SciPy's brentq.
    """
    if (fb > 0.0) == (fc > 0.0):  # keep the root between b and c
        c, fc = a, fa
        d = b - a
        e = d
    if abs(fc) < abs(fb):  # b is the best estimate
        a, fa = b, fb
        b, fb = c, fc
        c, fc = a, fa
    tol1 = 0.5 * (4.0 * _EPS + 4.0 * _EPS * abs(b))
    xm = 0.5 * (c - b)
    if abs(xm) < tol1 or fb == 0.0:
        return True, a, fa, b, c, fc, d, e
    if abs(e) >= tol1 and abs(fa) > abs(fb):
        s = fb / fa
        if a == c:  # secant
            p = 2.0 * xm * s
            q = 1.0 - s
        else:  # inverse quadratic interpolation
            q = fa / fc
            r = fb / fc
            p = s * (2.0 * xm * q * (q - r) - (b - a) * (r - 1.0))
            q = (q - 1.0) * (r - 1.0) * (s - 1.0)
        if p > 0.0:
            q = -q
        p = abs(p)
        if 2.0 * p < min(3.0 * xm * q - abs(tol1 * q), abs(e * q)):
            e = d
            d = p / q
        else:  # bisection
            d = xm
            e = d
    else:
        d = xm
        e = d
    a, fa = b, fb
    b += d if abs(d) > tol1 else math.copysign(tol1, xm)
    return False, a, fa, b, c, fc, d, e


@njit(cache=True, error_model="numpy")
def _brent(
    code,
    a,
    b,
    t_on,
    quiet,
    method,
    t_old,
    h,
    y_old,
    Q,
    ytmp,
    side,
    m,
    H,
    K,
    C_,
    mp,
    ep,
    kind,
    par,
    smp,
):
    """Root of event `code` on the dense output in [a, b] (`zeroin_next`).

    The end values bracket a root by construction (signs at the step ends);
    if round-off in the interpolant at `b` spoils the bracket, `b` is the root.
    """
    _dense_eval(method, a, t_old, h, y_old, Q, ytmp)
    fa = event_value(code, a, ytmp, t_on, quiet, side, m, H, K, C_, mp, ep, kind, par, smp)
    _dense_eval(method, b, t_old, h, y_old, Q, ytmp)
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
        _dense_eval(method, b, t_old, h, y_old, Q, ytmp)
        fb = event_value(code, b, ytmp, t_on, quiet, side, m, H, K, C_, mp, ep, kind, par, smp)
    return b


@njit(cache=True, error_model="numpy")
def _first_step(
    t0,
    y0,
    f0,
    t_bound,
    max_step,
    order,
    rtol,
    atol,
    ytmp,
    f1,
    side,
    m,
    H,
    K,
    C_,
    mp,
    fp,
    kind,
    par,
    smp,
):
    """Initial step (Hairer, Nørsett & Wanner I, Sec. II.4)."""
    ny = y0.size
    span = abs(t_bound - t0)
    d0 = 0.0
    d1 = 0.0
    for j in range(ny):
        sc = atol + abs(y0[j]) * rtol
        d0 += (y0[j] / sc) ** 2
        d1 += (f0[j] / sc) ** 2
    d0 = math.sqrt(d0) / math.sqrt(ny)
    d1 = math.sqrt(d1) / math.sqrt(ny)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, span)
    for j in range(ny):
        ytmp[j] = y0[j] + h0 * f0[j]
    rhs_call(t0 + h0, ytmp, f1, side, m, H, K, C_, mp, fp, kind, par, smp)
    d2 = 0.0
    for j in range(ny):
        sc = atol + abs(y0[j]) * rtol
        d2 += ((f1[j] - f0[j]) / sc) ** 2
    d2 = math.sqrt(d2) / math.sqrt(ny) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / (order + 1))
    return min(100.0 * h0, h1, span, max_step)
