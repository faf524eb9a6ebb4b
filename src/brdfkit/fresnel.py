"""
Fresnel reflectance
===================

Free functions of the cosine of the angle between the incident direction and
the (micro)surface normal, used by the models the way the papers write them.
Each exists twice from one source: a scalar ``@njit`` function (prefix ``_``)
that model kernels call, and a NumPy ufunc compiled from the same Python
source for the public API. Arguments broadcast. The dielectric and conductor
reflectances are formulas of :mod:`brdfkit._dual` (selects only, names such as
``sqrt`` instead of ``math.sqrt``), so the Mitsuba bridge traces the same code
with Dr.Jit; the models' kernels call these (``_fresnel_dielectric``,
``_fresnel_conductor``), never a copy.

Public objects
--------------
- :func:`fresnel_dielectric` — exact unpolarised reflectance of a dielectric
  with relative index η (Cook & Torrance 1982, as printed in Lewis §3.2).
- :func:`fresnel_conductor` — exact unpolarised reflectance for a complex
  index η + iκ (conductors); equals :func:`fresnel_dielectric` at κ = 0.
- :func:`fresnel_schlick` — Schlick's approximation F₀ + (1 − F₀)(1 − c)⁵.
- :func:`f0_from_eta` — normal-incidence reflectance ((η − 1)/(η + 1))².
- :func:`fresnel_moments` — F(1) and the cosine-weighted average 2∫₀¹ F(μ) μ dμ of the
  conductor reflectance (Kulla & Conty 2017's F_avg), per channel.

References
----------
- R. L. Cook, K. E. Torrance, *A Reflectance Model for Computer Graphics*,
  ACM TOG 1(1), 1982, eq. for F (reproduced in Lewis 1993 §3.2).
- M. Pharr, W. Jakob, G. Humphreys, *Physically Based Rendering*, 3rd ed.,
  §8.2.1 (``FrConductor``, the real-arithmetic form used here, rewritten as sums
  of squares); 4th ed. §9.3.6 (the same via the complex refraction cosine).
- C. Schlick, *An Inexpensive BRDF Model for Physically-based Rendering*,
  CGF 13(3), 1994.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from brdfkit._cache import memo
from brdfkit._dual import absolute, formula, maximum, minimum, select, sqrt

__all__ = ["fresnel_dielectric", "fresnel_conductor", "fresnel_schlick", "f0_from_eta",
           "fresnel_moments"]


def _fresnel_dielectric_py(c: float, eta: float) -> float:
    # Cook & Torrance's F in g and c (Lewis §3.2). A formula (brdfkit._dual), the one every
    # kernel with a dielectric Fresnel calls (nielsen, torrance-sparrow, cook-torrance, the
    # ABC surrogate): total internal reflection is a select, so that it vectorises inside
    # the compiled kernels and Dr.Jit can trace it.
    c = minimum(maximum(c, 0.0), 1.0)  # clamp: a cosine of unit vectors (rounding)
    g2 = eta * eta + c * c - 1.0
    tir = g2 <= 0.0  # total internal reflection (possible only for eta < 1): F = 1
    g = sqrt(select(tir, 1.0, g2))  # 1.0: the discarded lane stays finite
    gpc = g + c
    gmc = g - c
    a = c * gpc - 1.0
    b = c * gmc + 1.0
    return select(tir, 1.0, 0.5 * (gmc * gmc) / (gpc * gpc) * (1.0 + (a * a) / (b * b)))


TINY = 5e-324  # the smallest positive float64, a divisor floor of _fresnel_conductor_py


def _fresnel_conductor_py(c: float, eta: float, k: float) -> float:
    # Real arithmetic, exact for every η > 0, κ ≥ 0 (no complex division: the complex form
    # divided by n² and overflowed to a 0/0 for η ≲ 1e-154). With n = η + iκ, write
    # n cos θ_t = √(n² − sin²θ) = a + ib (principal root, a, b ≥ 0); then
    #   R_s = |c − (a + ib)|²/|c + (a + ib)|² = ((c − a)² + b²)/((c + a)² + b²),
    #   R_p/R_s = ((ac − s²)² + (bc)²)/((ac + s²)² + (bc)²),  s² = sin²θ,
    # (pbrt-v3's FrConductor expanded into sums of squares, so that nothing cancels:
    # F ≈ 2.5e-9 at η = 1.0001 keeps its relative accuracy). a² + b² = A = |n² − s²| and
    # a² − b² = t₀ = η² − κ² − s²; the smaller of a², b² is formed as 2η²κ²/(A ± t₀) instead
    # of (A ∓ t₀)/2, which would cancel for small κ. A formula (brdfkit._dual): selects
    # only, so that it vectorises inside the compiled kernels and Dr.Jit can trace it.
    c = minimum(maximum(c, 0.0), 1.0)  # clamp: a cosine of unit vectors, see above
    s2 = (1.0 - c) * (1.0 + c)  # sin²θ, accurate also near c = 1
    e2 = eta * eta
    ek2 = e2 * (k * k)
    t0 = e2 - k * k - s2
    big = sqrt(t0 * t0 + 4.0 * ek2)  # A
    # A + |t₀| is 0 only when t₀ = 0 = ηκ: then a = b = 0. The floor TINY (not a select of
    # the divisor, which LLVM turns back into a 0/0 that raises NumPy's "invalid" flag)
    # keeps that lane 0/TINY = 0; the select covers float32, where TINY rounds to 0.
    apt = big + absolute(t0)
    small2 = select(apt > 0.0, 2.0 * ek2 / maximum(apt, TINY), 0.0)
    pos = t0 >= 0.0
    a2 = select(pos, 0.5 * apt, small2)
    b2 = select(pos, small2, 0.5 * apt)
    a = sqrt(a2)
    num_s = (c - a) * (c - a) + b2
    den_s = (c + a) * (c + a) + b2
    ac = a * c
    num_p = (ac - s2) * (ac - s2) + b2 * (c * c)
    den_p = (ac + s2) * (ac + s2) + b2 * (c * c)
    # a denominator is 0 only with a = b = 0 (η and κ below ~1e-154, their squares 0):
    # R_s = 1 at c = 0 (grazing) and R_p = R_s at c = 1 (normal incidence), the limits
    rs = select(den_s > 0.0, num_s / maximum(den_s, TINY), 1.0)  # floor: as apt above
    ratio_p = select(den_p > 0.0, num_p / maximum(den_p, TINY), 1.0)
    return 0.5 * rs * (1.0 + ratio_p)


def _fresnel_schlick_py(c: float, f0: float) -> float:
    c = min(max(c, 0.0), 1.0)  # clamp: a cosine of unit vectors, see above
    m = 1.0 - c
    m2 = m * m
    return f0 + (1.0 - f0) * m2 * m2 * m


# Scalar kernels for model code (inlined into the compiled model kernels).
_fresnel_dielectric = formula(_fresnel_dielectric_py)  # Numba; Dr.Jit: _dual.drjit_version
_fresnel_conductor = formula(_fresnel_conductor_py)  # Numba; Dr.Jit: _dual.drjit_version
_fresnel_schlick = numba.njit(cache=True, inline="always")(_fresnel_schlick_py)

# The array versions, compiled (or loaded from Numba's cache) on first use: building a
# ufunc's wrapper costs ~0.1-0.3 s even from the cache, which every `import brdfkit` paid
# before (most commands never call these).
_UFUNC_SPECS = {
    "dielectric": ("float64(float64, float64)", _fresnel_dielectric_py),
    "conductor": ("float64(float64, float64, float64)", _fresnel_conductor_py),
    "schlick": ("float64(float64, float64)", _fresnel_schlick_py),
}


@memo(maxsize=len(_UFUNC_SPECS))  # one per array version (a rebuild costs 0.1-0.3 s)
def _ufunc(name: str):
    signature, py_func = _UFUNC_SPECS[name]
    return numba.vectorize([signature], cache=True)(py_func)


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
    return _ufunc("dielectric")(np.asarray(cos_theta, dtype=np.float64), eta)


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
    return _ufunc("conductor")(np.asarray(cos_theta, dtype=np.float64), eta, k_arr)


def fresnel_schlick(cos_theta, f0):
    """Schlick's approximation F₀ + (1 − F₀)(1 − cos θ)⁵ (Schlick 1994, eq. 24)."""
    f0_arr = np.asarray(f0, dtype=np.float64)
    if np.any(~((f0_arr >= 0.0) & (f0_arr <= 1.0))):
        raise ValueError(f"f0 must lie in [0, 1]; got {f0!r}")
    return _ufunc("schlick")(np.asarray(cos_theta, dtype=np.float64), f0_arr)


def f0_from_eta(eta):
    """Normal-incidence reflectance ((η − 1)/(η + 1))² of a dielectric."""
    eta = _check_positive("eta", eta)
    return ((eta - 1.0) / (eta + 1.0)) ** 2


#: Gauss–Legendre nodes per panel of :func:`fresnel_moments`: on each panel F is analytic
#: in t (below), so 64 nodes reach rounding (tests/test_compensation.py checks 1e-13
#: against scipy.integrate.quad).
_MOMENT_NODES = 64


def fresnel_moments(eta, k=0.0) -> tuple[np.ndarray, np.ndarray]:
    """F₀ = F(1) and F_avg = 2∫₀¹ F(μ) μ dμ of :func:`fresnel_conductor`, per channel.

    F_avg is the cosine-weighted hemispherical average of Kulla & Conty 2017 (slide
    "Multiple scattering: Fresnel", their F_avg). For η < 1 (κ = 0) F = 1 below the
    critical cosine μ_c = √(1 − η²) and has a square-root edge there: the rule splits
    [0, 1] at μ_c and substitutes μ = μ_c + (1 − μ_c) t² on the upper panel, which makes
    the integrand smooth (also for small κ > 0, where the edge is rounded).

    Parameters
    ----------
    eta, k : array_like (C,) or scalar
        The complex index η + iκ (η > 0, κ ≥ 0), broadcast against each other.

    Returns
    -------
    (f0, f_avg) : two 1-D arrays of the broadcast shape (at least one element).
    """
    eta = np.atleast_1d(_check_positive("eta", eta))
    k = np.atleast_1d(np.asarray(k, dtype=np.float64))
    if np.any(~(k >= 0.0)):
        raise ValueError(f"k (extinction coefficient) must be >= 0; got {k!r}")
    eta, k = np.broadcast_arrays(eta, k)
    x, w = np.polynomial.legendre.leggauss(_MOMENT_NODES)
    t, wt = 0.5 * (x + 1.0), 0.5 * w  # on [0, 1]
    conductor = _ufunc("conductor")
    f0 = conductor(1.0, eta, k)
    f_avg = np.empty_like(f0)
    for j, (e, kk) in enumerate(zip(eta.ravel(), k.ravel(), strict=True)):
        mu_c = math.sqrt(max(1.0 - e * e, 0.0))  # 0 for η ≥ 1: one panel
        mu = mu_c * t  # the lower panel [0, μ_c] (empty for η ≥ 1)
        lower = float(np.sum(wt * 2.0 * mu * conductor(mu, e, kk))) * mu_c
        mu = mu_c + (1.0 - mu_c) * t * t  # dμ = 2(1 − μ_c) t dt
        upper = float(np.sum(wt * 2.0 * mu * conductor(mu, e, kk) * 2.0 * (1.0 - mu_c) * t))
        f_avg.ravel()[j] = lower + upper
    return f0.ravel(), f_avg.ravel()
