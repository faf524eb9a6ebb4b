"""
The compiled kernels of pumped models
=====================================

A pumped model's kernel is composed from its root's (or base's) kernel and
:class:`brdfkit.tables.Lookup` reads (``docs/pumping.md``, "Evaluation: one
lookup for a whole chain"):

- :func:`chain_kernel` — f_root · q(max(N·L, N·V)) for a chain of stages with
  non-decreasing albedos, one lookup however many stages;
- :func:`stage_kernel` — f_base / g for one stage, two albedo lookups, as
  eq. (20)/(21) is written.

Each is generated with its own compiled loop (:func:`brdfkit.models._drivers.composed`:
the base kernel inlined, the module cached on disk, so the next process loads it) and
memoised per (kernel, structure). :data:`G_NUMPY` holds the built-in g in
NumPy for models evaluated without a kernel.
"""

from __future__ import annotations

import numpy as np

from brdfkit.models._drivers import composed
from brdfkit.tables import _lookup

__all__ = ["G_NUMPY", "chain_kernel", "stage_kernel"]

# The kernels' templates (models/_drivers.composed): plain functions whose globals below
# are bound per composition — the base kernel, the compile-time table offset and flags —
# and compiled, with their checked loop, into one generated module cached on disk.
root_kernel = base_kernel = None  # a kernel (ix, iy, iz, ox, oy, oz, p) -> float
k = depth = 0  # offsets into the packed row
capped = controlled = False  # eq. (17) cap; controlled g (eq. 21)


def _chain(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
    f = root_kernel(ix, iy, iz, ox, oy, oz, p)  # 0 below the horizon
    if f == 0.0:
        return 0.0  # nothing to pump (outside the lobe, below the horizon)
    q = _lookup(p, k, iz if iz > oz else oz)
    if capped and q < 1.0:
        q = 1.0  # eq. (17) g <= 1 for every stage
    return f * q


def _stage(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
    f = base_kernel(ix, iy, iz, ox, oy, oz, p)  # 0 below the horizon
    if f == 0.0:
        return 0.0
    off = int(p[p.shape[0] - depth])
    a_i = _lookup(p, off, iz)
    a_o = _lookup(p, off, oz)
    g = a_i if a_i > a_o else a_o
    if capped and g > 1.0:
        g = 1.0  # eq. (17) g <= 1
    if controlled:
        if iz > g:
            g = iz
        if oz > g:
            g = oz
    return f / g


def chain_kernel(root_kernel, k: int, capped: bool):
    """(kernel, driver) for f·q(max(N·L, N·V)), a chain of monotone stages (cached).

    Packed parameters of one channel (``p``): the root model's K parameters,
    then the :class:`Lookup` of q = 1/∏ g_j at the constant offset K (then
    possibly later stages' lookups and the offsets trailer, see
    :meth:`brdfkit.pumping.PumpedBRDF._pack`). The root kernel reads its parameters from the
    front of ``p`` — no slicing, and a compile-time offset: both measurably
    cheaper than reading the offset from ``p`` and slicing. *capped*: every
    stage caps g at 1, so q ≥ 1 exactly (the lookup's margin may dip below 1
    where q = 1; raising it back keeps q̃ ≤ q because q ≥ 1 there).
    """
    return composed(_chain, root_kernel=root_kernel, k=int(k), capped=bool(capped))


def stage_kernel(base_kernel, controlled: bool, capped: bool, depth: int):
    """(kernel, driver) for f/g of stage number *depth*, two albedo lookups (cached).

    The base kernel (pumped or not) reads the same packed row ``p``; this
    stage's :class:`Lookup` starts at ``p[len(p) - depth]`` (the offsets trailer
    of :meth:`brdfkit.pumping.PumpedBRDF._pack`), so stages nest without slicing. *capped*:
    g ≤ 1 (eq. 17) is applied after the lookup (whose margin may exceed 1
    where a = 1).
    """
    return composed(_stage, base_kernel=base_kernel, controlled=bool(controlled),
                    capped=bool(capped), depth=int(depth))


def _g_max(wi, wo, a_i, a_o):
    return np.maximum(a_i, a_o)


def _g_controlled(wi, wo, a_i, a_o):
    g = np.maximum(a_i, a_o)
    cz = np.maximum(wi[..., 2], wo[..., 2])
    return np.maximum(g, cz[..., None] if g.ndim > cz.ndim else cz)


G_NUMPY = {"max": _g_max, "controlled": _g_controlled}
