"""Scalar building blocks for the compiled model kernels.

Kernels receive the components of wi = (ix, iy, iz) and wo = (ox, oy, oz) in
the local frame (n = +z). These inlined helpers name the dot products the
papers use, so that kernels read like the equations: N·L is ``iz``, N·V is
``oz``, R·V is :func:`r_dot_v`, N·H is :func:`n_dot_h`. :func:`half` and
:func:`n_dot_h` stay exact when the components of L + V are so small that their
squares underflow (both directions within ~1e-154 of the horizon):
:data:`SMALL_LENGTH`, :func:`scaled_length`.
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


# |L + V| is computed from squared components; when all of them are below ~1e-154 the squares
# underflow (both directions within ~1e-154 of the horizon and nearly opposite), the sum is
# 0 or subnormal and H = s/|s| would be 0/0, inf or inaccurate. Below this length the
# components are first scaled by the largest one (exact: a division by a positive number),
# which costs one compare on the common path. 1e-140: a component whose square underflows
# (< 2.3e-308) then changes |s|² ≥ 1e-280 by < 1e-27 relative.
SMALL_LENGTH = 1e-140


@_jit
def scaled_length(x, y, z) -> float:
    """√(x² + y² + z²) without underflow: the slow path for lengths below SMALL_LENGTH."""
    m = max(abs(x), abs(y), abs(z))
    if m == 0.0:
        return 0.0
    a, b, c = x / m, y / m, z / m
    return m * math.sqrt(a * a + b * b + c * c)


@_jit
def half(ix, iy, iz, ox, oy, oz):
    """Unit half vector H = (L + V)/|L + V| and |L + V|.

    Returns (hx, hy, hz, length). When L = −V the bisector is undefined;
    the normal is returned with length 0 so that callers can treat it.
    Above the horizon L + V has z-component N·L + N·V > 0, so H is defined;
    it is computed without underflow also when every component of L + V is
    subnormal (see SMALL_LENGTH), where H may still be far from the normal.
    """
    hx = ix + ox
    hy = iy + oy
    hz = iz + oz
    length = math.sqrt(hx * hx + hy * hy + hz * hz)
    if length < SMALL_LENGTH:
        length = scaled_length(hx, hy, hz)  # rare: squares underflowed
        if length == 0.0:
            return 0.0, 0.0, 1.0, 0.0
        # divide by the largest component first: length/m ≥ 1 is normal, so no 1/length
        # overflow or subnormal quotient
        m = max(abs(hx), abs(hy), abs(hz))
        r = length / m
        return (hx / m) / r, (hy / m) / r, (hz / m) / r, length
    return hx / length, hy / length, hz / length, length


@_jit
def n_dot_h(ix, iy, iz, ox, oy, oz) -> float:
    """N·H = (N·L + N·V)/|L + V| (without underflow; see :func:`half`)."""
    s = iz + oz
    hx = ix + ox
    hy = iy + oy
    length = math.sqrt(hx * hx + hy * hy + s * s)
    if length < SMALL_LENGTH:
        m = max(abs(hx), abs(hy), abs(s))  # rare: squares underflowed; scale first
        if m == 0.0:
            return 0.0
        a, b, c = hx / m, hy / m, s / m
        return c / math.sqrt(a * a + b * b + c * c)
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
