"""
Fresnel reflectance
===================

Free functions of the cosine of the angle between the incident direction and
the (micro)surface normal, used by the models the way the papers write them.
Each exists twice from one source: a scalar ``@njit`` function (prefix ``_``)
that model kernels call, and a NumPy ufunc compiled from the same Python
source for the public API. Arguments broadcast.

Public objects
--------------
- :func:`fresnel_dielectric` — exact unpolarised reflectance of a dielectric
  with relative index η (Cook & Torrance 1982, as printed in Lewis §3.2).
- :func:`fresnel_conductor` — exact unpolarised reflectance for a complex
  index η + iκ (conductors); equals :func:`fresnel_dielectric` at κ = 0.
- :func:`fresnel_schlick` — Schlick's approximation F₀ + (1 − F₀)(1 − c)⁵.
- :func:`f0_from_eta` — normal-incidence reflectance ((η − 1)/(η + 1))².

References
----------
- R. L. Cook, K. E. Torrance, *A Reflectance Model for Computer Graphics*,
  ACM TOG 1(1), 1982, eq. for F (reproduced in Lewis 1993 §3.2).
- M. Pharr, W. Jakob, G. Humphreys, *Physically Based Rendering*, 4th ed.,
  §9.3.6 (complex Fresnel via the complex refraction cosine).
- C. Schlick, *An Inexpensive BRDF Model for Physically-based Rendering*,
  CGF 13(3), 1994.
"""

from __future__ import annotations

import cmath
import math

import numba
import numpy as np

__all__ = ["fresnel_dielectric", "fresnel_conductor", "fresnel_schlick", "f0_from_eta"]


def _fresnel_dielectric_py(c: float, eta: float) -> float:
    # c is a cosine; clamp to [0, 1] because the callers pass dot products of
    # unit vectors, which rounding can push just outside that range.
    c = min(max(c, 0.0), 1.0)
    g2 = eta * eta + c * c - 1.0
    if g2 <= 0.0:
        # Total internal reflection (possible only for eta < 1).
        return 1.0
    g = math.sqrt(g2)
    gpc = g + c
    gmc = g - c
    a = c * gpc - 1.0
    b = c * gmc + 1.0
    return 0.5 * (gmc * gmc) / (gpc * gpc) * (1.0 + (a * a) / (b * b))


def _fresnel_conductor_py(c: float, eta: float, k: float) -> float:
    c = min(max(c, 0.0), 1.0)  # clamp: a cosine of unit vectors, see above
    n = complex(eta, k)
    sin2_i = 1.0 - c * c
    cos_t = cmath.sqrt(1.0 - sin2_i / (n * n))
    r_parl = (n * c - cos_t) / (n * c + cos_t)
    r_perp = (c - n * cos_t) / (c + n * cos_t)
    return 0.5 * (abs(r_parl) ** 2 + abs(r_perp) ** 2)


def _fresnel_schlick_py(c: float, f0: float) -> float:
    c = min(max(c, 0.0), 1.0)  # clamp: a cosine of unit vectors, see above
    m = 1.0 - c
    m2 = m * m
    return f0 + (1.0 - f0) * m2 * m2 * m


# Scalar kernels for model code (inlined into the compiled model kernels).
_fresnel_dielectric = numba.njit(cache=True, inline="always")(_fresnel_dielectric_py)
_fresnel_conductor = numba.njit(cache=True, inline="always")(_fresnel_conductor_py)
_fresnel_schlick = numba.njit(cache=True, inline="always")(_fresnel_schlick_py)

_ufunc_dielectric = numba.vectorize(["float64(float64, float64)"], cache=True)(
    _fresnel_dielectric_py
)
_ufunc_conductor = numba.vectorize(["float64(float64, float64, float64)"], cache=True)(
    _fresnel_conductor_py
)
_ufunc_schlick = numba.vectorize(["float64(float64, float64)"], cache=True)(_fresnel_schlick_py)


def _check_positive(name: str, value) -> np.ndarray:
    a = np.asarray(value, dtype=np.float64)
    if np.any(~(a > 0.0)):
        raise ValueError(f"{name} must be > 0 (a relative index of refraction); got {value!r}")
    return a


def fresnel_dielectric(cos_theta, eta):
    """Unpolarised Fresnel reflectance of a dielectric.

    Parameters
    ----------
    cos_theta : array_like
        Cosine of the angle between the incident direction and the normal of
        the reflecting (micro)surface; clamped to [0, 1].
    eta : array_like
        Relative index of refraction η = n_t/n_i (> 0). η < 1 gives total
        internal reflection past the critical angle.

    Returns
    -------
    ndarray
        F = (g−c)²/(2(g+c)²) · [1 + (c(g+c)−1)²/(c(g−c)+1)²] with c = cos θ and
        g² = η² + c² − 1 (Lewis §3.2). F(c=1) = ((η−1)/(η+1))², F(c=0) = 1.
    """
    eta = _check_positive("eta", eta)
    return _ufunc_dielectric(np.asarray(cos_theta, dtype=np.float64), eta)


def fresnel_conductor(cos_theta, eta, k):
    """Unpolarised Fresnel reflectance for the complex index η + iκ.

    Parameters
    ----------
    cos_theta : array_like
        Cosine of the incident angle to the (micro)surface normal; clamped to [0, 1].
    eta : array_like
        Real part of the relative index (> 0).
    k : array_like
        Extinction coefficient κ (≥ 0); κ = 0 is a dielectric.
    """
    eta = _check_positive("eta", eta)
    k_arr = np.asarray(k, dtype=np.float64)
    if np.any(~(k_arr >= 0.0)):
        raise ValueError(f"k (extinction coefficient) must be >= 0; got {k!r}")
    return _ufunc_conductor(np.asarray(cos_theta, dtype=np.float64), eta, k_arr)


def fresnel_schlick(cos_theta, f0):
    """Schlick's approximation F₀ + (1 − F₀)(1 − cos θ)⁵ (Schlick 1994, eq. 24)."""
    f0_arr = np.asarray(f0, dtype=np.float64)
    if np.any(~((f0_arr >= 0.0) & (f0_arr <= 1.0))):
        raise ValueError(f"f0 must lie in [0, 1]; got {f0!r}")
    return _ufunc_schlick(np.asarray(cos_theta, dtype=np.float64), f0_arr)


def f0_from_eta(eta):
    """Normal-incidence reflectance ((η − 1)/(η + 1))² of a dielectric."""
    eta = _check_positive("eta", eta)
    return ((eta - 1.0) / (eta + 1.0)) ** 2
