"""
Diffuse and separable models
============================

Public objects
--------------
- :class:`Lambert` — ``lambert``: ρ_d/π.

(The Neumann–Neumann lacquer model and the Minnaert shaders of Lewis §3.3–3.4
and §4.3 live here too.)

References
----------
- [Lewis1993] §3.3 (Neumann–Neumann), §3.4 and §4.3 (Minnaert).
"""

from __future__ import annotations

import numba

from brdfkit._kern import INV_PI, below_horizon
from brdfkit.models._base import BRDF, Param
from brdfkit.models._registry import register

RHO_D = Param("rho_d", 0.8, 0.0, 1.0, "", "diffuse albedo (fraction of irradiance reflected)",
              kind="colour")


@numba.njit(cache=True)
def _lambert(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    rho_d = p[0]
    return rho_d * INV_PI


@register
class Lambert(BRDF):
    """Lambertian diffuse reflector, f_r = ρ_d/π.

    ========  =======  ======  ==========================================
    name      default  bounds  meaning
    ========  =======  ======  ==========================================
    rho_d     0.8      [0, 1]  albedo; constant in θ_i (exactly ρ_d)
    ========  =======  ======  ==========================================

    Cosine sampling is exact: f cos θ_i / pdf = ρ_d.
    """

    name = "lambert"
    aliases = ("diffuse", "lambertian")
    summary = "Lambertian diffuse: rho_d/pi"
    params = (RHO_D,)
    citation = "Lambert 1760; Lewis 1993 eq. (8) with k_s = 0 (k_d = rho_d/pi)"
    reciprocal = True
    has_sampler = True
    kernel = _lambert
