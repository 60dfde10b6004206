"""What a Moreau–Jean run will cost before it starts (time and memory), and the
largest mesh the engine accepts.

The model, per run of ``n_steps`` steps on a beam of ``n_el`` elements
(``n = 3 n_el`` free degrees of freedom: three per node, minus the three
support constraints):

    seconds ≈ SETUP_S_PER_N3 · n³ + n_steps · (STEP_S + STEP_S_PER_N2 · n²)
    memory  ≈ ASSEMBLY_BYTES_PER_N2 · n² + rows · 8 · 8 B

* The set-up is dense linear algebra, O(n³): the generalised eigenproblem of
  the beam (Rayleigh damping), the Cholesky factors of K (preload) and of
  A = M + Δtθ C + (Δtθ)² K, and A⁻¹ (paper 002, Eqs 26, 33).
* A step is a fixed overhead (free flight, contact detection on four
  vertices, the 2 × 2 contact problems) plus the dense product A⁻¹ r of
  the beam's free velocity (paper 002, Eq 24), O(n²), which dominates from
  about 30 elements on.
* The assembly keeps about seven dense n × n arrays alive at its peak (full
  and reduced K, M, C, the eigen-solver's copies; then A, its factor, the
  identity and A⁻¹); the recorded series has `rows` rows of 8 floats.

Calibration (this machine kind: 2 cores shared with other jobs, numba, OpenBLAS;
measure again with ``python -m benchmarks.nscd_cost --calibrate``). B6M
released at 11.268° on paper 002's rigid base (E = 1e24 Pa), Δt = 1e-5 s, θ = 1,
best of two runs, once on quiet cores and once at a load average of 3.3:

====  =====  ===========  ============  =====================================
n_el    n    quiet µs/st  loaded µs/st  model STEP_S + STEP_S_PER_N2 · n² (µs)
====  =====  ===========  ============  =====================================
   3     9      1.39          1.60         1.9
   6    18      1.80          2.79         2.4
  12    36      2.8–3.9       5.60         4.0
  24    72      7.4          11.3         10.6
  48   144     25–37         33.7         37
  96   288     89–99        158          143
 192   576    377–381       503          566
 384  1152   1510–1730        —         2260
====  =====  ===========  ============  =====================================

The constants are the least-squares fit (relative errors) of the loaded column,
the slow end, so that a run is rarely estimated cheaper than it is. Flexible
beams (E = Ē·10² and Ē) cost 0.9–1.4 times the rigid base at the same mesh
(more simultaneous contacts, longer Gauss–Seidel). The set-up took 1.6–6.5
ns · n³ (0.09–0.16 s at 96 elements, 3–9 s at 384, 57 s at 1000). The peak
memory of the assembly, measured with tracemalloc for 24–768 elements, is
7.0–7.7 · 8 n² bytes. The first run in a process also loads the compiled
kernel from numba's cache (~1 s, more when it must compile), which is not
part of the estimate. The estimate guards against slips of orders of
magnitude, not seconds.
"""

from __future__ import annotations

import math

from multimass.progress import RunCost, format_bytes, format_duration

__all__ = [
    "STEP_S",
    "STEP_S_PER_N2",
    "SETUP_S_PER_N3",
    "ASSEMBLY_BYTES_PER_N2",
    "SERIES_COLUMNS",
    "MAX_ELEMENTS",
    "CHUNK_SECONDS",
    "n_dof",
    "step_seconds",
    "setup_seconds",
    "assembly_memory",
    "estimate",
    "chunk_steps",
]

#: fixed cost of one step (s): free flight, contact detection, contact solution
STEP_S = 1.8e-6
#: cost of one step per squared degree of freedom (s): the dense product A⁻¹ r (Eq 24)
STEP_S_PER_N2 = 1.7e-9
#: set-up per cubed degree of freedom (s): eigenproblem, Cholesky factors, A⁻¹
SETUP_S_PER_N3 = 3.0e-9
#: peak bytes of the assembly per squared degree of freedom (eight dense n × n float arrays)
ASSEMBLY_BYTES_PER_N2 = 8 * 8
#: floats per recorded row (nscd.kernel.SERIES)
SERIES_COLUMNS = 8
#: Largest number of beam elements accepted. Paper 002 uses 3–24 elements (its
#: rigid-base responses agree from 3 elements on, Fig 11); the engine keeps dense
#: beam matrices, so at
#: 1000 elements (3000 degrees of freedom) the set-up already takes about a
#: minute and 0.6 GB, each step ~15 ms (100 min for 4 s at Δt = 1e-5 s), and the
#: condition number of K, which grows as n_el⁴ (1.2e12 at 384 elements on paper
#: 002's beam), reaches ~5e13, leaving the static preload and A⁻¹ with 2–3 digits
#: in their worst direction.
MAX_ELEMENTS = 1000
#: wall time of one call of the compiled kernel between two progress updates (s)
CHUNK_SECONDS = 0.25


def n_dof(n_elements: int) -> int:
    """Free degrees of freedom of the simply supported beam: 3 (n_el + 1) − 3."""
    return 3 * int(n_elements)


def step_seconds(n_elements: int) -> float:
    """Estimated wall time of one step (s)."""
    return STEP_S + STEP_S_PER_N2 * n_dof(n_elements) ** 2


def setup_seconds(n_elements: int) -> float:
    """Estimated wall time of the assembly (s)."""
    return SETUP_S_PER_N3 * n_dof(n_elements) ** 3


def assembly_memory(n_elements: int) -> float:
    """Estimated peak memory of the assembly (bytes)."""
    return float(ASSEMBLY_BYTES_PER_N2) * n_dof(n_elements) ** 2


def estimate(n_elements: int, steps: float, rows: float) -> RunCost:
    """Cost of a run of `steps` steps on `n_elements` elements recording `rows` rows.

    `steps` may be a float (even inf) so that a slip such as Δt = 1e-300 s is
    estimated, not overflowed.
    """
    n = n_dof(n_elements)
    per_step = step_seconds(n_elements)
    seconds = setup_seconds(n_elements) + steps * per_step
    memory = assembly_memory(n_elements) + float(rows) * SERIES_COLUMNS * 8
    basis = (
        f"{n_elements} elements ({n} degrees of freedom): ~{per_step * 1e6:.2g} µs per step, "
        f"set-up {format_duration(setup_seconds(n_elements))}, dense beam matrices "
        f"{format_bytes(assembly_memory(n_elements))}, {rows:.3g} recorded rows"
    )
    return RunCost(steps=float(steps), seconds=seconds, memory=memory, basis=basis)


def chunk_steps(n_elements: int, n_steps: int) -> int:
    """Steps per call of the compiled kernel: about `CHUNK_SECONDS` of work, at least 1."""
    return int(max(1, min(n_steps, math.floor(CHUNK_SECONDS / step_seconds(n_elements)))))
