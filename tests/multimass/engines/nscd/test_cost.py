"""The cost model of a Moreau–Jean run against measurements on this machine."""

import math
import time
import tracemalloc

import pytest

from multimass.engines import nscd
from multimass.engines.nscd import cost
from multimass.engines.nscd.model import build_system


def test_assembly_memory_covers_the_measured_peak():
    # measured independently: tracemalloc's peak while assembling 96 elements (288 DOF)
    tracemalloc.start()
    build_system("B6M", theta0=0.1, dt=1e-5, n_elements=96)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    est = cost.assembly_memory(96)
    assert peak <= est <= 2.0 * peak


def test_time_estimate_is_within_an_order_of_magnitude():
    # loose on purpose: the cores are shared; the estimate guards against slips of orders
    kw = dict(theta0=math.radians(11.268), dt=1e-5, t_end=0.2, progress=False)
    nscd.simulate("B6M", n_elements=6, **kw)  # load the compiled kernel
    for n_el in (6, 48):
        res = nscd.simulate("B6M", n_elements=n_el, **kw)
        per_step = res.kernel_time_s / res.n_steps
        assert cost.step_seconds(n_el) / 10 <= per_step <= 10 * cost.step_seconds(n_el)


def test_chunks_are_about_a_quarter_second():
    assert cost.chunk_steps(6, 10) == 10  # short runs: one call
    n = cost.chunk_steps(6, 10**9)
    assert 1 <= n < 10**9 and n * cost.step_seconds(6) == pytest.approx(
        cost.CHUNK_SECONDS, rel=1e-3
    )
    assert cost.chunk_steps(1000, 10**9) >= 1


def test_estimate_of_a_slip_does_not_overflow():
    c = nscd.estimate_cost(6, 1e-300, 4.0)
    assert c.steps == pytest.approx(4e300) and c.seconds > 1e294 and math.isfinite(c.memory)


def test_setup_estimate_is_rough_but_not_absurd():
    n_el = 192
    t0 = time.perf_counter()
    build_system("B6M", theta0=0.1, dt=1e-5, n_elements=n_el)
    wall = time.perf_counter() - t0
    assert cost.setup_seconds(n_el) / 20 <= wall <= 20 * cost.setup_seconds(n_el)
