"""Developer-only benchmark scripts (not installed): ``python -m benchmarks.fast_path`` and
friends. The benchmarks that ``multimass bench`` runs ship in the package, `multimass.bench`."""
