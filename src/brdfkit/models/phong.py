"""
The Phong family
================

Phong and Blinn shaders as BRDFs and their physically plausible variants from
all three papers. Every kernel is written over the dot products of the local
frame (N·L = ``iz``, N·V = ``oz``, R·V, N·H; see :mod:`brdfkit._kern`).

Public objects
--------------
- :class:`ModifiedPhong` — ``modified-phong``, Nielsen eq. (1).
- :class:`Phong` — ``phong``: Lewis eqs. (5) and (8), the original shader as a BRDF.
- :class:`Blinn` — ``blinn``: Lewis eqs. (6) and (8).
- :class:`PhongEnergyConserving` — ``phong-energy-conserving``: Lewis eq. (22).
- :class:`PhongBlinnReciprocal` — ``phong-blinn-reciprocal``: Lewis eq. (24),
  Neumann eq. (6) "reciprocal Blinn".
- :class:`NHPowerSeries` — ``nh-power-series``: Lewis §7.
- :class:`ModifiedBlinnPhong` — ``modified-blinn-phong``: Nielsen eq. (2).
- :class:`Lafortune` — ``lafortune``: Neumann eq. (7), Lafortune et al. 1997.
- :class:`NeumannPhong` — ``neumann-phong``: Neumann eq. (22).
- :class:`Nielsen` — ``nielsen``: Nielsen eq. (3) with Fresnel.
- :func:`specular_integral` — Lewis's H_s(S) for the Phong or Blinn lobe, by
  quadrature in the lobe frame (relative accuracy ~1e-11).
- :func:`lobe_pow` — max(0, x)ⁿ with 0⁰ = 1, binary exponentiation for integral n.
- :func:`blinn_normal_albedo` — ∫(N·H)ⁿ cos θ_o dω_o at normal incidence, closed form.
- :func:`sample_phong_lobe`, :func:`pdf_phong_lobe`, :func:`sample_blinn_lobe`,
  :func:`pdf_blinn_lobe`, :func:`diffuse_fraction`, :func:`split_uniform` —
  sampling helpers.

References
----------
- [Lewis1993] R. R. Lewis, *Making Shaders More Physically Plausible*, 1993:
  eqs. (5), (6), (8), (16), (19), (22), (24), §7.
- [Neumann1999] L. Neumann, A. Neumann, L. Szirmay-Kalos, *Reflectance Models
  by Pumping up the Albedo Function*, 1999: eqs. (6), (7), (22).
- [Nielsen2015] J. B. Nielsen, J. R. Frisvad, K. Conradsen, H. Aanæs,
  *Addressing Grazing Angle Reflections in Phong Models*: eqs. (1)–(3).
- [Lafortune1997] E. P. F. Lafortune, S.-C. Foo, K. E. Torrance,
  D. P. Greenberg, *Non-Linear Approximation of Reflectance Functions*,
  SIGGRAPH 1997.
- [Akenine-Möller2008] T. Akenine-Möller, E. Haines, N. Hoffman,
  *Real-Time Rendering*, 3rd ed. (the (n+8)/8π factor of Nielsen eq. 2).
"""

from __future__ import annotations

import functools
import math

import numba
import numpy as np

from brdfkit._array import as_directions, as_uniform, stack
from brdfkit._kern import (
    INV_PI,
    INV_TWO_PI,
    SMALL_LENGTH,
    below_horizon,
    n_dot_h,
    r_dot_v,
    scaled_length,
)
from brdfkit.errors import ParameterError
from brdfkit.fresnel import _fresnel_dielectric
from brdfkit.geometry import (
    local_to_world,
    pdf_cosine_hemisphere,
    reflect,
    sample_cosine_hemisphere,
)
from brdfkit.halfangle import beta_from_exponent, exponent_from_beta
from brdfkit.models._base import BRDF, Lobe, Param
from brdfkit.models._registry import register
from brdfkit.tables import Lookup, _lookup, build_lookup

RHO_D = Param("rho_d", 0.2, 0.0, 1.0, "", "diffuse albedo", kind="colour")
RHO_S = Param("rho_s", 0.5, 0.0, 1.0, "",
              "specular reflectance (albedo of the normalised lobe at normal incidence)",
              kind="colour")
N_EXP = Param("n", 20.0, 0.0, 1e6, "",
              "specular exponent (lobe sharpness); ~1-10 rough, 100-1000 glossy, >1e4 mirror")
K_D = Param("k_d", 0.1, 0.0, 1.0, "1/sr",
            "diffuse BRDF constant (albedo k_d*pi; <= 1/pi conserves energy; Lewis's "
            "figures use k_d = 1 - k_s)", kind="colour")
K_S = Param("k_s", 1.0, 0.0, 1e6, "1/sr",
            "specular coefficient (unnormalised; (n+2)/2pi gives unit normal-incidence "
            "albedo for the R.V lobe)", kind="colour")


# Floor of a cosine that divides (1/(N·L) in phong and blinn, 1/max(N·L, N·V) in
# neumann-phong). The true value overflows float64 when the cosine is subnormal; with the
# floor f ≤ k_s·1e300 ≤ 1e306 (k_s ≤ 1e6) and ≤ c_n·1e300 ≤ 1e307 (c_n ≤ 1e7): finite for
# every accepted parameter. Cost: f is too small by the factor cos/1e-300 only for cosines
# below 1e-300 (θ within 1e-300 rad of 90°), where float64 cannot represent it anyway.
COS_DIVISOR_FLOOR = 1e-300


# --------------------------------------------------------------------------- kernel helper
@numba.njit(cache=True, inline="always")
def lobe_pow(x: float, n: float) -> float:
    """max(0, x)ⁿ with 0⁰ = 1 (as :func:`brdfkit._kern.pos_pow`), faster for integral n.

    Integral exponents below 1024 (the usual Phong exponents) use binary
    exponentiation — ≤ 20 multiplications, ~4x faster than ``pow`` and within
    ~n·1e-16 relative of it; other exponents call ``pow``. The branch depends
    on the parameters only, so it is perfectly predicted inside a batch.
    """
    if x <= 0.0:
        return 1.0 if n == 0.0 else 0.0
    if n < 1024.0 and n == math.floor(n):
        k = int(n)
        r = 1.0
        b = x
        while k:
            if k & 1:
                r *= b
            b *= b
            k >>= 1
        return r
    return x**n


# --------------------------------------------------------------------------- sampling helpers
def sample_phong_lobe(axis: np.ndarray, n: float, u: np.ndarray) -> np.ndarray:
    """Direction about *axis* with density (n+1)/(2π) cosⁿα on the sphere.

    Inverting the CDF of cosⁿα sinα gives cos α = u₀^{1/(n+1)}.
    """
    cos_a = u[..., 0] ** (1.0 / (n + 1.0))
    sin_a = np.sqrt(np.maximum(0.0, 1.0 - cos_a * cos_a))  # clamp: rounding near cos_a = 1
    phi = 2.0 * np.pi * u[..., 1]
    local = stack(sin_a * np.cos(phi), sin_a * np.sin(phi), cos_a)
    return local_to_world(local, axis)


def pdf_phong_lobe(cos_alpha: np.ndarray, n: float) -> np.ndarray:
    """Density of :func:`sample_phong_lobe`, (n+1)/(2π) max(0, cos α)ⁿ."""
    return (n + 1.0) / (2.0 * np.pi) * np.maximum(cos_alpha, 0.0) ** n


def sample_blinn_lobe(wo: np.ndarray, n: float, u: np.ndarray) -> np.ndarray:
    """wi = mirror of *wo* about h, h drawn about the normal with density (n+1)/(2π) cosⁿθ_h.

    The map h ↦ wi = 2(wo·h)h − wo has Jacobian dω_i/dω_h = 4|wo·h|, so wi has
    density p_h/(4|wo·h|) (:func:`pdf_blinn_lobe`). Where wo·h < 0 the
    direction lands below the horizon (the BRDF is 0 there).
    """
    h = sample_phong_lobe(np.array([0.0, 0.0, 1.0]), n, u)
    h = np.broadcast_to(h, np.broadcast_shapes(h.shape, wo.shape))
    return 2.0 * np.sum(wo * h, axis=-1, keepdims=True) * h - wo


def pdf_blinn_lobe(wi: np.ndarray, wo: np.ndarray, n: float) -> np.ndarray:
    """Solid-angle density of :func:`sample_blinn_lobe` over the full sphere of wi."""
    h = wi + wo
    norm = np.linalg.norm(h, axis=-1)
    ok = norm > 0.0
    h = h / np.where(ok, norm, 1.0)[..., None]
    # the sampled h is in the upper hemisphere; wi + wo is ±h, so take the upper one
    h = np.where(h[..., 2:3] < 0.0, -h, h)
    cos_oh = np.abs(np.sum(wo * h, axis=-1))
    ok &= cos_oh > 0.0
    p = pdf_phong_lobe(h[..., 2], n) / (4.0 * np.where(ok, cos_oh, 1.0))
    return np.where(ok, p, 0.0)


def diffuse_fraction(rho_d, rho_s) -> float:
    """Probability of picking the diffuse lobe in a diffuse + specular mixture.

    Proportional to the channel-mean reflectances; 1/2 when both are zero.
    """
    d = float(np.mean(rho_d))
    s = float(np.mean(rho_s))
    return 0.5 if d + s <= 0.0 else d / (d + s)


def split_uniform(u0: np.ndarray, p: float) -> tuple[np.ndarray, np.ndarray]:
    """Pick the first lobe where u₀ < p and rescale u₀ to [0, 1) in both branches."""
    first = u0 < p
    if p <= 0.0:
        return np.zeros_like(u0, dtype=bool), u0
    if p >= 1.0:
        return np.ones_like(u0, dtype=bool), u0
    return first, np.where(first, u0 / p, (u0 - p) / (1.0 - p))


# Mixture components: (kind, exponent, axis_fn). "cosine" ignores the rest;
# "phong" samples (n+1)/2π cosⁿ about axis_fn(wo) (default: the mirror of wo);
# "blinn" samples through the half vector. A lobe with exponent 0 is constant
# over the hemisphere (0⁰ = 1, see lobe_pow) and is sampled by the cosine.
def _component_sample(comp, wo, u):
    kind, n, axis_fn = comp
    if kind == "cosine" or n == 0.0:
        return np.broadcast_to(sample_cosine_hemisphere(u), wo.shape)
    if kind == "phong":
        axis = reflect(wo) if axis_fn is None else axis_fn(wo)
        return sample_phong_lobe(axis, n, u)
    return sample_blinn_lobe(wo, n, u)


def _component_pdf(comp, wi, wo):
    kind, n, axis_fn = comp
    if kind == "cosine" or n == 0.0:
        return pdf_cosine_hemisphere(wi)
    if kind == "phong":
        axis = reflect(wo) if axis_fn is None else axis_fn(wo)
        return pdf_phong_lobe(np.sum(wi * axis, axis=-1), n)
    return pdf_blinn_lobe(wi, wo, n)


def _mixture_sample(comps, weights, wo, u):
    """Draw wi from Σ_k w_k p_k; *weights* (K,) or (..., K) summing to 1."""
    shape = np.broadcast_shapes(wo.shape[:-1], u.shape[:-1])
    wo = np.broadcast_to(wo, (*shape, 3))
    u = np.broadcast_to(u, (*shape, 2))
    w = np.broadcast_to(np.asarray(weights, dtype=np.float64), (*shape, len(comps)))
    cum = np.cumsum(w, axis=-1)
    u0 = u[..., 0]
    k = np.minimum(np.sum(cum <= u0[..., None], axis=-1), len(comps) - 1)
    # never pick a zero-weight component (u₀ = 1 or rounding in the cumulative sum)
    k = np.where(np.take_along_axis(w, k[..., None], -1)[..., 0] > 0.0, k,
                 np.argmax(w, axis=-1))
    lo = np.take_along_axis(cum - w, k[..., None], -1)[..., 0]
    wk = np.take_along_axis(w, k[..., None], -1)[..., 0]
    # rescale u₀ within the picked component's interval (clip: rounding)
    u0r = np.clip((u0 - lo) / np.where(wk > 0.0, wk, 1.0), 0.0, 1.0)
    ur = np.stack([u0r, u[..., 1]], axis=-1)
    wi = np.empty((*shape, 3))
    for j, comp in enumerate(comps):
        sel = k == j
        if np.any(sel):
            wi[sel] = np.broadcast_to(_component_sample(comp, wo, ur), (*shape, 3))[sel]
    return wi


def _mixture_pdf(comps, weights, wi, wo):
    shape = np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1])
    w = np.broadcast_to(np.asarray(weights, dtype=np.float64), (*shape, len(comps)))
    p = np.zeros(shape)
    for j, comp in enumerate(comps):
        wj = w[..., j]
        if np.any(wj > 0.0):
            p = p + wj * _component_pdf(comp, wi, wo)
    return np.where(wo[..., 2] > 0.0, p, 0.0)


def _normalised(weights) -> np.ndarray:
    w = np.maximum(np.asarray(weights, dtype=np.float64), 0.0)
    s = float(np.sum(w))
    return np.full(w.shape, 1.0 / w.size) if s <= 0.0 else w / s


def _lobe(kind: str, n: float) -> Lobe:
    """Lobe hint of a cosⁿ lobe: half-angle β with cosⁿβ = 1/2 (n = 0: constant, diffuse)."""
    if n <= 0.0:
        return Lobe("diffuse", math.pi / 2)
    return Lobe(kind, float(beta_from_exponent(n)))


# --------------------------------------------------------------------------- closed forms
def blinn_normal_albedo(n):
    """∫ (N·H)ⁿ cos θ_o dω_o at normal incidence (L = N), in closed form.

    With L = N, H bisects N and V, so θ_o = 2θ_h, cos θ_o = 2h² − 1 (h = cos θ_h)
    and sin θ_o dθ_o = −4h dh; the integral over θ_o ∈ [0, π/2] becomes

        8π ∫_{1/√2}^1 h^{n+1} (2h² − 1) dh
          = 8π [2(1 − 2^{−(n+4)/2})/(n+4) − (1 − 2^{−(n+2)/2})/(n+2)].

    n = 0 gives π (the cosine integral, Lewis eq. 16); for large n it tends to
    8π/n. Nielsen eq. (2)'s factor (n+8)/8π (Akenine-Möller et al.) is an
    approximation of its reciprocal, too large by up to 7.5 % (n ≈ 8.76).
    """
    n = np.asarray(n, dtype=np.float64)
    a = -np.expm1(-0.5 * (n + 4.0) * math.log(2.0)) / (n + 4.0)
    b = -np.expm1(-0.5 * (n + 2.0) * math.log(2.0)) / (n + 2.0)
    return 8.0 * math.pi * (2.0 * a - b)


# --------------------------------------------------------------------------- H_s(S)
def _tanh_sinh(h: float = 1.0 / 32.0, t_max: float = 3.6):
    """Tanh-sinh nodes on [0, 1] as distances from both ends, and weights.

    Double-exponential quadrature converges exponentially even with algebraic
    endpoint singularities (the kinks where the horizon starts to cut a lobe
    behave like d^{3/2}); distances from each end are returned separately so
    that integrands can be evaluated without cancellation near the ends.
    """
    t = np.arange(-t_max, t_max + 0.5 * h, h)
    s = 0.5 * np.pi * np.sinh(t)
    left = 1.0 / (1.0 + np.exp(-2.0 * s))
    right = 1.0 / (1.0 + np.exp(2.0 * s))
    w = 0.5 * h * (0.5 * np.pi) * np.cosh(t) / np.cosh(s) ** 2
    return left, right, w


_TS_LEFT, _TS_RIGHT, _TS_W = _tanh_sinh()
#: The lobe factor is truncated where it has fallen below e^{-60} of its value at
#: the kink (negligible against any relative accuracy in double precision).
_DECAY = 60.0


def _hs_phong(theta: np.ndarray, n: float) -> np.ndarray:
    """H_s for F_s = max(0, R·V)ⁿ, in the frame of R (α from R, φ about R).

    With c = cos θ_i, s = sin θ_i: V_z = cos α c + sin α s cos φ. For α below
    α_k = π/2 − θ_i the whole ring is above the horizon and the φ-integral is
    2π cos α c (closed form in α); above it, ∫(a + b cos φ)₊ dφ =
    2(a φ₀ + √(b² − a²)) with φ₀ = atan2(√(b² − a²), −a), b² − a² = sin²α − c².
    """
    th = theta[:, None]
    c, s = np.cos(th), np.sin(th)
    a_k = 0.5 * np.pi - th
    with np.errstate(divide="ignore"):
        log_s = np.log(s)
    # ∫_0^{α_k} cos^{n+1}α sin α dα · 2π c = 2π c (1 − sin^{n+2}θ)/(n+2)
    closed = 2.0 * np.pi * c * -np.expm1((n + 2.0) * log_s) / (n + 2.0)
    a_max = np.maximum(np.arccos(np.minimum(1.0, s * math.exp(-_DECAY / n))), a_k)
    length = a_max - a_k
    d = length * _TS_LEFT  # α − α_k
    e = (0.5 * np.pi - a_max) + length * _TS_RIGHT  # π/2 − α
    cos_a = np.sin(e)
    sin_a = np.sin(a_k + d)
    a = cos_a * c
    # sin α − sin α_k = 2 cos(α_k + d/2) sin(d/2), without cancellation
    r = np.sqrt(np.maximum(0.0, 2.0 * np.cos(a_k + 0.5 * d) * np.sin(0.5 * d) * (sin_a + c)))
    g = 2.0 * (a * np.arctan2(r, -a) + r)
    with np.errstate(divide="ignore"):
        lobe = np.exp(n * np.log(cos_a))
    part = length[:, 0] * np.sum(_TS_W * lobe * g * sin_a, axis=-1)
    return closed[:, 0] + part


def _hs_blinn(theta: np.ndarray, n: float) -> np.ndarray:
    """H_s for F_s = (N·H)ⁿ, integrated over H (θ_h = γ, azimuth φ about N).

    dω_V = 4 (S·H) dω_H and V_z = 2(S·H) cos γ − c. With x = S·H = A + B cos φ
    (A = c cos γ, B = s sin γ) the φ-integrand is 4x(2x cos γ − c)₊: the whole
    ring counts for γ ≤ γ₁ = (π/2 − θ_i)/2, none of it for γ ≥ γ₂ =
    (π/2 + θ_i)/2, and |φ| < φ₁ = arccos t in between, with
    1 + t = sin 2(γ − γ₁)/(2 cos γ B) and 1 − t = sin 2(γ₂ − γ)/(2 cos γ B).
    """
    th = theta[:, None]
    c, s = np.cos(th), np.sin(th)
    g1 = 0.5 * (0.5 * np.pi - th)
    g2 = 0.5 * (0.5 * np.pi + th)
    h1 = np.cos(g1)
    log_h1 = np.log(h1)
    # γ ≤ γ₁: 2π-ring integral 16π c² h³ + 8π s² h(1 − h²) − 8π c² h, times hⁿ, h from h₁ to 1
    full = ((16.0 * np.pi * c * c - 8.0 * np.pi * s * s) * -np.expm1((n + 4.0) * log_h1)
            / (n + 4.0)
            + (8.0 * np.pi * s * s - 8.0 * np.pi * c * c) * -np.expm1((n + 2.0) * log_h1)
            / (n + 2.0))
    g_max = np.minimum(g2, np.arccos(np.minimum(1.0, h1 * math.exp(-_DECAY / n))))
    g_max = np.maximum(g_max, g1)
    length = g_max - g1
    d1 = length * _TS_LEFT
    d2 = (g2 - g_max) + length * _TS_RIGHT
    g = g1 + d1
    h, sg = np.cos(g), np.sin(g)
    A = c * h
    B = np.maximum(s * sg, 1e-300)  # clamp: B = 0 only on an empty interval (θ_i = 0)
    den = 2.0 * h * B
    opt = np.maximum(np.sin(2.0 * d1) / den, 0.0)  # 1 + t (clamp: rounding at γ₁)
    omt = np.maximum(np.sin(2.0 * d2) / den, 0.0)  # 1 − t (clamp: rounding at γ₂)
    phi1 = 2.0 * np.arctan2(np.sqrt(omt), np.sqrt(opt))
    sin1 = np.sqrt(omt * opt)
    cos1 = 0.5 * (opt - omt)
    ring = (8.0 * h * (2.0 * A * A * phi1 + 4.0 * A * B * sin1 + B * B * (phi1 + sin1 * cos1))
            - 4.0 * c * (2.0 * A * phi1 + 2.0 * B * sin1))
    with np.errstate(divide="ignore"):
        lobe = np.exp(n * np.log(h))
    part = length[:, 0] * np.sum(_TS_W * lobe * ring * sg, axis=-1)
    return full[:, 0] + part


def specular_integral(theta_i, n: float, lobe: str = "phong") -> np.ndarray:
    """Lewis's H_s(S) = ∫_Ω F_s(S, V) (N·V) dω_V for F_s = max(0, R·V)ⁿ or (N·H)ⁿ.

    Parameters
    ----------
    theta_i : array_like
        Incident polar angle(s) in radians, in [0, π/2].
    n : float
        Exponent ≥ 0. n = 0 means F_s ≡ 1 (0⁰ = 1, Lewis §7), so H_s = π.
    lobe : {"phong", "blinn"}
        Lewis eq. (5) (R·V) or eq. (6) (N·H).

    Returns
    -------
    ndarray
        H_s(θ_i) (sr). Computed in the lobe frame with the azimuthal integral
        in closed form and a tanh-sinh rule over the polar angle where the
        horizon cuts the lobe; relative accuracy ~1e-11 for n ≤ 1e6. Checks:
        H_s(0) = 2π/(n+2) (Phong, Lewis eq. 16); H_s(π/2) = B((n+1)/2, 3/2)
        (Phong), 8π/((n+2)(n+4)) (Blinn); Blinn at n = 0 is π at every θ_i.
    """
    th = np.asarray(theta_i, dtype=np.float64)
    if np.any(~((th >= 0.0) & (th <= 0.5 * np.pi))):
        raise ParameterError(f"theta_i must lie in [0, pi/2] rad; got {theta_i!r}")
    if not (math.isfinite(n) and n >= 0.0):
        raise ParameterError(f"n must be a finite number >= 0; got {n!r}")
    if lobe not in ("phong", "blinn"):
        raise ParameterError(f"lobe must be one of phong, blinn; got {lobe!r}")
    flat = th.reshape(-1)
    if n == 0.0:
        return np.full(th.shape, np.pi)
    fn = _hs_phong if lobe == "phong" else _hs_blinn
    out = np.concatenate([fn(flat[i:i + 512], float(n)) for i in range(0, flat.size, 512)]
                         ) if flat.size else np.empty(0)
    return out.reshape(th.shape)


#: Relative tolerance of the H_s lookup (``phong-energy-conserving``'s kernel divides by
#: it): measured ≤ 2.6e-9 including the margin for n ∈ [0.5, 1e6], both lobes.
HS_LOOKUP_TOL = 1e-9


@functools.lru_cache(maxsize=64)
def _hs_table(n: float, lobe: str) -> Lookup:
    """H_s(θ_i) of *lobe* and *n* as the shared compiled lookup in μ = cos θ_i.

    An upper bound (so F_s/H_s never gains energy: the albedo is ≤ k_ρ to rounding)
    within 2.6e-9 relative (measured against :func:`specular_integral` for n = 0.5 …
    1e6, both lobes; the former table, cubic Lagrange in the grid variable w of
    :mod:`brdfkit.tables` at 512–4096 nodes, was within 7e-9 and 10–20 % slower to read).
    Built in 0.1–0.4 s for most n; the Phong lobe at n < 2 takes longer (~1 s at n = 1,
    ~5 s at n = 0.5: H_s has a term in θ_i^{n+2}, not smooth in μ at the normal, and the
    lookup refines uniformly in its last cell) and so does n ~ 1e6 (~1 s: the lobe meets
    the horizon within ~1e-3 of grazing).
    """
    # clamp: the lookup's last node may exceed μ = 1 by rounding (arccos would be NaN)
    return build_lookup(
        lambda mu: specular_integral(np.arccos(np.clip(mu, 0.0, 1.0)), n, lobe)[:, None],
        tol=HS_LOOKUP_TOL, bound="upper")


# --------------------------------------------------------------------------- modified Phong
@numba.njit(cache=True)
def _modified_phong(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    rho_d, rho_s, n = p[0], p[1], p[2]
    cos_r = r_dot_v(ix, iy, iz, ox, oy, oz)  # ω_r·ω_o
    return rho_d * INV_PI + rho_s * (n + 2.0) * INV_TWO_PI * lobe_pow(cos_r, n)


@register
class ModifiedPhong(BRDF):
    """Modified (normalised, reciprocal) Phong: Nielsen et al. eq. (1).

    f_r = ρ_d/π + ρ_s (n+2)/(2π) max(0, ω_r·ω_o)ⁿ, with ω_r the mirror of ω_i.
    This is Neumann eq. (6) with c_Phong(n) = ρ_s (n+2)/2π; the factor makes
    the specular albedo exactly ρ_s at normal incidence
    (∫ cosⁿα cos θ dω = 2π/(n+2) when the lobe is centred on the normal). At
    oblique incidence the horizon cuts the lobe and the albedo falls below ρ_d
    + ρ_s (Neumann §1.2: the "dark Phong mirror").

    ======  =======  ===========  =============================================
    name    default  bounds       meaning
    ======  =======  ===========  =============================================
    rho_d   0.2      [0, 1]       diffuse albedo (per channel)
    rho_s   0.5      [0, 1]       specular reflectance (per channel)
    n       20       [0, 1e6]     exponent; or give ``beta``, the half-angle
    ======  =======  ===========  =============================================

    Reciprocal (R·V is symmetric). Energy conserving when ρ_d + ρ_s ≤ 1.
    Sampled as a mixture of cosine and the cosⁿ lobe about the mirror of wo.
    """

    name = "modified-phong"
    aliases = ("phong-modified", "nielsen-phong")
    summary = "normalised reciprocal Phong, rho_d/pi + rho_s (n+2)/2pi (R.V)^n"
    params = (RHO_D, RHO_S, N_EXP)
    citation = "Nielsen et al. eq. (1); Neumann et al. 1999 eq. (6)"
    reciprocal = True
    has_sampler = True
    width_param = "n"
    kernel = _modified_phong
    examples = (
        {},
        {"rho_d": 0.0, "rho_s": 1.0, "n": 5000.0},
        {"rho_d": [0.1, 0.2, 0.3], "rho_s": [0.5, 0.4, 0.3], "n": 2.0},
    )

    def lobes(self):
        from brdfkit.halfangle import beta_from_exponent

        n = self._values["n"]
        out = [Lobe("diffuse", math.pi / 2)] if np.any(self._values["rho_d"]) else []
        return out + [Lobe("mirror", float(beta_from_exponent(n)) if n > 0 else math.pi / 2)]

    @classmethod
    def width_from_beta(cls, beta: float) -> float:
        return exponent_from_beta(beta)

    def sample(self, wo, u):
        wo = as_directions(wo, "wo")
        u = as_uniform(u)
        v = self._values
        p_d = diffuse_fraction(v["rho_d"], v["rho_s"])
        diffuse, u0 = split_uniform(u[..., 0], p_d)
        u = np.stack([u0, u[..., 1]], axis=-1)
        shape = np.broadcast_shapes(wo.shape, u.shape[:-1] + (3,))
        wi_d = np.broadcast_to(sample_cosine_hemisphere(u), shape)
        wi_s = np.broadcast_to(sample_phong_lobe(np.broadcast_to(reflect(wo), shape),
                                                 v["n"], u), shape)
        wi = np.where(diffuse[..., None], wi_d, wi_s)
        return wi, self.pdf(wi, wo)

    def pdf(self, wi, wo):
        wi = as_directions(wi, "wi")
        wo = as_directions(wo, "wo")
        v = self._values
        p_d = diffuse_fraction(v["rho_d"], v["rho_s"])
        cos_alpha = np.sum(wi * reflect(wo), axis=-1)
        p = p_d * pdf_cosine_hemisphere(wi) + (1.0 - p_d) * pdf_phong_lobe(cos_alpha, v["n"])
        return np.where(wo[..., 2] > 0.0, p, 0.0)




# --------------------------------------------------------------------------- mixture sampling
class _MixtureSampled(BRDF):
    """Models sampled by a mixture of cosine and lobe densities (:meth:`_mixture`)."""

    has_sampler = True

    @classmethod
    def width_from_beta(cls, beta: float) -> float:
        """Exponent with cosⁿβ = 1/2 (Lewis §3.1): ``n``, or ``s`` in ``nielsen``."""
        return float(exponent_from_beta(beta))

    def _mixture(self, wo: np.ndarray) -> tuple[list, np.ndarray]:
        """Components and weights (shape (K,) or (..., K), summing to 1) for viewer(s) *wo*."""
        raise NotImplementedError

    def sample(self, wo, u):
        wo = as_directions(wo, "wo")
        u = as_uniform(u)
        comps, w = self._mixture(wo)
        wi = _mixture_sample(comps, w, wo, u)
        return wi, self.pdf(wi, wo)

    def pdf(self, wi, wo):
        wi = as_directions(wi, "wi")
        wo = as_directions(wo, "wo")
        comps, w = self._mixture(wo)
        return _mixture_pdf(comps, w, wi, wo)


def _mean(x) -> float:
    return float(np.mean(x))


# --------------------------------------------------------------------------- Lewis: Phong, Blinn
@numba.njit(cache=True)
def _phong(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    k_d, k_s, n = p[0], p[1], p[2]
    # Lewis eq. (8) with F_s^P of eq. (5). The true f diverges like 1/(N·L) and overflows
    # float64 for N·L < k_s/1.8e308; N·L is floored at COS_DIVISOR_FLOOR (see there)
    return k_d + k_s * lobe_pow(r_dot_v(ix, iy, iz, ox, oy, oz), n) / max(iz, COS_DIVISOR_FLOOR)


@register
class Phong(_MixtureSampled):
    """The original Phong shader as a BRDF: Lewis eqs. (5) and (8).

    f_r(S, V) = k_d + k_s F_s^P(S, V)/(N·S), F_s^P = max(0, R_l·V)ⁿ with
    R_l = 2N(N·S) − S. Eq. (8) is what makes the shader L_r = [k_d (N·S) + k_s
    F_s] L_d (eq. 4) a BRDF. Its albedo is k_ρ = k_d π + k_s H_s(S)/(N·S)
    (Lewis eq. 19), which diverges as θ_i → 90° (H_s stays positive): the
    shader does not conserve energy for any k_s > 0 (Lewis §4.1).

    ======  =======  ===========  =============================================
    name    default  bounds       meaning
    ======  =======  ===========  =============================================
    k_d     0.1      [0, 1]       diffuse BRDF constant, 1/sr (per channel);
                                  albedo k_d π, so ≤ 1/π conserves energy
                                  (Lewis's figures use k_d = 1 − k_s)
    k_s     1        [0, 1e6]     specular coefficient, 1/sr (per channel)
    n       20       [0, 1e6]     Phong exponent n_s^P; or give ``beta``
                                  (cosⁿβ = 1/2, Lewis §3.1)
    ======  =======  ===========  =============================================

    Not reciprocal (the 1/(N·S) factor; Lewis §5.1). Sampled as a mixture of
    cosine (k_d) and the cosⁿ lobe about the mirror of wo: f cos θ_i = k_d cos θ_i
    + k_s (R_l·V)ⁿ, so the cosine of the division cancels and the lobe is
    sampled exactly.
    """

    name = "phong"
    aliases = ("phong-original", "lewis-phong")
    summary = "original Phong shader as a BRDF, k_d + k_s (R.V)^n / (N.L) (not reciprocal)"
    params = (K_D, K_S, N_EXP)
    citation = "Lewis 1993 eqs. (5) and (8)"
    reciprocal = False
    width_param = "n"
    kernel = _phong
    examples = (
        {},
        {"k_d": 0.0, "k_s": 800.0, "n": 5000.0},
        {"k_d": [0.05, 0.1, 0.15], "k_s": [1.0, 0.5, 0.25], "n": 3.0},
    )

    def lobes(self):
        out = [Lobe("diffuse", math.pi / 2)] if np.any(self._values["k_d"]) else []
        return out + [_lobe("mirror", self._values["n"])]

    def _mixture(self, wo):
        v = self._values
        n = v["n"]
        w = _normalised([math.pi * _mean(v["k_d"]), _mean(v["k_s"]) * 2.0 * math.pi / (n + 1.0)])
        return [("cosine", 0.0, None), ("phong", n, None)], w


@numba.njit(cache=True)
def _blinn(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    k_d, k_s, n = p[0], p[1], p[2]
    # Lewis eq. (8) with F_s^B of eq. (6); N·L floored as in _phong (COS_DIVISOR_FLOOR)
    return k_d + k_s * lobe_pow(n_dot_h(ix, iy, iz, ox, oy, oz), n) / max(iz, COS_DIVISOR_FLOOR)


@register
class Blinn(_MixtureSampled):
    """The Blinn shader as a BRDF: Lewis eqs. (6) and (8).

    f_r(S, V) = k_d + k_s (N·H)ⁿ/(N·S), H = (S + V)/|S + V|. Although F_s^B
    is symmetric, the 1/(N·S) makes the BRDF non-reciprocal (Lewis §5.1,
    footnote 9) and its albedo k_d π + k_s H_s(S)/(N·S) (eq. 19) diverges at
    grazing incidence.

    ======  =======  ===========  =============================================
    name    default  bounds       meaning
    ======  =======  ===========  =============================================
    k_d     0.1      [0, 1]       diffuse BRDF constant, 1/sr (per channel)
    k_s     1        [0, 1e6]     specular coefficient, 1/sr (per channel)
    n       20       [0, 1e6]     Blinn exponent n_s^B; or ``beta``
                                  (n = −ln 2/ln cos β, Lewis §3.1)
    ======  =======  ===========  =============================================

    Not reciprocal. Sampled as a mixture of cosine and the Blinn lobe: h with
    density (n+1)/(2π) cosⁿθ_h, wi the mirror of wo about h, pdf
    p_h/(4|wo·h|); f cos θ_i = k_d cos θ_i + k_s (N·H)ⁿ.
    """

    name = "blinn"
    aliases = ("blinn-original", "lewis-blinn")
    summary = "Blinn shader as a BRDF, k_d + k_s (N.H)^n / (N.L) (not reciprocal)"
    params = (K_D, K_S, N_EXP)
    citation = "Lewis 1993 eqs. (6) and (8)"
    reciprocal = False
    width_param = "n"
    kernel = _blinn
    examples = (
        {},
        {"k_d": 0.0, "k_s": 400.0, "n": 10000.0},
        {"k_d": [0.05, 0.1, 0.15], "k_s": [1.0, 0.5, 0.25], "n": 3.0},
    )

    def lobes(self):
        out = [Lobe("diffuse", math.pi / 2)] if np.any(self._values["k_d"]) else []
        return out + [_lobe("half", self._values["n"])]

    def _mixture(self, wo):
        v = self._values
        n = v["n"]
        w = _normalised([math.pi * _mean(v["k_d"]), _mean(v["k_s"]) * blinn_normal_albedo(n)])
        return [("cosine", 0.0, None), ("blinn", n, None)], w


# --------------------------------------------------------------------------- Lewis eq. (22)
PHONG_LOBE, BLINN_LOBE = 0, 1


@numba.njit(cache=True)
def _phong_energy_conserving(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    k_rho, k_sigma, n = p[0], p[1], p[2]
    if p[3] == PHONG_LOBE:
        fs = lobe_pow(r_dot_v(ix, iy, iz, ox, oy, oz), n)
    else:
        fs = lobe_pow(n_dot_h(ix, iy, iz, ox, oy, oz), n)
    hs = _lookup(p, 4, iz)  # H_s(S) > 0 at every θ_i, also at 90° (see _hs_table)
    return k_rho * ((1.0 - k_sigma) * INV_PI + k_sigma * fs / hs)


@register
class PhongEnergyConserving(_MixtureSampled):
    """Lewis's energy-conserving Phong shader, eq. (22).

    f_r(S, V) = k_ρ [(1 − k_σ)/π + k_σ F_s(S, V)/H_s(S)], with F_s Phong's
    max(0, R_l·V)ⁿ (eq. 5) or Blinn's (N·H)ⁿ (eq. 6) and
    H_s(S) = ∫ F_s(S, V') (N·V') dω' (the integral of Lewis eq. 17).
    Dividing by H_s makes the albedo exactly k_ρ at every incident angle —
    the model's defining property (eqs. 20–22 solve eq. 19 for k_d and k_s).

    H_s depends on θ_i and n only. It is computed once per (n, lobe) by
    quadrature in the lobe frame (:func:`specular_integral`, relative accuracy
    ~1e-11) and stored as the shared compiled lookup of :mod:`brdfkit.tables`
    (local cubics in cos θ_i, an upper bound within 2.6e-9 relative for
    n ≤ 1e6; see ``_hs_table``). At θ_i = 90° H_s is positive (e.g. B((n+1)/2, 3/2)
    for Phong), so the kernel is finite there.

    =======  =======  ============  ===========================================
    name     default  bounds        meaning
    =======  =======  ============  ===========================================
    k_rho    0.8      [0, 1]        directional-hemispherical reflectance k_ρ,
                                    the albedo at every θ_i (per channel)
    k_sigma  0.5      [0, 1]        specular fraction k_σ of the exitance
                                    (per channel)
    n        20       [0, 1e6]      exponent of F_s; or ``beta``
    lobe     blinn    phong/blinn   F_s^P (eq. 5) or F_s^B (eq. 6; Lewis's
                                    Fig. 6 uses Blinn)
    =======  =======  ============  ===========================================

    Not reciprocal: F_s(S,V)/H_s(S) ≠ F_s(V,S)/H_s(V) (Lewis §5.1). Sampled as
    a mixture of cosine (weight ∝ 1 − k_σ) and the lobe (Phong lobe about the
    mirror of wo, or the Blinn half-vector lobe).
    """

    name = "phong-energy-conserving"
    aliases = ("energy-conserving-phong", "lewis-energy-conserving")
    summary = "Lewis's energy-conserving Phong, k_rho[(1-k_sigma)/pi + k_sigma F_s/H_s(S)]"
    params = (
        Param("k_rho", 0.8, 0.0, 1.0, "",
              "directional-hemispherical reflectance: the albedo at every incident angle",
              kind="colour"),
        Param("k_sigma", 0.5, 0.0, 1.0, "", "fraction of the exitance reflected specularly",
              kind="colour"),
        N_EXP,
        Param("lobe", "blinn", kind="choice", choices=("phong", "blinn"),
              doc="specular function: phong (R.V)^n, Lewis eq. 5; blinn (N.H)^n, eq. 6"),
    )
    citation = "Lewis 1993 eq. (22) with (5)/(6) and H_s of eq. (17)"
    reciprocal = False
    width_param = "n"
    kernel = _phong_energy_conserving
    examples = (
        {},
        {"k_rho": 1.0, "k_sigma": 1.0, "n": 10000.0, "lobe": "phong"},
        {"k_rho": [0.9, 0.6, 0.3], "k_sigma": [0.2, 0.5, 0.8], "n": 5.0, "lobe": "phong"},
    )

    def _pack_channel(self, v):
        row = super()._pack_channel(v)
        return [*row, *_hs_table(float(v["n"]), v["lobe"]).packed(0).tolist()]

    def lobes(self):
        v = self._values
        out = [Lobe("diffuse", math.pi / 2)] if np.any(np.asarray(v["k_sigma"]) < 1.0) else []
        return out + [_lobe("mirror" if v["lobe"] == "phong" else "half", v["n"])]

    def specular_integral(self, theta_i) -> np.ndarray:
        """H_s(θ_i) of this model's lobe and exponent (see :func:`specular_integral`)."""
        return specular_integral(theta_i, self._values["n"], self._values["lobe"])

    def _mixture(self, wo):
        v = self._values
        k_rho, k_sigma = np.asarray(v["k_rho"]), np.asarray(v["k_sigma"])
        w = _normalised([_mean(k_rho * (1.0 - k_sigma)), _mean(k_rho * k_sigma)])
        return [("cosine", 0.0, None), (v["lobe"], v["n"], None)], w


# --------------------------------------------------------------------------- Lewis eq. (24)
@numba.njit(cache=True)
def _phong_blinn_reciprocal(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    return p[0] + p[1] * lobe_pow(n_dot_h(ix, iy, iz, ox, oy, oz), p[2])


@register
class PhongBlinnReciprocal(_MixtureSampled):
    """Lewis's reciprocal Phong–Blinn shader, eq. (24); Neumann's reciprocal Blinn, eq. (6).

    f_r(S, V) = k_d + k_s (N·H)ⁿ: eq. (8) without the 1/(N·S) of the specular
    term. Reciprocal because F_s^B is. Its albedo is bounded (Lewis Fig. 9),
    so energy is conserved by limiting k_d and k_s; at normal incidence the
    specular albedo is k_s·:func:`blinn_normal_albedo` (n) ≈ 8π k_s/n.

    ======  =======  ===========  =============================================
    name    default  bounds       meaning
    ======  =======  ===========  =============================================
    k_d     0.1      [0, 1]       diffuse BRDF constant, 1/sr (per channel)
    k_s     1        [0, 1e6]     specular coefficient, 1/sr (per channel)
    n       20       [0, 1e6]     Blinn exponent; or ``beta``
    ======  =======  ===========  =============================================

    Sampled as a mixture of cosine and the Blinn half-vector lobe.
    """

    name = "phong-blinn-reciprocal"
    aliases = ("reciprocal-phong-blinn", "reciprocal-blinn", "blinn-reciprocal")
    summary = "Lewis's reciprocal Phong-Blinn shader, k_d + k_s (N.H)^n"
    params = (K_D, K_S, N_EXP)
    citation = "Lewis 1993 eq. (24); Neumann et al. 1999 eq. (6) (reciprocal Blinn)"
    reciprocal = True
    width_param = "n"
    kernel = _phong_blinn_reciprocal
    examples = (
        {},
        {"k_d": 0.0, "k_s": 400.0, "n": 10000.0},
        {"k_d": [0.05, 0.1, 0.15], "k_s": [1.0, 0.5, 0.25], "n": 3.0},
    )

    def lobes(self):
        out = [Lobe("diffuse", math.pi / 2)] if np.any(self._values["k_d"]) else []
        return out + [_lobe("half", self._values["n"])]

    def _mixture(self, wo):
        v = self._values
        n = v["n"]
        w = _normalised([math.pi * _mean(v["k_d"]), _mean(v["k_s"]) * blinn_normal_albedo(n)])
        return [("cosine", 0.0, None), ("blinn", n, None)], w


# --------------------------------------------------------------------------- Lewis §7
@numba.njit(cache=True)
def _nh_power_series(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    m = int(p[0])
    nh = n_dot_h(ix, iy, iz, ox, oy, oz)
    acc = 0.0
    for i in range(m):
        acc += p[1 + i] * lobe_pow(nh, p[1 + m + i])  # (N·H)^0 = 1: the diffuse term
    return acc


@register
class NHPowerSeries(_MixtureSampled):
    """A power series in N·H, Lewis §7: f_r = Σ_i k_i (N·H)^{n_i}.

    Lewis suggests it as a basis for fitting, observing that a diffuse surface
    is the case n = 0 of eq. (24). Each term is reciprocal and has bounded
    albedo (k_i·:func:`blinn_normal_albedo` (n_i) at normal incidence), so
    the series is reciprocal and conserves energy for small enough k_i.

    ======  =======  ===========  =============================================
    name    default  bounds       meaning
    ======  =======  ===========  =============================================
    k_s     0.5      [0, 1e6]     coefficients k_i, 1/sr: one per term
    n       20       [0, 1e6]     exponents n_i, one per term; n_0 = 0 is the
                                  diffuse term ((N·H)^0 = 1)
    ======  =======  ===========  =============================================

    Give ``k_s`` and ``n`` as sequences of equal length (a scalar broadcasts),
    e.g. ``k_s=[0.1, 0.5, 20], n=[0, 10, 500]``. Lewis writes the coefficient
    as k_n; we name it k_s like the other specular coefficients. Sampled as a
    mixture of one Blinn lobe per term (cosine for n_i = 0).
    """

    name = "nh-power-series"
    aliases = ("nh-series", "lewis-power-series")
    summary = "Lewis's power series in N.H, sum_i k_i (N.H)^n_i (n_0 = 0: diffuse)"
    params = (
        Param("k_s", 0.5, 0.0, 1e6, "1/sr", "coefficient of each term (one per term)",
              kind="lobes"),
        Param("n", 20.0, 0.0, 1e6, "",
              "exponent of each term (one per term); 0 is the diffuse term", kind="lobes"),
    )
    citation = "Lewis 1993 §7 (power series generalising eq. (24))"
    reciprocal = True
    kernel = _nh_power_series
    examples = (
        {"k_s": [0.1, 0.5, 5.0], "n": [0.0, 10.0, 200.0]},
        {"k_s": [0.05, 400.0], "n": [0.0, 10000.0]},
        {"k_s": 0.3, "n": 5.0},
    )

    def _pack_channel(self, v):
        k, n = np.asarray(v["k_s"], dtype=np.float64), np.asarray(v["n"], dtype=np.float64)
        return [float(k.size), *k.tolist(), *n.tolist()]  # the kernel reads the count first

    def lobes(self):
        v = self.channel_values(0)
        out = [_lobe("half", float(n)) for k, n in zip(v["k_s"], v["n"], strict=True) if k > 0.0]
        return out or [Lobe("diffuse", math.pi / 2)]

    def _mixture(self, wo):
        v = self.channel_values(0)
        comps = [("blinn", float(n), None) for n in v["n"]]
        w = _normalised([k * blinn_normal_albedo(n) for k, n in zip(v["k_s"], v["n"], strict=True)])
        return comps, w


# --------------------------------------------------------------------------- Nielsen eq. (2)
@numba.njit(cache=True)
def _modified_blinn_phong(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    rho_d, rho_s, n = p[0], p[1], p[2]
    nh = n_dot_h(ix, iy, iz, ox, oy, oz)
    return rho_d * INV_PI + rho_s * (n + 8.0) * (1.0 / (8.0 * math.pi)) * lobe_pow(nh, n)


@register
class ModifiedBlinnPhong(_MixtureSampled):
    """Modified Blinn–Phong: Nielsen et al. eq. (2), after Akenine-Möller et al. 2008.

    f_r = ρ_d/π + ρ_s (n+8)/(8π) (ω_h·n)ⁿ. The factor (n+8)/8π is an
    APPROXIMATE normalisation, kept here as printed. The exact normal-incidence
    albedo of the N·H lobe is (:func:`blinn_normal_albedo`)

        ∫ (N·H)ⁿ cos θ_o dω_o = 8π [2(1 − 2^{−(n+4)/2})/(n+4) − (1 − 2^{−(n+2)/2})/(n+2)],

    so the specular albedo at normal incidence is ρ_s·(n+8)/(8π)·that, which is
    ≥ ρ_s for every n ≥ 0: exactly ρ_s at n = 0, 1.0243 ρ_s at n = 1, 1.0625 ρ_s
    at n = 4, a maximum of 1.0752 ρ_s at n ≈ 8.76, 1.0607 ρ_s at n = 20,
    1.0181 ρ_s at n = 100 and ≈ (1 + 2/n) ρ_s for large n (the exact factor,
    1/that integral, tends to (n+2)(n+4)/(8πn) ≈ (n+6)/8π). The approximation thus
    over-estimates the albedo by up to 7.5 %: ρ_d + ρ_s ≤ 1 does not quite
    guarantee energy conservation.

    ======  =======  ===========  =============================================
    name    default  bounds       meaning
    ======  =======  ===========  =============================================
    rho_d   0.2      [0, 1]       diffuse albedo (per channel)
    rho_s   0.5      [0, 1]       specular reflectance (per channel)
    n       20       [0, 1e6]     exponent (Nielsen's s); or ``beta``
    ======  =======  ===========  =============================================

    Reciprocal (N·H is symmetric). Sampled as a mixture of cosine and the
    Blinn half-vector lobe.
    """

    name = "modified-blinn-phong"
    aliases = ("blinn-phong-modified", "nielsen-blinn-phong")
    summary = "normalised reciprocal Blinn-Phong, rho_d/pi + rho_s (n+8)/8pi (N.H)^n"
    params = (RHO_D, RHO_S, N_EXP)
    citation = "Nielsen et al. eq. (2); Akenine-Möller et al. 2008"
    reciprocal = True
    width_param = "n"
    kernel = _modified_blinn_phong
    examples = (
        {},
        {"rho_d": 0.0, "rho_s": 1.0, "n": 10000.0},
        {"rho_d": [0.1, 0.2, 0.3], "rho_s": [0.5, 0.4, 0.3], "n": 2.0},
    )

    def lobes(self):
        out = [Lobe("diffuse", math.pi / 2)] if np.any(self._values["rho_d"]) else []
        return out + [_lobe("half", self._values["n"])]

    def _mixture(self, wo):
        v = self._values
        p_d = diffuse_fraction(v["rho_d"], v["rho_s"])
        return [("cosine", 0.0, None), ("blinn", v["n"], None)], np.array([p_d, 1.0 - p_d])


# --------------------------------------------------------------------------- Lafortune
@numba.njit(cache=True)
def _lafortune(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    m = int(p[0])
    rho_d, rho_s = p[1], p[2]
    xy = ix * ox + iy * oy
    zz = iz * oz
    acc = 0.0
    for j in range(m):
        base = p[3 + j] * xy + p[3 + m + j] * zz
        # clamp at 0 (lobe_pow): a negative base is a lobe pointing away from wo; its
        # non-integer power is undefined and a negative lobe would be unphysical
        acc += lobe_pow(base, p[3 + 2 * m + j])
    return rho_d * INV_PI + rho_s * acc


def _lafortune_axis(c_xy: float, c_z: float):
    def axis(wo):
        a = stack(c_xy * wo[..., 0], c_xy * wo[..., 1], c_z * wo[..., 2])
        norm = np.linalg.norm(a, axis=-1, keepdims=True)
        up = np.broadcast_to(np.array([0.0, 0.0, 1.0]), a.shape)
        # zero axis (C_xy = C_z = 0): the lobe vanishes and gets weight 0; any axis will do
        return np.where(norm > 0.0, a / np.where(norm > 0.0, norm, 1.0), up)
    return axis


@register
class Lafortune(_MixtureSampled):
    """Lafortune et al. 1997 generalised cosine lobes; Neumann et al. eq. (7).

    f_r = ρ_d/π + ρ_s Σ_j max(0, C_xy,j (ix·ox + iy·oy) + C_z,j iz·oz)^{n_j}
    (isotropic: C_x = C_y = C_xy). With R = (−ix, −iy, iz) the mirror of wi,
    Neumann's form c_Lafortune (R_x V_x + R_y V_y + s R_z V_z)ⁿ is one lobe with
    C_xy = −c, C_z = c·s and c_Lafortune = cⁿ (the constant moves inside the
    power). C_xy = −1, C_z = 1 is the Phong lobe (R·V)ⁿ; C_xy = −C_z·k with
    k > 1 (|C_z| < |C_xy|) pushes the lobe toward grazing (Neumann's s < 1:
    "emphasis to grazing angles"); C_xy > 0 gives retro-reflection; C_xy = 0 a
    lobe about the normal. The base is clamped at 0 (see the kernel).

    ======  =======  ============  ===========================================
    name    default  bounds        meaning
    ======  =======  ============  ===========================================
    rho_d   0.2      [0, 1]        diffuse albedo (per channel)
    rho_s   1        [0, 1e6]      scale of the lobe sum (per channel)
    C_xy    −1       [−100, 100]   tangential coefficient of each lobe
    C_z     1        [−100, 100]   normal coefficient of each lobe
    n       20       [0, 1e6]      exponent of each lobe; or ``beta`` (sets
                                   every lobe's exponent)
    ======  =======  ============  ===========================================

    ``C_xy``, ``C_z`` and ``n`` may be sequences (one value per lobe, equal
    lengths; scalars broadcast). The lobe's peak is max(|C_xy|, |C_z|)ⁿ, which
    must stay finite (checked). Reciprocal (the form is symmetric in wi, wo).
    Sampled as a mixture of cosine and, per lobe, the cosⁿ lobe about the unit
    axis along (C_xy ox, C_xy oy, C_z oz) — exact in shape, since the base is
    wi·(C_xy ox, C_xy oy, C_z oz) — weighted by its integral.
    """

    name = "lafortune"
    aliases = ("lafortune-1997", "generalized-cosine-lobe")
    summary = "Lafortune et al. 1997 generalised cosine lobes (Neumann eq. 7)"
    params = (
        RHO_D,
        Param("rho_s", 1.0, 0.0, 1e6, "", "scale of the lobe sum", kind="colour"),
        Param("C_xy", -1.0, -100.0, 100.0, "", "tangential coefficient (-1: mirror lobe)",
              kind="lobes"),
        Param("C_z", 1.0, -100.0, 100.0, "", "normal coefficient (1: mirror lobe)",
              kind="lobes"),
        Param("n", 20.0, 0.0, 1e6, "", "exponent of each lobe", kind="lobes"),
    )
    citation = "Lafortune et al. 1997; Neumann et al. 1999 eq. (7)"
    reciprocal = True
    width_param = "n"
    kernel = _lafortune
    examples = (
        {"C_xy": [-1.0, -0.9], "C_z": [1.0, 0.7], "n": [20.0, 5.0]},
        {"rho_d": 0.0, "C_xy": -1.0, "C_z": 1.0, "n": 10000.0},
        {"rho_d": [0.1, 0.2, 0.3], "rho_s": [1.0, 0.8, 0.6], "C_xy": [-1.0, 0.5],
         "C_z": [0.95, 0.5], "n": [30.0, 2.0]},
    )

    def _validate(self):
        v = self.channel_values(0)
        big = np.maximum(np.abs(v["C_xy"]), np.abs(v["C_z"]))
        with np.errstate(divide="ignore"):
            log_peak = v["n"] * np.log(big)
        bad = np.flatnonzero(log_peak > 690.0)  # e^690 ≈ 1e300: the lobe's peak value
        if bad.size:
            j = int(bad[0])
            raise ParameterError(
                f"{self.name}: lobe {j} has peak max(|C_xy|, |C_z|)^n = "
                f"{big[j]:g}^{v['n'][j]:g}, beyond 1e300; reduce C_xy, C_z or n"
            )

    def _pack_channel(self, v):
        row = [float(self.n_lobes()), float(v["rho_d"]), float(v["rho_s"])]
        for name in ("C_xy", "C_z", "n"):
            row.extend(np.asarray(v[name], dtype=np.float64).tolist())
        return row  # the kernel reads the number of lobes first

    def lobes(self):
        v = self.channel_values(0)
        out = [Lobe("diffuse", math.pi / 2)] if np.any(self._values["rho_d"]) else []
        for c_xy, n in zip(v["C_xy"], v["n"], strict=True):
            # C_xy < 0: about the (off-)specular direction; 0: about the normal; > 0: retro
            kind = "mirror" if c_xy < 0.0 else ("normal" if c_xy == 0.0 else "diffuse")
            lb = _lobe(kind, float(n))
            out.append(lb if kind != "diffuse" else Lobe("diffuse", lb.width))
        return out

    def _mixture(self, wo):
        v = self.channel_values(0)
        comps = [("cosine", 0.0, None)]
        logw = [np.full(wo.shape[:-1], math.log(_mean(self._values["rho_d"]))
                        if _mean(self._values["rho_d"]) > 0.0 else -np.inf)]
        rho_s = _mean(self._values["rho_s"])
        log_s = math.log(rho_s) if rho_s > 0.0 else -np.inf
        for c_xy, c_z, n in zip(v["C_xy"], v["C_z"], v["n"], strict=True):
            comps.append(("phong", float(n), _lafortune_axis(float(c_xy), float(c_z))))
            if n == 0.0:  # constant lobe over the hemisphere: ∫ 1 cos θ_i dω = π
                logw.append(np.full(wo.shape[:-1], log_s + math.log(math.pi)))
                continue
            size = np.sqrt((c_xy * c_xy) * (wo[..., 0] ** 2 + wo[..., 1] ** 2)
                           + (c_z * wo[..., 2]) ** 2)
            with np.errstate(divide="ignore"):
                # ∫ (wi·a)₊ⁿ dω = |a|ⁿ 2π/(n+1), in logs (|a|ⁿ may overflow or underflow)
                logw.append(log_s + n * np.log(size) + math.log(2.0 * math.pi / (n + 1.0)))
        logw = np.stack(logw, axis=-1)
        top = np.max(logw, axis=-1, keepdims=True)
        none = ~np.isfinite(top)
        with np.errstate(invalid="ignore"):
            w = np.exp(logw - np.where(none, 0.0, top))
        w = np.where(none, np.eye(len(comps))[0], w)  # nothing reflects: cosine
        return comps, w / np.sum(w, axis=-1, keepdims=True)


# --------------------------------------------------------------------------- Neumann eq. (22)
@numba.njit(cache=True)
def _neumann_phong(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    c_n, n = p[0], p[1]
    # max(N·L, N·V) > 0 above the horizon but can be subnormal (both directions within
    # 1e-300 of the horizon), where c_n/max overflows; floored at COS_DIVISOR_FLOOR (see there)
    return c_n * lobe_pow(r_dot_v(ix, iy, iz, ox, oy, oz), n) / max(iz, oz, COS_DIVISOR_FLOOR)


@register
class NeumannPhong(_MixtureSampled):
    """The limit of repeated controlled pumping-up of Phong: Neumann et al. eq. (22).

    f_r(L, V) = c_n max(0, R·V)ⁿ / max(N·L, N·V).

    The paper states that c_n ≤ (n+2)/2π "must hold in order for the model to
    preserve energy balance"; ``c_n=None`` (default) takes that value. The
    bound is NECESSARY (at normal incidence the albedo is c_n 2π/(n+2), Lewis
    eq. 16). It is SUFFICIENT only for exponents that are not small: with
    c_n = (n+2)/2π the albedo peaks at normal incidence for n ≳ 1.7
    (numerically; e.g. n = 2, 5, 50, 1000), but for smaller n it exceeds 1 at
    oblique incidence — slightly at n = 1 (1.00029 at θ_i ≈ 13°), more at
    n = 0.1 (≈ 1.06 at θ_i = 45°), and at n = 0 (0⁰ = 1) it is exactly
    2 − cos θ_i (split the hemisphere at cos θ_o = cos θ_i:
    [2π(1 − cos θ_i) + π cos θ_i]/π). A bound sufficient for all
    n is c_n ≤ (n+1)/2π, because cos θ_o/max(cos θ_i, cos θ_o) ≤ 1 and
    ∫ max(0, R·V)ⁿ dω ≤ 2π/(n+1). Values above either bound are accepted, so
    that analyses can show the violation.

    ======  =======  ===========  =============================================
    name    default  bounds       meaning
    ======  =======  ===========  =============================================
    c_n     None     [0, 1e7]     scale, 1/sr (per channel); None: (n+2)/2π,
                                  the paper's bound
    n       20       [0, 1e6]     exponent; or ``beta``
    ======  =======  ===========  =============================================

    Reciprocal (R·V and max(N·L, N·V) are symmetric). Sampled by the cosⁿ
    lobe about the mirror of wo (cosine for n = 0).
    """

    name = "neumann-phong"
    aliases = ("neumann-22", "pumped-phong-limit")
    summary = "Neumann et al. eq. (22): c_n (R.V)^n / max(N.L, N.V)"
    params = (
        Param("c_n", None, 0.0, 1e7, "1/sr",
              "scale; none: (n+2)/2pi, the paper's bound (not sufficient, see docs)",
              kind="colour", optional=True),
        N_EXP,
    )
    citation = "Neumann et al. 1999 eq. (22)"
    albedo_kinks = frozenset({"nv=nl"})  # the max(N·L, N·V) denominator of eq. (22)
    reciprocal = True
    width_param = "n"
    kernel = _neumann_phong
    examples = (
        {},
        {"n": 5000.0},
        {"c_n": [0.5, 1.0, 2.0], "n": 10.0},
    )

    def c_n(self, channel: int = 0) -> float:
        """The scale in use for *channel* (the paper's bound (n+2)/2π when c_n is None)."""
        v = self.channel_values(channel)
        return (v["n"] + 2.0) * INV_TWO_PI if v["c_n"] is None else float(v["c_n"])

    def _pack_channel(self, v):
        c_n = (v["n"] + 2.0) * INV_TWO_PI if v["c_n"] is None else float(v["c_n"])
        return [c_n, float(v["n"])]

    def lobes(self):
        return [_lobe("mirror", self._values["n"])]

    def _mixture(self, wo):
        return [("phong", self._values["n"], None)], np.array([1.0])


# --------------------------------------------------------------------------- Nielsen eq. (3)
@numba.njit(cache=True)
def _nielsen(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    rho_d, k_s, s, alpha, eta = p[0], p[1], p[2], p[3], p[4]
    # One square root, one division: ω_h·n = (N·L + N·V)/|L + V|,
    # ω_i·ω_h = (1 + L·V)/|L + V| = |L + V|/2 and ω_r·ω_o = 2(N·L)(N·V) − L·V.
    # |L + V| comes from the components (not √(2 + 2 L·V), which rounds to 0 for
    # grazing opposite directions).
    lv = ix * ox + iy * oy + iz * oz
    sx, sy, sz = ix + ox, iy + oy, iz + oz
    length = math.sqrt(sx * sx + sy * sy + sz * sz)  # ≥ sz > 0 above the horizon, but:
    if length < SMALL_LENGTH:
        # rare: the squares underflowed (grazing, nearly opposite directions); 0 here would
        # give hz = inf. Scale by the largest component first (brdfkit._kern.half).
        length = scaled_length(sx, sy, sz)
        m = max(abs(sx), abs(sy), sz)
        hz = (sz / m) / (length / m)
    else:
        hz = sz / length
    f = 1.0 if eta == 0.0 else _fresnel_dielectric(0.5 * length, eta)  # no eta: F = 1
    hz2 = hz * hz
    base = (1.0 - alpha) * (2.0 * iz * oz - lv) + alpha * hz2 * hz2
    # clamp the mixed base at 0 (lobe_pow): R·V < 0 away from the mirror direction can make
    # it negative, where a non-integer power is undefined and the Phong lobe of eq. (1)
    # is 0 (max(0, ·), as in Akenine-Möller et al.)
    return rho_d * INV_PI + k_s * f * lobe_pow(base, s)


@register
class Nielsen(_MixtureSampled):
    """Nielsen et al.'s Phong variant, eq. (3), with Fresnel-weighted specular term.

    f_r = ρ_d/π + k_s R_F(ω_i·ω_h, η) max(0, (1 − α)(ω_r·ω_o) + α(ω_h·n)⁴)^s.

    α = 0 is the (unnormalised) modified Phong lobe, α = 1 the Blinn–Phong
    lobe (N·H)^{4s} ("the Phong exponent is roughly 4 times" the Blinn one).
    The paper multiplies k_s by the Fresnel reflectance R_F(ω_i·ω_h, η) in the
    text; here the exact dielectric Fresnel (:func:`brdfkit.fresnel.fresnel_dielectric`),
    F = 1 when η is not given. k_s stands for ρ_s times a normalisation (the
    text prints "(s+ε)/(sπ)", a garbled (s+2)/2π), so k_s has units 1/sr and
    is not bounded by 1.

    ======  =======  ===========  =============================================
    name    default  bounds       meaning
    ======  =======  ===========  =============================================
    rho_d   0.2      [0, 1]       diffuse albedo (per channel)
    k_s     2        [0, 1e6]     specular coefficient, 1/sr (per channel);
                                  ≈ ρ_s (s+2)/2π
    s       20       [0, 1e6]     exponent (shininess); or ``beta``
    alpha   0.5      [0, 1]       interpolation: 0 Phong-like, 1 Blinn-like
                                  grazing behaviour
    eta     None     (0, 100]     refractive index (per channel); None: F = 1
    ======  =======  ===========  =============================================

    Reciprocal: ω_r·ω_o (= R·V), ω_h·n and ω_i·ω_h = ω_o·ω_h are all symmetric.
    Sampled as a mixture of cosine, the cosˢ lobe about the mirror of wo
    (weight ∝ 1 − α) and the Blinn lobe of exponent 4s (weight ∝ α).
    """

    name = "nielsen"
    aliases = ("nielsen-2015", "nielsen-eq3", "nielsen-mixed")
    summary = "Nielsen et al. eq. (3): Fresnel-weighted mix of Phong and Blinn-Phong cosines"
    params = (
        RHO_D,
        Param("k_s", 2.0, 0.0, 1e6, "1/sr", "specular coefficient (~ rho_s (s+2)/2pi)",
              kind="colour"),
        Param("s", 20.0, 0.0, 1e6, "", "shininess exponent"),
        Param("alpha", 0.5, 0.0, 1.0, "", "mix: 0 Phong (R.V), 1 Blinn-Phong (N.H)^4"),
        Param("eta", None, 0.0, 100.0, "", "refractive index; none: F = 1", kind="colour",
              lower_open=True, optional=True),
    )
    citation = "Nielsen et al. eq. (3), Fresnel factor as in the text"
    reciprocal = True
    width_param = "s"
    kernel = _nielsen
    examples = (
        {"eta": 1.5},
        {"rho_d": 0.0, "k_s": 800.0, "s": 5000.0, "alpha": 0.3},
        {"rho_d": [0.1, 0.2, 0.3], "k_s": [3.0, 2.0, 1.0], "s": 8.0, "alpha": 0.7,
         "eta": [1.4, 1.5, 1.6]},
    )

    # Nielsen's α is not the microfacet roughness; its name matches the paper.
    def lobes(self):
        v = self._values
        out = [Lobe("diffuse", math.pi / 2)] if np.any(v["rho_d"]) else []
        if v["alpha"] < 1.0:
            out.append(_lobe("mirror", v["s"]))
        if v["alpha"] > 0.0:
            out.append(_lobe("half", 4.0 * v["s"]))
        return out

    def _mixture(self, wo):
        v = self._values
        s, alpha, k_s = v["s"], v["alpha"], _mean(v["k_s"])
        w = _normalised([_mean(v["rho_d"]),
                         k_s * (1.0 - alpha) * 2.0 * math.pi / (s + 2.0),
                         k_s * alpha * blinn_normal_albedo(4.0 * s)])
        return [("cosine", 0.0, None), ("phong", s, None), ("blinn", 4.0 * s, None)], w
