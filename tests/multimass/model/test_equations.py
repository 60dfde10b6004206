"""One source for each equation: `multimass.model.equations` and
`multimass.impact_models.gaussian_force` are the only implementations of paper 001's
Eqs 3–8 and 14–17, and both the solve_ivp path and the compiled path run them.

References: the papers' equation numbers (paper 001, Sec 2); the hand-computed
one-node values of Eqs 3 and 8 live in `test_transitions.py`, the symbolic
derivation of Eqs 4–5 in `test_eom_symbolic.py`, the two paths' agreement in
`test_fast.py`.
"""

import re
from pathlib import Path

import numpy as np
import pytest

from multimass.impact_models import gaussian_force as gf
from multimass.model import equations as eq

ROOT = Path(__file__).resolve().parents[3]
SOURCES = [
    p
    for folder in ("multimass", "impact_models", "modal", "specimens")
    for p in (ROOT / folder).rglob("*.py")
    if not p.is_symlink() and ".ipynb" not in p.name
]


def _files_citing(paper: str, number: int) -> set[str]:
    pattern = re.compile(rf"#.*paper {paper}, Eq {number}\b")
    return {
        str(p.relative_to(ROOT))
        for p in SOURCES
        if any(pattern.search(line) for line in p.read_text(encoding="utf-8").splitlines())
    }


@pytest.mark.parametrize(
    "number, home",
    [
        (3, "multimass/model/equations.py"),
        (4, "multimass/model/equations.py"),
        (5, "multimass/model/equations.py"),
        (7, "multimass/model/equations.py"),
        (8, "multimass/model/equations.py"),
        (9, "impact_models/models.py"),
        (10, "impact_models/models.py"),
        (11, "impact_models/models.py"),
        (12, "impact_models/models.py"),
        (13, "impact_models/restitution.py"),
        (14, "impact_models/gaussian_force.py"),
        (15, "impact_models/gaussian_force.py"),
        (16, "impact_models/gaussian_force.py"),
        (17, "impact_models/gaussian_force.py"),
    ],
)
def test_each_equation_of_paper_001_has_one_home(number, home):
    # a grep for the equation's comment lands on its one implementation
    assert _files_citing("001", number) == {home}


def test_the_folders_are_read_once():
    # the design card's folders enter the package through symbolic links; reading them
    # twice would hide a second copy behind the first
    names = [str(p.relative_to(ROOT)) for p in SOURCES]
    assert len(names) == len(set(names)) and "multimass/model/equations.py" in names
    assert not any(n.startswith("multimass/modal/") for n in names)


def _calls(paths: list[str], name: str) -> bool:
    text = "".join((ROOT / p).read_text(encoding="utf-8") for p in paths)
    return re.search(rf"\b{name}\(", text) is not None


COMPILED = [
    "multimass/engines/fast/_maths.py",
    "multimass/engines/fast/_kernel.py",
    "multimass/engines/fast/_block_kernel.py",
    "multimass/engines/fast/_column_kernel.py",
]
REFERENCE = [
    "multimass/engines/_run.py",
    "multimass/model/_phase.py",
    "multimass/engines/_events.py",
    "multimass/model/kinematics.py",
    "multimass/model/eom.py",
    "multimass/engines/_recorder.py",
    "impact_models/models.py",
]
# computed outside the kernels on both paths: the recorder's Eq 7 accelerations, and the
# release angle of Eq 17 (DiracDelta.release_angle, passed to the kernel as a limit)
BOTH_OUTSIDE = {"total_acceleration", "deactivation_angle"}


@pytest.mark.parametrize("name", eq.__all__ + gf.__all__)
def test_both_paths_call_the_one_source(name):
    text = (ROOT / "multimass/engines/fast/_maths.py").read_text(encoding="utf-8")
    assert f"def {name}(" not in text  # registered (numba register_jitable), not redefined
    assert _calls(REFERENCE, name), name
    assert _calls(COMPILED, name) or name in BOTH_OUTSIDE, name


def test_the_equations_run_on_arrays_as_on_scalars():
    # the same source serves one state (scalars, compiled) and many (arrays, recorder)
    rng = np.random.default_rng(3)
    thd, cud, ku, m, ag, th = rng.normal(size=(6, 5))
    c, sn = np.cos(th), np.sin(th)
    arm = eq.pivot_arm(1.0, 0.3, m, ku)
    rows = eq.rocking_forcing_u(arm, thd, cud, ku, m, ag, c, sn, 9.81)
    one = [
        eq.rocking_forcing_u(arm[i], thd[i], cud[i], ku[i], m[i], ag[i], c[i], sn[i], 9.81)
        for i in range(5)
    ]
    np.testing.assert_array_equal(rows, one)
    F = gf.impact_force(th, 1.0, 2.0, 0.8, 0.01, 0.3)
    np.testing.assert_array_equal(F, [gf.impact_force(x, 1.0, 2.0, 0.8, 0.01, 0.3) for x in th])


@pytest.mark.parametrize("alpha", [0.05, 0.25, 1.2])
def test_free_rocking_peak_solves_the_energy_balance(alpha):
    # m g R [cos(α − φ) − cos α] = E, with q = E / (m g R (1 − cos α)), solved by brentq
    # (its residual carries ~1e-16 of cancellation: φ to ~1e-14 absolute)
    from scipy.optimize import brentq

    def residual(x, q):
        return np.cos(alpha - x) - np.cos(alpha) - q * (1.0 - np.cos(alpha))

    assert eq.free_rocking_peak(alpha, 0.0) == 0.0  # no energy: no swing
    assert eq.free_rocking_peak(alpha, 1.0) == pytest.approx(alpha, rel=1e-15)  # up to α
    assert eq.free_rocking_peak(alpha, -1e-3) == 0.0  # clipped to [0, 1]
    assert eq.free_rocking_peak(alpha, 2.0) == pytest.approx(alpha, rel=1e-15)
    for q in (1e-9, 1e-4, 0.3, 0.5, 0.9, 1.0 - 1e-9):
        phi = brentq(residual, 0.0, alpha, args=(q,), xtol=1e-16, rtol=1e-15)
        assert eq.free_rocking_peak(alpha, q) == pytest.approx(phi, rel=1e-9, abs=1e-14), q
