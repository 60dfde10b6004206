"""Speed × accuracy benchmarks; run by ``multimass bench``, not by the test suite.

* `multimass.bench.config` — the full, quick and smoke sizes;
* `multimass.bench.cases` — the five models, their methods and tight references;
* `multimass.bench.results` — one `RunResult` per run, whatever the solver;
* `multimass.bench.work_precision` — error measures and the tolerance / Δt sweeps;
* `multimass.bench.failures` — where methods fail: detection, stiffness sweep, NSCD convergence;
* `multimass.bench.targets` — the speed targets (single run, map, 2-worker scaling), compile cost;
* `multimass.bench.charts`, `multimass.bench.summary` — figures and the table of figures;
* `multimass.bench.run` — the orchestration (``python -m multimass.bench.run --out DIR``);
* `multimass.bench.scaling`, `multimass.bench.scaling_report` — how cost grows with cells,
  workers and nodes, with fitted exponents (``multimass bench --scaling``).

Older single-purpose scripts: `fast_path`, `newmark_cost`, `nscd_cost`, `sweep_overhead`.
"""
