"""Benchmark scripts and task suites; each `bench_*.py` runs as a script and records figures for docs/performance.md."""
