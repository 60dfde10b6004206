"""What `multimass bench` runs: the full, quick and smoke configurations.

Every size (durations, tolerances, time steps, grids, repeats) lives here, so
the modules that measure and chart never hard-code a budget. Measured on a
shared 2-core machine: the full run takes ~10 min, the quick run ~2.5 min, the
smoke run (structure checks in the test suite) ~15 s.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Config", "FULL", "QUICK", "SMOKE", "preset", "ScalingConfig", "scaling_preset"]

#: explicit solve_ivp methods and LSODA: five decades of rtol (atol = rtol / 100)
_RTOLS = (1e-3, 1e-4, 1e-6, 1e-8, 1e-10)
#: the implicit methods stop at 1e-8: at 1e-10 one S1 run of Radau or BDF takes minutes
_RTOLS_IMPLICIT = (1e-3, 1e-4, 1e-6, 1e-8)


@dataclass(frozen=True)
class Config:
    """Sizes of one benchmark run (SI units; see the module docstring).

    Attributes
    ----------
    name : str
        "full", "quick" or "smoke".
    rtols, rtols_implicit : tuple of float
        Relative tolerances of the explicit (and LSODA, compiled) and of the
        implicit (Radau, BDF) methods; atol = rtol / 100.
    ref_rtol, ref_atol : float
        Tolerances of the tight references (DOP853).
    target_t_end : float
        Duration of the S1 DD2 release of the speed-up target (10 s).
    column_t_end : float
        Duration of the S1 release cases of the charts (s).
    block_t_end, lcp_t_end, nscd_t_end : float
        Durations of the rigid-block, LCP-block and NSCD cases (s).
    newmark_dts, mj_dts : tuple of float
        Time steps of Newmark and of Moreau–Jean (s).
    nscd_exponents : tuple of int
        Flexible beams E = Ē·10ⁿ of the NSCD case (paper 002, Figs 16–19).
    nscd_ref_dt : float
        Time step of each flexible beam's self-reference (s).
    stiffness_scales, stiffness_t_end, stiffness_rtol :
        The stiffness sweep of S1 (E_s, K_rot, K_fp times each scale).
    map_n : int
        The B6M sine map is map_n × map_n.
    baseline_cells : int or None
        solve_ivp cells timed for the map baseline (a seeded random subsample,
        scaled to the grid); None: every cell.
    repeats : int
        Repeats of the target ratios (median and spread reported).
    spin_steps : int
        Length of each of the 32 pure-Python tasks that measure the machine's own
        2-worker scaling after each map pair (1e6: ~0.08 s per task here).
    cold_compile : bool
        Time the numba compilation in a fresh process with an empty cache.
    min_time_s, max_repeat :
        Work-precision runs faster than `min_time_s` are repeated up to
        `max_repeat` times (median).
    """

    name: str
    rtols: tuple = _RTOLS
    rtols_implicit: tuple = _RTOLS_IMPLICIT
    ref_rtol: float = 1e-12
    ref_atol: float = 1e-14
    target_t_end: float = 10.0
    column_t_end: float = 10.0
    block_t_end: float = 2.5
    lcp_t_end: float = 3.0
    nscd_t_end: float = 2.5
    newmark_dts: tuple = (1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 1e-5)
    mj_dts: tuple = (1e-3, 1e-4, 1e-5, 1e-6)
    nscd_exponents: tuple = (4, 2, 0)
    nscd_ref_dt: float = 1e-6
    stiffness_scales: tuple = (1.0, 10.0, 100.0, 1e3, 1e4)
    stiffness_t_end: float = 1.0
    stiffness_rtol: float = 1e-6
    map_n: int = 100
    baseline_cells: int | None = 1000
    repeats: int = 5
    spin_steps: int = 1_000_000
    cold_compile: bool = True
    min_time_s: float = 0.3
    max_repeat: int = 3


FULL = Config("full")

QUICK = Config(
    "quick",
    rtols=(1e-3, 1e-6, 1e-9),
    rtols_implicit=(1e-3, 1e-6),
    ref_rtol=1e-11,
    ref_atol=1e-13,
    column_t_end=3.0,
    block_t_end=2.0,
    lcp_t_end=2.0,
    nscd_t_end=2.0,
    newmark_dts=(1e-2, 1e-3, 1e-4),
    mj_dts=(1e-3, 1e-4, 1e-5),
    nscd_exponents=(2,),
    nscd_ref_dt=1e-6,
    stiffness_scales=(1.0, 100.0, 1e3),
    stiffness_t_end=0.5,
    map_n=30,
    baseline_cells=None,
    repeats=2,
    cold_compile=False,
    min_time_s=0.1,
    max_repeat=2,
)

SMOKE = Config(
    "smoke",
    rtols=(1e-4,),
    rtols_implicit=(1e-4,),
    ref_rtol=1e-9,
    ref_atol=1e-11,
    target_t_end=0.6,
    column_t_end=0.6,
    block_t_end=0.8,
    lcp_t_end=0.8,
    nscd_t_end=0.8,
    newmark_dts=(1e-3,),
    mj_dts=(1e-3,),
    nscd_exponents=(2,),
    nscd_ref_dt=1e-4,
    stiffness_scales=(1.0, 10.0),
    stiffness_t_end=0.2,
    map_n=3,
    baseline_cells=None,
    repeats=1,
    spin_steps=1_000,
    cold_compile=False,
    min_time_s=0.0,
    max_repeat=1,
)

_PRESETS = {c.name: c for c in (FULL, QUICK, SMOKE)}


def preset(name: str) -> Config:
    """The configuration called `name` ("full", "quick" or "smoke")."""
    try:
        return _PRESETS[name]
    except KeyError:
        from multimass.errors import InputError

        raise InputError(f"`config` = {name!r}: use one of {', '.join(_PRESETS)}") from None


@dataclass(frozen=True)
class ScalingConfig:
    """Sizes of `multimass bench --scaling` (`multimass.bench.scaling`).

    Attributes
    ----------
    name : str
        "full", "quick" or "smoke".
    map_sides : tuple of int
        The B6M sine maps of the cells series are side × side (10² … 10⁶ cells).
    workers_side : int
        The map of the workers series is workers_side × workers_side.
    workers : tuple of int
        Process-pool sizes of the workers series.
    spin_tasks, spin_steps : int
        The machine's own scaling beside it: `spin_tasks` pure-Python loops of
        `spin_steps` steps on the same pools (`targets.machine_times`).
    nodes : tuple of int
        N of the uniform N-node columns of the nodes series.
    nodes_impact : str
        Impact model of the nodes series ("DD2" or "CIM").
    nodes_t_end : float
        Duration of each free-rocking run (s; 10 s by default).
    theta0 : float
        Release angle of the nodes series (rad; S1's 0.11).
    compiled_budget_s, scipy_budget_s : float
        A run of the compiled (solve_ivp) path whose `multimass.estimate` exceeds this
        is skipped and listed. The compiled estimate is cautious: S1-like N = 40,
        estimated 284 s, runs in ~85 s here; solve_ivp at N = 16 is estimated 175 s.
    repeats : int
        Repeats of every point (median, min, max).
    """

    name: str
    map_sides: tuple = (10, 32, 100, 316, 1000)
    workers_side: int = 200
    workers: tuple = (1, 2)
    spin_tasks: int = 32
    spin_steps: int = 1_000_000
    nodes: tuple = (1, 2, 3, 5, 8, 12, 16, 20, 30, 40)
    nodes_impact: str = "DD2"
    nodes_t_end: float = 10.0
    theta0: float = 0.11
    compiled_budget_s: float = 300.0
    scipy_budget_s: float = 120.0
    repeats: int = 3


SCALING_FULL = ScalingConfig("full")
SCALING_QUICK = ScalingConfig(
    "quick",
    map_sides=(10, 32, 100, 316),
    workers_side=100,
    spin_tasks=16,
    nodes=(1, 2, 5, 10, 20),
    compiled_budget_s=10.0,
    scipy_budget_s=30.0,
    repeats=2,
)
SCALING_SMOKE = ScalingConfig(
    "smoke",
    map_sides=(10, 32),
    workers_side=8,
    spin_tasks=4,
    spin_steps=1_000,
    nodes=(1, 2),
    nodes_t_end=0.3,
    compiled_budget_s=5.0,
    scipy_budget_s=5.0,
    repeats=1,
)
_SCALING = {c.name: c for c in (SCALING_FULL, SCALING_QUICK, SCALING_SMOKE)}


def scaling_preset(name: str) -> ScalingConfig:
    """The scaling configuration called `name` ("full", "quick" or "smoke")."""
    try:
        return _SCALING[name]
    except KeyError:
        from multimass.errors import InputError

        raise InputError(f"`config` = {name!r}: use one of {', '.join(_SCALING)}") from None
