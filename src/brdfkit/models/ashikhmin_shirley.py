"""
The Ashikhmin–Shirley anisotropic Phong model
=============================================

Ashikhmin & Shirley (2000): an anisotropic Phong lobe of the half vector with
Schlick's Fresnel factor, and a diffuse term coupled to it so that the sum stays
below 1 (energy) while f(k₁, k₂) = f(k₂, k₁) (reciprocity). With k₁ = ω_i, k₂ = ω_o,
k·h = ω_i·h = ω_o·h, μ = cos θ and h = (ω_i + ω_o)/|ω_i + ω_o|:

- specular, eq. (4):
  ρ_s = √((n_u + 1)(n_v + 1))/(8π) · (n·h)^{(n_u h_x² + n_v h_y²)/(1 − (n·h)²)}
  / ((k·h) max(μ_i, μ_o)) · F(k·h), with Schlick's F = R_s + (1 − R_s)(1 − k·h)⁵;
  the exponent n_u cos²φ_h + n_v sin²φ_h written with h_x², h_y² (no φ_h, no
  singularity at h = n, where (n·h)^e = 1 whatever e);
- diffuse, eq. (5):
  ρ_d = 28 R_d/(23π) (1 − R_s)(1 − (1 − μ_i/2)⁵)(1 − (1 − μ_o/2)⁵).

28/23 is the constant that makes 2 ∫₀¹ (28/23)(1 − (1 − μ/2)⁵) μ dμ = 1 (the integral
is 23/56), so the diffuse albedo is R_d (1 − R_s)(1 − (1 − μ_i/2)⁵) in closed form
(``tests/test_ashikhmin_shirley.py``). The equation numbers are those of the JGT paper
as we know it (the paper is not on this machine); the formulas are checked by a second
implementation in angles, closed forms and identities, not against the paper's text.

Parameters
----------
=====  =======  ===========  ======================================================
name   default  bounds       meaning
=====  =======  ===========  ======================================================
n_u    10       [0, 1e4]     Phong exponent for h tilting along the tangent X (+x):
                             large n_u keeps h near the normal in x (a narrow
                             highlight along x)
n_v    100      [0, 1e4]     the exponent along the bitangent Y (+y)
R_s    0.05     [0, 1]       specular reflectance at normal incidence (Schlick's F₀;
                             per channel): 0.04-0.05 dielectrics, 0.5-1 metals
R_d    0.5      [0, 1]       diffuse reflectance (per channel), scaled by 1 − R_s
=====  =======  ===========  ======================================================

Guidance: n_u = n_v is an isotropic Phong lobe of exponent n; n_u ≠ n_v brushed
materials (the paper's examples use 10–10 000). Exponents above ~1e4 are sharper than
the albedo engine was checked at.

Public objects
--------------
- :class:`AshikhminShirley` — ``ashikhmin-shirley``.
- :func:`ashikhmin_shirley`, :func:`as_sample`, :func:`as_pdf`, :func:`as_half`,
  :func:`as_half_pdf` — its formulas (kernel, the mixture sampler and its density,
  the half-vector sampler of §3 and its density).
- :class:`AshikhminShirleyHalf` — the half-vector distribution on NumPy arrays
  (the NumPy versions of the formulas).

References
----------
- [Ashikhmin2000] M. Ashikhmin, P. Shirley, *An Anisotropic Phong BRDF Model*,
  Journal of Graphics Tools 5(2), 2000, eqs. (4) and (5), §3 (sampling:
  φ_h = arctan(√((n_u+1)/(n_v+1)) tan(πu₁/2)) per quadrant,
  cos θ_h = (1 − u₂)^{1/(n_u cos²φ_h + n_v sin²φ_h + 1)},
  p_h = √((n_u+1)(n_v+1))/(2π) (n·h)^{n_u cos²φ_h + n_v sin²φ_h},
  p(k₂) = p_h/(4 k₁·h)).
- [Schlick1994] C. Schlick, *An Inexpensive BRDF Model for Physically-based
  Rendering*, Computer Graphics Forum 13(3), 1994 (the Fresnel approximation).
"""

from __future__ import annotations

import math

import numpy as np

from brdfkit._array import stack
from brdfkit._dual import (
    Formulas,
    cos,
    formula,
    log1p,
    maximum,
    minimum,
    numpy_version,
    power,
    select,
    sin,
    sqrt,
)
from brdfkit._kern import exp_nonpos
from brdfkit.halfangle import beta_from_exponent
from brdfkit.models._base import BRDF, Lobe, Param
from brdfkit.models._params import packed_indices
from brdfkit.models._registry import register
from brdfkit.models.microfacet import cos_d_of, half_sum, reflection_jacobian
from brdfkit.models.microfacet_distributions import U0_MAX
from brdfkit.models.sampling import (
    COSINE,
    HalfVector,
    HalfVectorDistribution,
    Mixture,
    StrategySampled,
    malley,
)

__all__ = ["AshikhminShirley", "AshikhminShirleyHalf", "ashikhmin_shirley", "as_sample",
           "as_pdf", "as_half", "as_half_pdf"]

PARAMS = (
    Param("n_u", 10.0, 0.0, 1e4, "",
          "Phong exponent along the tangent X (+x): h_x tilts less as it grows"),
    Param("n_v", 100.0, 0.0, 1e4, "", "Phong exponent along the bitangent Y (+y)"),
    Param("R_s", 0.05, 0.0, 1.0, "",
          "specular reflectance at normal incidence (Schlick's F0): 0.05 dielectric",
          kind="colour"),
    Param("R_d", 0.5, 0.0, 1.0, "", "diffuse reflectance (scaled by 1 - R_s)", kind="colour"),
)
P_NU, P_NV, P_RS, P_RD = packed_indices(PARAMS, "n_u", "n_v", "R_s", "R_d")

INV_8PI = 1.0 / (8.0 * math.pi)
INV_2PI = 1.0 / (2.0 * math.pi)
INV_PI = 1.0 / math.pi
TWO_PI = 2.0 * math.pi
DIFFUSE_NORM = 28.0 / (23.0 * math.pi)  # eq. (5): 2∫(28/23)(1 − (1 − μ/2)⁵)μ dμ = 1
# floor of (k·h) max(μ_i, μ_o) ≥ max(μ)²/2: only both directions within 1e-140 of the
# horizon reach it; it keeps ρ_s ≤ √((n_u+1)(n_v+1))/(8π·1e-280) < 1e281 finite.
DEN_FLOOR = 1e-280
# the Fresnel average 2∫(1 − μ)⁵ μ dμ = 1/21 of Schlick's (1 − R_s) part: the specular
# weight of the sampler's mixture is R_s + (1 − R_s)/21 (an estimate of its albedo).
SCHLICK_AVG = 1.0 / 21.0


@formula
def pow5(x):
    """x⁵ by multiplications (no libm call: vectorises)."""
    x2 = x * x
    return x2 * x2 * x


@formula
def as_lobe(hx2, hy2, hxy2, l2, nu, nv):
    """(n·h)^{(n_u h_x² + n_v h_y²)/(1 − (n·h)²)} from the squared components of s (any
    length; l2 = |s|²): exp(e/2 · ln(1 − |s_xy|²/|s|²)), log1p exact near the normal, and
    e = (n_u s_x² + n_v s_y²)/|s_xy|² (1 − (n·h)² = |h_xy|²: no cancellation). 1 at h = n."""
    flat = hxy2 > 0.0
    e = (nu * hx2 + nv * hy2) / select(flat, hxy2, 1.0)  # 1.0: h = n, the power is 1 anyway
    # ≤ 0: e ≥ 0 and ln(1 − y) ≤ 0 for y ∈ [0, 1] (NaN only in discarded lanes)
    return exp_nonpos(0.5 * select(flat, e, 0.0) * log1p(-hxy2 / l2))


@formula
def ashikhmin_shirley(ix, iy, iz, ox, oy, oz, p):
    """ρ_s + ρ_d of eqs. (4), (5) (module docstring) for one channel's row *p* (formula).

    Branch-free and total: s = ω_i + ω_o rescaled when short (``half_sum``), k·h = |s|/2,
    the lobe from :func:`as_lobe`; 0 at and below the horizon.
    """
    nu, nv, rs, rd = p[P_NU], p[P_NV], p[P_RS], p[P_RD]
    live = (iz > 0.0) & (oz > 0.0)
    sx, sy, sz, small = half_sum(ix, iy, iz, ox, oy, oz)
    sx2 = sx * sx
    sy2 = sy * sy
    sxy2 = sx2 + sy2
    l2 = select(live, sxy2 + sz * sz, 1.0)  # 1.0: discarded lanes finite
    kh = minimum(cos_d_of(l2, small), 1.0)  # k·h = |s|/2 ≤ 1 (min: rounding)
    lobe = as_lobe(sx2, sy2, sxy2, l2, nu, nv)
    fres = rs + (1.0 - rs) * pow5(1.0 - kh)
    den = maximum(kh * maximum(iz, oz), DEN_FLOOR)
    spec = sqrt((nu + 1.0) * (nv + 1.0)) * INV_8PI * lobe * fres / den
    diff = (DIFFUSE_NORM * rd * (1.0 - rs) * (1.0 - pow5(1.0 - 0.5 * iz))
            * (1.0 - pow5(1.0 - 0.5 * oz)))
    return select(live, spec + diff, 0.0)


# --------------------------------------------------------------------------- sampling
@formula
def as_half(u0, u1, nu, nv):
    """h from u₀, u₁ ∈ [0, 1) with density :func:`as_half_pdf` (§3, formula).

    φ_h is the direction of (√(n_v+1) cos 2πu₁, √(n_u+1) sin 2πu₁): tan φ_h =
    √((n_u+1)/(n_v+1)) tan 2πu₁ in the quadrant of 2πu₁, which is the paper's
    arctan(√((n_u+1)/(n_v+1)) tan(πξ/2)) applied per quadrant without atan or cases;
    cos θ_h = (1 − u₀)^{1/(n_u cos²φ_h + n_v sin²φ_h + 1)}.
    """
    psi = TWO_PI * u1
    cx = sqrt(nv + 1.0) * cos(psi)
    cy = sqrt(nu + 1.0) * sin(psi)
    r = sqrt(cx * cx + cy * cy)  # ≥ 1
    c = cx / r
    s = cy / r
    e = nu * (c * c) + nv * (s * s) + 1.0
    cos_h = power(1.0 - minimum(u0, U0_MAX), 1.0 / e)  # clamp: u₀ = 1 is θ_h = 90°
    sin_h = sqrt(maximum(0.0, 1.0 - cos_h * cos_h))  # clamp: rounding
    return sin_h * c, sin_h * s, cos_h


@formula
def as_half_pdf(hx, hy, hz, nu, nv):
    """p_h(h) = √((n_u+1)(n_v+1))/(2π) (n·h)^{n_u cos²φ_h + n_v sin²φ_h} (§3), 0 for h_z ≤ 0."""
    hx2 = hx * hx
    hy2 = hy * hy
    up = hz > 0.0
    lobe = as_lobe(hx2, hy2, hx2 + hy2, select(up, hx2 + hy2 + hz * hz, 1.0), nu, nv)
    return select(up, sqrt((nu + 1.0) * (nv + 1.0)) * INV_2PI * lobe, 0.0)


@formula
def as_sample(ox, oy, oz, u0, u1, nu, nv, w_d):
    """ω_i from (u₀, u₁): the cosine when u₀ < w_d (the diffuse term), else the mirror of ω_o
    about h from :func:`as_half`, u₀ rescaled into its interval (both evaluated)."""
    pick_cos = u0 < w_d
    uc = minimum(u0 / maximum(w_d, 1e-30), 1.0)  # floor: w_d = 0 (never picked), clamp: rounding
    us = maximum((u0 - w_d) / maximum(1.0 - w_d, 1e-30), 0.0)  # floor: w_d = 1 (never picked)
    cx, cy, cz = malley(uc, u1)
    hx, hy, hz = as_half(us, u1, nu, nv)
    c = 2.0 * (ox * hx + oy * hy + oz * hz)
    return (select(pick_cos, cx, c * hx - ox),
            select(pick_cos, cy, c * hy - oy), select(pick_cos, cz, c * hz - oz))


@formula
def as_pdf(ix, iy, iz, ox, oy, oz, nu, nv, w_d):
    """Density of :func:`as_sample` over the sphere: w_d cos⁺θ_i/π + (1 − w_d) p_h/(4|ω_o·h|)
    (§3); 0 when ω_o is at or below the horizon."""
    hx, hy, hz, ok, jac = reflection_jacobian(ix, iy, iz, ox, oy, oz)
    ps = select(ok, as_half_pdf(hx, hy, hz, nu, nv) / jac, 0.0)
    return select(oz > 0.0, w_d * maximum(iz, 0.0) * INV_PI + (1.0 - w_d) * ps, 0.0)


class AshikhminShirleyHalf(HalfVectorDistribution):
    """The half-vector density p_h of §3 on NumPy arrays (:func:`as_half`, :func:`as_half_pdf`
    through :func:`~brdfkit._dual.numpy_version`)."""

    def __init__(self, n_u: float, n_v: float):
        self.n_u, self.n_v = float(n_u), float(n_v)

    def __repr__(self) -> str:
        return f"AshikhminShirleyHalf(n_u={self.n_u!r}, n_v={self.n_v!r})"

    def sample(self, u):
        return stack(*numpy_version(as_half)(u[..., 0], u[..., 1], self.n_u, self.n_v))

    def pdf(self, h):
        with np.errstate(divide="ignore", invalid="ignore"):
            return numpy_version(as_half_pdf)(h[..., 0], h[..., 1], h[..., 2], self.n_u,
                                              self.n_v)


@register
class AshikhminShirley(StrategySampled, BRDF):
    """Ashikhmin & Shirley (2000) anisotropic Phong BRDF, eqs. (4) + (5) (module docstring).

    Reciprocal (both terms are symmetric in ω_i, ω_o); not isotropic for n_u ≠ n_v.
    Energy: the paper claims conservation (albedo ≤ 1 for R_s, R_d ≤ 1: the specular
    lobe normalised by max(μ_i, μ_o), the diffuse term scaled by 1 − R_s); measured with
    the albedo engine in ``tests/test_ashikhmin_shirley.py``: max 0.9960 (R_s = 1,
    n_u = n_v = 1000, θ_i = 0), 31/32 + the Schlick tail at R_s = 0. Sampled by the
    paper's half-vector sampler (§3) mixed with the cosine for the diffuse term.
    """

    name = "ashikhmin-shirley"
    aliases = ("as2000", "anisotropic-phong", "ashikhmin")
    summary = "Ashikhmin-Shirley 2000 anisotropic Phong: n_u, n_v lobe, Schlick F, coupled diffuse"
    params = PARAMS
    citation = "Ashikhmin & Shirley 2000, eqs. (4) (specular) and (5) (diffuse), §3 sampling"
    reciprocal = True
    isotropic = False
    has_sampler = True
    kernel = ashikhmin_shirley
    # The specular denominator's max(μ_i, μ_o) kinks ω_o ↦ f on N·V = N·L; declared as
    # albedo_kinks {"nv=nl"} it changed no error estimate of the albedo engine (θ_i 30-89.9°,
    # φ_i = 45°, n = 10/1000 and 10/10) and cost up to twice the time: left to refinement.
    # At grazing incidence the lobe peaks as 1/((k·h) μ_i) near the horizon, where the
    # engine may stop at its refinement limit (status and error estimate say so).
    examples = (
        {},
        {"n_u": 1000.0, "n_v": 10.0, "R_s": [0.9, 0.6, 0.3], "R_d": [0.1, 0.2, 0.3]},
        {"n_u": 0.0, "n_v": 0.0, "R_s": 0.0, "R_d": 1.0},
        {"n_u": 5000.0, "n_v": 5000.0, "R_s": 1.0, "R_d": 0.0},
    )

    def _weight_diffuse(self) -> float:
        """w_d: the diffuse term's share of the mixture, R_d(1 − R_s) against R_s + (1 − R_s)/21
        (channel means; SCHLICK_AVG); 1/2 when both are 0."""
        rs = np.asarray(self._values["R_s"], dtype=float)
        d = float(np.mean(np.asarray(self._values["R_d"], dtype=float) * (1.0 - rs)))
        s = float(np.mean(rs + (1.0 - rs) * SCHLICK_AVG))
        return 0.5 if d + s <= 0.0 else d / (d + s)

    def lobes(self):
        v = self._values
        n = max(float(v["n_u"]), float(v["n_v"]))
        # the sharper axis sets the resolution (cosⁿβ = 1/2); n = 0: a flat lobe
        out = [Lobe("half", float(beta_from_exponent(n)))] if n > 0.0 else []
        if np.any(np.asarray(v["R_d"]) > 0.0) or not out:
            out.append(Lobe("diffuse", math.pi / 2))
        return out

    def _strategy(self, wo):
        w_d = self._weight_diffuse()
        lobe = HalfVector(AshikhminShirleyHalf(self._values["n_u"], self._values["n_v"]),
                          fold=False)
        return Mixture([COSINE, lobe], [w_d, 1.0 - w_d])

    def formulas(self) -> Formulas:
        """The kernel, :func:`as_sample` and :func:`as_pdf`, args (n_u, n_v, w_d)."""
        v = self._values
        return Formulas(eval=ashikhmin_shirley, sample=as_sample, pdf=as_pdf,
                        args=(float(v["n_u"]), float(v["n_v"]), self._weight_diffuse()))
