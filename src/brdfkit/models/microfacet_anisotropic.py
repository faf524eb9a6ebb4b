"""
The anisotropic Walter et al. (2007) microfacet model
=====================================================

Walter's eq. (20) with the anisotropic GGX or Beckmann distribution of
:mod:`brdfkit.models.anisotropic_distributions` (α_x along brdfkit's tangent X = +x,
α_y along the bitangent Y = +y) and the Smith G₁ of the projected roughness
α(ω) = √(cos²φ α_x² + sin²φ α_y²) (Heitz 2014 §5.3): the model of Mitsuba 3's
``roughconductor`` with ``alpha_u``/``alpha_v`` and of pbrt-v4's ``conductor`` with
``uroughness``/``vroughness``. At α_x = α_y it is :class:`~brdfkit.models.microfacet.Microfacet`
to rounding.

Parameters
----------
============  ==========  ============  ================================================
name          default     bounds        meaning
============  ==========  ============  ================================================
distribution  beckmann    beckmann/ggx  microfacet normal distribution
alpha_x       0.1         [1e-4, 4]     roughness along the tangent X (+x): 0.01
                                        near-mirror, 0.1 glossy, 0.5 rough
alpha_y       0.3         [1e-4, 4]     roughness along the bitangent Y (+y)
eta           None        (0, 100]      real index (per channel); None: F = 1
k             0           [0, 100]      extinction (per channel); 0: dielectric; needs eta
rho_s         1           [0, 1]        specular scale (per channel)
============  ==========  ============  ================================================

Guidance: the larger α is the axis along which the microfacet normals tilt most, and
the highlight spreads along it: a metal brushed along x (grooves along x, normals
tilting in y) has α_y > α_x. Mitsuba's ``alpha_u`` is α_x and
``alpha_v`` α_y (checked against Mitsuba in ``tests/test_microfacet_anisotropic.py``).
The lower bound 1e-4 is Mitsuba's clamp of α; narrower anisotropic lobes were not
verified with the albedo engine.

Public objects
--------------
- :class:`MicrofacetAnisotropic` — ``microfacet-anisotropic``; its kernel is branch-free
  and runs in the vectorised loop.
- :func:`walter_anisotropic`, :func:`walter_sample_anisotropic`,
  :func:`walter_pdf_anisotropic` — its formulas (:mod:`brdfkit._dual`), traced by the
  Mitsuba bridge; :func:`walter_anisotropic_terms` (D G₁ G₁) and
  :func:`walter_anisotropic_rgb` (three channels in the ``"rgb"`` loop, bit-equal per
  channel to the per-channel kernel).

References
----------
- [Walter2007] eq. (20) (BRDF), (25)-(28) Beckmann, (33)-(35) GGX.
- [Heitz2014] E. Heitz, *Understanding the Masking-Shadowing Function in
  Microfacet-Based BRDFs*, JCGT 3(2), 2014, §5.3 (anisotropic distributions by stretching; equation
  numbers not cited: the paper is not on this machine).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from brdfkit._dual import Formulas, formula, maximum, select, sqrt
from brdfkit.errors import ParameterError
from brdfkit.models._base import BRDF, VECTOR_OPTIONS, Lobe, Param
from brdfkit.models._drivers import loop_driver
from brdfkit.models._params import ETA, eta_fresnel_split, packed_indices
from brdfkit.models._registry import register
from brdfkit.models.anisotropic_distributions import (
    anisotropic_distribution,
    d_of_h_anisotropic,
    q_of,
    r2_of,
    sample_half_anisotropic,
)
from brdfkit.models.microfacet import (
    cos_d_of,
    half_sum,
    reflection_jacobian,
    walter_channel,
    walter_channels,
)
from brdfkit.models.microfacet_distributions import (
    _beckmann_g1_over_cos_r,
    beckmann_dg_core,
    d_ggx_of_u,
    ggx_g1_over_cos_r2,
)
from brdfkit.models.sampling import HalfVector, StrategySampled

__all__ = ["MicrofacetAnisotropic", "walter_anisotropic", "walter_sample_anisotropic",
           "walter_pdf_anisotropic", "walter_anisotropic_terms", "walter_anisotropic_rgb"]

BECKMANN, GGX = 0, 1  # the packed value of the distribution choice

# α ≥ 1e-4: Mitsuba's own clamp of α; the anisotropic lobe is not verified narrower
_ALPHA_DOC = ("roughness along the tangent {axis}: 0.01 near-mirror, 0.1 glossy, 0.5 rough "
              "(Mitsuba's alpha_{uv})")
PARAMS = (
    Param("distribution", "beckmann", kind="choice", choices=("beckmann", "ggx"),
          doc="microfacet normal distribution"),
    Param("alpha_x", 0.1, 1e-4, 4.0, "", _ALPHA_DOC.format(axis="X (+x)", uv="u")),
    Param("alpha_y", 0.3, 1e-4, 4.0, "", _ALPHA_DOC.format(axis="Y (+y)", uv="v")),
    ETA,
    Param("k", 0.0, 0.0, 100.0, "", "extinction coefficient (conductors)", kind="colour"),
    Param("rho_s", 1.0, 0.0, 1.0, "", "specular scale", kind="colour"),
)
P_DIST, P_AX, P_AY, P_ETA, P_K, P_SCALE = packed_indices(
    PARAMS, "distribution", "alpha_x", "alpha_y", "eta", "k", "rho_s")
INF = math.inf


@formula
def walter_anisotropic(ix, iy, iz, ox, oy, oz, p, ggx, fresnel):
    """F D G₁(ω_i) G₁(ω_o)/(4 cos θ_i cos θ_o) with the anisotropic D and G₁ (formula).

    Walter eq. (20) as :func:`~brdfkit.models.microfacet.walter` computes it (s = ω_i + ω_o
    rescaled when short, ω·h = |s|/2, no 1 − cos²), with q = (s_x/α_x)² + (s_y/α_y)²:
    GGX D = 1/(π α_x α_y ((s_z² + q)/|s|²)²), Beckmann's exponent −q/s_z², and G₁/cos
    from r² = α_x² ω_x² + α_y² ω_y² per direction. Branch-free and total. The
    channel-independent part is :func:`walter_anisotropic_terms`, the channel's
    :func:`~brdfkit.models.microfacet.walter_channel` (the RGB kernel calls the first once).
    """
    ax, ay, eta, k, scale = p[P_AX], p[P_AY], p[P_ETA], p[P_K], p[P_SCALE]
    live, c, v = walter_anisotropic_terms(ix, iy, iz, ox, oy, oz, ax, ay, ggx)
    return walter_channel(live, c, v, eta, k, scale, fresnel)


@formula
def walter_anisotropic_terms(ix, iy, iz, ox, oy, oz, ax, ay, ggx):
    """(live, c, v) of :func:`walter_anisotropic`: f_r = select(live, scale · F(c) · v, 0),
    v = D G₁ G₁/(4 cos θ_i cos θ_o), c = ω_i·h (1 where not live: F finite)."""
    live = (iz > 0.0) & (oz > 0.0)  # 0 at and below the horizon
    sx, sy, sz, small = half_sum(ix, iy, iz, ox, oy, oz)
    sxy2 = sx * sx + sy * sy
    sz2 = sz * sz
    l2 = sxy2 + sz2
    q = q_of(sx, sy, ax, ay)
    c = select(live, cos_d_of(l2, small), 1.0)  # 1.0: F finite where not live
    ri2 = r2_of(ix, iy, ax, ay)
    ro2 = r2_of(ox, oy, ax, ay)
    if ggx:
        d = d_ggx_of_u((sz2 + q) / l2, ax * ay)
        g = ggx_g1_over_cos_r2(iz, ri2) * ggx_g1_over_cos_r2(oz, ro2)
        v = d * g * 0.25
        live = live & (v < INF)
    else:
        ni, di = _beckmann_g1_over_cos_r(iz, sqrt(ri2))
        no, do = _beckmann_g1_over_cos_r(oz, sqrt(ro2))
        v = beckmann_dg_core(sxy2 / sz2, -q / sz2, ax * ay, ni, di, no, do, live)
    return live, c, v


@formula(**VECTOR_OPTIONS)
def _beckmann(ix, iy, iz, ox, oy, oz, p):
    return walter_anisotropic(ix, iy, iz, ox, oy, oz, p, False, False)


@formula(**VECTOR_OPTIONS)
def _beckmann_f(ix, iy, iz, ox, oy, oz, p):
    return walter_anisotropic(ix, iy, iz, ox, oy, oz, p, False, True)


@formula(**VECTOR_OPTIONS)
def _ggx(ix, iy, iz, ox, oy, oz, p):
    return walter_anisotropic(ix, iy, iz, ox, oy, oz, p, True, False)


@formula(**VECTOR_OPTIONS)
def _ggx_f(ix, iy, iz, ox, oy, oz, p):
    return walter_anisotropic(ix, iy, iz, ox, oy, oz, p, True, True)


_KERNELS = {(False, False): _beckmann, (False, True): _beckmann_f, (True, False): _ggx,
            (True, True): _ggx_f}


# The three channels at once (the "rgb" loop of models/_drivers.py) over t, the three
# packed rows as one flat tuple (t[c·N_PACKED + k]): the terms once, then each channel as
# walter_anisotropic computes it (the same operations: bit-equal to the per-channel kernels).
N_PACKED = len(PARAMS)
if (P_ETA, P_K, P_SCALE) != (N_PACKED - 3, N_PACKED - 2, N_PACKED - 1):  # walter_channels
    raise RuntimeError("microfacet-anisotropic: eta, k, rho_s must end the packed row "
                      "(walter_channels)")


@numba.njit(cache=True, inline="always", **VECTOR_OPTIONS)
def walter_anisotropic_rgb(ix, iy, iz, ox, oy, oz, t, ggx, fresnel):  # pragma: no cover
    """(f_R, f_G, f_B) of :func:`walter_anisotropic` over the flat tuple *t* of the rows."""
    live, c, v = walter_anisotropic_terms(ix, iy, iz, ox, oy, oz, t[P_AX], t[P_AY], ggx)
    return walter_channels(live, c, v, t, fresnel)


@numba.njit(cache=True, inline="always", **VECTOR_OPTIONS)
def _beckmann_rgb(ix, iy, iz, ox, oy, oz, t):  # pragma: no cover - compiled
    return walter_anisotropic_rgb(ix, iy, iz, ox, oy, oz, t, False, False)


@numba.njit(cache=True, inline="always", **VECTOR_OPTIONS)
def _beckmann_f_rgb(ix, iy, iz, ox, oy, oz, t):  # pragma: no cover - compiled
    return walter_anisotropic_rgb(ix, iy, iz, ox, oy, oz, t, False, True)


@numba.njit(cache=True, inline="always", **VECTOR_OPTIONS)
def _ggx_rgb(ix, iy, iz, ox, oy, oz, t):  # pragma: no cover - compiled
    return walter_anisotropic_rgb(ix, iy, iz, ox, oy, oz, t, True, False)


@numba.njit(cache=True, inline="always", **VECTOR_OPTIONS)
def _ggx_f_rgb(ix, iy, iz, ox, oy, oz, t):  # pragma: no cover - compiled
    return walter_anisotropic_rgb(ix, iy, iz, ox, oy, oz, t, True, True)


_RGB_KERNELS = {(False, False): _beckmann_rgb, (False, True): _beckmann_f_rgb,
                (True, False): _ggx_rgb, (True, True): _ggx_f_rgb}


@numba.njit(cache=True, **VECTOR_OPTIONS)
def _microfacet_anisotropic(ix, iy, iz, ox, oy, oz, p):
    """The model's kernel for callers with one kernel per model (albedo engine, pumping):
    dispatches on the packed distribution and on whether η is given (0: F = 1)."""
    if p[P_DIST] == GGX:
        if p[P_ETA] == 0.0:
            return _ggx(ix, iy, iz, ox, oy, oz, p)
        return _ggx_f(ix, iy, iz, ox, oy, oz, p)
    if p[P_ETA] == 0.0:
        return _beckmann(ix, iy, iz, ox, oy, oz, p)
    return _beckmann_f(ix, iy, iz, ox, oy, oz, p)


@formula
def walter_sample_anisotropic(ox, oy, oz, u0, u1, ax, ay, ggx):
    """ω_i = 2(ω_o·h)h − ω_o, h from D(h) cos θ_h (:func:`sample_half_anisotropic`)."""
    hx, hy, hz = sample_half_anisotropic(u0, u1, ax, ay, ggx)
    c = 2.0 * (ox * hx + oy * hy + oz * hz)
    return c * hx - ox, c * hy - oy, c * hz - oz


@formula
def walter_pdf_anisotropic(ix, iy, iz, ox, oy, oz, ax, ay, ggx):
    """Solid-angle density of :func:`walter_sample_anisotropic`: D(h) cos θ_h/(4|ω_o·h|)."""
    hx, hy, hz, ok, jac = reflection_jacobian(ix, iy, iz, ox, oy, oz)
    p = d_of_h_anisotropic(hx, hy, hz, ax, ay, ggx) * maximum(hz, 0.0) / jac
    return select(ok, p, 0.0)


@formula
def _sample_ggx(ox, oy, oz, u0, u1, ax, ay):
    return walter_sample_anisotropic(ox, oy, oz, u0, u1, ax, ay, True)


@formula
def _sample_beckmann(ox, oy, oz, u0, u1, ax, ay):
    return walter_sample_anisotropic(ox, oy, oz, u0, u1, ax, ay, False)


@formula
def _pdf_ggx(ix, iy, iz, ox, oy, oz, ax, ay):
    return walter_pdf_anisotropic(ix, iy, iz, ox, oy, oz, ax, ay, True)


@formula
def _pdf_beckmann(ix, iy, iz, ox, oy, oz, ax, ay):
    return walter_pdf_anisotropic(ix, iy, iz, ox, oy, oz, ax, ay, False)


@register
class MicrofacetAnisotropic(StrategySampled, BRDF):
    """Anisotropic rough conductor of Walter et al. (2007) eq. (20) (module docstring).

    f_r = F(ω_i·h) D(h) G₁(ω_i) G₁(ω_o)/(4 cos θ_i cos θ_o) with D and G₁ of (α_x, α_y).
    Reciprocal; not isotropic (the albedo depends on the incidence azimuth φ_i, with
    a(θ, φ; α_x, α_y) = a(θ, φ + 90°; α_y, α_x)). Energy bounded by 1 with F ≤ 1 (single
    scattering only). Sampled by D(h) cos θ_h (pdf D cos θ_h/(4|ω_o·h|)).
    """

    name = "microfacet-anisotropic"
    aliases = ("roughconductor-anisotropic", "walter-anisotropic", "anisotropic-microfacet")
    summary = "anisotropic Walter 2007 microfacet BRDF (Beckmann/GGX with alpha_x, alpha_y)"
    params = PARAMS
    citation = ("Walter et al. 2007 eq. (20) with (25)-(27)/(33)-(34) made anisotropic; "
                "Heitz 2014 §5.3")
    reciprocal = True
    isotropic = False
    has_sampler = True
    kernel = _microfacet_anisotropic
    examples = (
        {},
        {"distribution": "ggx", "alpha_x": 0.05, "alpha_y": 0.5, "eta": [0.2, 0.9, 1.1],
         "k": [3.9, 2.4, 2.2]},
        {"alpha_x": 0.6, "alpha_y": 0.02},
        {"distribution": "ggx", "alpha_x": 1.0, "alpha_y": 0.3, "eta": 1.5},
    )

    def _validate(self):
        v = self._values
        if v["eta"] is None and np.any(np.asarray(v["k"]) != 0.0):
            raise ParameterError(
                f"{self.name}: k needs eta: give eta (the real part of the index) or drop k")
        # BRDF.eval's loop: the vectorised loop of this instance's (distribution, Fresnel);
        # RGB: the "rgb" loop (D G₁ G₁ once per pair, three Fresnel factors)
        if self.n_channels == 3:
            key = (v["distribution"] == "ggx", v["eta"] is not None)
            self._driver = loop_driver(_RGB_KERNELS[key], loop="rgb", width=3 * N_PACKED)
        else:
            self._driver = loop_driver(self._kernel(), loop="vector")

    def _kernel(self):
        v = self._values
        return _KERNELS[(v["distribution"] == "ggx", v["eta"] is not None)]

    def lobes(self):
        # the narrower axis sets the resolution; a half-vector lobe (D of h)
        return [Lobe("half", float(min(self._values["alpha_x"], self._values["alpha_y"])))]

    def albedo_half_axes(self):
        """(α_x, α_y, q): D is d(tan²θ_h (cos²ψ/α_x² + sin²ψ/α_y²)) (Heitz 2014 §5.3), d
        Beckmann's e^{−x} (q = 0) or GGX's (1 + x)^{−2} (q = 1)."""
        v = self._values
        return (float(v["alpha_x"]), float(v["alpha_y"]),
                1.0 if v["distribution"] == "ggx" else 0.0)

    def fresnel_split(self):
        """F = ρ_s · F_conductor(η, κ) (1 without η); white: η not given, κ = 0, ρ_s = 1 (as
        :meth:`~brdfkit.models.microfacet.Microfacet.fresnel_split`)."""
        return eta_fresnel_split(self, k="k", scale="rho_s")

    def _strategy(self, wo):
        v = self._values
        return HalfVector(anisotropic_distribution(v["distribution"], v["alpha_x"],
                                                   v["alpha_y"]), fold=False)

    def formulas(self) -> Formulas:
        """:func:`walter_anisotropic` (this instance's kernel) and its sampler, args (α_x, α_y)."""
        ggx = self._values["distribution"] == "ggx"
        return Formulas(eval=self._kernel(), sample=_sample_ggx if ggx else _sample_beckmann,
                        pdf=_pdf_ggx if ggx else _pdf_beckmann,
                        args=(float(self._values["alpha_x"]), float(self._values["alpha_y"])))
