"""
The Phong family
================

Phong and Blinn shaders as BRDFs and their physically plausible variants from
all three papers.

Public objects
--------------
- :class:`ModifiedPhong` — ``modified-phong``, Nielsen eq. (1).

References
----------
- [Lewis1993] eqs. (5), (6), (8), (22), (24), §7.
- [Neumann1999] eqs. (6), (7), (22).
- [Nielsen2015] eqs. (1)–(3).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from brdfkit._array import as_directions, as_uniform, stack
from brdfkit._kern import INV_PI, INV_TWO_PI, below_horizon, pos_pow, r_dot_v
from brdfkit.geometry import (
    local_to_world,
    pdf_cosine_hemisphere,
    reflect,
    sample_cosine_hemisphere,
)
from brdfkit.halfangle import exponent_from_beta
from brdfkit.models._base import BRDF, Lobe, Param
from brdfkit.models._registry import register

RHO_D = Param("rho_d", 0.2, 0.0, 1.0, "", "diffuse albedo", kind="colour")
RHO_S = Param("rho_s", 0.5, 0.0, 1.0, "",
              "specular reflectance (albedo of the normalised lobe at normal incidence)",
              kind="colour")
N_EXP = Param("n", 20.0, 0.0, 1e6, "",
              "specular exponent (lobe sharpness); ~1-10 rough, 100-1000 glossy, >1e4 mirror")


# --------------------------------------------------------------------------- sampling helpers
def sample_phong_lobe(axis: np.ndarray, n: float, u: np.ndarray) -> np.ndarray:
    """Direction about *axis* with density (n+1)/(2π) cosⁿα on the sphere.

    Inverting the CDF of cosⁿα sinα gives cos α = u₀^{1/(n+1)}.
    """
    cos_a = u[..., 0] ** (1.0 / (n + 1.0))
    sin_a = np.sqrt(np.maximum(0.0, 1.0 - cos_a * cos_a))  # clamp: rounding near cos_a = 1
    phi = 2.0 * np.pi * u[..., 1]
    local = stack(sin_a * np.cos(phi), sin_a * np.sin(phi), cos_a)
    return local_to_world(local, axis)


def pdf_phong_lobe(cos_alpha: np.ndarray, n: float) -> np.ndarray:
    """Density of :func:`sample_phong_lobe`, (n+1)/(2π) max(0, cos α)ⁿ."""
    return (n + 1.0) / (2.0 * np.pi) * np.maximum(cos_alpha, 0.0) ** n


def diffuse_fraction(rho_d, rho_s) -> float:
    """Probability of picking the diffuse lobe in a diffuse + specular mixture.

    Proportional to the channel-mean reflectances; 1/2 when both are zero.
    """
    d = float(np.mean(rho_d))
    s = float(np.mean(rho_s))
    return 0.5 if d + s <= 0.0 else d / (d + s)


def split_uniform(u0: np.ndarray, p: float) -> tuple[np.ndarray, np.ndarray]:
    """Pick the first lobe where u₀ < p and rescale u₀ to [0, 1) in both branches."""
    first = u0 < p
    if p <= 0.0:
        return np.zeros_like(u0, dtype=bool), u0
    if p >= 1.0:
        return np.ones_like(u0, dtype=bool), u0
    return first, np.where(first, u0 / p, (u0 - p) / (1.0 - p))


# --------------------------------------------------------------------------- modified Phong
@numba.njit(cache=True)
def _modified_phong(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    rho_d, rho_s, n = p[0], p[1], p[2]
    cos_r = r_dot_v(ix, iy, iz, ox, oy, oz)  # ω_r·ω_o
    return rho_d * INV_PI + rho_s * (n + 2.0) * INV_TWO_PI * pos_pow(cos_r, n)


@register
class ModifiedPhong(BRDF):
    """Modified (normalised, reciprocal) Phong: Nielsen et al. eq. (1).

    f_r = ρ_d/π + ρ_s (n+2)/(2π) max(0, ω_r·ω_o)ⁿ, with ω_r the mirror of ω_i.
    This is Neumann eq. (6) with c_Phong(n) = ρ_s (n+2)/2π; the factor makes
    the specular albedo exactly ρ_s at normal incidence
    (∫ cosⁿα cos θ dω = 2π/(n+2) when the lobe is centred on the normal). At
    oblique incidence the horizon cuts the lobe and the albedo falls below ρ_d
    + ρ_s (Neumann §1.2: the "dark Phong mirror").

    ======  =======  ===========  =============================================
    name    default  bounds       meaning
    ======  =======  ===========  =============================================
    rho_d   0.2      [0, 1]       diffuse albedo (per channel)
    rho_s   0.5      [0, 1]       specular reflectance (per channel)
    n       20       [0, 1e6]     exponent; or give ``beta``, the half-angle
    ======  =======  ===========  =============================================

    Reciprocal (R·V is symmetric). Energy conserving when ρ_d + ρ_s ≤ 1.
    Sampled as a mixture of cosine and the cosⁿ lobe about the mirror of wo.
    """

    name = "modified-phong"
    aliases = ("phong-modified", "nielsen-phong")
    summary = "normalised reciprocal Phong, rho_d/pi + rho_s (n+2)/2pi (R.V)^n"
    params = (RHO_D, RHO_S, N_EXP)
    citation = "Nielsen et al. eq. (1); Neumann et al. 1999 eq. (6)"
    reciprocal = True
    has_sampler = True
    width_param = "n"
    kernel = _modified_phong
    examples = (
        {},
        {"rho_d": 0.0, "rho_s": 1.0, "n": 5000.0},
        {"rho_d": [0.1, 0.2, 0.3], "rho_s": [0.5, 0.4, 0.3], "n": 2.0},
    )

    def lobes(self):
        from brdfkit.halfangle import beta_from_exponent

        n = self._values["n"]
        out = [Lobe("diffuse", math.pi / 2)] if np.any(self._values["rho_d"]) else []
        return out + [Lobe("mirror", float(beta_from_exponent(n)) if n > 0 else math.pi / 2)]

    @classmethod
    def width_from_beta(cls, beta: float) -> float:
        return exponent_from_beta(beta)

    def sample(self, wo, u):
        wo = as_directions(wo, "wo")
        u = as_uniform(u)
        v = self._values
        p_d = diffuse_fraction(v["rho_d"], v["rho_s"])
        diffuse, u0 = split_uniform(u[..., 0], p_d)
        u = np.stack([u0, u[..., 1]], axis=-1)
        shape = np.broadcast_shapes(wo.shape, u.shape[:-1] + (3,))
        wi_d = np.broadcast_to(sample_cosine_hemisphere(u), shape)
        wi_s = np.broadcast_to(sample_phong_lobe(np.broadcast_to(reflect(wo), shape),
                                                 v["n"], u), shape)
        wi = np.where(diffuse[..., None], wi_d, wi_s)
        return wi, self.pdf(wi, wo)

    def pdf(self, wi, wo):
        wi = as_directions(wi, "wi")
        wo = as_directions(wo, "wo")
        v = self._values
        p_d = diffuse_fraction(v["rho_d"], v["rho_s"])
        cos_alpha = np.sum(wi * reflect(wo), axis=-1)
        p = p_d * pdf_cosine_hemisphere(wi) + (1.0 - p_d) * pdf_phong_lobe(cos_alpha, v["n"])
        return np.where(wo[..., 2] > 0.0, p, 0.0)


