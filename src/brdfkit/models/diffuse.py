"""
Diffuse and separable models
============================

Public objects
--------------
- :class:`Lambert` — ``lambert``: ρ_d/π.
- :class:`NeumannNeumann` — ``neumann-neumann``: the lacquer model, Lewis §3.3.
- :class:`Minnaert` — ``minnaert``: Lewis §3.4.
- :class:`MinnaertEnergyConserving` — ``minnaert-energy-conserving``: Lewis §4.3.

Paper errors handled here (see :mod:`brdfkit.halfangle` and the tests):
Lewis's β → s conversion for Neumann–Neumann is negative (wrong); Lewis's
claim that any k_ρ ∈ [0, 1] makes the normalised Minnaert shader conserve
energy needs k ≥ 1.

References
----------
- [Lewis1993] §3.3 (Neumann–Neumann), §3.4 and §4.3 (Minnaert).
"""

from __future__ import annotations

import math

from brdfkit._dual import Formulas, exp, formula, maximum, power, select
from brdfkit._kern import INV_PI, INV_TWO_PI
from brdfkit.halfangle import (
    beta_from_minnaert_k,
    beta_from_neumann_s,
    minnaert_k_from_beta,
    neumann_s_from_beta,
)
from brdfkit.models._base import BRDF, VECTOR_OPTIONS, Lobe, Param
from brdfkit.models._drivers import loop_driver
from brdfkit.models._params import DIFFUSE_ALBEDO, packed_indices
from brdfkit.models._registry import register
from brdfkit.models.rough_diffuse import cosine_pdf, cosine_sample
from brdfkit.models.sampling import (
    CosPowerNormal,
    StrategySampled,
    cos_power_normal_pdf,
    cos_power_normal_sample,
)


class _Traced:
    """The vectorised loop of the class's formula kernel (``kernel``, a formula of
    :mod:`brdfkit._dual`) and its formulas for the Mitsuba bridge: the kernel, and the
    sampler of ``_formula_sampler`` (cosine by default)."""

    def _validate(self):
        super()._validate()
        self._driver = loop_driver(type(self).kernel, loop="vector")

    def _formula_sampler(self) -> tuple:
        return cosine_sample, cosine_pdf, ()

    def formulas(self) -> Formulas:
        sample, pdf, args = self._formula_sampler()
        return Formulas(eval=type(self).kernel, sample=sample, pdf=pdf, args=args)


class _CosPowerTraced(_Traced):
    """:class:`_Traced` sampled by ``CosPowerNormal(q)`` (``_cos_power_q``), as formulas;
    reciprocal (f depends on N·S and N·V symmetrically) and its width parameter from a
    half-angle β by the class's ``_width_of_beta`` (a :mod:`brdfkit.halfangle` function)."""

    reciprocal = True
    has_sampler = True

    @classmethod
    def width_from_beta(cls, beta: float) -> float:
        return cls._width_of_beta(beta)

    def _strategy(self, wo):
        return CosPowerNormal(self._cos_power_q())

    def _formula_sampler(self) -> tuple:
        return cos_power_normal_sample, cos_power_normal_pdf, (self._cos_power_q(),)

LAMBERT_PARAMS = (DIFFUSE_ALBEDO,)
(P_RHO_D,) = packed_indices(LAMBERT_PARAMS, "rho_d")


@formula(**VECTOR_OPTIONS)
def _lambert(ix, iy, iz, ox, oy, oz, p):
    """ρ_d/π above the horizon, 0 at and below it (a formula: :mod:`brdfkit._dual`)."""
    rho_d = p[P_RHO_D]
    return select((iz > 0.0) & (oz > 0.0), rho_d * INV_PI, 0.0)


@register
class Lambert(_Traced, BRDF):
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
    params = LAMBERT_PARAMS
    citation = "Lambert 1760; Lewis 1993 eq. (8) with k_s = 0 (k_d = rho_d/pi)"
    reciprocal = True
    has_sampler = True
    kernel = _lambert


# --------------------------------------------------------------------------- Neumann-Neumann
NEUMANN_NEUMANN_PARAMS = (
    Param("b_N", 0.25, 0.0, 10.0, "1/sr", "value at S = V = N", kind="colour"),
    Param("s", 0.5, 0.0, 1e7, "", "optical thickness of the lacquer; larger = narrower lobe"),
)
P_B_N, P_S = packed_indices(NEUMANN_NEUMANN_PARAMS, "b_N", "s")


@formula(**VECTOR_OPTIONS)
def _neumann_neumann(ix, iy, iz, ox, oy, oz, p):
    """b_N exp{−s(1/(N·S) + 1/(N·V) − 2)} (Lewis §3.3), 0 at and below the horizon; a
    formula (:mod:`brdfkit._dual`)."""
    b_n, s = p[P_B_N], p[P_S]
    live = (iz > 0.0) & (oz > 0.0)
    # 1/iz overflows to inf only for subnormal iz; exp(-inf) = 0 is then the right limit.
    lacquer = b_n * exp(-s * (1.0 / iz + 1.0 / oz - 2.0))
    # s = 0: the lacquer is clear, a Lambertian b_N (avoids 0 * inf above)
    return select(live, select(s == 0.0, b_n, lacquer), 0.0)


@register
class NeumannNeumann(_CosPowerTraced, StrategySampled, BRDF):
    """Neumann–Neumann "lacquer" model as written by Lewis §3.3.

    f_r(S, V) = b_N exp{−s (1/(N·S) + 1/(N·V) − 2)}: a diffuse base under an
    absorbing, non-scattering layer of optical thickness s; b_N is the value
    at S = V = N.

    ======  =======  ===========  ==============================================
    name    default  bounds       meaning
    ======  =======  ===========  ==============================================
    b_N     0.25     [0, 10] 1/sr value at S = V = N (per channel)
    s       0.5      [0, 1e7]     optical thickness; 0 is Lambertian b_N, large
                                  values concentrate the lobe about the normal.
                                  Or give ``beta``: s = ln2 cos β/(1 − cos β)
    ======  =======  ===========  ==============================================

    Albedo (closed form, substitute t = 1/cos θ_o):
    a(θ_i) = 2π b_N e^{2s − s/cos θ_i} E₃(s), with E₃ the exponential
    integral; it is largest at normal incidence, 2π b_N e^{s} E₃(s), so
    b_N ≤ 1/(2π e^{s} E₃(s)) conserves energy (Lewis §4.3 integrates this
    numerically, Fig. 8). Reciprocal (Lewis §5.3). The radiance always peaks
    at the normal (Lewis §3.3, Table 2).

    The β conversion printed by Lewis §3.3, s = −ln 2/(1 + cos β), is wrong
    (negative); see :func:`brdfkit.halfangle.neumann_s_from_beta`.

    Sampling: f cos θ_i ∝ μ e^{−s/μ} (μ = cos θ_i) has no invertible CDF, so
    wi is drawn from the density (s+2)/(2π) μ^{s+1} (inverse CDF
    μ = u₀^{1/(s+2)}), which dominates it: the weight f cos θ_i/pdf is
    proportional to exp{−s(1/μ − 1 + ln μ)} ≤ 1 (the exponent is ≥ 0 on
    (0, 1]), so the estimator's weights are bounded by their value at μ = 1.
    """

    name = "neumann-neumann"
    aliases = ("lacquer", "neumann-lacquer")
    summary = "Neumann-Neumann lacquer: b_N exp{-s(1/N.S + 1/N.V - 2)}"
    params = NEUMANN_NEUMANN_PARAMS
    citation = "Lewis 1993 §3.3 (after Neumann & Neumann 1989)"
    width_param = "s"
    kernel = _neumann_neumann
    _width_of_beta = staticmethod(neumann_s_from_beta)
    examples = (
        {},
        {"b_N": 1.0, "s": 50.0},
        {"b_N": [0.1, 0.2, 0.3], "s": 0.05},
    )


    def lobes(self):
        s = float(self._values["s"])
        return [Lobe("normal", beta_from_neumann_s(s) if s > 0.0 else math.pi / 2)]

    def _cos_power_q(self) -> float:
        return float(self._values["s"]) + 1.0


# --------------------------------------------------------------------------- Minnaert
# Minnaert's exponent k - 1 is negative for k < 1 and the lobe then diverges at
# the horizon. Flooring each cosine at COS_FLOOR keeps every factor
# cos^{k-1} <= COS_FLOOR^{-1} = 1e150 for all allowed k > 0, so the product of
# the two stays below 1e300 (finite), while changing f only within 1e-150 rad
# of the horizon -- the divergence of the albedo as theta_i -> 90 deg remains
# visible to the analysis.
COS_FLOOR = 1e-150


@formula
def _minnaert_core(iz, oz, k):
    """((N·S)(N·V))^{k−1} as two powers (no underflow of the product), 1 for k = 1."""
    e = k - 1.0
    lobe = power(maximum(iz, COS_FLOOR), e) * power(maximum(oz, COS_FLOOR), e)  # see COS_FLOOR
    return select(e == 0.0, 1.0, lobe)


K_MINNAERT = Param("k", 2.0, 0.0, 1e7, "",
                   "Minnaert exponent: 1 is Lambertian, > 1 peaks at the normal, < 1 brightens "
                   "toward the limb (the Moon: ~0.5-1)", lower_open=True)


MINNAERT_PARAMS = (
    Param("b_M", 0.2, 0.0, 10.0, "1/sr", "scale (value at S = V = N)", kind="colour"),
    K_MINNAERT,
)
P_B_M, P_K = packed_indices(MINNAERT_PARAMS, "b_M", "k")
MINNAERT_EC_PARAMS = (
    Param("k_rho", 0.8, 0.0, 1.0, "", "albedo at normal incidence", kind="colour"),
    K_MINNAERT,
)
P_K_RHO, P_EC_K = packed_indices(MINNAERT_EC_PARAMS, "k_rho", "k")


@formula(**VECTOR_OPTIONS)
def _minnaert(ix, iy, iz, ox, oy, oz, p):
    """b_M ((N·S)(N·V))^{k−1} (Lewis §3.4), 0 at and below the horizon; a formula."""
    b_m, k = p[P_B_M], p[P_K]
    return select((iz > 0.0) & (oz > 0.0), b_m * _minnaert_core(iz, oz, k), 0.0)


@formula(**VECTOR_OPTIONS)
def _minnaert_ec(ix, iy, iz, ox, oy, oz, p):
    """k_ρ (k+1)/(2π) ((N·S)(N·V))^{k−1} (Lewis §4.3), 0 at and below the horizon; a
    formula."""
    k_rho, k = p[P_K_RHO], p[P_EC_K]
    f = k_rho * (k + 1.0) * INV_TWO_PI * _minnaert_core(iz, oz, k)
    return select((iz > 0.0) & (oz > 0.0), f, 0.0)


def _minnaert_lobes(k: float) -> list:
    return [Lobe("normal", beta_from_minnaert_k(k) if k > 1.0 else math.pi / 2)]


@register
class Minnaert(_CosPowerTraced, StrategySampled, BRDF):
    """Minnaert's lunar shader as a BRDF (Lewis §3.4).

    f_r(S, V) = b_M ((N·S)(N·V))^{k−1}, from L_r = b_M (N·S)^k (N·V)^{k−1} L_i
    (Minnaert 1941).

    ======  =======  ============  =============================================
    name    default  bounds        meaning
    ======  =======  ============  =============================================
    b_M     0.2      [0, 10] 1/sr  scale (per channel)
    k       2        (0, 1e7]      exponent (Lewis's symbol). k = 1: Lambertian;
                                   k > 1: lobe about the normal, or give
                                   ``beta``: k = 1 − ln2/ln cos β;
                                   k < 1: grows toward the horizon
    ======  =======  ============  =============================================

    Albedo (closed form): a(θ_i) = 2π b_M cos^{k−1}θ_i/(k+1). For k ≥ 1 it is
    largest at normal incidence and b_M ≤ (k+1)/(2π) conserves energy; for
    k < 1 it diverges as θ_i → 90°, so no b_M > 0 conserves energy. k < 1
    is allowed (it is Minnaert's lunar regime) so that the analysis can
    show the divergence; the kernel floors the cosines at 1e-150 to stay
    finite. Reciprocal (Lewis §5.3). Sampled exactly: pdf (k+1)/(2π) cos^k θ_i.
    """

    name = "minnaert"
    aliases = ("minnaert-lewis",)
    summary = "Minnaert: b_M ((N.S)(N.V))^(k-1)"
    params = MINNAERT_PARAMS
    citation = "Lewis 1993 §3.4 (after Minnaert 1941)"
    width_param = "k"
    kernel = _minnaert
    _width_of_beta = staticmethod(minnaert_k_from_beta)
    examples = (
        {},
        {"b_M": 1.0, "k": 200.0},
        {"b_M": [0.1, 0.2, 0.3], "k": 0.7},
    )


    def lobes(self):
        return _minnaert_lobes(float(self._values["k"]))

    def _cos_power_q(self) -> float:
        # exact: f cos θ_i ∝ cos^k θ_i for fixed wo, so f cos θ_i / pdf does not depend on wi
        return float(self._values["k"])


@register
class MinnaertEnergyConserving(_CosPowerTraced, StrategySampled, BRDF):
    """Energy-normalised Minnaert shader (Lewis §4.3).

    f_r(S, V) = k_ρ (k+1)/(2π) ((N·S)(N·V))^{k−1}.

    ======  =======  ========  ================================================
    name    default  bounds    meaning
    ======  =======  ========  ================================================
    k_rho   0.8      [0, 1]    albedo at normal incidence (per channel)
    k       2        (0, 1e7]  exponent; or give ``beta`` (k = 1 − ln2/ln cos β)
    ======  =======  ========  ================================================

    Albedo (derived): ∫ (N·V)^{k−1} cos θ_o dω_o = 2π/(k+1), so
    a(θ_i) = k_ρ cos^{k−1}θ_i. Lewis states that "any value of k_ρ between 0
    and 1 will guarantee energy conservation"; that holds only for **k ≥ 1**.
    For 0 < k < 1 the albedo k_ρ cos^{k−1}θ_i exceeds 1 once
    cos θ_i < k_ρ^{1/(1−k)} and diverges at grazing incidence. We keep
    0 < k < 1 allowed (finite kernel: cosines floored at 1e-150, so f < 1e300)
    so that the plausibility analysis can detect this divergence, and state it
    here instead of silently bounding k ≥ 1.

    Reciprocal. Sampled exactly: pdf (k+1)/(2π) cos^k θ_i, for which
    f cos θ_i/pdf = k_ρ cos^{k−1}θ_o.
    """

    name = "minnaert-energy-conserving"
    aliases = ("minnaert-ec", "minnaert-normalised", "minnaert-normalized")
    summary = "energy-normalised Minnaert: k_rho (k+1)/2pi ((N.S)(N.V))^(k-1)"
    params = MINNAERT_EC_PARAMS
    citation = "Lewis 1993 §4.3"
    width_param = "k"
    kernel = _minnaert_ec
    _width_of_beta = staticmethod(minnaert_k_from_beta)
    examples = (
        {},
        {"k_rho": 1.0, "k": 200.0},
        {"k_rho": [0.2, 0.5, 0.9], "k": 1.0},
        {"k_rho": 0.5, "k": 0.5},
    )


    def lobes(self):
        return _minnaert_lobes(float(self._values["k"]))

    def _cos_power_q(self) -> float:
        # exact: f cos θ_i ∝ cos^k θ_i for fixed wo, so f cos θ_i / pdf does not depend on wi
        return float(self._values["k"])
