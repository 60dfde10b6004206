"""The compiled loop runs in chunks (for progress and Ctrl-C) without changing one bit."""

import importlib
import math

import numpy as np
import pytest

from multimass.engines import nscd

engine = importlib.import_module("multimass.engines.nscd.run")
FIELDS = (
    "t",
    "theta",
    "thetadot",
    "X",
    "Y",
    "v_mid",
    "energy",
    "n_contacts",
    "peaks",
    "peak_times",
    "impact_times",
)


def _run(monkeypatch, chunk, **kw):
    monkeypatch.setattr(engine.cost, "chunk_steps", lambda n_el, n_steps: chunk or n_steps)
    return nscd.simulate("B6M", progress=False, **kw)


@pytest.mark.parametrize(
    "kw",
    [
        # flexible beam, low friction: two-contact steps, sliding, Gauss–Seidel warm starts and cap
        # hits carried across chunk boundaries; a record stride of 7 that chunks of 997 cut anywhere
        dict(
            theta0=math.radians(11.268),
            dt=1e-4,
            t_end=1.0,
            mu=0.02,
            record_every=7,
            E=10 * nscd.flexible_modulus("B6M"),
        ),
        # rigid base, left corner, Newton restitution
        dict(theta0=-0.15, dt=1e-4, t_end=1.5, restitution=0.3),
        # diverges (explicit theta-method on a stiff beam): the stop is found in whichever chunk
        dict(theta0=0.1, dt=1e-4, t_end=0.05, theta_method=0.0),
    ],
)
def test_chunked_run_equals_one_call_bit_for_bit(monkeypatch, kw):
    one = _run(monkeypatch, None, **kw)
    for chunk in (1, 7, 997):
        many = _run(monkeypatch, chunk, **kw)
        for f in FIELDS:
            assert np.array_equal(getattr(one, f), getattr(many, f)), (chunk, f)
        for a, b in zip(one.final_state, many.final_state):
            assert np.array_equal(a, b)
        assert one.events_frame().equals(many.events_frame()), chunk  # NaN where NaN
        for f in (
            "rest_time",
            "n_steps",
            "status",
            "outcome",
            "max_gs_iterations",
            "n_gs_cap_hits",
            "max_gs_residual",
            "n_multi_contact_steps",
            "n_slip_steps",
            "max_slip_speed",
            "max_energy_increase",
            "energy_scale",
            "max_penetration",
        ):
            assert getattr(one, f) == getattr(many, f), (chunk, f)
    if kw.get("mu") == 0.02:  # the case exercises what it claims to
        assert one.n_multi_contact_steps > 0 and one.n_slip_steps > 0 and one.n_gs_cap_hits > 0
