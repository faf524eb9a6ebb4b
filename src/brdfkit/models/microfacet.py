"""
The Walter et al. (2007) microfacet model
=========================================

The distributions of microfacet normals (D, G₁, Λ, sampling) are one object
each in :mod:`brdfkit.models.microfacet_distributions`; the other microfacet
families have their own modules: :mod:`~brdfkit.models.vgroove`
(Torrance–Sparrow, Cook–Torrance), :mod:`~brdfkit.models.ward`,
:mod:`~brdfkit.models.he_torrance`.

Public objects
--------------
- :class:`Microfacet` — ``microfacet``: Walter et al. 2007, Beckmann or GGX,
  separable Smith masking, conductor Fresnel; its kernel is branch-free and
  runs in the vectorised loop (:func:`~brdfkit.models._drivers.loop_driver`,
  ``loop="vector"``).
- :func:`walter`, :func:`walter_sample`, :func:`walter_pdf` — its formulas; :func:`walter`
  is :func:`walter_terms` (D G₁ G₁, the channel-independent part) and
  :func:`walter_channel` (F and the scale), which :func:`walter_rgb` (three channels in the
  ``"rgb"`` loop, bit-equal per channel) calls once and thrice;
  :func:`half_sum`, :func:`cos_d_of`, :func:`reflection_jacobian` — their first steps,
  shared with :mod:`~brdfkit.models.microfacet_anisotropic` and
  :mod:`~brdfkit.models.ashikhmin_shirley`.
- Re-exported for existing callers: the distribution functions
  (:func:`d_beckmann`, :func:`d_ggx`, :func:`beckmann_g1_of_a`,
  :func:`smith_g1_beckmann`, :func:`ggx_g1_over_cos`, …).

References
----------
- [Walter2007] eqs. (20) (BRDF), (25)–(28) Beckmann D, G₁ and sampling,
  (33)–(35) GGX.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from brdfkit._array import as_directions, as_uniform
from brdfkit._dual import Formulas, absolute, formula, maximum, select, sqrt
from brdfkit._kern import SMALL_LENGTH
from brdfkit.errors import ParameterError
from brdfkit.fresnel import _fresnel_conductor
from brdfkit.halfangle import beckmann_m_from_beta, trowbridge_reitz_c_from_beta
from brdfkit.models._base import BRDF, VECTOR_OPTIONS, Lobe, Param, _check_beta
from brdfkit.models._drivers import loop_driver
from brdfkit.models._params import ETA, eta_fresnel_split, packed_indices
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

BECKMANN, GGX = 0, 1  # the packed value of the distribution choice

#: The parameters of :class:`Microfacet`, declared before its kernels, which read them by
#: name: the packed slots below are generated from this tuple (module constants).
PARAMS = (
    Param("distribution", "beckmann", kind="choice", choices=("beckmann", "ggx"),
          doc="microfacet normal distribution"),
    # lower bound 1e-8: verified there (GGX and Beckmann) that the albedo engine gives
    # a(0°) = a(45°) = a(80°) = 1 ± 1e-9 with F = 1 (the Smith G₁ of a near-mirror is
    # 1 − O(α²)); at 1e-12 the lobe is narrower than it resolves, and below ~1e-154
    # the peak 1/(πα²) overflows. Mitsuba clamps α at 1e-4.
    Param("alpha", 0.1, 1e-8, 4.0, "",
          "roughness: 0.01 near-mirror, 0.1 glossy, 0.5 rough (>= 1e-8: narrower lobes "
          "are not resolved by the albedo engine)"),
    ETA,
    Param("k", 0.0, 0.0, 100.0, "", "extinction coefficient (conductors)", kind="colour"),
    Param("rho_s", 1.0, 0.0, 1.0, "", "specular scale", kind="colour"),
)
P_DIST, P_ALPHA, P_ETA, P_K, P_SCALE = packed_indices(
    PARAMS, "distribution", "alpha", "eta", "k", "rho_s")


# =========================================================================== Walter 2007
_TWO_600 = 2.0 ** 600  # the exact rescaling of a short s = wi + wo (see walter)
_TWO_M600 = 2.0 ** -600
INF = math.inf


@formula
def walter(ix, iy, iz, ox, oy, oz, p, ggx, fresnel):
    """F D G₁(ω_i) G₁(ω_o) / (4 cos θ_i cos θ_o), Walter eq. (20): one basic block.

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
    the factor is exactly 1). The channel-independent part is :func:`walter_terms`,
    the channel's :func:`walter_channel` (the RGB kernel calls the first once).
    """
    # all parameters read first (vectorises)
    alpha, eta, k, scale = p[P_ALPHA], p[P_ETA], p[P_K], p[P_SCALE]
    live, c, v = walter_terms(ix, iy, iz, ox, oy, oz, alpha, ggx)
    return walter_channel(live, c, v, eta, k, scale, fresnel)


@formula
def walter_terms(ix, iy, iz, ox, oy, oz, alpha, ggx):
    """(live, c, v) of :func:`walter`: f_r = select(live, scale · F(c) · v, 0) with
    v = D G₁ G₁/(4 cos θ_i cos θ_o) and c = ω_i·h (1 where not live: F finite)."""
    inv_a2 = 1.0 / (alpha * alpha)
    live = (iz > 0.0) & (oz > 0.0)  # 0 at and below the horizon
    sx, sy, sz, small = half_sum(ix, iy, iz, ox, oy, oz)
    sxy2 = sx * sx + sy * sy
    sz2 = sz * sz
    l2 = sxy2 + sz2
    c = select(live, cos_d_of(l2, small), 1.0)  # 1.0: F finite where not live
    if ggx:
        inv_l2 = 1.0 / l2
        d = d_ggx_of_h(sz2 * inv_l2, sxy2 * inv_l2, inv_a2, alpha)
        # G₁/cos per direction (ggx_g1_over_cos): no 0/0 at grazing angles
        g = ggx_g1_over_cos(iz, alpha) * ggx_g1_over_cos(oz, alpha)
        v = d * g * 0.25
        live = live & (v < INF)  # 1/α² = inf (α < 1e-154) off the mirror: D = 0
    else:
        v = beckmann_dg_over_cos(iz, oz, sxy2, sz2, alpha, inv_a2, live)
    return live, c, v


@formula
def walter_channel(live, c, v, eta, k, scale, fresnel):
    """One channel of f_r from :func:`walter_terms` (or the anisotropic ones): scale ·
    F_conductor(c; η, κ) · v (F = 1 unless *fresnel*), 0 where not live."""
    if fresnel:
        f = _fresnel_conductor(c, eta, k)
    else:
        f = 1.0
    return select(live, scale * f * v, 0.0)


@formula
def half_sum(ix, iy, iz, ox, oy, oz):
    """(s_x, s_y, s_z, small): s = ω_i + ω_o, multiplied by 2^600 when s_z < SMALL_LENGTH
    (*small*; exact: a power of two), the shared first step of the half-vector kernels.

    s_z ≥ 5e-324 then becomes ≥ 2e-143, whose square is a normal number;
    SMALL_LENGTH·2^600 ≈ 4e40 cannot overflow when squared. (1/max|s_k| would overflow
    for a subnormal s.) On the common path the factor is exactly 1 (no rounding added).
    """
    sz = iz + oz  # > 0 in live lanes
    small = sz < SMALL_LENGTH
    r = select(small, _TWO_600, 1.0)
    return (ix + ox) * r, (iy + oy) * r, sz * r, small


@formula
def cos_d_of(l2, small):
    """ω_i·h = ω_o·h = |s|/2 from l2 = |s|² of :func:`half_sum`'s (scaled) s."""
    return 0.5 * sqrt(l2) * select(small, _TWO_M600, 1.0)


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


# The three channels at once (the "rgb" loop of models/_drivers.py), over t, the three
# packed rows as one flat tuple (t[c·N_PACKED + k]): walter_terms once, then each channel as
# walter computes it (the same operations: bit-equal to the per-channel kernels).
N_PACKED = len(PARAMS)
if (P_ETA, P_K, P_SCALE) != (N_PACKED - 3, N_PACKED - 2, N_PACKED - 1):  # walter_channels
    raise RuntimeError("microfacet: eta, k, rho_s must end the packed row (walter_channels)")


@numba.njit(cache=True, inline="always", **VECTOR_OPTIONS)
def walter_channels(live, c, v, t, fresnel):  # pragma: no cover - compiled
    """(f_R, f_G, f_B): :func:`walter_channel` of each row of the flat tuple *t* of three
    rows whose last three entries are η, κ and the scale (the rows of ``microfacet`` and
    ``microfacet-anisotropic``; row length len(t)/3, a constant of the tuple's type that
    LLVM folds into the indices)."""
    n = len(t) // 3
    return (walter_channel(live, c, v, t[n - 3], t[n - 2], t[n - 1], fresnel),
            walter_channel(live, c, v, t[2 * n - 3], t[2 * n - 2], t[2 * n - 1], fresnel),
            walter_channel(live, c, v, t[3 * n - 3], t[3 * n - 2], t[3 * n - 1], fresnel))


@numba.njit(cache=True, inline="always", **VECTOR_OPTIONS)
def walter_rgb(ix, iy, iz, ox, oy, oz, t, ggx, fresnel):  # pragma: no cover - compiled
    """(f_R, f_G, f_B) of :func:`walter` over the flat tuple *t* of the three rows."""
    live, c, v = walter_terms(ix, iy, iz, ox, oy, oz, t[P_ALPHA], ggx)
    return walter_channels(live, c, v, t, fresnel)


@numba.njit(cache=True, inline="always", **VECTOR_OPTIONS)
def _walter_beckmann_rgb(ix, iy, iz, ox, oy, oz, t):  # pragma: no cover - compiled
    return walter_rgb(ix, iy, iz, ox, oy, oz, t, False, False)


@numba.njit(cache=True, inline="always", **VECTOR_OPTIONS)
def _walter_beckmann_f_rgb(ix, iy, iz, ox, oy, oz, t):  # pragma: no cover - compiled
    return walter_rgb(ix, iy, iz, ox, oy, oz, t, False, True)


@numba.njit(cache=True, inline="always", **VECTOR_OPTIONS)
def _walter_ggx_rgb(ix, iy, iz, ox, oy, oz, t):  # pragma: no cover - compiled
    return walter_rgb(ix, iy, iz, ox, oy, oz, t, True, False)


@numba.njit(cache=True, inline="always", **VECTOR_OPTIONS)
def _walter_ggx_f_rgb(ix, iy, iz, ox, oy, oz, t):  # pragma: no cover - compiled
    return walter_rgb(ix, iy, iz, ox, oy, oz, t, True, True)


@numba.njit(cache=True, **VECTOR_OPTIONS)
def _microfacet(ix, iy, iz, ox, oy, oz, p):
    """The model's kernel for callers with one kernel per model (albedo engine, pumping):
    dispatches on the packed distribution and on whether η is given (0: F = 1)."""
    if p[P_DIST] == GGX:
        if p[P_ETA] == 0.0:
            return _walter_ggx(ix, iy, iz, ox, oy, oz, p)
        return _walter_ggx_f(ix, iy, iz, ox, oy, oz, p)
    if p[P_ETA] == 0.0:
        return _walter_beckmann(ix, iy, iz, ox, oy, oz, p)
    return _walter_beckmann_f(ix, iy, iz, ox, oy, oz, p)


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
    hx, hy, hz, ok, jac = reflection_jacobian(ix, iy, iz, ox, oy, oz)
    p = d_of_h(hx, hy, hz, alpha, ggx) * maximum(hz, 0.0) / jac
    return select(ok, p, 0.0)


@formula
def reflection_jacobian(ix, iy, iz, ox, oy, oz):
    """(h_x, h_y, h_z, ok, 4|ω_o·h|) of the half-vector samplers' densities p_h(h)/(4|ω_o·h|).

    h = (ω_i + ω_o)/|ω_i + ω_o| as it is (not folded: a direction reached with
    ω_o·h < 0 has density 0); *ok* false (and the Jacobian 4, finite) when ω_o is at or
    below the horizon, ω_i = −ω_o or ω_o·h = 0.
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
    return hx, hy, hz, ok, 4.0 * select(ok, cos_oh, 1.0)


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
_WALTER_RGB = {(False, False): _walter_beckmann_rgb, (False, True): _walter_beckmann_f_rgb,
               (True, False): _walter_ggx_rgb, (True, True): _walter_ggx_f_rgb}


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


# walter_pdf as kernels of the plain loop (models/_drivers) over the packed row [α]
@numba.njit(cache=True, **VECTOR_OPTIONS)
def _pdf_ggx_row(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
    return walter_pdf(ix, iy, iz, ox, oy, oz, p[0], True)


@numba.njit(cache=True, **VECTOR_OPTIONS)
def _pdf_beckmann_row(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
    return walter_pdf(ix, iy, iz, ox, oy, oz, p[0], False)


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
    params = PARAMS
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
        # BRDF.eval's loop: the vectorised loop of this instance's (distribution, Fresnel)
        # kernel, generated and cached on disk on first use (models/_drivers.py); RGB: the
        # "rgb" loop (D G₁ G₁ once per pair, three Fresnel factors)
        key = (v["distribution"] == "ggx", v["eta"] is not None)
        if self.n_channels == 3:
            self._driver = loop_driver(_WALTER_RGB[key], loop="rgb", width=3 * N_PACKED)
        else:
            self._driver = loop_driver(_WALTER_KERNELS[key], loop="vector")

    def lobes(self):
        return [Lobe("half", float(self._values["alpha"]))]

    def fresnel_split(self):
        """F = ρ_s · F_conductor(η, κ) (1 without η); white: η not given, κ = 0, ρ_s = 1."""
        return eta_fresnel_split(self, k="k", scale="rho_s")

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
        p = np.empty((int(np.prod(shape)), 1))
        kernel = _pdf_ggx_row if self._values["distribution"] == "ggx" else _pdf_beckmann_row
        loop_driver(kernel, loop="plain")(_rows(wi, shape, 3), _rows(wo, shape, 3),
                                          np.array([[float(self._values["alpha"])]]), p)
        return p.reshape(shape)
