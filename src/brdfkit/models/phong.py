"""
Phong and Blinn shaders as BRDFs
================================

The normalised reciprocal Phong model and Lewis's shaders: the original Phong
(R·V) and Blinn (N·H) shaders made BRDFs by eq. (8), and the energy-conserving
shader of eq. (22). Every kernel is written over the dot products of the local
frame (N·L = ``iz``, N·V = ``oz``, R·V, N·H; see :mod:`brdfkit._kern`).

The rest of the Phong family lives next door: reciprocal N·H lobes in
:mod:`~brdfkit.models.blinn`, Lafortune's lobes in
:mod:`~brdfkit.models.lafortune`, the grazing-angle variants of Neumann et al.
and Nielsen et al. in :mod:`~brdfkit.models.grazing`; H_s in
:mod:`~brdfkit.models.specular`; sampling strategies in
:mod:`~brdfkit.models.sampling`.

Public objects
--------------
- :class:`ModifiedPhong` — ``modified-phong``, Nielsen eq. (1).
- :class:`Phong` — ``phong``: Lewis eqs. (5) and (8), the original shader as a BRDF.
- :class:`Blinn` — ``blinn``: Lewis eqs. (6) and (8).
- :class:`PhongEnergyConserving` — ``phong-energy-conserving``: Lewis eq. (22).

Re-exported from the modules they live in (``from brdfkit.models.phong import X``
keeps working): :func:`~brdfkit.models.specular.specular_integral`,
:func:`~brdfkit.models.specular.blinn_normal_albedo`,
:func:`~brdfkit.models._lobes.lobe_pow`,
:func:`~brdfkit.models.sampling.sample_phong_lobe`,
:func:`~brdfkit.models.sampling.pdf_phong_lobe`,
:func:`~brdfkit.models.sampling.sample_blinn_lobe`,
:func:`~brdfkit.models.sampling.pdf_blinn_lobe`,
:func:`~brdfkit.models.sampling.diffuse_fraction`,
:func:`~brdfkit.models.sampling.split_uniform`; and, on first access, the
model classes that moved (:class:`~brdfkit.models.blinn.PhongBlinnReciprocal`,
:class:`~brdfkit.models.blinn.NHPowerSeries`,
:class:`~brdfkit.models.blinn.ModifiedBlinnPhong`,
:class:`~brdfkit.models.lafortune.Lafortune`,
:class:`~brdfkit.models.grazing.NeumannPhong`,
:class:`~brdfkit.models.grazing.Nielsen`).

References
----------
- [Lewis1993] R. R. Lewis, *Making Shaders More Physically Plausible*, 1993:
  eqs. (5), (6), (8), (16), (19), (22).
- [Neumann1999] L. Neumann, A. Neumann, L. Szirmay-Kalos, *Reflectance Models
  by Pumping up the Albedo Function*, 1999: eq. (6).
- [Nielsen2015] J. B. Nielsen, J. R. Frisvad, K. Conradsen, H. Aanæs,
  *Addressing Grazing Angle Reflections in Phong Models*: eq. (1).
"""

from __future__ import annotations

import importlib
import math

import numba
import numpy as np

from brdfkit._cache import memo
from brdfkit._dual import Formulas, formula, maximum, power, select, sqrt
from brdfkit._kern import INV_PI, INV_TWO_PI, below_horizon, n_dot_h, r_dot_v
from brdfkit.halfangle import beta_from_exponent
from brdfkit.models._base import VECTOR_OPTIONS, Lobe, Param
from brdfkit.models._lobes import (
    COS_DIVISOR_FLOOR,
    K_D,
    K_S,
    LOBE_AUTO,
    LOBE_INTEGRAL,
    N_EXP,
    RHO_D,
    RHO_S,
    UP,
    CosineLobeBRDF,
    KdKsBlinnBRDF,
    KdKsLobeBRDF,
    channel_mean,
    lobe_hint,
    lobe_pow,
    lobe_power,
    lobe_sampler_args,
    nh_dot,
    rv_dot,
)
from brdfkit.models._params import packed_indices
from brdfkit.models._registry import register
from brdfkit.models.sampling import (
    COSINE,
    Mixture,
    blinn_lobe,
    diffuse_fraction,
    lobes_pdf,
    lobes_sample,
    normalised_weights,
    pdf_blinn_lobe,
    pdf_phong_lobe,
    phong_lobe,
    sample_blinn_lobe,
    sample_phong_lobe,
    split_uniform,
)
from brdfkit.models.specular import blinn_normal_albedo, specular_integral
from brdfkit.tables import Lookup, _lookup, build_lookup, lookup

__all__ = [
    "ModifiedPhong", "Phong", "Blinn", "PhongEnergyConserving",
    # re-exported (see the module docstring)
    "specular_integral", "blinn_normal_albedo", "lobe_pow", "sample_phong_lobe",
    "pdf_phong_lobe", "sample_blinn_lobe", "pdf_blinn_lobe", "diffuse_fraction",
    "split_uniform", "COS_DIVISOR_FLOOR",
]

# Model classes that moved to the other Phong-family modules: importable from here on first
# access (PEP 562), without importing those modules here (that would register their models
# before this module's and change the registry order).
_MOVED = {"PhongBlinnReciprocal": "blinn", "NHPowerSeries": "blinn",
          "ModifiedBlinnPhong": "blinn", "Lafortune": "lafortune",
          "NeumannPhong": "grazing", "Nielsen": "grazing"}


def __getattr__(name: str):
    if name in _MOVED:
        return getattr(importlib.import_module(f"brdfkit.models.{_MOVED[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


#: Relative tolerance of the H_s lookup (``phong-energy-conserving``'s kernel divides by
#: it): measured ≤ 2.6e-9 including the margin for n ∈ [0.5, 1e6], both lobes.
HS_LOOKUP_TOL = 1e-9


# 64 (n, lobe) pairs: a fit or a figure series revisits a few exponents; each lookup is a
# few thousand nodes (tens of kB) and costs 0.1-5 s to build
@memo(maxsize=64)
def _hs_table(n: float, lobe: str) -> Lookup:
    """H_s(θ_i) of *lobe* and *n* as the shared compiled lookup in μ = cos θ_i.

    An upper bound (so F_s/H_s never gains energy: the albedo is ≤ k_ρ to rounding)
    within 2.6e-9 relative (measured against :func:`specular_integral` for n = 0.5 …
    1e6, both lobes; the former table, cubic Lagrange in the grid variable w of
    :mod:`brdfkit.tables` at 512–4096 nodes, was within 7e-9 and 10–20 % slower to read).
    Built in 0.1–0.4 s for most n; the Phong lobe at n < 2 takes longer (~1 s at n = 1,
    ~5 s at n = 0.5: H_s has a term in θ_i^{n+2}, not smooth in μ at the normal, and the
    lookup refines uniformly in its last cell) and so does n ~ 1e6 (~1 s: the lobe meets
    the horizon within ~1e-3 of grazing).
    """
    # clamp: the lookup's last node may exceed μ = 1 by rounding (arccos would be NaN)
    return build_lookup(
        lambda mu: specular_integral(np.arccos(np.clip(mu, 0.0, 1.0)), n, lobe)[:, None],
        tol=HS_LOOKUP_TOL, bound="upper")


# --------------------------------------------------------------------------- modified Phong
MODIFIED_PHONG_PARAMS = (RHO_D, RHO_S, N_EXP)
P_RHO_D, P_RHO_S, P_N = packed_indices(MODIFIED_PHONG_PARAMS, "rho_d", "rho_s", "n")


@formula
def modified_phong(ix, iy, iz, ox, oy, oz, p, mode):
    """Nielsen eq. (1), a formula (:mod:`brdfkit._dual`): branch-free, 0 at and below the
    horizon; *mode* the compile-time :func:`~brdfkit.models._lobes.lobe_power` mode."""
    rho_d, rho_s, n = p[P_RHO_D], p[P_RHO_S], p[P_N]
    cos_r = rv_dot(ix, iy, iz, ox, oy, oz)  # ω_r·ω_o
    f = rho_d * INV_PI + rho_s * (n + 2.0) * INV_TWO_PI * lobe_power(cos_r, n, mode)
    return select((iz > 0.0) & (oz > 0.0), f, 0.0)


@formula(**VECTOR_OPTIONS)
def _modified_phong(ix, iy, iz, ox, oy, oz, p):
    return modified_phong(ix, iy, iz, ox, oy, oz, p, LOBE_AUTO)


@formula(**VECTOR_OPTIONS)
def _modified_phong_int(ix, iy, iz, ox, oy, oz, p):
    return modified_phong(ix, iy, iz, ox, oy, oz, p, LOBE_INTEGRAL)


@register
class ModifiedPhong(CosineLobeBRDF):
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
    params = MODIFIED_PHONG_PARAMS
    citation = "Nielsen et al. eq. (1); Neumann et al. 1999 eq. (6)"
    reciprocal = True
    has_sampler = True
    width_param = "n"
    kernel = _modified_phong
    lobe_kernels = (_modified_phong, _modified_phong_int)
    lobe_layout = ("cosine", "phong")
    examples = (
        {},
        {"rho_d": 0.0, "rho_s": 1.0, "n": 5000.0},
        {"rho_d": [0.1, 0.2, 0.3], "rho_s": [0.5, 0.4, 0.3], "n": 2.0},
    )

    def lobes(self):
        n = self._values["n"]
        out = [Lobe("diffuse", math.pi / 2)] if np.any(self._values["rho_d"]) else []
        return out + [Lobe("mirror", float(beta_from_exponent(n)) if n > 0 else math.pi / 2)]

    def _strategy(self, wo):
        v = self._values
        p_d = diffuse_fraction(v["rho_d"], v["rho_s"])
        return Mixture([COSINE, phong_lobe(v["n"])], np.array([p_d, 1.0 - p_d]))


# --------------------------------------------------------------------------- Lewis: Phong, Blinn
LEWIS_PARAMS = (K_D, K_S, N_EXP)
P_K_D, P_K_S, P_K_N = packed_indices(LEWIS_PARAMS, "k_d", "k_s", "n")


@formula
def lewis(ix, iy, iz, ox, oy, oz, p, mode, half):
    """Lewis eq. (8) with F_s^P of eq. (5) (R·V) or, *half*, F_s^B of eq. (6) (N·H), a
    formula; 0 at and below the horizon. The true f diverges like 1/(N·L) and overflows
    float64 for N·L < k_s/1.8e308; N·L is floored at COS_DIVISOR_FLOOR (see there)."""
    k_d, k_s, n = p[P_K_D], p[P_K_S], p[P_K_N]
    if half:
        c, _ = nh_dot(ix, iy, iz, ox, oy, oz)
    else:
        c = rv_dot(ix, iy, iz, ox, oy, oz)
    f = k_d + k_s * lobe_power(c, n, mode) / maximum(iz, COS_DIVISOR_FLOOR)
    return select((iz > 0.0) & (oz > 0.0), f, 0.0)


@formula(**VECTOR_OPTIONS)
def _phong(ix, iy, iz, ox, oy, oz, p):
    return lewis(ix, iy, iz, ox, oy, oz, p, LOBE_AUTO, False)


@formula(**VECTOR_OPTIONS)
def _phong_int(ix, iy, iz, ox, oy, oz, p):
    return lewis(ix, iy, iz, ox, oy, oz, p, LOBE_INTEGRAL, False)


@formula(**VECTOR_OPTIONS)
def _blinn(ix, iy, iz, ox, oy, oz, p):
    return lewis(ix, iy, iz, ox, oy, oz, p, LOBE_AUTO, True)


@formula(**VECTOR_OPTIONS)
def _blinn_int(ix, iy, iz, ox, oy, oz, p):
    return lewis(ix, iy, iz, ox, oy, oz, p, LOBE_INTEGRAL, True)


@register
class Phong(KdKsLobeBRDF):
    """The original Phong shader as a BRDF: Lewis eqs. (5) and (8).

    f_r(S, V) = k_d + k_s F_s^P(S, V)/(N·S), F_s^P = max(0, R_l·V)ⁿ with
    R_l = 2N(N·S) − S. Eq. (8) is what makes the shader L_r = [k_d (N·S) + k_s
    F_s] L_d (eq. 4) a BRDF. Its albedo is k_ρ = k_d π + k_s H_s(S)/(N·S)
    (Lewis eq. 19), which diverges as θ_i → 90° (H_s stays positive): the
    shader does not conserve energy for any k_s > 0 (Lewis §4.1).

    ======  =======  ===========  =============================================
    name    default  bounds       meaning
    ======  =======  ===========  =============================================
    k_d     0.1      [0, 1]       diffuse BRDF constant, 1/sr (per channel);
                                  albedo k_d π, so ≤ 1/π conserves energy
                                  (Lewis's figures use k_d = 1 − k_s)
    k_s     1        [0, 1e6]     specular coefficient, 1/sr (per channel)
    n       20       [0, 1e6]     Phong exponent n_s^P; or give ``beta``
                                  (cosⁿβ = 1/2, Lewis §3.1)
    ======  =======  ===========  =============================================

    Not reciprocal (the 1/(N·S) factor; Lewis §5.1). Sampled as a mixture of
    cosine (k_d) and the cosⁿ lobe about the mirror of wo: f cos θ_i = k_d cos θ_i
    + k_s (R_l·V)ⁿ, so the cosine of the division cancels and the lobe is
    sampled exactly.
    """

    name = "phong"
    aliases = ("phong-original", "lewis-phong")
    summary = "original Phong shader as a BRDF, k_d + k_s (R.V)^n / (N.L) (not reciprocal)"
    params = LEWIS_PARAMS
    citation = "Lewis 1993 eqs. (5) and (8)"
    reciprocal = False
    width_param = "n"
    kernel = _phong
    lobe_kernels = (_phong, _phong_int)
    lobe_layout = ("cosine", "phong")
    examples = (
        {},
        {"k_d": 0.0, "k_s": 800.0, "n": 5000.0},
        {"k_d": [0.05, 0.1, 0.15], "k_s": [1.0, 0.5, 0.25], "n": 3.0},
    )

    lobe_kind = "mirror"


@register
class Blinn(KdKsBlinnBRDF):
    """The Blinn shader as a BRDF: Lewis eqs. (6) and (8).

    f_r(S, V) = k_d + k_s (N·H)ⁿ/(N·S), H = (S + V)/|S + V|. Although F_s^B
    is symmetric, the 1/(N·S) makes the BRDF non-reciprocal (Lewis §5.1,
    footnote 9) and its albedo k_d π + k_s H_s(S)/(N·S) (eq. 19) diverges at
    grazing incidence.

    ======  =======  ===========  =============================================
    name    default  bounds       meaning
    ======  =======  ===========  =============================================
    k_d     0.1      [0, 1]       diffuse BRDF constant, 1/sr (per channel)
    k_s     1        [0, 1e6]     specular coefficient, 1/sr (per channel)
    n       20       [0, 1e6]     Blinn exponent n_s^B; or ``beta``
                                  (n = −ln 2/ln cos β, Lewis §3.1)
    ======  =======  ===========  =============================================

    Not reciprocal. Sampled as a mixture of cosine and the Blinn lobe: h with
    density (n+1)/(2π) cosⁿθ_h, wi the mirror of wo about h, pdf
    p_h/(4|wo·h|); f cos θ_i = k_d cos θ_i + k_s (N·H)ⁿ.
    """

    name = "blinn"
    aliases = ("blinn-original", "lewis-blinn")
    summary = "Blinn shader as a BRDF, k_d + k_s (N.H)^n / (N.L) (not reciprocal)"
    params = LEWIS_PARAMS
    citation = "Lewis 1993 eqs. (6) and (8)"
    reciprocal = False
    width_param = "n"
    kernel = _blinn
    lobe_kernels = (_blinn, _blinn_int)
    lobe_layout = ("cosine", "blinn")
    examples = (
        {},
        {"k_d": 0.0, "k_s": 400.0, "n": 10000.0},
        {"k_d": [0.05, 0.1, 0.15], "k_s": [1.0, 0.5, 0.25], "n": 3.0},
    )


# --------------------------------------------------------------------------- Lewis eq. (22)
PHONG_LOBE, BLINN_LOBE = 0, 1
ENERGY_CONSERVING_PARAMS = (
    Param("k_rho", 0.8, 0.0, 1.0, "",
          "directional-hemispherical reflectance: the albedo at every incident angle",
          kind="colour"),
    Param("k_sigma", 0.5, 0.0, 1.0, "", "fraction of the exitance reflected specularly",
          kind="colour"),
    N_EXP,
    Param("lobe", "blinn", kind="choice", choices=("phong", "blinn"),
          doc="specular function: phong (R.V)^n, Lewis eq. 5; blinn (N.H)^n, eq. 6"),
)
P_K_RHO, P_K_SIGMA, P_EC_N, P_LOBE = packed_indices(
    ENERGY_CONSERVING_PARAMS, "k_rho", "k_sigma", "n", "lobe")
#: where the H_s lookup starts: after the default row (PhongEnergyConserving._pack_channel)
P_HS_TABLE = len(ENERGY_CONSERVING_PARAMS)


@numba.njit(cache=True)
def _phong_energy_conserving(ix, iy, iz, ox, oy, oz, p):
    if below_horizon(iz, oz):
        return 0.0
    k_rho, k_sigma, n = p[P_K_RHO], p[P_K_SIGMA], p[P_EC_N]
    if p[P_LOBE] == PHONG_LOBE:
        fs = lobe_pow(r_dot_v(ix, iy, iz, ox, oy, oz), n)
    else:
        fs = lobe_pow(n_dot_h(ix, iy, iz, ox, oy, oz), n)
    hs = _lookup(p, P_HS_TABLE, iz)  # H_s(S) > 0 at every θ_i, also at 90° (see _hs_table)
    return k_rho * ((1.0 - k_sigma) * INV_PI + k_sigma * fs / hs)


@register
class PhongEnergyConserving(CosineLobeBRDF):
    """Lewis's energy-conserving Phong shader, eq. (22).

    f_r(S, V) = k_ρ [(1 − k_σ)/π + k_σ F_s(S, V)/H_s(S)], with F_s Phong's
    max(0, R_l·V)ⁿ (eq. 5) or Blinn's (N·H)ⁿ (eq. 6) and
    H_s(S) = ∫ F_s(S, V') (N·V') dω' (the integral of Lewis eq. 17).
    Dividing by H_s makes the albedo exactly k_ρ at every incident angle —
    the model's defining property (eqs. 20–22 solve eq. 19 for k_d and k_s).

    H_s depends on θ_i and n only. It is computed once per (n, lobe) by
    quadrature in the lobe frame (:func:`specular_integral`, relative accuracy
    ~1e-11) and stored as the shared compiled lookup of :mod:`brdfkit.tables`
    (local cubics in cos θ_i, an upper bound within 2.6e-9 relative for
    n ≤ 1e6; see ``_hs_table``). At θ_i = 90° H_s is positive (e.g. B((n+1)/2, 3/2)
    for Phong), so the kernel is finite there.

    =======  =======  ============  ===========================================
    name     default  bounds        meaning
    =======  =======  ============  ===========================================
    k_rho    0.8      [0, 1]        directional-hemispherical reflectance k_ρ,
                                    the albedo at every θ_i (per channel)
    k_sigma  0.5      [0, 1]        specular fraction k_σ of the exitance
                                    (per channel)
    n        20       [0, 1e6]      exponent of F_s; or ``beta``
    lobe     blinn    phong/blinn   F_s^P (eq. 5) or F_s^B (eq. 6; Lewis's
                                    Fig. 6 uses Blinn)
    =======  =======  ============  ===========================================

    Not reciprocal: F_s(S,V)/H_s(S) ≠ F_s(V,S)/H_s(V) (Lewis §5.1). Sampled as
    a mixture of cosine (weight ∝ 1 − k_σ) and the lobe (Phong lobe about the
    mirror of wo, or the Blinn half-vector lobe).
    """

    name = "phong-energy-conserving"
    aliases = ("energy-conserving-phong", "lewis-energy-conserving")
    summary = "Lewis's energy-conserving Phong, k_rho[(1-k_sigma)/pi + k_sigma F_s/H_s(S)]"
    params = ENERGY_CONSERVING_PARAMS
    citation = "Lewis 1993 eq. (22) with (5)/(6) and H_s of eq. (17)"
    reciprocal = False
    width_param = "n"
    kernel = _phong_energy_conserving
    examples = (
        {},
        {"k_rho": 1.0, "k_sigma": 1.0, "n": 10000.0, "lobe": "phong"},
        {"k_rho": [0.9, 0.6, 0.3], "k_sigma": [0.2, 0.5, 0.8], "n": 5.0, "lobe": "phong"},
    )

    def _pack_channel(self, v):
        row = super()._pack_channel(v)
        return [*row, *_hs_table(float(v["n"]), v["lobe"]).packed(0).tolist()]

    def lobes(self):
        v = self._values
        out = [Lobe("diffuse", math.pi / 2)] if np.any(np.asarray(v["k_sigma"]) < 1.0) else []
        return out + [lobe_hint("mirror" if v["lobe"] == "phong" else "half", v["n"])]

    def specular_integral(self, theta_i) -> np.ndarray:
        """H_s(θ_i) of this model's lobe and exponent (see :func:`specular_integral`)."""
        return specular_integral(theta_i, self._values["n"], self._values["lobe"])

    def _weights(self) -> np.ndarray:
        """The mixture's weights (cosine, lobe): ∝ k_ρ(1 − k_σ) and k_ρ k_σ, channel means."""
        v = self._values
        k_rho, k_sigma = np.asarray(v["k_rho"]), np.asarray(v["k_sigma"])
        return normalised_weights([channel_mean(k_rho * (1.0 - k_sigma)),
                                   channel_mean(k_rho * k_sigma)])

    def _strategy(self, wo):
        v = self._values
        lobe = phong_lobe(v["n"]) if v["lobe"] == "phong" else blinn_lobe(v["n"])
        return Mixture([COSINE, lobe], self._weights())

    def formulas(self) -> Formulas:
        """The kernel as a formula (H_s read with :func:`brdfkit.tables.lookup`, the table
        from column :data:`P_HS_TABLE` on) and the sampler's mixture as formulas: the same
        directions and density as :meth:`sample`/:meth:`pdf` (``_strategy``: the mixture
        :func:`~brdfkit.models.sampling.lobes_sample` draws, as the other Phong models')."""
        blinn = self._values["lobe"] == "blinn"
        layout = ("cosine", "blinn" if blinn else "phong")
        return Formulas(eval=_pec_blinn if blinn else _pec_phong, sample=lobes_sample,
                        pdf=lobes_pdf, args=lobe_sampler_args(self._strategy(UP), layout),
                        tables=P_HS_TABLE)


# phong-energy-conserving's eval as a formula (brdfkit._dual); its sampler is lobes_sample
#: floor of |L + V| in N·H (a discarded lane's divisor: L = −V; a live lane has L_z + V_z > 0)
_LENGTH_FLOOR = 1e-30


@formula
def pec_eval(ix, iy, iz, ox, oy, oz, p, blinn):
    """Lewis eq. (22) over the packed row (k_ρ, k_σ, n, lobe, H_s lookup); *blinn* a
    compile-time flag (the kernel reads it from p[P_LOBE])."""
    k_rho, k_sigma, n = p[P_K_RHO], p[P_K_SIGMA], p[P_EC_N]
    if blinn:
        s = iz + oz
        hx = ix + ox
        hy = iy + oy
        c = s / maximum(sqrt(hx * hx + hy * hy + s * s), _LENGTH_FLOOR)  # N·H
    else:
        c = 2.0 * iz * oz - (ix * ox + iy * oy + iz * oz)  # R·V
    fs = power(maximum(c, 0.0), n)  # lobe_pow: max(0, x)^n, 0^0 = 1
    hs = lookup(p, P_HS_TABLE, iz)  # H_s(S) > 0 at every θ_i
    f = k_rho * ((1.0 - k_sigma) * INV_PI + k_sigma * fs / hs)
    return select((iz > 0.0) & (oz > 0.0), f, 0.0)  # 0 below the horizon


@formula
def _pec_phong(ix, iy, iz, ox, oy, oz, p):
    return pec_eval(ix, iy, iz, ox, oy, oz, p, False)


@formula
def _pec_blinn(ix, iy, iz, ox, oy, oz, p):
    return pec_eval(ix, iy, iz, ox, oy, oz, p, True)
