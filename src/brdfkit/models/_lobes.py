"""
Shared pieces of the Phong-family modules
=========================================

The parameter declarations, the kernel helper and the lobe hints that
:mod:`~brdfkit.models.phong`, :mod:`~brdfkit.models.blinn`,
:mod:`~brdfkit.models.lafortune` and :mod:`~brdfkit.models.grazing` share,
and their common base class.

Public objects (re-exported by :mod:`brdfkit.models.phong`)
-----------------------------------------------------------
- :func:`lobe_pow` — max(0, x)ⁿ with 0⁰ = 1, binary exponentiation for integral n.
- :data:`COS_DIVISOR_FLOOR` — floor of a cosine that divides.
- :class:`CosineLobeBRDF` — base of the cosⁿ-lobe models: strategy-sampled
  (:mod:`brdfkit.models.sampling`), ``beta`` converts by cosⁿβ = 1/2.

References
----------
- [Lewis1993] R. R. Lewis, *Making Shaders More Physically Plausible*, 1993:
  §3.1 (the half-angle β of a cosⁿ lobe).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from brdfkit.halfangle import beta_from_exponent, exponent_from_beta
from brdfkit.models._base import BRDF, Lobe, Param
from brdfkit.models._params import DIFFUSE_PART
from brdfkit.models.sampling import COSINE, Mixture, StrategySampled, blinn_lobe, normalised_weights
from brdfkit.models.specular import blinn_normal_albedo

__all__ = ["COS_DIVISOR_FLOOR", "CosineLobeBRDF", "lobe_pow"]

RHO_D = DIFFUSE_PART  # ρ_d of the diffuse part beside a lobe (models/_params.py)
RHO_S = Param("rho_s", 0.5, 0.0, 1.0, "",
              "specular reflectance (albedo of the normalised lobe at normal incidence)",
              kind="colour")
N_EXP = Param("n", 20.0, 0.0, 1e6, "",
              "specular exponent (lobe sharpness); ~1-10 rough, 100-1000 glossy, >1e4 mirror")
K_D = Param("k_d", 0.1, 0.0, 1.0, "1/sr",
            "diffuse BRDF constant (albedo k_d*pi; <= 1/pi conserves energy; Lewis's "
            "figures use k_d = 1 - k_s)", kind="colour")
K_S = Param("k_s", 1.0, 0.0, 1e6, "1/sr",
            "specular coefficient (unnormalised; (n+2)/2pi gives unit normal-incidence "
            "albedo for the R.V lobe)", kind="colour")


# Floor of a cosine that divides (1/(N·L) in phong and blinn, 1/max(N·L, N·V) in
# neumann-phong). The true value overflows float64 when the cosine is subnormal; with the
# floor f ≤ k_s·1e300 ≤ 1e306 (k_s ≤ 1e6) and ≤ c_n·1e300 ≤ 1e307 (c_n ≤ 1e7): finite for
# every accepted parameter. Cost: f is too small by the factor cos/1e-300 only for cosines
# below 1e-300 (θ within 1e-300 rad of 90°), where float64 cannot represent it anyway.
COS_DIVISOR_FLOOR = 1e-300


# --------------------------------------------------------------------------- kernel helper
@numba.njit(cache=True, inline="always")
def lobe_pow(x: float, n: float) -> float:
    """max(0, x)ⁿ with 0⁰ = 1 (as :func:`brdfkit._kern.pos_pow`), faster for integral n.

    Integral exponents below 1024 (the usual Phong exponents) use binary
    exponentiation — ≤ 20 multiplications, ~4x faster than ``pow`` and within
    ~n·1e-16 relative of it; other exponents call ``pow``. The branch depends
    on the parameters only, so it is perfectly predicted inside a batch.
    """
    if x <= 0.0:
        return 1.0 if n == 0.0 else 0.0
    if n < 1024.0 and n == math.floor(n):
        k = int(n)
        r = 1.0
        b = x
        while k:
            if k & 1:
                r *= b
            b *= b
            k >>= 1
        return r
    return x**n


def lobe_hint(kind: str, n: float) -> Lobe:
    """Lobe hint of a cosⁿ lobe: half-angle β with cosⁿβ = 1/2 (n = 0: constant, diffuse)."""
    if n <= 0.0:
        return Lobe("diffuse", math.pi / 2)
    return Lobe(kind, float(beta_from_exponent(n)))


def channel_mean(x) -> float:
    """The mean over channels of a (per-channel) parameter value: what mixture weights use."""
    return float(np.mean(x))


class CosineLobeBRDF(StrategySampled, BRDF):
    """Base of the cosⁿ-lobe models: sampled by ``_strategy(wo)`` (see
    :class:`~brdfkit.models.sampling.StrategySampled`); the width parameter is the
    exponent, converted from a half-angle ``beta`` by cosⁿβ = 1/2."""

    @classmethod
    def width_from_beta(cls, beta: float) -> float:
        """Exponent with cosⁿβ = 1/2 (Lewis §3.1): ``n``, or ``s`` in ``nielsen``."""
        return float(exponent_from_beta(beta))


class KdKsBlinnBRDF(CosineLobeBRDF):
    """Base of the k_d + k_s (N·H)ⁿ models (``blinn``, ``phong-blinn-reciprocal``): their
    lobes (a diffuse one where k_d > 0 and the N·H lobe) and their sampler, the cosine and
    the N·H lobe mixed in proportion to their normal-incidence albedos πk_d and
    k_s ∫(N·H)ⁿ cos θ_o dω_o (:func:`blinn_normal_albedo`)."""

    def lobes(self):
        out = [Lobe("diffuse", math.pi / 2)] if np.any(self._values["k_d"]) else []
        return out + [lobe_hint("half", self._values["n"])]

    def _strategy(self, wo):
        v = self._values
        n = v["n"]
        w = normalised_weights([math.pi * channel_mean(v["k_d"]),
                                channel_mean(v["k_s"]) * blinn_normal_albedo(n)])
        return Mixture([COSINE, blinn_lobe(n)], w)
