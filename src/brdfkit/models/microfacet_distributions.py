"""
Microfacet distributions
========================

Each distribution of microfacet normals is one set of functions — D, the
Smith G₁ and Λ, and the sampler with its pdf — as pbrt-v4's
``TrowbridgeReitzDistribution``: for the compiled kernels, module-level
``@njit(inline="always")`` scalar functions per distribution; for sampling, a
small NumPy object per distribution (:func:`distribution`) that every model
uses. The models (:mod:`brdfkit.models.microfacet`,
:mod:`brdfkit.models.he_torrance`) combine them the way their papers write
them.

Beckmann (Walter eqs. 25-28; Lewis's D₄, Neumann eq. 9, Ward's lobe)
    :func:`d_beckmann`, :func:`beckmann_lobe`, :func:`smith_g1_beckmann`
    (:func:`beckmann_g1_of_a`, tabulated without libm calls, < 1e-13
    relative; :func:`smith_g1_beckmann_exact` is the erf form),
    :func:`beckmann_lambda`, :func:`beckmann_dg_over_cos` (the vectorisable
    D G₁G₁/(4 cos cos) of the Walter kernel), :class:`Beckmann`.
GGX / Trowbridge-Reitz (Walter eqs. 33-35; Lewis's D₃)
    :func:`d_ggx`, :func:`d_ggx_of_h` (from the half-vector components, no
    cancellation for tiny α), :func:`smith_g1_ggx`, :func:`ggx_g1_over_cos`,
    :func:`ggx_lambda`, :class:`GGX`.
Formulas (:mod:`brdfkit._dual`: compiled by Numba, traced by Dr.Jit in the Mitsuba bridge)
    :func:`d_ggx_of_h`, :func:`ggx_g1_over_cos`, :func:`beckmann_dg_over_cos`,
    :func:`d_of_h` and :func:`sample_half` (the D cos θ_h sampler of both
    distributions and its D); the Beckmann h(a) is a primitive (table for
    Numba, ``erf`` for Dr.Jit). The forms the anisotropic distributions
    (:mod:`brdfkit.models.anisotropic_distributions`) share with these:
    :func:`d_ggx_of_u`, :func:`d_beckmann_of_t`, :func:`beckmann_dg_core`,
    :func:`ggx_g1_over_cos_r2`, :func:`_beckmann_g1_over_cos_r`, :func:`tan2_half`.
Phong lobe (Lewis's D₁, a sampling proposal)
    :class:`~brdfkit.models.sampling.PowerHalf` (the "phong" distribution).

Clamps are commented where they are. tan²θ_h is always formed from the
components of s = ωi + ωo as |s_xy|²/s_z² (or from those of h), never as
(1 − cos²θ_h)/cos²θ_h, which loses every digit once 1 − cos θ_h < 1e-16 (a
lobe of α ≲ 1e-7).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from brdfkit._array import stack
from brdfkit._dual import cos, formula, log1p, maximum, minimum, primitive, select, sin, sqrt
from brdfkit._kern import exp_nonpos
from brdfkit.models.sampling import (
    COSINE,
    HalfVector,
    HalfVectorDistribution,
    Mixture,
    PowerHalf,
    StrategySampled,
)

_jit = numba.njit(cache=True, inline="always")
SQRT_PI = math.sqrt(math.pi)
PI = math.pi  # a constant of the formulas (brdfkit._dual reads no attributes)


# =========================================================================== Beckmann
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


# =========================================================================== GGX
@_jit
def d_ggx(cos_h: float, alpha: float) -> float:
    """GGX / Trowbridge–Reitz NDF, Walter eq. (33): α²/(π cos⁴θ_h (α² + tan²θ_h)²)."""
    if cos_h <= 0.0:
        return 0.0
    c2 = cos_h * cos_h
    a2 = alpha * alpha
    t = a2 * c2 + (1.0 - c2)  # = cos²θ_h (α² + tan²θ_h)
    return a2 / (math.pi * t * t)


@formula
def ggx_g1_over_cos(cos_v: float, alpha: float) -> float:
    """G₁(v)/cos θ_v for GGX (Walter eq. 34, v·h > 0 assumed): 2/(c + √(c² + α² sin²θ_v)).

    Equal to :func:`smith_g1_ggx` divided by c = cos θ_v (multiply the numerator and the
    denominator of 2/(1 + √(1 + α² tan²θ_v)) by c), but with no division by c or c²: the
    denominator is ≥ max(c, α sin θ_v) > 0, so the ratio is finite and accurate down to
    c = 0 (→ 2/α), where G₁ and c both underflow and G₁/c would be 0/0.
    """
    c2 = cos_v * cos_v
    return ggx_g1_over_cos_r2(cos_v, alpha * alpha * maximum(0.0, 1.0 - c2))  # clamp: rounding


@formula
def ggx_g1_over_cos_r2(cos_v: float, r2: float) -> float:
    """G₁(v)/cos θ_v for GGX from r² = α(ω)² sin²θ_v: 2/(c + √(c² + r²)) (Walter eq. 34).

    The form both the isotropic (r² = α² sin²θ_v, :func:`ggx_g1_over_cos`) and the
    anisotropic distributions (r² = α_x² v_x² + α_y² v_y², the projected roughness
    α(ω)² = cos²φ α_x² + sin²φ α_y² times sin²θ) share: finite down to c = 0.
    """
    return 2.0 / (cos_v + sqrt(cos_v * cos_v + r2))


@_jit
def smith_g1_ggx(cos_v: float, cos_vh: float, alpha: float) -> float:
    """Smith masking for GGX, Walter eq. (34): 2/(1 + √(1 + α² tan²θ_v))."""
    if cos_v <= 0.0 or cos_vh <= 0.0:
        return 0.0
    c2 = cos_v * cos_v
    tan2 = max(0.0, 1.0 - c2) / c2  # clamp: rounding can make 1 − c² < 0
    return 2.0 / (1.0 + math.sqrt(1.0 + alpha * alpha * tan2))


@_jit
def _beckmann_h_total(a: float) -> float:
    """:func:`_beckmann_h_poly` for any a (NaN, inf, negative): clamped into [0, G1_A_MAX]
    first, NaN to G1_A_MAX, so that the table index is in bounds for every input (the
    vectorised kernels evaluate discarded lanes too)."""
    x = a if a < G1_A_MAX else G1_A_MAX  # clamp: table domain (NaN → G1_A_MAX)
    x = x if x > 0.0 else 0.0  # clamp: table domain (a < 0 only in discarded lanes)
    return _beckmann_h_poly(x)


def _beckmann_h_drjit(dr):
    """h(a) = a√π (1 + erf a) + e^{−a²} in Dr.Jit (its ``erf``), a clamped as above."""
    def h(a):
        x = dr.clip(a, 0.0, G1_A_MAX)  # clamp: the formula's domain (discarded lanes)
        return x * SQRT_PI * (1.0 + dr.erf(x)) + dr.exp(-x * x)
    return h


# a primitive of the formulas (brdfkit._dual): the table for Numba, erf for Dr.Jit
primitive(_beckmann_h_total, _beckmann_h_drjit)


@_jit
def beckmann_lambda(a: float) -> float:
    """Smith Λ of Beckmann as a function of a = cot θ/α (> 0): G₁ = 1/(1 + Λ)."""
    return 1.0 / beckmann_g1_of_a(a) - 1.0


@formula
def _beckmann_g1_over_cos(cos_v: float, alpha: float):
    """(numerator, denominator) of G₁(v)/cos θ_v for Beckmann, branch-free and total.

    G₁/cos θ = 2√π/(α sin θ h(a)) for a = cot θ/α < 6 and 1/cos θ for a ≥ 6 (G₁ = 1
    exactly, see G1_A_MAX), as two selects: the cosine cancels out of the first form, so
    nothing underflows at grazing angles.
    """
    s = sqrt(maximum(0.0, 1.0 - cos_v * cos_v))  # clamp: rounding near the pole
    return _beckmann_g1_over_cos_r(cos_v, alpha * s)


@formula
def _beckmann_g1_over_cos_r(cos_v: float, r: float):
    """:func:`_beckmann_g1_over_cos` from r = α(ω) sin θ_v (a = cos θ_v/r): α sin θ for the
    isotropic distribution, √(α_x² v_x² + α_y² v_y²) for the anisotropic one."""
    a = cos_v / r  # inf at the pole (r = 0): selected away below
    h = _beckmann_h_total(a)
    small = a < G1_A_MAX
    return select(small, 2.0 * SQRT_PI, 1.0), select(small, r * h, cos_v)


@formula
def beckmann_dg_over_cos(iz, oz, sxy2, sz2, alpha, inv_a2, live):
    """D G₁(ω_i) G₁(ω_o)/(4 cos θ_i cos θ_o) for Beckmann, Walter eqs. (20), (25), (27).

    Branch-free and total (the Walter kernel's vectorised core): tan²θ_h =
    |s_xy|²/s_z² with s = wi + wo, D = e^{−tan²/α²}(1 + tan²)²/(π α²) and G₁/cos
    per direction from :func:`_beckmann_g1_over_cos`. Lanes with *live* false, or
    with tan²θ_h/α² > 700 (D < 1e-290, returned as 0), give exactly 0 whatever
    the inputs (the exponent is replaced by one whose e^x is 0 and the
    denominator by 1).
    """
    t = sxy2 / sz2  # tan²θ_h, without the cancellation of (1 − cos²)/cos²
    ni, di = _beckmann_g1_over_cos(iz, alpha)
    no, do = _beckmann_g1_over_cos(oz, alpha)
    return beckmann_dg_core(t, -t * inv_a2, alpha * alpha, ni, di, no, do, live)


@formula
def beckmann_dg_core(t, e, a2, ni, di, no, do, live):
    """The core of :func:`beckmann_dg_over_cos`, shared with the anisotropic distribution:
    tan²θ_h *t*, the exponent *e* = −tan²θ_h/α² (anisotropic: −((h_x/α_x)² + (h_y/α_y)²)/h_z²),
    *a2* = α² (α_x α_y), the G₁/cos pairs (ni/di, no/do) of both directions."""
    live = live & (e >= -700.0)  # NaN (0/0, discarded lanes) is not live
    e = select(live, e, -1000.0)  # e^{−1000} = 0 exactly (exp_nonpos)
    sec2 = 1.0 + select(live, t, 0.0)  # 1/cos²θ_h
    den = 4.0 * PI * a2 * di * do
    den = select(live, den, 1.0)
    return exp_nonpos(e) * (sec2 * sec2) * (ni * no) / den


@formula
def d_ggx_of_h(hz2: float, hxy2: float, inv_a2: float, alpha: float) -> float:
    """GGX D from the squared components of the unit half vector (hz² + |h_xy|² = 1).

    D = 1/(π α² (cos²θ_h + |h_xy|²/α²)²) — Walter eq. (33) multiplied out, with
    no 1 − cos²θ_h (exact for tiny α) and no underflow (the bracket is ≥
    min(1, 1/α²)/… ≥ 1/16 for α ≤ 4); 1/α² = inf gives D = 0 off the mirror.
    """
    return d_ggx_of_u(hz2 + hxy2 * inv_a2, alpha * alpha)


@formula
def d_ggx_of_u(u: float, a2: float) -> float:
    """GGX D = 1/(π a2 u²) from u = h_z² + |h_xy|²/α² (isotropic, a2 = α²) or
    h_z² + (h_x/α_x)² + (h_y/α_y)² (anisotropic, a2 = α_x α_y): Walter eq. (33) and its
    anisotropic form (Heitz 2014 §5.3) multiplied out."""
    return 1.0 / (PI * a2 * (u * u))


# =========================================================================== sampling (formulas)
U0_MAX = 1.0 - 1e-16  # the largest u₀ the samplers use: u₀ = 1 would map to θ_h = 90°
TWO_PI = 2.0 * math.pi


@formula
def d_of_h(hx, hy, hz, alpha, ggx):
    """D(h) of GGX (*ggx* true, Walter eq. 33) or Beckmann (eq. 25) at a unit vector h.

    A formula (:mod:`brdfkit._dual`; *ggx* a Python constant): the density of
    the samplers below with :func:`sample_half` (pdf D(h) cos θ_h). 0 for
    h_z ≤ 0; Beckmann gives 0 where tan²θ_h/α² > 700 (D < 1e-290), as
    :func:`beckmann_dg_over_cos`. tan²θ_h = |h_xy|²/h_z² (no 1 − cos²θ_h).
    """
    hz2 = hz * hz
    hxy2 = hx * hx + hy * hy
    a2 = alpha * alpha
    up = hz > 0.0
    if ggx:
        d = d_ggx_of_u(hz2 + hxy2 / a2, a2)  # as d_ggx_of_h: no 1 − cos², ≥ 1/16
    else:
        t = hxy2 / hz2  # tan²θ_h (NaN or inf only where h_z ≤ 0: selected away)
        d, up = d_beckmann_of_t(t, -t / a2, a2, up)
    return select(up, d, 0.0)


@formula
def d_beckmann_of_t(t, e, a2, up):
    """Beckmann D = e^{e}(1 + t)²/(π a2) from tan²θ_h *t* and the exponent *e* (−t/α², or
    −((h_x/α_x)² + (h_y/α_y)²)/h_z² anisotropic, a2 = α_x α_y); ``(D, up)`` with *up*
    false where e < −700 (D < 1e-290, given as 0) or NaN, as :func:`beckmann_dg_over_cos`."""
    up = up & (e >= -700.0)  # NaN is not up
    sec2 = 1.0 + select(up, t, 0.0)  # 1/cos²θ_h
    return exp_nonpos(select(up, e, -1000.0)) * (sec2 * sec2) / (PI * a2), up


@formula
def sample_half(u0, u1, alpha, ggx):
    """A half vector h with density D(h) cos θ_h from u₀, u₁ ∈ [0, 1) (formula).

    tan²θ_h = α² u₀/(1 − u₀) (GGX, Walter eq. 35) or −α² ln(1 − u₀) (Beckmann,
    eq. 28), φ_h = 2π u₁; cos θ_h = 1/√(1 + tan²θ_h) and sin θ_h = tan θ_h cos θ_h
    (exact for tiny θ_h, no 1 − cos²).
    """
    tan2 = tan2_half(u0, alpha * alpha, ggx)
    cos_h = 1.0 / sqrt(1.0 + tan2)
    sin_h = sqrt(tan2) * cos_h
    phi = TWO_PI * u1
    return sin_h * cos(phi), sin_h * sin(phi), cos_h


@formula
def tan2_half(u0, a2, ggx):
    """tan²θ_h of the D cos θ_h sampler from u₀ ∈ [0, 1) and a2 = α² (anisotropic: α(φ_h)²):
    a2 u₀/(1 − u₀) (GGX, Walter eq. 35) or −a2 ln(1 − u₀) (Beckmann, eq. 28)."""
    u = minimum(u0, U0_MAX)  # clamp: u₀ = 1 maps to θ_h = 90°
    if ggx:
        return a2 * u / (1.0 - u)
    return -a2 * log1p(-u)


@_jit
def ggx_lambda(cos_v: float, alpha: float) -> float:
    """Smith Λ of GGX: (√(1 + α² tan²θ) − 1)/2, G₁ = 1/(1 + Λ)."""
    c2 = cos_v * cos_v
    return 0.5 * (math.sqrt(1.0 + alpha * alpha * max(0.0, 1.0 - c2) / c2) - 1.0)  # clamp: rounding


# =========================================================================== sampling (NumPy)
def _tan2_of_h(h: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(tan²θ_h, cos θ_h) of unit half vectors h (..., 3): tan² = |h_xy|²/h_z² (no
    cancellation near the normal), inf where h_z ≤ 0."""
    hz = h[..., 2]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        tan2 = (h[..., 0] ** 2 + h[..., 1] ** 2) / (hz * hz)
    return np.where(hz > 0.0, tan2, np.inf), hz


def _normal_from_tan2(tan2: np.ndarray, u1: np.ndarray) -> np.ndarray:
    cos_h = 1.0 / np.sqrt(1.0 + tan2)
    sin_h = np.sqrt(tan2) * cos_h  # tan θ cos θ: exact for tiny θ (no 1 − cos²)
    phi = 2.0 * np.pi * u1
    return stack(sin_h * np.cos(phi), sin_h * np.sin(phi), cos_h)


class Beckmann(HalfVectorDistribution):
    """Beckmann distribution of width α (NumPy side): D, sampling of D cos θ_h, its pdf."""

    def __repr__(self) -> str:
        return f"Beckmann(alpha={self.alpha!r})"

    def __init__(self, alpha: float):
        self.alpha = float(alpha)

    def d(self, h: np.ndarray) -> np.ndarray:
        """D(h) = e^{−tan²θ_h/α²}/(π α² cos⁴θ_h) (Walter eq. 25); 0 for h_z ≤ 0."""
        tan2, hz = _tan2_of_h(h)
        a2 = self.alpha**2
        with np.errstate(under="ignore", over="ignore", invalid="ignore"):
            d = np.exp(-tan2 / a2) * (1.0 + tan2) ** 2 / (np.pi * a2)
        return np.where((hz > 0.0) & np.isfinite(d), d, 0.0)

    def pdf(self, h: np.ndarray) -> np.ndarray:
        """Solid-angle density D(h) cos θ_h of :meth:`sample`."""
        return self.d(h) * np.maximum(h[..., 2], 0.0)

    def sample(self, u: np.ndarray) -> np.ndarray:
        """h with density D cos θ_h: tan²θ_h = −α² ln(1 − u₀) (Walter eq. 28)."""
        u0 = np.minimum(u[..., 0], 1.0 - 1e-16)  # clamp: u₀ = 1 maps to θ_h = 90°
        return _normal_from_tan2(-self.alpha**2 * np.log1p(-u0), u[..., 1])


class GGX(HalfVectorDistribution):
    """GGX / Trowbridge-Reitz distribution of width α (NumPy side)."""

    def __repr__(self) -> str:
        return f"GGX(alpha={self.alpha!r})"

    def __init__(self, alpha: float):
        self.alpha = float(alpha)

    def d(self, h: np.ndarray) -> np.ndarray:
        """D(h) = α²/(π cos⁴θ_h (α² + tan²θ_h)²) (Walter eq. 33); 0 for h_z ≤ 0."""
        hz = h[..., 2]
        hxy2 = h[..., 0] ** 2 + h[..., 1] ** 2
        a2 = self.alpha**2
        u = hz * hz + hxy2 / a2  # as d_ggx_of_h: no 1 − cos², ≥ 1/16
        return np.where(hz > 0.0, 1.0 / (np.pi * a2 * u * u), 0.0)

    def pdf(self, h: np.ndarray) -> np.ndarray:
        return self.d(h) * np.maximum(h[..., 2], 0.0)

    def sample(self, u: np.ndarray) -> np.ndarray:
        """h with density D cos θ_h: tan²θ_h = α² u₀/(1 − u₀) (Walter eq. 35)."""
        u0 = np.minimum(u[..., 0], 1.0 - 1e-16)  # clamp: u₀ = 1 maps to θ_h = 90°
        return _normal_from_tan2(self.alpha**2 * u0 / (1.0 - u0), u[..., 1])


_DISTRIBUTIONS = {"beckmann": Beckmann, "ggx": GGX, "phong": PowerHalf}


def distribution(kind: str, width: float):
    """The NumPy distribution object of *kind* ("beckmann", "ggx", "phong") and *width*."""
    return _DISTRIBUTIONS[kind](width)


@_jit
def beckmann_lobe(cos_h: float, m: float) -> float:
    """exp(−tan²δ/m²)/cos⁴δ, the shape shared by Lewis's D₄ and Neumann eq. (9)."""
    if cos_h <= 0.0:
        return 0.0
    c2 = cos_h * cos_h
    if c2 * 700.0 * m * m < 1.0 - c2:
        return 0.0  # tan²δ/m² > 700: value < 1e-290 (see d_beckmann); avoids 0/0 near the horizon
    return math.exp(-(1.0 - c2) / (c2 * m * m)) / (c2 * c2)


class _HalfVectorSampling(StrategySampled):
    """Mixture sampler: cosine (probability ``_p_diffuse``) + reflection about a half vector.

    The strategy ``Mixture([COSINE, HalfVector(D, fold=False)], [p_d, 1 − p_d])`` of
    :mod:`brdfkit.models.sampling`: density p_d cos θ_i/π + (1 − p_d) p_h(h)/(4 |wo·h|)
    (the Jacobian of wi = 2(wo·h)h − wo). Subclasses define ``_half_lobe() -> (kind,
    width)`` and ``_p_diffuse()``.
    """

    def _p_diffuse(self) -> float:
        return 0.0

    def _strategy(self, wo):
        kind, width = self._half_lobe()
        p_d = self._p_diffuse()
        lobe = HalfVector(distribution(kind, width), fold=False)
        return lobe if p_d <= 0.0 else Mixture([COSINE, lobe], [p_d, 1.0 - p_d])
