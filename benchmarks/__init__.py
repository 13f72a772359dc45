"""Benchmarks: task suites (``gsr.benchmarks.suites``), agents, the checked-step runner, metrics and reports.

``gsr bench list|run|export`` is the command line (docs/benchmarks.md); the ``bench_*.py`` scripts
measure speed and record figures for docs/performance.md.
"""
