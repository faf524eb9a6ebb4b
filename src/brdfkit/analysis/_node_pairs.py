"""
The albedo engine's nodes as direction pairs for a model's own loop
===================================================================

Most models are integrated through their compiled kernel, called per node and channel
by the ``"albedo"`` loop of :mod:`brdfkit.models._drivers`. A model that brings its own
loop over pairs computing every channel in one pass (``BRDF._driver``: an NBRDF net,
one network evaluation for three channels; a measured table, one bin search for three)
is cheaper through that loop: the nodes are turned into the pairs (ω_i, ω_o) here —
compiled, the NumPy version of this bookkeeping cost more than the net — the loop runs
over all of them at once (in parallel when it is), and the values go back to the nodes.

The pairs are exactly those of the ``"albedo"`` loop: ω_i = (sin θ_i cos φ_i,
sin θ_i sin φ_i, cos θ_i) and the node ω_o rotated about the normal by φ_i; nodes at or
below the horizon (unused slots, rounding) are not evaluated and contribute 0; a
non-finite value is counted against its angle (which becomes NONFINITE) and stored as 0.

Public objects
--------------
- :func:`own_loop_evaluator` — ``evaluate(th, ph, offsets, wo) -> (vals, bad)`` for the
  engine's level loop, through ``model._driver``.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numba
import numpy as np

__all__ = ["own_loop_evaluator"]


@numba.njit(cache=True)
def _node_pairs(th, ph, offsets, wo, inc, out, slot):  # pragma: no cover - compiled
    """Write the pairs of the nodes above the horizon into inc/out; return their number."""
    k = 0
    for t in range(th.size):
        st, ct = math.sin(th[t]), math.cos(th[t])
        c, s = math.cos(ph[t]), math.sin(ph[t])
        for j in range(offsets[t], offsets[t + 1]):
            if wo[j, 2] > 0.0:
                inc[k, 0], inc[k, 1], inc[k, 2] = st * c, st * s, ct
                out[k, 0] = c * wo[j, 0] - s * wo[j, 1]
                out[k, 1] = s * wo[j, 0] + c * wo[j, 1]
                out[k, 2] = wo[j, 2]
                slot[k] = j
                k += 1
    return k


@numba.njit(cache=True)
def _gather(th_size, offsets, slot, k, got, vals, bad):  # pragma: no cover - compiled
    """vals[slot] = got (non-finite: 0, counted in bad[angle]); other slots 0."""
    vals[:] = 0.0
    q = 0
    for t in range(th_size):
        stop = offsets[t + 1]
        while q < k and slot[q] < stop:
            for c in range(got.shape[1]):
                v = got[q, c]
                if math.isfinite(v):
                    vals[slot[q], c] = v
                else:
                    bad[t] += 1
            q += 1


def own_loop_evaluator(model) -> tuple[Callable, int]:
    """(evaluate, n_channels) of the engine's level loop through ``model._driver``."""
    driver, data = model._driver, model._driver_data()
    n_channels = int(np.asarray(model.packed).shape[0])

    def evaluate(th, ph, offsets, wo):
        n = wo.shape[0]
        inc, out = np.empty((n, 3)), np.empty((n, 3))
        slot = np.empty(n, dtype=np.int64)
        k = _node_pairs(th, ph, offsets, wo, inc, out, slot)
        got = np.empty((k, n_channels))
        driver(inc[:k], out[:k], data, got)  # a pair the loop rejects is a NaN row: counted
        vals = np.empty((n, n_channels))
        bad = np.zeros(th.size, dtype=np.int64)
        _gather(th.size, offsets, slot, k, got, vals, bad)
        return vals, bad

    return evaluate, n_channels
