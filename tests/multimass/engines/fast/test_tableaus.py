"""The written-out Butcher tableaus of the compiled path (`multimass.engines.fast._tableaus`).

References: SciPy's own arrays (``scipy.integrate._ivp.rk`` and
``scipy.integrate._ivp.dop853_coefficients``, which the solve_ivp path steps with: the
two paths must use the same floats), and the order conditions of Hairer, Nørsett &
Wanner, *Solving ODEs I*, Sec. II.2 (an independent check of the published values).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate._ivp import dop853_coefficients as dop
from scipy.integrate._ivp.rk import RK23, RK45

from multimass.engines.fast import _rk
from multimass.engines.fast import _tableaus as tab

# (ours, SciPy's) for every array
PAIRS = {
    "RK23_A": (tab.RK23_A, RK23.A),
    "RK23_B": (tab.RK23_B, RK23.B),
    "RK23_C": (tab.RK23_C, RK23.C),
    "RK23_E": (tab.RK23_E, RK23.E),
    "RK23_P": (tab.RK23_P, RK23.P),
    "RK45_A": (tab.RK45_A, RK45.A),
    "RK45_B": (tab.RK45_B, RK45.B),
    "RK45_C": (tab.RK45_C, RK45.C),
    "RK45_E": (tab.RK45_E, RK45.E),
    "RK45_P": (tab.RK45_P, RK45.P),
    "DOP853_A": (tab.DOP853_A, dop.A),
    "DOP853_B": (tab.DOP853_B, dop.B),
    "DOP853_C": (tab.DOP853_C, dop.C),
    "DOP853_E3": (tab.DOP853_E3, dop.E3),
    "DOP853_E5": (tab.DOP853_E5, dop.E5),
    "DOP853_D": (tab.DOP853_D, dop.D),
}


@pytest.mark.parametrize("name", PAIRS)
def test_every_entry_is_scipys_float_bit_for_bit(name):
    ours, scipys = PAIRS[name]
    scipys = np.asarray(scipys, dtype=np.float64)
    assert ours.dtype == np.float64 and ours.flags.c_contiguous
    assert ours.shape == scipys.shape
    assert np.array_equal(ours.view(np.int64), scipys.view(np.int64))  # -0.0 ≠ 0.0 too


def test_stage_counts_are_scipys():
    assert (tab.DOP853_N_STAGES, tab.DOP853_N_STAGES_EXTENDED) == (
        dop.N_STAGES,
        dop.N_STAGES_EXTENDED,
    )


def test_the_kernels_step_with_these_arrays():
    assert _rk._A8 is tab.DOP853_A and _rk._D8 is tab.DOP853_D and _rk._E8_3 is tab.DOP853_E3
    assert _rk._A5 is tab.RK45_A and _rk._P3 is tab.RK23_P


@pytest.mark.parametrize(
    "A, B, C, order",
    [
        (tab.RK23_A, tab.RK23_B, tab.RK23_C, 3),
        (tab.RK45_A, tab.RK45_B, tab.RK45_C, 5),
        (
            tab.DOP853_A[: tab.DOP853_N_STAGES, : tab.DOP853_N_STAGES],
            tab.DOP853_B,
            tab.DOP853_C[: tab.DOP853_N_STAGES],
            8,
        ),
    ],
    ids=["RK23", "RK45", "DOP853"],
)
def test_published_values_meet_the_order_conditions(A, B, C, order):
    # HNW I, Sec. II.2: c_i = Σ_j a_ij; quadrature conditions Σ b_i c_i^(k-1) = 1/k,
    # k = 1 … order; and Σ b_i a_ij c_j = 1/6 (the tree of order 3)
    np.testing.assert_allclose(A.sum(axis=1), C, atol=1e-15)
    for k in range(1, order + 1):
        assert B @ C ** (k - 1) == pytest.approx(1.0 / k, abs=1e-14)
    assert B @ A @ C[: A.shape[1]] == pytest.approx(1.0 / 6.0, abs=1e-14)  # A: s × (s-1) or s × s


@pytest.mark.parametrize("E", [tab.RK23_E, tab.RK45_E, tab.DOP853_E3, tab.DOP853_E5])
def test_error_weights_sum_to_zero(E):
    # E is the difference of two consistent weight vectors (Σ b = Σ b̂ = 1)
    assert E.sum() == pytest.approx(0.0, abs=1e-14)


def test_a_changed_tableau_drops_the_cached_kernels():
    # numba freezes the arrays into the machine code and keys its cache on the file of
    # each function only: the groups' fingerprints must cover the tableaus' file
    from pathlib import Path

    from multimass.engines.fast import block_runs
    from multimass.engines.fast import compile as fc

    here = Path(tab.__file__).resolve()
    for sources in (block_runs._sources(), fc._sources(), fc._sources(contact=True)):
        assert here in {Path(p).resolve() for p in sources}
