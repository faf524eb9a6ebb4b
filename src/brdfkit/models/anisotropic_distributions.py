"""
Anisotropic microfacet distributions
====================================

GGX and Beckmann with two roughnesses, α_x along brdfkit's tangent X (+x) and α_y
along the bitangent Y (+y), as one set of formulas (:mod:`brdfkit._dual`: compiled by
Numba, traced by Dr.Jit) and one NumPy object each (:func:`anisotropic_distribution`)
whose methods are the NumPy versions of the same formulas
(:func:`brdfkit._dual.numpy_version`): nothing is written twice. They are the
isotropic distributions of :mod:`brdfkit.models.microfacet_distributions` with
the slope scaled per axis, and they reuse its pieces (:func:`d_ggx_of_u`,
:func:`d_beckmann_of_t`, :func:`beckmann_dg_core`, :func:`ggx_g1_over_cos_r2`,
:func:`_beckmann_g1_over_cos_r`, :func:`tan2_half`); at α_x = α_y they equal the
isotropic ones to rounding (``tests/test_microfacet_anisotropic.py``).

With q(h) = (h_x/α_x)² + (h_y/α_y)² (so q/h_z² = tan²θ_h (cos²φ_h/α_x² + sin²φ_h/α_y²)):

- D_GGX(h) = 1/(π α_x α_y (h_z² + q)²) and D_Beckmann(h) = e^{−q/h_z²}/(π α_x α_y h_z⁴)
  (Heitz 2014 §5.3: the isotropic D of the slopes stretched by α_x, α_y);
- Smith Λ and G₁ = 1/(1 + Λ) of the isotropic distributions with the projected
  roughness α(ω) = √(cos²φ α_x² + sin²φ α_y²) (Heitz 2014 §5.3):
  α(ω)² tan²θ = (α_x² ω_x² + α_y² ω_y²)/ω_z²;
- the sampler of D(h) cos θ_h: φ_h the direction of (α_x cos 2πu₁, α_y sin 2πu₁), i.e.
  tan φ_h = (α_y/α_x) tan 2πu₁ in the right quadrant, and tan²θ_h the isotropic one with
  α² → α(φ_h)² = α_x² cos²2πu₁ + α_y² sin²2πu₁ = 1/(cos²φ_h/α_x² + sin²φ_h/α_y²)
  (the marginal of φ_h is 1/(2π α_x α_y (cos²φ_h/α_x² + sin²φ_h/α_y²)) for both
  distributions).

Public objects
--------------
- :func:`q_of`, :func:`d_of_h_anisotropic`, :func:`sample_half_anisotropic`,
  :func:`r2_of` (α(ω)² sin²θ) — formulas.
- :class:`AnisotropicGGX`, :class:`AnisotropicBeckmann` — NumPy distribution objects
  (:class:`~brdfkit.models.sampling.HalfVectorDistribution`: ``d``, ``pdf``, ``sample``,
  and ``lambda_``, ``g1``); :func:`anisotropic_distribution` dispatches.

References
----------
- [Heitz2014] E. Heitz, *Understanding the Masking-Shadowing Function in
  Microfacet-Based BRDFs*, JCGT 3(2), 2014, §5.3 (anisotropic distributions by stretching; equation
  numbers not cited: the paper is not on this machine).
- [Walter2007] eqs. (25)-(28), (33)-(35) (the isotropic distributions).
"""

from __future__ import annotations

import math

import numpy as np

from brdfkit._array import stack
from brdfkit._dual import cos, formula, numpy_version, select, sin, sqrt
from brdfkit.models.microfacet_distributions import (
    TWO_PI,
    d_beckmann_of_t,
    d_ggx_of_u,
    tan2_half,
)
from brdfkit.models.sampling import HalfVectorDistribution

__all__ = ["q_of", "r2_of", "d_of_h_anisotropic", "sample_half_anisotropic", "AnisotropicGGX",
           "AnisotropicBeckmann", "anisotropic_distribution"]


@formula
def q_of(x, y, ax, ay):
    """(x/α_x)² + (y/α_y)²: the slope term of the anisotropic D (x, y of h or of s = ω_i + ω_o)."""
    x = x / ax
    y = y / ay
    return x * x + y * y


@formula
def r2_of(x, y, ax, ay):
    """α(ω)² sin²θ = α_x² ω_x² + α_y² ω_y² of a unit direction ω (Heitz 2014 §5.3)."""
    x = x * ax
    y = y * ay
    return x * x + y * y


@formula
def d_of_h_anisotropic(hx, hy, hz, ax, ay, ggx):
    """D(h) of the anisotropic GGX (*ggx* true) or Beckmann at a unit vector h (formula).

    0 for h_z ≤ 0; Beckmann 0 where q/h_z² > 700 (D < 1e-290), as the isotropic
    :func:`~brdfkit.models.microfacet_distributions.d_of_h`.
    """
    hz2 = hz * hz
    q = q_of(hx, hy, ax, ay)
    a2 = ax * ay
    up = hz > 0.0
    if ggx:
        d = d_ggx_of_u(hz2 + q, a2)  # no 1 − cos²: ≥ 1/(16 π α_x α_y)-bounded bracket
    else:
        t = (hx * hx + hy * hy) / hz2  # tan²θ_h (NaN or inf only where h_z ≤ 0: selected)
        d, up = d_beckmann_of_t(t, -q / hz2, a2, up)
    return select(up, d, 0.0)


@formula
def sample_half_anisotropic(u0, u1, ax, ay, ggx):
    """A half vector h with density D(h) cos θ_h from u₀, u₁ ∈ [0, 1) (formula).

    (cos φ_h, sin φ_h) = (α_x cos 2πu₁, α_y sin 2πu₁)/α(φ_h) with α(φ_h)² the squared
    length, tan²θ_h = :func:`tan2_half` (u₀, α(φ_h)²) (module docstring); no atan, no
    quadrant cases. At α_x = α_y = α it is the isotropic sampler to rounding.
    """
    phi = TWO_PI * u1
    cx = ax * cos(phi)
    cy = ay * sin(phi)
    a2 = cx * cx + cy * cy  # α(φ_h)² ≥ min(α_x, α_y)² > 0
    tan2 = tan2_half(u0, a2, ggx)
    cos_h = 1.0 / sqrt(1.0 + tan2)
    s = sqrt(tan2) * cos_h / sqrt(a2)  # sin θ_h/α(φ_h): tan θ cos θ, exact for tiny θ
    return s * cx, s * cy, cos_h


@formula
def _d_ggx(hx, hy, hz, ax, ay):
    return d_of_h_anisotropic(hx, hy, hz, ax, ay, True)


@formula
def _d_beckmann(hx, hy, hz, ax, ay):
    return d_of_h_anisotropic(hx, hy, hz, ax, ay, False)


@formula
def _half_ggx(u0, u1, ax, ay):
    return sample_half_anisotropic(u0, u1, ax, ay, True)


@formula
def _half_beckmann(u0, u1, ax, ay):
    return sample_half_anisotropic(u0, u1, ax, ay, False)


class _Anisotropic(HalfVectorDistribution):
    """D, its D cos θ_h sampler and pdf, Λ and G₁ on NumPy arrays: the NumPy versions of
    the formulas above (subclasses name theirs)."""

    _d = _half = None

    def __init__(self, alpha_x: float, alpha_y: float):
        self.alpha_x, self.alpha_y = float(alpha_x), float(alpha_y)

    def __repr__(self) -> str:
        return f"{type(self).__name__}(alpha_x={self.alpha_x!r}, alpha_y={self.alpha_y!r})"

    def d(self, h: np.ndarray) -> np.ndarray:
        """D(h) at unit vectors h (..., 3); 0 for h_z ≤ 0."""
        with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
            return numpy_version(type(self)._d)(h[..., 0], h[..., 1], h[..., 2], self.alpha_x,
                                                self.alpha_y)

    def pdf(self, h: np.ndarray) -> np.ndarray:
        """Solid-angle density D(h) cos θ_h of :meth:`sample`."""
        return self.d(h) * np.maximum(h[..., 2], 0.0)

    def sample(self, u: np.ndarray) -> np.ndarray:
        """h (..., 3) with density D cos θ_h from u (..., 2) (:func:`sample_half_anisotropic`)."""
        x, y, z = numpy_version(type(self)._half)(u[..., 0], u[..., 1], self.alpha_x,
                                                  self.alpha_y)
        return stack(x, y, z)

    def a(self, w: np.ndarray) -> np.ndarray:
        """a = 1/(α(ω) tan θ) = cos θ/√(α_x² ω_x² + α_y² ω_y²) of unit directions (inf at N)."""
        with np.errstate(divide="ignore"):
            r2 = numpy_version(r2_of)(w[..., 0], w[..., 1], self.alpha_x, self.alpha_y)
            return w[..., 2] / np.sqrt(r2)

    def g1(self, w: np.ndarray) -> np.ndarray:
        """Smith G₁ = 1/(1 + Λ(ω)) for ω above the horizon (0 below)."""
        return np.where(w[..., 2] > 0.0, 1.0 / (1.0 + self.lambda_(w)), 0.0)


class AnisotropicGGX(_Anisotropic):
    """Anisotropic GGX / Trowbridge–Reitz (α_x along +x, α_y along +y), NumPy side."""

    _d, _half = _d_ggx, _half_ggx

    def lambda_(self, w: np.ndarray) -> np.ndarray:
        """Λ = (√(1 + 1/a²) − 1)/2 (Heitz 2014 §5.3 with the GGX Λ)."""
        with np.errstate(divide="ignore"):
            return 0.5 * (np.sqrt(1.0 + 1.0 / self.a(w) ** 2) - 1.0)


class AnisotropicBeckmann(_Anisotropic):
    """Anisotropic Beckmann (α_x along +x, α_y along +y), NumPy side."""

    _d, _half = _d_beckmann, _half_beckmann

    def lambda_(self, w: np.ndarray) -> np.ndarray:
        """Λ = (erf a − 1)/2 + e^{−a²}/(2a√π) (Walter eq. 27 before its fit, a of α(ω))."""
        from scipy.special import erf  # SciPy only where Λ itself is asked for

        a = self.a(w)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            lam = 0.5 * (erf(a) - 1.0) + np.exp(-a * a) / (2.0 * a * math.sqrt(math.pi))
        return np.where(np.isinf(a), 0.0, lam)  # a = inf (normal incidence): no masking


_KINDS = {"ggx": AnisotropicGGX, "beckmann": AnisotropicBeckmann}


def anisotropic_distribution(kind: str, alpha_x: float, alpha_y: float) -> _Anisotropic:
    """The NumPy object of the anisotropic *kind* ("ggx", "beckmann") with α_x, α_y."""
    return _KINDS[kind](alpha_x, alpha_y)
