"""
The compiled kernels of compensated models
==========================================

A compensated model's kernel wraps its base's kernel with reads of the base's
tabulated white-form albedo Ẽ(μ) (:class:`brdfkit.tables.Lookup`), like the
pumped models' (:mod:`brdfkit.pumping.kernels`): each is generated with its own
compiled loop (:func:`brdfkit.models._drivers.composed`: the base kernel inlined, the
module cached on disk) and memoised per (base kernel, offset).

Packed row of one channel (``p``): the base's K parameters, then the channel's
constant at ``p[K]`` (Kulla–Conty: F_ms/(π(1 − E_avg)); Turquin: F₀), then the
:class:`~brdfkit.tables.Lookup` of Ẽ at ``p[K + 1:]`` (padded to the longest
channel's). The lookup is an upper bound of min(E, 1) within its margin; the kernels
clamp what they read at 1 (:func:`_e`), so 1 − Ẽ ≥ 0 and the compensated albedo
1 + E − Ẽ never exceeds 1 by the table's error (``docs/compensation.md``).

- :func:`kulla_conty_kernel` — f_base + c (1 − Ẽ(μ_i))(1 − Ẽ(μ_o));
- :func:`turquin_kernel` — f_base (1 + F₀ (1 − Ẽ(μ_i))/Ẽ(μ_i)).
"""

from __future__ import annotations

import numba

from brdfkit.models._drivers import VECTOR_OPTIONS, composed
from brdfkit.tables import _lookup

__all__ = ["kulla_conty_kernel", "turquin_kernel"]

# The templates' globals, bound per composition (models/_drivers.composed): the base kernel
# and the compile-time offset of the channel's constant.
base_kernel = None  # a kernel (ix, iy, iz, ox, oy, oz, p) -> float
k = 0


@numba.njit(cache=True, inline="always", **VECTOR_OPTIONS)
def _e(p, off, mu):  # pragma: no cover - compiled (inlined into the templates)
    e = _lookup(p, off, mu)
    return e if e < 1.0 else 1.0  # clamp (a select): the lookup's margin may exceed min(E, 1) = 1


def _kulla_conty(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
    f = base_kernel(ix, iy, iz, ox, oy, oz, p)  # 0 below the horizon
    # branch-free (a select), so that the "vector" loop vectorises it; _lookup clamps μ to
    # [0, 1], so the lanes below the horizon read in bounds and are discarded
    e_i = _e(p, k + 1, iz)
    e_o = _e(p, k + 1, oz)
    ms = p[k] * (1.0 - e_i) * (1.0 - e_o)
    return f + (ms if (iz > 0.0) & (oz > 0.0) else 0.0)


def _turquin(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
    f = base_kernel(ix, iy, iz, ox, oy, oz, p)  # 0 below the horizon
    e_i = _e(p, k + 1, iz)  # >= E_FLOOR > 0 (brdfkit.compensation.table): no 0/0
    return f * (1.0 + p[k] * (1.0 - e_i) / e_i)


def _options(vector: bool) -> tuple[str, dict]:
    return ("vector", {"inline": "always", **VECTOR_OPTIONS}) if vector else ("checked", None)


def kulla_conty_kernel(base_kernel, k: int, *, vector: bool = False):
    """(kernel, driver) of f_base + p[k] (1 − Ẽ(N·L))(1 − Ẽ(N·V)) (cached). *vector*: the
    base kernel is branch-free and total (a formula of :mod:`brdfkit._dual`), so the
    composition runs in the vectorising loop."""
    loop, options = _options(vector)
    return composed(_kulla_conty, loop=loop, options=options, base_kernel=base_kernel, k=int(k))


def turquin_kernel(base_kernel, k: int, *, vector: bool = False):
    """(kernel, driver) of f_base (1 + p[k] (1 − Ẽ(N·L))/Ẽ(N·L)) (cached); *vector* as
    :func:`kulla_conty_kernel`."""
    loop, options = _options(vector)
    return composed(_turquin, loop=loop, options=options, base_kernel=base_kernel, k=int(k))
