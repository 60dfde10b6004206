"""Flexible rocking oscillator (paper 000, Section 4): SymPy EOMs, uplift, impacts, energy."""

import json
import math

import numpy as np
import pytest
import sympy as sp

from multimass import InputError, Ricker
from multimass.engines.contact_dynamics import _Phase
from multimass.engines.flexible_oscillator import (
    FlexibleOscillator,
    OscillatorResponse,
    _OscillatorModel,
    simulate_oscillator,
)
from multimass.model.flexible_oscillator_eom import numeric, symbolic
from multimass.result import EVENT_KINDS, LEDGER_NAMES, OUTCOMES, STATUSES, Result

# an illustrative oscillator (paper 000 takes its specimens from [23], not reproduced there)
OSC = dict(m=1000.0, m_c=200.0, m_b=300.0, h=2.0, b=0.3, zeta=0.02)


@pytest.fixture(scope="module")
def osc():
    return FlexibleOscillator.from_frequency(2.0, **OSC)


def test_mass_matrix_matches_the_legible_terms_of_eq_30():
    s = symbolic()
    P, (u, _x, _y, ph) = s.params, s.q
    m, mc, mb, h = P["m"], P["m_c"], P["m_b"], P["h"]
    L = m + sp.Rational(3, 8) * mc  # m + (α3/4 + α2/3 + α1/2 + α0) m_c, Eq 30
    assert sp.simplify(s.M[0, 0] - (m + sp.Rational(33, 140) * mc)) == 0  # m̃, Eq 27
    assert sp.simplify(s.M[0, 1] - L * sp.cos(ph)) == 0  # Eq 30, row 1
    assert sp.simplify(s.M[0, 2] - L * sp.sin(ph)) == 0  # Eq 30, row 1
    assert sp.simplify(s.M[1, 1] - (m + mb + mc)) == 0  # Eq 30, row 2
    assert sp.simplify(s.M[2, 2] - (m + mb + mc)) == 0  # Eq 30, row 3
    # Eq 30 row 2: −(m h cos φ + m u sin φ + ½ m_c h cos φ + (3/8) m_c u sin φ) φ̈
    assert (
        sp.simplify(
            s.M[1, 3]
            + m * h * sp.cos(ph)
            + m * u * sp.sin(ph)
            + mc * h * sp.cos(ph) / 2
            + sp.Rational(3, 8) * mc * u * sp.sin(ph)
        )
        == 0
    )
    # the φ̈ coefficient of row 1 is −(m + (α3/5 + α2/4 + α1/3 + α0/2) m_c) h (printed garbled)
    assert sp.simplify(s.M[0, 3] + (m + sp.Rational(11, 40) * mc) * h) == 0


def test_forcing_matches_the_legible_right_hand_sides_of_eq_30():
    s = symbolic()
    P, (u, _x, _y, ph), (ud, _xd, _yd, phd) = s.params, s.q, s.qd
    m, mc, mb, h, g, k, c = (P[n] for n in ("m", "m_c", "m_b", "h", "g", "k", "c"))
    L, mt = m + sp.Rational(3, 8) * mc, m + sp.Rational(33, 140) * mc
    # row 1: −c u̇ − k̃ u + m̃ u φ̇² − L cos φ ü_g − L sin φ g
    row1 = -c * ud - k * u + mt * u * phd**2 - L * sp.cos(ph) * s.ag - L * sp.sin(ph) * g
    assert sp.simplify(s.forcing[0] - row1) == 0
    # row 2: −(m h sin φ − m u cos φ + ½ m_c h sin φ − (3/8) m_c u cos φ) φ̇²
    #        + 2 L sin φ u̇ φ̇ − (m + m_b + m_c) ü_g
    row2 = (
        -(
            m * h * sp.sin(ph)
            - m * u * sp.cos(ph)
            + mc * h * sp.sin(ph) / 2
            - sp.Rational(3, 8) * mc * u * sp.cos(ph)
        )
        * phd**2
        + 2 * L * sp.sin(ph) * ud * phd
        - (m + mb + mc) * s.ag
    )
    assert sp.simplify(s.forcing[1] - row2) == 0
    # row 3 (printed garbled): ends with −(m + m_b + m_c) g
    assert sp.simplify(s.forcing[2].subs({phd: 0, ud: 0}) + (m + mb + mc) * g) == 0


@pytest.mark.parametrize(
    "shape",
    [
        (0, 0, sp.Rational(3, 2), -sp.Rational(1, 2)),
        (0, 1, 0, 0),
        (sp.Rational(1, 5), sp.Rational(1, 2), sp.Rational(1, 2), -sp.Rational(1, 5)),
    ],
)
def test_generalised_mass_and_stiffness_of_eq_27(shape):
    s = symbolic(shape)
    a0, a1, a2, a3 = shape
    m, mc, _h = s.params["m"], s.params["m_c"], s.params["h"]
    # Eq 27 with α3²/7 (the printed α3²/3 is a typo: ∫₀¹ s⁶ ds = 1/7)
    m_tilde = (
        m
        + (
            a3**2 / 7
            + a3 * a2 / 3
            + 2 * a3 * a1 / 5
            + a3 * a0 / 2
            + a2**2 / 5
            + a2 * a1 / 2
            + 2 * a2 * a0 / 3
            + a1**2 / 3
            + a1 * a0
            + a0**2
        )
        * mc
    )
    assert sp.simplify(s.m_tilde - m_tilde) == 0
    assert sp.simplify(s.k_tilde_factor - 4 * (3 * a3**2 + a2**2 + 3 * a3 * a2)) == 0  # Eq 27


def test_lambdified_functions_are_built_once():
    assert numeric() is numeric()
    assert symbolic() is symbolic()


def test_uplift_condition_eq_28_is_the_sign_of_the_left_contact_force(osc):
    # the general contact forces of the full-contact phase against Eq 28:
    # λ_left = −(m g / 2) · LHS(Eq 28), so Eq 28 ≥ 0 ⇔ the left corner unloads
    rng = np.random.default_rng(3)
    osc_damped = FlexibleOscillator.from_frequency(2.0, **dict(OSC, zeta=0.05))
    for o in (osc, osc_damped):
        for _trial in range(50):
            u, ud, ag = rng.normal(0, 0.02), rng.normal(0, 0.2), rng.normal(0, 4.0)
            model = _OscillatorModel(o, lambda t, ag=ag: ag, np.inf)
            q, v = np.array([u, 0, 0, 0.0]), np.array([ud, 0, 0, 0.0])
            lam = _Phase(model, (0, 1), q, v).solve(0.0, q, v)[1]
            margin = o.uplift_margin(u, ud, ag)
            assert lam[0] == pytest.approx(-0.5 * o.m * o.g * margin, rel=1e-10, abs=1e-8)


def test_u_cr_of_eq_29_is_where_eq_28_vanishes(osc):
    undamped = FlexibleOscillator.from_frequency(2.0, **dict(OSC, zeta=0.0))
    for o in (osc, undamped):
        # ζ = 0 term-by-term: with u̇ = 0 and ü_g = 0 the damping term is zero anyway
        assert o.uplift_margin(o.u_cr, 0.0, 0.0) == pytest.approx(0.0, abs=1e-12)
        assert o.uplift_margin(1.01 * o.u_cr, 0.0, 0.0) > 0.0
        assert o.uplift_margin(0.99 * o.u_cr, 0.0, 0.0) < 0.0
        model = _OscillatorModel(o, lambda t: 0.0, np.inf)
        q, v = np.array([o.u_cr, 0, 0, 0.0]), np.zeros(4)
        lam = _Phase(model, (0, 1), q, v).solve(0.0, q, v)[1]
        assert abs(lam[0]) < 1e-10 * o.m * o.g
    # the printed factor (1 + 31/140 γ) in Eq 28 is inconsistent with Eq 29:
    g_mc, o = osc.m_c / osc.m, osc
    printed = (
        o.h / o.b * (1 + 11 / 40 * g_mc) / (1 + 31 / 140 * g_mc) * o.k_tilde * o.u_cr / (o.m * o.g)
        - (1 + o.m_b / o.m + g_mc)
        + (1 + 3 / 8 * g_mc) * o.u_cr / o.b
    )
    assert abs(printed) > 1e-3


def test_u_cr_closed_form(osc):
    # paper 000, Eq 29 written out for the adopted shape
    g_mc, g_mb = osc.m_c / osc.m, osc.m_b / osc.m
    w2 = osc.k_tilde / (osc.m * (1 + 33 / 140 * g_mc))
    expected = (
        (1 + g_mb + g_mc)
        * osc.b
        * osc.g
        / ((1 + 11 / 40 * g_mc) * osc.h * w2 + (1 + 3 / 8 * g_mc) * osc.g)
    )
    assert osc.u_cr == pytest.approx(expected, rel=1e-14)
    assert osc.omega_n == pytest.approx(2 * math.pi * 2.0, rel=1e-14)
    assert osc.k_tilde == pytest.approx(3 * osc.EI / osc.h**3, rel=1e-14)  # cantilever


@pytest.mark.parametrize("eps", [0.0, 0.5])
def test_free_release_energy_ledger_closes(osc, eps):
    r = simulate_oscillator(osc, eps, 3.0, u0=2.5 * osc.u_cr)
    E0 = r.raw.energy[0]
    assert E0 > 0
    assert np.abs(r.raw.ledger_error).max() < 1e-7 * E0
    assert r.raw.damping[-1] > 0
    impacts = r.raw.impacts
    assert impacts and all(ev.impact.energy_loss >= -1e-10 * E0 for ev in impacts)
    # release beyond u_cr rocks about the right corner first (u > 0 leans right, φ < 0)
    assert r.phase[1] == "rock_right" and r.phi[5] < 0


def test_impacts_bounce_only_with_positive_eps(osc):
    # Poisson's law: ε_P = 0 keeps the impacting corner down (ġ_N⁺ = 0, Eq 11 with
    # ε = 0), ε_P > 0 lets it bounce off (ġ_N⁺ > 0), paper 000 Sec 4.1
    for eps in (0.0, 0.6):
        r = simulate_oscillator(osc, eps, 2.0, u0=2.5 * osc.u_cr)
        rebound = []
        for ev in r.raw.impacts:
            new = [i for i, c in enumerate(ev.contacts) if c not in ev.closed_before]
            v_scale = np.abs(ev.impact.gN_minus).max()
            rebound += [ev.impact.gN_plus[i] / v_scale for i in new]
        assert rebound
        if eps == 0.0:
            np.testing.assert_allclose(rebound, 0.0, atol=1e-9)
        else:
            assert max(rebound) > 0.1


def test_ricker_pulse_response_and_ledger(osc):
    ag = Ricker(amplitude=0.25 * osc.g, omega=2 * math.pi * 1.0)
    r = simulate_oscillator(osc, 0.3, 6.0, ag=ag)
    assert r.status == "completed"
    assert {"rock_left", "rock_right"} <= set(r.phase)
    ref = np.abs(r.raw.ground_work).max()
    assert np.abs(r.raw.ledger_error).max() < 1e-7 * ref


@pytest.mark.parametrize(
    "kw, match",
    [
        (dict(m=-1.0), "`m`"),
        (dict(h=0.0), "`h`"),
        (dict(zeta=-0.1), "`zeta`"),
        (dict(shape=(0.0, 0.0, 1.0, 0.5)), "`shape`"),
        (dict(shape=0.0), "`shape`"),
        (dict(shape=(0.0, 0.0, float("nan"), 1.0)), "`shape`"),
        (dict(shape=(1.0, 0.0, 0.0, 0.0)), "no stiffness"),  # ψ'' ≡ 0: k̃ = 0 (Eq 27)
        (dict(m=10**400), "`m`"),
        (dict(h=1e-300), "derived"),
        (dict(EI=1e308, h=1e-100), "k_tilde"),
    ],
)
def test_bad_oscillator(kw, match):
    args = dict(OSC, EI=1e5)
    args.update(kw)
    with pytest.raises(InputError, match=match):
        FlexibleOscillator(**args)


def test_bad_simulation_input(osc):
    with pytest.raises(InputError, match="eps_p"):
        simulate_oscillator(osc, 1.2, 1.0)
    with pytest.raises(InputError, match="`ag`"):
        simulate_oscillator(osc, 0.5, 1.0, ag="record.csv")


# -- runs that start on the ground: the given state, its energy, friction


@pytest.mark.parametrize("u0, udot0", [(0.0, 0.0), (0.5, 0.0), (0.5, -0.3), (2.5, 0.2)])
def test_ledger_starts_from_the_given_state(osc, u0, udot0):
    # base flat and at rest: E(t0) = ½ k̃ u0² + ½ m̃ u̇0² (Eq 27), whatever happens at t0
    u0 *= osc.u_cr
    r = simulate_oscillator(osc, 0.5, 0.5, u0=u0, udot0=udot0)
    E0 = 0.5 * osc.k_tilde * u0**2 + 0.5 * osc.m_tilde * udot0**2
    assert r.raw.t[0] == 0.0 and r.u[0] == u0
    assert r.raw.energy[0] == pytest.approx(E0, rel=1e-12, abs=1e-12)
    weight_h = (osc.m + osc.m_c + osc.m_b) * osc.g * osc.h  # round-off of V ~ 1e-16 of it
    assert np.abs(r.raw.ledger_error).max() <= 1e-7 * E0 + 1e-12 * weight_h
    assert r.status == "completed" and r.checks["energy_balance"]["passed"]


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_base_spinning_at_the_start_rocks_like_a_rigid_body(sign):
    # The base starts flat, pivoting on one corner at rate φ̇0 (the other corner separates,
    # so it must be left open). Hand closed forms of the rigid body (column undeformed):
    # T0 = ½ φ̇0² [m (h² + b²) + m_b b² + m_b b²/3 + m_c (h²/3 + b²)], and the first peak
    # from T0 = g [m (b sin φ + h cos φ − h) + m_b b sin φ + m_c (b sin φ + h/2 (cos φ − 1))].
    # A 20 Hz column follows the rigid peak within 1e-3 (measured 7.3e-4).
    from scipy.optimize import brentq

    from multimass.engines.contact_dynamics import simulate_contacts

    o = FlexibleOscillator.from_frequency(20.0, **dict(OSC, zeta=0.0))
    m, mc, mb, h, b, g = o.m, o.m_c, o.m_b, o.h, o.b, o.g
    w = sign * 0.1
    T0 = 0.5 * w * w * (m * (h * h + b * b) + mb * b * b * 4 / 3 + mc * (h * h / 3 + b * b))

    def V(p):
        return g * (
            m * (b * math.sin(p) + h * math.cos(p) - h)
            + mb * b * math.sin(p)
            + mc * (b * math.sin(p) + h / 2 * (math.cos(p) - 1))
        )

    peak = brentq(lambda p: V(p) - T0, 0.0, o.alpha)
    model = _OscillatorModel(o, lambda t: 0.0, 0.0)
    r = simulate_contacts(
        model,
        np.zeros(4),
        [0.0, 0.0, abs(w) * b, w],
        0.12,
        0.0,
        dt_out=1e-4,
        gap_tol=1e-9 * h,
        zeno_velocity=1e-4 * math.sqrt(g * b),
    )
    assert r.closed[0] == (1 if sign > 0 else 2)  # on the pivot corner only
    assert r.energy[0] == pytest.approx(T0, rel=1e-12)
    assert np.abs(r.q[:, 3]).max() == pytest.approx(peak, rel=1e-3)
    assert np.abs(r.ledger_error).max() < 1e-7 * T0
    assert r.status == "completed"


def test_full_contact_friction_demand_closed_form():
    # Fixed-base free vibration from u0 (|u0| < u_cr, ζ = 0, no ground motion): the ground
    # holds the base with T = L ü, L = m + 3/8 m_c (Eq 30, row 2), and N = (m + m_b + m_c) g;
    # |ü| peaks at k̃ u0 / m̃, so the demand is L k̃ u0 / (m̃ (m + m_b + m_c) g).
    o = FlexibleOscillator.from_frequency(2.0, **dict(OSC, zeta=0.0))
    u0 = 0.5 * o.u_cr
    L = o.m + 3 / 8 * o.m_c
    expected = L * o.k_tilde * u0 / (o.m_tilde * (o.m + o.m_b + o.m_c) * o.g)
    r = simulate_oscillator(o, 0.0, 1.0, u0=u0, mu=0.5 * expected)
    assert set(r.phase) == {"full"}
    assert r.friction.smooth == pytest.approx(expected, rel=1e-7)
    assert r.status == "inaccurate" and r.outcome == "completed"
    assert r.checks["friction_smooth"] == {
        "value": r.friction.smooth,
        "limit": 0.5 * expected,
        "passed": False,
    }
    ok = simulate_oscillator(o, 0.0, 1.0, u0=u0, mu=2.0 * expected)
    assert ok.status == "completed" and ok.warnings == ()


def test_bad_new_simulation_input(osc):
    for kw, match in [
        (dict(mu=0.0), "`mu`"),
        (dict(mu=-1.0), "`mu`"),
        (dict(u0=float("nan")), "`u0`"),
        (dict(udot0="fast"), "`udot0`"),
    ]:
        with pytest.raises(InputError, match=match):
            simulate_oscillator(osc, 0.5, 1.0, **kw)


def test_a_ground_acceleration_that_is_not_finite_is_refused(osc):
    with pytest.raises(InputError, match=r"`ag` returned inf at t = 0 s"):
        simulate_oscillator(osc, 0.5, 1.0, ag=lambda t: float("inf"))


# -- the one result contract (multimass.result)


def test_oscillator_response_follows_the_result_contract(osc):
    ag = Ricker(amplitude=0.25 * osc.g, omega=2 * math.pi * 1.0)
    r = simulate_oscillator(osc, 0.3, 6.0, ag=ag)
    assert isinstance(r, OscillatorResponse) and isinstance(r, Result) and r.engine == "contact"
    assert r.status in STATUSES and r.outcome in OUTCOMES and r.status == "completed"
    assert {e.kind for e in r.events} <= EVENT_KINDS and r.n_impacts > 0
    # the base starts flat: no release peak, the peaks are the half-cycles of θ = −φ
    assert r.theta[0] == 0.0 and r.peaks.size >= 2
    assert np.abs(r.theta).max() == pytest.approx(r.theta_max, rel=1e-4)
    for pk, tp in zip(r.peaks, r.peak_times):  # each peak sits on a sample's |θ| or above
        i = int(np.argmin(np.abs(r.t - tp)))
        assert pk >= abs(r.theta[i]) - 1e-15 and abs(r.t[i] - tp) <= 0.005
    for e in r.events:  # the phase of every event is that of its corners
        for closed, phase in ((e.closed_before, e.phase_before), (e.closed_after, e.phase_after)):
            assert phase == {(0, 1): 0, (1,): 1, (0,): -1, (): None}[tuple(closed)]
    df = r.series
    assert list(df.columns[:4]) == ["t", "theta", "thetadot", "phase"]
    assert {"u", "x", "y", "phi", "udot"} <= set(df.columns)
    np.testing.assert_array_equal(df["u"], r.u)
    led = r.ledger
    assert set(led.columns) <= set(LEDGER_NAMES) and {"t", "energy", "damping"} <= set(led.columns)
    assert led["damping"].iloc[-1] > 0.0

    def refuse(c):
        raise ValueError(f"{c} in JSON")

    info = json.loads(r.to_json(), parse_constant=refuse)
    assert info["engine"] == "contact" and info["model"] == "flexible_oscillator"
    assert info["peaks"] == list(r.peaks) and info["u_cr"] == osc.u_cr
