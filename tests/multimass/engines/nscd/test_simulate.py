"""Free rocking on the rigid base and on flexible beams (paper 002, Section 6)."""

import importlib
import json
import math

import numpy as np
import pytest

from multimass import specimens
from multimass.engines import nscd
from multimass.errors import InputError

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
    return {
        name: nscd.simulate(name, theta0=math.radians(th0), dt=1e-5, t_end=1.2, n_elements=6)
        for name, (th0, _) in PAPER.items()
    }


@pytest.mark.parametrize("name", list(PAPER))
def test_first_peak_reproduces_paper_002(paper_runs, name):
    res = paper_runs[name]
    assert res.status == "completed" and len(res.peaks) >= 3  # the release's and two after
    assert abs(math.degrees(res.first_peak) - PAPER[name][1]) <= 0.03  # paper 002, Section 6.2
    assert res.n_slip_steps == 0  # paper 002, Section 6.2: no slip with mu = 0.364


@pytest.mark.parametrize("name", list(PAPER))
def test_first_peak_is_the_plastic_impact_limit(paper_runs, name):
    # closed form (Housner's restitution): 8.2808, 7.7665, 6.2026 deg
    assert math.degrees(paper_runs[name].first_peak) == pytest.approx(
        exact_first_peak_deg(name, PAPER[name][0]), abs=0.01
    )


def test_first_peak_converges_as_dt_decreases():
    exact = exact_first_peak_deg("B6M", 11.268)
    err = [
        abs(
            math.degrees(
                nscd.simulate("B6M", theta0=math.radians(11.268), dt=dt, t_end=0.8).first_peak
            )
            - exact
        )
        for dt in (1e-3, 1e-4, 1e-5, 1e-6)
    ]
    assert err[0] > err[1] > err[2] > err[3] and err[3] < 1e-3
    slope = np.polyfit(np.log([1e-3, 1e-4, 1e-5, 1e-6]), np.log(err), 1)[0]
    assert slope > 0.7  # first order in dt, with scatter from where the impact falls in a step


def test_b6m_comes_to_rest_near_3_5_s():
    res = nscd.simulate("B6M", theta0=math.radians(11.268), dt=1e-5, t_end=4.0)
    # paper 002, Section 6.2: "Both time histories reach a rest state around 3.5 s"
    assert res.rest_time is not None and 3.3 <= res.rest_time <= 3.8
    assert abs(res.theta[-1]) < 0.01 * math.radians(11.268)
    assert res.n_gs_cap_hits == 0 and res.n_slip_steps == 0


@pytest.mark.parametrize("mu", [0.364, 0.7, 1.0])
def test_no_sliding_for_paper_friction(mu):
    # paper 002, Section 6.2: mu = 0.364 (measured), 0.7 and 1.0 give the same response
    ref = nscd.simulate("B4M", theta0=math.radians(14.839), dt=1e-4, t_end=1.5, mu=1.0)
    res = nscd.simulate("B4M", theta0=math.radians(14.839), dt=1e-4, t_end=1.5, mu=mu)
    assert res.n_slip_steps == 0 and res.max_slip_speed == 0.0
    assert np.degrees(res.peaks) == pytest.approx(np.degrees(ref.peaks), abs=1e-12)


def test_low_friction_slides():
    res = nscd.simulate("B4M", theta0=math.radians(14.839), dt=1e-4, t_end=0.6, mu=0.02)
    assert res.n_slip_steps > 0 and res.max_slip_speed > 1e-3


@pytest.mark.parametrize("E_factor, mu", [(None, 0.364), (1e2, 0.364), (1.0, 0.364), (None, 0.02)])
def test_energy_never_increases_with_plastic_impacts(E_factor, mu):
    E = None if E_factor is None else E_factor * nscd.flexible_modulus("B6M")
    res = nscd.simulate("B6M", theta0=math.radians(11.268), dt=1e-4, t_end=2.0, E=E, mu=mu)
    # theta = 1, e = 0: Delta E = -|dv|_M^2/2 - |dq|_K^2/2 - dt v.Cv + U.P <= 0 per step
    assert res.max_energy_increase <= 1e-13 * res.energy_scale
    assert res.energy[-1] < res.energy[0]
    assert res.checks["energy_gain_per_step"] == {
        "value": res.max_energy_increase / res.energy_scale,
        "limit": 1e-9,
        "passed": True,
    }
    assert res.status == res.outcome == "completed" and res.warnings == ()


def test_left_corner_mirrors_right_corner():
    right = nscd.simulate("B6M", theta0=0.15, dt=1e-4, t_end=1.5)
    left = nscd.simulate("B6M", theta0=-0.15, dt=1e-4, t_end=1.5)
    assert np.degrees(left.peaks) == pytest.approx(np.degrees(right.peaks), abs=1e-9)
    assert np.allclose(left.theta, -right.theta, atol=1e-10)


def test_sign_convention_and_initial_state():
    res = nscd.simulate("B6M", theta0=0.15, dt=1e-4, t_end=0.05)
    blk = specimens.load("B6M")
    # toolkit convention (paper 001, Fig 1): theta > 0 rests on the right corner, whose
    # abscissa is L/2 + b/2; closed form for the centre of gravity of the tilted block
    x_pivot = 0.15 + blk.b / 2
    assert res.X[0] == pytest.approx(
        x_pivot - blk.b / 2 * math.cos(0.15) + blk.h / 2 * math.sin(0.15), abs=1e-12
    )
    assert res.theta[0] == 0.15 and res.theta[-1] < 0.15 and res.thetadot[-1] < 0


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


def test_gauss_seidel_cap_makes_the_run_inaccurate():
    E = 1e2 * nscd.flexible_modulus("B6M")
    res = nscd.simulate(
        "B6M", theta0=math.radians(11.268), dt=1e-4, t_end=4.0, E=E, gs_max_iter=3, gs_tol=1e-14
    )
    assert res.n_gs_cap_hits > 0 and res.max_gs_iterations == 3
    # run-status contract: the physical end stays available, the status says the check failed
    assert res.status == "inaccurate" and res.outcome == "completed"
    gs = res.checks["gauss_seidel_residual"]
    assert gs["passed"] is False and gs["value"] > gs["limit"] == 1e-4
    # theta = 1, e = 0 dissipates at every step once the impulses are solved (module docstring
    # of nscd.result): unconverged impulses show as an energy gain above round-off
    assert res.checks["energy_gain_per_step"]["passed"] is False
    assert any(
        w.startswith("Gauss–Seidel stopped at its cap of 3 iterations") for w in res.warnings
    )
    assert "accuracy check failed" in res.message
    assert len(res.peaks) > 1  # the raw answer is still there


def test_settled_gauss_seidel_at_the_cap_is_accepted():
    # E = 10 Ebar with mu = 0.02: some steps stop at the default cap of 5000 sweeps with the
    # impulses settled to ~1e-7; the answer equals a run converged to 1e-12 within 1e-8 deg
    kw = dict(
        theta0=math.radians(11.268),
        dt=1e-4,
        t_end=1.0,
        mu=0.02,
        E=10 * nscd.flexible_modulus("B6M"),
    )
    res = nscd.simulate("B6M", **kw)
    ref = nscd.simulate("B6M", gs_max_iter=1_000_000, gs_tol=1e-12, **kw)
    assert res.n_gs_cap_hits > 0 and 0 < res.max_gs_residual < 1e-4
    assert ref.n_gs_cap_hits == 0 and ref.max_gs_residual == 0.0
    assert res.status == "completed" and res.warnings == () and "settled" in res.message
    assert np.max(np.abs(np.degrees(res.theta - ref.theta))) < 1e-8


def test_a_check_that_is_not_judged_on_round_off():
    # e = 0.5 (Newton): the scheme may gain a little energy at an impact; the limit is then
    # the bench's 1e-3 of the energy scale, not the 1e-9 of the dissipative theta = 1, e = 0
    res = nscd.simulate(
        "B6M",
        theta0=math.radians(11.268),
        dt=1e-4,
        t_end=1.0,
        restitution=0.5,
        E=1e2 * nscd.flexible_modulus("B6M"),
    )
    chk = res.checks["energy_gain_per_step"]
    assert chk["limit"] == 1e-3 and 0 < chk["value"] < 1e-3 and res.status == "completed"


def test_summary_is_strict_json_for_a_failed_run():
    res = nscd.simulate("B6M", theta0=0.1, dt=1e-4, t_end=0.05, theta_method=0.0)
    assert res.status == res.outcome == "failed"
    data = json.loads(json.dumps(res.summary(), allow_nan=False))  # no NaN, no Infinity
    assert data["status"] == "failed" and "diverged" in data["message"]


def test_summary_holds_the_cli_fields():
    res = nscd.simulate("B6M", theta0=0.1, dt=1e-4, t_end=0.2)
    s = res.summary()
    for key in (
        "status",
        "peaks_deg",
        "rest_time",
        "n_steps",
        "max_gs_iterations",
        "wall_time_s",
    ):
        assert key in s
    assert s["n_steps"] == 2000 and s["rest_time"] is None


# --- the user's own inputs: validated before anything is built, costed before it runs ----

GOOD = dict(theta0=0.1, dt=1e-4, t_end=0.01)


@pytest.mark.parametrize(
    "override, fragment",
    [
        ({"dt": True}, "`dt` = True: expected a number"),
        ({"dt": "1e-4"}, "`dt` = '1e-4': expected a number"),
        ({"dt": math.nan}, "`dt` = nan"),
        ({"dt": 0.0}, "`dt`"),
        ({"t_end": math.inf}, "`t_end` = inf"),
        ({"t_end": 1e-6}, "longer than `t_end`"),
        ({"theta0": math.nan}, "`theta0`"),
        ({"theta0": 0.3}, "`theta0` = 0.3 rad: the block does not rest on its corner"),
        ({"E": math.nan}, "`E`"),
        ({"E": 1e9}, "`E` = 1e+09 Pa: too soft"),
        ({"E": 1e31}, "`E` = 1e+31 Pa: above 1e+30 Pa"),
        ({"n_elements": 6.0}, "`n_elements` = 6.0: expected a whole number"),
        ({"n_elements": True}, "`n_elements` = True"),
        ({"n_elements": 1001}, "`n_elements` = 1001: at most 1000 elements"),
        ({"theta_method": -0.1}, "`theta_method`"),
        ({"mu": math.inf}, "`mu`"),
        ({"restitution": math.nan}, "`restitution`"),
        ({"x_centre": "0.15"}, "`x_centre`"),
        ({"gs_tol": 0.0}, "`gs_tol`"),
        ({"gs_tol": 1e-16}, "`gs_tol`"),
        ({"gs_max_iter": 2.5}, "`gs_max_iter`"),
        ({"gs_max_iter": 10**7}, "`gs_max_iter`"),
        ({"record_every": 0}, "`record_every`"),
        ({"rest_fraction": 0.0}, "`rest_fraction`"),
        ({"max_hours": 0.0}, "`max_hours`"),
        ({"progress": "yes"}, "`progress` = 'yes'"),
    ],
)
def test_bad_argument_names_the_field(override, fragment):
    with pytest.raises(InputError) as err:
        nscd.simulate("B6M", **{**GOOD, **override})
    assert fragment in str(err.value)


def test_run_over_the_budget_is_refused_before_it_starts(monkeypatch):
    engine = importlib.import_module("multimass.engines.nscd.run")
    monkeypatch.setattr(engine, "assemble", lambda *a: pytest.fail("assembled a refused run"))
    # 4e9 steps (the reviewer's --dt 1e-9) at >= 1.3 µs per step: hours, over the 1 h default
    with pytest.raises(InputError, match=r"estimated .* \(4e\+09 steps.*over the budget of 1 h"):
        nscd.simulate("B6M", theta0=0.1, dt=1e-9, t_end=4.0)
    # the budget is the caller's: 4e6 steps (>= 5 s) are refused within 1e-4 h = 0.36 s
    with pytest.raises(InputError, match="over the budget"):
        nscd.simulate("B6M", theta0=0.1, dt=1e-6, t_end=4.0, max_hours=1e-4)


def test_output_beyond_memory_is_refused():
    # every step recorded: 1e12 rows of 8 floats = 64 TB, refused on memory (checked first)
    with pytest.raises(InputError, match="its output would need .*TiB"):
        nscd.simulate("B6M", theta0=0.1, dt=1e-9, t_end=1e3, record_every=1)


class _Recorder:
    """Stands in for multimass.progress.Progress and records the clock it is given."""

    made = []

    def __init__(self, total, desc, *, show=None, estimate=None, unit="s"):
        self.total, self.desc, self.show, self.estimate, self.ticks = (
            total,
            desc,
            show,
            estimate,
            [],
        )
        _Recorder.made.append(self)

    shown = property(lambda self: True)

    def update(self, t):
        self.ticks.append(t)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        pass


def test_progress_moves_between_chunks(monkeypatch):
    engine = importlib.import_module("multimass.engines.nscd.run")
    monkeypatch.setattr(engine, "Progress", _Recorder)
    monkeypatch.setattr(engine.cost, "chunk_steps", lambda n_el, n_steps: 300)
    _Recorder.made.clear()
    res = nscd.simulate("B6M", theta0=0.1, dt=1e-4, t_end=0.1, progress=True)
    bar = _Recorder.made[-1]
    assert bar.show is True and bar.desc == "nscd B6M" and bar.total == pytest.approx(0.1)
    assert bar.estimate == res.estimated_s > 0
    # 1000 steps in chunks of 300: the bar moves at steps 300, 600, 900 and 1000
    assert bar.ticks == pytest.approx([0.03, 0.06, 0.09, 0.1], abs=1e-12)


def test_progress_is_automatic_above_a_few_seconds(monkeypatch):
    engine = importlib.import_module("multimass.engines.nscd.run")
    monkeypatch.setattr(engine, "Progress", _Recorder)
    _Recorder.made.clear()
    nscd.simulate("B6M", theta0=0.1, dt=1e-4, t_end=0.01)
    assert _Recorder.made[-1].show is None  # automatic: multimass.progress decides
    nscd.simulate("B6M", theta0=0.1, dt=1e-4, t_end=0.01, progress=False)
    assert _Recorder.made[-1].show is False
