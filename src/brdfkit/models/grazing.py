"""
Phong variants for grazing angles
=================================

Two answers to the Phong lobe's behaviour at grazing angles: the limit of
repeated albedo pumping of Phong by Neumann et al. (eq. 22), whose
max(N·L, N·V) denominator lifts the albedo where the horizon cuts the lobe,
and Nielsen et al.'s Fresnel-weighted mix of the Phong (R·V) and Blinn–Phong
(N·H)⁴ lobes (eq. 3). Kernels are written over the dot products of the local
frame (see :mod:`brdfkit._kern`).

Public objects
--------------
- :class:`NeumannPhong` — ``neumann-phong``: Neumann eq. (22).
- :class:`Nielsen` — ``nielsen``: Nielsen eq. (3) with Fresnel.

References
----------
- [Neumann1999] L. Neumann, A. Neumann, L. Szirmay-Kalos, *Reflectance Models
  by Pumping up the Albedo Function*, 1999: eq. (22).
- [Nielsen2015] J. B. Nielsen, J. R. Frisvad, K. Conradsen, H. Aanæs,
  *Addressing Grazing Angle Reflections in Phong Models*: eqs. (1)–(3).
- [Lewis1993] R. R. Lewis, *Making Shaders More Physically Plausible*, 1993:
  eq. (16) (the normal-incidence albedo behind Neumann's bound).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from brdfkit._dual import formula, maximum, select
from brdfkit._kern import INV_PI, INV_TWO_PI
from brdfkit.fresnel import _fresnel_dielectric as fresnel_dielectric
from brdfkit.models._base import VECTOR_OPTIONS, Lobe, Param
from brdfkit.models._lobes import (
    COS_DIVISOR_FLOOR,
    LOBE_AUTO,
    LOBE_INTEGRAL,
    N_EXP,
    RHO_D,
    CosineLobeBRDF,
    channel_mean,
    lobe_hint,
    lobe_mode,
    lobe_power,
    nh_dot,
    rv_dot,
)
from brdfkit.models._params import ETA, packed_indices
from brdfkit.models._registry import register
from brdfkit.models.sampling import COSINE, Mixture, blinn_lobe, normalised_weights, phong_lobe
from brdfkit.models.specular import blinn_normal_albedo

__all__ = ["NeumannPhong", "Nielsen"]


# --------------------------------------------------------------------------- Neumann eq. (22)
NEUMANN_PHONG_PARAMS = (
    Param("c_n", None, 0.0, 1e7, "1/sr",
          "scale; none: (n+2)/2pi, the paper's bound (not sufficient, see docs)",
          kind="colour", optional=True),
    N_EXP,
)
# one slot each, in declared order (NeumannPhong._pack_channel writes c_n's value in use)
P_C_N, P_N = packed_indices(NEUMANN_PHONG_PARAMS, "c_n", "n")


@formula
def neumann_phong(ix, iy, iz, ox, oy, oz, p, mode):
    """Neumann eq. (22), a formula (:mod:`brdfkit._dual`): branch-free, 0 at and below the
    horizon; *mode* the compile-time ``lobe_power`` mode. max(N·L, N·V) > 0 above the
    horizon but can be subnormal (both directions within 1e-300 of the horizon), where
    c_n/max overflows; floored at COS_DIVISOR_FLOOR (see there)."""
    c_n, n = p[P_C_N], p[P_N]
    f = (c_n * lobe_power(rv_dot(ix, iy, iz, ox, oy, oz), n, mode)
         / maximum(maximum(iz, oz), COS_DIVISOR_FLOOR))
    return select((iz > 0.0) & (oz > 0.0), f, 0.0)


@formula(**VECTOR_OPTIONS)
def _neumann_phong(ix, iy, iz, ox, oy, oz, p):
    return neumann_phong(ix, iy, iz, ox, oy, oz, p, LOBE_AUTO)


@formula(**VECTOR_OPTIONS)
def _neumann_phong_int(ix, iy, iz, ox, oy, oz, p):
    return neumann_phong(ix, iy, iz, ox, oy, oz, p, LOBE_INTEGRAL)


@register
class NeumannPhong(CosineLobeBRDF):
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
    params = NEUMANN_PHONG_PARAMS
    citation = "Neumann et al. 1999 eq. (22)"
    albedo_kinks = frozenset({"nv=nl"})  # the max(N·L, N·V) denominator of eq. (22)
    reciprocal = True
    width_param = "n"
    kernel = _neumann_phong
    lobe_kernels = (_neumann_phong, _neumann_phong_int)
    lobe_layout = ("phong",)
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
        return [lobe_hint("mirror", self._values["n"])]

    def _strategy(self, wo):
        return Mixture([phong_lobe(self._values["n"])], np.array([1.0]))


# --------------------------------------------------------------------------- Nielsen eq. (3)
NIELSEN_PARAMS = (
    RHO_D,
    Param("k_s", 2.0, 0.0, 1e6, "1/sr", "specular coefficient (~ rho_s (s+2)/2pi)",
          kind="colour"),
    Param("s", 20.0, 0.0, 1e6, "", "shininess exponent"),
    Param("alpha", 0.5, 0.0, 1.0, "", "mix: 0 Phong (R.V), 1 Blinn-Phong (N.H)^4"),
    replace(ETA, doc="refractive index; none: F = 1"),
)
N_RHO_D, N_K_S, N_S, N_ALPHA, N_ETA = packed_indices(
    NIELSEN_PARAMS, "rho_d", "k_s", "s", "alpha", "eta")


@formula
def nielsen(ix, iy, iz, ox, oy, oz, p, mode, fresnel):
    """Nielsen eq. (3), a formula (:mod:`brdfkit._dual`): branch-free, 0 at and below the
    horizon; *mode* the ``lobe_power`` mode, *fresnel* whether η is given (else F = 1),
    both compile-time constants.

    One square root, one division: ω_h·n = (N·L + N·V)/|L + V|,
    ω_i·ω_h = (1 + L·V)/|L + V| = |L + V|/2 and ω_r·ω_o = 2(N·L)(N·V) − L·V.
    |L + V| comes from the components (not √(2 + 2 L·V), which rounds to 0 for
    grazing opposite directions), rescaled where its squares underflow (``nh_dot``).
    """
    rho_d, k_s, s, alpha, eta = p[N_RHO_D], p[N_K_S], p[N_S], p[N_ALPHA], p[N_ETA]
    hz, length = nh_dot(ix, iy, iz, ox, oy, oz)
    if fresnel:
        f = fresnel_dielectric(0.5 * length, eta)
    else:
        f = 1.0
    hz2 = hz * hz
    base = (1.0 - alpha) * rv_dot(ix, iy, iz, ox, oy, oz) + alpha * hz2 * hz2
    # the mixed base clamped at 0 (lobe_power): R·V < 0 away from the mirror direction can
    # make it negative, where a non-integer power is undefined and the Phong lobe of eq. (1)
    # is 0 (max(0, ·), as in Akenine-Möller et al.)
    f = rho_d * INV_PI + k_s * f * lobe_power(base, s, mode)
    return select((iz > 0.0) & (oz > 0.0), f, 0.0)


@formula(**VECTOR_OPTIONS)
def _nielsen(ix, iy, iz, ox, oy, oz, p):
    """The class kernel (any s; F where the packed η is not 0, the "not given" value)."""
    f = nielsen(ix, iy, iz, ox, oy, oz, p, LOBE_AUTO, True)
    return select(p[N_ETA] == 0.0, nielsen(ix, iy, iz, ox, oy, oz, p, LOBE_AUTO, False), f)


@formula(**VECTOR_OPTIONS)
def _nielsen_any(ix, iy, iz, ox, oy, oz, p):
    return nielsen(ix, iy, iz, ox, oy, oz, p, LOBE_AUTO, False)


@formula(**VECTOR_OPTIONS)
def _nielsen_any_f(ix, iy, iz, ox, oy, oz, p):
    return nielsen(ix, iy, iz, ox, oy, oz, p, LOBE_AUTO, True)


@formula(**VECTOR_OPTIONS)
def _nielsen_int(ix, iy, iz, ox, oy, oz, p):
    return nielsen(ix, iy, iz, ox, oy, oz, p, LOBE_INTEGRAL, False)


@formula(**VECTOR_OPTIONS)
def _nielsen_int_f(ix, iy, iz, ox, oy, oz, p):
    return nielsen(ix, iy, iz, ox, oy, oz, p, LOBE_INTEGRAL, True)


# (integral s, η given) → the kernel (Nielsen._lobe_kernel)
_NIELSEN_KERNELS = {(False, False): _nielsen_any, (False, True): _nielsen_any_f,
                    (True, False): _nielsen_int, (True, True): _nielsen_int_f}


@register
class Nielsen(CosineLobeBRDF):
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
    params = NIELSEN_PARAMS
    citation = "Nielsen et al. eq. (3), Fresnel factor as in the text"
    fit_bound_starts = ("alpha",)  # α = 0: the Phong-like lobe, α = 1: the Blinn-like one
    reciprocal = True
    width_param = "s"
    kernel = _nielsen
    lobe_kernels = (_nielsen_any, _nielsen_int)  # and with F: _lobe_kernel
    lobe_layout = ("cosine", "phong", "blinn")
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
            out.append(lobe_hint("mirror", v["s"]))
        if v["alpha"] > 0.0:
            out.append(lobe_hint("half", 4.0 * v["s"]))
        return out

    def _lobe_kernel(self):
        v = self._values
        return _NIELSEN_KERNELS[(lobe_mode(v["s"]) == LOBE_INTEGRAL, v["eta"] is not None)]

    def _strategy(self, wo):
        v = self._values
        s, alpha, k_s = v["s"], v["alpha"], channel_mean(v["k_s"])
        w = normalised_weights([channel_mean(v["rho_d"]),
                                k_s * (1.0 - alpha) * 2.0 * math.pi / (s + 2.0),
                                k_s * alpha * blinn_normal_albedo(4.0 * s)])
        return Mixture([COSINE, phong_lobe(s), blinn_lobe(4.0 * s)], w)
