"""
Geometry of the local shading frame
===================================

Vectorised helpers on directions of shape ``(..., 3)`` in the frame with the
normal ``n = +z`` (see :mod:`brdfkit` for the conventions).

Public objects
--------------
- :func:`spherical_to_cartesian`, :func:`cartesian_to_spherical`
- :func:`reflect` — mirror direction about the normal (Lewis's R_l).
- :func:`half_vector` — normalised bisector H of two directions.
- :func:`to_rusinkiewicz`, :func:`from_rusinkiewicz` — half/difference
  angles (θ_h, θ_d, φ_d) of Rusinkiewicz 1998, as used by MERL.
- :func:`merl_theta_h` — MERL's quadratic θ_h grid θ_h = (π/2)u², u ∈ [0, 1]
  (the bins, the fitting samples and edges, the explorer's θ_h axis).
- :func:`sample_uniform_hemisphere`, :func:`pdf_uniform_hemisphere`
- :func:`sample_cosine_hemisphere`, :func:`pdf_cosine_hemisphere`
- :func:`frame_around` — an orthonormal frame whose third axis is a given
  direction (used to sample lobes about R or to integrate in a lobe's frame).

References
----------
- S. Rusinkiewicz, *A New Change of Variables for Efficient BRDF
  Representation*, EGWR 1998.
- T. Duff et al., *Building an Orthonormal Basis, Revisited*, JCGT 6(1), 2017
  (the branch-free frame used by :func:`frame_around`).
"""

from __future__ import annotations

import numpy as np

from brdfkit._array import as_directions, as_uniform, stack

__all__ = [
    "spherical_to_cartesian",
    "cartesian_to_spherical",
    "reflect",
    "half_vector",
    "to_rusinkiewicz",
    "from_rusinkiewicz",
    "merl_theta_h",
    "sample_uniform_hemisphere",
    "pdf_uniform_hemisphere",
    "sample_cosine_hemisphere",
    "pdf_cosine_hemisphere",
    "frame_around",
    "rotate_z",
    "rotate_y",
]


def spherical_to_cartesian(theta, phi) -> np.ndarray:
    """Unit vector(s) at polar angle *theta* from +z and azimuth *phi* (radians)."""
    theta = np.asarray(theta, dtype=np.float64)
    phi = np.asarray(phi, dtype=np.float64)
    s = np.sin(theta)
    return stack(s * np.cos(phi), s * np.sin(phi), np.cos(theta))


def cartesian_to_spherical(v) -> tuple[np.ndarray, np.ndarray]:
    """Polar angle θ ∈ [0, π] and azimuth φ ∈ (−π, π] of direction(s) *v*.

    Robust at the pole: θ comes from ``arctan2(|v_xy|, v_z)`` rather than
    ``arccos(v_z)``, which loses half the digits near θ = 0.
    """
    v = as_directions(v, "v")
    rho = np.hypot(v[..., 0], v[..., 1])
    return np.arctan2(rho, v[..., 2]), np.arctan2(v[..., 1], v[..., 0])


def reflect(v) -> np.ndarray:
    """Mirror direction of *v* about the normal: R = 2 n (n·v) − v."""
    v = as_directions(v, "v")
    r = -v.copy()
    r[..., 2] = v[..., 2]
    return r


def half_vector(wi, wo) -> np.ndarray:
    """Normalised bisector H = (wi + wo)/|wi + wo|.

    Where wi = −wo the bisector is undefined; the normal (0, 0, 1) is returned
    there (a zero-length sum would otherwise give NaN).
    """
    wi = as_directions(wi, "wi")
    wo = as_directions(wo, "wo")
    h = wi + wo
    norm = np.linalg.norm(h, axis=-1, keepdims=True)
    degenerate = norm[..., 0] <= 1e-300
    h = np.where(norm > 1e-300, h / np.where(norm > 1e-300, norm, 1.0), 0.0)
    h[degenerate] = (0.0, 0.0, 1.0)
    return h


def rotate_z(v: np.ndarray, angle) -> np.ndarray:
    """Rotate directions *v* by *angle* about +z (right-handed)."""
    c, s = np.cos(angle), np.sin(angle)
    return stack(c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1], v[..., 2])


def rotate_y(v: np.ndarray, angle) -> np.ndarray:
    """Rotate directions *v* by *angle* about +y (right-handed)."""
    c, s = np.cos(angle), np.sin(angle)
    return stack(c * v[..., 0] + s * v[..., 2], v[..., 1], -s * v[..., 0] + c * v[..., 2])


def to_rusinkiewicz(wi, wo) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Half/difference angles (θ_h, φ_h, θ_d, φ_d) of the pair (wi, wo).

    The difference vector d is wi rotated by −φ_h about z and then by −θ_h
    about y (Rusinkiewicz 1998, §3), so that H maps to the pole.
    """
    h = half_vector(wi, wo)
    theta_h, phi_h = cartesian_to_spherical(h)
    d = rotate_y(rotate_z(as_directions(wi, "wi"), -phi_h), -theta_h)
    theta_d, phi_d = cartesian_to_spherical(d)
    return theta_h, phi_h, theta_d, phi_d


def from_rusinkiewicz(theta_h, phi_h, theta_d, phi_d) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of :func:`to_rusinkiewicz`: the pair (wi, wo).

    wi = R_z(φ_h) R_y(θ_h) d and wo = R_z(φ_h) R_y(θ_h) d', with d' the mirror
    of d about the pole (the half vector in the rotated frame).
    """
    d = spherical_to_cartesian(theta_d, phi_d)
    d_mirror = stack(-d[..., 0], -d[..., 1], d[..., 2])
    wi = rotate_z(rotate_y(d, theta_h), phi_h)
    wo = rotate_z(rotate_y(d_mirror, theta_h), phi_h)
    return wi, wo


def merl_theta_h(u) -> np.ndarray:
    """θ_h = (π/2)·u² (radians) of MERL's quadratic θ_h spacing, for index coordinates
    u ∈ [0, 1] (u = (i + ½)/90 at bin i's centre): dense near the specular peak at
    θ_h = 0; dθ_h/du = π u. Computed as (u·u)·(π/2), the rounding every caller used."""
    u = np.asarray(u, dtype=np.float64)
    return u * u * (0.5 * np.pi)


def sample_uniform_hemisphere(u) -> np.ndarray:
    """Uniform direction on the upper hemisphere from *u* ∈ [0,1]² (pdf 1/2π)."""
    u = as_uniform(u)
    z = u[..., 0]
    r = np.sqrt(np.maximum(0.0, 1.0 - z * z))  # clamp: rounding can make 1 − z² < 0
    phi = 2.0 * np.pi * u[..., 1]
    return stack(r * np.cos(phi), r * np.sin(phi), z)


def pdf_uniform_hemisphere(w) -> np.ndarray:
    """Solid-angle density of :func:`sample_uniform_hemisphere` (0 below the horizon)."""
    w = as_directions(w, "w")
    return np.where(w[..., 2] > 0.0, 1.0 / (2.0 * np.pi), 0.0)


def sample_cosine_hemisphere(u) -> np.ndarray:
    """Cosine-distributed direction (pdf cos θ/π) from *u* ∈ [0,1]².

    Malley's method: a uniform point on the unit disk lifted to the
    hemisphere.
    """
    u = as_uniform(u)
    r = np.sqrt(u[..., 0])
    phi = 2.0 * np.pi * u[..., 1]
    x, y = r * np.cos(phi), r * np.sin(phi)
    z = np.sqrt(np.maximum(0.0, 1.0 - x * x - y * y))  # clamp: rounding at the rim
    return stack(x, y, z)


def pdf_cosine_hemisphere(w) -> np.ndarray:
    """Solid-angle density of :func:`sample_cosine_hemisphere`."""
    w = as_directions(w, "w")
    return np.maximum(w[..., 2], 0.0) / np.pi


def frame_around(axis) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Orthonormal (t, b, axis) with *axis* the third vector (Duff et al. 2017)."""
    a = as_directions(axis, "axis")
    x, y, z = a[..., 0], a[..., 1], a[..., 2]
    sign = np.where(z >= 0.0, 1.0, -1.0)
    p = -1.0 / (sign + z)
    q = x * y * p
    t = stack(1.0 + sign * x * x * p, sign * q, -sign * x)
    b = stack(q, sign + y * y * p, -y)
    return t, b, a


def local_to_world(local: np.ndarray, axis) -> np.ndarray:
    """Express directions given in the frame of :func:`frame_around` in the shading frame."""
    t, b, a = frame_around(axis)
    return (
        local[..., 0:1] * t + local[..., 1:2] * b + local[..., 2:3] * a
    )
