"""
He-Torrance-Sillion-Greenberg (1991)
====================================

The physically based model of He et al. (1991) as Neumann et al. use it:
directional-diffuse part as the kernel, the specular delta as
:meth:`HeTorrance.specular_albedo`. Shadowing, effective roughness and the
series of D are the free functions :func:`htsg_shadow`, :func:`htsg_sigma`,
:func:`htsg_series`; the kernel takes σ and S from the formulas below (one source with
the traced route), the series from :func:`htsg_series`.

The same as formulas (:mod:`brdfkit._dual`: the Mitsuba bridge's traced route), with
fixed-length, branch-free forms of the two loops (:func:`he_torrance_formulas`):

- the effective roughness σ: HTSG's equation for u = z₀/σ₀, √(π/2) u = A e^{−u²/2}, is
  u² e^{u²} = B², B = A√(2/π), so u² = W(B²) (Lambert's W). W is computed from
  L = ln B² by SIGMA_NEWTON_STEPS Newton steps on w + ln w = L (concave: from the first
  step on the iterates approach the root from below, staying positive) from Winitzki's
  start w₀ = ℓ(1 − ln(1 + ℓ)/(2 + ℓ)), ℓ = ln(1 + e^L), within 2 % of W everywhere;
  the relative error squares per step (factor ≤ 1/2): ≤ 1e-15 after four
  (:func:`htsg_sigma_of_coef_formula`; tests/test_formulas_he_torrance.py checks it
  against SciPy's Lambert W and :func:`htsg_sigma`'s safeguarded Newton);
- the series of D: written as T = S/g = Σ_{m≥1} e^{−g} g^{m−1}/(m!·m) e^{−a/m} (so that
  G·S = (v·v)²(2πσ)² T needs no division by v_z and no small-g branch), summed upward
  from m = 1 over a fixed number of terms N, the smallest whose tail bound
  g^N/((N+1)!(N+1)(1 − g/(N+2))) is ≤ SERIES_TOL at the instance's largest
  g = (4πσ₀)² (σ ≤ σ₀, v_z ≤ 2): |T_N − T| ≤ 1e-12·T(g, 0) (the lobe's value at its
  peak for that g; relative to the local value only where that is not ≪ the peak).
  An instance that needs more than SERIES_MAX_TERMS terms (σ₀ ≳ 0.45) gives no
  formulas: the bridge's wavefront route.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from brdfkit._cache import memo
from brdfkit._dual import Formulas, erfc, exp, formula, log, log1p, maximum, minimum, select, sqrt
from brdfkit._kern import INV_PI, below_horizon
from brdfkit.errors import ParameterError
from brdfkit.fresnel import _fresnel_conductor
from brdfkit.halfangle import beta_from_beckmann_m
from brdfkit.models._base import BRDF, Lobe, Param
from brdfkit.models._params import ETA, packed_indices
from brdfkit.models._registry import register
from brdfkit.models.microfacet_distributions import SQRT_PI, _HalfVectorSampling
from brdfkit.models.ward import ward_pdf, ward_sample

_jit = numba.njit(cache=True, inline="always")

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


# --------------------------------------------------------------------------- formulas
#: Newton steps of the formula σ (module docstring): Winitzki's start is within 2 % of W
#: (measured ≤ 1.9 %); the relative error e → e²/2 per step: 2e-2, 2e-4, 2e-8, 2e-16
SIGMA_NEWTON_STEPS = 4
#: L = ln B² above which Winitzki's ln(1 + e^L) is L (e^{−30} ≈ 1e-13 relative, below the
#: Newton steps' reach), and below which W(e^L) = x(1 − x) (x = e^L ≤ 1e-13: the next term
#: 1.5x³ is below float64's resolution of x)
SIGMA_LOG_SPLIT = 30.0
#: cap of L: never reached in float64 (A ≤ 1e300·erfc ≤ e^{691}, L ≤ 1383); in float32 an
#: A that overflows (a cosine below 1e-38) gives L = inf: capped, σ finite (≈ σ₀/100)
SIGMA_LOG_CAP = 1e4
LOG_TWO_OVER_PI = math.log(2.0 / math.pi)
TINY_COS = 1e-300  # the floor of _htsg_k, kept
#: the longest series the formula sums (module docstring): beyond it the wavefront route
SERIES_MAX_TERMS = 64
TWO_PI = 2.0 * math.pi
QUARTER_PI2 = 0.25 * math.pi * math.pi  # D = (π²τ²/4) Σ …
SHADOW_GRAZING = 1e-8  # htsg_shadow's small-a limit, kept


@formula
def _w_step(w, big_l):
    """One Newton step on w + ln w = L: w (1 + L − ln w)/(1 + w)."""
    return w * (1.0 + big_l - log(w)) / (1.0 + w)


@formula
def htsg_sigma_of_coef_formula(a_coef, sigma0):
    """σ = σ₀/√(1 + u²), u² = W(B²), from HTSG's A = (K_i + K_r)/4 (module docstring; A ≤ 0:
    σ₀, as :func:`htsg_sigma`)."""
    live = a_coef > 0.0
    big_l = minimum(2.0 * log(select(live, a_coef, 1.0)) + LOG_TWO_OVER_PI, SIGMA_LOG_CAP)
    x = exp(minimum(big_l, SIGMA_LOG_SPLIT))
    ell = select(big_l > SIGMA_LOG_SPLIT, big_l, log1p(x))
    w = ell * (1.0 - log1p(ell) / (2.0 + ell))  # Winitzki's start
    w = maximum(w, 1e-300)  # floor: ln w finite (the lanes that use the series below)
    w = _w_step(w, big_l)
    w = _w_step(w, big_l)
    w = _w_step(w, big_l)
    w = _w_step(w, big_l)  # SIGMA_NEWTON_STEPS
    w = select(big_l < -SIGMA_LOG_SPLIT, x * (1.0 - x), w)  # W(x) = x − x² + O(x³)
    return select(live, sigma0 / sqrt(1.0 + w), sigma0)


@formula
def htsg_k_shadow_formula(cos_t, sigma0, tau):
    """(K(θ), S(θ)) of one direction with ONE erfc, a = τ cot θ/(2σ₀): :func:`_htsg_k` and
    :func:`htsg_shadow` as one formula (their branches selects, the same operations).
    Equal to them for cos θ ≥ 1e-300 (TINY_COS); below it K's tan θ is floored as before
    but its erfc reads the true a (the same to O(a) ≤ 1e-8 relative, since then a < 1e-8
    unless σ₀/τ < 1e-292)."""
    c = maximum(cos_t, TINY_COS)  # floor: tan θ stays finite (< 1e300) at the horizon
    sin_t = sqrt(maximum(0.0, 1.0 - cos_t * cos_t))  # clamp: rounding near the pole
    pos = sin_t > 0.0
    a = tau * cos_t / (2.0 * sigma0 * select(pos, sin_t, 1.0))  # 1.0: the normal (S = 1, K = 0)
    erfc_a = erfc(a)
    k = select(pos, (sin_t / c) * erfc_a, 0.0)
    small = a < SHADOW_GRAZING  # grazing: S = a√π (1 + O(a))
    b = select(small, 1.0, a)  # 1.0: the discarded lane stays finite
    lam = 0.5 * (exp(-b * b) / (b * SQRT_PI) - erfc_a)
    s = select(small, a * SQRT_PI, (1.0 - 0.5 * erfc_a) / (lam + 1.0))
    return k, select(cos_t <= 0.0, 0.0, select(pos, s, 1.0))


def series_terms(g_max: float) -> int:
    """The number N of terms of the formula's series for g ≤ *g_max*: the smallest with
    tail bound g^N/((N+1)!(N+1)(1 − g/(N+2))) ≤ SERIES_TOL (module docstring), or
    SERIES_MAX_TERMS + 1 when none up to SERIES_MAX_TERMS is."""
    log_g = math.log(g_max) if g_max > 0.0 else -math.inf
    for n in range(1, SERIES_MAX_TERMS + 1):
        if n + 2 <= g_max:
            continue
        log_bound = (n * log_g - math.lgamma(n + 2.0) - math.log(n + 1.0)
                     - math.log1p(-g_max / (n + 2.0)))
        if log_bound <= math.log(SERIES_TOL):
            return n
    return SERIES_MAX_TERMS + 1


_EVAL_SOURCE = '''"""brdfkit: generated he-torrance formula, {n} terms of D's series."""
from brdfkit._dual import exp, formula, select, sqrt
from brdfkit.fresnel import _fresnel_conductor
from brdfkit.models.he_torrance import (INV_PI, QUARTER_PI2, TWO_PI, htsg_k_shadow_formula,
                                        htsg_sigma_of_coef_formula)


@formula(cache={cache})
def he_torrance_eval(ix, iy, iz, ox, oy, oz, p):
    sigma0, tau, eta, kappa, rho_d = p[{p_sigma0}], p[{p_tau}], p[{p_eta}], p[{p_k}], p[{p_rho_d}]
    live = (iz > 0.0) & (oz > 0.0)
    sx = ix + ox
    sy = iy + oy
    sz = iz + oz
    vv = sx * sx + sy * sy + sz * sz
    k_i, shadow_i = htsg_k_shadow_formula(iz, sigma0, tau)
    k_r, shadow_r = htsg_k_shadow_formula(oz, sigma0, tau)
    sigma = htsg_sigma_of_coef_formula(0.25 * (k_i + k_r), sigma0)
    q = TWO_PI * sigma
    g = (q * sz) * (q * sz)
    a = tau * tau * (TWO_PI * TWO_PI) * (sx * sx + sy * sy) / 4.0
    # T = S/g: the terms e^(-g) g^(m-1)/m! (w) over m, times e^(-a/m)
    w = exp(-g)
    t = w * exp(-a)
{terms}
    geo_d = vv * vv * (q * q) * t * QUARTER_PI2 * tau * tau
    s_i = shadow_i / select(live, iz, 1.0)
    s_r = shadow_r / select(live, oz, 1.0)
    cos_d = sqrt(vv) * 0.5
    f = select(eta == 0.0, 1.0, _fresnel_conductor(cos_d, eta, kappa))
    return select(live, f * geo_d * s_i * s_r * INV_PI + rho_d * INV_PI, 0.0)
'''


def _eval_source(n: int, cache: bool) -> str:
    terms = "\n".join(f"    w = w * g / {m!r}\n    t = t + w / {m!r} * exp(-a / {m!r})"
                      for m in (float(k) for k in range(2, n + 1)))
    return _EVAL_SOURCE.format(n=n, cache=cache, terms=terms, p_sigma0=P_SIGMA0, p_tau=P_TAU,
                               p_eta=P_ETA, p_k=P_K, p_rho_d=P_RHO_D)


@memo(maxsize=SERIES_MAX_TERMS)  # one per series length
def he_torrance_eval_formula(n: int):
    """The generated eval formula summing *n* terms (module docstring), cached on disk
    with the drivers (compiled in memory when the directory cannot be written)."""
    from brdfkit.models._drivers import _load

    module = _load(_eval_source(n, cache=True))
    if module is not None:
        return module.he_torrance_eval
    ns: dict = {"__name__": f"brdfkit_generated_he_torrance_{n}"}
    exec(compile(_eval_source(n, cache=False), "<brdfkit he-torrance formula>", "exec"), ns)
    return ns["he_torrance_eval"]


PARAMS = (
    Param("sigma0", 0.1, 0.0, 10.0, "lambda", "RMS surface height in wavelengths",
          lower_open=True),
    Param("tau", 1.7, 0.0, 1000.0, "lambda", "autocorrelation length in wavelengths",
          lower_open=True),
    ETA,
    Param("k", 0.0, 0.0, 100.0, "", "extinction coefficient (conductors)", kind="colour"),
    Param("rho_d", 0.0, 0.0, 1.0, "", "uniform-diffuse albedo a(lambda)", kind="colour"),
)
P_SIGMA0, P_TAU, P_ETA, P_K, P_RHO_D = packed_indices(
    PARAMS, "sigma0", "tau", "eta", "k", "rho_d")


@numba.njit(cache=True)
def _he_torrance(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    sigma0, tau, eta, kappa, rho_d = p[P_SIGMA0], p[P_TAU], p[P_ETA], p[P_K], p[P_RHO_D]
    # v = k_r − k_i in units of 2π/λ (λ = 1): both directions point away, so v ∝ wi + wo.
    sx = ix + ox
    sy = iy + oy
    sz = iz + oz  # v_z (> 0 above the horizon)
    vv = sx * sx + sy * sy + sz * sz
    # K and S of each direction share one erfc; σ by Lambert's W (the formulas' route:
    # four Newton steps, not the safeguarded iteration of htsg_sigma: ~10x faster)
    k_i, shadow_i = htsg_k_shadow_formula(iz, sigma0, tau)
    k_r, shadow_r = htsg_k_shadow_formula(oz, sigma0, tau)
    sigma = htsg_sigma_of_coef_formula(0.25 * (k_i + k_r), sigma0)
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
    s_i = shadow_i / iz
    s_r = shadow_r / oz
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
      z₀ with K_i + K_r exactly: u² = W(B²) by four Newton steps from Winitzki's
      start, ~1e-15 relative (:func:`htsg_sigma_of_coef_formula`, the formulas'
      route, ~3x faster than the safeguarded Newton of :func:`htsg_sigma`, which
      stays as the reference; tests/test_formulas_he_torrance.py). K and S of a
      direction share one erfc (:func:`htsg_k_shadow_formula`).
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
    params = PARAMS
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

    def _series_terms(self) -> int:
        """Terms of the formula's series at this σ₀ (largest g = (4πσ₀)²)."""
        return series_terms((4.0 * math.pi * float(np.max(self._values["sigma0"]))) ** 2)

    def formulas(self) -> Formulas | None:
        """f_r (the directional-diffuse and uniform-diffuse parts; the delta spike is not a
        formula: the bridge warns) with σ and D's series of fixed length (module
        docstring), and the cosine + Beckmann sampler of ``_strategy``
        (:func:`~brdfkit.models.ward.ward_sample`, the same mixture); None beyond
        SERIES_MAX_TERMS terms."""
        n = self._series_terms()
        if n > SERIES_MAX_TERMS:
            return None
        return Formulas(eval=he_torrance_eval_formula(n), sample=ward_sample, pdf=ward_pdf,
                        args=(self._sampling_m(), self._p_diffuse()))

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
