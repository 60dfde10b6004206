"""The compiled time loop against the readable NumPy reference step (same maths,
independent code: whole-system matrices, numpy.roots, explicit W = Q B Q^T)."""

import numpy as np
import pytest

from multimass.engines import nscd
from multimass.engines.nscd.model import build_system
from multimass.engines.nscd.reference import reference_run
from multimass.engines.nscd.run import run_system


@pytest.mark.parametrize(
    "theta0, flex, theta_method, mu",
    [
        (0.003, None, 1.0, 0.364),  # rigid base, one impact at ~0.02 s
        (-0.003, None, 1.0, 0.364),  # on the left corner
        (0.003, 10.0, 1.0, 0.364),  # flexible beam E = 10 Ebar: bouncing contacts
        (0.003, 10.0, 0.5, 0.364),  # trapezoidal theta-method
        (0.003, 10.0, 1.0, 0.02),  # sliding
    ],
)
def test_kernel_matches_reference(theta0, flex, theta_method, mu):
    E = None if flex is None else flex * nscd.flexible_modulus("B6M")
    sys = build_system("B6M", theta0=theta0, dt=1e-4, E=E, theta_method=theta_method, mu=mu)
    n = 300
    q, v = reference_run(sys, n)
    res = run_system(sys, n * sys.dt)
    qk, vk, qe, ve = res.final_state
    assert res.n_steps == n and len(res.impact_times) >= 1
    assert res.n_multi_contact_steps >= 1  # Gauss-Seidel over two contacts ran
    if mu < 0.1:
        assert res.n_slip_steps > 0
    assert qk == pytest.approx(q[:3], rel=1e-9, abs=1e-13)
    assert vk == pytest.approx(v[:3], rel=1e-8, abs=1e-11)
    assert np.max(np.abs(qe - q[3:])) <= 1e-8 * np.max(np.abs(q[3:]))
    assert np.max(np.abs(ve - v[3:])) <= 1e-7 * np.max(np.abs(v[3:])) + 1e-12
