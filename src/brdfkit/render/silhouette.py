"""
Anti-aliasing of the sphere's silhouette
========================================

The direct engine (:func:`brdfkit.render.sphere.render_sphere`) evaluates each pixel at
its centre: exact there, but a pixel the rim of the disc crosses is then all sphere or
all background, and the silhouette is a staircase. :func:`silhouette_pixels` finds the
pixels the rim may cross — those whose centre lies within half a pixel diagonal of the
unit circle, so every crossed pixel is among them — and :func:`silhouette_samples` gives
each an n × n grid of sub-pixel sample points (cell midpoints); :func:`terminator_pixels`
adds those the terminator N·L = 0 crosses (a shader with a 1/(N·L) factor jumps there).
The renderer replaces such a
pixel's value by the mean over its n² samples of the radiance at the sample (0 off the
sphere): the midpoint rule of the pixel's area average, whose error falls as 1/n² for the
smooth shading and as 1/n for the rim's coverage.

Public objects
--------------
- :func:`silhouette_pixels`, :func:`terminator_pixels`, :func:`edge_pixels`,
  :func:`silhouette_samples`, :func:`local_frame_pairs`,
  :data:`DEFAULT_ANTIALIAS`, :data:`MAX_ANTIALIAS`.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["silhouette_pixels", "terminator_pixels", "edge_pixels", "silhouette_samples",
           "local_frame_pairs",
           "DEFAULT_ANTIALIAS", "MAX_ANTIALIAS"]

#: Default sub-samples per axis of a silhouette pixel: 4 × 4 gives 17 coverage levels,
#: more than an 8-bit display of a rim that is one pixel wide can tell apart from 64.
DEFAULT_ANTIALIAS = 4
#: Most sub-samples per axis: 16² = 256 per rim pixel (about 10·S rim pixels: 2.6 M
#: evaluations at S = 1024, a second at most for a compiled model).
MAX_ANTIALIAS = 16


def silhouette_pixels(size: int) -> np.ndarray:
    """Flat indices (r·S + c) of the pixels whose centre is within half a pixel diagonal
    (√2/S in the image's [−1, 1] units) of the unit circle: every pixel the rim crosses."""
    c = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    rad = np.hypot(c[None, :], c[:, None])  # |(x, y)| of each centre (symmetric in x, y)
    near = np.abs(rad - 1.0) <= math.sqrt(2.0) / size
    return np.flatnonzero(near.reshape(-1))


def terminator_pixels(size: int, light) -> np.ndarray:
    """Flat indices of the pixels the terminator N·L = 0 crosses inside the disc: N·L > 0
    at some of the pixel's corners on the sphere and not at others (a corner off the
    sphere says nothing: its pixel is a rim pixel, :func:`silhouette_pixels`). Shaders
    with a 1/(N·L) factor (Lewis's F_s/(N·S)) are discontinuous there, so such a pixel
    needs its area average as the rim's does."""
    lx, ly, lz = light
    e = np.arange(size + 1) / size * 2.0 - 1.0  # corner coordinates
    x, y = e[None, :], -e[:, None]
    r2 = x * x + y * y
    on = r2 < 1.0
    lit = on & ((lx * x + ly * y + lz * np.sqrt(np.maximum(1.0 - r2, 0.0))) > 0.0)
    dark = on & ~lit

    def any4(a):
        return a[:-1, :-1] | a[:-1, 1:] | a[1:, :-1] | a[1:, 1:]

    return np.flatnonzero((any4(lit) & any4(dark)).reshape(-1))


def edge_pixels(size: int, light) -> np.ndarray:
    """The pixels to anti-alias: the rim's (:func:`silhouette_pixels`) and the
    terminator's (:func:`terminator_pixels`), sorted, each once."""
    return np.union1d(silhouette_pixels(size), terminator_pixels(size, light))


def silhouette_samples(size: int, index: np.ndarray, n: int):
    """(x, y) of the n × n cell midpoints of each pixel in *index*: two arrays (P, n²)."""
    r, col = np.divmod(np.asarray(index, dtype=np.int64), size)
    off = ((np.arange(n) + 0.5) / n - 0.5) * (2.0 / size)  # sub-cell midpoints
    ox, oy = np.meshgrid(off, off)
    x = ((col + 0.5) / size * 2.0 - 1.0)[:, None] + ox.reshape(1, -1)
    y = (1.0 - (r + 0.5) / size * 2.0)[:, None] - oy.reshape(1, -1)
    return x, y


def local_frame_pairs(x: np.ndarray, y: np.ndarray, light) -> tuple:
    """(inside, wi, wo, N·L) at image points (x, y) of the disc seen from V = +z, in the
    pixel's local frame: T the world x axis projected onto the tangent plane, B = N × T
    (the frame of :func:`brdfkit.render.sphere._lit_pixels`; s = √(1 − x²) > 0 inside).
    *inside* is a mask of the points strictly inside the disc; the arrays hold those only."""
    lx, ly, lz = light
    r2 = x * x + y * y
    inside = r2 < 1.0
    x, y = x[inside], y[inside]
    z = np.sqrt(1.0 - x * x - y * y)
    s = np.sqrt(1.0 - x * x)
    n_dot_l = lx * x + ly * y + lz * z
    wi = np.stack([(lx * (1.0 - x * x) - ly * x * y - lz * x * z) / s,
                   (ly * z - lz * y) / s, n_dot_l], axis=-1)
    wo = np.stack([-x * z / s, -y / s, z], axis=-1)
    return inside, wi, wo, n_dot_l
