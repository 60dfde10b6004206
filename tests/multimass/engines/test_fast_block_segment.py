"""A rigid block's rocking segment (`_block_segment.rocking_segment`) against `integrate_phase`.

`rocking_segment` is `multimass.engines.fast._kernel.integrate_phase` for the five states of
a rigid block with the events of a rocking phase and one output time, t_stop. The
reference is `integrate_phase` itself on the same segment: the same status, end time,
event, RHS calls, end state (its sample at t_stop, or its state at the terminal event)
and max |θ| of its θ̇ = 0 roots, bit for bit — the same tableau, steps and root finder.
"""

import math

import numpy as np
import pytest
from numba import njit

import multimass
from multimass import SineWave
from multimass.engines._rigid import uplift_threshold
from multimass.engines.fast import _maths as mx
from multimass.engines.fast._block_segment import NY, rocking_segment, unowned, workspace
from multimass.engines.fast._kernel import integrate_phase
from multimass.engines.fast._rk import EVENT, METHOD_CODES, OK
from multimass.engines.fast.excitation import encode
from multimass.engines.fast.path import ROCKING_EVENTS, event_params

ST = multimass.rigid_block("B6M")
DELAY = 1e-4  # a quiet guard after the restart (multimass.engines._run.QUIET_DELAY's role)


def _events(t0):
    _, codes, dirs, term, quiet, guarded = ROCKING_EVENTS
    t_on = np.where(guarded, t0 + DELAY, -math.inf)
    return codes, dirs, term, quiet, t_on


def _both(method, t0, t_stop, y0, side, amp, tol=(1e-8, 1e-10, math.inf)):
    """(integrate_phase's, rocking_segment's) (status, t, event, nfev, peak, end state)."""
    exc = SineWave(amplitude=amp * uplift_threshold(ST), omega=2.0 * ST.p)
    kind, par, smp = encode(exc)
    mp, ep = mx.model_params(ST), event_params(ST, 1e-6, ST.alpha_cg)
    code = METHOD_CODES[method]
    none, fp = np.empty(0), np.zeros(mx.FP_SIZE)
    codes, dirs, term, quiet, t_on = _events(t0)
    status, t, y, ev, nfev, samples, _, _, nt_y = integrate_phase(
        t0, t_stop, np.array(y0), np.array([t_stop]), side, none, none, np.empty((0, 0)),
        np.empty((0, 0)), mp, fp, codes, dirs, term, quiet, t_on, ep, kind, par, smp, code,
        *tol, np.zeros(1),
    )  # fmt: skip
    peak = max((abs(v) for v in nt_y[:, 0]), default=0.0)
    ref = (status, t, ev, nfev, peak, samples[-1] if status == OK else y)
    y_new = np.array(y0)
    got = rocking_segment(
        t0, t_stop, y_new, side, code, tol, (codes, dirs, term, quiet, t_on), ep,
        (kind, par, smp), mp, workspace(codes.size),
    )  # fmt: skip
    return ref, (*got, y_new)


def _same(ref, got):
    for a, b in zip(ref[:5], got[:5]):
        assert a == b
    np.testing.assert_array_equal(got[5], ref[5])


@pytest.mark.parametrize("method", ["RK23", "RK45", "DOP853"])
def test_free_rocking_to_the_impact(method):
    # released at 0.5 α on pivot +1 after the pulse: it rocks back to θ = 0 (event "zero")
    ref, got = _both(method, 0.5, 3.0, [0.5 * ST.alpha_cg, 0.0, 0.0, 0.0, 0.0], 1, 2.0)
    assert ref[0] == EVENT and ref[2] == 0
    _same(ref, got)


@pytest.mark.parametrize("method", ["RK23", "RK45", "DOP853"])
def test_a_pulse_that_overturns_it(method):
    # rocking on pivot −1 early in a strong pulse (ü_g > 0 pushes θ < 0): it passes α
    ref, got = _both(method, 0.02, 3.0, [-0.01, -0.5, 0.0, 0.0, 0.0], -1, 6.0)
    assert ref[0] == EVENT and ref[2] == 1
    _same(ref, got)


@pytest.mark.parametrize("method", ["RK45", "DOP853"])
def test_stops_at_t_stop_past_a_peak(method):
    # thrown away from θ = 0 on pivot −1: it peaks (θ̇ = 0) before t_stop, no terminal event
    ref, got = _both(method, 1.0, 1.1, [-0.2 * ST.alpha_cg, -0.3, 0.0, 0.0, 0.0], -1, 1.0)
    assert ref[0] == OK and ref[4] > 0.2 * ST.alpha_cg
    _same(ref, got)


def test_buffers_reused_across_segments():
    # one workspace for two different segments: the second as with fresh buffers
    ws = workspace(3)
    kind, par, smp = encode(SineWave(amplitude=3.0 * uplift_threshold(ST), omega=2.0 * ST.p))
    mp, ep = mx.model_params(ST), event_params(ST, 1e-6, ST.alpha_cg)
    args = lambda t0: (  # noqa: E731
        METHOD_CODES["DOP853"], (1e-8, 1e-10, math.inf), _events(t0), ep, (kind, par, smp),
        mp,
    )  # fmt: skip
    y1 = np.array([0.0] * NY)
    rocking_segment(0.0, 3.0, y1, 1, *args(0.0), ws)
    y2 = np.array([0.3 * ST.alpha_cg, 0.0, 0.0, 0.0, 0.0])
    y3 = y2.copy()
    a = rocking_segment(0.5, 3.0, y2, 1, *args(0.5), ws)
    b = rocking_segment(0.5, 3.0, y3, 1, *args(0.5), workspace(3))
    assert a == b
    np.testing.assert_array_equal(y2, y3)


@njit
def _through(a, b):
    v, w = unowned(a), unowned(b)
    v[1, 2] = 7.0
    w[0] += 1.0
    return v.shape, v.strides, w.shape, w.strides, v[0, 1], w.sum()


def test_unowned_is_the_same_array():
    # `unowned` drops the view's owner, not its data: the same shape and strides (a
    # strided view's too), reads of the caller's values, writes that reach its array
    a, b = np.arange(12.0).reshape(3, 4), np.arange(5.0)[::2]
    got = _through(a, b)
    assert got[:4] == (a.shape, a.strides, b.shape, b.strides)
    assert got[4] == 1.0 and got[5] == 1.0 + 2.0 + 4.0  # b = [0, 2, 4], then b[0] += 1
    assert a[1, 2] == 7.0 and b[0] == 1.0
