"""
Microfacet models
=================

The distributions of microfacet normals (D, G₁, Λ, sampling) are one object
each in :mod:`brdfkit.models.microfacet_distributions`; each model here
combines them the way its paper writes it. He-Torrance is in
:mod:`brdfkit.models.he_torrance`.

Public objects
--------------
- :class:`Microfacet` — ``microfacet``: Walter et al. 2007, Beckmann or GGX,
  separable Smith masking, conductor Fresnel; its kernel is branch-free and
  runs in a vectorised loop (:func:`~brdfkit.models._base.checked_driver`).
- :class:`TorranceSparrow`, :class:`CookTorrance`, :class:`Ward` — the
  V-groove and Ward models of Lewis and Neumann et al.
- :func:`g_vgroove` — the V-groove masking-shadowing factor.
- Re-exported for existing callers: the distribution functions
  (:func:`d_beckmann`, :func:`d_ggx`, :func:`beckmann_g1_of_a`,
  :func:`smith_g1_beckmann`, :func:`ggx_g1_over_cos`, …) and He-Torrance's.

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

from brdfkit._array import as_directions, as_uniform
from brdfkit._dual import Formulas, absolute, formula, maximum, select, sqrt
from brdfkit._kern import INV_PI, SMALL_LENGTH, below_horizon, half, pos_pow
from brdfkit.errors import ParameterError
from brdfkit.fresnel import _fresnel_conductor, _fresnel_dielectric
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
from brdfkit.models._base import BRDF, VECTOR_OPTIONS, Lobe, Param, _check_beta, checked_driver
from brdfkit.models._registry import register
from brdfkit.models.microfacet_distributions import (  # noqa: F401 - re-exported
    G1_A_MAX,
    G1_TABLE,
    SQRT_PI,
    Beckmann,
    _HalfVectorSampling,
    beckmann_dg_over_cos,
    beckmann_g1_of_a,
    beckmann_lambda,
    beckmann_lobe,
    d_beckmann,
    d_ggx,
    d_ggx_of_h,
    d_of_h,
    distribution,
    ggx_g1_over_cos,
    ggx_lambda,
    sample_half,
    smith_g1_beckmann,
    smith_g1_beckmann_exact,
    smith_g1_ggx,
)

_jit = numba.njit(cache=True, inline="always")
BECKMANN, GGX = 0, 1  # the packed index of the distribution choice
# Compile options of the scalar (non-vectorised) fast kernels: as VECTOR_OPTIONS.
_FAST = VECTOR_OPTIONS["fastmath"]


# =========================================================================== Walter 2007
_TWO_600 = 2.0 ** 600  # the exact rescaling of a short s = wi + wo (see walter)
_TWO_M600 = 2.0 ** -600
INF = math.inf


@formula
def walter(ix, iy, iz, ox, oy, oz, p, ggx, fresnel):
    """F D G₁(ω_i) G₁(ω_o)/(4 cos θ_i cos θ_o), Walter eq. (20): one basic block.

    A formula (:mod:`brdfkit._dual`): the compiled kernels below and the
    Mitsuba bridge's traced BSDF are this one function. Branch-free and total
    (see :mod:`brdfkit._kern`), so that the driver vectorises it; *ggx* and
    *fresnel* are compile-time constants of the four kernels below; *p* is the
    packed row (distribution, α, η, κ, scale) — a float64 array here, a tuple of
    Dr.Jit values (η, κ, scale may be colours or spectra) in the bridge.

    Written with s = wi + wo: tan²θ_h = |s_xy|²/s_z², cos²θ_h = s_z²/|s|² and
    ω_i·h = ω_o·h = |s|/2 (unit vectors). When every component of s is below
    SMALL_LENGTH (both directions within 1e-140 of the horizon) their squares
    underflow: s is first multiplied by 2^600 (a select; exact; in the common case
    the factor is exactly 1).
    """
    alpha, eta, k, scale = p[1], p[2], p[3], p[4]  # all parameters read first (vectorises)
    inv_a2 = 1.0 / (alpha * alpha)
    live = (iz > 0.0) & (oz > 0.0)  # 0 at and below the horizon
    sx = ix + ox
    sy = iy + oy
    sz = iz + oz  # > 0 in live lanes
    small = sz < SMALL_LENGTH
    # scale s by 2^600 when short (exact: a power of two): s_z ≥ 5e-324 then becomes
    # ≥ 2e-143, whose square is a normal number; SMALL_LENGTH·2^600 ≈ 4e40 cannot
    # overflow when squared. (1/max|s_k| would overflow for a subnormal s.)
    r = select(small, _TWO_600, 1.0)  # exact 1 on the common path (no rounding added)
    sx *= r
    sy *= r
    sz *= r
    sxy2 = sx * sx + sy * sy
    sz2 = sz * sz
    l2 = sxy2 + sz2
    if fresnel:
        cos_d = 0.5 * sqrt(l2) * select(small, _TWO_M600, 1.0)  # ω_i·h = |s|/2
        f = _fresnel_conductor(select(live, cos_d, 1.0), eta, k)  # 1.0: discarded lanes finite
    else:
        f = 1.0
    if ggx:
        inv_l2 = 1.0 / l2
        d = d_ggx_of_h(sz2 * inv_l2, sxy2 * inv_l2, inv_a2, alpha)
        # G₁/cos per direction (ggx_g1_over_cos): no 0/0 at grazing angles
        g = ggx_g1_over_cos(iz, alpha) * ggx_g1_over_cos(oz, alpha)
        v = d * g * 0.25
        live = live & (v < INF)  # 1/α² = inf (α < 1e-154) off the mirror: D = 0
    else:
        v = beckmann_dg_over_cos(iz, oz, sxy2, sz2, alpha, inv_a2, live)
    return select(live, scale * f * v, 0.0)


@formula(**VECTOR_OPTIONS)
def _walter_beckmann(ix, iy, iz, ox, oy, oz, p):
    return walter(ix, iy, iz, ox, oy, oz, p, False, False)


@formula(**VECTOR_OPTIONS)
def _walter_beckmann_f(ix, iy, iz, ox, oy, oz, p):
    return walter(ix, iy, iz, ox, oy, oz, p, False, True)


@formula(**VECTOR_OPTIONS)
def _walter_ggx(ix, iy, iz, ox, oy, oz, p):
    return walter(ix, iy, iz, ox, oy, oz, p, True, False)


@formula(**VECTOR_OPTIONS)
def _walter_ggx_f(ix, iy, iz, ox, oy, oz, p):
    return walter(ix, iy, iz, ox, oy, oz, p, True, True)


@numba.njit(cache=True, **VECTOR_OPTIONS)
def _microfacet(ix, iy, iz, ox, oy, oz, p):
    """The model's kernel for callers with one kernel per model (albedo engine, pumping):
    dispatches on the packed distribution and on whether η is given (p[2] = 0: F = 1)."""
    if p[0] == GGX:
        if p[2] == 0.0:
            return _walter_ggx(ix, iy, iz, ox, oy, oz, p)
        return _walter_ggx_f(ix, iy, iz, ox, oy, oz, p)
    if p[2] == 0.0:
        return _walter_beckmann(ix, iy, iz, ox, oy, oz, p)
    return _walter_beckmann_f(ix, iy, iz, ox, oy, oz, p)


# BRDF.eval's loops, one per (distribution, Fresnel) kernel, vectorised (compiled on first use)
_WALTER_DRIVERS = {
    (False, False): checked_driver(_walter_beckmann, vectorise=True),
    (False, True): checked_driver(_walter_beckmann_f, vectorise=True),
    (True, False): checked_driver(_walter_ggx, vectorise=True),
    (True, True): checked_driver(_walter_ggx_f, vectorise=True),
}


@formula
def walter_sample(ox, oy, oz, u0, u1, alpha, ggx):
    """ω_i = 2(ω_o·h)h − ω_o, h drawn from D(h) cos θ_h (Walter eqs. 28, 35), a formula.

    Below the horizon when ω_o·h < 0 (the pdf is then 0: see :func:`walter_pdf`).
    """
    hx, hy, hz = sample_half(u0, u1, alpha, ggx)
    c = 2.0 * (ox * hx + oy * hy + oz * hz)
    return c * hx - ox, c * hy - oy, c * hz - oz


@formula
def walter_pdf(ix, iy, iz, ox, oy, oz, alpha, ggx):
    """Solid-angle density of :func:`walter_sample`: D(h) cos θ_h/(4 |ω_o·h|), a formula.

    h = (ω_i + ω_o)/|ω_i + ω_o| as it is (not folded to the upper hemisphere: a
    direction reached with ω_o·h < 0 has density 0, Walter eq. 14's Jacobian);
    0 when ω_o is at or below the horizon or ω_i = −ω_o.
    """
    hx = ix + ox
    hy = iy + oy
    hz = iz + oz
    norm = sqrt(hx * hx + hy * hy + hz * hz)
    ok = norm > 0.0
    n = select(ok, norm, 1.0)  # 1: keep the discarded lane finite
    hx = hx / n
    hy = hy / n
    hz = hz / n
    cos_oh = absolute(ox * hx + oy * hy + oz * hz)
    ok = ok & (cos_oh > 0.0) & (oz > 0.0)
    p = d_of_h(hx, hy, hz, alpha, ggx) * maximum(hz, 0.0) / (4.0 * select(ok, cos_oh, 1.0))
    return select(ok, p, 0.0)


# the sampler and its pdf per distribution (ggx a constant), for Formulas
@formula
def _sample_ggx(ox, oy, oz, u0, u1, alpha):
    return walter_sample(ox, oy, oz, u0, u1, alpha, True)


@formula
def _sample_beckmann(ox, oy, oz, u0, u1, alpha):
    return walter_sample(ox, oy, oz, u0, u1, alpha, False)


@formula
def _pdf_ggx(ix, iy, iz, ox, oy, oz, alpha):
    return walter_pdf(ix, iy, iz, ox, oy, oz, alpha, True)


@formula
def _pdf_beckmann(ix, iy, iz, ox, oy, oz, alpha):
    return walter_pdf(ix, iy, iz, ox, oy, oz, alpha, False)


_WALTER_KERNELS = {(False, False): _walter_beckmann, (False, True): _walter_beckmann_f,
                   (True, False): _walter_ggx, (True, True): _walter_ggx_f}


@numba.njit(cache=True, **VECTOR_OPTIONS)
def _sample_rows(wo, u, alpha, ggx, wi, pdf):  # pragma: no cover - compiled
    """walter_sample and walter_pdf over rows: wo (M, 3), u (M, 2) → wi (M, 3), pdf (M,)."""
    for j in range(wo.shape[0]):
        ox, oy, oz = wo[j, 0], wo[j, 1], wo[j, 2]
        x, y, z = walter_sample(ox, oy, oz, u[j, 0], u[j, 1], alpha, ggx)
        wi[j, 0] = x
        wi[j, 1] = y
        wi[j, 2] = z
        pdf[j] = walter_pdf(x, y, z, ox, oy, oz, alpha, ggx)


@numba.njit(cache=True, **VECTOR_OPTIONS)
def _pdf_rows(wi, wo, alpha, ggx, pdf):  # pragma: no cover - compiled
    for j in range(wi.shape[0]):
        pdf[j] = walter_pdf(wi[j, 0], wi[j, 1], wi[j, 2], wo[j, 0], wo[j, 1], wo[j, 2],
                            alpha, ggx)


def _rows(a: np.ndarray, shape: tuple, k: int) -> np.ndarray:
    return np.ascontiguousarray(np.broadcast_to(a, shape + (k,)).reshape(-1, k))


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
    alpha         0.1         [1e-8, 4]     roughness (RMS slope for Beckmann);
                                            0.01 near-mirror, 0.1 glossy, 0.5 rough
    eta           None        (0, 100]      real index (per channel); None: F = 1
    k             0           [0, 100]      extinction (per channel); 0: dielectric;
                                            needs eta
    rho_s         1           [0, 1]        specular scale (per channel)
    ============  ==========  ============  ==========================================

    ``beta`` (half-angle, radians) sets α so that D(β) = D(0)/2
    (:func:`~brdfkit.halfangle.beckmann_m_from_beta` for Beckmann,
    :func:`~brdfkit.halfangle.trowbridge_reitz_c_from_beta` for GGX).

    Reciprocal. Energy: bounded by 1 with F ≤ 1 (only single scattering, so
    rough surfaces lose energy). Sampled by the distribution of normals
    D(h) cos θ_h (Walter eqs. 28, 35), pdf D cos θ_h / (4 |ω_o·h|).

    f_r, the sampler and its pdf are formulas (:mod:`brdfkit._dual`:
    :func:`walter`, :func:`walter_sample`, :func:`walter_pdf`), compiled by
    Numba here and traced by Dr.Jit in the Mitsuba bridge.
    """

    name = "microfacet"
    aliases = ("walter", "roughconductor")
    summary = "Walter et al. 2007 microfacet BRDF (Beckmann/GGX, Smith, Fresnel)"
    params = (
        Param("distribution", "beckmann", kind="choice", choices=("beckmann", "ggx"),
              doc="microfacet normal distribution"),
        # lower bound 1e-8: verified there (GGX and Beckmann) that the albedo engine gives
        # a(0°) = a(45°) = a(80°) = 1 ± 1e-9 with F = 1 (the Smith G₁ of a near-mirror is
        # 1 − O(α²)); at 1e-12 the lobe is narrower than it resolves, and below ~1e-154
        # the peak 1/(πα²) overflows. Mitsuba clamps α at 1e-4.
        Param("alpha", 0.1, 1e-8, 4.0, "",
              "roughness: 0.01 near-mirror, 0.1 glossy, 0.5 rough (>= 1e-8: narrower lobes "
              "are not resolved by the albedo engine)"),
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

    def _validate(self):
        v = self._values
        if v["eta"] is None and np.any(np.asarray(v["k"]) != 0.0):
            raise ParameterError(
                f"{self.name}: k needs eta: give eta (the real part of the index) or drop k")
        # the vectorised loop of this instance's (distribution, Fresnel) kernel
        self._driver = _WALTER_DRIVERS[(v["distribution"] == "ggx", v["eta"] is not None)]

    def lobes(self):
        return [Lobe("half", float(self._values["alpha"]))]

    def formulas(self) -> Formulas:
        """:func:`walter` (this instance's distribution and Fresnel) and its sampler."""
        v = self._values
        ggx = v["distribution"] == "ggx"
        return Formulas(eval=_WALTER_KERNELS[(ggx, v["eta"] is not None)],
                        sample=_sample_ggx if ggx else _sample_beckmann,
                        pdf=_pdf_ggx if ggx else _pdf_beckmann, args=(float(v["alpha"]),))

    def sample(self, wo, u):
        """Draw wi given wo from *u* ∈ [0, 1]² (..., 2) (:func:`walter_sample`); ``(wi, pdf)``."""
        wo = as_directions(wo, "wo")
        u = as_uniform(u)
        shape = np.broadcast_shapes(wo.shape[:-1], u.shape[:-1])
        w, uu = _rows(wo, shape, 3), _rows(u, shape, 2)
        wi = np.empty_like(w)
        p = np.empty(w.shape[0])
        _sample_rows(w, uu, float(self._values["alpha"]), self._values["distribution"] == "ggx",
                     wi, p)
        return wi.reshape(shape + (3,)), p.reshape(shape)

    def pdf(self, wi, wo):
        """Solid-angle density of :meth:`sample` (:func:`walter_pdf`); 0 for wo below."""
        wi = as_directions(wi, "wi")
        wo = as_directions(wo, "wo")
        shape = np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1])
        p = np.empty(int(np.prod(shape)))
        _pdf_rows(_rows(wi, shape, 3), _rows(wo, shape, 3), float(self._values["alpha"]),
                  self._values["distribution"] == "ggx", p)
        return p.reshape(shape)


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
        # D₃; the denominator is ≥ min(c², 1) > 0 unless c² underflows (c < 1e-154) at the
        # exact bisector, where q = 1 is the limit (D₃ peaks at b for every c)
        den = hz * hz * (c * c - 1.0) + 1.0
        q = c * c / den if den > 0.0 else 1.0
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


# He-Torrance registers after Ward (the registry order of `brdfkit models` and Table 2)
from brdfkit.models.he_torrance import (  # noqa: E402,F401 - re-exported
    HeTorrance,
    htsg_series,
    htsg_shadow,
    htsg_sigma,
)
