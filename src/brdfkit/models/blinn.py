"""
Reciprocal N·H (Blinn–Phong) lobes
==================================

BRDFs built from powers of N·H without Lewis's 1/(N·L) (eq. 8), so they are
reciprocal and their albedo stays bounded. Every kernel is written over the
dot products of the local frame (N·L = ``iz``, N·V = ``oz``, N·H; see
:mod:`brdfkit._kern`). Sampled through the half vector
(:func:`brdfkit.models.sampling.blinn_lobe`).

Public objects
--------------
- :class:`PhongBlinnReciprocal` — ``phong-blinn-reciprocal``: Lewis eq. (24),
  Neumann eq. (6) "reciprocal Blinn".
- :class:`NHPowerSeries` — ``nh-power-series``: Lewis §7.
- :class:`ModifiedBlinnPhong` — ``modified-blinn-phong``: Nielsen eq. (2).

References
----------
- [Lewis1993] R. R. Lewis, *Making Shaders More Physically Plausible*, 1993:
  eq. (24), §7.
- [Neumann1999] L. Neumann, A. Neumann, L. Szirmay-Kalos, *Reflectance Models
  by Pumping up the Albedo Function*, 1999: eq. (6).
- [Nielsen2015] J. B. Nielsen, J. R. Frisvad, K. Conradsen, H. Aanæs,
  *Addressing Grazing Angle Reflections in Phong Models*: eq. (2).
- [Akenine-Möller2008] T. Akenine-Möller, E. Haines, N. Hoffman,
  *Real-Time Rendering*, 3rd ed. (the (n+8)/8π factor of Nielsen eq. 2).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from brdfkit._dual import Formulas, formula, select
from brdfkit._kern import INV_PI, below_horizon, n_dot_h
from brdfkit.models._base import VECTOR_OPTIONS, Lobe, Param
from brdfkit.models._drivers import loop_driver
from brdfkit.models._lobes import (
    K_D,
    K_S,
    LOBE_AUTO,
    LOBE_INTEGRAL,
    N_EXP,
    RHO_D,
    RHO_S,
    CosineLobeBRDF,
    DiffuseLobeBRDF,
    KdKsBlinnBRDF,
    lobe_hint,
    lobe_pow,
    lobe_power,
    nh_dot,
)
from brdfkit.models._params import packed_indices
from brdfkit.models._registry import register
from brdfkit.models.lobe_series import nh_series_formulas, series_eval
from brdfkit.models.sampling import (
    COSINE,
    Mixture,
    blinn_lobe,
    diffuse_fraction,
    normalised_weights,
)
from brdfkit.models.specular import blinn_normal_albedo

__all__ = ["PhongBlinnReciprocal", "NHPowerSeries", "ModifiedBlinnPhong"]


# --------------------------------------------------------------------------- Lewis eq. (24)
RECIPROCAL_PARAMS = (K_D, K_S, N_EXP)
P_K_D, P_K_S, P_K_N = packed_indices(RECIPROCAL_PARAMS, "k_d", "k_s", "n")


@formula
def phong_blinn_reciprocal(ix, iy, iz, ox, oy, oz, p, mode):
    """Lewis eq. (24), k_d + k_s (N·H)ⁿ, a formula (:mod:`brdfkit._dual`): branch-free, 0 at
    and below the horizon; *mode* the compile-time ``lobe_power`` mode."""
    k_d, k_s, n = p[P_K_D], p[P_K_S], p[P_K_N]
    nh, _ = nh_dot(ix, iy, iz, ox, oy, oz)
    return select((iz > 0.0) & (oz > 0.0), k_d + k_s * lobe_power(nh, n, mode), 0.0)


@formula(**VECTOR_OPTIONS)
def _phong_blinn_reciprocal(ix, iy, iz, ox, oy, oz, p):
    return phong_blinn_reciprocal(ix, iy, iz, ox, oy, oz, p, LOBE_AUTO)


@formula(**VECTOR_OPTIONS)
def _phong_blinn_reciprocal_int(ix, iy, iz, ox, oy, oz, p):
    return phong_blinn_reciprocal(ix, iy, iz, ox, oy, oz, p, LOBE_INTEGRAL)


@register
class PhongBlinnReciprocal(KdKsBlinnBRDF):
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
    params = RECIPROCAL_PARAMS
    citation = "Lewis 1993 eq. (24); Neumann et al. 1999 eq. (6) (reciprocal Blinn)"
    reciprocal = True
    width_param = "n"
    kernel = _phong_blinn_reciprocal
    lobe_kernels = (_phong_blinn_reciprocal, _phong_blinn_reciprocal_int)
    lobe_layout = ("cosine", "blinn")
    examples = (
        {},
        {"k_d": 0.0, "k_s": 400.0, "n": 10000.0},
        {"k_d": [0.05, 0.1, 0.15], "k_s": [1.0, 0.5, 0.25], "n": 3.0},
    )


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
class NHPowerSeries(CosineLobeBRDF):
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
        out = [lobe_hint("half", float(n))
               for k, n in zip(v["k_s"], v["n"], strict=True) if k > 0.0]
        return out or [Lobe("diffuse", math.pi / 2)]

    def _weights(self) -> np.ndarray:
        """The mixture weights: each term's normal-incidence albedo k_i ∫(N·H)^{n_i} cos dω."""
        v = self.channel_values(0)
        return normalised_weights([k * blinn_normal_albedo(n)
                                   for k, n in zip(v["k_s"], v["n"], strict=True)])

    def _strategy(self, wo):
        comps = [blinn_lobe(float(n)) for n in self.channel_values(0)["n"]]
        return Mixture(comps, self._weights())

    def _validate(self):
        # model.eval runs the formula unrolled for this instance's number of terms in the
        # vectorising loop: bit-identical to the kernel's loop over the terms, which LLVM
        # cannot vectorise (measured: 2-3x the M evals/s of the kernel's checked loop)
        self._driver = loop_driver(series_eval("nh", self.channel_values(0)["n"]),
                                   loop="vector")

    def formulas(self) -> Formulas:
        """f_r, the sampler of :meth:`_strategy` and its pdf as formulas unrolled for this
        instance's number of terms (:mod:`brdfkit.models.lobe_series`)."""
        return nh_series_formulas(self, self._weights())


# --------------------------------------------------------------------------- Nielsen eq. (2)
MODIFIED_BLINN_PARAMS = (RHO_D, RHO_S, N_EXP)
P_RHO_D, P_RHO_S, P_N = packed_indices(MODIFIED_BLINN_PARAMS, "rho_d", "rho_s", "n")


INV_8PI = 1.0 / (8.0 * math.pi)  # the (n+8)/8π of Nielsen eq. (2)


@formula
def modified_blinn_phong(ix, iy, iz, ox, oy, oz, p, mode):
    """Nielsen eq. (2), a formula (:mod:`brdfkit._dual`): branch-free, 0 at and below the
    horizon; *mode* the compile-time ``lobe_power`` mode."""
    rho_d, rho_s, n = p[P_RHO_D], p[P_RHO_S], p[P_N]
    nh, _ = nh_dot(ix, iy, iz, ox, oy, oz)
    f = rho_d * INV_PI + rho_s * (n + 8.0) * INV_8PI * lobe_power(nh, n, mode)
    return select((iz > 0.0) & (oz > 0.0), f, 0.0)


@formula(**VECTOR_OPTIONS)
def _modified_blinn_phong(ix, iy, iz, ox, oy, oz, p):
    return modified_blinn_phong(ix, iy, iz, ox, oy, oz, p, LOBE_AUTO)


@formula(**VECTOR_OPTIONS)
def _modified_blinn_phong_int(ix, iy, iz, ox, oy, oz, p):
    return modified_blinn_phong(ix, iy, iz, ox, oy, oz, p, LOBE_INTEGRAL)


@register
class ModifiedBlinnPhong(DiffuseLobeBRDF):
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
    params = MODIFIED_BLINN_PARAMS
    citation = "Nielsen et al. eq. (2); Akenine-Möller et al. 2008"
    reciprocal = True
    width_param = "n"
    kernel = _modified_blinn_phong
    lobe_kernels = (_modified_blinn_phong, _modified_blinn_phong_int)
    lobe_layout = ("cosine", "blinn")
    examples = (
        {},
        {"rho_d": 0.0, "rho_s": 1.0, "n": 10000.0},
        {"rho_d": [0.1, 0.2, 0.3], "rho_s": [0.5, 0.4, 0.3], "n": 2.0},
    )

    diffuse_param = "rho_d"

    def _strategy(self, wo):
        v = self._values
        p_d = diffuse_fraction(v["rho_d"], v["rho_s"])
        return Mixture([COSINE, blinn_lobe(v["n"])], np.array([p_d, 1.0 - p_d]))
