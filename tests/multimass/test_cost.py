"""The cost estimate of a run (multimass.cost) and the progress helpers (multimass.progress)."""

import math

import numpy as np
import pytest

import multimass
from multimass import FreeRelease, InputError, estimate, simulate
from multimass.cost import simulation_cost, spectral_radius
from multimass.progress import Progress, RunCost, format_bytes, format_duration


def test_spectral_radius_against_the_foss_eigenvalues():
    # an independent implementation of the same state matrix: modal's Foss solver (Eq 24)
    from multimass.modal.eigen import foss
    from multimass.modal.linearisation import full_contact

    for name in ("S1", "S2", "S3"):
        st = multimass.column(name)
        ref = np.abs(foss(full_contact(st)).eigenvalues).max()
        assert spectral_radius(st) == pytest.approx(ref, rel=1e-10)
    assert spectral_radius(multimass.rigid_block("B6M")) == 0.0


def test_a_single_degree_of_freedom_in_closed_form():
    # one node, Rayleigh damping ζ: |λ| = ω for ζ < 1 (λ = −ζω ± iω√(1−ζ²))
    class Sdof:
        n, m, K = 1, np.array([2.0]), np.array([[800.0]])
        C = np.array([[2 * 0.05 * math.sqrt(800.0 * 2.0)]])

    assert spectral_radius(Sdof) == pytest.approx(20.0, rel=1e-12)


@pytest.mark.parametrize("scale", [1.0, 100.0])
def test_steps_follow_the_stiffest_mode(scale):
    # the estimate's steps against what the compiled DOP853 path really took (12 RHS a step):
    # never below the real count, never more than 3× above (the spread of the calibration)
    st = multimass.column("S1", E_s=200e9 * scale)
    r = simulate(st, FreeRelease(0.1), "DD2", 1.0, backend="compiled", output_dt=None)
    cost = simulation_cost(
        st,
        1.0,
        method="DOP853",
        max_step=5e-3,
        output_dt=None,
        backend="compiled",
        integrator="solve_ivp",
    )
    ratio = cost.steps / (r.n_rhs / 12)
    assert 0.9 <= ratio <= 3.0, ratio
    assert "stiffest mode" in cost.basis


def test_the_exponential_estimate_against_its_steps():
    # the exponential rocking integrator: 9 right-hand sides a step attempt; its steps are
    # not set by the stiffest mode, so the estimate is its typical step (S1 released)
    r = simulate(
        "S1", FreeRelease(0.1), "DD2", 2.0, backend="compiled", method="exponential",
        output_dt=None, max_step=math.inf,
    )  # fmt: skip
    cost = simulation_cost(
        multimass.column("S1"), 2.0, method="exponential", max_step=math.inf, output_dt=None,
        backend="compiled", integrator="solve_ivp",
    )  # fmt: skip
    ratio = cost.steps / (r.n_rhs / 9)
    assert 0.5 <= ratio <= 3.0, ratio
    assert "exponential steps" in cost.basis


def test_memory_counts_the_output_grid():
    st = multimass.column("S1")
    cost = simulation_cost(
        st,
        10.0,
        method="DOP853",
        max_step=5e-3,
        output_dt=1e-3,
        backend="scipy",
        integrator="solve_ivp",
    )
    assert cost.memory == pytest.approx(1e4 * 8 * (6 * 5 + 19))
    assert "1e+04 output samples" in cost.basis


def test_newmark_cost_is_its_steps():
    st = multimass.rigid_block("B6M")
    cost = simulation_cost(
        st,
        2.0,
        method="DOP853",
        max_step=5e-3,
        output_dt=None,
        backend="scipy",
        integrator="newmark",
        dt=1e-3,
    )
    assert cost.steps == pytest.approx(2000.0)


def test_run_cost_check_names_both_problems():
    cost = RunCost(steps=1e12, seconds=1e9, memory=1e15, basis="steps of 1 ms")
    with pytest.raises(InputError) as err:
        cost.check("a run", "do less", max_seconds=3600.0, max_memory=1e9)
    msg = str(err.value)
    assert msg.startswith("a run: estimated 32 years") and "909 TiB" in msg  # 1e15 B / 2**40
    assert "(steps of 1 ms); do less" in msg and "max_hours" in msg
    assert RunCost(1.0, 1.0, 1.0, "").check("ok", "", max_seconds=2.0, max_memory=2.0)


def test_formats():
    assert format_duration(42.0) == "42 s" and format_duration(720.0) == "12 min"
    assert format_duration(3.4 * 3600) == "3.4 h" and format_duration(math.inf) == "forever"
    assert format_bytes(100) == "100 B" and format_bytes(7.3 * 2**40) == "7.3 TiB"


def test_progress_is_automatic_from_the_estimate(capsys):
    with Progress(10.0, "quick", estimate=0.1) as bar:
        bar.update(5.0)
        assert not bar.shown
    with Progress(10.0, "slow", estimate=30.0) as bar:
        assert bar.shown
        bar.update(5.0)
        bar.update(50.0)  # beyond the end: clipped
        assert bar._bar.n == 10.0
    assert "slow: estimated 30 s" in capsys.readouterr().err


def test_estimate_of_a_long_record_run_shows_progress():
    # a run that takes tens of seconds shows progress: S1 for 40 s through solve_ivp
    cost = estimate("S1", FreeRelease(0.1), "DD2", 40.0)
    from multimass.progress import PROGRESS_AFTER_S

    assert cost.seconds > PROGRESS_AFTER_S


def test_an_output_beyond_the_budget_is_refused_before_the_run():
    """output_dt = 1e-7 s over 1 s (10⁷ rows × 19 columns of a block's series, 1.42 GiB)
    ran silent for minutes; the output's size is estimated from the arguments and
    refused, naming output_dt, its value and the step that fits. 1e-6 s is allowed."""
    from multimass.cost import OUTPUT_BUDGET

    with pytest.raises(InputError) as err:
        estimate("B6M", FreeRelease(0.1), "CIM", 1.0, output_dt=1e-7)
    msg = str(err.value)
    assert msg.startswith("`output_dt` (--output-dt) = 1e-07: the output would hold 1e+07 rows")
    assert "19 columns (1.42 GiB), more than the 1 GiB" in msg
    assert f"to ≥ {19 * 8 / OUTPUT_BUDGET:.2g} s" in msg and "output_dt=None" in msg
    assert estimate("B6M", FreeRelease(0.1), "CIM", 1.0, output_dt=1e-6).memory < OUTPUT_BUDGET


def test_a_large_allowed_output_shows_progress():
    """Each output row costs time (recording, Eq 7's accelerations, the ledger): 10⁶ rows
    of a one-second block run are estimated above the progress threshold, so the run
    shows a bar instead of going silent."""
    from multimass.progress import PROGRESS_AFTER_S

    quiet = estimate("B6M", FreeRelease(0.1), "CIM", 1.0, output_dt=1e-3)
    large = estimate("B6M", FreeRelease(0.1), "CIM", 1.0, output_dt=1e-6)
    assert quiet.seconds < PROGRESS_AFTER_S <= large.seconds
    assert large.seconds - quiet.seconds >= (1e6 - 1e3) * 7e-6  # ≥ the fastest rate measured


def test_a_stiff_column_over_the_budget_is_pointed_to_the_exponential_method():
    """A uniform 40-node column (S ≈ 1 600): on the default solve_ivp path its stiffest mode
    holds DOP853 to 1.3 µs steps, 7.9 h estimated; the refusal names the options and flags
    that run it with the exponential method, and those options finish it in a few
    thousand steps (compiled DOP853 needs 2 million: 24.6e6 right-hand sides)."""
    from multimass.bench.scaling import uniform_column

    st = uniform_column(40)
    with pytest.raises(InputError) as err:
        simulate(st, FreeRelease(0.11), "DD2", 10.0)
    msg = str(err.value)
    assert "over the budget" in msg and "the column is stiff (S = " in msg
    assert (
        "method='exponential', backend='compiled' (--method exponential --backend compiled)" in msg
    )
    r = simulate(st, FreeRelease(0.11), "DD2", 10.0, method="exponential", backend="compiled",
                 output_dt=None)  # fmt: skip
    assert r.status == "completed" and r.n_rhs < 1e5


def test_a_long_stiff_run_says_the_exponential_method_would_be_faster(capsys):
    """The 20-node column on compiled DOP853 (estimated above PROGRESS_AFTER_S): the note
    under the estimate names method='exponential' only (the backend is compiled already);
    following it gives the same impacts and θ_max within 1e-6 rad (DOP853's run here
    the reference)."""
    from multimass.bench.scaling import uniform_column

    st = uniform_column(20)
    dop = simulate(st, FreeRelease(0.11), "DD2", 10.0, backend="compiled", output_dt=None)
    err = capsys.readouterr().err
    assert "the column is stiff" in err and "method='exponential' (--method exponential)" in err
    assert "backend='compiled'" not in err
    exp = simulate(st, FreeRelease(0.11), "DD2", 10.0, backend="compiled", output_dt=None,
                   method="exponential", progress=False)  # fmt: skip
    assert "stiff" not in capsys.readouterr().err
    impacts = lambda r: np.array([e.time for e in r.events if e.kind == "impact"])  # noqa: E731
    assert impacts(exp).size == impacts(dop).size > 10
    assert np.abs(impacts(exp) - impacts(dop)).max() < 1e-6
    assert exp.theta_max == pytest.approx(dop.theta_max, abs=1e-6)


@pytest.mark.parametrize(
    "structure, kw",
    [
        ("S1", {}),  # S ≈ 1.9: DOP853 is as fast (`multimass.sweeps.method_choice`)
        ("B6M", {}),  # a rigid block: no elastic modes
        ("stiff", {"method": "Radau"}),  # an implicit method: no stability limit to lift
        ("stiff", {"backend": "compiled", "method": "exponential"}),  # already
    ],
)
def test_no_hint_where_the_exponential_method_would_not_help(structure, kw):
    from multimass.bench.scaling import uniform_column
    from multimass.simulation import _stiff_hint
    from multimass.simulation_options import SimulationOptions

    st = uniform_column(20) if structure == "stiff" else multimass.model.structure.from_specimen(
        structure)  # fmt: skip
    o = SimulationOptions.of(None, **kw)
    assert _stiff_hint(st, 100.0, o, 1e4) == ""
    if structure == "stiff" and "backend" not in kw:
        assert _stiff_hint(st, 100.0, SimulationOptions.of(None), 1e4) != ""  # DOP853: yes
