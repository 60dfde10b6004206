"""Speed x accuracy benchmarks (not run by the test suite)."""
