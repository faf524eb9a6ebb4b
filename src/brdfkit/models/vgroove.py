"""
V-groove microfacet models: Torrance–Sparrow and Cook–Torrance
==============================================================

Two models of reflection from V-shaped grooves (masking-shadowing
:func:`g_vgroove`), as Lewis and Neumann et al. write them; the facet
distributions are those of :mod:`brdfkit.models.microfacet_distributions`.

Public objects
--------------
- :class:`TorranceSparrow` — ``torrance-sparrow``: Lewis eq. (10) with D₁–D₄.
- :class:`CookTorrance` — ``cook-torrance``: Neumann et al. eqs. (9)–(10).
- :func:`g_vgroove` — the V-groove masking-shadowing factor.
- :data:`DENOM_FLOOR` — the floor of the (N·L)(N·V) denominators.

References
----------
- [Lewis1993] eq. (10) and D₁–D₄; [Neumann1999] eqs. (9)–(10).
"""

from __future__ import annotations

import math

import numba

from brdfkit._dual import (
    Formulas,
    acos,
    exp,
    exp_nonpos,
    formula,
    maximum,
    minimum,
    power,
    select,
    sqrt,
)
from brdfkit.errors import ParameterError
from brdfkit.fresnel import _fresnel_dielectric as fresnel_dielectric
from brdfkit.halfangle import (
    beckmann_m_from_beta,
    beta_from_beckmann_m,
    beta_from_exponent,
    beta_from_trowbridge_reitz_c,
    exponent_from_beta,
    gaussian_c_from_beta,
    trowbridge_reitz_c_from_beta,
)
from brdfkit.models._base import BRDF, VECTOR_OPTIONS, Lobe, Param, _check_beta
from brdfkit.models._drivers import loop_driver
from brdfkit.models._params import ETA_DIELECTRIC, M_SLOPE, eta_fresnel_split, packed_indices
from brdfkit.models._registry import register
from brdfkit.models.microfacet import (
    _pdf_beckmann,
    _pdf_ggx,
    _sample_beckmann,
    _sample_ggx,
    cos_d_of,
    half_sum,
    reflection_jacobian,
)
from brdfkit.models.microfacet_distributions import _HalfVectorSampling
from brdfkit.models.sampling import cos_power_normal_sample

__all__ = ["TorranceSparrow", "CookTorrance", "g_vgroove", "DENOM_FLOOR", "TS_PARAMS",
           "CT_PARAMS"]

_jit = numba.njit(cache=True, inline="always")


# =========================================================================== shared
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


# =========================================================================== Torrance-Sparrow
PHONG_D, GAUSSIAN_D, TR_D, BECKMANN_D = 0, 1, 2, 3
_TS_DISTRIBUTIONS = ("phong", "gaussian", "trowbridge-reitz", "beckmann")
_TS_WIDTH = {"phong": "n", "gaussian": "c", "trowbridge-reitz": "c", "beckmann": "m"}
_TS_DEFAULT_C = {"gaussian": 4.0, "trowbridge-reitz": 0.3}  # both β ≈ 12°


TS_PARAMS = (
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
TS_DIST, TS_B, TS_N, TS_C, TS_M, TS_ETA = packed_indices(
    TS_PARAMS, "distribution", "b", "n", "c", "m", "eta")


@formula
def torrance_sparrow(ix, iy, iz, ox, oy, oz, p, dist, fresnel):
    """F G D/(π (N·S)(N·V)), Lewis eq. (10) with D₁–D₄ and the V-groove G of §3.2; a formula
    (:mod:`brdfkit._dual`; *dist* and *fresnel* compile-time constants, F = 1 without η).

    H = s/|s| with s = ω_i + ω_o (:func:`~brdfkit.models.microfacet.half_sum`, rescaled
    when short: H is scale-invariant). 0 at and below the horizon.
    """
    b, n, c, m, eta = p[TS_B], p[TS_N], p[TS_C], p[TS_M], p[TS_ETA]
    live = (iz > 0.0) & (oz > 0.0)
    sx, sy, sz, small = half_sum(ix, iy, iz, ox, oy, oz)
    length = sqrt(select(live, sx * sx + sy * sy + sz * sz, 1.0))  # 1: discarded lanes finite
    hx = sx / length
    hy = sy / length
    hz = sz / length
    cos_vh = ox * hx + oy * hy + oz * hz  # = L·H
    if dist == PHONG_D:
        d = b * power(hz, n)  # D₁ = b cos^{c₁} α (h_z > 0 above the horizon; 0⁰ = 1)
    elif dist == GAUSSIAN_D:
        t = c * acos(minimum(hz, 1.0))  # clamp: rounding can give hz slightly > 1
        d = b * exp(-(t * t))  # D₂
    elif dist == TR_D:
        # D₃; the denominator is ≥ min(c², 1) > 0 unless c² underflows (c < 1e-154) at the
        # exact bisector, where q = 1 is the limit (D₃ peaks at b for every c)
        den = hz * hz * (c * c - 1.0) + 1.0
        q = select(den > 0.0, c * c / select(den > 0.0, den, 1.0), 1.0)
        d = b * q * q
    else:
        # D₄ = e^{−tan²α/m²}/(4m² cos⁴α), no b; 0 where tan²α/m² > 700 (as beckmann_lobe)
        c2 = hz * hz
        ok = c2 * 700.0 * m * m >= 1.0 - c2
        e = -(1.0 - c2) / (c2 * m * m)
        # clamp: e ≤ 0 but for the rounding of hz just above 1
        d = select(ok, 0.25 * (exp(minimum(select(ok, e, -1000.0), 0.0)) / (c2 * c2))
                   / (m * m), 0.0)
    # V-groove G (g_vgroove): 0 where V·H ≤ 0 (L = −V: no bisector)
    vh = select(cos_vh > 0.0, cos_vh, 1.0)
    g = select(cos_vh > 0.0, minimum(1.0, minimum(2.0 * hz * oz / vh, 2.0 * hz * iz / vh)), 0.0)
    if fresnel:
        f = fresnel_dielectric(cos_vh, eta)
    else:
        f = 1.0
    return select(live, f * g * d / (PI * maximum(iz * oz, DENOM_FLOOR)), 0.0)  # floor: DENOM_FLOOR


@formula(**VECTOR_OPTIONS)
def _ts_phong(ix, iy, iz, ox, oy, oz, p):
    return torrance_sparrow(ix, iy, iz, ox, oy, oz, p, PHONG_D, False)


@formula(**VECTOR_OPTIONS)
def _ts_phong_f(ix, iy, iz, ox, oy, oz, p):
    return torrance_sparrow(ix, iy, iz, ox, oy, oz, p, PHONG_D, True)


@formula(**VECTOR_OPTIONS)
def _ts_gaussian(ix, iy, iz, ox, oy, oz, p):
    return torrance_sparrow(ix, iy, iz, ox, oy, oz, p, GAUSSIAN_D, False)


@formula(**VECTOR_OPTIONS)
def _ts_gaussian_f(ix, iy, iz, ox, oy, oz, p):
    return torrance_sparrow(ix, iy, iz, ox, oy, oz, p, GAUSSIAN_D, True)


@formula(**VECTOR_OPTIONS)
def _ts_tr(ix, iy, iz, ox, oy, oz, p):
    return torrance_sparrow(ix, iy, iz, ox, oy, oz, p, TR_D, False)


@formula(**VECTOR_OPTIONS)
def _ts_tr_f(ix, iy, iz, ox, oy, oz, p):
    return torrance_sparrow(ix, iy, iz, ox, oy, oz, p, TR_D, True)


@formula(**VECTOR_OPTIONS)
def _ts_beckmann(ix, iy, iz, ox, oy, oz, p):
    return torrance_sparrow(ix, iy, iz, ox, oy, oz, p, BECKMANN_D, False)


@formula(**VECTOR_OPTIONS)
def _ts_beckmann_f(ix, iy, iz, ox, oy, oz, p):
    return torrance_sparrow(ix, iy, iz, ox, oy, oz, p, BECKMANN_D, True)


#: (packed distribution, η given) → the formula kernel
_TS_KERNELS = {(PHONG_D, False): _ts_phong, (PHONG_D, True): _ts_phong_f,
               (GAUSSIAN_D, False): _ts_gaussian, (GAUSSIAN_D, True): _ts_gaussian_f,
               (TR_D, False): _ts_tr, (TR_D, True): _ts_tr_f,
               (BECKMANN_D, False): _ts_beckmann, (BECKMANN_D, True): _ts_beckmann_f}


@numba.njit(cache=True, **VECTOR_OPTIONS)
def _torrance_sparrow(ix, iy, iz, ox, oy, oz, p):
    """The model's kernel for callers with one kernel per model (albedo engine, pumping):
    dispatches on the packed distribution and on whether η is given (0: F = 1)."""
    dist, fres = p[TS_DIST], p[TS_ETA] != 0.0
    if dist == PHONG_D:
        if fres:
            return _ts_phong_f(ix, iy, iz, ox, oy, oz, p)
        return _ts_phong(ix, iy, iz, ox, oy, oz, p)
    if dist == GAUSSIAN_D:
        if fres:
            return _ts_gaussian_f(ix, iy, iz, ox, oy, oz, p)
        return _ts_gaussian(ix, iy, iz, ox, oy, oz, p)
    if dist == TR_D:
        if fres:
            return _ts_tr_f(ix, iy, iz, ox, oy, oz, p)
        return _ts_tr(ix, iy, iz, ox, oy, oz, p)
    if fres:
        return _ts_beckmann_f(ix, iy, iz, ox, oy, oz, p)
    return _ts_beckmann(ix, iy, iz, ox, oy, oz, p)


@formula
def power_half_sample(ox, oy, oz, u0, u1, n):
    """ω_i = 2(ω_o·h)h − ω_o with h from (n+1)/(2π) cosⁿθ_h (``HalfVector(PowerHalf(n))``,
    :func:`~brdfkit.models.sampling.cos_power_normal_sample`), a formula."""
    hx, hy, hz = cos_power_normal_sample(ox, oy, oz, u0, u1, n)
    k = 2.0 * (ox * hx + oy * hy + oz * hz)
    return k * hx - ox, k * hy - oy, k * hz - oz


@formula
def power_half_pdf(ix, iy, iz, ox, oy, oz, n):
    """Density of :func:`power_half_sample`: (n+1)/(2π) cosⁿθ_h/(4|ω_o·h|), h not folded
    (``fold=False``); 0 when ω_o is at or below the horizon."""
    hx, hy, hz, ok, jac = reflection_jacobian(ix, iy, iz, ox, oy, oz)
    up = hz > 0.0
    ph = (n + 1.0) / TWO_PI * power(select(up, hz, 1.0), n)  # 1: the discarded lane finite
    return select(ok & up, ph / jac, 0.0)


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
    params = TS_PARAMS
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
        self._validate_kernel()

    @classmethod
    def width_from_beta(cls, beta: float) -> float:
        return beckmann_m_from_beta(beta)

    @classmethod
    def describe(cls) -> dict:
        d = super().describe()
        d["beta"] = "n (phong), c (gaussian, trowbridge-reitz) or m (beckmann)"
        return d

    def _validate_kernel(self):
        v = self._values
        key = (_TS_DISTRIBUTIONS.index(v["distribution"]), v["eta"] is not None)
        self._driver = loop_driver(_TS_KERNELS[key], loop="vector")
        return _TS_KERNELS[key]

    def formulas(self) -> Formulas:
        """:func:`torrance_sparrow` (this instance's D and Fresnel) and the half-vector
        sampler of ``_half_lobe``: cosⁿ (phong), Beckmann or GGX (Walter eqs. 28, 35)."""
        kind, width = self._half_lobe()
        v = self._values
        kernel = _TS_KERNELS[(_TS_DISTRIBUTIONS.index(v["distribution"]), v["eta"] is not None)]
        sample, pdf = {"phong": (power_half_sample, power_half_pdf),
                       "beckmann": (_sample_beckmann, _pdf_beckmann),
                       "ggx": (_sample_ggx, _pdf_ggx)}[kind]
        return Formulas(eval=kernel, sample=sample, pdf=pdf, args=(float(width),))

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

    def fresnel_split(self):
        """F = F_dielectric(η) (1 without η); white: η not given."""
        return eta_fresnel_split(self)

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
CT_PARAMS = (
    M_SLOPE,
    ETA_DIELECTRIC,
    Param("rho_s", 1.0, 0.0, 1.0, "", "specular scale", kind="colour"),
)
CT_M, CT_ETA, CT_RHO_S = packed_indices(CT_PARAMS, "m", "eta", "rho_s")


PI = math.pi
TWO_PI = 2.0 * math.pi
_TWO_600 = 2.0 ** 600  # the exact rescaling of a short s = wi + wo (half_sum)
#: tan²δ/m² beyond which e^{−tan²δ/m²} < 1e-290 is given as 0 (as beckmann_lobe)
EXPONENT_FLOOR = -700.0
FOUR_PI = 4.0 * math.pi


@formula
def cook_torrance(ix, iy, iz, ox, oy, oz, p, fresnel):
    """ρ_s F D G/((N·L)(N·V)), Neumann et al. eqs. (9)–(10), D = e^{−tan²δ/m²}/(4π m² cos⁴δ);
    a formula (:mod:`brdfkit._dual`; *fresnel* a compile-time constant: F = 1 without η).

    Written with s = ω_i + ω_o (:func:`~brdfkit.models.microfacet.half_sum`, multiplied by
    2^600 when both directions are within 1e-140 of the horizon, exact): cos²δ = s_z²/|s|²,
    L·H = V·H = |s|/2 and, in eq. (10), 2(N·H)(N·V)/(V·H) = 4 s_z (N·V)/|s|² (times 2^600
    for a rescaled s). 0 at and below the horizon and where tan²δ/m² > 700 (D < 1e-290).
    """
    m, eta, rho_s = p[CT_M], p[CT_ETA], p[CT_RHO_S]
    live = (iz > 0.0) & (oz > 0.0)
    sx, sy, sz, small = half_sum(ix, iy, iz, ox, oy, oz)
    l2 = select(live, sx * sx + sy * sy + sz * sz, 1.0)  # 1: the discarded lanes finite
    length = sqrt(l2)
    hz = sz / length
    c2 = hz * hz  # cos²δ
    # −tan²δ/m² rounded exactly as beckmann_lobe (with half()'s N·H): the rounding of the
    # exponent is amplified up to 700× by e^x, and torrance-sparrow's D₄ must agree to 1e-13
    e = -(1.0 - c2) / (c2 * m * m)
    ok = live & (e >= EXPONENT_FLOOR)  # false for NaN (0/0 at the horizon)
    # clamp: e ≤ 0 but for the rounding of hz just above 1
    d = exp_nonpos(minimum(select(ok, e, -1000.0), 0.0)) / (FOUR_PI * m * m * c2 * c2)
    # V-groove G, eq. (10); a rescaled s: 4 (s_z/|s|²)(N·V) 2^600 (s_z/|s|² first: s_z (N·V)
    # would underflow), the common path as the kernel always wrote it
    grazing = 4.0 * (sz / l2) * minimum(iz, oz) * _TWO_600
    g = minimum(1.0, select(small, grazing, 4.0 * sz * minimum(iz, oz) / l2))
    if fresnel:
        f = fresnel_dielectric(cos_d_of(l2, small), eta)
    else:
        f = 1.0
    return select(ok, rho_s * f * d * g / maximum(iz * oz, DENOM_FLOOR), 0.0)  # floor: DENOM_FLOOR


@formula(**VECTOR_OPTIONS)
def _cook_torrance_white(ix, iy, iz, ox, oy, oz, p):
    return cook_torrance(ix, iy, iz, ox, oy, oz, p, False)


@formula(**VECTOR_OPTIONS)
def _cook_torrance_f(ix, iy, iz, ox, oy, oz, p):
    return cook_torrance(ix, iy, iz, ox, oy, oz, p, True)


@numba.njit(cache=True, **VECTOR_OPTIONS)
def _cook_torrance(ix, iy, iz, ox, oy, oz, p):
    """The model's kernel for callers with one kernel per model (albedo engine, pumping):
    dispatches on whether η is given (0: F = 1)."""
    if p[CT_ETA] == 0.0:
        return _cook_torrance_white(ix, iy, iz, ox, oy, oz, p)
    return _cook_torrance_f(ix, iy, iz, ox, oy, oz, p)


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
    params = CT_PARAMS
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

    def _ct_kernel(self):
        return _cook_torrance_white if self._values["eta"] is None else _cook_torrance_f

    def _validate(self):
        self._driver = loop_driver(self._ct_kernel(), loop="vector")

    def formulas(self) -> Formulas:
        """:func:`cook_torrance` and the Beckmann sampler of ``_half_lobe`` (Walter eq. 28)."""
        return Formulas(eval=self._ct_kernel(), sample=_sample_beckmann, pdf=_pdf_beckmann,
                        args=(float(self._values["m"]),))

    def lobes(self):
        return [Lobe("half", float(beta_from_beckmann_m(self._values["m"])))]

    def fresnel_split(self):
        """F = ρ_s · F_dielectric(η) (1 without η); white: η not given, ρ_s = 1."""
        return eta_fresnel_split(self, scale="rho_s")
