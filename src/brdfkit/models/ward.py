"""
The isotropic Ward model
========================

Ward (1992) as Neumann et al. write it, eq. (8): a diffuse term and an
elliptical-Gaussian-like lobe e^{−tan²δ/m²}/√((N·L)(N·V)), sampled with Ward's
half-vector distribution (Walter 2005's correction of its pdf).

Public objects
--------------
- :class:`Ward` — ``ward``.

References
----------
- [Neumann1999] eq. (8) and §2.1 (its albedo diverges at grazing angles).
"""

from __future__ import annotations

import math

import numpy as np

from brdfkit._dual import Formulas, exp_nonpos, formula, maximum, minimum, select, sqrt
from brdfkit._kern import INV_PI
from brdfkit.halfangle import beta_from_ward_m, ward_m_from_beta
from brdfkit.models._base import BRDF, VECTOR_OPTIONS, Lobe, Param
from brdfkit.models._drivers import loop_driver
from brdfkit.models._params import M_SLOPE, packed_indices
from brdfkit.models._registry import register
from brdfkit.models.microfacet import half_sum, walter_pdf, walter_sample
from brdfkit.models.microfacet_distributions import _HalfVectorSampling
from brdfkit.models.sampling import malley

__all__ = ["Ward"]


# =========================================================================== Ward
PARAMS = (
    Param("rho_d", 0.0, 0.0, 1.0, "", "diffuse albedo", kind="colour"),
    Param("rho_s", 1.0, 0.0, 1.0, "", "specular albedo scale", kind="colour"),
    M_SLOPE,
)
P_RHO_D, P_RHO_S, P_M = packed_indices(PARAMS, "rho_d", "rho_s", "m")


FOUR_PI = 4.0 * math.pi
#: tan²δ/m² beyond which e^{−tan²δ/m²} < 1e-290 is given as 0 (as beckmann_lobe)
EXPONENT_FLOOR = -700.0
#: floor of √((N·L)(N·V)): f ≤ ρ_s/(4π m² 1e-140) stays finite when both cosines are
#: within 1e-280 of the horizon
ROOT_FLOOR = 1e-140


@formula(**VECTOR_OPTIONS)
def _ward(ix, iy, iz, ox, oy, oz, p):
    """ρ_d/π + ρ_s e^{−tan²δ/m²}/(4π m² √((N·L)(N·V))), Neumann et al. eq. (8); a formula
    (:mod:`brdfkit._dual`), 0 at and below the horizon.

    cos δ = s_z/|s| with s = ω_i + ω_o (:func:`~brdfkit.models.microfacet.half_sum`, rescaled
    when short); e^{−tan²δ/m²} is written as ``beckmann_lobe(cos δ, m) cos⁴δ`` was (the same
    rounding), 0 where tan²δ/m² > 700.
    """
    rho_d, rho_s, m = p[P_RHO_D], p[P_RHO_S], p[P_M]
    live = (iz > 0.0) & (oz > 0.0)
    sx, sy, sz, small = half_sum(ix, iy, iz, ox, oy, oz)
    l2 = select(live, sx * sx + sy * sy + sz * sz, 1.0)  # 1: the discarded lanes finite
    hz = sz / sqrt(l2)
    c2 = hz * hz
    e = -(1.0 - c2) / (c2 * m * m)
    up = e >= EXPONENT_FLOOR  # false for NaN (c2 = 0 in a discarded lane)
    # clamp: e ≤ 0 but for the rounding of hz just above 1
    lobe = exp_nonpos(minimum(select(up, e, -1000.0), 0.0)) / (c2 * c2) * c2 * c2
    # sqrt of each cosine separately avoids underflow of the product; floor: ROOT_FLOOR
    root = maximum(sqrt(maximum(iz, 0.0)) * sqrt(maximum(oz, 0.0)), ROOT_FLOOR)
    spec = select(up, rho_s * lobe / (FOUR_PI * m * m * root), 0.0)
    return select(live, rho_d * INV_PI + spec, 0.0)


@formula
def ward_sample(ox, oy, oz, u0, u1, m, w_d):
    """The sampler of :class:`Ward` (``Mixture([COSINE, HalfVector(Beckmann(m))], [w_d,
    1 − w_d])``) as a formula: the cosine when u₀ < w_d, else the mirror of ω_o about a
    Beckmann half vector (Walter eq. 28), u₀ rescaled into its interval (both evaluated)."""
    pick_cos = u0 < w_d
    uc = minimum(u0 / maximum(w_d, 1e-30), 1.0)  # floor: w_d = 0 (never picked), clamp: rounding
    us = maximum((u0 - w_d) / maximum(1.0 - w_d, 1e-30), 0.0)  # floor: w_d = 1 (never picked)
    cx, cy, cz = malley(uc, u1)
    x, y, z = walter_sample(ox, oy, oz, us, u1, m, False)
    return select(pick_cos, cx, x), select(pick_cos, cy, y), select(pick_cos, cz, z)


@formula
def ward_pdf(ix, iy, iz, ox, oy, oz, m, w_d):
    """Density of :func:`ward_sample`: w_d cos⁺θ_i/π + (1 − w_d) D(h) cos θ_h/(4|ω_o·h|);
    0 when ω_o is at or below the horizon."""
    ps = walter_pdf(ix, iy, iz, ox, oy, oz, m, False)
    return select(oz > 0.0, w_d * maximum(iz, 0.0) * INV_PI + (1.0 - w_d) * ps, 0.0)


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
    params = PARAMS
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

    def _validate(self):
        self._driver = loop_driver(_ward, loop="vector")

    def formulas(self) -> Formulas:
        """:func:`_ward` and the cosine + Beckmann half-vector mixture of ``_strategy``."""
        return Formulas(eval=_ward, sample=ward_sample, pdf=ward_pdf,
                        args=(float(self._values["m"]), self._p_diffuse()))

    def lobes(self):
        out = [Lobe("diffuse", math.pi / 2)] if np.any(self._values["rho_d"]) else []
        return out + [Lobe("half", float(beta_from_ward_m(self._values["m"])))]
