"""Scalar building blocks for the compiled model kernels.

Kernels receive the components of wi = (ix, iy, iz) and wo = (ox, oy, oz) in
the local frame (n = +z). These inlined helpers name the dot products the
papers use, so that kernels read like the equations: N·L is ``iz``, N·V is
``oz``, R·V is :func:`r_dot_v`, N·H is :func:`n_dot_h`.
"""

from __future__ import annotations

import math

import numba

INV_PI = 1.0 / math.pi
INV_TWO_PI = 1.0 / (2.0 * math.pi)
_jit = numba.njit(cache=True, inline="always")


@_jit
def below_horizon(iz: float, oz: float) -> bool:
    """True when either direction is at or below the horizon (the BRDF is 0 there)."""
    return iz <= 0.0 or oz <= 0.0


@_jit
def dot3(ax, ay, az, bx, by, bz) -> float:
    return ax * bx + ay * by + az * bz


@_jit
def r_dot_v(ix, iy, iz, ox, oy, oz) -> float:
    """R·V with R = 2N(N·L) − L the mirror of L: 2(N·L)(N·V) − L·V (symmetric in L, V)."""
    return 2.0 * iz * oz - (ix * ox + iy * oy + iz * oz)


@_jit
def half(ix, iy, iz, ox, oy, oz):
    """Unit half vector H = (L + V)/|L + V| and |L + V|.

    Returns (hx, hy, hz, length). When L = −V the bisector is undefined;
    the normal is returned with length 0 so that callers can treat it.
    """
    hx = ix + ox
    hy = iy + oy
    hz = iz + oz
    length = math.sqrt(hx * hx + hy * hy + hz * hz)
    if length <= 1e-300:
        return 0.0, 0.0, 1.0, 0.0
    return hx / length, hy / length, hz / length, length


@_jit
def n_dot_h(ix, iy, iz, ox, oy, oz) -> float:
    """N·H = (N·L + N·V)/|L + V|."""
    s = iz + oz
    hx = ix + ox
    hy = iy + oy
    length = math.sqrt(hx * hx + hy * hy + s * s)
    if length <= 1e-300:
        return 0.0
    return s / length


@_jit
def pos(x: float) -> float:
    """max(0, x) — the clamp every lobe applies outside its support."""
    return x if x > 0.0 else 0.0


@_jit
def pos_pow(x: float, n: float) -> float:
    """max(0, x)ⁿ with 0⁰ = 1 (so n = 0 is a constant lobe, as Lewis §7 uses)."""
    if x <= 0.0:
        return 1.0 if n == 0.0 else 0.0
    return x**n
