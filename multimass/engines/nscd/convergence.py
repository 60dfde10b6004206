"""Convergence studies of the Moreau–Jean simulation (paper 002, Sections 6.1 and
6.3, Figs 10–11 and 16–19): a block run at successive refinements of the time
step or the mesh, each judged by `nscd.verdicts`.

Every study validates all its runs and estimates their total cost before the
first starts: levels must be distinct, positive and (for the verdicts) share
one refinement ratio; the study is refused if it would exceed its budget
(``max_hours``, one hour by default, for the whole study). Each run then shows
its own progress bar when it is estimated above a few seconds, and
``report(line)`` is called after each.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

import numpy as np

from multimass.errors import InputError
from multimass.progress import (
    PROGRESS_AFTER_S,
    RunCost,
    budget_seconds,
    format_duration,
)
from multimass.validation import positive

from .model import (
    check_elements,
    check_exponent,
    check_inputs,
    flexible_modulus,
    load_block,
)
from .result import NSCDResult
from .run import REST_FRACTION, check_run, estimate_cost, execute
from .verdicts import (
    MIN_ORDER,
    TOLERANCES,
    Study,
    Verdict,
    compare_runs,
    housner_first_peak,
    judge,
)

__all__ = [
    "Verdict",
    "Study",
    "FirstPeakStudy",
    "judge",
    "compare_runs",
    "housner_first_peak",
    "dt_study",
    "mesh_study",
    "first_peak_study",
    "flexibility_study",
    "check_levels",
    "TOLERANCES",
    "MIN_ORDER",
]


def _theta0(block, theta0):
    blk = load_block(block)
    if theta0 is not None:
        return theta0
    if blk.reference.theta0_deg is None:
        raise InputError(
            f"`theta0` is required: block {blk.name!r} has no reference "
            "theta0_deg; give the release angle in rad"
        )
    return math.radians(blk.reference.theta0_deg)


def check_levels(
    name: str, values, *, kind: str, min_levels: int = 2, geometric: bool = True
) -> tuple:
    """Refinement levels, validated and sorted coarse → fine.

    Parameters
    ----------
    name : str
        The argument named in messages (e.g. ``"dts"`` or ``"--meshes"``).
    values : sequence
        Time steps (s) for ``kind="dt"``, element counts for ``kind="mesh"``.
    min_levels : int
        Fewest levels (a verdict compares at least two).
    geometric : bool
        Require a constant refinement ratio (within 1 %): the verdicts compare
        successive differences, whose expected ratio is ratio^(−order).

    Raises
    ------
    InputError
        Not a list, too few levels, a level not a positive finite number (a
        whole number in 3..`MAX_ELEMENTS` for meshes), repeated levels, or
        levels without a constant ratio.
    """
    if isinstance(values, (str, bytes)) or not hasattr(values, "__len__"):
        raise InputError(
            f"`{name}` = {values!r}: give a list of levels, e.g. "
            + ("1e-3 1e-4 1e-5" if kind == "dt" else "3 6 12")
        )
    if kind == "dt":
        levels = [positive(f"{name}[{i}]", v, "a time step in s") for i, v in enumerate(values)]
    else:
        levels = [check_elements(v, f"{name}[{i}]") for i, v in enumerate(values)]
    if len(levels) < min_levels:
        raise InputError(
            f"`{name}` = {list(values)!r}: give at least {min_levels} levels "
            "(a study compares successive refinements)"
        )
    if len(set(levels)) != len(levels):
        raise InputError(f"`{name}` = {list(values)!r}: a level is repeated; give distinct levels")
    levels = sorted(levels, reverse=(kind == "dt"))
    ratios = [a / b if kind == "dt" else b / a for a, b in zip(levels[:-1], levels[1:])]
    if geometric and any(abs(r / ratios[0] - 1.0) > 0.01 for r in ratios):
        raise InputError(
            f"`{name}` = {list(values)!r}: the refinement ratios "
            f"{', '.join(f'{r:.3g}' for r in ratios)} differ; the verdicts compare "
            "successive differences and need one ratio, e.g. "
            + (
                "1e-3 1e-4 1e-5 (10) or 4e-4 2e-4 1e-4 (2)"
                if kind == "dt"
                else "3 6 12 or 6 12 24 (2)"
            )
        )
    return tuple(levels)


def _ratio(kind: str, levels) -> float:
    return levels[0] / levels[1] if kind == "dt" else levels[1] / levels[0]


@dataclass(frozen=True)
class _Plan:
    """One validated run of a study: its label, inputs, options and estimated cost."""

    label: str
    inp: object
    opts: object
    seconds: float
    memory: float


def _plan(
    label,
    block,
    *,
    theta0,
    dt,
    t_end,
    E,
    n_elements,
    beam="beam_mudric2024",
    theta_method=1.0,
    mu=None,
    restitution=0.0,
    x_centre=None,
    gs_tol=1e-8,
    gs_max_iter=5000,
    record_every=None,
    rest_fraction=REST_FRACTION,
    names=None,
) -> _Plan:
    """Validate one run and estimate its cost, before any run of the study starts."""
    inp = check_inputs(
        block,
        beam,
        theta0=theta0,
        dt=dt,
        E=E,
        n_elements=n_elements,
        theta_method=theta_method,
        mu=mu,
        restitution=restitution,
        x_centre=x_centre,
        names=names,
    )
    o = check_run(
        t_end,
        inp.dt,
        gs_tol=gs_tol,
        gs_max_iter=gs_max_iter,
        record_every=record_every,
        rest_fraction=rest_fraction,
        names=names,
    )
    c = estimate_cost(inp.n_elements, inp.dt, o.t_end, o.stride)
    return _Plan(label, inp, o, c.seconds, c.memory)


def _execute(plans: list[_Plan], what: str, *, report, progress, max_hours) -> list[NSCDResult]:
    """Check the total cost of `plans` against the budget, then run them in order.

    Each run shows its own progress bar (automatic: when it is estimated above a
    few seconds); `report(line)` is called after each run.
    """
    if progress is not None and not isinstance(progress, bool):
        raise InputError(f"`progress` = {progress!r}: expected True, False or None")
    total = sum(p.seconds for p in plans)
    RunCost(
        float(sum(p.opts.n_steps for p in plans)),
        total,
        max(p.memory for p in plans),
        f"{len(plans)} runs, the longest {format_duration(max(p.seconds for p in plans))}",
    ).check(
        what,
        "use fewer or coarser levels, or a shorter t_end",
        max_seconds=budget_seconds(max_hours),
    )
    if progress or (progress is None and total >= PROGRESS_AFTER_S):
        print(f"{what}: {len(plans)} runs, estimated {format_duration(total)}", file=sys.stderr)
    runs = []
    for k, p in enumerate(plans, 1):
        runs.append(
            execute(
                p.inp,
                p.opts,
                progress=progress,
                estimated=p.seconds,
                desc=f"{p.inp.block.name} {p.label} ({k}/{len(plans)})",
            )
        )
        if report:
            r = runs[-1]
            note = "" if r.status in _NORMAL else f": {r.status}"
            report(f"{p.inp.block.name} {p.label} done ({r.wall_time_s:.1f} s){note}")
    return runs


_NORMAL = ("completed", "overturned")


def _study(kind, block, levels, plans, what, settings, report, progress, max_hours) -> Study:
    runs = _execute(plans, what, report=report, progress=progress, max_hours=max_hours)
    return Study(
        kind,
        load_block(block).name,
        tuple(levels),
        tuple(runs),
        tuple(compare_runs(levels, runs, _ratio(kind, levels))),
        {"E_Pa": runs[0].params["E"], **settings},
    )


def dt_study(
    block,
    dts=(1e-3, 1e-4, 1e-5, 1e-6),
    *,
    E=None,
    n_elements=6,
    t_end=4.0,
    theta0=None,
    report=None,
    progress=None,
    max_hours=None,
    names=None,
    **kw,
) -> Study:
    """Time-step refinement (paper 002, Fig 10; dt from 1e-3 to 1e-6 s).

    `dts` (≥ 2 distinct positive steps with one refinement ratio) are sorted
    coarse → fine. All runs are validated and their total cost estimated
    before the first starts; `max_hours` is the budget of the whole study.
    `report(line)` is called after each run; `progress` as in `simulate`;
    `kw` are further arguments of `simulate` (beam, theta_method, mu, ...).
    """
    dts = check_levels(_name(names, "dts"), dts, kind="dt")
    th0 = _theta0(block, theta0)
    plans = [
        _plan(
            f"dt = {dt:g} s",
            block,
            theta0=th0,
            dt=dt,
            t_end=t_end,
            E=E,
            n_elements=n_elements,
            names=names,
            **kw,
        )
        for dt in dts
    ]
    return _study(
        "dt",
        block,
        dts,
        plans,
        f"dt study of {load_block(block).name}",
        {
            "n_elements": plans[0].inp.n_elements,
            "t_end_s": plans[0].opts.t_end,
            "theta0": plans[0].inp.theta0,
            "theta0_deg": math.degrees(plans[0].inp.theta0),
        },
        report,
        progress,
        max_hours,
    )


def mesh_study(
    block,
    meshes=(3, 6, 12),
    *,
    dt=1e-5,
    E=None,
    t_end=4.0,
    theta0=None,
    report=None,
    progress=None,
    max_hours=None,
    names=None,
    **kw,
) -> Study:
    """Mesh refinement (paper 002, Fig 11: 3, 6 and 12 elements); see `dt_study`."""
    meshes = check_levels(_name(names, "meshes"), meshes, kind="mesh")
    th0 = _theta0(block, theta0)
    plans = [
        _plan(
            f"{n} elements",
            block,
            theta0=th0,
            dt=dt,
            t_end=t_end,
            E=E,
            n_elements=n,
            names=names,
            **kw,
        )
        for n in meshes
    ]
    return _study(
        "mesh",
        block,
        meshes,
        plans,
        f"mesh study of {load_block(block).name}",
        {
            "dt_s": plans[0].inp.dt,
            "t_end_s": plans[0].opts.t_end,
            "theta0": plans[0].inp.theta0,
            "theta0_deg": math.degrees(plans[0].inp.theta0),
        },
        report,
        progress,
        max_hours,
    )


def _name(names, key):
    return (names or {}).get(key, key)


@dataclass(frozen=True)
class FirstPeakStudy:
    """First post-impact peak against the exact Housner value as dt → 0.

    A table for reading, as paper 002 gives it: angles in degrees (the names
    end with ``_deg``), block name → one value per dt (None where a run had no
    first peak); the runs' own `NSCDResult.first_peak` is in radians.
    """

    blocks: tuple[str, ...]
    dts: tuple[float, ...]
    exact_deg: dict
    paper_deg: dict
    peaks_deg: dict
    errors_deg: dict
    fitted_order: dict
    successive_order: dict
    warnings: tuple = ()

    def to_dict(self) -> dict:
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in self.__dict__.items()}


def _run_warnings(labels, runs) -> list[str]:
    """Warnings of a first-peak study's runs: failed or inaccurate runs, missing peaks."""
    out = []
    for label, r in zip(labels, runs):
        if r.outcome == "failed":
            out.append(f"{label}: the run failed: {r.message}")
        out += [f"{label}: {w}" for w in r.warnings]
        if r.first_peak is None and r.outcome != "failed":
            out.append(
                f"{label}: no first peak ({r.outcome} before a half-cycle closed); extend t_end"
            )
    return out


def _blocks(blocks, name: str) -> tuple:
    if isinstance(blocks, str) or not hasattr(blocks, "__len__"):
        blocks = (blocks,)
    if len(blocks) == 0:
        raise InputError(f"`{name}` = {blocks!r}: give at least one block, e.g. B6M")
    return tuple(load_block(b) for b in blocks)


def _orders(dts, err) -> tuple[float | None, list]:
    """Least-squares slope of log|error| on log dt, and the orders between decades."""
    ok = [(math.log(d), math.log(e)) for d, e in zip(dts, err) if e is not None and e > 0]
    fit = float(np.polyfit(*zip(*ok), 1)[0]) if len(ok) >= 2 else None
    decades = [i for i, d in enumerate(dts) if abs(math.log10(d) - round(math.log10(d))) < 1e-9]
    succ = [
        math.log10(err[i] / err[j]) / math.log10(dts[i] / dts[j]) if err[i] and err[j] else None
        for i, j in zip(decades[:-1], decades[1:])
    ]
    return fit, succ


def first_peak_study(
    blocks=("B4M", "B6M", "B8M"),
    dts=None,
    *,
    t_end=2.0,
    E=None,
    n_elements=6,
    report=None,
    progress=None,
    max_hours=None,
    names=None,
    **kw,
) -> FirstPeakStudy:
    """First peak of each block for dt → 0 against the exact rigid-block value.

    The observed order is the least-squares slope of log|error| against
    log dt (the error of one impact in an event-capturing scheme depends on
    where the impact falls inside a step, so successive ratios scatter);
    successive orders between decades are given too. `dts` needs at least two
    distinct steps (any spacing); a run without a first peak (still in its
    first half-cycle at t_end, or overturned) has no error and is left out
    of the fit, with a warning. `kw` are further arguments of `simulate`.
    """
    blks = _blocks(blocks, _name(names, "blocks"))
    if dts is None:
        dts = (1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6, 1e-6)
    dts = check_levels(_name(names, "dts"), dts, kind="dt", geometric=False)
    plans = [
        _plan(
            f"dt = {dt:g} s",
            blk,
            theta0=_theta0(blk, None),
            dt=dt,
            t_end=t_end,
            E=E,
            n_elements=n_elements,
            names=names,
            **kw,
        )
        for blk in blks
        for dt in dts
    ]
    runs = _execute(
        plans,
        f"first-peak study of {', '.join(b.name for b in blks)}",
        report=report,
        progress=progress,
        max_hours=max_hours,
    )
    exact, paper, peaks, errors, fit, succ, warns = {}, {}, {}, {}, {}, {}, []
    for i, blk in enumerate(blks):
        mine = runs[i * len(dts) : (i + 1) * len(dts)]
        ex = math.degrees(housner_first_peak(blk, _theta0(blk, None)))
        vals = [None if r.first_peak is None else math.degrees(r.first_peak) for r in mine]
        err = [None if v is None else abs(v - ex) for v in vals]
        warns += _run_warnings([f"{blk.name} dt = {dt:g} s" for dt in dts], mine)
        exact[blk.name], paper[blk.name] = ex, blk.reference.first_peak_deg
        peaks[blk.name], errors[blk.name] = vals, err
        fit[blk.name], succ[blk.name] = _orders(dts, err)
    return FirstPeakStudy(
        tuple(b.name for b in blks), dts, exact, paper, peaks, errors, fit, succ, tuple(warns)
    )


def flexibility_study(
    block,
    exponents=(8, 6, 4, 2, 0),
    *,
    meshes=(6, 12, 24),
    dts=(1e-4, 1e-5, 1e-6),
    base_dt=None,
    base_mesh=None,
    t_end=4.0,
    theta0=None,
    report=None,
    progress=None,
    max_hours=None,
    names=None,
    **kw,
) -> dict:
    """Flexibility sweep E = Ē·10ⁿ with mesh and time-step sensitivity (paper 002, Figs 16–19).

    Ē gives a midspan deflection of L/2500 under the block's weight. For each
    n, a mesh study (at `base_dt`, default the middle of `dts`) and a dt study
    (at `base_mesh`, default the coarsest of `meshes`) are run; the run at
    (base_dt, base_mesh) is shared, so `base_dt` must be one of `dts` and
    `base_mesh` one of `meshes`. A run on the beam specimen's own E (the rigid
    base for paper 002's beam) is included for comparison. All runs are
    validated and costed before the first starts.

    Returns
    -------
    dict
        ``{"E_bar": Ē, "rigid": NSCDResult, "base": {n: NSCDResult},
        "mesh": {n: Study}, "dt": {n: Study}, ...}``; "base" is the run at
        (`base_dt`, `base_mesh`).
    """
    exps = _exponents(exponents, block, kw.get("beam", "beam_mudric2024"), names)
    ms = check_levels(_name(names, "meshes"), meshes, kind="mesh")
    ds = check_levels(_name(names, "dts"), dts, kind="dt")
    base_dt = ds[len(ds) // 2] if base_dt is None else _member(base_dt, ds, "base_dt", "dts", names)
    base_mesh = ms[0] if base_mesh is None else _member(base_mesh, ms, "base_mesh", "meshes", names)
    th0 = _theta0(block, theta0)
    Ebar = flexible_modulus(block, kw.get("beam", "beam_mudric2024"))
    keys = [(None, base_dt, base_mesh)] + sorted(
        {
            (n, dt, m)
            for n in exps
            for dt, m in [(base_dt, m) for m in ms] + [(d, base_mesh) for d in ds]
        },
        key=lambda k: (exps.index(k[0]), -k[1], k[2]),
    )
    plans = [
        _plan(
            ("beam's own E" if n is None else f"n = {n:g}") + f", dt = {dt:g} s, {m} el.",
            block,
            theta0=th0,
            dt=dt,
            t_end=t_end,
            E=None if n is None else Ebar * 10.0**n,
            n_elements=m,
            names=names,
            **kw,
        )
        for n, dt, m in keys
    ]
    name = load_block(block).name
    runs = dict(
        zip(
            keys,
            _execute(
                plans,
                f"flexibility study of {name}",
                report=report,
                progress=progress,
                max_hours=max_hours,
            ),
        )
    )
    out = {
        "E_bar": Ebar,
        "block": name,
        "theta0": plans[0].inp.theta0,
        "exponents": exps,
        "rigid": runs[None, base_dt, base_mesh],
        "base": {},
        "mesh": {},
        "dt": {},
    }
    for n in exps:
        settings = {
            "E_Pa": Ebar * 10.0**n,
            "exponent": n,
            "t_end_s": plans[0].opts.t_end,
            "theta0": plans[0].inp.theta0,
            "theta0_deg": math.degrees(plans[0].inp.theta0),
        }
        mesh_runs, dt_runs = [runs[n, base_dt, m] for m in ms], [runs[n, d, base_mesh] for d in ds]
        out["base"][n] = runs[n, base_dt, base_mesh]
        out["mesh"][n] = Study(
            "mesh",
            name,
            ms,
            tuple(mesh_runs),
            tuple(compare_runs(ms, mesh_runs, _ratio("mesh", ms))),
            {**settings, "dt_s": base_dt},
        )
        out["dt"][n] = Study(
            "dt",
            name,
            ds,
            tuple(dt_runs),
            tuple(compare_runs(ds, dt_runs, _ratio("dt", ds))),
            {**settings, "n_elements": base_mesh},
        )
    return out


def _exponents(exponents, block, beam, names) -> tuple:
    name = _name(names, "exponents")
    if (
        isinstance(exponents, (str, bytes))
        or not hasattr(exponents, "__len__")
        or len(exponents) == 0
    ):
        raise InputError(
            f"`{name}` = {exponents!r}: give a list of exponents n of E = Ē·10^n, e.g. 8 6 4 2 0"
        )
    exps = tuple(check_exponent(n, block, beam, f"{name}[{i}]") for i, n in enumerate(exponents))
    if len(set(exps)) != len(exps):
        raise InputError(f"`{name}` = {list(exponents)!r}: an exponent is repeated")
    return tuple(n if not float(n).is_integer() else int(n) for n in exps)


def _member(value, levels, key, levels_key, names):
    if value not in levels:
        raise InputError(
            f"`{_name(names, key)}` = {value!r}: must be one of "
            f"`{_name(names, levels_key)}` = {list(levels)!r} (its run is shared by "
            "the mesh and the time-step studies)"
        )
    return value
