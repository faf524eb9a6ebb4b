"""
Microfacet models
=================

NDF, masking and Fresnel are free functions; each model combines them the way
its paper writes them.

Public objects
--------------
- :class:`Microfacet` — ``microfacet``: Walter et al. 2007, Beckmann or GGX,
  separable Smith masking, conductor/dielectric Fresnel.
- :func:`beckmann_g1_of_a` — Beckmann Smith G₁(a), a = cot θ/α, tabulated
  without libm calls (< 1e-13 relative); :func:`smith_g1_beckmann_exact` is the
  erf form it is tested against.
- :func:`ggx_g1_over_cos` — GGX G₁(v)/cos θ_v (Walter eq. 34) without a division
  by the cosine: finite and accurate down to cos θ_v = 0 (subnormal cosines).

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
from brdfkit._kern import INV_PI, SMALL_LENGTH, below_horizon, half, pos_pow
from brdfkit.errors import ParameterError
from brdfkit.fresnel import _fresnel_conductor, _fresnel_dielectric
from brdfkit.geometry import sample_cosine_hemisphere
from brdfkit.halfangle import (
    beckmann_m_from_beta,
    beta_from_beckmann_m,
    beta_from_exponent,
    beta_from_trowbridge_reitz_c,
    beta_from_ward_m,
    exponent_from_beta,
    gaussian_c_from_beta,
    trowbridge_reitz_c_from_beta,
    ward_m_from_beta,
)
from brdfkit.models._base import BRDF, Lobe, Param, _check_beta
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
    if c2 * 700.0 * alpha * alpha < 1.0 - c2:
        # tan²θ_h/α² > 700: D < e^{-700}(1 + 700α²)²/(πα²) < 1e-290 for α ≤ 4; returning 0
        # also avoids 0/0 when cos⁴θ_h underflows (both directions within 1e-77 of the horizon).
        return 0.0
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


def smith_g1_beckmann_exact(cos_v: float, cos_vh: float, alpha: float) -> float:
    """Exact Smith masking for Beckmann, Walter eq. (27) before its rational fit.

    G₁ = χ⁺(v·h / v·n) · 2/(1 + erf(a) + e^{−a²}/(a√π)), a = 1/(α tan θ_v),
    with ``math.erf``/``math.exp`` (pure Python; the reference that
    :func:`smith_g1_beckmann` is tested against).
    """
    if cos_v <= 0.0 or cos_vh <= 0.0:
        return 0.0
    sin_v = math.sqrt(max(0.0, 1.0 - cos_v * cos_v))  # clamp: rounding near the pole
    if sin_v == 0.0:
        return 1.0  # tan θ = 0: no masking at normal incidence
    a = cos_v / (alpha * sin_v)
    if a < 1e-150:
        # grazing: G₁ = 2a√π (1 + O(a)); also avoids 1/0 when a underflows to 0
        return 2.0 * a * SQRT_PI
    return 2.0 / (1.0 + math.erf(a) + math.exp(-a * a) / (a * SQRT_PI))


# Beckmann G₁ without erf/exp. Write G₁ = 2a√π / h(a) with
#     h(a) = a√π (1 + erf a) + e^{−a²},
# an entire function with h(0) = 1, increasing to h(6) ≈ 12√π; h is tabulated once at import
# as a piecewise polynomial: G1_INTERVALS equal intervals of [0, G1_A_MAX], on each the
# degree-G1_DEGREE interpolant at Chebyshev nodes (values from math.erf/math.exp), stored in
# the power basis of the local variable x ∈ [−1, 1]. Measured relative error of h, hence of
# G₁, on 10⁶ random points: < 3e-15 (tests/test_fast_kernels.py checks < 1e-13 against the
# math.erf form). Dividing by h (≥ 1) keeps the relative accuracy uniform down to a → 0,
# where G₁ → 2a√π.
# For a ≥ G1_A_MAX = 6, G₁ = 1 exactly in float64: 1 − G₁ = (e^{−a²}/(a√π) − erfc a)/2 + …
# ≤ e^{−36}/(6√π)/(4·36) ≈ 1.6e-19 < 2^{−53}.
G1_A_MAX = 6.0
G1_INTERVALS = 128
G1_DEGREE = 6


def _beckmann_h(a: float) -> float:
    return a * SQRT_PI * (1.0 + math.erf(a)) + math.exp(-a * a)


def _build_g1_table() -> np.ndarray:
    width = G1_A_MAX / G1_INTERVALS
    x = np.cos(np.pi * (np.arange(G1_DEGREE + 1) + 0.5) / (G1_DEGREE + 1))  # Chebyshev nodes
    table = np.empty((G1_INTERVALS, G1_DEGREE + 1))
    for k in range(G1_INTERVALS):
        y = np.array([_beckmann_h(k * width + (t + 1.0) * 0.5 * width) for t in x])
        cheb = np.polynomial.chebyshev.chebfit(x, y, G1_DEGREE)
        table[k] = np.polynomial.chebyshev.cheb2poly(cheb)
    return table


G1_TABLE = _build_g1_table()
_G1_INV_WIDTH = G1_INTERVALS / G1_A_MAX


@_jit
def _beckmann_h_poly(a: float) -> float:
    """h(a) from the table for 0 ≤ a ≤ G1_A_MAX (callers clamp a; no branch, no libm)."""
    k = min(int(a * _G1_INV_WIDTH), G1_INTERVALS - 1)  # min: a = 6 exactly
    x = (a - k * (1.0 / _G1_INV_WIDTH)) * (2.0 * _G1_INV_WIDTH) - 1.0
    h = G1_TABLE[k, 6]
    h = h * x + G1_TABLE[k, 5]
    h = h * x + G1_TABLE[k, 4]
    h = h * x + G1_TABLE[k, 3]
    h = h * x + G1_TABLE[k, 2]
    h = h * x + G1_TABLE[k, 1]
    return h * x + G1_TABLE[k, 0]


@_jit
def beckmann_g1_of_a(a: float) -> float:
    """Beckmann Smith G₁ as a function of a = cot θ_v/α ≥ 0 (piecewise polynomial, see above).

    Relative error < 1e-13 (measured < 3e-15) against the erf form for all
    a ≥ 0; exactly 1 for a ≥ 6 (including a = inf) and 0 at a = 0.
    """
    if a >= G1_A_MAX:
        return 1.0  # exact in float64, see the bound above
    return 2.0 * SQRT_PI * a / _beckmann_h_poly(a)


@_jit
def smith_g1_beckmann(cos_v: float, cos_vh: float, alpha: float) -> float:
    """Exact Smith masking for Beckmann, Walter eq. (27) before its rational fit.

    G₁ = χ⁺(v·h / v·n) · 2/(1 + erf(a) + e^{−a²}/(a√π)), a = 1/(α tan θ_v),
    evaluated by :func:`beckmann_g1_of_a` (relative error < 1e-13, no libm
    calls); :func:`smith_g1_beckmann_exact` is the erf form.
    """
    if cos_v <= 0.0 or cos_vh <= 0.0:
        return 0.0
    sin_v = math.sqrt(max(0.0, 1.0 - cos_v * cos_v))  # clamp: rounding near the pole
    if cos_v >= G1_A_MAX * alpha * sin_v:
        return 1.0  # a ≥ 6 (incl. sin θ = 0): G₁ = 1 exactly in float64, see G1_A_MAX
    # here sin_v > 0 and a < 6; a ≥ cos_v/α > 0 cannot underflow to 0 for cos_v > 0 normal
    return beckmann_g1_of_a(cos_v / (alpha * sin_v))


@_jit
def ggx_g1_over_cos(cos_v: float, alpha: float) -> float:
    """G₁(v)/cos θ_v for GGX (Walter eq. 34, v·h > 0 assumed): 2/(c + √(c² + α² sin²θ_v)).

    Equal to :func:`smith_g1_ggx` divided by c = cos θ_v (multiply the numerator and the
    denominator of 2/(1 + √(1 + α² tan²θ_v)) by c), but with no division by c or c²: the
    denominator is ≥ max(c, α sin θ_v) > 0, so the ratio is finite and accurate down to
    c = 0 (→ 2/α), where G₁ and c both underflow and G₁/c would be 0/0.
    """
    c2 = cos_v * cos_v
    return 2.0 / (cos_v + math.sqrt(c2 + alpha * alpha * max(0.0, 1.0 - c2)))  # clamp: rounding


@_jit
def smith_g1_ggx(cos_v: float, cos_vh: float, alpha: float) -> float:
    """Smith masking for GGX, Walter eq. (34): 2/(1 + √(1 + α² tan²θ_v))."""
    if cos_v <= 0.0 or cos_vh <= 0.0:
        return 0.0
    c2 = cos_v * cos_v
    tan2 = max(0.0, 1.0 - c2) / c2  # clamp: rounding can make 1 − c² < 0
    return 2.0 / (1.0 + math.sqrt(1.0 + alpha * alpha * tan2))


BECKMANN, GGX = 0, 1

# Kernel compile options of the fast kernels. error_model="numpy": IEEE division (no
# zero-divisor test per division; every division is guarded or harmless). fastmath
# "contract" only: a·b + c may become one fused multiply-add (more accurate, shorter
# dependency chains in the G₁ polynomial); no flag that assumes finite or non-NaN values.
_FAST = {"contract"}


# --------------------------------------------------------------------------- Walter 2007
@_jit
def _beckmann_dgg(iz, oz, sxy2, sz2, alpha):
    """D G₁(ω_i) G₁(ω_o)/(4 cos θ_i cos θ_o) for Beckmann, Walter eqs. (20), (25), (27).

    The fast path of :func:`_microfacet` (same values as d_beckmann and
    smith_g1_beckmann to ~1e-14 relative): four divisions instead of eleven,
    no libm call but one exp, and the G₁ = 1 cases as selects, not branches. With
    tan²θ_h = |s_xy|²/s_z² (s = wi + wo) and
    G₁(v)/cos θ_v = 2√π/(α sin θ_v h(a_v)) for a_v < 6 (1/cos θ_v for a_v ≥ 6,
    where G₁ = 1 exactly), the cosines cancel out of the denominator, so that
    nothing underflows at grazing angles.
    """
    a2 = alpha * alpha
    t = sxy2 / sz2  # tan²θ_h, without the cancellation of (1 − cos²)/cos²
    e = -t * (1.0 / a2)  # −tan²θ_h/α² (1/α² is loop-invariant: hoisted by the compiler)
    if not e >= -700.0:
        # D < 1e-290: see d_beckmann. "not ≥" also catches e = NaN (0/0 if s_z² underflows
        # with s_xy = 0); _microfacet avoids that case with _beckmann_grazing.
        return 0.0
    # D = e^{−tan²/α²}/(π α² cos⁴θ_h) with 1/cos²θ_h = 1 + tan²θ_h (≤ 1 + 700 α² here)
    sec2 = 1.0 + t
    si = math.sqrt(max(0.0, 1.0 - iz * iz))  # clamp: rounding near the pole
    so = math.sqrt(max(0.0, 1.0 - oz * oz))
    ai = iz / (alpha * si)  # a = cot θ/α; inf at the pole (selected away below)
    ao = oz / (alpha * so)
    hi = _beckmann_h_poly(min(ai, G1_A_MAX))  # min: table domain; a ≥ 6 is G₁ = 1 below
    ho = _beckmann_h_poly(min(ao, G1_A_MAX))
    # (numerator, denominator) of G₁/cos θ per direction; a ≥ 6: G₁ = 1 exactly (G1_A_MAX)
    ni = 2.0 * SQRT_PI if ai < G1_A_MAX else 1.0
    di = alpha * si * hi if ai < G1_A_MAX else iz
    no = 2.0 * SQRT_PI if ao < G1_A_MAX else 1.0
    do = alpha * so * ho if ao < G1_A_MAX else oz
    return math.exp(e) * (sec2 * sec2) * ni * no / (4.0 * math.pi * a2 * di * do)


@numba.njit(cache=True)
def _beckmann_grazing(iz, oz, sx, sy, sz, alpha, eta, k):
    """F D G₁G₁/(4 cos cos) for Beckmann when s = wi + wo is shorter than SMALL_LENGTH.

    The slow path of :func:`_microfacet` (not inlined): the squares of the components of s
    underflow there, so that tan²θ_h = |s_xy|²/s_z² would be 0/0 (or inaccurate). The
    components are scaled by the largest one first; tan²θ_h is scale-invariant and
    |s| = m·|s/m| (for the Fresnel factor at ω_i·h = |s|/2).
    """
    m = max(abs(sx), abs(sy), sz)  # ≥ sz > 0 above the horizon
    a, b, c = sx / m, sy / m, sz / m
    sxy2 = a * a + b * b
    sz2 = c * c  # ≥ 1/3: no underflow
    f = 1.0 if eta == 0.0 else _fresnel_conductor(0.5 * m * math.sqrt(sxy2 + sz2), eta, k)
    return f * _beckmann_dgg(iz, oz, sxy2, sz2, alpha)


@numba.njit(cache=True, error_model="numpy", fastmath=_FAST)
def _microfacet(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    dist, alpha, eta, k, scale = p[0], p[1], p[2], p[3], p[4]
    sx = ix + ox
    sy = iy + oy
    sz = iz + oz  # > 0 above the horizon
    sxy2 = sx * sx + sy * sy
    sz2 = sz * sz
    l2 = sxy2 + sz2
    # ω_i·h = (1 + wi·wo)/|wi + wo| = |wi + wo|/2 (the same for wo); |wi + wo| ≥ s_z > 0
    if dist == BECKMANN:
        if sz < SMALL_LENGTH:  # rare: both directions within 1e-140 of the horizon
            return scale * _beckmann_grazing(iz, oz, sx, sy, sz, alpha, eta, k)
        if eta == 0.0:  # eta not given: F = 1 (and no square root needed)
            return scale * _beckmann_dgg(iz, oz, sxy2, sz2, alpha)
        f = _fresnel_conductor(0.5 * math.sqrt(l2), eta, k)
        return scale * f * _beckmann_dgg(iz, oz, sxy2, sz2, alpha)
    hx, hy, hz, length = half(ix, iy, iz, ox, oy, oz)  # GGX: the general (slower) path
    cos_ih = ix * hx + iy * hy + iz * hz  # = |wi + wo|/2 = cos_oh; > 0 up to rounding
    if cos_ih <= 0.0:
        return 0.0  # χ⁺(v·h) of eq. (34) (as smith_g1_ggx)
    f = 1.0 if eta == 0.0 else _fresnel_conductor(cos_ih, eta, k)  # eta not given: F = 1
    d = d_ggx(hz, alpha)
    # G₁/cos per direction (ggx_g1_over_cos): G₁(ω_i)G₁(ω_o)/(4 cos θ_i cos θ_o) without the
    # 0/0 of an underflowing numerator and denominator at grazing angles
    g = ggx_g1_over_cos(iz, alpha) * ggx_g1_over_cos(oz, alpha)
    return scale * f * d * g * 0.25


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

    ``beta`` (half-angle, radians) sets α so that D(β) = D(0)/2
    (:func:`~brdfkit.halfangle.beckmann_m_from_beta` for Beckmann,
    :func:`~brdfkit.halfangle.trowbridge_reitz_c_from_beta` for GGX).

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
    width_param = "alpha"
    kernel = _microfacet
    examples = (
        {},
        {"alpha": 0.01},
        {"distribution": "ggx", "alpha": 0.5, "eta": [0.2, 0.9, 1.1], "k": [3.9, 2.4, 2.2]},
        {"alpha": 1.0, "eta": 1.5},
    )

    @classmethod
    def width_from_beta(cls, beta: float) -> float:
        """α of the default (Beckmann) distribution; GGX is handled per instance."""
        return beckmann_m_from_beta(beta)

    def __init__(self, **values):
        beta = values.pop("beta", None)
        if beta is not None:
            if "alpha" in values:
                raise ParameterError(f"{self.name}: give either 'beta' or 'alpha', not both")
            dist = values.get("distribution", "beckmann")
            # D(β) = D(0)/2: Beckmann is Lewis's D₄ shape (α = m), GGX is Lewis's D₃ (α = c₃).
            conv = trowbridge_reitz_c_from_beta if str(dist).lower() == "ggx" \
                else beckmann_m_from_beta
            values["alpha"] = conv(_check_beta(self.name, beta))
        super().__init__(**values)

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
        # clamp: avoid 0-division where D is 0 anyway; 1e-60 keeps π α² c⁴ ≥ 1e-248 α² from
        # underflowing to 0 (which gave 0/0 = NaN with 1e-100), and D(1e-60) is 0 (Beckmann)
        # or α²/π within 1e-120 relative of the true GGX value there.
        c = np.clip(cos_h, 1e-60, 1.0)
        c2 = c * c
        tan2 = (1.0 - c2) / c2
        if self._values["distribution"] == "beckmann":
            with np.errstate(under="ignore"):
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


# =========================================================================== shared helpers
# Both directions within ~1e-140 of the horizon make (N·L)(N·V) underflow; the
# denominators below are floored at DENOM_FLOOR so that f stays finite there
# (it changes f only where both cosines are < 1e-140).
DENOM_FLOOR = 1e-280


@_jit
def g_vgroove(n_h: float, n_l: float, n_v: float, v_h: float) -> float:
    """V-groove masking-shadowing (Torrance–Sparrow; Lewis §3.2, Neumann eq. 10).

    G = min{1, 2(N·H)(N·V)/(V·H), 2(N·H)(N·L)/(V·H)}; V·H = L·H for the bisector.
    """
    if v_h <= 0.0:
        return 0.0  # L = −V (no bisector): nothing is reflected
    return min(1.0, 2.0 * n_h * n_v / v_h, 2.0 * n_h * n_l / v_h)


@_jit
def beckmann_lobe(cos_h: float, m: float) -> float:
    """exp(−tan²δ/m²)/cos⁴δ, the shape shared by Lewis's D₄ and Neumann eq. (9)."""
    if cos_h <= 0.0:
        return 0.0
    c2 = cos_h * cos_h
    if c2 * 700.0 * m * m < 1.0 - c2:
        return 0.0  # tan²δ/m² > 700: value < 1e-290 (see d_beckmann); avoids 0/0 near the horizon
    return math.exp(-(1.0 - c2) / (c2 * m * m)) / (c2 * c2)


def _half_and_cos(wi: np.ndarray, wo: np.ndarray):
    h = wi + wo
    norm = np.linalg.norm(h, axis=-1)
    h = h / np.where(norm > 0.0, norm, 1.0)[..., None]
    return h, norm


def sample_half_vector(kind: str, width: float, u: np.ndarray) -> np.ndarray:
    """Half vector about the normal for a microfacet-type lobe.

    ``beckmann``: density exp(−tan²δ/m²)/(π m² cos³δ), tan²δ = −m² ln(1−u₀)
    (Walter eq. 28; Ward's half-vector sampling as corrected by Walter 2005).
    ``ggx``: density α²/(π cos³δ (α² + tan²δ)²), tan²δ = α² u₀/(1−u₀)
    (Walter eq. 35). ``phong``: density (n+1)/(2π) cosⁿδ, cos δ = u₀^{1/(n+1)}.
    """
    u0 = np.minimum(u[..., 0], 1.0 - 1e-16)  # clamp: u₀ = 1 maps to δ = 90°
    if kind == "beckmann":
        cos_h = 1.0 / np.sqrt(1.0 - width * width * np.log1p(-u0))
    elif kind == "ggx":
        cos_h = 1.0 / np.sqrt(1.0 + width * width * u0 / (1.0 - u0))
    else:
        cos_h = u[..., 0] ** (1.0 / (width + 1.0))
    sin_h = np.sqrt(np.maximum(0.0, 1.0 - cos_h * cos_h))  # clamp: rounding at cos_h = 1
    phi = 2.0 * np.pi * u[..., 1]
    return stack(sin_h * np.cos(phi), sin_h * np.sin(phi), cos_h)


def pdf_half_vector(kind: str, width: float, cos_h: np.ndarray) -> np.ndarray:
    """Solid-angle density of :func:`sample_half_vector` at cos δ = *cos_h*."""
    # clamp: avoid 0-division where the density is 0 anyway (1e-100: c⁴ must not underflow)
    c = np.clip(cos_h, 1e-100, 1.0)
    c2 = c * c
    tan2 = (1.0 - c2) / c2
    if kind == "beckmann":
        with np.errstate(under="ignore"):
            p = np.exp(-tan2 / width**2) / (np.pi * width**2 * c2 * c)
    elif kind == "ggx":
        t = width**2 * c2 + (1.0 - c2)
        p = width**2 * c / (np.pi * t * t)
    else:
        p = (width + 1.0) / (2.0 * np.pi) * c**width
    return np.where(cos_h > 0.0, p, 0.0)


class _HalfVectorSampling:
    """Mixture sampler: cosine (probability ``_p_diffuse``) + reflection about a half vector.

    The pdf is the exact density of this mixture: p_d cos θ_i/π +
    (1 − p_d) p_h(h)/(4 |wo·h|) (the Jacobian of wi = 2(wo·h)h − wo).
    Subclasses define ``_half_lobe() -> (kind, width)`` and ``_p_diffuse()``.
    """

    def _p_diffuse(self) -> float:
        return 0.0

    def sample(self, wo, u):
        wo = as_directions(wo, "wo")
        u = as_uniform(u)
        kind, width = self._half_lobe()
        p_d = self._p_diffuse()
        shape = np.broadcast_shapes(wo.shape, u.shape[:-1] + (3,))
        if p_d > 0.0:
            first = u[..., 0] < p_d
            u0 = np.where(first, u[..., 0] / p_d, (u[..., 0] - p_d) / (1.0 - p_d)) \
                if p_d < 1.0 else u[..., 0]
            u = np.stack([np.minimum(u0, 1.0), u[..., 1]], axis=-1)
        h = np.broadcast_to(sample_half_vector(kind, width, u), shape)
        wo_b = np.broadcast_to(wo, shape)
        wi = 2.0 * np.sum(wo_b * h, axis=-1, keepdims=True) * h - wo_b
        if p_d > 0.0:
            wi_d = np.broadcast_to(sample_cosine_hemisphere(u), shape)
            wi = np.where(np.broadcast_to(first, shape[:-1])[..., None], wi_d, wi)
        return wi, self.pdf(wi, wo)

    def pdf(self, wi, wo):
        wi = as_directions(wi, "wi")
        wo = as_directions(wo, "wo")
        kind, width = self._half_lobe()
        p_d = self._p_diffuse()
        h, norm = _half_and_cos(wi, wo)
        cos_oh = np.abs(np.sum(wo * h, axis=-1))
        p_spec = pdf_half_vector(kind, width, h[..., 2]) / (
            4.0 * np.where(cos_oh > 0.0, cos_oh, 1.0))
        p_spec = np.where((norm > 0.0) & (cos_oh > 0.0), p_spec, 0.0)
        p = (1.0 - p_d) * p_spec + p_d * np.maximum(wi[..., 2], 0.0) / np.pi
        return np.where(wo[..., 2] > 0.0, p, 0.0)


ETA_DIELECTRIC = Param("eta", None, 0.0, 100.0, "",
                       "index of refraction (dielectric Fresnel); none: F = 1",
                       kind="colour", lower_open=True, optional=True)
M_SLOPE = Param("m", 0.1, 1e-4, 100.0, "",
                "RMS slope: 0.01 near-mirror, 0.1 glossy, 0.5 rough")


# =========================================================================== Torrance-Sparrow
PHONG_D, GAUSSIAN_D, TR_D, BECKMANN_D = 0, 1, 2, 3
_TS_DISTRIBUTIONS = ("phong", "gaussian", "trowbridge-reitz", "beckmann")
_TS_WIDTH = {"phong": "n", "gaussian": "c", "trowbridge-reitz": "c", "beckmann": "m"}
_TS_DEFAULT_C = {"gaussian": 4.0, "trowbridge-reitz": 0.3}  # both β ≈ 12°


@numba.njit(cache=True)
def _torrance_sparrow(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    dist, b, n, c, m, eta = p[0], p[1], p[2], p[3], p[4], p[5]
    hx, hy, hz, length = half(ix, iy, iz, ox, oy, oz)
    cos_vh = ox * hx + oy * hy + oz * hz  # = L·H
    if dist == PHONG_D:
        d = b * pos_pow(hz, n)  # D₁ = b cos^{c₁} α
    elif dist == GAUSSIAN_D:
        alpha = math.acos(min(hz, 1.0))  # clamp: rounding can give hz slightly > 1
        d = b * math.exp(-(c * alpha) ** 2)  # D₂
    elif dist == TR_D:
        q = c * c / (hz * hz * (c * c - 1.0) + 1.0)  # D₃; denominator ≥ min(c², 1) > 0
        d = b * q * q
    else:
        d = 0.25 * beckmann_lobe(hz, m) / (m * m)  # D₄ = e^{−tan²α/m²}/(4m² cos⁴α), no b
    g = g_vgroove(hz, iz, oz, cos_vh)
    f = 1.0 if eta == 0.0 else _fresnel_dielectric(cos_vh, eta)  # eta not given: F = 1
    return f * g * d / (math.pi * max(iz * oz, DENOM_FLOOR))  # floor: see DENOM_FLOOR


@register
class TorranceSparrow(_HalfVectorSampling, BRDF):
    """Torrance–Sparrow shader as formulated by Lewis, eq. (10).

    f_r = F G D/(π (N·S)(N·V)), G the V-groove factor
    min{1, 2(N·H)(N·V)/(V·H), 2(N·H)(N·S)/(V·H)}, F the dielectric Fresnel
    of V·H (Cook & Torrance; F = 1 without ``eta``), and D one of
    (cos α = N·H):

    - ``phong``: D₁ = b cos^{n}α (Lewis's c₁ is ``n``),
    - ``gaussian``: D₂ = b e^{−(cα)²} (c₂ is ``c``, in 1/rad),
    - ``trowbridge-reitz``: D₃ = b [c²/(cos²α(c²−1)+1)]² (c₃ is ``c``),
    - ``beckmann``: D₄ = e^{−tan²α/m²}/(4m² cos⁴α) (no b).

    ============  ==========  ============  ========================================
    name          default     bounds        meaning
    ============  ==========  ============  ========================================
    distribution  beckmann    see above     facet slope distribution D
    b             1           [0, 1e3]      scale of D₁–D₃ (ignored by beckmann)
    n             20          [0, 1e6]      c₁, exponent of D₁
    c             None        (0, 1e3]      c₂ of D₂ (default 4) or c₃ of D₃
                                            (default 0.3; must be ≤ 1 so that D₃
                                            peaks at α = 0)
    m             0.1         [1e-4, 100]   RMS slope of D₄
    eta           None        (0, 100]      index of refraction; None: F = 1
    ============  ==========  ============  ========================================

    ``beta`` (half-angle, radians) sets the width of the chosen distribution
    through :mod:`brdfkit.halfangle` (n, c₂, c₃ or m — Lewis §3.2).

    With D₄ the model equals the Walter-normalised Beckmann microfacet BRDF
    with V-groove G, F G D_B/(4 (N·S)(N·V)) with D_B = e^{−tan²α/m²}/(π m² cos⁴α):
    Lewis's π in eq. (10) and the 4 in D₄ together make D normalised. D₁–D₃
    carry Lewis's arbitrary b, so their albedo is not bounded by 1 in
    general (Lewis Fig. 7). Reciprocal (Lewis §5.2). Sampled by the facet
    distribution: cosⁿ lobe (D₁), Beckmann with m = 1/c (D₂, approximate
    proposal, exact pdf), GGX with α = c (D₃, the same lobe), Beckmann (D₄).
    """

    name = "torrance-sparrow"
    aliases = ("torrance", "lewis-torrance-sparrow")
    summary = "Torrance-Sparrow F G D / (pi N.S N.V), D1-D4 of Lewis"
    params = (
        Param("distribution", "beckmann", kind="choice", choices=_TS_DISTRIBUTIONS,
              doc="facet slope distribution: phong (D1), gaussian (D2), trowbridge-reitz (D3), "
                  "beckmann (D4)"),
        Param("b", 1.0, 0.0, 1e3, "", "scale of D1-D3 (Lewis's b; beckmann has none)"),
        Param("n", 20.0, 0.0, 1e6, "", "exponent c1 of D1 (phong)"),
        Param("c", None, 0.0, 1e3, "",
              "c2 of D2 (gaussian, 1/rad, default 4) or c3 of D3 (trowbridge-reitz, <= 1, "
              "default 0.3)", lower_open=True, optional=True),
        M_SLOPE,
        ETA_DIELECTRIC,
    )
    citation = "Lewis 1993 eq. (10) with D1-D4 and G of §3.2 (after Cook & Torrance 1982)"
    albedo_kinks = frozenset({"vgroove"})  # G of §3.2
    reciprocal = True
    has_sampler = True
    width_param = "m"  # of the default distribution; per instance it follows `distribution`
    kernel = _torrance_sparrow
    examples = (
        {},
        {"m": 0.01},
        {"distribution": "phong", "n": 2000.0},
        {"distribution": "gaussian", "c": 40.0, "eta": 1.5},
        {"distribution": "trowbridge-reitz", "c": 0.05},
        {"distribution": "trowbridge-reitz", "b": 0.5, "c": 0.4, "eta": [1.3, 1.5, 1.7]},
    )

    def __init__(self, **values):
        dist = values.get("distribution", "beckmann")
        dist = dist.lower() if isinstance(dist, str) else dist
        width = _TS_WIDTH.get(dist, "m")
        beta = values.pop("beta", None)
        if beta is not None:
            if width in values:
                raise ParameterError(
                    f"{self.name}: give either 'beta' or {width!r} (the width of the "
                    f"{dist} distribution), not both")
            values[width] = _TS_FROM_BETA[dist](_check_beta(self.name, beta))
        if values.get("c") is None and dist in _TS_DEFAULT_C:
            values["c"] = _TS_DEFAULT_C[dist]
        self.width_param = width
        super().__init__(**values)

    def _validate(self):
        v = self._values
        if v["distribution"] == "trowbridge-reitz" and v["c"] > 1.0:
            raise ParameterError(
                f"{self.name}: with distribution 'trowbridge-reitz' parameter 'c' (c3) must lie "
                f"in (0, 1] (D3 peaks at the normal only then); got {v['c']:g}")

    @classmethod
    def width_from_beta(cls, beta: float) -> float:
        return beckmann_m_from_beta(beta)

    @classmethod
    def describe(cls) -> dict:
        d = super().describe()
        d["beta"] = "n (phong), c (gaussian, trowbridge-reitz) or m (beckmann)"
        return d

    def _half_lobe(self):
        v = self._values
        dist = v["distribution"]
        if dist == "phong":
            return "phong", float(v["n"])
        if dist == "gaussian":
            return "beckmann", 1.0 / float(v["c"])  # exp(−c²α²) ≈ exp(−tan²α/m²), m = 1/c
        if dist == "trowbridge-reitz":
            return "ggx", float(v["c"])  # D₃ ∝ GGX with α = c₃
        return "beckmann", float(v["m"])

    def lobes(self):
        v = self._values
        dist = v["distribution"]
        if dist == "phong":
            beta = beta_from_exponent(v["n"]) if v["n"] > 0 else math.pi / 2
        elif dist == "gaussian":
            beta = min(math.sqrt(math.log(2.0)) / v["c"], math.pi / 2)
        elif dist == "trowbridge-reitz":
            beta = beta_from_trowbridge_reitz_c(v["c"]) if v["c"] < 2.0**-0.25 else math.pi / 2
        else:
            beta = beta_from_beckmann_m(v["m"])
        return [Lobe("half", float(beta))]


_TS_FROM_BETA = {
    "phong": exponent_from_beta,
    "gaussian": gaussian_c_from_beta,
    "trowbridge-reitz": trowbridge_reitz_c_from_beta,
    "beckmann": beckmann_m_from_beta,
}


# =========================================================================== Cook-Torrance
@numba.njit(cache=True)
def _cook_torrance_grazing(iz, oz, sx, sy, sz, m, eta, rho_s):
    """:func:`_cook_torrance` when s = wi + wo is shorter than SMALL_LENGTH (not inlined).

    The squares of the components of s underflow there (cos²δ = s_z²/|s|² would be 0/0,
    which the kernel returned as 0). Written with s/q, q the largest component: cos δ and
    tan δ are scale-invariant, |s| = q|s/q| and 4 s_z (N·V)/|s|² = 4 (s_z/q)(N·V)/(q|s/q|²).
    """
    q = max(abs(sx), abs(sy), sz)  # ≥ sz > 0 above the horizon
    a, b, c = sx / q, sy / q, sz / q
    l2 = a * a + b * b + c * c  # in [1, 3]: no underflow
    root = math.sqrt(l2)
    c2 = c * c / l2  # cos²δ
    e = -(1.0 - c2) / (c2 * m * m)
    if not e >= -700.0:
        return 0.0  # D < 1e-290 (see beckmann_lobe)
    d = math.exp(e) / (4.0 * math.pi * m * m * c2 * c2)
    g = min(1.0, 4.0 * c * min(iz, oz) / (l2 * q))  # ≤ 4c²/l2 since min(iz, oz) ≤ s_z = c q
    f = 1.0 if eta == 0.0 else _fresnel_dielectric(0.5 * q * root, eta)
    return rho_s * f * d * g / max(iz * oz, DENOM_FLOOR)  # floor: see DENOM_FLOOR


@numba.njit(cache=True, error_model="numpy", fastmath=_FAST)
def _cook_torrance(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    m, eta, rho_s = p[0], p[1], p[2]
    # Written with s = wi + wo (five divisions, one square root): cos²δ = s_z²/|s|²,
    # tan²δ = |s_xy|²/s_z²,
    # L·H = V·H = |s|/2 (unit vectors) and, in eq. (10), 2(N·H)(N·V)/(V·H) = 4 s_z (N·V)/|s|².
    sx = ix + ox
    sy = iy + oy
    sz = iz + oz  # > 0 above the horizon
    if sz < SMALL_LENGTH:  # rare: both directions within 1e-140 of the horizon
        return _cook_torrance_grazing(iz, oz, sx, sy, sz, m, eta, rho_s)
    sxy2 = sx * sx + sy * sy
    sz2 = sz * sz
    l2 = sxy2 + sz2
    length = math.sqrt(l2)  # |s| ≥ s_z > 0
    hz = sz / length
    c2 = hz * hz  # cos²δ
    # −tan²δ/m² rounded exactly as beckmann_lobe (with half()'s N·H): the rounding of the
    # exponent is amplified up to 700× by e^x, and torrance-sparrow's D₄ must agree to 1e-13
    e = -(1.0 - c2) / (c2 * m * m)
    if not e >= -700.0:
        return 0.0  # D < 1e-290 (see beckmann_lobe); NaN (0/0 at the horizon): see _beckmann_dgg
    d = math.exp(e) / (4.0 * math.pi * m * m * c2 * c2)  # e^{−tan²δ/m²}/(4π m² cos⁴δ)
    g = min(1.0, 4.0 * sz * min(iz, oz) / l2)  # V-groove G, eq. (10) (g_vgroove)
    f = 1.0 if eta == 0.0 else _fresnel_dielectric(0.5 * length, eta)  # no eta: F = 1
    return rho_s * f * d * g / max(iz * oz, DENOM_FLOOR)  # floor: see DENOM_FLOOR


@register
class CookTorrance(_HalfVectorSampling, BRDF):
    """Cook–Torrance model as written by Neumann et al., eqs. (9)–(10).

    f_r = ρ_s F · e^{−tan²δ/m²}/(4π m² cos⁴δ) · G/((N·L)(N·V)), δ the angle
    between N and H, G the V-groove factor of eq. (10), F the dielectric
    Fresnel of L·H (F = 1 without ``eta``, as in Neumann Fig. 1).

    =====  =======  ===========  ==============================================
    name   default  bounds       meaning
    =====  =======  ===========  ==============================================
    m      0.1      [1e-4, 100]  RMS slope; or give ``beta`` (Lewis's D₄ m(β))
    eta    None     (0, 100]     index of refraction (per channel); None: F = 1
    rho_s  1        [0, 1]       scale (per channel)
    =====  =======  ===========  ==============================================

    This is exactly Walter's microfacet BRDF D G/(4 (N·L)(N·V)) with the
    normalised Beckmann D = e^{−tan²δ/m²}/(π m² cos⁴δ) and the V-groove G,
    and equal to ``torrance-sparrow`` with D₄. Reciprocal. Its albedo
    diverges as θ_i → 90° (Neumann §2.1, eq. 15): near the mirror
    configuration G = 1 and f ~ 1/((N·L)(N·V)). Sampled by the Beckmann
    distribution of normals (exact pdf).
    """

    name = "cook-torrance"
    aliases = ("cook", "cooktorrance")
    summary = "Cook-Torrance: Beckmann D, V-groove G, Fresnel / (4 N.L N.V)"
    params = (
        M_SLOPE,
        ETA_DIELECTRIC,
        Param("rho_s", 1.0, 0.0, 1.0, "", "specular scale", kind="colour"),
    )
    citation = "Neumann et al. 1999 eqs. (9)-(10) (Cook & Torrance 1982)"
    albedo_kinks = frozenset({"vgroove"})  # G of eq. (10)
    reciprocal = True
    has_sampler = True
    width_param = "m"
    kernel = _cook_torrance
    examples = (
        {},
        {"m": 0.01},
        {"m": 0.5, "eta": [1.3, 1.5, 1.7], "rho_s": [0.9, 0.8, 0.7]},
    )

    @classmethod
    def width_from_beta(cls, beta: float) -> float:
        return beckmann_m_from_beta(beta)

    def _half_lobe(self):
        return "beckmann", float(self._values["m"])

    def lobes(self):
        return [Lobe("half", float(beta_from_beckmann_m(self._values["m"])))]


# =========================================================================== Ward
@numba.njit(cache=True)
def _ward(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    rho_d, rho_s, m = p[0], p[1], p[2]
    hx, hy, hz, length = half(ix, iy, iz, ox, oy, oz)
    lobe = beckmann_lobe(hz, m) * (hz * hz) * (hz * hz)  # e^{−tan²δ/m²}
    # sqrt of each cosine separately avoids underflow of the product; the floor
    # keeps f ≤ ρ_s/(4π m² 1e-140) finite when both are within 1e-280 of the horizon.
    root = max(math.sqrt(iz) * math.sqrt(oz), 1e-140)
    return rho_d * INV_PI + rho_s * lobe / (4.0 * math.pi * m * m * root)


@register
class Ward(_HalfVectorSampling, BRDF):
    """Isotropic Ward (1992) model as written by Neumann et al., eq. (8).

    f_r = ρ_d/π + ρ_s/(4π m²) · e^{−tan²δ/m²}/√((N·L)(N·V)).

    =====  =======  ===========  ==============================================
    name   default  bounds       meaning
    =====  =======  ===========  ==============================================
    rho_d  0        [0, 1]       diffuse albedo (per channel)
    rho_s  1        [0, 1]       specular albedo scale (per channel)
    m      0.1      [1e-4, 100]  RMS slope; or ``beta``: m = tan β/√ln2
    =====  =======  ===========  ==============================================

    Reciprocal. The specular albedo is close to ρ_s at normal incidence for
    small m but diverges as θ_i → 90° (Neumann §2.1, eq. 14: f ≥ μ/√(N·L)
    on a critical region of viewing directions). Sampled with Ward's
    half-vector distribution, tan²δ = −m² ln u (Walter 2005's correction of
    Ward's pdf: p_h = e^{−tan²δ/m²}/(π m² cos³δ)), mixed with cosine sampling
    for the diffuse part; the pdf is exact.
    """

    name = "ward"
    aliases = ("ward-isotropic", "ward92")
    summary = "isotropic Ward: rho_d/pi + rho_s exp(-tan^2 d/m^2)/(4 pi m^2 sqrt(N.L N.V))"
    params = (
        Param("rho_d", 0.0, 0.0, 1.0, "", "diffuse albedo", kind="colour"),
        Param("rho_s", 1.0, 0.0, 1.0, "", "specular albedo scale", kind="colour"),
        M_SLOPE,
    )
    citation = "Neumann et al. 1999 eq. (8) (Ward 1992, isotropic)"
    reciprocal = True
    has_sampler = True
    width_param = "m"
    kernel = _ward
    examples = (
        {},
        {"m": 0.01},
        {"rho_d": [0.1, 0.2, 0.3], "rho_s": [0.5, 0.4, 0.3], "m": 0.3},
    )

    @classmethod
    def width_from_beta(cls, beta: float) -> float:
        return ward_m_from_beta(beta)

    def _half_lobe(self):
        return "beckmann", float(self._values["m"])

    def _p_diffuse(self):
        d = float(np.mean(self._values["rho_d"]))
        s = float(np.mean(self._values["rho_s"]))
        return 0.5 if d + s <= 0.0 else d / (d + s)

    def lobes(self):
        out = [Lobe("diffuse", math.pi / 2)] if np.any(self._values["rho_d"]) else []
        return out + [Lobe("half", float(beta_from_ward_m(self._values["m"])))]


# =========================================================================== He-Torrance (HTSG)
SQRT_HALF_PI = math.sqrt(0.5 * math.pi)
# Truncation of the series of D: the remaining terms are bounded by geometric
# series (below); summation stops when that bound is below SERIES_TOL times the
# partial sum, so the relative truncation error is < 1e-12. SERIES_CAP bounds
# the terms beyond the Poisson mode g (e^{-g} g^m/m! is negligible, < e^{-800},
# beyond g + 40 sqrt(g) + 100) in case the partial sum is 0 (a underflows it).
SERIES_TOL = 1e-12
SERIES_CAP_SIGMAS = 40.0


@_jit
def htsg_shadow(cos_t: float, sigma0: float, tau: float) -> float:
    """Smith shadowing of a Gaussian surface as used by HTSG (He et al. 1991, eq. for S).

    S(θ) = (1 − ½ erfc(a))/(Λ(a) + 1), a = τ cot θ/(2σ₀),
    Λ(a) = ½ (e^{−a²}/(a√π) − erfc(a)) (Smith 1967; rms slope 2σ₀/τ).
    """
    if cos_t <= 0.0:
        return 0.0
    sin_t = math.sqrt(max(0.0, 1.0 - cos_t * cos_t))  # clamp: rounding near the pole
    if sin_t == 0.0:
        return 1.0  # normal direction: no shadowing
    a = tau * cos_t / (2.0 * sigma0 * sin_t)
    if a < 1e-8:
        # grazing: Λ = 1/(2a√π) − ½ + O(a), so S = a√π (1 + O(a)); also avoids 1/0 when a
        # underflows to 0
        return a * SQRT_PI
    erfc_a = math.erfc(a)
    lam = 0.5 * (math.exp(-a * a) / (a * SQRT_PI) - erfc_a)
    return (1.0 - 0.5 * erfc_a) / (lam + 1.0)


@_jit
def _htsg_k(cos_t: float, sigma0: float, tau: float) -> float:
    """K(θ) = tan θ erfc(τ cot θ/(2σ₀)) of the effective-roughness equation."""
    c = max(cos_t, 1e-300)  # floor: tan θ stays finite (< 1e300) at the horizon
    s = math.sqrt(max(0.0, 1.0 - c * c))  # clamp: rounding near the pole
    if s == 0.0:
        return 0.0
    return (s / c) * math.erfc(tau * c / (2.0 * sigma0 * s))


@_jit
def htsg_sigma(cos_i: float, cos_r: float, sigma0: float, tau: float) -> float:
    """Effective roughness σ = σ₀/√(1 + z₀²/σ₀²) (He et al. 1991).

    z₀ solves √(π/2) z₀ = (σ₀/4)(K_i + K_r) e^{−z₀²/(2σ₀²)}. With u = z₀/σ₀
    and A = (K_i + K_r)/4, f(u) = √(π/2) u − A e^{−u²/2} is increasing with
    f(0) = −A ≤ 0 and f(hi) ≥ 0 for hi = max(1, √(2 ln max(A√(2/π), 1))),
    so safeguarded Newton on [0, hi] converges to the unique root.
    """
    a_coef = 0.25 * (_htsg_k(cos_i, sigma0, tau) + _htsg_k(cos_r, sigma0, tau))
    if a_coef <= 0.0:
        return sigma0
    lo = 0.0
    hi = max(1.0, math.sqrt(2.0 * math.log(max(a_coef / SQRT_HALF_PI, 1.0))))
    u = 0.5 * hi
    for _ in range(100):
        e = math.exp(-0.5 * u * u)
        f = SQRT_HALF_PI * u - a_coef * e
        if f > 0.0:
            hi = u
        else:
            lo = u
        step = f / (SQRT_HALF_PI + a_coef * u * e)
        u_new = u - step
        if not (lo < u_new < hi):
            u_new = 0.5 * (lo + hi)  # Newton left the bracket: bisect
        if abs(u_new - u) <= 1e-15 * max(u, 1.0):
            u = u_new
            break
        u = u_new
    return sigma0 / math.sqrt(1.0 + u * u)


@_jit
def htsg_series(g: float, a: float) -> float:
    """Σ_{m≥1} e^{−g} g^m/(m!·m) · e^{−a/m} (He et al. 1991, the sum in D).

    Summed outward from the Poisson mode m₀ = max(1, ⌊g⌋) so that large g
    neither overflows g^m nor underflows e^{−g}. Tail bounds: above the mode
    Σ_{j>m} w_j/j ≤ (w_m/m) r/(1−r) with r = g/(m+1) < 1; below it
    Σ_{j<m} w_j ≤ w_m (m/g)/(1 − m/g) (w_m the Poisson weight; 1/j and e^{−a/j}
    are ≤ 1).
    """
    if g <= 0.0:
        return 0.0
    m0 = max(1.0, math.floor(g))
    w0 = math.exp(m0 * math.log(g) - g - math.lgamma(m0 + 1.0))
    total = w0 / m0 * math.exp(-a / m0)
    cap = m0 + SERIES_CAP_SIGMAS * math.sqrt(g) + 100.0
    w = w0
    m = m0
    while m < cap:  # upward from the mode
        m += 1.0
        w *= g / m
        total += w / m * math.exp(-a / m)
        r = g / (m + 1.0)
        if r < 1.0 and (w / m) * r / (1.0 - r) <= SERIES_TOL * total:
            break
    w = w0
    m = m0
    while m > 1.0:  # downward from the mode
        w *= m / g
        m -= 1.0
        total += w / m * math.exp(-a / m)
        q = m / g
        if q < 1.0 and w * q / (1.0 - q) <= SERIES_TOL * total:
            break
    return total


@numba.njit(cache=True)
def _he_torrance(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    sigma0, tau, eta, kappa, rho_d = p[0], p[1], p[2], p[3], p[4]
    # v = k_r − k_i in units of 2π/λ (λ = 1): both directions point away, so v ∝ wi + wo.
    sx = ix + ox
    sy = iy + oy
    sz = iz + oz  # v_z (> 0 above the horizon)
    vv = sx * sx + sy * sy + sz * sz
    sigma = htsg_sigma(iz, oz, sigma0, tau)
    two_pi = 2.0 * math.pi
    g = (two_pi * sigma * sz) ** 2
    a = tau * tau * (two_pi * two_pi) * (sx * sx + sy * sy) / 4.0  # τ² v_xy²/4
    # G D with G = (v·v/v_z)² (the polarisation sums reduce to this). G overflows when v_z
    # is tiny while D vanishes like g ∝ v_z²; for g < 1e-100 the first term of the series
    # alone is exact to 1e-100 and the product is written out: G·g = (v·v)² (2πσ)².
    if g < 1e-100:
        geo_d = vv * vv * (two_pi * sigma) ** 2 * math.exp(-a - g)
    else:
        geo_d = (vv / sz) ** 2 * htsg_series(g, a)
    geo_d *= 0.25 * math.pi * math.pi * tau * tau  # D = (π²τ²/4) Σ ...
    # S(θ)/cos θ stays finite at the horizon (S ≈ a√π ∝ cos θ there), so divide per direction.
    s_i = htsg_shadow(iz, sigma0, tau) / iz
    s_r = htsg_shadow(oz, sigma0, tau) / oz
    cos_d = math.sqrt(vv) * 0.5  # wi·h = |wi + wo|/2, the local (bisector) angle
    f = 1.0 if eta == 0.0 else _fresnel_conductor(cos_d, eta, kappa)  # eta not given: F = 1
    return f * geo_d * s_i * s_r * INV_PI + rho_d * INV_PI


@numba.njit(cache=True)
def _htsg_specular(cos_i, sigma0, tau, eta, kappa):
    if cos_i <= 0.0:
        return 0.0
    sigma = htsg_sigma(cos_i, cos_i, sigma0, tau)
    g = (4.0 * math.pi * sigma * cos_i) ** 2  # mirror direction: v_z = 2 cos θ_i
    s = htsg_shadow(cos_i, sigma0, tau)
    f = 1.0 if eta == 0.0 else _fresnel_conductor(cos_i, eta, kappa)
    return f * math.exp(-g) * s * s


@numba.njit(cache=True)
def _htsg_specular_array(cos_i, sigma0, tau, eta, kappa, out):  # pragma: no cover - compiled
    for j in range(cos_i.shape[0]):
        out[j] = _htsg_specular(cos_i[j], sigma0, tau, eta, kappa)


@register
class HeTorrance(_HalfVectorSampling, BRDF):
    """He–Torrance–Sillion–Greenberg (1991) model, non-delta part.

    f_r = ρ_dd + ρ_d/π with the directional-diffuse term

        ρ_dd = F G S D/(π cos θ_i cos θ_r),
        D = (π² τ²/4) Σ_{m≥1} e^{−g} g^m/(m!·m) · exp(−τ² v_xy²/(4m)),
        g = (2π σ (cos θ_i + cos θ_r))²,  G = (v·v/v_z)²,

    with v = k_r − k_i in units of 2π/λ, i.e. v = 2π (wi + wo). All lengths
    (σ₀, τ, σ) are in units of the wavelength (λ = 1): spectral rendering
    scales σ₀/λ and τ/λ per wavelength. The specular part ρ_sp is a Dirac delta
    at the mirror direction carrying the energy |F(θ_i)|² e^{−g} S(θ_i)²
    (with g at the mirror direction); :meth:`eval` does **not** include it;
    :meth:`specular_albedo` returns it for the albedo engine and renderers.

    ======  =======  ===========  ==============================================
    name    default  bounds       meaning
    ======  =======  ===========  ==============================================
    sigma0  0.1      (0, 10]      RMS height σ₀ / λ (0.1: shiny metal; Neumann
                                  Fig. 1); g ≫ 1 (σ₀ ≳ 0.5) is the geometric-
                                  optics regime
    tau     1.7      (0, 1000]    autocorrelation length τ / λ (Neumann Fig. 1:
                                  1.7); RMS slope is 2σ₀/τ
    eta     None     (0, 100]     real index (per channel); None: F = 1
    k       0        [0, 100]     extinction (per channel; conductor Fresnel)
    rho_d   0        [0, 1]       uniform-diffuse albedo a(λ) (per channel)
    ======  =======  ===========  ==============================================

    Simplifications (stated, not hidden):

    - Unpolarised light; F is the unpolarised reflectance at the bisector
      angle (cos = wi·h) for ρ_dd and at θ_i for ρ_sp. The polarisation sums
      in HTSG's G, [(ŝ_r·k̂_i)² + (p̂_r·k̂_i)²][(ŝ_i·k̂_r)² + (p̂_i·k̂_r)²]
      /|k̂_r × k̂_i|⁴, equal 1 exactly (orthonormal triads), so G = (v·v/v_z)².
    - S = S(θ_i) S(θ_r), Smith's shadowing of a Gaussian surface with HTSG's
      form (1 − ½ erfc a)/(Λ + 1); no correlation between the two directions.
    - The effective roughness σ = σ₀/√(1 + z₀²/σ₀²) solves HTSG's equation for
      z₀ with K_i + K_r exactly (safeguarded Newton to 1e-15), not by a fixed
      number of iterations.
    - The series of D is truncated with a rigorous tail bound at relative
      error 1e-12.
    - The uniform-diffuse term a(λ) is a free constant ρ_d, as in HTSG.

    With Neumann's Fig. 1 parameters (σ₀ = 0.1, τ = 1.7, F = 1) the
    directional-diffuse albedo falls from ≈ 0.80 at θ_i = 0 to ≈ 0.11 at 80°,
    the "bad decrease" Neumann et al. describe, while the specular delta
    rises from e^{−(0.4π)²} ≈ 0.21 toward 1, so that their sum stays close to
    1 — the albedo curve of Neumann Fig. 1 is consistent with the
    directional-diffuse part only.

    In the geometric-optics limit (g ≫ 1) the series tends to e^{−tan²δ/m²}/g
    with m = 2σ/τ and ρ_dd tends to the Cook–Torrance form
    F S e^{−tan²δ/m²}/(4π m² cos⁴δ cos θ_i cos θ_r), which the tests check.
    Reciprocal. Sampled by a Beckmann proposal of m = max(2σ₀/τ, 1/(2πτ))
    mixed with cosine sampling (exact pdf of the mixture).
    """

    name = "he-torrance"
    aliases = ("htsg", "he-torrance-sillion-greenberg")
    summary = "He-Torrance-Sillion-Greenberg 1991 (directional-diffuse + uniform-diffuse)"
    params = (
        Param("sigma0", 0.1, 0.0, 10.0, "lambda", "RMS surface height in wavelengths",
              lower_open=True),
        Param("tau", 1.7, 0.0, 1000.0, "lambda", "autocorrelation length in wavelengths",
              lower_open=True),
        Param("eta", None, 0.0, 100.0, "", "real part of the index of refraction; none: F = 1",
              kind="colour", lower_open=True, optional=True),
        Param("k", 0.0, 0.0, 100.0, "", "extinction coefficient (conductors)", kind="colour"),
        Param("rho_d", 0.0, 0.0, 1.0, "", "uniform-diffuse albedo a(lambda)", kind="colour"),
    )
    citation = ("He, Torrance, Sillion, Greenberg 1991 (rho_dd, rho_sp, sigma, S); "
                "Neumann et al. 1999 Fig. 1 (sigma0 = 0.1, tau = 1.7)")
    has_delta = True  # the specular spike of eq. (5): specular_albedo
    reciprocal = True
    has_sampler = True
    kernel = _he_torrance
    examples = (
        {},
        {"sigma0": 0.02, "tau": 10.0},
        {"sigma0": 0.3, "tau": 3.0, "eta": [0.2, 0.9, 1.1], "k": [3.9, 2.4, 2.2],
         "rho_d": [0.05, 0.05, 0.1]},
    )

    def _sampling_m(self) -> float:
        v = self._values
        return max(2.0 * v["sigma0"] / v["tau"], 1.0 / (2.0 * math.pi * v["tau"]))

    def _half_lobe(self):
        return "beckmann", self._sampling_m()

    def _p_diffuse(self):
        d = float(np.mean(self._values["rho_d"]))
        return max(0.25, d / (d + 1.0))  # defensive cosine share: the dd lobe can be broad

    def lobes(self):
        out = [Lobe("diffuse", math.pi / 2)] if np.any(self._values["rho_d"]) else []
        return out + [Lobe("half", float(beta_from_beckmann_m(self._sampling_m())))]

    def specular_albedo(self, theta_i) -> np.ndarray:
        """Energy of the specular delta, |F(θ_i)|² e^{−g} S(θ_i)², at incidence *theta_i*.

        Parameters
        ----------
        theta_i : array_like
            Incident polar angle(s) in radians; 0 beyond 90°.

        Returns
        -------
        ndarray, shape (...) or (..., C)
            The fraction of incident power reflected into the mirror direction
            (add it to the albedo of :meth:`eval`).
        """
        t = np.asarray(theta_i, dtype=np.float64)
        if not np.all(np.isfinite(t)):
            raise ParameterError(f"{self.name}: theta_i must be finite; got {theta_i!r}")
        cos_i = np.ascontiguousarray(np.cos(t).reshape(-1))
        cos_i = np.where(np.abs(t.reshape(-1)) < np.pi / 2, cos_i, 0.0)
        out = np.empty((cos_i.shape[0], self._packed.shape[0]))
        for c in range(self._packed.shape[0]):
            sigma0, tau, eta, kappa = self._packed[c, :4]
            col = np.empty(cos_i.shape[0])
            _htsg_specular_array(cos_i, sigma0, tau, eta, kappa, col)
            out[:, c] = col
        if self.n_channels is None:
            return out[:, 0].reshape(t.shape)
        return out.reshape(*t.shape, self.n_channels)
