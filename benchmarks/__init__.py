"""Speed × accuracy benchmarks (issue 7); run by ``multimass bench``, not by the test suite.

* `benchmarks.config` — the full, quick and smoke sizes;
* `benchmarks.cases` — the five models, their methods and tight references;
* `benchmarks.results` — one `RunResult` per run, whatever the solver;
* `benchmarks.work_precision` — error measures and the tolerance / Δt sweeps;
* `benchmarks.failures` — where methods fail: detection, stiffness sweep, NSCD convergence;
* `benchmarks.targets` — the speed targets (single run, map, 2-worker scaling), compile cost;
* `benchmarks.charts`, `benchmarks.summary` — figures and the table of figures;
* `benchmarks.run` — the orchestration (``python -m benchmarks.run --out DIR``).

Older single-purpose scripts: `fast_path`, `newmark_cost`, `nscd_cost`, `sweep_overhead`.
"""
