"""Closest point on the deformed beam (paper 002, Eqs 59-63): the compiled search
against the NumPy reference (numpy.roots on every element) and closed forms."""

import math

import numpy as np
import pytest

from multimass.engines.nscd.geometry import closest_point, contact_frame
from multimass.engines.nscd.model import build_system
from multimass.engines.nscd.reference import closest_point_roots


@pytest.fixture(scope="module")
def system():
    return build_system("B6M", theta0=0.1, dt=1e-4, E=1e11, n_elements=6)


def _distance(sys, qe, e, s, d):
    N = np.zeros(6)
    cpsi, spsi, gap = contact_frame(
        N, qe, sys.beam.edof, sys.beam.x_nodes, sys.beam.Le, e, s, d[0], d[1]
    )
    return abs(gap), (cpsi, spsi, gap)


def test_flat_beam_is_the_vertical_projection(system):
    qe = np.zeros(system.beam.n_dof)
    bm = system.beam
    for dx, dy in [(0.137, 0.004), (0.15, -0.002), (0.2001, 0.01), (0.01, 0.0)]:
        e, s = closest_point(qe, bm.edof, bm.x_nodes, bm.Le, dx, dy)
        assert bm.x_nodes[e] + s == pytest.approx(dx, abs=1e-14)
        _, (cpsi, spsi, gap) = _distance(system, qe, e, s, (dx, dy))
        # closed form: flat beam, n = (0, 1) (psi = pi/2, Eq 63), gap = dy
        assert (cpsi, spsi) == pytest.approx((0.0, 1.0), abs=1e-15)
        assert gap == pytest.approx(dy, abs=1e-15)


def test_search_moves_to_the_neighbouring_element(system):
    bm = system.beam
    # a tilted straight beam v = k x (rotations k at every node): the nearest point of a
    # vertex above x = 0.1499 lies to its left, in the previous element when it is close
    # to the node at 0.1 ... here the vertex is above element 2 but its foot is in element 1
    k = 0.2
    qe = np.zeros(bm.n_dof)
    for e in range(bm.n_elements):
        for a, val in ((1, k * bm.x_nodes[e]), (2, k), (4, k * bm.x_nodes[e + 1]), (5, k)):
            if bm.edof[e, a] >= 0:
                qe[bm.edof[e, a]] = val
    d = (0.101, 0.1)
    e, s = closest_point(qe, bm.edof, bm.x_nodes, bm.Le, *d)
    # closed form: foot of the perpendicular to the line y = k x
    x_foot = (d[0] + k * d[1]) / (1 + k * k)
    assert e == 2 and bm.x_nodes[e] + s == pytest.approx(x_foot, abs=1e-12)
    d = (0.149, 0.1)  # foot at 0.1673..., one element to the right
    e, s = closest_point(qe, bm.edof, bm.x_nodes, bm.Le, *d)
    assert e == 3 and bm.x_nodes[e] + s == pytest.approx((d[0] + k * d[1]) / (1 + k * k), abs=1e-12)


@pytest.mark.parametrize("amplitude", [1e-4, 3e-3, 1e-2])
def test_compiled_search_matches_numpy_roots(system, amplitude):
    rng = np.random.default_rng(20240725)
    bm = system.beam
    for _ in range(60):
        qe = np.zeros(bm.n_dof)
        for e in range(bm.n_elements):
            for a, scale in (
                (1, amplitude),
                (2, amplitude / bm.Le),
                (4, amplitude),
                (5, amplitude / bm.Le),
            ):
                if bm.edof[e, a] >= 0:
                    qe[bm.edof[e, a]] = rng.uniform(-scale, scale)
        d = np.array([rng.uniform(0.0, bm.L), rng.uniform(-2 * amplitude, 2 * amplitude)])
        e, s = closest_point(qe, bm.edof, bm.x_nodes, bm.Le, *d)
        e_ref, s_ref = closest_point_roots(system, qe, d)
        f, _ = _distance(system, qe, e, s, d)
        f_ref, _ = _distance(system, qe, e_ref, s_ref, d)
        assert f == pytest.approx(f_ref, rel=1e-9, abs=1e-15)


def test_gap_sign_and_normal_on_a_slope(system):
    bm = system.beam
    qe = np.zeros(bm.n_dof)
    k = 0.05
    for e in range(bm.n_elements):
        for a, val in ((1, k * bm.x_nodes[e]), (2, k), (4, k * bm.x_nodes[e + 1]), (5, k)):
            if bm.edof[e, a] >= 0:
                qe[bm.edof[e, a]] = val
    d = (0.12, k * 0.12 - 1e-3)  # 1 mm below the line: overlap
    e, s = closest_point(qe, bm.edof, bm.x_nodes, bm.Le, *d)
    _, (cpsi, spsi, gap) = _distance(system, qe, e, s, d)
    # closed form: psi = atan(k) + pi/2 (Eq 63); distance to the line = 1e-3 cos(atan k)
    assert (cpsi, spsi) == pytest.approx(
        (math.cos(math.atan(k) + math.pi / 2), math.sin(math.atan(k) + math.pi / 2)), abs=1e-14
    )
    assert gap == pytest.approx(-1e-3 / math.sqrt(1 + k * k), rel=1e-10)
