"""The model ladder: from the cheapest model of a scene to the richest.

Columns (paper 001)::

    rigid     rigid equivalent, 1 DOF (θ)              `reduce.rigid_equivalent`
    sdof      flexible SDOF oscillator, 2 DOF (θ, u*)  `reduce.sdof` (mode 1)
    modal-n   n-node column, first n modes, n+1 DOF    `reduce.modal_reduction` (2 ≤ n < N)
    column    the N-node column, N+1 DOF               `multimass.column`

Blocks (papers 004, 002)::

    rigid-block   rigid block on rigid ground, 1 DOF (Housner; `multimass.rigid_block`)
    nscd          the block on an FE beam (Moreau–Jean, `multimass.engines.nscd.run`): 3 + 3(n_el+1) − 3 DOF;
                  on rigid ground the beam's rigid-base modulus (E = 1e24 Pa, paper 002 §6.1).
                  Free rocking only: under ground motion the ladder of a block has one rung.

Within a rung the impact model (the scene's: DD2 for columns, CIM with Housner's η for
blocks) and the mesh (the beam's elements) are the scene's. Every rung answers every
question it can: the rigid rung has no vibration modes (no uplifted_frequencies), a
rung with n modes answers uplifted_frequencies only for n_modes ≤ n.

Columns run on the compiled backend of `multimass.simulate` when it is available
(`multimass.engines.fast`, compiled once per process before any clock starts) and fall back to
SciPy otherwise; NSCD runs its compiled kernel.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

import multimass.modal as modal
import multimass.specimens as specimens

from ..errors import InputError, SolverError
from ..model.structure import column, rigid_block
from ..simulation import simulate
from .recovery import node_accelerations
from .reduce import Reduced, modal_reduction, rigid_equivalent

__all__ = ["Rung", "RungAnswer", "ladder", "OUTPUT_DT_ACCELERATION", "BACKENDS"]

BACKENDS = ("auto", "compiled", "scipy")

#: Sampling of the time history for peak accelerations (s): ≥ 8 samples a period
#: up to 500 Hz, the highest modes of S1–S3 (paper 001, Fig 4: up to ~530 Hz).
OUTPUT_DT_ACCELERATION = 2.5e-4

_WARM = {"fast": None, "nscd": False}


@dataclass(frozen=True)
class RungAnswer:
    """One model's answer to a scene's question.

    Attributes
    ----------
    model : str
        Rung name.
    value : float, bool or tuple of float
        The answer in `unit` (rad, m/s², Hz, or a verdict).
    unit : str
    wall_time_s : float
        Build + simulation + post-processing, compilation excluded.
    status : str
        The simulation's status ("completed", "overturned", "modal").
    detail : dict
    """

    model: str
    value: object
    unit: str
    wall_time_s: float
    status: str
    detail: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Rung:
    """A model of the ladder.

    Attributes
    ----------
    name, label : str
        Short name (``"sdof"``) and a description (``"flexible SDOF oscillator (2 DOF)"``).
    dofs : int
        Degrees of freedom.
    n_modes : int or None
        Elastic modes a column rung keeps (0 rigid, N the full column); None for blocks.
    """

    name: str
    label: str
    dofs: int
    n_modes: int | None = None

    def answer(self, scene, backend: str = "auto") -> RungAnswer:
        """Run this model on `scene` and answer its question.

        `backend` of `multimass.simulate`: "auto" (compiled when available, else
        SciPy), "compiled" or "scipy". NSCD always runs its own compiled kernel.
        """
        if backend not in BACKENDS:
            raise InputError(f"`backend` = {backend!r}: use one of {', '.join(BACKENDS)}")
        if self.n_modes is not None:
            return _column_answer(self, scene, backend)
        return _block_answer(self, scene, backend)


def ladder(scene) -> list[Rung]:
    """The rungs of `scene`, cheapest first, that can answer its question."""
    if scene.kind == "column":
        n = len(scene.spec.heights)
        rungs = [Rung("rigid", "rigid equivalent (1 DOF)", 1, 0)]
        if n > 1:
            rungs.append(Rung("sdof", "flexible SDOF oscillator (2 DOF)", 2, 1))
        rungs += [
            Rung(f"modal-{k}", f"{k}-node modal column ({k + 1} DOF)", k + 1, k)
            for k in range(2, n)
        ]
        rungs.append(Rung("column", f"{n}-node column ({n + 1} DOF)", n + 1, n))
        if scene.question.kind == "uplifted_frequencies":
            rungs = [r for r in rungs if r.n_modes >= scene.question.n_modes]
        return rungs
    rungs = [Rung("rigid-block", "rigid block on rigid ground (1 DOF)", 1)]
    if scene.is_release:
        n_el = scene.nscd_elements or _beam(scene).n_elements
        where = "rigid base" if scene.beam is None else f"FE beam, {n_el} elements"
        rungs.append(Rung("nscd", f"block on {where} (NSCD, {3 + 3 * n_el} DOF)", 3 + 3 * n_el))
    return rungs


def _beam(scene):
    return scene.beam_spec or specimens.load("beam_mudric2024")


# ---------------------------------------------------------------------------- columns
def reduced_model(rung: Rung, scene) -> Reduced:
    """The (reduced) structure of a column rung with its recovery matrix."""
    st = column(scene.spec)
    if rung.n_modes == 0:
        return rigid_equivalent(st)
    if rung.n_modes == st.n:
        return Reduced(st, np.eye(st.n), st)
    return modal_reduction(st, rung.n_modes)


def _fast_ready() -> bool:
    if _WARM["fast"] is None:
        try:
            from ..engines.fast import warm_up

            warm_up()
            _WARM["fast"] = True
        except Exception:  # no numba or no compiled path: the SciPy reference is used
            _WARM["fast"] = False
    return _WARM["fast"]


def simulate_scene(structure, scene, output_dt, backend: str = "auto"):
    """`multimass.simulate` with the scene's options; "auto": compiled when possible."""

    kw = dict(
        impact=scene.impact_model,
        restitution=scene.restitution_value,
        t_end=scene.duration,
        output_dt=output_dt,
        max_step=scene.solver_max_step,
    )
    if backend == "compiled":
        return simulate(structure, scene.excitation, backend="compiled", **kw)
    if backend == "auto" and _fast_ready():
        try:
            return simulate(structure, scene.excitation, backend="compiled", **kw)
        except InputError as exc:
            if "backend" not in str(exc):
                raise
    return simulate(structure, scene.excitation, **kw)


def _trusted(resp, rung: str, scene) -> None:
    """Raise SolverError unless the run can answer the scene: completed or overturned, its
    checks passed (an inaccurate run would make the model comparison meaningless)."""
    if resp.status not in ("completed", "overturned", "inaccurate"):
        raise SolverError(f"model {rung!r} of scene {scene.name!r} {resp.status}: {resp.message}")
    if resp.status == "inaccurate":
        raise SolverError(
            f"model {rung!r} of scene {scene.name!r} is inaccurate: " + "; ".join(resp.warnings)
        )


def _rotation(resp, scene) -> float:
    if resp.status == "overturned":
        return math.pi / 2
    peaks = np.asarray(resp.peaks)[scene.after_impacts :]
    return float(peaks.max()) if peaks.size else 0.0


def _column_answer(rung: Rung, scene, backend: str) -> RungAnswer:
    q = scene.question
    if backend != "scipy":
        _fast_ready()
    start = time.perf_counter()
    red = reduced_model(rung, scene)
    if q.kind == "uplifted_frequencies":
        modes = modal.analyse(red.structure).rocking.to_pandas()  # by mode number,
        freqs = tuple(float(f) for f in modes["freq_hz"].iloc[: q.n_modes])  # overdamped too
        return RungAnswer(rung.name, freqs, "Hz", time.perf_counter() - start, "modal")

    output_dt = OUTPUT_DT_ACCELERATION if q.kind == "peak_acceleration" else None
    resp = simulate_scene(red.structure, scene, output_dt, backend)
    _trusted(resp, rung.name, scene)
    if q.kind == "peak_rotation":
        value = _rotation(resp, scene)
    elif q.kind == "overturning":
        value = resp.status == "overturned"
    else:
        value = float(np.abs(node_accelerations(red, resp.series, [scene.node])).max())
    wall = time.perf_counter() - start
    return RungAnswer(
        rung.name,
        value,
        q.unit,
        wall,
        resp.status,
        {
            "n_impacts": resp.n_impacts,
            "theta_max": resp.theta_max,
            "backend": resp.options.get("backend", "scipy"),
            "structure": red.structure.name,
        },
    )


# ---------------------------------------------------------------------------- blocks
def _nscd_warm():
    if not _WARM["nscd"]:
        import multimass.engines.nscd as nscd

        nscd.simulate("B6M", theta0=0.1, dt=1e-3, t_end=0.01)  # compile or load the kernel
        _WARM["nscd"] = True


def _block_answer(rung: Rung, scene, backend: str) -> RungAnswer:
    q = scene.question
    if rung.name == "rigid-block":
        if backend != "scipy":
            _fast_ready()
        start = time.perf_counter()
        resp = simulate_scene(rigid_block(scene.spec), scene, None, backend)
        _trusted(resp, "rigid-block", scene)
        value = _rotation(resp, scene) if q.kind == "peak_rotation" else resp.status == "overturned"
        return RungAnswer(
            rung.name,
            value,
            q.unit,
            time.perf_counter() - start,
            resp.status,
            {"n_impacts": resp.n_impacts, "backend": resp.options.get("backend", "scipy")},
        )
    import multimass.engines.nscd as nscd

    _nscd_warm()
    start = time.perf_counter()
    res = nscd.simulate(
        scene.spec,
        _beam(scene),
        theta0=scene.excitation.theta0,
        dt=scene.nscd_dt,
        t_end=scene.duration,
        E=scene.E,
        n_elements=scene.nscd_elements,
    )
    wall = time.perf_counter() - start
    _trusted(res, "nscd", scene)
    # the peaks follow the one convention of every engine (the release's first)
    value = _rotation(res, scene) if q.kind == "peak_rotation" else res.status == "overturned"
    return RungAnswer(
        rung.name,
        value,
        q.unit,
        wall,
        res.status,
        {
            "n_steps": res.n_steps,
            "dt_s": scene.nscd_dt,
            "E_Pa": res.params["E"],
            "n_elements": res.params["n_elements"],
            "cost_per_step_us": res.cost_per_step_us,
        },
    )
