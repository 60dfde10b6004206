"""The simulation behind `multimass.identify.synthetic_trace`: its impact model, with
restitution tables drawn long enough, on the compiled backend where it can."""

from __future__ import annotations

import dataclasses

import numpy as np

from multimass.impact_models import (
    Classical,
    CornerRestitution,
    DiracDelta,
    DrawnRestitution,
    impact_model,
)

from .. import validation as v
from ..errors import InputError, SolverError
from ..simulation import simulate
from ._synthetic_setup import draw_table

__all__ = ["OWN_OPTIONS", "check_options", "model_of", "run"]

#: Options of `simulate` that `synthetic_trace` sets itself.
OWN_OPTIONS = ("output_dt", "restitution", "seed", "k", "eps_p", "C_p")
_COMPILED_METHODS = ("RK23", "RK45", "DOP853")


def check_options(options: dict) -> None:
    """Refuse the options of `simulate` that `synthetic_trace` sets itself."""
    for key in OWN_OPTIONS:
        if key in options:
            fix = (
                "give it as the `C_p` argument"
                if key == "C_p"
                else "give the restitution through `restitution_means` and `restitution_spread`"
                if key in ("restitution", "k", "eps_p")
                else "remove it"
            )
            raise InputError(f"`{key}` is set by synthetic_trace; {fix}")


def model_of(st, impact, C_p, source):
    """The impact model `impact` with the restitution `source`; only models that use one."""
    if C_p is not None:
        C_p = v.positive("C_p", C_p, "kg m/rad/s, of a Dirac-delta model")
    if isinstance(impact, str):
        model = impact_model(impact, st.specimen, restitution=source, C_p=C_p)
        if C_p is not None and not isinstance(model, DiracDelta):
            raise InputError(
                f"`C_p` = {C_p!r}: applies to the Dirac-delta models (DD, DD1 … DD5), "
                f"not to impact = {impact!r}; remove it"
            )
    elif isinstance(impact, (Classical, DiracDelta)):
        if C_p is not None:
            raise InputError(
                f"`C_p` = {C_p!r}: applies to a model given by name; set C_p in the "
                f"{type(impact).__name__} object instead"
            )
        model = dataclasses.replace(impact, restitution=source)
    else:
        model = impact_model(impact, st.specimen)  # raises for what is not a model
    if not isinstance(model, (Classical, DiracDelta)):
        raise InputError(
            f"`impact` = {getattr(model, 'name', impact)!r} draws no coefficient of "
            "restitution; use CIM, DD1 … DD5, DD or a Classical / DiracDelta object"
        )
    return model


def run(st, excitation, model, means, spread, stream, grid, cfg, options):
    """(response, model, tables): the simulation with restitution tables long enough for
    every draw of the run (at most 1 + uplifts + impacts)."""
    n = 256
    while True:
        rng = np.random.default_rng(stream)
        tables = tuple(draw_table(rng, m, spread, n) for m in means)
        source = DrawnRestitution(tuple(tables[0]), tuple(tables[1]), CornerRestitution(*means))
        model = dataclasses.replace(model, restitution=source)
        response = _simulate(st, excitation, model, grid.t_simulated, cfg, options)
        draws = 1 + sum(e.kind in ("uplift", "impact") for e in response.events)
        if draws <= n:
            return response, model, tables
        n *= 4


def _simulate(st, excitation, model, t_end: float, cfg, options: dict):
    """`simulate` at the high rate, compiled where the kernels know the model and motion."""
    kw = {"progress": None} | options  # a bar only for a run estimated at seconds or more
    kw.setdefault("backend", _backend(model, excitation, kw))
    response = simulate(
        st, excitation, model, t_end, output_dt=1.0 / cfg.fs_in, seed=cfg.seed, **kw
    )
    if response.status == "failed":
        raise SolverError(f"the simulation of the synthetic trace failed: {response.message}")
    if response.outcome == "overturned":
        t_over = next((e.time for e in response.events if e.kind == "overturn"), response.t[-1])
        raise InputError(
            f"`excitation`: {st.name} overturned at t = {t_over:.4g} s; a synthetic "
            "trace needs a test it survives: lower the excitation"
        )
    if response.t.size < 2 or response.t[-1] < t_end - 1e-9:
        raise SolverError(
            f"the simulation of the synthetic trace stopped at t = {response.t[-1]:.6g} s "
            f"before {t_end:.6g} s ({response.message})"
        )
    return response


def _backend(model, excitation, kw: dict) -> str:
    """ "compiled" if its kernels know `model` and `excitation` (and the method), else "scipy"."""
    method = kw.get("method", "DOP853")
    if kw.get("integrator", "solve_ivp") != "solve_ivp" or method not in _COMPILED_METHODS:
        return "scipy"
    from ..engines.fast import check_model, encode

    try:
        check_model(model)
        encode(excitation)
    except InputError:
        return "scipy"
    return "compiled"
