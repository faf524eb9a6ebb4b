"""The registered ``disney`` model against its reference implementation (issue 22 §1, §4).

References, each independent of the registered kernel (``src/brdfkit/models/disney.py``):

- **BRDF Explorer's disney.brdf in real GLSL.** The reference implementation of Burley
  2012 (github.com/wdas/brdf, ``src/brdfs/disney.brdf``, kept unchanged with its Apache
  2.0 notice in ``tests/brdf_files/wdas/``) compiled by Mesa and run on llvmpipe
  (``tests/glsl_reference.py``), float32: agreement to float32 precision (the harness's
  bound: 1e-5 relative + 8 one-ulp perturbation spreads) at random pairs and parameter
  sets over the whole declared ranges, colours (so the tint's channel coupling) included.
- **The same file through brdfkit's translator** (``brdfkit.model(path)``, float64): to
  float64 rounding.
- **Limits from other models and closed forms:** metallic = 1 is a GGX conductor with
  Schlick's Fresnel (``microfacet`` GGX times F₀ + (1 − F₀)(1 − cos θ_d)⁵), anisotropic
  against Heitz 2014's anisotropic GGX D and Smith Λ (eqs. 77, 86 with the stretched
  α(ω)) written here; the clearcoat, sheen and subsurface terms from Burley's formulas
  written here (GTR1, Schlick, the Hanrahan–Krueger form), linear in their weights.
- **Albedo**: the engine's a(θ) against a Gauss–Legendre × trapezoid quadrature of the
  NumPy formula written here; the measured values answer issue 22 §3's question (does
  Disney's diffuse exceed 1 at grazing on rough surfaces?).
- χ² of the sampler at anisotropic settings and incidence azimuths ≠ 0 (beside the
  registry-wide tests/test_sampling_chi2.py), the formulas' Dr.Jit versions, and a
  traced Mitsuba render.
"""

from __future__ import annotations

import gc
import math
import warnings
from pathlib import Path

import glsl_reference as ref
import numpy as np
import pytest

import brdfkit
from brdfkit.analysis import albedo
from brdfkit.analysis.chi2 import chi2_test
from brdfkit.models._drivers import loop_driver
from brdfkit.models.disney import _principled

REFERENCE = Path(__file__).parent / "brdf_files" / "wdas" / "disney.brdf"
#: registered parameter → disney.brdf's name
NAMES = {"base_color": "baseColor", "metallic": "metallic", "subsurface": "subsurface",
         "specular": "specular", "roughness": "roughness", "specular_tint": "specularTint",
         "anisotropic": "anisotropic", "sheen": "sheen", "sheen_tint": "sheenTint",
         "clearcoat": "clearcoat", "clearcoat_gloss": "clearcoatGloss"}
FLOATS = [k for k in NAMES if k != "base_color"]


def _f32(x):
    return float(np.float32(x))


def parameter_sets(rng, n: int) -> list[dict]:
    """*n* random sets over the declared ranges (float32 values: what the GPU sees), RGB
    colours; plus the corners roughness 0 (α floored at 0.001) and every weight at 1."""
    out = []
    for _ in range(n):
        v = {k: _f32(rng.uniform(0.0, 1.0)) for k in FLOATS}
        v["base_color"] = [_f32(c) for c in rng.uniform(0.0, 1.0, 3)]
        out.append(v)
    out.append({**{k: 1.0 for k in FLOATS}, "roughness": 0.0, "base_color": [0.9, 0.5, 0.1]})
    out.append({**{k: 0.0 for k in FLOATS}, "base_color": [0.0, 0.0, 0.0]})
    return out


def upper(rng, n, lo=0.0):
    z = rng.uniform(lo, 1.0, n)
    ph = rng.uniform(0.0, 2.0 * math.pi, n)
    s = np.sqrt(1.0 - z * z)
    return np.stack([s * np.cos(ph), s * np.sin(ph), z], -1)


def ref_params(v: dict) -> dict:
    return {NAMES[k]: x for k, x in v.items()}


# --------------------------------------------------------------------------- Mesa's GLSL
def conditioning(wi, wo, v, f, eps):
    """How much the reference's own rounding (unit roundoff *eps*: 2⁻²⁴ in Mesa's float32,
    2⁻⁵³ in the float64 translation) moves its value, beyond a relative 1e-5 or 1e-13,
    where no input perturbation sees it (absolute, (N, 1)):

    - its GTR1 forms 1 + (a² − 1) cos²θ_h, which cancels to a² cos²θ_h + sin²θ_h near the
      mirror: an error of a few ulps of 1 (cos θ_h from normalize() is itself ~3 ulp off),
      so D_r errs by ~8 eps/(1 + (a² − 1) cos²θ_h) relative — up to 1.3e-4 in float32 for
      a = 0.035 (measured: 4.1e-5 in f at a near-mirror pair; cos θ_h is stationary at the
      peak, so perturbing the directions does not show it);
    - black with F₀ = 0 (the corner set), f is Schlick's weight (1 − cos θ_d)⁵ times D G
      alone, and 1 − cos θ_d (cos θ_d = L·normalize(L + V)) errs by a few ulps of 1:
      5·8 eps/(1 − cos θ_d) relative in f (measured in float32: 3.2e-5 at cos θ_d = 0.983,
      4 % at 0.99998 where f = 2e-31).
    """
    h = wi + wo
    cos_h = h[:, 2] / np.linalg.norm(h, axis=-1)
    g = v["clearcoat_gloss"]
    a = 0.1 * (1.0 - g) + 0.001 * g
    coat = (0.25 * v["clearcoat"] * gtr1(cos_h, a) * schlick(0.04, cos_d(wi, wo))
            * smith_ggx_over_2cos(wi[:, 2], 0.25) * smith_ggx_over_2cos(wo[:, 2], 0.25))
    out = (coat * 8.0 * eps / (1.0 + (a * a - 1.0) * cos_h ** 2))[:, None]
    if v["base_color"] == [0.0, 0.0, 0.0]:
        out = out + np.abs(f) * (40.0 * eps / np.maximum(1.0 - cos_d(wi, wo), 1e-30))[:, None]
    return out


def test_against_the_reference_glsl_in_mesa(rng):
    mesa_error = ref.unavailable_reason()
    if mesa_error:
        pytest.skip(mesa_error)
    glsl = ref.GlslBRDF(REFERENCE)
    worst, worst_rel, rels = 0.0, 0.0, []
    for v in parameter_sets(rng, 14):
        wi = ref.as_float32(ref.random_directions(rng, 2000))
        wo = ref.as_float32(ref.random_directions(rng, 2000))
        ours = brdfkit.model("disney", **v).eval(wi, wo)
        gpu = glsl(wi, wo, **ref_params(v)).astype(np.float64)
        spread = (ref.perturbation_spread(glsl, wi, wo, **ref_params(v))
                  + conditioning(wi, wo, v, gpu, 2.0 ** -24) / ref.SPREAD_FACTOR)
        ratio = ref.worst_ratio(ours, gpu, spread)
        assert ratio <= 1.0, f"{v}: worst |brdfkit − Mesa| / float32 bound = {ratio:.3g}"
        worst = max(worst, ratio)
        if v["base_color"] != [0.0, 0.0, 0.0]:
            rel = np.abs(ours - gpu) / np.maximum(np.abs(ours), np.abs(gpu))
            worst_rel = max(worst_rel, float(np.max(rel)))
            rels.append(rel.ravel())
    print(f"disney vs Mesa disney.brdf: worst ratio to the float32 bound {worst:.3g}, "
          f"relative difference max {worst_rel:.3g}, median "
          f"{float(np.median(np.concatenate(rels))):.3g} (but the black corner)")


# --------------------------------------------------------------------------- translator
def test_against_the_reference_through_the_translator(rng):
    worst = 0.0
    for v in parameter_sets(rng, 20):
        wi, wo = upper(rng, 4000, 1e-3), upper(rng, 4000, 1e-3)
        ours = brdfkit.model("disney", **v).eval(wi, wo)
        theirs = brdfkit.model(str(REFERENCE), **ref_params(v)).eval(wi, wo)
        # float64 against float64 with the operations in another order (|s|/2 for L·H, one
        # division per term): 1e-13 relative (~450 ulp) plus the reference's conditioning
        bound = 1e-13 * np.abs(theirs) + conditioning(wi, wo, v, theirs, 2.0 ** -53) + 1e-300
        ratio = float(np.max(np.abs(ours - theirs) / bound))
        assert ratio <= 1.0, f"{v}: worst |brdfkit − translated| / bound = {ratio:.3g}"
        if v["base_color"] != [0.0, 0.0, 0.0]:
            worst = max(worst, float(np.max(np.abs(ours - theirs) / np.abs(theirs))))
    print(f"disney vs translated disney.brdf: max relative difference {worst:.3g} (but the "
          "black corner)")


def test_rgb_pass_is_the_per_channel_kernel(rng):
    # model.eval runs the "rgb" loop (shared terms once); the albedo engine, pumping and the
    # Mitsuba bridge run the per-channel kernel: the same operations, so bit-equal
    m = brdfkit.model("disney", base_color=[0.2, 0.5, 0.8], specular_tint=0.6, sheen=0.7,
                      clearcoat=0.4, anisotropic=0.5, subsurface=0.3, roughness=0.35)
    wi, wo = upper(rng, 5001), upper(rng, 5001)
    out = np.empty((5001, 3))
    loop_driver(_principled, loop="vector")(wi, wo, m.packed.copy(), out)
    assert np.array_equal(m.eval(wi, wo), out)


# --------------------------------------------------------------------------- limits
def schlick(f0, c):
    return f0 + (1.0 - f0) * (1.0 - c) ** 5


def cos_d(wi, wo):
    h = wi + wo
    return np.sum(wi * h, -1) / np.linalg.norm(h, axis=-1)


@pytest.mark.parametrize("roughness", [0.1, 0.45, 0.9])
def test_metal_is_ggx_with_schlick(roughness, rng):
    # metallic = 1: no diffuse, sheen or coat, F₀ = C_d = base_color^2.2 (Burley's
    # metallic), α = roughness², D_GTR2 = GGX, Smith G = Walter's GGX G₁G₁
    c = np.array([0.9, 0.6, 0.3])
    m = brdfkit.model("disney", base_color=c.tolist(), metallic=1.0, specular=0.0,
                      roughness=roughness)
    ggx = brdfkit.model("microfacet", distribution="ggx", alpha=roughness ** 2)
    wi, wo = upper(rng, 3000, 1e-3), upper(rng, 3000, 1e-3)
    want = ggx.eval(wi, wo)[:, None] * schlick(c ** 2.2, cos_d(wi, wo)[:, None])
    np.testing.assert_allclose(m.eval(wi, wo), want, rtol=1e-12, atol=0)


def heitz_aniso_ggx(wi, wo, ax, ay):
    """D G₁G₁/(4 cos cos) with Heitz 2014's anisotropic GGX: D eq. (86), Λ eq. (77) with
    α(ω)² = α_x² cos²φ + α_y² sin²φ (eq. 80)."""
    h = wi + wo
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    d = 1.0 / (np.pi * ax * ay * ((h[:, 0] / ax) ** 2 + (h[:, 1] / ay) ** 2 + h[:, 2] ** 2) ** 2)

    def g1(w):
        tan2 = (w[:, 0] ** 2 + w[:, 1] ** 2) / w[:, 2] ** 2
        a2 = (ax ** 2 * w[:, 0] ** 2 + ay ** 2 * w[:, 1] ** 2) / (w[:, 0] ** 2 + w[:, 1] ** 2)
        lam = 0.5 * (np.sqrt(1.0 + a2 * tan2) - 1.0)
        return 1.0 / (1.0 + lam)

    return d * g1(wi) * g1(wo) / (4.0 * wi[:, 2] * wo[:, 2])


@pytest.mark.parametrize("anisotropic", [0.4, 1.0])
def test_anisotropic_metal_is_heitz_ggx(anisotropic, rng):
    # α_x = α/aspect acts along the tangent x (brdfkit's frame), α_y = α·aspect
    r = 0.6
    aspect = math.sqrt(1.0 - 0.9 * anisotropic)
    ax, ay = r * r / aspect, r * r * aspect
    m = brdfkit.model("disney", base_color=1.0, metallic=1.0, roughness=r,
                      anisotropic=anisotropic)
    assert m.isotropic is False
    wi, wo = upper(rng, 3000, 1e-2), upper(rng, 3000, 1e-2)
    np.testing.assert_allclose(m.eval(wi, wo), heitz_aniso_ggx(wi, wo, ax, ay), rtol=1e-11)
    # the lobe is wider along x: swapping x and y of both directions changes f
    swapped = m.eval(wi[:, [1, 0, 2]], wo[:, [1, 0, 2]])
    assert np.max(np.abs(swapped - m.eval(wi, wo)) / m.eval(wi, wo)) > 0.1


def gtr1(cos_h, a):
    """Burley's normalised GTR with γ = 1 (the clearcoat's D), its 1 + (a² − 1) cos²θ_h
    written a² cos²θ_h + sin²θ_h (no cancellation at the peak of a sharp coat)."""
    a2 = a * a
    return (a2 - 1.0) / (np.pi * np.log(a2) * (a2 * cos_h ** 2 + (1.0 - cos_h ** 2)))


def smith_ggx_over_2cos(c, alpha):
    """Walter's GGX G₁/(2 cos θ) = 1/(cos θ + √(α² + cos²θ − α² cos²θ))."""
    return 1.0 / (c + np.sqrt(alpha ** 2 + c * c - alpha ** 2 * c * c))


@pytest.mark.parametrize("gloss", [0.0, 0.5, 1.0])
def test_clearcoat_alone(gloss, rng):
    # f(coat = 1) − f(coat = 0) = ¼ G_r F_r D_r: a = mix(0.1, 0.001, gloss), F₀ = 0.04,
    # Smith GGX with α = 0.25
    kw = {"base_color": [0.3, 0.4, 0.5], "roughness": 0.4, "clearcoat_gloss": gloss}
    on, off = (brdfkit.model("disney", clearcoat=c, **kw) for c in (1.0, 0.0))
    wi, wo = upper(rng, 3000, 1e-2), upper(rng, 3000, 1e-2)
    h = wi + wo
    cos_h = h[:, 2] / np.linalg.norm(h, axis=-1)
    a = 0.1 * (1.0 - gloss) + 0.001 * gloss
    coat = (0.25 * gtr1(cos_h, a) * schlick(0.04, cos_d(wi, wo))
            * smith_ggx_over_2cos(wi[:, 2], 0.25) * smith_ggx_over_2cos(wo[:, 2], 0.25))
    f_on = on.eval(wi, wo)
    np.testing.assert_allclose(f_on - off.eval(wi, wo), coat[:, None] * np.ones(3),
                               rtol=0, atol=1e-13 * float(np.max(f_on)))


def test_sheen_and_subsurface_terms(rng):
    # sheen: (1 − metallic) sheen C_sheen (1 − cos θ_d)⁵, C_sheen = mix(1, C_d/lum, tint);
    # subsurface: f is linear in it, f(1) − f(0) = (1 − m) C_d/π (f_ss − f_d)
    c = np.array([0.8, 0.5, 0.2])
    c_d = c ** 2.2
    lum = 0.3 * c_d[0] + 0.6 * c_d[1] + 0.1 * c_d[2]  # disney.brdf's luminance weights
    kw = {"base_color": c.tolist(), "metallic": 0.25, "roughness": 0.7, "sheen_tint": 0.4}
    wi, wo = upper(rng, 3000, 1e-2), upper(rng, 3000, 1e-2)
    fh = (1.0 - cos_d(wi, wo)) ** 5
    c_sheen = 0.6 + 0.4 * c_d / lum
    got = (brdfkit.model("disney", sheen=1.0, **kw).eval(wi, wo)
           - brdfkit.model("disney", sheen=0.0, **kw).eval(wi, wo))
    np.testing.assert_allclose(got, 0.75 * fh[:, None] * c_sheen, rtol=1e-10, atol=1e-15)
    f = {t: brdfkit.model("disney", subsurface=t, **kw).eval(wi, wo) for t in (0.0, 0.3, 1.0)}
    np.testing.assert_allclose(f[0.3], 0.7 * f[0.0] + 0.3 * f[1.0], rtol=1e-12)
    nl, nv, cd2 = wi[:, 2], wo[:, 2], cos_d(wi, wo) ** 2
    fl, fv = (1 - nl) ** 5, (1 - nv) ** 5
    f_d = (1 + (0.5 + 2 * cd2 * 0.7 - 1) * fl) * (1 + (0.5 + 2 * cd2 * 0.7 - 1) * fv)
    f_ss = (1 + (cd2 * 0.7 - 1) * fl) * (1 + (cd2 * 0.7 - 1) * fv)
    ss = 1.25 * (f_ss * (1.0 / (nl + nv) - 0.5) + 0.5)
    np.testing.assert_allclose(f[1.0] - f[0.0], 0.75 * c_d / np.pi * (ss - f_d)[:, None],
                               rtol=1e-9, atol=1e-14)


def test_tint_uses_the_references_luminance_and_parameters_are_checked():
    m = brdfkit.model("disney", base_color=[0.9, 0.2, 0.4], specular_tint=1.0)
    c_d = np.array([0.9, 0.2, 0.4]) ** 2.2
    tint = c_d / (0.3 * c_d[0] + 0.6 * c_d[1] + 0.1 * c_d[2])
    np.testing.assert_allclose(m.packed[:, 2], 0.08 * 0.5 * tint, rtol=1e-15)
    assert brdfkit.model("disney", base_color=[0.0, 0.0, 0.0], specular_tint=1.0).packed[0, 2] \
        == pytest.approx(0.04)  # lum = 0: C_tint = 1
    with pytest.raises(brdfkit.errors.ParameterError, match="'base_color' must be one value"):
        brdfkit.model("disney", base_color=[0.5, 0.5])
    with pytest.raises(brdfkit.errors.ParameterError, match="'roughness'.*1.5"):
        brdfkit.model("disney", roughness=1.5)
    assert brdfkit.model("disney").isotropic and brdfkit.model("principled").name == "disney"


# --------------------------------------------------------------------------- albedo
def burley_numpy(wi, wo, *, rho, roughness, specular, metallic=0.0):
    """disney.brdf's diffuse and specular for a grey base, sheen = clearcoat =
    subsurface = anisotropic = 0, written here in NumPy: (diffuse, specular)."""
    nl, nv = wi[..., 2], wo[..., 2]
    h = wi + wo
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    nh, lh = h[..., 2], np.sum(wi * h, -1)
    fl, fv = (1 - nl) ** 5, (1 - nv) ** 5
    fd90 = 0.5 + 2 * lh * lh * roughness
    c_d = rho ** 2.2
    diffuse = (1 - metallic) * c_d / np.pi * (1 + (fd90 - 1) * fl) * (1 + (fd90 - 1) * fv)
    a = max(0.001, roughness ** 2)
    d = a * a / (np.pi * (1 + (a * a - 1) * nh * nh) ** 2)
    f0 = 0.08 * specular * (1 - metallic) + c_d * metallic
    spec = (d * schlick(f0, lh) * smith_ggx_over_2cos(nl, a) * smith_ggx_over_2cos(nv, a))
    return diffuse, spec


def quadrature_albedo(theta, n_mu=160, n_phi=128, **kw):
    """∫ f cos θ_o dω_o by Gauss–Legendre in cos θ_o × the trapezoid rule in φ_o (periodic)."""
    x, w = np.polynomial.legendre.leggauss(n_mu)
    mu, w_mu = 0.5 * (x + 1.0), 0.5 * w
    phi = np.arange(n_phi) * 2.0 * np.pi / n_phi
    m, p = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt(1.0 - m * m)
    wo = np.stack([s * np.cos(p), s * np.sin(p), m], -1)
    wi = np.array([math.sin(theta), 0.0, math.cos(theta)])
    d, sp = burley_numpy(np.broadcast_to(wi, wo.shape), wo, **kw)
    weight = (w_mu * mu)[:, None] * (2.0 * np.pi / n_phi)
    return float(np.sum(d * weight)), float(np.sum(sp * weight))


def test_albedo_of_the_rough_white_dielectric():
    # issue 22 §3: base_color = 1, roughness = 1, metallic = specular = 0
    kw = {"rho": 1.0, "roughness": 1.0, "specular": 0.0}
    m = brdfkit.model("disney", base_color=1.0, roughness=1.0, metallic=0.0, specular=0.0)
    spec_only = brdfkit.model("disney", base_color=0.0, roughness=1.0, specular=0.0)
    theta = np.radians([0.0, 60.0, 80.0, 89.0])
    a, a_spec = albedo(m, theta), albedo(spec_only, theta)
    assert np.all(a.success) and np.all(a_spec.success)
    rows = []
    for t, total, spec in zip(theta, a.albedo, a_spec.albedo, strict=True):
        q_d, q_s = quadrature_albedo(float(t), **kw)
        assert total == pytest.approx(q_d + q_s, rel=2e-5), math.degrees(t)
        assert spec == pytest.approx(q_s, rel=2e-5, abs=1e-7), math.degrees(t)
        rows.append(f"{math.degrees(t):4.0f}°: a = {total:.6f} (diffuse {total - spec:.6f}, "
                    f"specular {spec:.6f})")
    print("disney base_color=1 roughness=1 metallic=0 specular=0:\n  " + "\n  ".join(rows))
    diffuse = a.albedo - a_spec.albedo
    # closed form at normal incidence (roughness 1, C_d = 1): f_d = 1 + (F_D90 − 1)(1 − μ)⁵
    # with F_D90 − 1 = ½ + μ (cos²θ_d = (1 + μ)/2), so a = 1 + ∫(½ + μ)(1 − μ)⁵ 2μ dμ =
    # 1 + 1/42 + 1/84 = 1 + 1/28
    assert diffuse[0] == pytest.approx(1.0 + 1.0 / 28.0, rel=1e-9)
    # the measured answer: Burley's retro-reflective diffuse alone exceeds 1 at every θ_i on
    # the rough white surface (F_D90 = ½ + 2 cos²θ_d > 1), most at grazing (1.52 at 89°)
    assert np.all(diffuse > 1.0) and np.all(np.diff(diffuse) > 0.0) and diffuse[-1] > 1.5


# --------------------------------------------------------------------------- sampling
@pytest.mark.parametrize("phi_deg", [67.0, 150.0])
@pytest.mark.parametrize("params", [
    {"anisotropic": 1.0, "roughness": 0.5, "clearcoat": 1.0, "clearcoat_gloss": 0.7},
    {"anisotropic": 0.6, "roughness": 0.3, "metallic": 1.0, "base_color": [0.9, 0.7, 0.4]},
])
def test_sampler_chi2_anisotropic_azimuths(params, phi_deg):
    m = brdfkit.model("disney", **params)
    t, p = math.radians(50.0), math.radians(phi_deg)
    wo = np.array([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)])
    r = chi2_test(m, wo, n_samples=100_000, seed=int(phi_deg), alpha=0.01, n_tests=4)
    assert r.passed, r.message
    assert r.pdf_integral <= 1.0 + 1e-3


# --------------------------------------------------------------------------- Mitsuba
def test_formulas_trace_and_a_traced_render():
    from brdfkit._dual import drjit_version

    mi = pytest.importorskip("mitsuba")
    dr = pytest.importorskip("drjit")
    from brdfkit.render.mitsuba_bridge import mitsuba_bsdf, use_variant
    from brdfkit.render.mitsuba_sphere import render_sphere_mitsuba

    m = brdfkit.model("disney", base_color=[0.8, 0.4, 0.2], roughness=0.4, sheen=0.5,
                      clearcoat=0.6, specular_tint=0.3)
    f = m.formulas()
    for fn in (f.eval, f.sample, f.pdf):
        drjit_version(fn)  # the _dual contract holds (raises otherwise)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        variant = use_variant("llvm_ad_rgb")
    if not variant.startswith("llvm"):
        pytest.skip(f"the traced route needs an llvm variant (fell back to {variant})")
    bsdf = mitsuba_bsdf(m)
    assert bsdf.traced
    rng = np.random.default_rng(5)
    view = ref.as_float32(upper(rng, 256, 0.05))
    light = ref.as_float32(upper(rng, 256, 0.05))
    si = dr.zeros(mi.SurfaceInteraction3f, 256)
    si.wi = mi.Vector3f(view.T.astype(np.float32))
    ctx, wo = mi.BSDFContext(), mi.Vector3f(light.T.astype(np.float32))
    got = np.array(bsdf.eval(ctx, si, wo)).T
    want = m.eval(light, view) * light[:, 2:3]
    np.testing.assert_allclose(got, want, rtol=2e-4, atol=1e-6 * want.max())
    np.testing.assert_allclose(np.array(bsdf.pdf(ctx, si, wo)), m.pdf(light, view), rtol=2e-4)
    u = rng.random((256, 2)).astype(np.float32)
    bs, _ = bsdf.sample(ctx, si, 0.5, mi.Point2f(u.T))
    want_wi, _ = m.sample(view, u.astype(np.float64))
    ok = want_wi[:, 2] > 0.01  # the traced sampler draws what model.sample draws
    np.testing.assert_allclose(np.array(bs.wo).T[ok], want_wi[ok], atol=5e-5)
    # its pdf at the direction it drew (the coat's a = 0.001 lobe moves 1 % between the
    # float32 and the float64 draw of the same u)
    drawn = np.array(bs.wo).T.astype(np.float64)
    drawn /= np.linalg.norm(drawn, axis=-1, keepdims=True)
    np.testing.assert_allclose(np.array(bs.pdf)[ok], m.pdf(drawn, view)[ok], rtol=2e-3)
    del bsdf
    img = render_sphere_mitsuba(m, phi_l=math.radians(30.0), ambient=0.2, size=24, spp=8)
    assert img.shape == (24, 24, 3) and np.all(np.isfinite(img))
    assert img[12, 12, 0] > img[12, 12, 2] > 0.0  # the reddish base colour
    gc.collect()
