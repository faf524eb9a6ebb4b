"""
Rough diffuse models: Oren–Nayar, Fujii's improved Oren–Nayar (FON), EON
========================================================================

A surface of V-cavities whose facets are Lambertian reflects more toward the
light than Lambert's law says (retro-reflection) and loses energy to masking
and shadowing; Oren & Nayar (1994) model it, Fujii's "improved" form (FON)
removes the qualitative model's dark rim, and EON (Portsmouth, Kutz, Hill 2025,
OpenPBR's diffuse) adds the energy FON loses back as a multiple-scattering lobe
in the Kulla–Conty form, in closed form.

Public objects
--------------
- :class:`OrenNayar` — ``oren-nayar``: the full model (C₁, C₂, C₃ and the
  interreflection term L²) or the qualitative one, a choice.
- :class:`FON` — ``fon``: ρ/π · A (1 + r s/t).
- EON (``eon``: f_FON + f_ms, energy-preserving for white ρ) and its clipped-LTC
  sampler are :mod:`brdfkit.models.eon`, built on the FON formulas here.
- :func:`fon_albedo`, :func:`fon_average_albedo` — E_FON(μ) (exact or the
  paper's polynomial) and Ē_FON, in NumPy.
- :func:`oren_nayar_full`, :func:`oren_nayar_qualitative`, :func:`fon`,
  :func:`g_exact`, :func:`g_approx`, :func:`cosine_sample`, :func:`cosine_pdf` — the
  formulas (:mod:`brdfkit._dual`): compiled kernels here, traced in Mitsuba.

Derivations (checked in ``tests/test_rough_diffuse.py``)
--------------------------------------------------------
**Reciprocity.** Every form depends on (θ_i, θ_o) only through α = max, β = min,
and on the azimuths through cos(φ_i − φ_o); FON's s = ω_i·ω_o − μ_iμ_o and
t = max(μ_i, μ_o) are symmetric; EON's f_ms is a product (1 − E(μ_i))(1 − E(μ_o)).
All three are reciprocal, both Oren–Nayar forms included.

**FON's albedo.** With s = sin θ_i sin θ_o cos φ (φ the relative azimuth),
∫ cos φ dφ over cos φ > 0 is 2 and over cos φ < 0 is −2, so
E_FON(μ) = A (1 + (r/π) G(μ)) with
G(μ) = 2 sin θ ∫ sin²θ_o cos θ_o / max(μ, cos θ_o) dθ_o − (2/3) sin θ
     = sin θ (θ − sin θ cos θ) + (2/3) [(sin θ/cos θ)(1 − sin³θ) − sin θ],
μ = cos θ (the integral split at θ_o = θ). G(0) = π/2 − 2/3, so E_FON(0) = 1
exactly; G(1) = 0, E_FON(1) = A. The kernel writes (sin θ/μ)(1 − sin³θ) as
sin θ · μ (1 + S + S²)/(1 + S) (S = sin θ, 1 − S = μ²/(1 + S)): no cancellation
at grazing. 2 ∫ E μ dμ = A (1 + (2/3 − 28/(15π)) r) = Ē_FON, as the paper states.

**EON without 0/0.** 1 − E_FON(μ) = A r (c₁ − G/π) and 1 − Ē = A r (c₁ − c₂),
c₁ = 1/2 − 2/(3π), c₂ = 2/3 − 28/(15π), so
f_ms = (ρ_ms/π) A r (c₁ − G_i/π)(c₁ − G_o/π)/(c₁ − c₂): exact at r = 0 (no ε
floors, unlike the authors' listing's max(1e-7, ·)). For ρ = 1, ρ_ms = 1 and
a(μ) = E + (1 − E)(1 − Ē)/(1 − Ē) = 1 with the exact E_FON.

**The full Oren–Nayar model is negative for σ > 0.664 rad.** Its C₂ branch for
cos(φ_r − φ_i) < 0 makes the direct term C₁ − 0.45 σ²/(σ² + 0.09)
(sin α − (2β/π)³) tan β at cos = −1, α = π/2, β → π/2, where
(1 − (2β/π)³) tan β → 6/π; C₁ = 0.45 σ²/(σ²+0.09)·6/π at σ = 0.6644 rad (38.1°).
Beyond it f < 0 at forward grazing for small ρ; the full form is therefore
bounded to σ ≤ 0.66 (the qualitative one, never negative, to π/2).

Parameters (Mitsuba-style)
--------------------------
==========  =======  ==============  =============================================
name        default  bounds          meaning
==========  =======  ==============  =============================================
rho         0.8      [0, 1]          facet albedo (per channel); ``oren-nayar``,
                                     ``fon``, ``eon``
sigma       0.3      [0, π/2] rad    ``oren-nayar``: standard deviation of the
                                     facet slope angle; 0 is Lambert, 0.1–0.2
                                     (6–11°) slightly rough, 0.3–0.6 (17–34°)
                                     visibly flat, retro-reflective (clay,
                                     plaster); ``form=full`` needs ≤ 0.66 (above)
form        full     full|qualit.    ``oren-nayar``: the full model or the
                                     qualitative A + B max(0, cos) sin α tan β
r           0.5      [0, 1]          ``fon``, ``eon``: roughness as the EON paper
                                     names it (0 Lambert, 1 roughest; r > 1 would
                                     make 1 + r s/t negative)
E_FON       exact    exact|approx    ``eon``: FON's albedo in closed form or the
                                     paper's quartic in 1 − μ (faster; for ρ = 1,
                                     |1 − a| ≤ 5.3e-4 measured)
==========  =======  ==============  =============================================

Sampling: cosine for ``oren-nayar`` and ``fon`` (cos θ_i/π, the weight is π f);
``eon`` by the paper's clipped linearly transformed cosine mixed with a uniform
lobe (:mod:`brdfkit.models.eon`).

References
----------
- [Oren1994] M. Oren, S. K. Nayar, *Generalization of Lambert's reflectance
  model*, SIGGRAPH 1994, §4: the functional approximation L_r = L_r¹ + L_r²
  (L_r¹ with C₁, C₂, C₃; L_r² the interreflection term) and the qualitative
  model. Cited as eqs. (27)–(29) and (30) from memory: the paper is not on this
  machine, so its printed numbering is unverified; the formulas are the ones
  every later reference reprints (and the tests' second implementation).
- [Fujii] Y. Fujii, *A tiny improvement of Oren–Nayar reflectance model*,
  https://mimosa-pudica.net/improved-oren-nayar.html (FON, as EON's §3 writes it).
- [Portsmouth2025] J. Portsmouth, P. Kutz, S. Hill, *EON: A practical
  energy-preserving rough diffuse BRDF*, JCGT 14(1), 2025 (arXiv 2410.18026):
  §§3–4 and Listing 1: f_FON, E_FON exact and approximate, Ē_FON, f_ms and
  ρ_ms (the paper is not on this machine; its equations are cited by section and
  listing, not by number). Constants checked
  against the authors' GLSL, repository ``portsmouth/OpenPBR-viewer``, file
  ``glsl/pathtracing/diffuse_brdf.glsl`` (``E_FON_exact``, ``E_FON_approx``,
  ``f_EON``); nothing copied.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from brdfkit._dual import (
    Formulas,
    absolute,
    atan2,
    cos,
    formula,
    maximum,
    minimum,
    numpy_version,
    select,
    sin,
    sqrt,
)
from brdfkit.errors import ParameterError
from brdfkit.models._base import BRDF, VECTOR_OPTIONS, Lobe, Param
from brdfkit.models._drivers import loop_driver
from brdfkit.models._params import packed_indices
from brdfkit.models._registry import register

__all__ = ["OrenNayar", "FON", "fon_albedo", "fon_average_albedo", "oren_nayar_full",
           "oren_nayar_qualitative", "fon", "g_exact", "g_approx", "cosine_sample",
           "cosine_pdf", "FON_PARAMS", "C1_FON", "C2_FON"]

INV_PI = 1.0 / math.pi
TWO_PI = 2.0 * math.pi
TWO_OVER_PI = 2.0 / math.pi
#: Floor of a cosine used as a divisor (tan β = sin β/cos β, s/t): 1e-30 keeps
#: f ≤ ~1e30 finite when both directions are within 1e-30 rad of the horizon, and is a
#: normal float32 number, so the floor also holds in Mitsuba's single-precision variants.
COS_FLOOR = 1e-30
#: FON's constants (EON §3): A = 1/(1 + C1_FON r), Ē_FON = A (1 + C2_FON r).
C1_FON = 0.5 - 2.0 / (3.0 * math.pi)
C2_FON = 2.0 / 3.0 - 28.0 / (15.0 * math.pi)
#: The paper's quartic fit of G(μ)/π in x = 1 − μ (E_FON ≈ A (1 + r g(x))).
G_APPROX = (0.0571085289, 0.491881867, -0.332181442, 0.0714429953)
G1, G2, G3, G4 = G_APPROX
#: The largest σ (rad) at which the full Oren–Nayar model stays ≥ 0 for every ρ
#: (module docstring: C₁(σ) = 0.45 σ²/(σ² + 0.09)·6/π at σ = 0.66440), rounded down.
SIGMA_FULL_MAX = 0.66

# =========================================================================== Oren–Nayar
ON_PARAMS = (
    Param("rho", 0.8, 0.0, 1.0, "", "albedo of the Lambertian facets", kind="colour"),
    Param("sigma", 0.3, 0.0, 0.5 * math.pi, "rad",
          "standard deviation of the facet slope angle: 0 Lambert, 0.1-0.2 slightly rough, "
          "0.3-0.6 flat and retro-reflective (form=full needs <= 0.66, where it stays >= 0)"),
    Param("form", "full", kind="choice", choices=("full", "qualitative"),
          doc="full: C1, C2, C3 and the interreflection term; qualitative: A + B max(0, cos) "
              "sin(alpha) tan(beta)"),
)
P_RHO, P_SIGMA, P_FORM = packed_indices(ON_PARAMS, "rho", "sigma", "form")
FULL, QUALITATIVE = 0, 1  # the packed value of the form choice


@formula
def _angles(ix, iy, iz, ox, oy, oz):
    """sin α, tan β, α, β (α = max(θ_i, θ_o), β = min) and cos(φ_i − φ_o) (0 where an
    azimuth is undefined: a direction at the normal, where every term it multiplies is 0)."""
    si = sqrt(ix * ix + iy * iy)
    so = sqrt(ox * ox + oy * oy)
    theta_i = atan2(si, iz)
    theta_o = atan2(so, oz)
    alpha = maximum(theta_i, theta_o)
    beta = minimum(theta_i, theta_o)
    sin_a = maximum(si, so)  # sin is increasing on [0, π/2]
    tan_b = minimum(si, so) / maximum(maximum(iz, oz), COS_FLOOR)  # floor: see COS_FLOOR
    d = si * so
    ok = d > 0.0
    c = (ix * ox + iy * oy) / select(ok, d, 1.0)  # 1: the discarded lane stays finite
    c = select(ok, minimum(maximum(c, -1.0), 1.0), 0.0)  # clamp: rounding of |c| ≤ 1
    return sin_a, tan_b, alpha, beta, c, si, so


@formula
def oren_nayar_full(ix, iy, iz, ox, oy, oz, p):
    """Oren & Nayar's functional approximation, f = (L_r¹ + L_r²)/(E₀ cos θ_i), a formula.

    L_r¹ (eqs. 27–28): ρ/π [C₁ + cos Δφ C₂ tan β + (1 − |cos Δφ|) C₃ tan((α+β)/2)],
    C₁ = 1 − σ²/(2(σ² + 0.33)), C₂ = 0.45 σ²/(σ² + 0.09) sin α for cos Δφ ≥ 0, else
    0.45 σ²/(σ² + 0.09)(sin α − (2β/π)³), C₃ = 0.125 σ²/(σ² + 0.09)(4αβ/π²)²;
    L_r² (eq. 29): 0.17 ρ²/π σ²/(σ² + 0.13)[1 − cos Δφ (2β/π)²].
    tan((α+β)/2) = (sin α + sin β)/(cos α + cos β) (the half-angle identity).
    """
    rho, sigma = p[P_RHO], p[P_SIGMA]
    live = (iz > 0.0) & (oz > 0.0)
    sin_a, tan_b, alpha, beta, c, si, so = _angles(ix, iy, iz, ox, oy, oz)
    s2 = sigma * sigma
    k = s2 / (s2 + 0.09)
    c1 = 1.0 - 0.5 * s2 / (s2 + 0.33)
    b3 = TWO_OVER_PI * beta
    c2 = 0.45 * k * (sin_a - select(c >= 0.0, 0.0, b3 * b3 * b3))
    ab = 4.0 * alpha * beta * INV_PI * INV_PI
    c3 = 0.125 * k * ab * ab
    tan_half = (si + so) / maximum(iz + oz, COS_FLOOR)  # floor: see COS_FLOOR
    direct = c1 + c * c2 * tan_b + (1.0 - absolute(c)) * c3 * tan_half
    inter = 0.17 * rho * s2 / (s2 + 0.13) * (1.0 - c * b3 * b3)
    return select(live, rho * INV_PI * (direct + inter), 0.0)


@formula
def oren_nayar_qualitative(ix, iy, iz, ox, oy, oz, p):
    """The qualitative model (eq. 30): ρ/π (A + B max(0, cos Δφ) sin α tan β),
    A = 1 − σ²/(2(σ² + 0.33)), B = 0.45 σ²/(σ² + 0.09); a formula."""
    rho, sigma = p[P_RHO], p[P_SIGMA]
    live = (iz > 0.0) & (oz > 0.0)
    sin_a, tan_b, alpha, beta, c, si, so = _angles(ix, iy, iz, ox, oy, oz)
    s2 = sigma * sigma
    a = 1.0 - 0.5 * s2 / (s2 + 0.33)
    b = 0.45 * s2 / (s2 + 0.09)
    return select(live, rho * INV_PI * (a + b * maximum(c, 0.0) * sin_a * tan_b), 0.0)


@formula(**VECTOR_OPTIONS)
def _on_full(ix, iy, iz, ox, oy, oz, p):
    return oren_nayar_full(ix, iy, iz, ox, oy, oz, p)


@formula(**VECTOR_OPTIONS)
def _on_qualitative(ix, iy, iz, ox, oy, oz, p):
    return oren_nayar_qualitative(ix, iy, iz, ox, oy, oz, p)


@numba.njit(cache=True, **VECTOR_OPTIONS)
def _oren_nayar(ix, iy, iz, ox, oy, oz, p):
    """The model's kernel for callers with one kernel per model (albedo engine, pumping):
    dispatches on the packed form."""
    if p[P_FORM] == QUALITATIVE:
        return _on_qualitative(ix, iy, iz, ox, oy, oz, p)
    return _on_full(ix, iy, iz, ox, oy, oz, p)


# =========================================================================== cosine sampling
@formula
def cosine_sample(ox, oy, oz, u0, u1):
    """Malley's method, as :func:`brdfkit.geometry.sample_cosine_hemisphere` (the same
    directions as ``model.sample``): a uniform point of the disk lifted to the hemisphere."""
    r = sqrt(u0)
    phi = TWO_PI * u1
    x = r * cos(phi)
    y = r * sin(phi)
    return x, y, sqrt(maximum(1.0 - x * x - y * y, 0.0))  # clamp: rounding at the rim


@formula
def cosine_pdf(ix, iy, iz, ox, oy, oz):
    """cos⁺θ_i/π, 0 when ω_o is at or below the horizon (``BRDF.pdf``)."""
    return select(oz > 0.0, maximum(iz, 0.0) * INV_PI, 0.0)


class _RoughDiffuse:
    """What the rough diffuse models share: one diffuse lobe, the N·V = N·L kink circle,
    cosine sampling (``BRDF.sample``/``pdf``; the weight is π f) and the formulas of this
    instance's kernel (``_formula``, set by ``_validate``) for the Mitsuba bridge."""

    has_sampler = True
    #: Albedo engine tolerance a table of this model's albedo asks for (read by
    #: brdfkit.compensation.table; None: the table's own). FON's and EON's t switches at
    #: the relative azimuth 90° (s = 0), which the engine cannot take as a kink in the
    #: normal frame: at 1e-7 (and 1e-8) its estimate misses it (measured for FON r = 0.5:
    #: 3.5e-6 off the closed form E_FON with 8e-8 estimated; EON 6.6e-6), at 1e-9 it
    #: refines past it (1e-15 off the closed form). Oren–Nayar meets 1e-7 (3e-8 measured).
    albedo_engine_tol = None

    def lobes(self):
        return [Lobe("diffuse", 0.5 * math.pi)]

    def albedo_kinks_nv(self, theta):
        """N·V = N·L, where max(θ_i, θ_o) (every form) and max(μ_i, μ_o) (FON's t) switch:
        a circle about the normal, the frame of the diffuse lobe (``"nv=nl"`` is the
        mirror frame's)."""
        return np.cos(np.asarray(theta, dtype=np.float64))[:, None]

    def formulas(self) -> Formulas:
        """This instance's kernel (a formula over its packed row) and cosine sampling."""
        return Formulas(eval=self._formula, sample=cosine_sample, pdf=cosine_pdf, args=())


@register
class OrenNayar(_RoughDiffuse, BRDF):
    """Oren & Nayar (1994): Lambertian V-cavities with Gaussian slope angles, std σ.

    ``form="full"``: the functional approximation with C₁, C₂, C₃ and the
    interreflection term L_r² (eqs. 27–29; :func:`oren_nayar_full`);
    ``form="qualitative"``: ρ/π (A + B max(0, cos(φ_i − φ_o)) sin α tan β)
    (eq. 30; :func:`oren_nayar_qualitative`). α = max(θ_i, θ_o), β = min(θ_i, θ_o).

    ======  =======  ================  ============================================
    name    default  bounds            meaning
    ======  =======  ================  ============================================
    rho     0.8      [0, 1]            facet albedo (per channel)
    sigma   0.3      [0, π/2] rad      slope-angle std; 0 is Lambert; full form
                                       ≤ 0.66 (it is negative beyond: module
                                       docstring)
    form    full     full/qualitative  which of the paper's two forms
    ======  =======  ================  ============================================

    Reciprocal (both forms: symmetric in α, β and cos Δφ). Not energy-conserving,
    either way (white ρ = 1, measured in the tests): the qualitative form loses up to
    44 % at normal incidence (1 − a(0°) = 1 − A: 0.22 at σ = 0.5, 0.44 at σ = π/2) but
    for small σ its B sin α tan β term returns more than 1 at grazing (a(89°) = 1.012
    at σ = 0.25); the full form's L_r² adds more (a(89°) = 1.043 at σ = 0.25). Both
    diverge as both directions approach the horizon (tan β), with a finite albedo.
    Sampled by the cosine.
    """

    name = "oren-nayar"
    aliases = ("orennayar", "oren-nayar-1994")
    summary = "Oren-Nayar 1994 rough diffuse (full with interreflection, or qualitative)"
    params = ON_PARAMS
    citation = ("Oren & Nayar 1994 §4: full approximation (C1, C2, C3 and interreflection "
                "L2; eqs. 27-29) or qualitative (eq. 30)")
    reciprocal = True
    kernel = _oren_nayar
    examples = (
        {},
        {"sigma": 0.66, "rho": [0.2, 0.5, 1.0]},
        {"form": "qualitative", "sigma": 1.5, "rho": 1.0},
    )

    def _validate(self):
        v = self._values
        if v["form"] == "full" and v["sigma"] > SIGMA_FULL_MAX:
            raise ParameterError(
                f"{self.name}: parameter 'sigma' must lie in [0, {SIGMA_FULL_MAX:g}] rad with "
                f"form='full' (the full model is negative beyond 0.664); got {v['sigma']:g}; "
                "use form='qualitative' for rougher surfaces")
        self._formula = _on_qualitative if v["form"] == "qualitative" else _on_full
        self._driver = loop_driver(self._formula, loop="vector")


# =========================================================================== FON
FON_PARAMS = (
    Param("rho", 0.8, 0.0, 1.0, "", "single-scattering albedo", kind="colour"),
    Param("r", 0.5, 0.0, 1.0, "", "roughness: 0 Lambert, 1 roughest (EON's symbol)"),
)
P_F_RHO, P_F_R = packed_indices(FON_PARAMS, "rho", "r")


@formula
def fon(ix, iy, iz, ox, oy, oz, p):
    """FON (EON §3, after Fujii): ρ/π A (1 + r s/t), s = ω_i·ω_o − μ_iμ_o,
    t = max(μ_i, μ_o) where s > 0 else 1, A = 1/(1 + (1/2 − 2/(3π)) r); a formula.

    s is computed as i_x o_x + i_y o_y (the same value, no cancellation).
    """
    rho, r = p[P_F_RHO], p[P_F_R]
    live = (iz > 0.0) & (oz > 0.0)
    s = ix * ox + iy * oy
    t = select(s > 0.0, maximum(maximum(iz, oz), COS_FLOOR), 1.0)  # floor: see COS_FLOOR
    a = 1.0 / (1.0 + C1_FON * r)
    return select(live, rho * INV_PI * a * (1.0 + r * s / t), 0.0)


@formula
def g_exact(sx, sy, mu):
    """G(μ)/π of FON's albedo (module docstring), sin θ = |(s_x, s_y)|; a formula."""
    s = sqrt(sx * sx + sy * sy)
    theta = atan2(s, mu)
    cubic = s * mu * (1.0 + s + s * s) / (1.0 + s)  # = (s/μ)(1 − s³), no cancellation
    return INV_PI * (s * (theta - s * mu) + (2.0 / 3.0) * (cubic - s))


@formula
def g_approx(mu):
    """The paper's quartic fit of G(μ)/π in x = 1 − μ; a formula."""
    x = 1.0 - mu
    return x * (G1 + x * (G2 + x * (G3 + x * G4)))


@formula(**VECTOR_OPTIONS)
def _fon(ix, iy, iz, ox, oy, oz, p):
    return fon(ix, iy, iz, ox, oy, oz, p)


@register
class FON(_RoughDiffuse, BRDF):
    """Fujii's improved Oren–Nayar (FON), as the EON paper writes it (§3).

    f = ρ/π · A (1 + r s/t), s = ω_i·ω_o − μ_iμ_o, t = max(μ_i, μ_o) for s > 0 else 1,
    A = 1/(1 + (1/2 − 2/(3π)) r).

    ====  =======  ======  ==================================================
    name  default  bounds  meaning
    ====  =======  ======  ==================================================
    rho   0.8      [0, 1]  single-scattering albedo (per channel)
    r     0.5      [0, 1]  roughness; 0 is Lambert
    ====  =======  ======  ==================================================

    Reciprocal. Single scattering only: its albedo E_FON(μ) (closed form,
    :func:`fon_albedo`) is 1 at grazing and A < 1 at normal incidence, its average
    Ē_FON = A (1 + (2/3 − 28/(15π)) r) (0.868 at r = 1): not energy-conserving
    for white ρ, the loss EON returns. Sampled by the cosine.
    """

    albedo_engine_tol = 1e-9  # the azimuth-90° switch of t (_RoughDiffuse)

    name = "fon"
    aliases = ("fujii", "improved-oren-nayar", "fujii-oren-nayar")
    summary = "Fujii's improved Oren-Nayar: rho/pi A (1 + r s/t)"
    params = FON_PARAMS
    citation = "Portsmouth, Kutz, Hill 2025 (EON) §3, Listing 1 (after Fujii's improved Oren-Nayar)"
    reciprocal = True
    kernel = _fon
    examples = (
        {},
        {"r": 1.0, "rho": [0.2, 0.5, 1.0]},
    )

    def _validate(self):
        self._formula = _fon  # per instance: a dispatcher class attribute would bind as a method
        self._driver = loop_driver(_fon, loop="vector")


# =========================================================================== NumPy closed forms
def _check_unit_interval(x, name: str) -> np.ndarray:
    x = np.asarray(x, dtype=np.float64)
    bad = ~((x >= 0.0) & (x <= 1.0))
    if np.any(bad):
        raise ParameterError(f"{name} must lie in [0, 1]; got {float(x[bad].ravel()[0])!r}")
    return x


def fon_albedo(mu, r, *, form: str = "exact") -> np.ndarray:
    """FON's directional albedo for ρ = 1, E_FON(μ) = A (1 + r G(μ)/π).

    Parameters
    ----------
    mu : array_like
        cos θ, in [0, 1].
    r : array_like
        Roughness in [0, 1] (broadcast with *mu*).
    form : {"exact", "approx"}, keyword-only
        The closed form (module docstring) or the paper's quartic in 1 − μ.
    """
    mu = _check_unit_interval(mu, "mu")
    r = _check_unit_interval(r, "r")
    if form not in ("exact", "approx"):
        raise ParameterError(f"form must be one of exact, approx; got {form!r}")
    if form == "exact":
        s = np.sqrt(np.maximum(1.0 - mu * mu, 0.0))  # clamp: rounding at μ = 1
        g = numpy_version(g_exact)(s, np.zeros_like(s), mu)
    else:
        g = numpy_version(g_approx)(mu)
    return (1.0 + r * g) / (1.0 + C1_FON * r)


def fon_average_albedo(r) -> np.ndarray:
    """Ē_FON = 2 ∫ E_FON(μ) μ dμ = A (1 + (2/3 − 28/(15π)) r) (EON's closed form)."""
    r = _check_unit_interval(r, "r")
    return (1.0 + C2_FON * r) / (1.0 + C1_FON * r)
