"""The exponential integrator of the rocking phases (`multimass.engines.fast._exp_kernel`).

References, each independent of the code under test:

* φ-functions: the first row of the exponential of an augmented matrix (the identity
  used by Expokit, R. B. Sidje, ACM TOMS 24 (1998) 130–156), by `scipy.linalg.expm`;
* the linear part: the uplifted modal analysis' state matrix (paper 001, Eqs 19–21,
  `multimass.modal.linearisation.rocking`);
* the linear system under a piecewise-linear ground motion (full contact, paper 001
  Eq 3, which is linear): the exact flow of the augmented system [x; 1; τ] over each
  record interval, by `scipy.linalg.expm` (Van Loan's construction);
* the nonlinear rocking runs: the compiled DOP853 at rtol 1e-12 (its own accuracy is
  checked against solve_ivp in tests/multimass/test_fast.py);
* the energy ledger's closure, an invariant.
* the transforms and L x on their real layouts: the plain complex products in Python,
  summed in the same order (to the bit); a kept φ-table: `_coefficients` of its size.
"""

from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

import multimass
from multimass import FreeRelease, InputError, simulate, simulate_outcome, simulation
from multimass.engines.fast import _maths as mx
from multimass.engines.fast._exp_kernel import exp_phase, new_cache, phi_functions
from multimass.engines.fast._kernel import integrate_phase
from multimass.engines.fast.path import ROCKING_EVENTS, FastPath, event_params
from multimass.engines.fast.rocking_modes import RockingModes
from multimass.impact_models import impact_model
from multimass.model._phase import Model, full_contact_rhs, rocking_rhs
from multimass.simulation import outcome_summary
from tests.multimass.engines.test_fast import _arrays  # (m, H, K, C, mp) of a structure

#: El Centro 1940 NS in g, the copy the examples carry (the same file as the shared record).
ELCENTRO = Path(__file__).parents[3] / "examples" / "data" / "records" / "elcentro_1940_NS.dat"
#: The README's record: the first 15 s of El Centro 1940 NS, in g.
RECORD_15S = Path(__file__).parents[3] / "examples" / "data" / "elcentro_1940_NS_15s.dat"


def _phi_reference(z, order=5):
    """φ_0 … φ_order of z from expm of [[z, e_1ᵀ], [0, J]] (J the shift matrix)."""
    A = np.zeros((order + 1, order + 1), complex)
    A[0, 0] = z
    for i in range(order):
        A[i, i + 1] = 1.0
    return scipy.linalg.expm(A)[0]


@pytest.mark.parametrize(
    "z", [0.0, 1e-8, 0.3 - 0.2j, -0.9 + 0.4j, 1.0 + 0.0j, -3.0 + 20.0j, -60.0 + 300.0j, 2.5]
)
def test_phi_functions_against_the_augmented_exponential(z):
    got = np.array(phi_functions(complex(z)))
    ref = _phi_reference(z)
    # the recurrence just above |z| = 1 costs φ_5 a few hundred ulps
    assert np.allclose(got, ref, rtol=1e-12, atol=0.0), (got, ref)


@pytest.mark.parametrize("name", ["S1", "S2", "S3"])
def test_linear_part_is_the_uplifted_modal_state_matrix(name):
    from multimass.modal.linearisation import rocking

    st = multimass.column(name)
    rm = RockingModes.of(st)
    n = st.n
    for side in (1, -1):
        lin = rocking(st, side)  # paper 001, Eqs 19–20: M_L z̈ + C_L ż + K_L z = ...
        Mi = np.linalg.inv(lin.M)
        A = np.block([[np.zeros((n + 1, n + 1)), np.eye(n + 1)], [-Mi @ lin.K, -Mi @ lin.C]])
        # Eqs 19–21 hold the mass matrix at rest; the Jacobian adds its change with u times
        # the restoring moment (g m_t B / J_p ~ 10 rad/s² against entries ~1e7)
        assert np.abs(rm.L - A).max() < 1e-4 * np.abs(A).max()
        # the same for both pivots: the Jacobian of the left pivot's right-hand side
        f = rocking_rhs(Model.of(st), side, lambda t: 0.0, None)
        J = np.empty_like(rm.L)
        for j in range(2 * n + 2):
            y = np.zeros(2 * n + 5)
            y[j] = 1e-5
            fp = f(0.0, y)
            y[j] = -1e-5
            J[:, j] = (fp - f(0.0, y))[: 2 * n + 2] / 2e-5
        assert np.abs(rm.L - J).max() < 1e-9 * np.abs(A).max()
    # the modes rebuild L: Σ wt Re(V diag(λ) W)
    back = np.real((rm.V * rm.wt) @ np.diag(rm.lam) @ rm.W)
    assert np.abs(back - rm.L).max() < 1e-9 * np.abs(rm.L).max()
    # the rocking pair ±p (paper 001: p ≈ 2.5 rad/s for S1) is real, one of each sign
    real = rm.lam[rm.lam.imag == 0.0].real
    assert sorted(np.sign(real)) == [-1.0, 1.0]


def test_a_rigid_block_is_refused():
    st = multimass.rigid_block("B6M")
    model = impact_model("CIM", st.specimen, None, None, None, None)
    with pytest.raises(InputError, match="rigid block has no elastic modes"):
        FastPath.of(st, model, FreeRelease(0.1), "exponential", 1e-9)


def test_the_option_needs_the_compiled_backend():
    with pytest.raises(InputError, match="needs backend='compiled'"):
        simulate("S1", FreeRelease(0.05), "DD2", 0.1, method="exponential")


def _full_contact_modes(st):
    """L of full contact (Eq 3: linear, exact central differences) and its modes."""
    n = st.n
    f = full_contact_rhs(Model.of(st), lambda t: 0.0)
    L = np.empty((2 * n + 2, 2 * n + 2))
    for j in range(2 * n + 2):
        y = np.zeros(2 * n + 5)
        y[j] = 1.0
        fp = f(0.0, y)
        y[j] = -1.0
        L[:, j] = (fp - f(0.0, y))[: 2 * n + 2] / 2.0
    lam, V = np.linalg.eig(L)
    W = np.linalg.inv(V)
    keep = lam.imag >= 0.0
    wt = np.where(lam.imag[keep] > 0.0, 2.0, 1.0)
    arrays = (L, lam[keep].copy(), V[:, keep].copy(), W[keep, :].copy(), wt)
    return tuple(np.ascontiguousarray(a) for a in arrays)


def test_the_linear_system_under_a_linear_ground_motion_is_exact():
    """Full contact (Eq 3) is linear: x' = L x − e ü_g with ü_g linear between samples.
    The scheme integrates it to round-off in one step per sample, whatever the tolerance."""
    st = multimass.column("S1")
    n = st.n
    rng = np.random.default_rng(7)
    dt = 0.02
    acc = rng.normal(scale=2.0, size=40)
    rec = multimass.Record.from_arrays(np.arange(40) * dt, acc, units="m/s2")
    kind, par, smp = multimass.engines.fast.encode(rec)
    m, H, K, C, mp = _arrays(st)
    modes = _full_contact_modes(st)
    y0 = np.zeros(2 * n + 5)
    y0[:n] = 1e-4 * rng.normal(size=n)
    t_eval = np.array([0.013, 0.2, 0.41, 0.7])
    no = np.zeros(0)
    got = exp_phase(
        0.0, 0.7, y0, t_eval, 0, m, H, K, C, mp, np.zeros(mx.FP_SIZE),
        np.zeros(0, np.int64), no, np.zeros(0, np.int64), no, no, np.zeros(mx.EP_SIZE),
        kind, par, smp, *modes, new_cache(modes[1].size), 1e-3, 1e-6, np.inf,
    )  # fmt: skip
    status, t, y, _, nfev, samples = got[:6]
    assert status == 0 and t == 0.7
    assert nfev <= 1 + 9 * 60  # a step per sample interval (35), the first steps growing
    # the exact flow over each interval: ξ = [x, 1, τ], ξ' = [[L, b0, b1], 0, [0, 1, 0]] ξ
    L = modes[0]
    nm = 2 * n + 2
    e = np.zeros(nm)
    e[n + 1 : 2 * n + 1] = 1.0  # ü = ... − ü_g on every node (Eq 3)

    def flow(x, i, t0, t1):  # within the interval [i dt, (i + 1) dt]
        s = (acc[i + 1] - acc[i]) / dt
        a0 = acc[i] + s * (t0 - i * dt)
        M = np.zeros((nm + 2, nm + 2))
        M[:nm, :nm], M[:nm, nm], M[:nm, nm + 1], M[nm + 1, nm] = L, -a0 * e, -s * e, 1.0
        return (scipy.linalg.expm(M * (t1 - t0)) @ np.r_[x, 1.0, 0.0])[:nm]

    def exact(te):
        x, i = y0[:nm].copy(), 0
        while (i + 1) * dt < te:
            x, i = flow(x, i, i * dt, (i + 1) * dt), i + 1
        return flow(x, i, i * dt, te)

    for te, row in zip(t_eval, samples):
        x = exact(te)
        for part in (slice(0, n), slice(n + 1, 2 * n + 1)):  # u, u̇ (θ, θ̇ stay 0)
            assert np.abs(row[part] - x[part]).max() <= 1e-11 * np.abs(x[part]).max()
        assert row[n] == 0.0 and row[2 * n + 1] == 0.0


def _release_segment(st, theta0, t_stop):
    """Arguments of one rocking segment of a release, with only the θ̇ = 0 event."""
    n = st.n
    model = impact_model("CIM", st.specimen, None, None, None, None)
    fe = FastPath.of(st, model, FreeRelease(theta0), "exponential", 1e-9)
    y0 = np.zeros(2 * n + 5)
    y0[n] = theta0
    _, codes, dirs, term, quiet, _ = ROCKING_EVENTS
    sl = slice(2, 3)  # the peak only: no impact before t_stop
    ep = event_params(st, 0.01, np.pi / 2)
    args = (0.0, t_stop, y0, np.array([t_stop]), 1, fe.m, fe.H, fe.K, fe.C, fe.mp,
            np.zeros(mx.FP_SIZE), codes[sl], dirs[sl], term[sl], quiet[sl],
            np.full(1, -np.inf), ep, fe.kind, fe.par, fe.samples)  # fmt: skip
    return args, fe.rocking.arrays


def test_order_of_convergence_on_the_nonlinear_rocking():
    """S1 released from 0.05 rad, 3/16 s of rocking (θ goes to 0.01 rad: sin θ, the θ̇²
    terms and the u-dependent mass matrix all act) at fixed steps 2⁻⁶ … 2⁻¹⁰ s. The
    elastic modes make the error's constant vary from one h to the next (local slopes
    3.8 … 5.7), so the order is the least-squares slope over five step sizes."""
    st = multimass.column("S1")
    args, rock = _release_segment(st, 0.05, 0.1875)
    ref = integrate_phase(*args, 2, 1e-13, 1e-15, np.inf, np.zeros(1))[5][-1]
    n = st.n
    scale = np.abs(ref[: 2 * n + 2])
    scale = np.maximum(scale, scale.max() * 1e-3)  # each coordinate in its own units
    hs = 2.0 ** -np.arange(6, 11)
    errs = []
    for h in hs:  # every step accepted (rtol, atol huge): fixed steps h
        got = exp_phase(*args, *rock, new_cache(rock[1].size), 1e10, 1e10, h)[5][-1]
        errs.append(np.abs((got - ref)[: 2 * n + 2] / scale).max())
    p = np.polyfit(np.log2(hs), np.log2(errs), 1)[0]
    assert p >= 4.0, (errs, p)
    assert errs[-1] < 1e-9


def test_agreement_with_a_tight_reference_on_a_release():
    """S1 released from 0.11 rad, DD2, 5 s: θ_max, impact times and the ledger against
    the compiled DOP853 at rtol 1e-12."""
    kw = dict(backend="compiled", output_dt=None, progress=False, max_step=np.inf)
    ref = simulate(
        "S1", FreeRelease(0.11), "DD2", 5.0, method="DOP853", rtol=1e-12, atol=1e-14, **kw
    )
    got = simulate(
        "S1", FreeRelease(0.11), "DD2", 5.0, method="exponential", rtol=1e-9, atol=1e-11, **kw
    )
    imp = lambda r: np.array([e.time for e in r.events if e.kind == "impact"])
    assert len(imp(got)) == len(imp(ref)) > 5
    assert np.abs(imp(got) - imp(ref)).max() < 1e-7  # s; the late impacts at |θ̇| ~ 0.05 rad/s
    assert np.abs(got.peaks[: len(ref.peaks)] - ref.peaks[: len(got.peaks)]).max() < 1e-9
    assert got.status == "completed" and got.energy_balance_error < 1e-7
    # the ledger's integrals close independently: D and W_F against the reference
    assert got.energy_balance_error < 1e-7


def test_agreement_with_a_tight_reference_under_el_centro():
    rec = multimass.read_record(ELCENTRO, units="g", scale=2.0)
    kw = dict(backend="compiled", output_dt=None, progress=False, max_step=np.inf, seed=1)
    ref = simulate_outcome("S1", rec, "DD2", 6.0, method="DOP853", rtol=1e-12, atol=1e-14, **kw)
    got = simulate_outcome("S1", rec, "DD2", 6.0, method="exponential", rtol=1e-9, atol=1e-11, **kw)
    imp = lambda r: np.array([e.time for e in r.events if e.kind in ("impact", "uplift")])
    assert len(imp(got)) == len(imp(ref)) > 5
    assert np.abs(imp(got) - imp(ref)).max() < 1e-6
    assert abs(got.theta_max - ref.theta_max) < 1e-8
    assert got.energy_balance_error < 1e-6


def test_a_short_activation_inside_one_step_is_found():
    """A uniform 20-node column under El Centro (the README's 15 s, scale 0.9, DD5, the
    draw of repeat 3 in `record_spectrum(..., repeats=5, seed=0)`): at 2.078 s the
    Dirac-delta force activates for 9 ms while a step of the exponential method is up to
    5 ms long; its margin (pivot momentum and θ̇, which swing with the elastic modes) dips
    below zero and back within one step. Reference: compiled DOP853 at rtol 1e-12, whose
    steps are far shorter. Without the test at the steps' Gauss nodes the run went on
    without the force there and its θ_max came 9.5e-4 rad short."""
    from multimass.bench.scaling import uniform_column
    from multimass.sweeps.seeding import job_seeds

    scale = np.linspace(0.4, 2.0, 17)[5]  # 0.9: run 5 × 5 + 3 of the spectrum
    rec = multimass.read_record(RECORD_15S, units="g").scaled(float(scale))
    kw = dict(backend="compiled", output_dt=None, progress=False, seed=int(job_seeds(0, 85)[28]))
    st = uniform_column(20)
    ref = simulate_outcome(st, rec, "DD5", 2.2, method="DOP853", rtol=1e-12, atol=1e-14, **kw)
    got = simulate_outcome(st, rec, "DD5", 2.2, method="exponential", **kw)
    activations = lambda r: [e.time for e in r.events if e.kind == "dd_activate"]
    assert [e.kind for e in got.events] == [e.kind for e in ref.events]
    assert min(abs(t - 2.0779) for t in activations(ref)) < 1e-4  # the 9 ms window
    assert np.abs(np.subtract(activations(got), activations(ref))).max() < 1e-6


def test_whole_run_kernel_runs_the_per_run_path():
    """`column_run` (one compiled call) and the Python phase loop call the same kernels:
    the same run, bit for bit."""
    rec = multimass.read_record(ELCENTRO, units="g", scale=1.5)
    kw = dict(backend="compiled", method="exponential", seed=3, rtol=1e-7, atol=1e-9)
    whole = outcome_summary("S1", rec, "DD5", 5.0, **kw)
    o = simulation.SimulationOptions.of(None, output_dt=None, progress=False, **kw)
    loop = simulation._prepare("S1", rec, "DD5", 5.0, o).run_phase_loop(lean=True)
    assert whole.theta_max == loop.theta_max
    assert whole.n_impacts == loop.n_impacts


def test_the_warm_up_compiles_the_one_specialisation_runs_use():
    from multimass.engines.fast import warm_up_exponential

    warm_up_exponential(progress=False)
    rec = multimass.read_record(ELCENTRO, units="g", scale=2.0)
    kw = dict(backend="compiled", method="exponential", output_dt=None, progress=False)
    simulate("S1", FreeRelease(0.05), "DD2", 0.5, **kw)
    simulate("S2", rec, "CIM", 1.0, **kw)
    outcome_summary("S1", rec, "DD5", 1.0, backend="compiled", method="exponential", seed=1)
    assert len(exp_phase.signatures) == 1


@pytest.mark.parametrize("amp, outcome", [(0.6, "completed"), (1.0, "overturned")])
def test_a_pulse_and_overturning_against_a_tight_reference(amp, outcome):
    """A cosine pulse (not piecewise linear: ü_g stays in N, steps are not cut at samples)
    that S1 survives or overturns under: outcome, overturning time, θ_max and the ledger."""
    exc = multimass.CosinePulse(omega=8.0, amplitude=amp * 9.81)
    kw = dict(backend="compiled", output_dt=None, progress=False, max_step=np.inf)
    ref = simulate("S1", exc, "DD2", 3.0, method="DOP853", rtol=1e-12, atol=1e-14, **kw)
    got = simulate("S1", exc, "DD2", 3.0, method="exponential", rtol=1e-9, atol=1e-11, **kw)
    over = lambda r: [e.time for e in r.events if e.kind == "overturn"]
    assert got.outcome == ref.outcome == outcome
    assert np.allclose(over(got), over(ref), rtol=0.0, atol=1e-7)
    assert abs(got.theta_max - ref.theta_max) < 1e-8
    assert got.energy_balance_error < 1e-6


def test_a_compile_group_of_its_own():
    from multimass.engines.fast import compile as fc

    fast = {
        k.py_func.__name__
        for k in fc._kernels_of(f"multimass.engines.fast.{m}" for m in fc._KERNEL_MODULES)
    }
    own = {
        k.py_func.__name__ for k in fc._kernels_of([f"multimass.engines.fast.{fc._EXPONENTIAL}"])
    }
    assert "exp_phase" in own and "exp_phase" not in fast
    # a step's parts are inlined into the step loop, not compiled (and linked, optimised
    # and emitted again at each level of calls) as kernels of their own: ~3 s less
    assert "_exp_steps" in own
    parts = {"_step", "_predictor", "_extrapolate", "_sweep", "_activation_scan", "_brent"}
    assert not parts & own
    # the whole column runs call it: its source is part of their cache's fingerprint
    assert fc._HERE / f"{fc._EXPONENTIAL}.py" in fc._sources(columns=True)


def test_series_on_the_output_grid_from_the_dense_output():
    """The recorded series (every 1 ms, from the dense output) and the ledger's columns
    against DOP853 at rtol 1e-12: S1 released, DD2, 2 s (three impacts)."""
    kw = dict(backend="compiled", progress=False, max_step=np.inf, output_dt=1e-3)
    ref = simulate(
        "S1", FreeRelease(0.11), "DD2", 2.0, method="DOP853", rtol=1e-12, atol=1e-14, **kw
    )
    got = simulate(
        "S1", FreeRelease(0.11), "DD2", 2.0, method="exponential", rtol=1e-9, atol=1e-11, **kw
    )
    assert len(got.t) == len(ref.t) > 2000
    a, b = got.series, ref.series
    assert np.abs(a["theta"] - b["theta"]).max() < 1e-9  # rad (measured 2e-10)
    assert np.abs(a["thetadot"] - b["thetadot"]).max() < 1e-7  # rad/s (measured 1e-8)
    top = f"udot{multimass.column('S1').n}"
    assert np.abs(a[top] - b[top]).max() < 1e-6 * np.abs(b[top]).max()  # (measured 5e-8)
    la, lb = got.ledger, ref.ledger
    for col in ("damping", "impact"):  # J; the integrals, not derived from the energy
        assert np.abs(la[col] - lb[col]).max() < 1e-6 * np.abs(lb[col]).max()


def test_transforms_are_the_plain_complex_products_to_the_bit():
    """`_to_modes`, `_from_modes` and N's L x on their real layouts give the numbers of the
    plain complex products, summed in the same order (Python's complex arithmetic, the
    same formulas as numba's), to the bit."""
    from multimass.engines.fast._exp_kernel import _from_modes, _layout, _nonlinear, _to_modes

    st = multimass.column("S1")
    L, lam, V, W, wt = RockingModes.of(st).arrays
    LT, lx, V2, W2 = _layout(L, V, W)
    nm, k = V.shape
    rng = np.random.default_rng(5)
    x = rng.standard_normal(nm + 3) * 1e-2
    x[: nm // 2 : 2] = 0.0  # zeros are skipped: the same sums
    z = np.empty(k, complex)
    _to_modes(W2, x, z)
    for j in range(k):
        acc = 0j
        for i in range(nm):
            acc += complex(W[j, i]) * complex(float(x[i]))
        assert z[j] == acc
    zin = rng.standard_normal(k) + 1j * rng.standard_normal(k)
    out = np.empty(nm + 3)
    _from_modes(V2, wt, zin, out)
    for i in range(nm):
        acc = 0.0
        for j in range(k):
            v = complex(V[i, j])
            acc += float(wt[j]) * (v.real * zin[j].real - v.imag * zin[j].imag)
        assert out[i] == acc
    m, H, K, C, mp = _arrays(st)
    model = (1, m, H, K, C, mp, np.zeros(mx.FP_SIZE), mx.EXC_NONE, np.zeros(mx.PAR_SIZE),
             np.zeros(2))  # fmt: skip
    f, got = np.empty(nm + 3), np.empty(nm + 3)
    mx.rhs_call(0.0, x, f, *model)
    _nonlinear(0.0, x, got, LT, lx, model)
    for i in range(nm):
        acc = 0.0
        for j in range(nm):
            acc += float(L[i, j]) * float(x[j])
        assert got[i] == f[i] - acc
    assert np.array_equal(got[nm:], f[nm:])


def test_a_spare_table_is_the_one_computed_for_its_size():
    """A φ-table put out of the slots and taken back for the same size holds the numbers
    `_coefficients` computes for that size; a size a few ulps away is computed anew."""
    from multimass.engines.fast._exp_kernel import _SLOTS, _coefficients, _table

    lam = RockingModes.of(multimass.column("S1")).lam
    tables, sizes, slots, _ = new_cache(lam.size)
    hs = [1e-3 * 2.0 ** (-i / 4) for i in range(_SLOTS + 1)]  # one more than the slots
    for h in hs:
        _table(h, 1.0, lam, tables, sizes, slots)
    fresh = np.empty_like(tables[0])
    for h in (hs[0], hs[1] * (1.0 + 8e-16)):  # a spare; a size near a spare's
        got = _table(h, 1.0, lam, tables, sizes, slots).copy()
        _coefficients(h, lam, fresh)
        assert np.array_equal(got, fresh)
