"""
Numba's thread count, set in one place
======================================

Two callers want fewer threads than Numba's default: :meth:`BRDF.eval
<brdfkit.models.BRDF.eval>` runs fewer than ``SERIAL_BELOW`` pairs on one
thread (waking the pool costs more than the work), and a fit evaluates on one
thread throughout (``brdfkit.fitting``: for ~15,000 pairs per evaluation the
wake-ups cost more than the work on a shared 2-core machine: 16 ms vs 0.3 ms).
Both go through :class:`numba_threads`, which sets the count only when it
differs from the current one (Numba's setting is thread-local: it affects only
the parallel regions this thread launches) and restores it after, so the
evaluations inside a one-thread fit do not flip it on every call (each
``set_num_threads`` costs a few µs).

Public objects
--------------
- :class:`numba_threads` — context manager: Numba's thread count inside the block.
"""

from __future__ import annotations

import numba

__all__ = ["numba_threads"]


class numba_threads:  # noqa: N801 - used as a function: `with numba_threads(1):`
    """Numba's thread count *n* inside the ``with`` block (this thread's parallel
    regions only), restored after; ``None`` or the current count: nothing is set."""

    __slots__ = ("n", "restore")

    def __init__(self, n: int | None):
        self.n = n
        self.restore: int | None = None

    def __enter__(self) -> numba_threads:
        if self.n is not None:
            current = numba.get_num_threads()
            if current != self.n:
                numba.set_num_threads(self.n)
                self.restore = current
        return self

    def __exit__(self, *exc) -> None:
        if self.restore is not None:
            numba.set_num_threads(self.restore)
            self.restore = None
