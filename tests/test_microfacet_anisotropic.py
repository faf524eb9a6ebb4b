"""``microfacet-anisotropic``: Walter et al. 2007 eq. (20) with anisotropic GGX/Beckmann.

References, each independent of the model's code:

- a second implementation written here in *angles* from the equations (Walter 2007
  eq. 20; D of Heitz 2014 §5.3 as tan²θ_h (cos²φ_h/α_x² + sin²φ_h/α_y²); Smith Λ of
  the projected roughness α(φ) = √(cos²φ α_x² + sin²φ α_y²), Heitz §5.3, with Walter's
  eqs. 27 (erf form) and 34; the exact conductor Fresnel from complex amplitudes);
- the registered isotropic ``microfacet`` at α_x = α_y (equal to rounding: values,
  samples, pdf, albedo);
- Mitsuba 3's ``roughconductor`` with ``alpha_u``/``alpha_v`` (an external
  implementation, float32; ``llvm_ad_rgb``, skipped when that variant cannot start):
  its eval is f_r cos θ, and alpha_u acts along x (the swapped pair does not agree);
- identities of the albedo: a(θ, φ; α_x, α_y) = a(θ, φ + 90°; α_y, α_x) (a quarter turn
  of the frame swaps the axes), period π in φ (f reads h_x², h_y²), and a real
  dependence on φ;
- χ² of the sampler at incidence azimuths ≠ 0, and Mitsuba's traced BSDF built from
  the model's formulas against the NumPy model.
"""

from __future__ import annotations

import functools
import json
import math
import warnings

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.special import erf

import brdfkit
from brdfkit.analysis import albedo
from brdfkit.analysis.chi2 import chi2_test
from brdfkit.cli import main

ETA = [0.2, 0.9, 1.1]
K = [3.9, 2.4, 2.2]


def sph(theta, phi):
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi),
                     np.cos(theta)], -1)


def pairs(rng, n, spread=0.3):
    """n random pairs on the upper hemisphere, half of them near the mirror."""
    wi = sph(np.arccos(rng.uniform(0.03, 1.0, n)), rng.uniform(0, 2 * math.pi, n))
    wo = sph(np.arccos(rng.uniform(0.03, 1.0, n)), rng.uniform(0, 2 * math.pi, n))
    near = wi[: n // 2] * [-1.0, -1.0, 1.0] + rng.normal(scale=spread, size=(n // 2, 3))
    near[:, 2] = np.abs(near[:, 2]) + 0.02
    wo[: n // 2] = near / np.linalg.norm(near, axis=-1, keepdims=True)
    return wi, wo


# ------------------------------------------------------------------ the second implementation
def fresnel_conductor(c, eta, k):
    """Unpolarised reflectance of a complex index η + iκ at cos θ = c (Fresnel's amplitudes)."""
    n = np.asarray(eta, dtype=complex) + 1j * np.asarray(k, dtype=float)
    c = np.asarray(c, dtype=complex)[..., None]
    ct = np.sqrt(1.0 - (1.0 - c * c) / (n * n))
    rs = (c - n * ct) / (c + n * ct)
    rp = (n * c - ct) / (n * c + ct)
    return 0.5 * (np.abs(rs) ** 2 + np.abs(rp) ** 2)


def walter_angles(wi, wo, ax, ay, dist, eta=None, k=None):
    """f_r from the angles of h, ω_i, ω_o (module docstring); (N,) or (N, C)."""
    t_i, t_o = np.arccos(wi[:, 2]), np.arccos(wo[:, 2])
    p_i, p_o = np.arctan2(wi[:, 1], wi[:, 0]), np.arctan2(wo[:, 1], wo[:, 0])
    h = wi + wo
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    t_h = np.arctan2(np.hypot(h[:, 0], h[:, 1]), h[:, 2])
    p_h = np.arctan2(h[:, 1], h[:, 0])
    a_inv = np.cos(p_h) ** 2 / ax**2 + np.sin(p_h) ** 2 / ay**2
    tan2 = np.tan(t_h) ** 2
    if dist == "ggx":
        d = 1.0 / (math.pi * ax * ay * np.cos(t_h) ** 4 * (1.0 + tan2 * a_inv) ** 2)
    else:
        d = np.exp(-tan2 * a_inv) / (math.pi * ax * ay * np.cos(t_h) ** 4)

    def lam(t, p):
        alpha = np.sqrt(np.cos(p) ** 2 * ax**2 + np.sin(p) ** 2 * ay**2)
        a = 1.0 / (alpha * np.tan(t))
        if dist == "ggx":
            return 0.5 * (-1.0 + np.sqrt(1.0 + 1.0 / (a * a)))
        return 0.5 * (erf(a) - 1.0) + np.exp(-a * a) / (2.0 * a * math.sqrt(math.pi))

    g = 1.0 / (1.0 + lam(t_i, p_i)) / (1.0 + lam(t_o, p_o))
    f = d * g / (4.0 * np.cos(t_i) * np.cos(t_o))
    if eta is None:
        return f
    return f[:, None] * fresnel_conductor(np.sum(wi * h, -1), eta, k)


@pytest.mark.parametrize("dist", ["ggx", "beckmann"])
@pytest.mark.parametrize("ax,ay", [(0.05, 0.5), (0.6, 0.02), (0.3, 0.3), (1.2, 0.4)])
def test_against_the_angles_form(dist, ax, ay):
    rng = np.random.default_rng(int(ax * 1000 + ay * 10))
    wi, wo = pairs(rng, 4000)
    m = brdfkit.model("microfacet-anisotropic", distribution=dist, alpha_x=ax, alpha_y=ay,
                      eta=ETA, k=K)
    want = walter_angles(wi, wo, ax, ay, dist, ETA, K)
    got = m.eval(wi, wo)
    assert want.max() > 1.0  # the lobe was hit
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-14 * want.max())
    # F = 1 without eta; rho_s scales
    m1 = brdfkit.model("microfacet-anisotropic", distribution=dist, alpha_x=ax, alpha_y=ay,
                       rho_s=0.5)
    np.testing.assert_allclose(m1.eval(wi, wo), 0.5 * walter_angles(wi, wo, ax, ay, dist),
                               rtol=1e-9, atol=1e-14 * want.max())


# ------------------------------------------------------------------ = microfacet at α_x = α_y
@pytest.mark.parametrize("dist", ["ggx", "beckmann"])
@pytest.mark.parametrize("alpha", [1e-3, 0.1, 0.5, 2.0])
def test_isotropic_case_is_microfacet(dist, alpha):
    rng = np.random.default_rng(7)
    wi, wo = pairs(rng, 20000, spread=3 * alpha)
    for kw in ({}, {"eta": ETA, "k": K}):
        iso = brdfkit.model("microfacet", distribution=dist, alpha=alpha, **kw)
        ani = brdfkit.model("microfacet-anisotropic", distribution=dist, alpha_x=alpha,
                            alpha_y=alpha, **kw)
        f, g = iso.eval(wi, wo), ani.eval(wi, wo)
        assert np.array_equal(f > 0, g > 0)
        # rounding: Beckmann's exponent −tan²θ_h/α² is formed in another order (|e| ≤ 700
        # times 2^-52 relative)
        np.testing.assert_allclose(g, f, rtol=1e-12, atol=0.0)
    np.testing.assert_allclose(ani.pdf(wi, wo), iso.pdf(wi, wo), rtol=1e-12, atol=0.0)
    u = rng.random((5000, 2))
    (w1, p1), (w2, p2) = iso.sample(wo[0], u), ani.sample(wo[0], u)
    np.testing.assert_allclose(w2, w1, rtol=0.0, atol=1e-14)
    ok = p1 > 0
    np.testing.assert_allclose(p2[ok], p1[ok], rtol=1e-9)


def test_isotropic_case_albedo_is_microfacet():
    th = np.radians([0.0, 60.0, 85.0])
    iso = albedo(brdfkit.model("microfacet", distribution="ggx", alpha=0.3), th)
    ani = albedo(brdfkit.model("microfacet-anisotropic", distribution="ggx", alpha_x=0.3,
                               alpha_y=0.3), th, phi=0.7)
    assert np.all(np.abs(ani.albedo - iso.albedo) <= ani.error + iso.error + 1e-9)


# --------------------------------------------------------------------------- the incidence azimuth
def test_albedo_quarter_turn_swaps_the_axes():
    th = np.radians([30.0, 75.0])
    phi = np.radians(25.0)
    for dist in ("ggx", "beckmann"):
        a = albedo(brdfkit.model("microfacet-anisotropic", distribution=dist, alpha_x=0.1,
                                 alpha_y=0.6), th, phi=phi)
        b = albedo(brdfkit.model("microfacet-anisotropic", distribution=dist, alpha_x=0.6,
                                 alpha_y=0.1), th, phi=phi + 0.5 * math.pi)
        c = albedo(brdfkit.model("microfacet-anisotropic", distribution=dist, alpha_x=0.1,
                                 alpha_y=0.6), th, phi=phi + math.pi)  # period π
        assert np.all(np.abs(a.albedo - b.albedo) <= a.error + b.error + 1e-9)
        assert np.all(np.abs(a.albedo - c.albedo) <= a.error + c.error + 1e-9)


@functools.cache
def _gauss_legendre(n):
    return np.polynomial.legendre.leggauss(n)


def brute_albedo(m, theta, phi, n=1200):
    """∫ f cos θ_o dω_o by a product Gauss–Legendre rule in (cos θ_o, φ_o), no lobe frame
    (1200²: converged to 3e-8 here, against 2400²)."""
    x, w = _gauss_legendre(n)
    mu, ph = 0.5 * (x + 1.0), math.pi * (x + 1.0)
    M, P = np.meshgrid(mu, ph, indexing="ij")
    wo = sph(np.arccos(M), P).reshape(-1, 3)
    wi = np.broadcast_to(sph(np.float64(theta), np.float64(phi)), wo.shape)
    return float((0.5 * w) @ (m.eval(wi, wo).reshape(M.shape) * M) @ (math.pi * w))


def test_albedo_depends_on_the_azimuth():
    m = brdfkit.model("microfacet-anisotropic", distribution="ggx", alpha_x=0.05, alpha_y=0.8)
    th = math.radians(75.0)
    a0, a90 = albedo(m, [th], phi=0.0), albedo(m, [th], phi=0.5 * math.pi)
    assert a90.albedo[0] - a0.albedo[0] > 100 * (a0.error[0] + a90.error[0])  # 0.739 vs 0.627
    # the engine's φ_i is the azimuth of ω_i: the brute-force rule at ω_i(θ, φ) agrees
    assert a0.albedo[0] == pytest.approx(brute_albedo(m, th, 0.0), abs=1e-6)
    assert a90.albedo[0] == pytest.approx(brute_albedo(m, th, 0.5 * math.pi), abs=1e-6)
    assert a0.to_dict()["phi_deg"] == [0.0]
    v = brdfkit.analysis.check(m.with_params(alpha_x=0.1, alpha_y=0.3), phi=0.5 * math.pi)
    assert v.reciprocal and v.energy == "conserves" and v.max_albedo < 1.0
    assert v.to_dict()["phi_deg"] == pytest.approx(90.0)


def test_cli_phi():
    r = CliRunner()
    out = {}
    for phi in ("0", "90"):
        res = r.invoke(main, ["albedo", "microfacet-anisotropic", "-p", "distribution=ggx",
                              "-p", "alpha_x=0.05", "-p", "alpha_y=0.8", "--theta", "75",
                              "--phi", phi, "--json"])
        assert res.exit_code == 0, res.output
        out[phi] = json.loads(res.output)
    a0, a90 = out["0"]["albedo"][0], out["90"]["albedo"][0]
    assert out["90"]["phi_deg"] == 90.0 and a90 > a0 + 0.1


# --------------------------------------------------------------------------- sampler
@pytest.mark.parametrize("phi_deg", [0.0, 67.0, 135.0, 290.0])
@pytest.mark.parametrize("ex", [{"distribution": "ggx", "alpha_x": 0.05, "alpha_y": 0.5},
                                {"alpha_x": 0.6, "alpha_y": 0.02}])
def test_chi2_at_azimuths(ex, phi_deg):
    m = brdfkit.model("microfacet-anisotropic", **ex)
    wo = sph(np.radians(60.0), np.radians(phi_deg))
    r = chi2_test(m, wo, n_samples=100_000, seed=int(phi_deg) + 11, alpha=0.01, n_tests=8)
    assert r.passed, r.message


def test_distribution_objects():
    from brdfkit.models.anisotropic_distributions import anisotropic_distribution

    rng = np.random.default_rng(3)
    w = sph(np.arccos(rng.uniform(0.05, 1.0, 2000)), rng.uniform(0, 2 * math.pi, 2000))
    for kind in ("ggx", "beckmann"):
        dist = anisotropic_distribution(kind, 0.2, 0.7)
        # Λ of the projected roughness (Heitz §5.3) against the test's own Λ: the G₁ of
        # walter_angles at normal ω_o is 1/(1 + Λ(ω_i)) times D/(4 cos θ_i) … use G₁ directly
        t, p = np.arccos(w[:, 2]), np.arctan2(w[:, 1], w[:, 0])
        alpha = np.sqrt(np.cos(p) ** 2 * 0.04 + np.sin(p) ** 2 * 0.49)
        a = 1.0 / (alpha * np.tan(t))
        lam = (0.5 * (-1.0 + np.sqrt(1.0 + 1.0 / (a * a))) if kind == "ggx" else
               0.5 * (erf(a) - 1.0) + np.exp(-a * a) / (2.0 * a * math.sqrt(math.pi)))
        np.testing.assert_allclose(dist.g1(w), 1.0 / (1.0 + lam), rtol=1e-12)
        # the projected area of the microfacets is 1: ∫ D(h) cos θ_h dω_h = 1 (quadrature)
        x, wx = _gauss_legendre(400)
        th = 0.25 * math.pi * (x + 1.0)  # θ_h ∈ [0, π/2]
        ph = math.pi * (x + 1.0)
        T, P = np.meshgrid(th, ph, indexing="ij")
        val = dist.pdf(sph(T, P)) * np.sin(T)
        assert (0.25 * math.pi * math.pi) * wx @ val @ wx == pytest.approx(1.0, abs=1e-6)


def test_fresnel_split():
    m = brdfkit.model("microfacet-anisotropic", alpha_x=0.1, alpha_y=0.4, eta=ETA, k=K,
                      rho_s=0.8)
    split = m.fresnel_split()
    assert split.white.values["eta"] is None and np.all(split.white.values["rho_s"] == 1.0)
    assert split.white.fresnel_split() is None
    assert split.white.values["alpha_y"] == 0.4
    # F₀ = ρ_s F(1): the conductor reflectance ((η−1)² + κ²)/((η+1)² + κ²) at normal incidence
    e, k = np.asarray(ETA), np.asarray(K)
    np.testing.assert_allclose(split.f0, 0.8 * ((e - 1) ** 2 + k**2) / ((e + 1) ** 2 + k**2),
                               rtol=1e-12)


# --------------------------------------------------------------------------- Mitsuba 3
@pytest.fixture(scope="module")
def llvm():
    mi = pytest.importorskip("mitsuba")
    pytest.importorskip("drjit")
    from brdfkit.render.mitsuba_bridge import use_variant

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        variant = use_variant("llvm_ad_rgb")
    if not variant.startswith("llvm"):
        pytest.skip(f"needs Mitsuba's llvm_ad_rgb variant (fell back to {variant})")
    return mi


def mitsuba_eval(mi, dist, au, av, wi, wo):
    """Mitsuba's roughconductor(alpha_u, alpha_v) eval, divided by its cos θ_o."""
    import drjit as dr

    bsdf = mi.load_dict({"type": "roughconductor", "distribution": dist, "alpha_u": au,
                         "alpha_v": av, "eta": {"type": "rgb", "value": ETA},
                         "k": {"type": "rgb", "value": K}, "sample_visible": False})
    si = dr.zeros(mi.SurfaceInteraction3f, wi.shape[0])
    si.wi = mi.Vector3f(wi.T.astype(np.float32))
    v = bsdf.eval(mi.BSDFContext(), si, mi.Vector3f(wo.T.astype(np.float32)))
    return np.array(v).T / wo[:, 2:3]


def g1_ratio(w, ax, ay):
    """Mitsuba's Beckmann G₁ (Walter eq. 27's rational fit) over the exact one, of α(ω)."""
    a = w[:, 2] / np.sqrt(ax**2 * w[:, 0] ** 2 + ay**2 * w[:, 1] ** 2)
    fit = np.where(a >= 1.6, 1.0, (3.535 * a + 2.181 * a * a) / (1 + 2.276 * a + 2.577 * a * a))
    exact = 2.0 / (1.0 + erf(a) + np.exp(-a * a) / (a * math.sqrt(math.pi)))
    return fit / exact


def rel_err(ours, theirs):
    return float(np.max(np.abs(ours - theirs) / np.maximum(np.abs(theirs),
                                                          1e-6 * np.abs(theirs).max())))


@pytest.mark.parametrize("dist", ["ggx", "beckmann"])
def test_against_mitsuba_roughconductor(llvm, dist):
    mi = llvm
    rng = np.random.default_rng(5)
    wi, wo = pairs(rng, 2000)
    wi, wo = (x.astype(np.float32).astype(float) for x in (wi, wo))
    wi /= np.linalg.norm(wi, axis=-1, keepdims=True)
    wo /= np.linalg.norm(wo, axis=-1, keepdims=True)
    ax, ay = 0.08, 0.4
    ours = brdfkit.model("microfacet-anisotropic", distribution=dist, alpha_x=ax, alpha_y=ay,
                         eta=ETA, k=K).eval(wi, wo)
    theirs = mitsuba_eval(mi, dist, ax, ay, wi, wo)
    assert theirs.max() > 1.0
    if dist == "beckmann":
        ours = ours * (g1_ratio(wi, ax, ay) * g1_ratio(wo, ax, ay))[:, None]
    assert rel_err(ours, theirs) < 2e-4  # float32 (Mitsuba) against float64
    # alpha_u acts along x: the swapped pair is another BRDF
    swapped = mitsuba_eval(mi, dist, ay, ax, wi, wo)
    assert rel_err(ours, swapped) > 0.5


@pytest.mark.parametrize("name,params", [
    ("microfacet-anisotropic", {"distribution": "ggx", "alpha_x": 0.1, "alpha_y": 0.4,
                                "eta": ETA, "k": K}),
    ("microfacet-anisotropic", {"alpha_x": 0.5, "alpha_y": 0.05}),
    ("ashikhmin-shirley", {"n_u": 20.0, "n_v": 400.0, "R_s": [0.3, 0.2, 0.1]}),
])
def test_traced_bsdf_is_the_model(llvm, name, params):
    """The Mitsuba bridge traces the model's formulas: eval, pdf and the samples' pdf."""
    mi = llvm
    import drjit as dr

    from brdfkit.render.mitsuba_bridge import mitsuba_bsdf

    model = brdfkit.model(name, **params)
    bsdf = mitsuba_bsdf(model, route="traced")
    assert bsdf.traced
    rng = np.random.default_rng(9)
    light, view = pairs(rng, 256, spread=0.2)
    light, view = (x.astype(np.float32).astype(float) for x in (light, view))
    si = dr.zeros(mi.SurfaceInteraction3f, 256)
    si.wi = mi.Vector3f(view.T.astype(np.float32))
    ctx, wo = mi.BSDFContext(), mi.Vector3f(light.T.astype(np.float32))
    want = np.broadcast_to(np.asarray(model.eval(light, view)).reshape(256, -1), (256, 3))
    want = want * light[:, 2:3]
    np.testing.assert_allclose(np.array(bsdf.eval(ctx, si, wo)).T, want, rtol=2e-4,
                               atol=1e-6 * want.max())
    np.testing.assert_allclose(np.array(bsdf.pdf(ctx, si, wo)), model.pdf(light, view),
                               rtol=2e-4, atol=1e-6)
    u = rng.random((256, 2)).astype(np.float32)
    bs, _ = bsdf.sample(ctx, si, 0.5, mi.Point2f(u.T))
    got = np.array(bs.wo).T
    ok = got[:, 2] > 1e-3
    np.testing.assert_allclose(np.array(bs.pdf)[ok], model.pdf(got[ok], view[ok]), rtol=2e-3)
    if name == "microfacet-anisotropic":  # the same formula draws the same directions
        want_wi, _ = model.sample(view, u.astype(float))
        np.testing.assert_allclose(got, want_wi, atol=5e-5)
