"""Verdicts on successive refinements and the detection of non-convergence
(paper 002, Sections 6.1 and 6.3)."""

import importlib
import math

import pytest

from multimass.engines import nscd
from multimass.engines.nscd.convergence import (
    check_levels,
    dt_study,
    first_peak_study,
    flexibility_study,
    housner_first_peak,
    judge,
    mesh_study,
)
from multimass.errors import InputError


@pytest.mark.parametrize(
    "diffs, ratio, status",
    [
        ([0.5, 0.05, 0.005], 10, "converged"),  # last one within tolerance 0.01
        ([1.0, 0.3], 10, "converging"),  # shrinks faster than 10^-0.5 = 0.32
        ([1.0, 0.5], 10, "not converged"),  # shrinks too slowly for a decade
        ([1.0, 0.6], 2, "converging"),  # halving: 0.6 <= 2^-0.5
        ([0.1, 0.4], 2, "not converged"),  # grows
        ([0.5], 10, "not converged"),  # one refinement above tolerance
        ([0.001], 10, "converged"),
        ([1.0, math.inf], 10, "not converged"),  # e.g. one run at rest, the next still rocking
    ],
)
def test_judge(diffs, ratio, status):
    v = judge("x", list(range(len(diffs) + 1)), [None] * (len(diffs) + 1), diffs, 0.01, ratio)
    assert v.status == status and v.reason


def test_observed_order():
    # a first-order sequence over decades: differences 1, 0.1, 0.01 -> order 1
    v = judge("x", [1e-3, 1e-4, 1e-5, 1e-6], [None] * 4, [1.0, 0.1, 0.01], 1e-6, 10.0)
    assert v.observed_order == pytest.approx((1.0, 1.0))


def test_housner_first_peak_closed_form():
    # paper 002, Section 6.2: 7.76 deg for B6M from 11.268 deg (rigid block, Housner's eta)
    assert math.degrees(housner_first_peak("B6M", math.radians(11.268))) == pytest.approx(
        7.766, abs=1e-3
    )


def test_mesh_does_not_matter_on_the_rigid_base():
    # paper 002, Fig 11: "No difference is observed in the results between the meshes"
    st = mesh_study("B6M", (3, 6, 12), dt=1e-4, t_end=1.5)
    assert st.status == "converged"
    assert max(max(v.differences) for v in st.verdicts if v.measure != "rest_time_s") < 0.05


def test_same_refinement_converges_on_rigid_base_but_not_on_a_flexible_beam():
    dts = (4e-4, 2e-4, 1e-4)
    rigid = dt_study("B6M", dts, t_end=4.0)
    flexible = dt_study("B6M", dts, t_end=4.0, E=nscd.flexible_modulus("B6M"))  # E = Ebar
    # rigid base: every measure converges at least as an order-1/2 method (paper 002, Fig 10)
    assert rigid.status in ("converging", "converged")
    # L/2500 beam: the differences between successive dt do not decrease (paper 002, Fig 19)
    assert flexible.status == "not converged"
    bad = {v.measure for v in flexible.verdicts if v.status == "not converged"}
    assert {"peaks_deg", "rest_time_s"} <= bad
    d = flexible.to_dict()
    assert d["status"] == "not converged" and len(d["runs"]) == 3


def test_rest_time_undetermined_when_still_rocking():
    st = mesh_study("B6M", (3, 6), dt=1e-4, t_end=1.0)  # rests only after ~3.5 s
    rest = next(v for v in st.verdicts if v.measure == "rest_time_s")
    assert rest.status == "undetermined" and "t_end" in rest.reason
    assert st.status == "converged"  # the undetermined measure is left out


# --- levels, budget and progress of a study --------------------------------------------


@pytest.mark.parametrize(
    "values, kind, kw, fragment",
    [
        ((1e-3, 0), "dt", {}, "`dts[1]` = 0"),
        ((1e-3,), "dt", {}, "at least 2 levels"),
        ((1e-3, 1e-3), "dt", {}, "repeated"),
        ((1e-3, 1e-4, 5e-5), "dt", {}, "ratios 10, 2 differ"),
        ("1e-3 1e-4", "dt", {}, "give a list of levels"),
        ((3, 6.0), "mesh", {}, "`meshes[1]` = 6.0: expected a whole number"),
        ((3, 5, 12), "mesh", {}, "ratios"),
        ((3, 1001), "mesh", {"geometric": False}, "at most 1000 elements"),
    ],
)
def test_bad_levels(values, kind, kw, fragment):
    with pytest.raises(InputError) as err:
        check_levels("dts" if kind == "dt" else "meshes", values, kind=kind, **kw)
    assert fragment in str(err.value)


def test_levels_are_sorted_coarse_to_fine():
    assert check_levels("dts", [1e-5, 1e-3, 1e-4], kind="dt") == (1e-3, 1e-4, 1e-5)
    assert check_levels("meshes", [12, 3, 6], kind="mesh") == (3, 6, 12)
    # the first-peak study fits a slope: any spacing
    assert check_levels("dts", [1e-3, 5e-4, 1e-4], kind="dt", geometric=False)[0] == 1e-3


def test_study_over_budget_is_refused_before_its_first_run(monkeypatch):
    engine = importlib.import_module("multimass.engines.nscd.convergence")
    monkeypatch.setattr(engine, "execute", lambda *a, **k: pytest.fail("a run started"))
    # 4e8 + 4e9 steps: hours in total, each run's own estimate notwithstanding
    with pytest.raises(InputError, match=r"dt study of B6M: estimated .*over the budget"):
        dt_study("B6M", (1e-8, 1e-9))
    # a later level with bad input stops the study before the first run, too
    with pytest.raises(InputError, match="`t_end`"):
        mesh_study("B6M", (3, 6), dt=1e-3, t_end=-1.0)
    with pytest.raises(InputError, match="`progress`"):
        mesh_study("B6M", (3, 6), dt=1e-3, t_end=0.05, progress="yes")


def test_study_reports_each_run():
    lines = []
    st = mesh_study("B6M", (3, 6), dt=1e-3, t_end=0.05, report=lines.append)
    assert [line.split(" done")[0] for line in lines] == ["B6M 3 elements", "B6M 6 elements"]
    assert st.to_dict()["warnings"] == []


def test_a_failed_run_fails_the_study():
    # explicit theta-method on the stiff rigid base: every run diverges (nothing to compare)
    st = dt_study("B6M", (2e-4, 1e-4), t_end=0.05, theta_method=0.0)
    assert all(r.outcome == "failed" for r in st.runs) and st.status == "failed"
    assert st.warnings and all("the run failed" in w for w in st.warnings)


def test_first_peak_study_takes_one_block_name():
    fps = first_peak_study("B6M", (1e-3, 5e-4), t_end=0.8)  # not the letters B, 6, M
    assert fps.blocks == ("B6M",) and fps.warnings == ()


def test_flexibility_base_level_must_be_shared():
    with pytest.raises(InputError, match="`base_dt` = 2e-05: must be one of `dts`"):
        flexibility_study("B6M", (2,), dts=(1e-4, 1e-5), base_dt=2e-5)
    with pytest.raises(InputError, match=r"`exponents\[0\]` = 1000"):
        flexibility_study("B6M", (1000,))
