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

import numba
import numpy as np

from brdfkit._kern import INV_PI, below_horizon, half
from brdfkit.halfangle import beta_from_ward_m, ward_m_from_beta
from brdfkit.models._base import BRDF, Lobe, Param
from brdfkit.models._params import M_SLOPE, packed_indices
from brdfkit.models._registry import register
from brdfkit.models.microfacet_distributions import _HalfVectorSampling, beckmann_lobe

__all__ = ["Ward"]


# =========================================================================== Ward
PARAMS = (
    Param("rho_d", 0.0, 0.0, 1.0, "", "diffuse albedo", kind="colour"),
    Param("rho_s", 1.0, 0.0, 1.0, "", "specular albedo scale", kind="colour"),
    M_SLOPE,
)
P_RHO_D, P_RHO_S, P_M = packed_indices(PARAMS, "rho_d", "rho_s", "m")


@numba.njit(cache=True)
def _ward(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    rho_d, rho_s, m = p[P_RHO_D], p[P_RHO_S], p[P_M]
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

    def lobes(self):
        out = [Lobe("diffuse", math.pi / 2)] if np.any(self._values["rho_d"]) else []
        return out + [Lobe("half", float(beta_from_ward_m(self._values["m"])))]
