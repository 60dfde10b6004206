"""Free rocking on the rigid base and on flexible beams (paper 002, Section 6)."""

import math

import numpy as np
import pytest

import nscd
import specimens

# paper 002, Section 6.2: release angles and simulated first post-impact peaks (magnitudes)
PAPER = {"B4M": (14.839, 8.28), "B6M": (11.268, 7.76), "B8M": (7.731, 6.18)}


def exact_first_peak_deg(name, theta0_deg):
    """Closed form: rigid block from rest, Housner's eta_H = 1 - 1.5 sin^2(alpha) (paper 004, Eq 9);
    cos(alpha - theta1) = cos(alpha) + eta^2 (cos(alpha - theta0) - cos(alpha))."""
    blk = specimens.load(name)
    a = math.atan2(blk.b, blk.h)
    eta = 1.0 - 1.5 * math.sin(a) ** 2
    t0 = math.radians(theta0_deg)
    return math.degrees(a - math.acos(math.cos(a) + eta**2 * (math.cos(a - t0) - math.cos(a))))


@pytest.fixture(scope="module")
def paper_runs():
    """The three blocks on the rigid base at the paper's dt = 1e-5 s and 6 elements."""
    return {name: nscd.simulate(name, theta0=math.radians(th0), dt=1e-5, t_end=1.2, n_elements=6)
            for name, (th0, _) in PAPER.items()}


@pytest.mark.parametrize("name", list(PAPER))
def test_first_peak_reproduces_paper_002(paper_runs, name):
    res = paper_runs[name]
    assert res.status == "completed" and len(res.peaks_deg) >= 2
    assert abs(res.first_peak_deg - PAPER[name][1]) <= 0.03          # paper 002, Section 6.2
    assert res.n_slip_steps == 0                 # paper 002, Section 6.2: no slip with mu = 0.364


@pytest.mark.parametrize("name", list(PAPER))
def test_first_peak_is_the_plastic_impact_limit(paper_runs, name):
    # closed form (Housner's restitution): 8.2808, 7.7665, 6.2026 deg
    assert paper_runs[name].first_peak_deg == pytest.approx(exact_first_peak_deg(name, PAPER[name][0]),
                                                           abs=0.01)


def test_first_peak_converges_as_dt_decreases():
    exact = exact_first_peak_deg("B6M", 11.268)
    err = [abs(nscd.simulate("B6M", theta0=math.radians(11.268), dt=dt, t_end=0.8).first_peak_deg - exact)
           for dt in (1e-3, 1e-4, 1e-5, 1e-6)]
    assert err[0] > err[1] > err[2] > err[3] and err[3] < 1e-3
    slope = np.polyfit(np.log([1e-3, 1e-4, 1e-5, 1e-6]), np.log(err), 1)[0]
    assert slope > 0.7          # first order in dt, with scatter from where the impact falls in a step


def test_b6m_comes_to_rest_near_3_5_s():
    res = nscd.simulate("B6M", theta0=math.radians(11.268), dt=1e-5, t_end=4.0)
    # paper 002, Section 6.2: "Both time histories reach a rest state around 3.5 s"
    assert res.rest_time_s is not None and 3.3 <= res.rest_time_s <= 3.8
    assert abs(res.theta[-1]) < 0.01 * math.radians(11.268)
    assert res.n_gs_cap_hits == 0 and res.n_slip_steps == 0


@pytest.mark.parametrize("mu", [0.364, 0.7, 1.0])
def test_no_sliding_for_paper_friction(mu):
    # paper 002, Section 6.2: mu = 0.364 (measured), 0.7 and 1.0 give the same response
    ref = nscd.simulate("B4M", theta0=math.radians(14.839), dt=1e-4, t_end=1.5, mu=1.0)
    res = nscd.simulate("B4M", theta0=math.radians(14.839), dt=1e-4, t_end=1.5, mu=mu)
    assert res.n_slip_steps == 0 and res.max_slip_speed == 0.0
    assert res.peaks_deg == pytest.approx(ref.peaks_deg, abs=1e-12)


def test_low_friction_slides():
    res = nscd.simulate("B4M", theta0=math.radians(14.839), dt=1e-4, t_end=0.6, mu=0.02)
    assert res.n_slip_steps > 0 and res.max_slip_speed > 1e-3


@pytest.mark.parametrize("E_factor, mu", [(None, 0.364), (1e2, 0.364), (1.0, 0.364), (None, 0.02)])
def test_energy_never_increases_with_plastic_impacts(E_factor, mu):
    E = None if E_factor is None else E_factor * nscd.flexible_modulus("B6M")
    res = nscd.simulate("B6M", theta0=math.radians(11.268), dt=1e-4, t_end=2.0, E=E, mu=mu)
    # theta = 1, e = 0: Delta E = -|dv|_M^2/2 - |dq|_K^2/2 - dt v.Cv + U.P <= 0 per step
    assert res.max_energy_increase_J <= 1e-13 * res.energy_scale_J
    assert res.energy[-1] < res.energy[0]


def test_left_corner_mirrors_right_corner():
    right = nscd.simulate("B6M", theta0=0.15, dt=1e-4, t_end=1.5)
    left = nscd.simulate("B6M", theta0=-0.15, dt=1e-4, t_end=1.5)
    assert left.peaks_deg == pytest.approx(right.peaks_deg, abs=1e-9)
    assert np.allclose(left.theta, -right.theta, atol=1e-10)


def test_sign_convention_and_initial_state():
    res = nscd.simulate("B6M", theta0=0.15, dt=1e-4, t_end=0.05)
    blk = specimens.load("B6M")
    # toolkit convention (paper 001, Fig 1): theta > 0 rests on the right corner, whose
    # abscissa is L/2 + b/2; closed form for the centre of gravity of the tilted block
    x_pivot = 0.15 + blk.b / 2
    assert res.X[0] == pytest.approx(x_pivot - blk.b / 2 * math.cos(0.15) + blk.h / 2 * math.sin(0.15),
                                     abs=1e-12)
    assert res.theta[0] == 0.15 and res.theta[-1] < 0.15 and res.theta_dot[-1] < 0


def test_flexible_beam_starts_in_static_equilibrium():
    E = nscd.flexible_modulus("B6M")
    sys = nscd.build_system("B6M", theta0=0.0, dt=1e-4, E=E)
    bm = sys.beam
    # closed form: midspan deflection = L/2500 (definition of Ebar, paper 002, Sec 6.3) for the
    # block's weight at midspan + 5 w L^4 / (384 E I) for the self-weight; the upright block's
    # weight is shared by its corners at L/2 -+ b/2, so its share is slightly smaller
    P, L, EI, b = sys.mass * 9.81, bm.L, E * bm.I, sys.block.b
    a = L / 2 - b / 2
    corner = 2 * (P / 2) * a * (3 * L**2 - 4 * a**2) / (48 * EI)
    self_w = 5 * bm.m * 9.81 * L**4 / (384 * EI)
    assert bm.deflection(sys.qe0, L / 2) == pytest.approx(-(corner + self_w), rel=1e-9)
    assert P * L**3 / (48 * EI) == pytest.approx(L / 2500, rel=1e-12)


def test_explicit_theta_method_on_a_stiff_beam_fails_cleanly():
    res = nscd.simulate("B6M", theta0=0.1, dt=1e-4, t_end=0.05, theta_method=0.0)
    assert res.status == "failed" and "θ < 1/2" in res.message
    assert np.all(np.isfinite(res.theta))


def test_gauss_seidel_cap_is_reported():
    E = 1e2 * nscd.flexible_modulus("B6M")
    res = nscd.simulate("B6M", theta0=math.radians(11.268), dt=1e-4, t_end=4.0, E=E,
                        gs_max_iter=3, gs_tol=1e-14)
    assert res.n_gs_cap_hits > 0 and res.max_gs_iterations == 3
    assert "Gauss–Seidel hit its cap of 3 iterations" in res.message


def test_summary_holds_the_cli_fields():
    res = nscd.simulate("B6M", theta0=0.1, dt=1e-4, t_end=0.2)
    s = res.summary()
    for key in ("status", "peaks_deg", "rest_time_s", "n_steps", "max_gs_iterations", "wall_time_s"):
        assert key in s
    assert s["n_steps"] == 2000 and s["rest_time_s"] is None
