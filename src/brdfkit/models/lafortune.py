"""
Lafortune's generalised cosine lobes
====================================

A sum of lobes max(0, C_xy (ix·ox + iy·oy) + C_z iz·oz)ⁿ (Lafortune et al.
1997, Neumann et al. eq. 7): off-specular, retro-reflective and
normal-centred lobes in one reciprocal form. Sampled by a mixture of the
cosine and, per lobe, the cosⁿ lobe about its own axis
(:class:`brdfkit.models.sampling.CosPowerAxis`) with weights per ω_o. Its formulas
(the Mitsuba bridge's traced route) are generated for the instance's number of lobes
(:mod:`brdfkit.models.lobe_series`).

Public objects
--------------
- :class:`Lafortune` — ``lafortune``: Neumann eq. (7), Lafortune et al. 1997.

References
----------
- [Lafortune1997] E. P. F. Lafortune, S.-C. Foo, K. E. Torrance,
  D. P. Greenberg, *Non-Linear Approximation of Reflectance Functions*,
  SIGGRAPH 1997.
- [Neumann1999] L. Neumann, A. Neumann, L. Szirmay-Kalos, *Reflectance Models
  by Pumping up the Albedo Function*, 1999: eq. (7).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from brdfkit._array import stack
from brdfkit._dual import Formulas
from brdfkit._kern import INV_PI, below_horizon
from brdfkit.errors import ParameterError
from brdfkit.models._base import Lobe, Param
from brdfkit.models._drivers import loop_driver
from brdfkit.models._lobes import RHO_D, CosineLobeBRDF, channel_mean, lobe_hint, lobe_pow
from brdfkit.models._registry import register
from brdfkit.models.lobe_series import lafortune_formulas, series_eval
from brdfkit.models.sampling import COSINE, Mixture, log_mixture_weights, phong_lobe

__all__ = ["Lafortune"]


# --------------------------------------------------------------------------- Lafortune
@numba.njit(cache=True)
def _lafortune(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    rho_d, rho_s = p[0], p[1]
    m = int(p[2])
    xy = ix * ox + iy * oy
    zz = iz * oz
    acc = 0.0
    for j in range(m):
        base = p[3 + j] * xy + p[3 + m + j] * zz
        # clamp at 0 (lobe_pow): a negative base is a lobe pointing away from wo; its
        # non-integer power is undefined and a negative lobe would be unphysical
        acc += lobe_pow(base, p[3 + 2 * m + j])
    return rho_d * INV_PI + rho_s * acc


def _lafortune_axis(c_xy: float, c_z: float):
    def axis(wo):
        a = stack(c_xy * wo[..., 0], c_xy * wo[..., 1], c_z * wo[..., 2])
        norm = np.linalg.norm(a, axis=-1, keepdims=True)
        up = np.broadcast_to(np.array([0.0, 0.0, 1.0]), a.shape)
        # zero axis (C_xy = C_z = 0): the lobe vanishes and gets weight 0; any axis will do
        return np.where(norm > 0.0, a / np.where(norm > 0.0, norm, 1.0), up)
    return axis


@register
class Lafortune(CosineLobeBRDF):
    """Lafortune et al. 1997 generalised cosine lobes; Neumann et al. eq. (7).

    f_r = ρ_d/π + ρ_s Σ_j max(0, C_xy,j (ix·ox + iy·oy) + C_z,j iz·oz)^{n_j}
    (isotropic: C_x = C_y = C_xy). With R = (−ix, −iy, iz) the mirror of wi,
    Neumann's form c_Lafortune (R_x V_x + R_y V_y + s R_z V_z)ⁿ is one lobe with
    C_xy = −c, C_z = c·s and c_Lafortune = cⁿ (the constant moves inside the
    power). C_xy = −1, C_z = 1 is the Phong lobe (R·V)ⁿ; C_xy = −C_z·k with
    k > 1 (|C_z| < |C_xy|) pushes the lobe toward grazing (Neumann's s < 1:
    "emphasis to grazing angles"); C_xy > 0 gives retro-reflection; C_xy = 0 a
    lobe about the normal. The base is clamped at 0 (see the kernel).

    ======  =======  ============  ===========================================
    name    default  bounds        meaning
    ======  =======  ============  ===========================================
    rho_d   0.2      [0, 1]        diffuse albedo (per channel)
    rho_s   1        [0, 1e6]      scale of the lobe sum (per channel)
    C_xy    −1       [−100, 100]   tangential coefficient of each lobe
    C_z     1        [−100, 100]   normal coefficient of each lobe
    n       20       [0, 1e6]      exponent of each lobe; or ``beta`` (sets
                                   every lobe's exponent)
    ======  =======  ============  ===========================================

    ``C_xy``, ``C_z`` and ``n`` may be sequences (one value per lobe, equal
    lengths; scalars broadcast). The lobe's peak is max(|C_xy|, |C_z|)ⁿ, which
    must stay finite (checked). Reciprocal (the form is symmetric in wi, wo).
    A fit (:func:`brdfkit.fitting.fit`) holds the first lobe's C_z at its given
    value (a gauge: its scale against ρ_s is not determined; ``fit_gauge``).
    Sampled as a mixture of cosine and, per lobe, the cosⁿ lobe about the unit
    axis along (C_xy ox, C_xy oy, C_z oz) — exact in shape, since the base is
    wi·(C_xy ox, C_xy oy, C_z oz) — weighted by its integral.
    """

    name = "lafortune"
    aliases = ("lafortune-1997", "generalized-cosine-lobe")
    summary = "Lafortune et al. 1997 generalised cosine lobes (Neumann eq. 7)"
    params = (
        RHO_D,
        Param("rho_s", 1.0, 0.0, 1e6, "", "scale of the lobe sum", kind="colour"),
        Param("C_xy", -1.0, -100.0, 100.0, "", "tangential coefficient (-1: mirror lobe)",
              kind="lobes"),
        Param("C_z", 1.0, -100.0, 100.0, "", "normal coefficient (1: mirror lobe)",
              kind="lobes"),
        Param("n", 20.0, 0.0, 1e6, "", "exponent of each lobe", kind="lobes"),
    )
    citation = "Lafortune et al. 1997; Neumann et al. 1999 eq. (7)"
    reciprocal = True
    width_param = "n"
    kernel = _lafortune
    # (C_xy, C_z) → t·(C_xy, C_z), ρ_s → ρ_s / tⁿ leaves the first lobe and the others
    # unchanged: a fit holds C_z of the first lobe (at its given value, default 1: the
    # scale goes into ρ_s, the direction into C_xy / C_z)
    fit_gauge = ("C_z[0]",)
    examples = (
        {"C_xy": [-1.0, -0.9], "C_z": [1.0, 0.7], "n": [20.0, 5.0]},
        {"rho_d": 0.0, "C_xy": -1.0, "C_z": 1.0, "n": 10000.0},
        {"rho_d": [0.1, 0.2, 0.3], "rho_s": [1.0, 0.8, 0.6], "C_xy": [-1.0, 0.5],
         "C_z": [0.95, 0.5], "n": [30.0, 2.0]},
    )

    def _validate(self):
        v = self.channel_values(0)
        big = np.maximum(np.abs(v["C_xy"]), np.abs(v["C_z"]))
        with np.errstate(divide="ignore"):
            log_peak = v["n"] * np.log(big)
        bad = np.flatnonzero(log_peak > 690.0)  # e^690 ≈ 1e300: the lobe's peak value
        if bad.size:
            j = int(bad[0])
            raise ParameterError(
                f"{self.name}: lobe {j} has peak max(|C_xy|, |C_z|)^n = "
                f"{big[j]:g}^{v['n'][j]:g}, beyond 1e300; reduce C_xy, C_z or n"
            )
        # model.eval runs the formula unrolled for this instance's number of lobes in the
        # vectorising loop: bit-identical to the kernel's loop over the lobes, which LLVM
        # cannot vectorise (measured: 1.4-2x the M evals/s of the kernel's checked loop)
        self._driver = loop_driver(series_eval("lafortune", self.channel_values(0)["n"]),
                                   loop="vector")

    def _pack_channel(self, v):
        # ρ_d, ρ_s in their parameters' slots (the Mitsuba bridge exposes them by slot),
        # then the number of lobes and the lobes
        row = [float(v["rho_d"]), float(v["rho_s"]), float(self.n_lobes())]
        for name in ("C_xy", "C_z", "n"):
            row.extend(np.asarray(v[name], dtype=np.float64).tolist())
        return row

    def lobes(self):
        v = self.channel_values(0)
        out = [Lobe("diffuse", math.pi / 2)] if np.any(self._values["rho_d"]) else []
        for c_xy, n in zip(v["C_xy"], v["n"], strict=True):
            # C_xy < 0: about the (off-)specular direction; 0: about the normal; > 0: retro
            kind = "mirror" if c_xy < 0.0 else ("normal" if c_xy == 0.0 else "diffuse")
            lb = lobe_hint(kind, float(n))
            out.append(lb if kind != "diffuse" else Lobe("diffuse", lb.width))
        return out

    def formulas(self) -> Formulas:
        """f_r, the sampler of :meth:`_strategy` and its pdf as formulas unrolled for this
        instance's number of lobes (:mod:`brdfkit.models.lobe_series`)."""
        return lafortune_formulas(self)

    def _strategy(self, wo):
        v = self.channel_values(0)
        comps = [COSINE]
        logw = [np.full(wo.shape[:-1], math.log(channel_mean(self._values["rho_d"]))
                        if channel_mean(self._values["rho_d"]) > 0.0 else -np.inf)]
        rho_s = channel_mean(self._values["rho_s"])
        log_s = math.log(rho_s) if rho_s > 0.0 else -np.inf
        for c_xy, c_z, n in zip(v["C_xy"], v["C_z"], v["n"], strict=True):
            comps.append(phong_lobe(float(n), _lafortune_axis(float(c_xy), float(c_z))))
            if n == 0.0:  # constant lobe over the hemisphere: ∫ 1 cos θ_i dω = π
                logw.append(np.full(wo.shape[:-1], log_s + math.log(math.pi)))
                continue
            size = np.sqrt((c_xy * c_xy) * (wo[..., 0] ** 2 + wo[..., 1] ** 2)
                           + (c_z * wo[..., 2]) ** 2)
            with np.errstate(divide="ignore"):
                # ∫ (wi·a)₊ⁿ dω = |a|ⁿ 2π/(n+1), in logs (|a|ⁿ may overflow or underflow)
                logw.append(log_s + n * np.log(size) + math.log(2.0 * math.pi / (n + 1.0)))
        # nothing reflects (every weight 0): the cosine
        return Mixture(comps, log_mixture_weights(logw))
