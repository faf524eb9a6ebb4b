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

The same two as formulas (:mod:`brdfkit._dual`, for the Mitsuba bridge's traced
route), composed from the root's or base's eval formula: :func:`chain_formula`,
:func:`stage_formula`, :func:`pumped_formula`; the tables are read with
:func:`brdfkit.tables.lookup`.
"""

from __future__ import annotations

import numpy as np

from brdfkit._dual import compose, maximum, minimum, select
from brdfkit.models._drivers import composed
from brdfkit.tables import _lookup, lookup

__all__ = ["G_NUMPY", "chain_formula", "chain_kernel", "pumped_formula", "stage_formula",
           "stage_kernel"]

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


# The formulas' templates (brdfkit._dual.compose): the same compositions over a root's or
# base's eval *formula*, branch-free (selects), reading the tables with the primitive lookup.
root_eval = base_eval = None  # an eval formula (ix, iy, iz, ox, oy, oz, p) -> f_r


def _chain_f(ix, iy, iz, ox, oy, oz, p):
    f = root_eval(ix, iy, iz, ox, oy, oz, p)  # 0 below the horizon
    q = lookup(p, k, select(iz > oz, iz, oz))
    if capped:
        q = maximum(q, 1.0)  # eq. (17) g <= 1 for every stage (as _chain)
    return select(f == 0.0, 0.0, f * q)


def _stage_f(ix, iy, iz, ox, oy, oz, p):
    f = base_eval(ix, iy, iz, ox, oy, oz, p)  # 0 below the horizon
    off = p[-depth]  # the offsets trailer (as _stage's p[len(p) - depth])
    a_i = lookup(p, off, iz)
    a_o = lookup(p, off, oz)
    g = select(a_i > a_o, a_i, a_o)
    if capped:
        g = minimum(g, 1.0)  # eq. (17) g <= 1
    if controlled:
        g = maximum(maximum(g, iz), oz)
    return select(f == 0.0, 0.0, f / g)  # g >= G_FLOOR > 0 (the lookup's floor)


def chain_formula(root_eval, k: int, capped: bool):
    """:func:`chain_kernel` as a formula over the root's eval formula (memoised)."""
    return compose(_chain_f, root_eval=root_eval, k=int(k), capped=bool(capped))


def stage_formula(base_eval, controlled: bool, capped: bool, depth: int):
    """:func:`stage_kernel` as a formula over the base's eval formula (memoised)."""
    return compose(_stage_f, base_eval=base_eval, controlled=bool(controlled),
                   capped=bool(capped), depth=int(depth))


def pumped_formula(stage, root_eval):
    """The eval formula of the pumped model *stage* (a :class:`~brdfkit.pumping.PumpedBRDF`
    with a kernel) over its root's eval formula: the chain's, or its base's wrapped by this
    stage's two lookups, as its kernel is composed."""
    if stage.chained:
        return chain_formula(root_eval, stage.root.packed.shape[1],
                             all(s.capped for s in stage._chain))
    base = root_eval if stage.base is stage.root else pumped_formula(stage.base, root_eval)
    return stage_formula(base, stage.g == "controlled", stage.capped, stage.depth)


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
