"""
Disney's principled BRDF (Burley 2012)
======================================

B. Burley's "principled" BRDF as its reference implementation computes it: BRDF
Explorer's ``src/brdfs/disney.brdf`` (github.com/wdas/brdf, Apache-2.0 with a
trademark clause; read, not copied: the formulas below are written over brdfkit's
local frame). Five terms,

    f_r = (1 − m) [C_d/π · mix(f_d, f_ss, subsurface) + sheen · C_sheen · F_H]
          + G_s F_s D_s + ¼ clearcoat · G_r F_r D_r,

- **diffuse with retro-reflection**: f_d = (1 + (F_D90 − 1) F_L)(1 + (F_D90 − 1) F_V),
  F_D90 = ½ + 2 roughness cos²θ_d, with Schlick's weight F_X = (1 − cos θ_X)⁵;
- **subsurface**: the Hanrahan–Krueger approximation f_ss = 1.25 (F_ss (1/(cos θ_l +
  cos θ_v) − ½) + ½), F_ss = (1 + (F_ss90 − 1) F_L)(1 + (F_ss90 − 1) F_V), F_ss90 =
  roughness cos²θ_d;
- **specular**: anisotropic GTR2 (GGX) D_s = 1/(π α_x α_y ((h_x/α_x)² + (h_y/α_y)² +
  h_z²)²), Smith GGX with anisotropic masking G_s = Π_{l,v} 1/(cos θ + √((w_x α_x)² +
  (w_y α_y)² + cos²θ)) (G₁G₁/(4 cos θ_l cos θ_v) in one), Schlick's Fresnel F_s =
  mix(C_spec0, 1, F_H), F_H = (1 − cos θ_d)⁵;
- **sheen**: sheen · C_sheen · F_H;
- **clearcoat**: GTR1 D_r = (a² − 1)/(π ln a² (1 + (a² − 1) cos²θ_h)), a =
  mix(0.1, 0.001, clearcoat_gloss); F_r = mix(0.04, 1, F_H) (η = 1.5); G_r the Smith GGX
  above, isotropic, α = 0.25.

Parameters (Burley's names, BRDF Explorer's defaults and ranges)
----------------------------------------------------------------
===============  ===============  ======  ==============================================
name             default          bounds  meaning
===============  ===============  ======  ==============================================
base_color       .82, .67, .16    [0, 1]  surface colour, *display* values (one or RGB)
subsurface       0                [0, 1]  blend of the diffuse towards the HK subsurface
metallic         0                [0, 1]  0 dielectric, 1 metal (no diffuse, tinted F₀)
specular         0.5              [0, 1]  F₀ = 0.08 · specular (0.5: η = 1.5, F₀ = 0.04)
specular_tint    0                [0, 1]  tints F₀ of a dielectric towards the hue
roughness        0.5              [0, 1]  α = roughness²; also diffuse retro-reflection
anisotropic      0                [0, 1]  aspect √(1 − 0.9·anisotropic), α_x ≥ α_y
sheen            0                [0, 1]  grazing sheen (cloth)
sheen_tint       0.5              [0, 1]  tints the sheen towards the hue
clearcoat        0                [0, 1]  strength of the GTR1 coat lobe (max ¼)
clearcoat_gloss  1                [0, 1]  coat a = mix(0.1, 0.001, gloss)
===============  ===============  ======  ==============================================

Conventions of the reference kept (each is disney.brdf's):

- the base colour is *linearised*, C_d = base_color^2.2 per channel (``mon2lin``), so
  the parameter is a display value as the artists picked it;
- the hue C_tint = C_d/lum(C_d) with lum = 0.3 R + 0.6 G + 0.1 B (its approximate
  luminance weights, not Rec. 709's), 1 when lum = 0; one value: C_tint = 1;
  C_spec0 = mix(0.08 specular mix(1, C_tint, specular_tint), C_d, metallic),
  C_sheen = mix(1, C_tint, sheen_tint). The tint couples the channels (each channel's
  value depends on the whole colour), so base_color is one value or RGB (3);
- α_x = max(0.001, roughness²/aspect), α_y = max(0.001, roughness² · aspect): the
  reference floors both at 0.001, so roughness 0 is a sharp but finite lobe (peak
  D = 1/(π 10⁻⁶)), kept; the clearcoat's a ≥ 0.001 likewise;
- the local frame: tangent X = +x, bitangent Y = +y, so α_x (the rougher one) acts
  along x (``dot(H, X)`` is h_x);
- f is computed where cos θ_l, cos θ_v ≥ 0; brdfkit returns 0 at the horizon itself.

One clamp is brdfkit's: the Hanrahan–Krueger factor 1/(cos θ_l + cos θ_v) diverges at
grazing incidence *and* exitance; the sum is floored at :data:`HK_SUM_FLOOR` so that f
stays finite for every pair above the horizon (the two differ only when the sum is
below 1e-300).

Claims. **Reciprocal**: every term is symmetric in (ω_i, ω_o) — f_d and F_ss are
products of one factor per direction with the symmetric F_D90(cos θ_d), f_ss depends on
cos θ_l + cos θ_v, D and F_H on h, G on one factor per direction — although Burley does
not claim it (the notes aim for plausibility, not a proof). **Isotropic** only when
anisotropic = 0 (per instance). **Energy**: not claimed (nor by Burley): the diffuse
retro-reflection exceeds a Lambertian's albedo (white, roughness 1: 1 + 1/28 at normal
incidence, 1.52 at 89°, ``tests/test_disney.py``), so does the subsurface term at grazing
incidence, and single-scattering GGX loses energy at high roughness.

Guidance: keep base_color a display colour (it is linearised); roughness 0.3–0.6 for
most dielectrics; metallic 0 or 1 (intermediate values blend); use anisotropic with a
roughness > 0.2 (the aspect stretches α along x); clearcoat ≤ 1 adds at most a 25 %
lobe.

Sampling: a mixture, the component picked from u₀ (as
:class:`~brdfkit.models.sampling.Mixture`): the cosine (diffuse, subsurface, sheen), the
anisotropic GTR2 half-vector sampler D_s cos θ_h (Burley's appendix B; the GGX slopes
stretched by α_x, α_y) and the GTR1 one (cos²θ_h = (1 − a^{2(1−u)})/(1 − a²)), with
weights estimating each term's albedo from the parameter values and cos θ_o
(:func:`mixture_weights`). Written once as formulas (:mod:`brdfkit._dual`): Numba runs
them for ``sample``/``pdf``, Mitsuba's traced route traces them.

Public objects
--------------
- :class:`Disney` — ``disney`` (aliases ``principled``, ``burley``).
- :func:`principled`, :func:`disney_sample`, :func:`disney_pdf`,
  :func:`mixture_weights` — the formulas.
- :data:`HK_SUM_FLOOR`.

References
----------
- [Burley2012] B. Burley, *Physically-Based Shading at Disney*, SIGGRAPH 2012 course
  "Practical physically-based shading in film and game production" (revised Aug 31,
  2012): §5 (the principled BRDF and its parameters), the GTR distribution, eq. (4), and
  the appendix (GTR1/GTR2 normalisation, anisotropic GTR2, their sampling).
- Walt Disney Animation Studios, *BRDF Explorer*, ``src/brdfs/disney.brdf``
  (github.com/wdas/brdf): the reference implementation.
- P. Hanrahan, W. Krueger, *Reflection from layered surfaces due to subsurface
  scattering*, SIGGRAPH 1993.
- B. Walter et al., *Microfacet Models for Refraction through Rough Surfaces*, EGSR
  2007, eqs. (14), (35) (half-vector sampling and its Jacobian).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from brdfkit._dual import (
    Formulas,
    absolute,
    cos,
    exp,
    formula,
    log,
    maximum,
    minimum,
    select,
    sin,
    sqrt,
)
from brdfkit.errors import ParameterError
from brdfkit.halfangle import beta_from_trowbridge_reitz_c
from brdfkit.models._base import BRDF, VECTOR_OPTIONS, Lobe, Param
from brdfkit.models._drivers import loop_driver
from brdfkit.models._registry import register
from brdfkit.models.microfacet import reflection_jacobian
from brdfkit.models.sampling import Strategy, StrategySampled, malley

__all__ = ["Disney", "principled", "disney_sample", "disney_pdf", "mixture_weights",
           "HK_SUM_FLOOR"]

PI = math.pi
INV_PI = 1.0 / math.pi
TWO_PI = 2.0 * math.pi

#: Floor of cos θ_l + cos θ_v in the Hanrahan–Krueger 1/(cos θ_l + cos θ_v): the term
#: diverges as both directions reach the horizon; at the floor f ≲ 1e300 (finite), and the
#: reference's value is kept wherever the sum is ≥ 1e-300.
HK_SUM_FLOOR = 1e-300
#: disney.brdf's floor of α_x, α_y (its ``max(.001, …)``): roughness 0 stays finite.
ALPHA_FLOOR = 0.001
#: The luminance weights of disney.brdf's tint (its "luminance approx."), not Rec. 709's.
TINT_LUMINANCE = (0.3, 0.6, 0.1)
GAMMA = 2.2  # mon2lin: the display base colour to linear, C^2.2 (disney.brdf)
#: Smith GGX α of the clearcoat's G_r (disney.brdf: 0.25), squared: α² = 0.0625.
COAT_G_A2 = 0.0625
#: 1/21 = ∫₀¹ (1 − μ)⁵ 2μ dμ, the cosine-weighted hemispherical mean of Schlick's weight:
#: the floor of the specular weight's Fresnel factor, so that the specular lobe keeps a
#: weight at normal incidence when F₀ = 0 (specular = metallic = 0), where its Fresnel
#: still rises to 1 towards grazing half-vector angles.
SCHLICK_MEAN = 1.0 / 21.0
# The exact rescaling of a short s = ω_i + ω_o (principled_terms): D_s = |s|⁴/(…)Q² needs
# |s|⁴ and Q² normal (Q ≤ 10⁶|s|²), so the largest component of s is brought into
# [1e-53, 1e46]: below 1e-75 by 2^400, 1e-150 by 2^650, 1e-225 (down to 5e-324) by 2^900.
_SHORT1, _SHORT2, _SHORT3 = 1e-75, 1e-150, 1e-225
_TWO_400, _TWO_650, _TWO_900 = 2.0 ** 400, 2.0 ** 650, 2.0 ** 900
_TWO_M400, _TWO_M650, _TWO_M900 = 2.0 ** -400, 2.0 ** -650, 2.0 ** -900
U0_MAX = 1.0 - 1e-16  # the largest u₀ the half-vector samplers use (u₀ = 1: θ_h = 90°)

PARAMS = (
    Param("base_color", (0.82, 0.67, 0.16), 0.0, 1.0, "",
          "surface colour as displayed (linearised as C^2.2); one value or RGB",
          kind="colour"),
    Param("subsurface", 0.0, 0.0, 1.0, "", "blend towards the Hanrahan-Krueger subsurface"),
    Param("metallic", 0.0, 0.0, 1.0, "", "0 dielectric, 1 metal (no diffuse, F0 = colour)"),
    Param("specular", 0.5, 0.0, 1.0, "", "dielectric F0 = 0.08 specular (0.5: F0 = 0.04)"),
    Param("specular_tint", 0.0, 0.0, 1.0, "", "tints the dielectric F0 towards the hue"),
    Param("roughness", 0.5, 0.0, 1.0, "",
          "alpha = roughness^2 (floored at 0.001); also the diffuse retro-reflection"),
    Param("anisotropic", 0.0, 0.0, 1.0, "",
          "aspect sqrt(1 - 0.9 anisotropic): alpha_x = alpha/aspect along x"),
    Param("sheen", 0.0, 0.0, 1.0, "", "grazing sheen (cloth)"),
    Param("sheen_tint", 0.5, 0.0, 1.0, "", "tints the sheen towards the hue"),
    Param("clearcoat", 0.0, 0.0, 1.0, "", "strength of the GTR1 clearcoat lobe (at most 1/4)"),
    Param("clearcoat_gloss", 1.0, 0.0, 1.0, "", "coat a = mix(0.1, 0.001, gloss)"),
)

# The packed row of one channel (Disney._pack): the per-channel colours first, then the
# values every channel shares, precomputed once per instance.
P_KD = 0     # (1 − metallic) C_d: the diffuse and subsurface colour
P_KSH = 1    # (1 − metallic) sheen C_sheen
P_CS0 = 2    # C_spec0
P_ROUGH = 3  # roughness (F_D90, F_ss90)
P_SUB = 4    # subsurface
P_IAX2 = 5   # 1/α_x²
P_IAY2 = 6   # 1/α_y²
P_AX = 7     # α_x
P_AY = 8     # α_y
P_KDS = 9    # 1/(π α_x α_y): D_s's normalisation
P_KCC = 10   # ¼ clearcoat (a² − 1)/(π ln a²): the coat's scale with D_r's normalisation
P_A2CC = 11  # a² of the coat
N_PACKED = 12


# =========================================================================== the formulas
@formula
def schlick_weight(c):
    """Schlick's (1 − c)⁵, the clamp to ≥ 0 as disney.brdf's (rounding can put
    cos θ_d = |ω_i + ω_o|/2 a hair above 1)."""
    m = maximum(1.0 - c, 0.0)
    m2 = m * m
    return m2 * m2 * m


@formula
def principled_terms(ix, iy, iz, ox, oy, oz, p):
    """The channel-independent factors of f_r: (live, diffuse, F_H, G_s D_s, coat) with
    f_r = C_kd·diffuse + C_ksh·F_H + mix(C_spec0, 1, F_H)·G_s D_s + coat where live (0
    elsewhere), for the shared columns of the packed row *p*. Branch-free and total.

    Written over s = ω_i + ω_o (unit directions): cos θ_d = ω_i·h = |s|/2, cos θ_h =
    s_z/|s|, h_{x,y} = s_{x,y}/|s|, so D_s = |s|⁴/(π α_x α_y Q²) with Q = s_x²/α_x² +
    s_y²/α_y² + s_z² and 1 + (a² − 1) cos²θ_h = (s_x² + s_y² + a² s_z²)/|s|² (no
    cancellation); D_s G_s, D_r G_r and 1/(cos θ_l + cos θ_v) take one division each.
    When every component of s is below 1e-75 (both directions within 1e-75 of the
    horizon, nearly opposite) s is multiplied by a power of 2 (exact; D_s and D_r are
    homogeneous of degree 0 in s; ``_SHORT1``…), as ``microfacet.walter`` does.
    """
    rough, sub = p[P_ROUGH], p[P_SUB]
    iax2, iay2, ax, ay, kds = p[P_IAX2], p[P_IAY2], p[P_AX], p[P_AY], p[P_KDS]
    kcc, a2cc = p[P_KCC], p[P_A2CC]
    live = (iz > 0.0) & (oz > 0.0)  # 0 at and below the horizon
    sx = ix + ox
    sy = iy + oy
    sz = iz + oz
    big = maximum(maximum(absolute(sx), absolute(sy)), absolute(sz))
    s1 = big < _SHORT1
    s2 = big < _SHORT2
    s3 = big < _SHORT3
    r = select(s1, select(s2, select(s3, _TWO_900, _TWO_650), _TWO_400), 1.0)  # 1: common
    r_inv = select(s1, select(s2, select(s3, _TWO_M900, _TWO_M650), _TWO_M400), 1.0)
    sx = sx * r
    sy = sy * r
    sz = sz * r
    sxy2 = sx * sx + sy * sy
    sz2 = sz * sz
    l2 = sxy2 + sz2  # |s|² (rescaled when short)
    cos_d = 0.5 * sqrt(l2) * r_inv  # ω_i·h = |s|/2 (exact: powers of 2)
    cos_d2 = cos_d * cos_d
    f_l = schlick_weight(iz)
    f_v = schlick_weight(oz)
    f_h = schlick_weight(cos_d)
    # diffuse with retro-reflection: F_D90 − 1 = 2 roughness cos²θ_d − ½
    fd90m1 = 2.0 * cos_d2 * rough - 0.5
    f_d = (1.0 + fd90m1 * f_l) * (1.0 + fd90m1 * f_v)
    # Hanrahan–Krueger subsurface, flattened by F_ss90 = roughness cos²θ_d
    fss90m1 = cos_d2 * rough - 1.0
    f_ss = (1.0 + fss90m1 * f_l) * (1.0 + fss90m1 * f_v)
    ss = 1.25 * (f_ss * (1.0 / maximum(iz + oz, HK_SUM_FLOOR) - 0.5) + 0.5)
    diffuse = INV_PI * (f_d * (1.0 - sub) + ss * sub)  # mix(f_d, f_ss, subsurface)
    # specular: anisotropic GTR2 with the anisotropic Smith GGX, G_s D_s in one division
    q = sx * sx * iax2 + sy * sy * iay2 + sz2
    # (w_x α_x)² as squares: a sum LLVM sees is ≥ 0 takes the vector sqrt, not libm's
    g_l = iz + sqrt((ix * ax) * (ix * ax) + (iy * ay) * (iy * ay) + iz * iz)
    g_v = oz + sqrt((ox * ax) * (ox * ax) + (oy * ay) * (oy * ay) + oz * oz)
    gd_s = kds * (l2 * l2) / ((q * q) * (g_l * g_v))
    # clearcoat: GTR1 D_r, Schlick F_r with F₀ = 0.04, Smith GGX G_r with α = 0.25
    c_l = iz + sqrt(COAT_G_A2 + (1.0 - COAT_G_A2) * (iz * iz))
    c_v = oz + sqrt(COAT_G_A2 + (1.0 - COAT_G_A2) * (oz * oz))
    f_r = 0.04 * (1.0 - f_h) + f_h
    coat = f_r * kcc * l2 / ((sxy2 + a2cc * sz2) * (c_l * c_v))
    return live, diffuse, f_h, gd_s, coat


@formula
def principled_channel(kd, ksh, cs0, live, diffuse, f_h, gd_s, coat):
    """One channel of f_r from :func:`principled_terms` and its colours (C_kd = (1 −
    metallic) C_d, C_ksh = (1 − metallic) sheen C_sheen, C_spec0); 0 where not live."""
    f_s = cs0 * (1.0 - f_h) + f_h  # mix(C_spec0, 1, F_H)
    return select(live, kd * diffuse + ksh * f_h + f_s * gd_s + coat, 0.0)


@formula
def principled(ix, iy, iz, ox, oy, oz, p):
    """f_r of disney.brdf (module docstring) for one channel's packed row *p* (N_PACKED
    values): one basic block (branch-free, total), so that the driver vectorises it."""
    # the row read first as a tuple: loads spread through the terms kept LLVM from vectorising
    q = (p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9], p[10], p[11])
    live, diffuse, f_h, gd_s, coat = principled_terms(ix, iy, iz, ox, oy, oz, q)
    return principled_channel(q[P_KD], q[P_KSH], q[P_CS0], live, diffuse, f_h, gd_s, coat)


@formula(**VECTOR_OPTIONS)
def _principled(ix, iy, iz, ox, oy, oz, p):
    """The registered kernel (the vectorised loop's options: IEEE division, no fast-math)."""
    return principled(ix, iy, iz, ox, oy, oz, p)


@numba.njit(cache=True, inline="always", **VECTOR_OPTIONS)
def _principled_rgb(ix, iy, iz, ox, oy, oz, t):  # pragma: no cover - compiled
    """The three channels at once (the ``"rgb"`` loop of :mod:`brdfkit.models._drivers`)
    over *t*, the three packed rows as one flat tuple (t[c·N_PACKED + k]): the shared terms
    once, then each channel as :func:`principled` computes it (the same operations:
    bit-equal)."""
    live, diffuse, f_h, gd_s, coat = principled_terms(ix, iy, iz, ox, oy, oz, t)
    return (principled_channel(t[P_KD], t[P_KSH], t[P_CS0], live, diffuse, f_h, gd_s, coat),
            principled_channel(t[N_PACKED + P_KD], t[N_PACKED + P_KSH], t[N_PACKED + P_CS0],
                               live, diffuse, f_h, gd_s, coat),
            principled_channel(t[2 * N_PACKED + P_KD], t[2 * N_PACKED + P_KSH],
                               t[2 * N_PACKED + P_CS0], live, diffuse, f_h, gd_s, coat))


# --------------------------------------------------------------------------- sampling
@formula
def mixture_weights(oz, w_d, s0, cc4):
    """(cosine, GTR2, GTR1) weights at cos θ_o, normalised: estimates of each term's
    albedo — *w_d* the diffuse, subsurface and sheen (from the parameters), the specular
    mean(C_spec0) + (1 − mean(C_spec0)) F(θ_o) with F floored at :data:`SCHLICK_MEAN`,
    the coat ¼ clearcoat mix(0.04, 1, F(θ_o)) (*cc4* = ¼ clearcoat)."""
    f_o = schlick_weight(minimum(maximum(oz, 0.0), 1.0))  # clamps: ω_o below or rounding
    w_s = s0 + (1.0 - s0) * maximum(f_o, SCHLICK_MEAN)  # > 0: see SCHLICK_MEAN
    w_c = cc4 * (0.04 + 0.96 * f_o)
    total = w_d + w_s + w_c
    return w_d / total, w_s / total, w_c / total


@formula
def gtr2_half(u0, u1, ax, ay):
    """h with density D_s(h) cos θ_h: the unit-α GGX slope (tan²θ = u/(1 − u), φ = 2πu₁)
    stretched by (α_x, α_y), as (α_x √u cos φ, α_y √u sin φ, √(1 − u)) normalised."""
    u = minimum(u0, U0_MAX)  # clamp: u = 1 maps to θ_h = 90°
    r = sqrt(u)
    phi = TWO_PI * u1
    hx = ax * r * cos(phi)
    hy = ay * r * sin(phi)
    hz = sqrt(1.0 - u)
    n = sqrt(hx * hx + hy * hy + hz * hz)
    return hx / n, hy / n, hz / n


@formula
def gtr1_half(u0, u1, a2):
    """h with density D_r(h) cos θ_h: cos²θ_h = (1 − a^{2(1−u)})/(1 − a²), φ = 2πu₁."""
    u = minimum(u0, U0_MAX)
    c2 = (1.0 - exp((1.0 - u) * log(a2))) / (1.0 - a2)
    c2 = minimum(maximum(c2, 0.0), 1.0)  # clamp: rounding
    s = sqrt(1.0 - c2)
    phi = TWO_PI * u1
    return s * cos(phi), s * sin(phi), sqrt(c2)


@formula
def _reflect(ox, oy, oz, hx, hy, hz):
    c = 2.0 * (ox * hx + oy * hy + oz * hz)
    return c * hx - ox, c * hy - oy, c * hz - oz


@formula
def disney_sample(ox, oy, oz, u0, u1, ax, ay, a2cc, w_d, s0, cc4):
    """ω_i from (u₀, u₁) ∈ [0, 1)²: the cosine when u₀ < p_d, the GTR2 half vector when
    u₀ < p_d + p_s, else the GTR1 one (:func:`mixture_weights`), u₀ rescaled into the
    chosen interval; every component evaluated, one kept (:func:`~brdfkit._dual.select`).
    A half-vector direction reached with ω_o·h < 0 lies below the horizon (pdf 0)."""
    p_d, p_s, p_c = mixture_weights(oz, w_d, s0, cc4)
    pick_d = u0 < p_d
    pick_s = u0 < p_d + p_s
    ud = minimum(u0 / maximum(p_d, 1e-300), 1.0)  # 1e-300: p_d = 0 is never picked
    us = minimum(maximum((u0 - p_d) / p_s, 0.0), 1.0)  # p_s > 0 always; clamps: rounding
    uc = minimum(maximum((u0 - p_d - p_s) / maximum(p_c, 1e-300), 0.0), 1.0)
    dx, dy, dz = malley(ud, u1)
    hx, hy, hz = gtr2_half(us, u1, ax, ay)
    sx, sy, sz = _reflect(ox, oy, oz, hx, hy, hz)
    kx, ky, kz = gtr1_half(uc, u1, a2cc)
    cx, cy, cz = _reflect(ox, oy, oz, kx, ky, kz)
    return (select(pick_d, dx, select(pick_s, sx, cx)),
            select(pick_d, dy, select(pick_s, sy, cy)),
            select(pick_d, dz, select(pick_s, sz, cz)))


@formula
def disney_pdf(ix, iy, iz, ox, oy, oz, ax, ay, a2cc, w_d, s0, cc4):
    """Solid-angle density of :func:`disney_sample` over the sphere of ω_i:
    p_d cos⁺θ_i/π + (p_s D_s(h) + p_c D_r(h)) cos θ_h/(4 |ω_o·h|), h = (ω_i + ω_o)/|…|
    as it is (h_z ≤ 0: never sampled, density 0); 0 when ω_o is at or below the horizon
    or ω_i = −ω_o."""
    p_d, p_s, p_c = mixture_weights(oz, w_d, s0, cc4)
    hx, hy, hz, ok, jac = reflection_jacobian(ix, iy, iz, ox, oy, oz)
    # the samplers only draw h with h_z > 0 and ω_o·h > 0 (where jac = 4 ω_o·h)
    ok = ok & (hz > 0.0) & (ox * hx + oy * hy + oz * hz > 0.0)
    t = hx * hx / (ax * ax) + hy * hy / (ay * ay) + hz * hz
    d_s = 1.0 / (PI * ax * ay * (t * t))
    d_r = (a2cc - 1.0) / (PI * log(a2cc) * (hx * hx + hy * hy + a2cc * hz * hz))
    half = (p_s * d_s + p_c * d_r) * hz / jac
    return select(oz > 0.0, p_d * maximum(iz, 0.0) * INV_PI + select(ok, half, 0.0), 0.0)


N_ARGS = 6  # (α_x, α_y, a², w_d, mean C_spec0, ¼ clearcoat)


@numba.njit(cache=True)
def _sample_rows(wo, u, args, wi):  # pragma: no cover - compiled
    """disney_sample over rows: wo (M, 3), u (M, 2), args (N_ARGS,) → wi (M, 3)."""
    ax, ay, a2, w_d, s0, cc4 = args[0], args[1], args[2], args[3], args[4], args[5]
    for j in range(wo.shape[0]):
        x, y, z = disney_sample(wo[j, 0], wo[j, 1], wo[j, 2], u[j, 0], u[j, 1],
                                ax, ay, a2, w_d, s0, cc4)
        wi[j, 0] = x
        wi[j, 1] = y
        wi[j, 2] = z


@numba.njit(cache=True)
def _pdf_row(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
    """disney_pdf as a kernel of the plain loop (models/_drivers) over the row of args."""
    return disney_pdf(ix, iy, iz, ox, oy, oz, p[0], p[1], p[2], p[3], p[4], p[5])


def _rows(a: np.ndarray, shape: tuple, k: int) -> np.ndarray:
    return np.ascontiguousarray(np.broadcast_to(a, shape + (k,)).reshape(-1, k),
                                dtype=np.float64)


class _DisneyMixture(Strategy):
    """:func:`disney_sample`/:func:`disney_pdf` on NumPy arrays for the sampler's *args*
    (a :class:`~brdfkit.models.sampling.Strategy`: the mixture of cosine, GTR2 and GTR1
    half-vector sampling, weights per ω_o)."""

    def __init__(self, args: tuple):
        self.args = np.array(args, dtype=np.float64)

    def sample(self, wo, u):
        shape = np.broadcast_shapes(wo.shape[:-1], u.shape[:-1])
        w, uu = _rows(wo, shape, 3), _rows(u, shape, 2)
        wi = np.empty_like(w)
        _sample_rows(w, uu, self.args, wi)
        return wi.reshape(shape + (3,))

    def pdf(self, wi, wo):
        shape = np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1])
        out = np.empty((int(np.prod(shape)), 1))
        loop_driver(_pdf_row, loop="plain")(_rows(wi, shape, 3), _rows(wo, shape, 3),
                                             self.args[None, :], out)
        return out.reshape(shape)

    def __repr__(self) -> str:
        return f"_DisneyMixture(args={self.args.tolist()})"


# =========================================================================== the model
def _gtr1_half_width(a: float) -> float:
    """Half-angle β where D_r falls to half its peak: 1 + (a² − 1) cos²β = 2a², i.e.
    tan²β = a²/(1 − 2a²) (a ≤ 0.1 here)."""
    return math.atan(a / math.sqrt(1.0 - 2.0 * a * a))


def _ggx_half_width(alpha: float) -> float:
    """Half-angle of a GGX lobe of α (Lewis's D₃: :mod:`brdfkit.halfangle`); π/2 where D
    never halves (α ≥ 2^(−1/4))."""
    if alpha >= 0.8:  # 2^(−1/4) ≈ 0.841: broader lobes have no half-angle; 0.8 → 1.2 rad
        return math.pi / 2
    return float(beta_from_trowbridge_reitz_c(alpha))


@register
class Disney(StrategySampled, BRDF):
    """Burley's (2012) principled BRDF as disney.brdf computes it: the parameter table,
    the conventions kept and the claims are the module docstring's.

    Reciprocal (every term symmetric; Burley does not claim it); isotropic when
    anisotropic = 0 (``isotropic`` is set per instance); energy not claimed. f_r, the
    sampler and its pdf are formulas (:func:`principled`, :func:`disney_sample`,
    :func:`disney_pdf`), compiled by Numba here and traced by Dr.Jit in Mitsuba; RGB is
    evaluated in one pass (:func:`_principled_rgb`, the ``"rgb"`` loop).
    """

    name = "disney"
    aliases = ("principled", "burley", "disney-principled")
    summary = "Burley 2012 principled BRDF (diffuse, subsurface, aniso GTR2, sheen, clearcoat)"
    params = PARAMS
    citation = ("Burley 2012 §5, GTR eq. (4) and appendix (GTR1/GTR2, sampling), as "
                "BRDF Explorer's src/brdfs/disney.brdf computes it")
    reciprocal = True
    has_sampler = True
    width_param = None
    kernel = _principled
    # Examples: the defaults first, then a sharp anisotropic metal, a rough surface with
    # every term on, a glossy coat over an anisotropic base. A colour with a tint couples
    # the channels (C_tint = C_d/lum), so tinted examples take one value of base_color;
    # tests/test_disney.py checks the tinted colours against the reference.
    examples = (
        {},
        {"base_color": [0.9, 0.6, 0.3], "metallic": 1.0, "roughness": 0.2,
         "anisotropic": 0.8},
        {"base_color": 0.8, "roughness": 1.0, "subsurface": 0.6, "sheen": 1.0,
         "sheen_tint": 0.3, "clearcoat": 0.5, "clearcoat_gloss": 0.2, "specular_tint": 0.7},
        {"base_color": 0.3, "roughness": 0.6, "anisotropic": 1.0, "metallic": 0.3,
         "clearcoat": 1.0, "clearcoat_gloss": 0.9},
    )

    def _validate(self):
        c = self.n_channels
        if c not in (None, 1, 3):
            raise ParameterError(
                f"{self.name}: parameter 'base_color' must be one value or RGB (3 values: "
                f"the tint divides by the luminance 0.3 R + 0.6 G + 0.1 B); got {c} values")
        v = self._values
        # per instance: anisotropic = 0 gives α_x = α_y (the protocol reads model.isotropic)
        self.isotropic = v["anisotropic"] == 0.0
        # BRDF.eval's loop (generated, cached on disk): RGB in one pass of the shared terms
        # (the "rgb" loop), else the vectorised loop of the one-channel kernel
        self._driver = (loop_driver(_principled_rgb, loop="rgb", width=3 * N_PACKED) if c == 3
                        else loop_driver(_principled, loop="vector"))

    # ------------------------------------------------------------- derived constants
    def _alphas(self) -> tuple[float, float]:
        v = self._values
        aspect = math.sqrt(1.0 - 0.9 * v["anisotropic"])
        a = v["roughness"] ** 2
        return max(ALPHA_FLOOR, a / aspect), max(ALPHA_FLOOR, a * aspect)

    def _coat_a(self) -> float:
        g = self._values["clearcoat_gloss"]
        return 0.1 * (1.0 - g) + 0.001 * g  # mix(.1, .001, gloss): a ∈ [0.001, 0.1]

    def _colours(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(C_d, C_spec0, C_sheen) per channel (module docstring: the reference's)."""
        v = self._values
        c_d = np.atleast_1d(np.asarray(v["base_color"], dtype=np.float64)) ** GAMMA
        lum = float(np.dot(TINT_LUMINANCE, c_d)) if c_d.size == 3 else float(c_d[0])
        tint = c_d / lum if lum > 0.0 else np.ones_like(c_d)
        st, sh, m = v["specular_tint"], v["sheen_tint"], v["metallic"]
        c_spec0 = (v["specular"] * 0.08 * ((1.0 - st) + tint * st)) * (1.0 - m) + c_d * m
        c_sheen = (1.0 - sh) + tint * sh
        return c_d, c_spec0, c_sheen

    def _pack(self) -> np.ndarray:
        v = self._values
        c_d, c_spec0, c_sheen = self._colours()
        ax, ay = self._alphas()
        a = self._coat_a()
        a2 = a * a
        m = v["metallic"]
        rows = np.empty((c_d.size, N_PACKED))
        rows[:, P_KD] = (1.0 - m) * c_d
        rows[:, P_KSH] = (1.0 - m) * v["sheen"] * c_sheen
        rows[:, P_CS0] = c_spec0
        rows[:, P_ROUGH] = v["roughness"]
        rows[:, P_SUB] = v["subsurface"]
        rows[:, P_IAX2] = 1.0 / (ax * ax)
        rows[:, P_IAY2] = 1.0 / (ay * ay)
        rows[:, P_AX] = ax
        rows[:, P_AY] = ay
        rows[:, P_KDS] = 1.0 / (PI * ax * ay)
        rows[:, P_KCC] = 0.25 * v["clearcoat"] * (a2 - 1.0) / (PI * math.log(a2))
        rows[:, P_A2CC] = a2
        return np.ascontiguousarray(rows)

    def sampler_args(self) -> tuple[float, ...]:
        """The sampler's arguments (α_x, α_y, a², w_d, mean C_spec0, ¼ clearcoat): w_d
        estimates the albedo of the diffuse, subsurface and sheen terms, (1 − metallic)
        (mean C_d + π sheen mean C_sheen/21: F_H's hemispherical mean, as SCHLICK_MEAN)."""
        v = self._values
        c_d, c_spec0, c_sheen = self._colours()
        ax, ay = self._alphas()
        a = self._coat_a()
        w_d = (1.0 - v["metallic"]) * (float(np.mean(c_d))
                                       + PI * v["sheen"] * float(np.mean(c_sheen)) / 21.0)
        return (ax, ay, a * a, w_d, float(np.mean(c_spec0)), 0.25 * v["clearcoat"])

    # ------------------------------------------------------------- protocol
    def lobes(self):
        v = self._values
        ax, ay = self._alphas()
        out = []
        c_d, _, _ = self._colours()
        if v["metallic"] < 1.0 and (np.any(c_d > 0.0) or v["sheen"] > 0.0):
            out.append(Lobe("diffuse", math.pi / 2))
        out.append(Lobe("half", _ggx_half_width(min(ax, ay))))
        if v["clearcoat"] > 0.0:
            out.append(Lobe("half", _gtr1_half_width(self._coat_a())))
        return out

    def _strategy(self, wo):
        return _DisneyMixture(self.sampler_args())

    def formulas(self) -> Formulas:
        """:func:`principled` over the packed row, :func:`disney_sample`,
        :func:`disney_pdf` with :meth:`sampler_args`."""
        return Formulas(eval=_principled, sample=disney_sample, pdf=disney_pdf,
                        args=self.sampler_args())
