"""Restitution formulas and sources (paper 004 Eqs 9–10, Table 1; paper 001 Eq 13, Table 2)."""

import math

import numpy as np
import pytest

import multimass
from multimass import specimens
from multimass.impact_models import (
    CornerRestitution,
    EmpiricalRestitution,
    FixedRestitution,
    ImpactContext,
    RandomRestitution,
    housner_eta,
    impact_model,
    modified_eta,
    r_h,
)
from multimass.impact_models.table2 import TABLE_2


@pytest.mark.parametrize(
    "name, eta_H, eta_M, k_avg",
    [
        # paper 004, Table 1 (η_M with the size averages k = 0.8608 / 0.7306, Section 3)
        ("B3M", 0.7526, 0.8106, 0.8608),
        ("B6M", 0.9294, 0.9472, 0.8608),
        ("B3L", 0.7526, 0.8598, 0.7306),
        ("B6L", 0.9294, 0.9617, 0.7306),
    ],
)
def test_table_1_restitution(name, eta_H, eta_M, k_avg):
    blk = specimens.load(name)
    assert blk.k_size_average == k_avg
    assert round(housner_eta(blk.alpha), 4) == eta_H
    assert round(modified_eta(blk.alpha, k_avg), 4) == eta_M


def test_modified_with_k_1_is_housner():
    for a in (0.1, 0.3, 0.6):
        assert modified_eta(a, 1.0) == pytest.approx(housner_eta(a), rel=1e-14)


def test_r_h_reduces_to_housner_for_a_rigid_block():
    # DESIGN.md: Eq 13 with u = 0 gives 1 − 1.5 sin²α for a uniform block
    blk = multimass.rigid_block("B6M")
    val = r_h(blk.J_p, blk.m_t, blk.B, np.zeros(0), np.zeros(0), 1)
    assert val == pytest.approx(housner_eta(blk.alpha_cg), rel=1e-12)


def test_r_h_is_angular_momentum_conservation_about_the_new_corner():
    # paper 001, Eq 13: L about the impacting corner before = after, u̇ unchanged
    s1 = multimass.column("S1")
    u = np.random.default_rng(3).normal(size=5) * 1e-3
    from multimass.model.kinematics import angular_momentum_new_pivot

    thd = -0.4
    r = r_h(s1.J_p, s1.m_t, s1.B, s1.m, u, -1)
    L_before = angular_momentum_new_pivot(s1, u, np.zeros(5), thd)
    # after: rocking about the new (left) pivot, L = (J_p + uᵀMu + 2B 1ᵀMu) θ̇⁺
    L_after = (s1.J_p + u @ (s1.m * u) + 2 * s1.B * (s1.m @ u)) * r * thd
    assert L_after == pytest.approx(L_before, rel=1e-12)


@pytest.mark.parametrize("bad", [0.0, -0.2, 1.2, math.nan])
def test_fixed_restitution_range(bad):
    with pytest.raises(ValueError, match="restitution"):
        FixedRestitution(bad)


def test_k_outside_unit_interval():
    with pytest.raises(ValueError, match="`k`"):
        modified_eta(0.2, 1.5)
    with pytest.raises(ValueError, match="`k`"):
        impact_model("CIM", specimens.load("B6M"), "modified", k=-0.1)


def _ctx(side, index=0, seed=0):
    return ImpactContext(
        multimass.column("S1"), side, np.zeros(5), index, np.random.default_rng(seed), index
    )


def test_corner_means_follow_the_impacting_corner():
    # paper 001, Table 1, S1: r_er = 0.93 (right corner), r_el = 0.87 (left)
    src = CornerRestitution(0.93, 0.87)
    assert src.value(_ctx(+1)) == 0.93 and src.value(_ctx(-1)) == 0.87


def test_empirical_then_fallback():
    src = EmpiricalRestitution((0.95, 0.91), CornerRestitution(0.93, 0.87))
    assert [src.value(_ctx(1, i)) for i in range(3)] == [0.95, 0.91, 0.93]


def test_random_restitution_is_clipped_and_seeded():
    src = RandomRestitution(0.98, 0.93, 0.2)
    s1 = multimass.column("S1")

    def draws(seed):
        rng = np.random.default_rng(seed)
        return [src.value(ImpactContext(s1, 1, np.zeros(5), i, rng, i)) for i in range(200)]

    vals = draws(5)
    assert all(0 < v <= 1.0 for v in vals) and max(vals) == 1.0  # clipped to (0, 1]
    assert vals == draws(5) and vals != draws(6)
    # closed form: E[min(X, 1)] = μ − σ (φ(z) − z (1 − Φ(z))), z = (1 − μ)/σ = 0.1 → 0.9098
    assert np.mean(vals) == pytest.approx(0.9098, abs=0.03)


@pytest.mark.parametrize("name", list(TABLE_2))
def test_table_2_configurations(name):
    # paper 001, Table 2
    model = impact_model(name, specimens.load("S1"))
    kind, rest, cp = TABLE_2[name]
    assert type(model).__name__ == {"classical": "Classical", "dirac": "DiracDelta"}[kind]
    if cp is not None:
        assert model.C_p == cp
    expected = {
        "mean": "CornerRestitution",
        "empirical": "EmpiricalRestitution",
        "random": "RandomRestitution",
    }[rest]
    assert type(model.restitution).__name__ == expected


def test_unknown_impact_name():
    with pytest.raises(ValueError, match="CIM, DD1"):
        impact_model("DD9", specimens.load("S1"))


def test_describe_is_json_ready():
    # regression: the empirical source's fallback was put in as an object
    import json

    model = impact_model("CIM", specimens.load("S1"))
    text = json.dumps(model.restitution.describe())
    assert "CornerRestitution" in text and "0.93" in text


def test_drawn_tables_follow_the_draw_and_the_corner():
    from multimass.impact_models import DrawnRestitution

    src = DrawnRestitution([0.95, 0.91], (0.85, 0.81), CornerRestitution(0.93, 0.87))
    assert src.right == (0.95, 0.91)  # stored as a tuple
    assert [src.value(_ctx(+1, i)) for i in range(3)] == [0.95, 0.91, 0.93]
    assert [src.value(_ctx(-1, i)) for i in range(3)] == [0.85, 0.81, 0.87]


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(right=(0.9,), left=()), r"`right` has 1 values and `left` 0"),
        (dict(right=(1.2,), left=(0.9,)), r"`right\[0\]` = 1.2: .*must lie in \(0, 1\]"),
        (dict(right=(0.9,), left=(True,)), r"`left\[0\]` = True: give a coefficient"),
        (dict(right="0.9", left=(0.9,)), r"`right` = '0.9': give a sequence"),
        (dict(right=(0.9,), left=(0.9,), fallback=0.9), r"`fallback` = 0.9: give a Restitution"),
    ],
)
def test_drawn_tables_are_checked(kwargs, message):
    from multimass.impact_models import DrawnRestitution

    args = dict(fallback=CornerRestitution(0.93, 0.87)) | kwargs
    with pytest.raises(ValueError, match=message):
        DrawnRestitution(**args)


def test_a_run_takes_the_drawn_values_in_order():
    # the classical model draws once per impact into a new half-cycle (paper 001, Eq 11),
    # so impact i takes entry i of its corner's table and θ̇⁺ = r θ̇⁻
    from multimass.impact_models import DrawnRestitution

    right = tuple(0.90 + 0.001 * i for i in range(6))
    left = tuple(0.80 + 0.001 * i for i in range(6))
    src = DrawnRestitution(right, left, CornerRestitution(0.93, 0.87))
    resp = multimass.simulate("S1", multimass.FreeRelease(0.08), "CIM", 2.5, restitution=src)
    impacts = [e for e in resp.events if e.kind == "impact"]
    assert len(impacts) > 6
    for i, e in enumerate(impacts):
        table = right if e.phase_after > 0 else left
        means = 0.93 if e.phase_after > 0 else 0.87  # the fallback after the tables
        assert e.restitution == (table[i] if i < 6 else means)
        assert e.thetadot_plus == pytest.approx(e.restitution * e.thetadot_minus, rel=1e-12)
