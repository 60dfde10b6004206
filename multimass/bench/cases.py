"""The model cases of the work-precision charts, their methods and their tight references.

Five charts, one per model:

* ``rigid_block`` — B6M released at 11.268° (paper 002, Section 6.2), classical
  impacts with Housner's η: solve_ivp (RK45, DOP853, Radau, BDF, LSODA), the
  compiled path (RK45, DOP853), Newmark + Newton–Raphson (paper 004) and
  Moreau–Jean on the rigid base (paper 002) against a tight DOP853 run;
* ``S1_CIM``, ``S1_DD2`` — S1 released from 0.11 rad (paper 001): solve_ivp and
  the compiled path against a tight DOP853 run;
* ``lcp_block`` — paper 000's (x, y, φ) block with Poisson LCP impacts (ε_P = 0)
  under a sine pulse, the block of B6M: the paper-000 event-driven driver
  (DOP853 only) at several rtol, and the engine's impact="LCP" with every
  method, against the paper-000 driver at tight tolerance;
* ``nscd`` — Moreau–Jean (paper 002) at several Δt on the rigid base (against
  the tight rigid-block run: the same free rocking) and on flexible beams
  E = Ē·10ⁿ (against their own finest Δt: no other reference exists).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from contextlib import contextmanager
from dataclasses import dataclass, field

import multimass
import multimass.engines.nscd as nscd
from multimass.inputs.excitations import FreeRelease, SineWave
from multimass.simulation import simulate

from .config import Config
from .results import RunResult, failed_run, from_block, from_nscd, from_response, timed

__all__ = [
    "Method",
    "Case",
    "all_cases",
    "column_case",
    "rigid_block_case",
    "lcp_block_case",
    "nscd_case",
    "NSCDRunner",
    "IVP_METHODS",
    "IMPLICIT",
    "scaled_column",
    "engine_runner",
]

IVP_METHODS = ("RK45", "DOP853", "Radau", "BDF", "LSODA")
IMPLICIT = ("Radau", "BDF")
COMPILED = ("RK45", "DOP853")
THETA0_B6M = math.radians(11.268)  # paper 002, Section 6.2
ENGINE_KINDS = ("uplift", "impact", "full_contact", "overturn")
BLOCK_DT_OUT = 1e-4  # s: sampling of the paper-000 driver (its peaks)


@dataclass(frozen=True, eq=False)
class Method:
    """One line of a chart: a method and the levels (rtol or Δt) it is run at."""

    name: str
    family: str  # "explicit", "implicit", "compiled", "time stepping", ...
    level_name: str  # "rtol" or "dt"
    levels: tuple
    run: Callable[[float], RunResult]
    warm: bool = False  # run once untimed first (compiled kernels' first call)
    kinds: tuple | None = None  # event kinds compared (default: the case's)
    reference: Callable[[], RunResult] | None = None  # default: the case's
    reference_label: str = ""


@dataclass(frozen=True, eq=False)
class Case:
    """A model: its tight reference and its methods."""

    key: str
    title: str
    t_end: float
    t_compare: float  # events and peaks are compared up to here (adjusted)
    reference: Callable[[], RunResult]
    reference_label: str
    methods: list = field(default_factory=list)
    kinds: tuple = ENGINE_KINDS


def _measure(fn, adapt, cfg: Config) -> RunResult:
    wall, out = timed(fn, cfg.min_time_s, cfg.max_repeat)
    return failed_run(out, wall) if isinstance(out, BaseException) else adapt(out, wall)


def engine_runner(structure, excitation, impact, t_end, cfg: Config, max_step=math.inf, **model):
    """run(level, method, backend, integrator) → RunResult for `multimass.simulate`.

    `max_step` is the solve_ivp step cap of the case: ∞ for rigid blocks (the
    tolerance alone sets the step; `simulate`'s default 5 ms would hide it),
    the default 5 ms for columns (it keeps the uplift check of full contact
    frequent: without it a long step can step over a brief uplift).
    """

    def run(level, method="DOP853", backend="scipy", integrator="solve_ivp", atol=None, step=None):
        if integrator == "newmark":
            kw = dict(integrator="newmark", dt=level)
        else:
            kw = dict(
                method=method,
                rtol=level,
                atol=level * 1e-2 if atol is None else atol,
                backend=backend,
                max_step=max_step if step is None else step,
            )
        return _measure(
            lambda: simulate(structure, excitation, impact, t_end, output_dt=None, **model, **kw),
            from_response,
            cfg,
        )

    return run


def _engine_methods(run, cfg: Config, compiled=True) -> list[Method]:
    out = [
        Method(
            m,
            "implicit" if m in IMPLICIT else ("LSODA (switching)" if m == "LSODA" else "explicit"),
            "rtol",
            cfg.rtols_implicit if m in IMPLICIT else cfg.rtols,
            lambda lv, m=m: run(lv, method=m),
        )
        for m in IVP_METHODS
    ]
    if compiled:
        out += [
            Method(
                f"compiled {m}",
                "compiled",
                "rtol",
                cfg.rtols,
                lambda lv, m=m: run(lv, method=m, backend="compiled"),
                warm=True,
            )
            for m in COMPILED
        ]
    return out


def _once(fn):
    """`fn` computed on the first call only (a reference is shared by several charts)."""
    box = []

    def call():
        if not box:
            box.append(fn())
        return box[0]

    return call


def _reference(run, cfg: Config):
    return _once(lambda: run(cfg.ref_rtol, method="DOP853", atol=cfg.ref_atol))


def column_case(impact: str, cfg: Config) -> Case:
    """S1 released from 0.11 rad with `impact` ("CIM" or "DD2"), max_step 5 ms (the default).

    One more line, DOP853 without the step cap, shows what the cap is for.
    """
    run = engine_runner(
        "S1",
        FreeRelease(0.11),
        impact,
        cfg.column_t_end,
        cfg,
        max_step=multimass.DEFAULTS["max_step"],
    )
    methods = _engine_methods(run, cfg)
    methods.append(
        Method(
            "DOP853, max_step ∞",
            "explicit",
            "rtol",
            cfg.rtols,
            lambda lv: run(lv, method="DOP853", step=math.inf),
        )
    )
    return Case(
        f"S1_{impact}",
        f"S1 released from 0.11 rad, {impact}, {cfg.column_t_end:g} s, max_step 5 ms",
        cfg.column_t_end,
        0.9 * cfg.column_t_end,
        _reference(run, cfg),
        f"solve_ivp DOP853, rtol {cfg.ref_rtol:g}",
        methods,
    )


class NSCDRunner:
    """Moreau–Jean runs of B6M released at 11.268°, cached by (E, Δt, t_end)."""

    def __init__(self, cfg: Config):
        self.cfg, self.raw, self.block = cfg, {}, multimass.rigid_block("B6M")
        self.E_bar = nscd.flexible_modulus("B6M")

    def __call__(self, dt: float, exponent=None, t_end=None) -> RunResult:
        t_end = self.cfg.nscd_t_end if t_end is None else t_end
        E = None if exponent is None else self.E_bar * 10.0**exponent
        key = (E, dt, t_end)
        if key not in self.raw:
            wall, out = timed(
                lambda: nscd.simulate(
                    "B6M", theta0=THETA0_B6M, dt=dt, t_end=t_end, E=E, n_elements=6
                ),
                self.cfg.min_time_s,
                self.cfg.max_repeat,
            )
            res = (
                failed_run(out, wall)
                if isinstance(out, BaseException)
                else from_nscd(out, wall, self.block)
            )
            self.raw[key] = (out, res)
        return self.raw[key][1]

    def result(self, dt, exponent=None, t_end=None):
        """The `nscd.NSCDResult` of a cached run (or the exception it raised)."""
        t_end = self.cfg.nscd_t_end if t_end is None else t_end
        E = None if exponent is None else self.E_bar * 10.0**exponent
        self(dt, exponent, t_end)
        return self.raw[(E, dt, t_end)][0]


def rigid_block_case(cfg: Config, mj: NSCDRunner) -> Case:
    """B6M released at 11.268°, CIM with Housner's η: every method that applies."""
    t_end = cfg.block_t_end
    run = engine_runner("B6M", FreeRelease(THETA0_B6M), "CIM", t_end, cfg, restitution="housner")
    methods = _engine_methods(run, cfg)
    methods.append(
        Method(
            "Newmark + NR",
            "time stepping",
            "dt",
            cfg.newmark_dts,
            lambda dt: run(dt, integrator="newmark"),
            warm=True,
        )
    )
    methods.append(
        Method(
            "Moreau–Jean, rigid base",
            "event capturing",
            "dt",
            cfg.mj_dts,
            lambda dt: mj(dt, None, t_end),
            kinds=("impact",),
        )
    )
    return Case(
        "rigid_block",
        f"B6M released at 11.268°, Housner's η, {t_end:g} s, solve_ivp max_step ∞",
        t_end,
        0.8 * t_end,
        _reference(run, cfg),
        f"solve_ivp DOP853, rtol {cfg.ref_rtol:g}",
        methods,
    )


@contextmanager
def _count_rhs():
    """Count the right-hand sides of `multimass.engines.contact_dynamics` (it keeps no count)."""
    from multimass.engines import contact_dynamics as cd

    original, box = cd._Phase.rhs, [0]

    def rhs(self, t, y):
        box[0] += 1
        return original(self, t, y)

    cd._Phase.rhs = rhs
    try:
        yield box
    finally:
        cd._Phase.rhs = original


def lcp_block_case(cfg: Config) -> Case:
    """Paper 000's block (B6M's b, h, m) under SineWave(amplitude=0.3 g, omega=3p), ε_P = 0."""
    from multimass.engines.poisson_block import PoissonBlock, simulate_block

    st, t_end = multimass.rigid_block("B6M"), cfg.lcp_t_end
    block = PoissonBlock(b=st.B, h=st.h0, mass=st.m0, g=st.g)
    exc = SineWave(amplitude=0.3 * block.g, omega=3.0 * block.p)

    def driver(rtol, atol=None):
        def once():
            with _count_rhs() as box:
                r = simulate_block(
                    block,
                    0.0,
                    t_end,
                    ag=exc,
                    dt_out=BLOCK_DT_OUT,
                    rtol=rtol,
                    atol=rtol * 1e-2 if atol is None else atol,
                )
            return r, box[0]

        return _measure(once, lambda out, wall: from_block(out[0], wall, out[1]), cfg)

    run = engine_runner(st, exc, "LCP", t_end, cfg, eps_p=0.0)
    methods = [Method("paper-000 driver (DOP853)", "LCP driver", "rtol", cfg.rtols, driver)]
    methods += [
        dataclasses.replace(m, name=f"engine LCP, {m.name}") for m in _engine_methods(run, cfg)
    ]
    return Case(
        "lcp_block",
        f"Paper 000 block (B6M size), sine 0.3 g at 3p, ε_P = 0, {t_end:g} s, max_step ∞",
        t_end,
        0.8 * t_end,
        _once(lambda: driver(cfg.ref_rtol, cfg.ref_atol)),
        f"paper-000 driver, rtol {cfg.ref_rtol:g}",
        methods,
    )


def nscd_case(cfg: Config, mj: NSCDRunner, rigid_reference) -> Case:
    """Moreau–Jean on the rigid base and on flexible beams E = Ē·10ⁿ."""
    t_end = cfg.nscd_t_end
    methods = [
        Method(
            "Moreau–Jean, rigid base",
            "event capturing",
            "dt",
            cfg.mj_dts,
            lambda dt: mj(dt, None, t_end),
            kinds=("impact",),
        )
    ]
    coarse = tuple(dt for dt in cfg.mj_dts if dt > cfg.nscd_ref_dt)
    for n in cfg.nscd_exponents:
        methods.append(
            Method(
                f"Moreau–Jean, E = Ē·10^{n}",
                "event capturing",
                "dt",
                coarse,
                lambda dt, n=n: mj(dt, n, t_end),
                kinds=("impact",),
                reference=lambda n=n: mj(cfg.nscd_ref_dt, n, t_end),
                reference_label=f"Moreau–Jean Δt = {cfg.nscd_ref_dt:g} s",
            )
        )
    return Case(
        "nscd",
        f"B6M on paper 002's beam, released at 11.268°, {t_end:g} s",
        t_end,
        0.8 * t_end,
        rigid_reference,
        f"rigid block, solve_ivp DOP853, rtol {cfg.ref_rtol:g}",
        methods,
        kinds=("impact",),
    )


def scaled_column(scale: float, name: str = "S1"):
    """The column `name` with E_s, K_rot and K_fp times `scale` (frequencies × √scale)."""
    import multimass.specimens as specimens

    spec = specimens.load(name)
    spec = dataclasses.replace(
        spec, E_s=spec.E_s * scale, K_rot=spec.K_rot * scale, K_fp=spec.K_fp * scale
    )
    return multimass.column(spec)


def all_cases(cfg: Config) -> tuple[list[Case], NSCDRunner]:
    """The five cases of the charts, in chart order (and the shared Moreau–Jean runner)."""
    mj = NSCDRunner(cfg)
    rigid = rigid_block_case(cfg, mj)
    if cfg.nscd_t_end == cfg.block_t_end:
        rigid_ref = rigid.reference
    else:
        run = engine_runner(
            "B6M", FreeRelease(THETA0_B6M), "CIM", cfg.nscd_t_end, cfg, restitution="housner"
        )
        rigid_ref = _reference(run, cfg)
    return (
        [
            rigid,
            column_case("CIM", cfg),
            column_case("DD2", cfg),
            lcp_block_case(cfg),
            nscd_case(cfg, mj, rigid_ref),
        ],
        mj,
    )
