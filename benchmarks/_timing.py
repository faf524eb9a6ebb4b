"""Timing helper shared by the benchmark scripts (run as scripts: ``benchmarks/`` is on
``sys.path``, so they ``from _timing import median_time``)."""

from __future__ import annotations

import statistics
import time


def median_time(fn, repeats: int) -> float:
    """Median wall time of *repeats* calls of ``fn()``, seconds (no warm-up: call it first)."""
    ts = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t)
    return statistics.median(ts)
