"""Full contact in closed form (`multimass.engines.fast._contact_kernel`, `.contact_modes`).

References, none computed with the code under test:

* the state: the matrix exponential of the whole first-order system (scipy.linalg.expm,
  Padé with scaling and squaring) augmented with the linear ground acceleration of each
  record interval — no modes;
* the ledger: Van Loan's block exponential (C. F. Van Loan 1978, IEEE TAC 23(3), Thm 1),
  which integrates a quadratic form of the same augmented state exactly;
* the energy balance E(t) + D − W_g = E(0) (an invariant; the kernel forms D and W_g
  from two different identities, so it does not hold by construction);
* events and whole runs: the Runge–Kutta kernel and the solve_ivp path at tight
  tolerances.
"""

import dataclasses
import math
import types

import numpy as np
import pytest
import scipy.linalg

import multimass
from multimass import CosinePulse, FreeRelease, InputError, Record, simulate
from multimass.engines.fast import _maths as mx
from multimass.engines.fast._contact_kernel import contact_phase
from multimass.engines.fast._kernel import integrate_phase
from multimass.engines.fast.contact_modes import ContactModes
from multimass.engines.fast.path import FastPath, event_params
from multimass.impact_models import impact_model
from tests.multimass.engines.test_fast import _arrays  # (m, H, K, C, mp) of a structure

PEAK_TOL = 1e-6  # rad


def _record(seed=3, n=60, dt=0.02, peak=3.0):
    rng = np.random.default_rng(seed)
    return Record.from_arrays(np.arange(n) * dt, peak * rng.uniform(-1, 1, n), units="m/s2")


def _no_events():
    return (np.zeros(0, np.int64), np.zeros(0), np.zeros(0), np.zeros(0))


def _uplift_events(t_on):
    return (
        np.array([mx.EV_UPLIFT_RIGHT, mx.EV_UPLIFT_LEFT], np.int64),
        np.array([1.0, 1.0]),
        np.array([-1.0, -1.0]),
        np.array([t_on, t_on]),
    )


def _run_exact(st, rec, t0, t_stop, y0, t_eval, events, ep=None):
    m, H, K, C, mp = _arrays(st)
    kind, par, smp = multimass.engines.fast.encode(rec)
    cm = ContactModes.of(st)
    ep = np.zeros(mx.EP_SIZE) if ep is None else ep
    return contact_phase(
        t0, t_stop, y0, t_eval, m, H, K, C, mp, *events, ep, kind, par, smp,
        cm.phi, cm.w, cm.z, cm.gam, cm.h_max, cm.screen,
    )  # fmt: skip


def _reference(st, rec, t0, y0, times):
    """(u, u̇, D, W_g) at `times` by expm of the augmented system, interval by interval."""
    n = st.n
    m, _, K, C, _ = _arrays(st)
    Minv = np.diag(1.0 / m)
    d = 2 * n + 2  # x = [u, u̇], a, s: ẋ = A x − 1 a, ȧ = s, ṡ = 0
    A = np.zeros((d, d))
    A[:n, n : 2 * n] = np.eye(n)
    A[n : 2 * n, :n] = -Minv @ K
    A[n : 2 * n, n : 2 * n] = -Minv @ C
    A[n : 2 * n, 2 * n] = -1.0
    A[2 * n, 2 * n + 1] = 1.0
    QD = np.zeros((d, d))  # u̇ᵀ C u̇
    QD[n : 2 * n, n : 2 * n] = C
    QW = np.zeros((d, d))  # −a 1ᵀ M u̇, symmetrised
    QW[2 * n, n : 2 * n] = QW[n : 2 * n, 2 * n] = -0.5 * m
    t_rec, a_rec = rec.time, rec.accel

    def flow(x, a0, s, h):
        # pieces of ≤ 0.2 ms: e^{−Aᵀτ} in Van Loan's block grows like e^{ζωτ} (S1: 626 s⁻¹)
        k = max(1, math.ceil(h / 2e-4))
        z, D, W = np.concatenate([x, [a0, s]]), 0.0, 0.0
        E = scipy.linalg.expm(A * h / k)
        G = []
        for Q in (QD, QW):  # Van Loan: ∫ e^{Aᵀτ} Q e^{Aτ} dτ = F22ᵀ F12
            F = scipy.linalg.expm(np.block([[-A.T, Q], [np.zeros((d, d)), A]]) * h / k)
            G.append(F[d:, d:].T @ F[:d, d:])
        for _ in range(k):
            D, W, z = D + z @ G[0] @ z, W + z @ G[1] @ z, E @ z
        return z[: 2 * n], D, W

    x, D, W, t = np.concatenate([y0[:n], y0[n + 1 : 2 * n + 1]]), 0.0, 0.0, t0
    knots = sorted(set(t_rec[(t_rec > t0)]) | set(times))
    rows = {}
    for tk in knots:
        a0 = s = 0.0  # ü_g ≡ 0 after the last sample
        if t < t_rec[-1]:
            j = np.searchsorted(t_rec, t, side="right") - 1
            s = (a_rec[j + 1] - a_rec[j]) / (t_rec[j + 1] - t_rec[j])
            a0 = a_rec[j] + s * (t - t_rec[j])
        x, dD, dW = flow(x, a0, s, tk - t)
        D, W, t = D + dD, W + dW, tk
        if tk in times:
            rows[tk] = (x[:n].copy(), x[n:].copy(), D, W)
    return [rows[tk] for tk in times]


def _energy(st, u, ud):
    m, _, K, _, _ = _arrays(st)
    return 0.5 * ud @ (m * ud) + 0.5 * u @ K @ u


@pytest.mark.parametrize("name", ["S1", "S2", "S3"])
def test_modes_of_the_bundled_columns(name):
    st = multimass.column(name)
    cm = ContactModes.of(st)
    m, _, K, C, _ = _arrays(st)
    np.testing.assert_allclose(cm.phi.T @ np.diag(m) @ cm.phi, np.eye(st.n), atol=1e-12)
    w_ref = np.sort(np.sqrt(np.linalg.eigvals(np.linalg.solve(np.diag(m), K)).real))
    np.testing.assert_allclose(cm.w, w_ref, rtol=1e-10)
    np.testing.assert_allclose(cm.phi.T @ C @ cm.phi, np.diag(2 * cm.z * cm.w), atol=1e-9)
    assert np.all((cm.z > 0) & (cm.z < 1))
    np.testing.assert_allclose(cm.gam, cm.phi.T @ m, rtol=1e-14)
    assert cm.h_max == pytest.approx(2 * math.pi / cm.w.max() / 16)


def test_why_a_structure_has_no_exact_contact():
    st = multimass.column("S1")
    m, H, K, C, _ = _arrays(st)
    like = lambda **kw: types.SimpleNamespace(**(dict(n=st.n, m=m, H=H, K=K, C=C) | kw))
    assert "rigid body" in ContactModes.of(multimass.rigid_block("B6M"))
    coupled = C.copy()
    coupled[0, -1] = coupled[-1, 0] = coupled[0, -1] + 0.05 * abs(C).max()
    assert "not classical" in ContactModes.of(like(C=coupled))
    assert "negative damping" in ContactModes.of(like(C=-C))
    assert "positive definite" in ContactModes.of(like(K=-K))
    skew = K.copy()
    skew[0, 1] *= 1.01
    assert "not symmetric" in ContactModes.of(like(K=skew))


@pytest.mark.parametrize("damping", [1.0, 10.0])
def test_free_vibration_and_record_against_the_matrix_exponential(damping):
    # damping 10: S1's C × 10, its modes 3-5 overdamped (ζ 1.0, 1.4, 1.9), as the top
    # modes of many-node columns under Rayleigh damping
    st = dataclasses.replace(multimass.column("S1"), C=damping * multimass.column("S1").C)
    if damping > 1:
        assert np.sum(ContactModes.of(st).z > 1) == 3
    n = st.n
    rec = _record()
    rng = np.random.default_rng(7)
    y0 = np.zeros(2 * n + 5)
    y0[:n] = 2e-5 * rng.normal(size=n)
    y0[n + 1 : 2 * n + 1] = 5e-3 * rng.normal(size=n)
    y0[2 * n + 2 :] = (0.25, -0.5, 0.125)  # the ledger carries on from the phase's start
    t0, t_stop = 0.0137, 1.5031  # off the record's grid; past its end (1.18 s) into free vibration
    times = [0.02, 0.0471, 0.5, 1.18, 1.2, t_stop]
    out = _run_exact(st, rec, t0, t_stop, y0, np.array(times), _no_events())
    assert out[0] == 0 and out[1] == t_stop and out[5].shape == (len(times), 2 * n + 5)
    for row, (u, ud, D, W), tk in zip(out[5], _reference(st, rec, t0, y0, times), times):
        scale_u, scale_v = np.abs(u).max(), np.abs(ud).max()
        np.testing.assert_allclose(row[:n], u, atol=1e-10 * scale_u, err_msg=f"u at {tk}")
        np.testing.assert_allclose(row[n + 1 : 2 * n + 1], ud, atol=1e-10 * scale_v)
        assert row[n] == row[2 * n + 1] == 0.0  # θ, θ̇
        assert row[2 * n + 2] - 0.25 == pytest.approx(D, rel=1e-9)
        assert row[2 * n + 3] + 0.5 == pytest.approx(W, rel=1e-9, abs=1e-12)
        assert row[2 * n + 4] == 0.125
        # the ledger closes: E(t) + D − W_g = E(t0)
        E0 = _energy(st, y0[:n], y0[n + 1 : 2 * n + 1])
        Et = _energy(st, row[:n], row[n + 1 : 2 * n + 1])
        balance = Et + (row[2 * n + 2] - 0.25) - (row[2 * n + 3] + 0.5) - E0
        assert abs(balance) <= 1e-12 * max(E0, Et, abs(W))
    np.testing.assert_array_equal(out[2], out[5][-1])


def test_uplift_found_as_the_runge_kutta_kernel_finds_it():
    st = multimass.column("S1")
    n = st.n
    rec = multimass.read_record(
        "examples/data/elcentro_1940_NS_15s.dat", units="g", scale=1.2
    )  # uplifts at ~1.6 s
    m, H, K, C, mp = _arrays(st)
    kind, par, smp = multimass.engines.fast.encode(rec)
    ep = event_params(st, 0.01, math.pi / 2)
    y0 = np.zeros(2 * n + 5)
    t_eval = np.array([1.0, 5.0])
    ev = _uplift_events(1e-9)
    exact = _run_exact(st, rec, 0.0, 5.0, y0, t_eval, ev, ep)
    rk = integrate_phase(
        0.0, 5.0, y0, t_eval, 0, m, H, K, C, mp, np.zeros(mx.FP_SIZE), ev[0], ev[1],
        np.ones(2, np.int64), ev[2], ev[3], ep, kind, par, smp, 2, 1e-12, 1e-16, 5e-3, np.zeros(1),
    )  # fmt: skip
    assert exact[0] == rk[0] == 1 and exact[3] == rk[3]  # the same terminal event
    assert 0.5 < exact[1] < 5.0 and abs(exact[1] - rk[1]) <= 1e-9
    np.testing.assert_allclose(exact[2][: 2 * n + 2], rk[2][: 2 * n + 2], rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(exact[2][2 * n + 2 :], rk[2][2 * n + 2 :], rtol=1e-7, atol=1e-14)
    np.testing.assert_allclose(exact[5], rk[5], rtol=1e-7, atol=1e-13)  # the sample at 1 s
    # held quiet past the uplift, the event waits for its guard to end
    late = _run_exact(st, rec, 0.0, 5.0, y0, t_eval, _uplift_events(exact[1] + 0.05), ep)
    assert late[0] == 0 or late[1] > exact[1] + 0.05


def _same_run(a, b, event_dt, peak_tol=PEAK_TOL):
    assert a.status == b.status
    assert [(e.kind, e.phase_before, e.phase_after) for e in a.events] == [
        (e.kind, e.phase_before, e.phase_after) for e in b.events
    ]
    dt = max(abs(x.time - y.time) for x, y in zip(a.events, b.events))
    assert dt <= event_dt, f"event times differ by {dt:.3g} s"
    assert np.max(np.abs(np.asarray(a.peaks) - np.asarray(b.peaks))) <= peak_tol


@pytest.mark.parametrize("impact", ["DD2", "CIM"])
def test_record_runs_agree_with_integrated_contact(impact):
    rec = multimass.read_record("examples/data/elcentro_1940_NS_15s.dat", units="g", scale=1.1)
    tight = dict(rtol=1e-12, atol=1e-14, output_dt=None, backend="compiled")
    exact = simulate("S1", rec, impact, 4.0, **tight)
    rk = simulate("S1", rec, impact, 4.0, full_contact="integrate", **tight)
    assert exact.n_impacts >= 5
    # both at tight tolerances: what is left is the rocking phases' own error (measured
    # 1.1e-8 s and 3e-10 rad against solve_ivp at rtol 1e-12 over 8 s; rk 5e-9 s)
    _same_run(exact, rk, event_dt=5e-8, peak_tol=1e-9)
    assert exact.n_rhs < 0.5 * rk.n_rhs  # full contact took no right-hand side
    assert exact.energy_balance_error <= 1e-10
    # at the default tolerances, within what rtol = 1e-8 buys on a record (both paths are
    # ~8e-6 s from the tight run at the late, slow impacts of an 8 s run)
    ref = simulate("S1", rec, impact, 4.0, output_dt=None)
    default = simulate("S1", rec, impact, 4.0, output_dt=None, backend="compiled")
    _same_run(ref, default, event_dt=2e-5)
    assert default.energy_balance_error <= 1e-8


def test_series_on_the_output_grid():
    rec = multimass.read_record("examples/data/elcentro_1940_NS_15s.dat", units="g", scale=1.1)
    kw = dict(output_dt=2e-3, backend="compiled", rtol=1e-11, atol=1e-13)
    a = simulate("S1", rec, "DD2", 3.0, **kw)
    b = simulate("S1", rec, "DD2", 3.0, full_contact="integrate", **kw)
    assert a.series.shape == b.series.shape
    grid = (a.series.t == b.series.t).to_numpy()  # not the transitions' rows (times ~1e-9 s apart)
    assert grid.sum() >= 1500
    # velocities and accelerations 1e-5: just after a transition S1's 527 Hz mode rings, and
    # transition times 1e-9 s apart shift u̇ by ~ω u̇ 1e-9 (measured 1.1e-6 of the peak)
    tols = dict(theta=1e-6, u5=1e-6, udot1=1e-5, a5=1e-5, ag=1e-12, damping=1e-6, ground_work=1e-6)
    for col, tol in tols.items():
        np.testing.assert_allclose(
            a.series[col][grid], b.series[col][grid], atol=tol * a.series[col].abs().max()
        )
    assert a.energy_balance_error <= 1e-8


def test_free_release_settles_into_exact_contact():
    a = simulate("S2", FreeRelease(0.02), "DD2", 3.0, output_dt=None)
    b = simulate("S2", FreeRelease(0.02), "DD2", 3.0, output_dt=None, backend="compiled")
    assert any(e.kind == "full_contact" for e in b.events)
    _same_run(a, b, event_dt=1e-7)  # test_fast's tolerance for columns


def test_full_contact_option():
    rec = _record()
    with pytest.raises(InputError, match="full_contact.*'auto', 'exact', 'integrate'"):
        simulate("S1", rec, "DD2", 1.0, backend="compiled", full_contact="closed")
    with pytest.raises(InputError, match="needs backend='compiled'"):
        simulate("S1", rec, "DD2", 1.0, full_contact="exact")
    with pytest.raises(InputError, match="not a record or a free release"):
        simulate(
            "S1",
            CosinePulse(omega=15.0, amplitude=5.0),
            "DD2",
            1.0,
            backend="compiled",
            full_contact="exact",
        )
    # "auto": exact for records and free releases of columns, integrated otherwise
    st = multimass.column("S1")
    dd2 = impact_model("DD2", st.specimen)
    of = lambda exc, how="auto": FastPath.of(st, dd2, exc, "DOP853", 1e-9, how).contact
    assert isinstance(of(rec), ContactModes) and isinstance(of(FreeRelease(0.01)), ContactModes)
    assert of(CosinePulse(omega=15.0, amplitude=5.0)) is None and of(rec, "integrate") is None
    blk = multimass.rigid_block("B6M")
    assert FastPath.of(blk, impact_model("CIM", blk.specimen), rec, "DOP853", 1e-9).contact is None


def test_a_short_uplift_that_steps_across_the_record_samples_miss():
    # S1, El Centro × 0.5, DD2: after the impact at 2.549 s the column uplifts again at
    # 2.5731 s for a short half-cycle. DOP853 at the default rtol = 1e-8, stepping across
    # the record's samples, stepped over it in full contact (θ_max 0.000899 rad instead of
    # 0.000797 over 20 s: 13 % off); an rtol = 1e-12 run finds it, and so do the closed
    # form and DOP853 with steps that end at each sample (`_kernel._accepted_step`), at
    # the default tolerances.
    rec = multimass.read_record("examples/data/elcentro_1940_NS_15s.dat", units="g", scale=0.5)
    run = lambda **kw: simulate("S1", rec, "DD2", 3.0, output_dt=None, backend="compiled", **kw)
    tight = run(full_contact="integrate", rtol=1e-12, atol=1e-14)
    uplifts = [e.time for e in tight.events if e.kind == "uplift"]
    assert abs(uplifts[2] - 2.5731) < 1e-4
    _same_run(run(), tight, event_dt=1e-6)
    _same_run(run(full_contact="integrate"), tight, event_dt=1e-6)


def test_an_uplift_soon_after_entering_full_contact():
    # A one-node column released from 0.11 rad (DD2, 10 s): from 9.59 s on it enters full
    # contact and uplifts again ~70 µs later, 26 times. Checked only every quarter period
    # (1.06 ms) from the start of each contact phase the closed form missed all of them
    # (134 events instead of 187); its first checks are now as close as the Runge–Kutta
    # kernel's first steps.
    from multimass.bench.scaling import uniform_column

    st = uniform_column(1)
    kw = dict(output_dt=None, backend="compiled")
    tight = simulate(
        st, FreeRelease(0.11), "DD2", 10.0, full_contact="integrate", rtol=1e-12, atol=1e-14, **kw
    )
    exact = simulate(st, FreeRelease(0.11), "DD2", 10.0, **kw)
    assert len(tight.events) == 187 and tight.n_full_contact == 29
    _same_run(exact, tight, event_dt=1e-6)


def test_a_short_positive_window_of_the_uplift_margin():
    # A three-node column released from 0.11 rad (DD2): in full contact from 5.6522 s its
    # uplift margin, which holds the top mode's velocity, turns positive at 5.6564 s for
    # less than a quarter of that mode's period. Checked 4 times per period the closed
    # form missed it (99 events instead of 101); 16 times, as now, it agrees with DOP853
    # at rtol 1e-12.
    from multimass.bench.scaling import uniform_column

    st = uniform_column(3)
    kw = dict(output_dt=None, backend="compiled", rtol=1e-12, atol=1e-14)
    tight = simulate(st, FreeRelease(0.11), "DD2", 6.0, full_contact="integrate", **kw)
    exact = simulate(st, FreeRelease(0.11), "DD2", 6.0, **kw)
    assert any(e.kind == "uplift" and abs(e.time - 5.65643) < 1e-4 for e in tight.events)
    _same_run(exact, tight, event_dt=1e-7, peak_tol=1e-9)
