"""
Microfacet models
=================

NDF, masking and Fresnel are free functions; each model combines them the way
its paper writes them.

Public objects
--------------
- :class:`Microfacet` — ``microfacet``: Walter et al. 2007, Beckmann or GGX,
  separable Smith masking, conductor/dielectric Fresnel.

References
----------
- [Walter2007] eqs. (20) (BRDF), (25)–(28) Beckmann D, G₁ and sampling,
  (33)–(35) GGX.
- [Lewis1993] eq. (10) and D₁–D₄; [Neumann1999] eqs. (8)–(10).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from brdfkit._array import as_directions, as_uniform, stack
from brdfkit._kern import below_horizon, half
from brdfkit.fresnel import _fresnel_conductor
from brdfkit.models._base import BRDF, Lobe, Param
from brdfkit.models._registry import register

_jit = numba.njit(cache=True, inline="always")
SQRT_PI = math.sqrt(math.pi)


# --------------------------------------------------------------------------- free functions
@_jit
def d_beckmann(cos_h: float, alpha: float) -> float:
    """Beckmann NDF, Walter eq. (25): exp(−tan²θ_h/α²)/(π α² cos⁴θ_h); 0 for cos θ_h ≤ 0."""
    if cos_h <= 0.0:
        return 0.0
    c2 = cos_h * cos_h
    tan2 = (1.0 - c2) / c2
    return math.exp(-tan2 / (alpha * alpha)) / (math.pi * alpha * alpha * c2 * c2)


@_jit
def d_ggx(cos_h: float, alpha: float) -> float:
    """GGX / Trowbridge–Reitz NDF, Walter eq. (33): α²/(π cos⁴θ_h (α² + tan²θ_h)²)."""
    if cos_h <= 0.0:
        return 0.0
    c2 = cos_h * cos_h
    a2 = alpha * alpha
    t = a2 * c2 + (1.0 - c2)  # = cos²θ_h (α² + tan²θ_h)
    return a2 / (math.pi * t * t)


@_jit
def smith_g1_beckmann(cos_v: float, cos_vh: float, alpha: float) -> float:
    """Exact Smith masking for Beckmann, Walter eq. (27) before its rational fit.

    G₁ = χ⁺(v·h / v·n) · 2/(1 + erf(a) + e^{−a²}/(a√π)), a = 1/(α tan θ_v).
    """
    if cos_v <= 0.0 or cos_vh <= 0.0:
        return 0.0
    sin_v = math.sqrt(max(0.0, 1.0 - cos_v * cos_v))  # clamp: rounding near the pole
    if sin_v == 0.0:
        return 1.0  # tan θ = 0: no masking at normal incidence
    a = cos_v / (alpha * sin_v)
    return 2.0 / (1.0 + math.erf(a) + math.exp(-a * a) / (a * SQRT_PI))


@_jit
def smith_g1_ggx(cos_v: float, cos_vh: float, alpha: float) -> float:
    """Smith masking for GGX, Walter eq. (34): 2/(1 + √(1 + α² tan²θ_v))."""
    if cos_v <= 0.0 or cos_vh <= 0.0:
        return 0.0
    c2 = cos_v * cos_v
    tan2 = max(0.0, 1.0 - c2) / c2  # clamp: rounding can make 1 − c² < 0
    return 2.0 / (1.0 + math.sqrt(1.0 + alpha * alpha * tan2))


BECKMANN, GGX = 0, 1


# --------------------------------------------------------------------------- Walter 2007
@numba.njit(cache=True)
def _microfacet(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    dist, alpha, eta, k, scale = p[0], p[1], p[2], p[3], p[4]
    hx, hy, hz, length = half(ix, iy, iz, ox, oy, oz)
    cos_ih = ix * hx + iy * hy + iz * hz  # = cos θ_d, the same for wo
    if dist == BECKMANN:
        d = d_beckmann(hz, alpha)
        g = smith_g1_beckmann(iz, cos_ih, alpha) * smith_g1_beckmann(oz, cos_ih, alpha)
    else:
        d = d_ggx(hz, alpha)
        g = smith_g1_ggx(iz, cos_ih, alpha) * smith_g1_ggx(oz, cos_ih, alpha)
    f = 1.0 if eta == 0.0 else _fresnel_conductor(cos_ih, eta, k)  # eta not given: F = 1
    return scale * f * d * g / (4.0 * iz * oz)


@register
class Microfacet(BRDF):
    """Rough conductor / dielectric reflection of Walter et al. (2007), eq. (20).

    f_r = F(ω_i·h) D(h) G₁(ω_i) G₁(ω_o) / (4 cos θ_i cos θ_o), separable Smith
    masking with the exact G₁ of each distribution. This is the model
    renderers use (Mitsuba's ``roughconductor``, pbrt's ``conductor``).

    ============  ==========  ============  ==========================================
    name          default     bounds        meaning
    ============  ==========  ============  ==========================================
    distribution  beckmann    beckmann/ggx  microfacet normal distribution
    alpha         0.1         (0, 4]        roughness (RMS slope for Beckmann);
                                            0.01 near-mirror, 0.1 glossy, 0.5 rough
    eta           None        (0, 100]      real index (per channel); None: F = 1
    k             0           [0, 100]      extinction (per channel); 0: dielectric
    rho_s         1           [0, 1]        specular scale (per channel)
    ============  ==========  ============  ==========================================

    Reciprocal. Energy: bounded by 1 with F ≤ 1 (only single scattering, so
    rough surfaces lose energy). Sampled by the distribution of normals
    D(h) cos θ_h (Walter eqs. 28, 35), pdf D cos θ_h / (4 |ω_o·h|).
    """

    name = "microfacet"
    aliases = ("walter", "roughconductor")
    summary = "Walter et al. 2007 microfacet BRDF (Beckmann/GGX, Smith, Fresnel)"
    params = (
        Param("distribution", "beckmann", kind="choice", choices=("beckmann", "ggx"),
              doc="microfacet normal distribution"),
        Param("alpha", 0.1, 0.0, 4.0, "", "roughness: 0.01 near-mirror, 0.1 glossy, 0.5 rough",
              lower_open=True),
        Param("eta", None, 0.0, 100.0, "", "real part of the index of refraction; none: F = 1",
              kind="colour", lower_open=True, optional=True),
        Param("k", 0.0, 0.0, 100.0, "", "extinction coefficient (conductors)", kind="colour"),
        Param("rho_s", 1.0, 0.0, 1.0, "", "specular scale", kind="colour"),
    )
    citation = "Walter et al. 2007, eq. (20) with (25)-(27) Beckmann, (33)-(34) GGX"
    reciprocal = True
    has_sampler = True
    kernel = _microfacet
    examples = (
        {},
        {"alpha": 0.01},
        {"distribution": "ggx", "alpha": 0.5, "eta": [0.2, 0.9, 1.1], "k": [3.9, 2.4, 2.2]},
        {"alpha": 1.0, "eta": 1.5},
    )

    def lobes(self):
        return [Lobe("half", float(self._values["alpha"]))]

    def _sample_normal(self, u: np.ndarray) -> np.ndarray:
        alpha = self._values["alpha"]
        u0 = u[..., 0]
        if self._values["distribution"] == "beckmann":
            tan2 = -alpha * alpha * np.log1p(-np.minimum(u0, 1.0 - 1e-16))  # Walter eq. (28)
        else:
            u0 = np.minimum(u0, 1.0 - 1e-16)  # clamp: u₀ = 1 maps to θ_h = 90°
            tan2 = alpha * alpha * u0 / (1.0 - u0)  # Walter eq. (35)
        cos_h = 1.0 / np.sqrt(1.0 + tan2)
        sin_h = np.sqrt(np.maximum(0.0, 1.0 - cos_h * cos_h))
        phi = 2.0 * np.pi * u[..., 1]
        return stack(sin_h * np.cos(phi), sin_h * np.sin(phi), cos_h)

    def _d(self, cos_h: np.ndarray) -> np.ndarray:
        alpha = self._values["alpha"]
        c = np.clip(cos_h, 1e-300, 1.0)  # clamp: avoid 0-division where D is 0 anyway
        c2 = c * c
        tan2 = (1.0 - c2) / c2
        if self._values["distribution"] == "beckmann":
            d = np.exp(-tan2 / alpha**2) / (np.pi * alpha**2 * c2 * c2)
        else:
            t = alpha**2 * c2 + (1.0 - c2)
            d = alpha**2 / (np.pi * t * t)
        return np.where(cos_h > 0.0, d, 0.0)

    def sample(self, wo, u):
        wo = as_directions(wo, "wo")
        u = as_uniform(u)
        h = self._sample_normal(u)
        h = np.broadcast_to(h, np.broadcast_shapes(h.shape, wo.shape))
        cos_oh = np.sum(wo * h, axis=-1, keepdims=True)
        wi = 2.0 * cos_oh * h - wo
        return wi, self.pdf(wi, wo)

    def pdf(self, wi, wo):
        wi = as_directions(wi, "wi")
        wo = as_directions(wo, "wo")
        h = wi + wo
        norm = np.linalg.norm(h, axis=-1)
        h = h / np.where(norm > 0.0, norm, 1.0)[..., None]
        cos_oh = np.abs(np.sum(wo * h, axis=-1))
        p = self._d(h[..., 2]) * h[..., 2] / (4.0 * np.where(cos_oh > 0.0, cos_oh, 1.0))
        return np.where((wo[..., 2] > 0.0) & (norm > 0.0) & (cos_oh > 0.0), p, 0.0)


