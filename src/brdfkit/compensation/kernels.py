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
channel's).

- :func:`kulla_conty_kernel` — f_base + c (1 − Ẽ(μ_i))(1 − Ẽ(μ_o));
- :func:`turquin_kernel` — f_base (1 + F₀ (1 − Ẽ(μ_i))/Ẽ(μ_i)).
"""

from __future__ import annotations

from brdfkit.models._drivers import composed
from brdfkit.tables import _lookup

__all__ = ["kulla_conty_kernel", "turquin_kernel"]

# The templates' globals, bound per composition (models/_drivers.composed): the base kernel
# and the compile-time offset of the channel's constant.
base_kernel = None  # a kernel (ix, iy, iz, ox, oy, oz, p) -> float
k = 0


def _kulla_conty(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
    f = base_kernel(ix, iy, iz, ox, oy, oz, p)  # 0 below the horizon
    if not (iz > 0.0 and oz > 0.0):
        return f
    e_i = _lookup(p, k + 1, iz)
    e_o = _lookup(p, k + 1, oz)
    return f + p[k] * (1.0 - e_i) * (1.0 - e_o)


def _turquin(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
    f = base_kernel(ix, iy, iz, ox, oy, oz, p)  # 0 below the horizon
    if f == 0.0:
        return 0.0
    e_i = _lookup(p, k + 1, iz)  # >= E_FLOOR > 0 (brdfkit.compensation.table)
    return f * (1.0 + p[k] * (1.0 - e_i) / e_i)


def kulla_conty_kernel(base_kernel, k: int):
    """(kernel, driver) of f_base + p[k] (1 − Ẽ(N·L))(1 − Ẽ(N·V)) (cached)."""
    return composed(_kulla_conty, base_kernel=base_kernel, k=int(k))


def turquin_kernel(base_kernel, k: int):
    """(kernel, driver) of f_base (1 + p[k] (1 − Ẽ(N·L))/Ẽ(N·L)) (cached)."""
    return composed(_turquin, base_kernel=base_kernel, k=int(k))
