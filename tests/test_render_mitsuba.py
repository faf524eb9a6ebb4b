"""Evidence for the Mitsuba 3 bridge (issue 11 §3 and the Mitsuba part of §5).

References, each independent of the code under test:

- **Direction mapping** (non-reciprocal Lewis Phong, f(L, V) ≠ f(V, L)): Mitsuba's
  documented convention (``BSDF.eval(ctx, si, wo)``: ``si.wi`` toward the viewer, ``wo``
  the sampled/light direction, f·cos θ_wo) against brdfkit's (``eval(wi=L, wo=V)``).
- **Sphere pixels**: the closed-form radiance of the sphere test configuration,
  E·f_r(L, V)·max(N·L, 0) + L_a·ρ(V), written out here (geometry: unit sphere, V = +z,
  pixel centres of issue 11 §1) and averaged over each pixel's area (Mitsuba's box
  filter) by 8×8 sub-pixel midpoints; ρ(V) = ∫ f_r(L′, V) cos θ_L′ dω_L′ from the
  deterministic albedo engine (``brdfkit.analysis.albedo``, a quadrature, not Monte
  Carlo), interpolated from 65 angles. f_r itself is ``model.eval``: what is tested is
  the renderer (sampling, geometry, mapping), not the formula.
- **White furnace** (Neumann et al. 1999, §2: under a uniform sky the image *is* the
  albedo): the same with E = 0, L_a = 1, for modified Phong and pumped modified Phong.
- **Bridge vs native**: Mitsuba's own ``roughconductor`` (GGX, same α, η, k; Walter et
  al. 2007, the formula brdfkit's ``microfacet`` implements, checked pointwise in
  tests/test_mitsuba_crosscheck.py) and ``diffuse``, same scene, different samplers.
- **Spectral vs RGB**: a grey model reflects every wavelength alike, so the spectral
  render under D65 light develops to the RGB render times D65's sRGB, which is white
  (sRGB's white point is D65; measured in Mitsuba 3.9.1: 1 ± 2e-4 per channel).
- **Sampling**: Mitsuba's own χ² harness (``mitsuba.chi2.ChiSquareTest``) on the
  plugin's ``sample``/``pdf``.
- **Traced route** (``microfacet``'s formulas rebound to Dr.Jit): pointwise against
  Mitsuba's ``roughconductor`` ``eval`` (GGX: the same Walter et al. 2007 formulas, an
  external implementation) and against the Numba compilation of the same formulas
  (two compilers, one code: equal to float32 rounding); the image tests above
  (``roughconductor`` comparisons, RGB and spectral) take this route.

Noise model (all image comparisons): K independent renders (different seeds) of spp
samples per pixel; each pixel's K values are i.i.d. around the pixel's expectation, and
pixels are independent. The statistics are the sums, over each 4×4 block of pixels and
over the whole image, of the per-pixel differences of the means (to the exact value, or
between two renderers); their variance is the sum of the per-pixel variances of the
means (estimated from the K renders), with Welch–Satterthwaite degrees of freedom, so
each is a t statistic with many degrees of freedom. All blocks plus the whole image form
a family that must pass at level α = 1e-3 with the Šidák bound (each test at
1 − (1 − α)^(1/M)). Pixels whose square crosses the silhouette are left out (the 8×8
midpoint reference resolves a partly covered square only to ~1/16 of its value); pixels
whose K values are all equal (constant 0) must match exactly. Each image test also
checks its power: the same family rejects a plausible mistake (a factor 1.05, the
swapped directions, the mirrored image).
"""

from __future__ import annotations

import gc
import json
import math

import numpy as np
import pytest
from scipy import stats

import brdfkit
from brdfkit.analysis import albedo
from brdfkit.models import DerivedBRDF
from brdfkit.pumping import pump

mi = pytest.importorskip("mitsuba")
dr = pytest.importorskip("drjit")

from traced_helpers import float32_hemisphere as _hemisphere  # noqa: E402
from traced_helpers import mitsuba_chi2  # noqa: E402
from traced_helpers import variant as _variant  # noqa: E402

from brdfkit.render.mitsuba_bridge import (  # noqa: E402
    WavefrontRouteWarning,
    mitsuba_bsdf,
    spectral_model,
    use_variant,
    wavefront,
)
from brdfkit.render.mitsuba_sphere import render_sphere_mitsuba, sphere_scene  # noqa: E402

ALPHA_FAMILY = 1e-3
SUB = 8  # sub-pixel midpoints per axis of the area-averaged reference
BLOCK = 4  # pixels per side of the blocks the t-tests sum over


def _budget(variant: str) -> tuple[int, int, int]:
    """(size, spp, K): small enough for the scalar fallback (one Python call per vertex)."""
    return (8, 8, 6) if variant.startswith("scalar") else (24, 16, 6)


# --------------------------------------------------------------------------- references
def _frames(n: np.ndarray):
    """Tangent frames (t, b, n) around normals n (..., 3): any frame suits isotropic models."""
    a = np.where(np.abs(n[..., :1]) < 0.9, np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
    t = np.cross(a, n)
    t /= np.linalg.norm(t, axis=-1, keepdims=True)
    return t, np.cross(n, t)


def _to_local(w, t, b, n):
    return np.stack([(w * t).sum(-1), (w * b).sum(-1), (w * n).sum(-1)], axis=-1)


def exact_sphere(model, *, phi_l, irradiance, ambient, size, rho_of_view):
    """Pixel-area averages of E f(L,V) max(N·L,0) + L_a ρ(V) (module docstring), (S,S,C),
    and the mask of pixels whose square lies entirely inside or outside the disc."""
    k = (np.arange(size * SUB) + 0.5) / (size * SUB)
    x = 2.0 * k - 1.0
    y = 1.0 - 2.0 * k
    X, Y = np.meshgrid(x, y)  # row index ↔ y decreasing, column ↔ x increasing
    r2 = X * X + Y * Y
    inside = r2 < 1.0
    n = np.stack([X, Y, np.sqrt(np.clip(1.0 - r2, 0.0, None))], axis=-1)[inside]
    t, b, n = *_frames(n), n
    light = np.array([math.sin(phi_l), 0.0, math.cos(phi_l)])
    view = np.array([0.0, 0.0, 1.0])
    ll = _to_local(np.broadcast_to(light, n.shape), t, b, n)
    vl = _to_local(np.broadcast_to(view, n.shape), t, b, n)
    vl /= np.linalg.norm(vl, axis=-1, keepdims=True)
    ll /= np.linalg.norm(ll, axis=-1, keepdims=True)
    value = np.zeros(n.shape[0])
    lit = ll[:, 2] > 0.0
    if irradiance > 0.0:
        value[lit] = irradiance * model.eval(ll[lit], vl[lit]) * ll[lit, 2]
    if ambient > 0.0:
        value += ambient * rho_of_view(np.arccos(np.clip(vl[:, 2], 0.0, 1.0)))
    full = np.zeros(X.shape)
    full[inside] = value
    img = full.reshape(size, SUB, size, SUB).mean(axis=(1, 3))
    cov = inside.reshape(size, SUB, size, SUB).mean(axis=(1, 3))
    # whole squares only: the corners farthest from/closest to the centre on one side
    c = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    cx, cy = np.meshgrid(c, -c)
    h = 1.0 / size
    far = np.hypot(np.abs(cx) + h, np.abs(cy) + h)
    near = np.hypot(np.maximum(np.abs(cx) - h, 0.0), np.maximum(np.abs(cy) - h, 0.0))
    whole = (far < 1.0) | (near > 1.0)
    assert np.all(cov[whole] % 1.0 == 0.0)
    return img, whole


def rho_table(model, *, swap: bool = False):
    """θ_V ↦ ρ(V) = ∫ f(L′, V) cos θ_L′ dω_L′, by the albedo engine on 129 angles.

    For a reciprocal model ρ is the albedo at θ_V; otherwise the engine integrates the
    swapped callable f(wi, wo) := model.eval(wo, wi) over its wo (= L′)."""
    theta = np.linspace(0.0, math.radians(89.9), 65)
    f = (lambda wi, wo: model.eval(wo, wi)) if swap else model
    res = albedo(f, theta, tol=1e-8)
    assert res.success
    return lambda th: np.interp(th, theta, res.albedo)


def renders(model_or_bsdf, *, variant, size, spp, k, phi_l=0.0, irradiance=1.0, ambient=0.0,
            seed0=0):
    """K renders (K, S, S, C) of the sphere configuration through Mitsuba, seeds seed0…"""
    if isinstance(model_or_bsdf, dict):
        scene = mi.load_dict(sphere_scene(model_or_bsdf, phi_l=phi_l, irradiance=irradiance,
                                          ambient=ambient, size=size, variant=variant))
        with wavefront():
            out = np.stack([np.array(mi.render(scene, spp=spp, seed=seed0 + j))
                            for j in range(k)])
        del scene
        gc.collect()
        return out
    return np.stack([render_sphere_mitsuba(model_or_bsdf, phi_l=phi_l, irradiance=irradiance,
                                           ambient=ambient, size=size, spp=spp,
                                           seed=seed0 + j, variant=variant)
                     for j in range(k)])


def worst_p(a: np.ndarray, ref: np.ndarray | None = None, b: np.ndarray | None = None,
            mask: np.ndarray | None = None) -> tuple[float, float]:
    """(smallest two-sided p-value, Šidák per-test level) of the block and global t-tests.

    a, b: (K, S, S, C) independent renders; ref: (S, S, C) exact values. The tests are
    on the sums over each BLOCK×BLOCK block of pixels (and over the whole image) of the
    per-pixel mean differences; their variance is the sum of the per-pixel variances of
    the means (pixels are independent), with Welch–Satterthwaite degrees of freedom.
    """
    k = a.shape[0]
    m = np.ones(a.shape[1:], bool) if mask is None else np.broadcast_to(
        mask[..., None], a.shape[1:])
    ua = a.var(0, ddof=1) / k  # variance of the per-pixel mean
    d = a.mean(0) - (ref if b is None else b.mean(0))
    parts = [(ua, k - 1)]
    if b is not None:
        parts.append((b.var(0, ddof=1) / b.shape[0], b.shape[0] - 1))
    se2 = sum(u for u, _ in parts)
    const = m & (se2 == 0.0)
    assert np.allclose(d[const], 0.0, atol=1e-6), "constant pixels differ"
    d = np.where(m, d, 0.0)
    size = a.shape[1]
    nb = size // BLOCK

    def blocks(x):
        x = x[:nb * BLOCK, :nb * BLOCK]
        return x.reshape(nb, BLOCK, nb, BLOCK, -1).sum(axis=(1, 3)).reshape(-1)

    sums = [blocks(d)] + [np.array([d.sum()])]
    var = [blocks(np.where(m, se2, 0.0))] + [np.array([np.where(m, se2, 0.0).sum()])]
    dof_den = [sum(blocks(np.where(m, u * u / f, 0.0)) for u, f in parts)]
    dof_den.append(np.array([sum(np.where(m, u * u / f, 0.0).sum() for u, f in parts)]))
    s_, v_, dd = (np.concatenate(x) for x in (sums, var, dof_den))
    test = v_ > 0.0
    t = s_[test] / np.sqrt(v_[test])
    dof = v_[test] ** 2 / dd[test]
    p = 2.0 * stats.t.sf(np.abs(t), dof)
    level = 1.0 - (1.0 - ALPHA_FAMILY) ** (1.0 / test.sum())
    return float(p.min()), level


# --------------------------------------------------------------------------- tests
def test_direction_mapping_non_reciprocal():
    """eval/pdf/sample of the bridge against brdfkit's eval(wi=L, wo=V) for Lewis's Phong."""
    variant = _variant("llvm_ad_rgb")
    model = brdfkit.model("phong", k_d=0.1, k_s=0.3, n=10.0)
    bsdf = mitsuba_bsdf(model)
    rng = np.random.default_rng(7)
    n = 1 if variant.startswith("scalar") else 64
    z = rng.uniform(0.2, 1.0, (2, n))
    ph = rng.uniform(0, 2 * math.pi, (2, n))
    s = np.sqrt(1 - z * z)
    view = np.stack([s[0] * np.cos(ph[0]), s[0] * np.sin(ph[0]), z[0]], -1)
    light = np.stack([s[1] * np.cos(ph[1]), s[1] * np.sin(ph[1]), z[1]], -1)
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.wi = mi.Vector3f(*view[0]) if n == 1 else mi.Vector3f(view.T.astype(np.float32))
    wo = mi.Vector3f(*light[0]) if n == 1 else mi.Vector3f(light.T.astype(np.float32))
    ctx = mi.BSDFContext()
    got = np.array(bsdf.eval(ctx, si, wo)).reshape(3, -1)[0]
    want = model.eval(light, view) * light[:, 2]
    swapped = model.eval(view, light) * light[:, 2]
    np.testing.assert_allclose(got, want, rtol=2e-5)  # float32 directions
    assert np.max(np.abs(swapped - want) / want) > 0.1  # the test can tell the two apart
    pdf = np.array(bsdf.pdf(ctx, si, wo)).reshape(-1)
    np.testing.assert_allclose(pdf, model.pdf(light, view), rtol=2e-5)
    # sample: weight = f cos / pdf at the returned direction
    u = rng.random((n, 2))
    bs, w = bsdf.sample(ctx, si, 0.5, mi.Point2f(*u[0]) if n == 1 else
                        mi.Point2f(u.T.astype(np.float32)))
    wl = np.array(bs.wo, dtype=np.float64).reshape(3, -1).T
    ok = np.array(bs.pdf).reshape(-1) > 0
    ref = model.eval(wl[ok], view[ok]) * wl[ok, 2] / model.pdf(wl[ok], view[ok])
    np.testing.assert_allclose(np.array(w).reshape(3, -1)[0][ok], ref, rtol=1e-4)
    del bsdf
    gc.collect()


@pytest.mark.parametrize("props,wi", [
    ({"model": "modified-phong", "rho_d": 0.3, "rho_s": 0.6, "n": 20.0}, [0.6, 0.0, 0.8]),
    # the parameters of the roughconductor comparison below (one compiled kernel for both)
    ({"model": "microfacet", "distribution": "ggx", "alpha": 0.3, "eta": "0.2, 0.9, 1.1",
      "k": "3.9, 2.4, 2.2"}, [0.48, 0.0, 0.877]),
    ({"model": "phong", "k_d": 0.1, "k_s": 0.3, "n": 10.0}, [0.0, 0.6, 0.8]),
    # the traced route's Beckmann sampler (GGX: the entry above, also traced). Not α = 0.2:
    # there, at res 51, Mitsuba's own roughconductor (Beckmann, sample_visible false) is
    # rejected by this harness with the same p-values (it draws the same directions), a
    # resolution limit of the harness's pdf integration, measured
    ({"model": "microfacet", "alpha": 0.5, "eta": 1.5}, [0.0, 0.8, 0.6]),
])
def test_chi2_mitsuba_harness(props, wi):
    """Mitsuba's own χ² goodness-of-fit test of the plugin's sample() against its pdf()."""
    _variant("llvm_ad_rgb")
    mitsuba_chi2(props, wi)


def test_sphere_against_exact_non_reciprocal():
    """Directional light + ambient, Lewis's Phong (non-reciprocal): the renderer's image
    against the closed form; the swapped mapping f(V, L) is rejected by the same test."""
    variant = _variant("llvm_ad_rgb")
    size, spp, k = _budget(variant)
    # a broad lobe (n = 3): f(L, V) and f(V, L) differ by N·L/N·V away from the peak
    model = brdfkit.model("phong", k_d=0.05, k_s=0.5, n=3.0)
    phi_l, e, la = math.radians(45.0), 1.0, 0.25
    imgs = renders(model, variant=variant, size=size, spp=spp, k=k, phi_l=phi_l,
                   irradiance=e, ambient=la)
    ref, whole = exact_sphere(model, phi_l=phi_l, irradiance=e, ambient=la, size=size,
                              rho_of_view=rho_table(model, swap=True))
    p, level = worst_p(imgs, ref[..., None], mask=whole)
    assert p > level, (p, level)
    # power: the image with f(L, V) and f(V, L) exchanged (both in the direct and ambient
    # terms: the mistake a swapped mapping would make) is rejected
    wrong, _ = exact_sphere(_Swapped(model), phi_l=phi_l, irradiance=e, ambient=la,
                            size=size, rho_of_view=rho_table(model))
    assert worst_p(imgs, wrong[..., None], mask=whole)[0] < level
    # orientation: the reference mirrored left-right (light from −x) is rejected
    assert worst_p(imgs, ref[:, ::-1, None], mask=whole & whole[:, ::-1])[0] < level


class _Swapped:
    """model with its directions exchanged: eval(L, V) := model.eval(V, L)."""

    def __init__(self, model):
        self.model = model

    def eval(self, wi, wo):
        return self.model.eval(wo, wi)


@pytest.mark.parametrize("pumped", [False, True, "kulla-conty"],
                         ids=["phong", "pumped-phong", "compensated-phong"])
def test_white_furnace(pumped):
    """Uniform sky only (L_a = 1, E = 0): every pixel shows the albedo at its view angle
    (the Kulla–Conty compensated Phong, its own white form: 1 everywhere)."""
    variant = _variant("llvm_ad_rgb")
    size, spp, k = _budget(variant)
    model = brdfkit.model("modified-phong", rho_d=0.2, rho_s=0.5, n=20.0)
    if pumped == "kulla-conty":
        model = brdfkit.compensate(model, "kulla-conty")
        assert mitsuba_bsdf(model).traced  # its formulas (the wavefront route before)
    elif pumped:
        model = pump(model, g="max")
    imgs = renders(model, variant=variant, size=size, spp=spp, k=k, irradiance=0.0,
                   ambient=1.0, seed0=100)
    ref, whole = exact_sphere(model, phi_l=0.0, irradiance=0.0, ambient=1.0, size=size,
                              rho_of_view=rho_table(model))
    p, level = worst_p(imgs, ref[..., None], mask=whole)
    assert p > level, (p, level)
    assert worst_p(imgs, 1.05 * ref[..., None], mask=whole)[0] < level  # power


def test_bridge_vs_native_roughconductor_and_diffuse():
    """brdfkit microfacet (GGX) vs Mitsuba's roughconductor, brdfkit diffuse vs Mitsuba's
    diffuse: same scene, different samplers, per-pixel Welch tests (Šidák)."""
    variant = _variant("llvm_ad_rgb")
    size, spp, k = _budget(variant)
    eta, kk, alpha = [0.2, 0.9, 1.1], [3.9, 2.4, 2.2], 0.3
    pairs = [
        (brdfkit.model("microfacet", distribution="ggx", alpha=alpha, eta=eta, k=kk),
         {"type": "roughconductor", "distribution": "ggx", "alpha": alpha,
          "eta": {"type": "rgb", "value": eta}, "k": {"type": "rgb", "value": kk}}),
        (brdfkit.model("diffuse", rho_d=0.6), {"type": "diffuse", "reflectance": 0.6}),
    ]
    for model, native in pairs:
        kw = {"variant": variant, "size": size, "spp": spp, "k": k,
              "phi_l": math.radians(30.0), "ambient": 0.3}
        ours = renders(model, **kw, seed0=0)
        theirs = renders(native, **kw, seed0=500)
        p, level = worst_p(ours, b=theirs)
        assert p > level, (model, p, level)
        assert worst_p(1.05 * ours, b=theirs)[0] < level  # power


def test_spectral_grey_matches_rgb():
    """A grey model in llvm_ad_spectral (D65 lights) equals the llvm_ad_rgb render."""
    model = brdfkit.model("modified-phong", rho_d=0.3, rho_s=0.4, n=10.0)
    spectral = _variant("llvm_ad_spectral")
    size, spp, k = _budget(spectral)
    kw = {"size": size, "spp": spp, "k": k, "phi_l": math.radians(30.0), "ambient": 0.3}
    a = renders(model, variant=spectral, **kw, seed0=0)
    b = renders(model, variant=_variant("llvm_ad_rgb"), **kw, seed0=50)
    p, level = worst_p(a, b=b)
    assert p > level, (p, level)


def test_spectral_wavelength_grid_and_mono():
    """Per-wavelength channels are interpolated at si.wavelengths; mono takes luminance."""
    variant = _variant("llvm_ad_spectral")
    grid = np.array([400.0, 500.0, 600.0, 700.0])
    # f is linear in rho_d: a grid rho_d(λ) = λ/1000 gives f = (λ/1000)/π at every λ inside
    model, lam = spectral_model("diffuse", grid, rho_d=lambda x: x / 1000.0)
    bsdf = mitsuba_bsdf(model, wavelengths=lam)
    n = 1 if variant.startswith("scalar") else 8
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.wi = mi.Vector3f(0.0, 0.0, 1.0)
    wl = np.linspace(420.0, 680.0, 4 * n).reshape(4, n)
    si.wavelengths = mi.Spectrum(*wl[:, 0]) if n == 1 else mi.Spectrum(wl.astype(np.float32))
    got = np.array(bsdf.eval(mi.BSDFContext(), si, mi.Vector3f(0.0, 0.0, 1.0))).reshape(4, -1)
    np.testing.assert_allclose(got, wl[:, :got.shape[1]] / 1000.0 / math.pi, rtol=1e-5)
    # an RGB model in a spectral variant: a grey RGB stays flat (the basis spectra are a
    # partition of unity), and red reflects more at 680 nm than at 420 nm (and blue less)
    ctx, up = mi.BSDFContext(), mi.Vector3f(0.0, 0.0, 1.0)
    grey_rgb = mitsuba_bsdf(brdfkit.model("diffuse", rho_d=[0.5, 0.5, 0.5]))
    np.testing.assert_allclose(np.array(grey_rgb.eval(ctx, si, up)), 0.5 / math.pi, rtol=1e-6)
    red = np.array(mitsuba_bsdf(brdfkit.model("diffuse", rho_d=[0.9, 0.1, 0.1])).eval(
        ctx, si, up)).reshape(4, -1)
    blue = np.array(mitsuba_bsdf(brdfkit.model("diffuse", rho_d=[0.1, 0.1, 0.9])).eval(
        ctx, si, up)).reshape(4, -1)
    assert red[3, -1] > 3 * red[0, 0] and blue[0, 0] > 3 * blue[3, -1]
    del grey_rgb
    with pytest.raises(brdfkit.errors.ParameterError, match="spectral variant"):
        mitsuba_bsdf(model, wavelengths=lam, variant="llvm_ad_rgb")
    mono = _variant("llvm_ad_mono")
    rgb = brdfkit.model("diffuse", rho_d=[0.2, 0.5, 0.8])
    b = mitsuba_bsdf(rgb)
    si = dr.zeros(mi.SurfaceInteraction3f, 1 if mono.startswith("scalar") else 2)
    si.wi = mi.Vector3f(0.0, 0.0, 1.0)
    v = np.array(b.eval(mi.BSDFContext(), si, mi.Vector3f(0.0, 0.0, 1.0))).reshape(-1)
    # Rec. 709 luminance of (0.2, 0.5, 0.8)/π (0.2126 R + 0.7152 G + 0.0722 B); in the
    # scalar fallback (no scalar_mono) the three channels themselves
    want = (0.212671 * 0.2 + 0.715160 * 0.5 + 0.072169 * 0.8) / math.pi
    if not mono.startswith("scalar"):
        np.testing.assert_allclose(v, want, rtol=1e-5)
    del bsdf, b
    gc.collect()


def test_fallback_warning(monkeypatch):
    """An llvm variant that cannot start falls back to scalar with one warning line."""
    real = mi.set_variant

    def failing(name, *a):
        if name.startswith("llvm"):
            raise ImportError("libLLVM not found")
        return real(name, *a)

    monkeypatch.setattr(mi, "set_variant", failing)
    with pytest.warns(RuntimeWarning, match=r"libllvm19.*\n?") as rec:
        used = use_variant("llvm_ad_spectral")
    assert used == "scalar_spectral"
    msg = str(rec[0].message)
    assert "\n" not in msg and "libLLVM not found" in msg and "apt-get install libllvm19" in msg
    # the route then falls back too, and says why in one line (issue 23)
    from brdfkit.render.mitsuba_bridge import WavefrontRouteWarning

    with pytest.warns(WavefrontRouteWarning) as rec:
        bsdf = mitsuba_bsdf(brdfkit.model("microfacet", alpha=0.2))
    msg = str(rec[0].message)
    assert not bsdf.traced and "\n" not in msg and msg.endswith(bsdf.route_reason)
    assert "microfacet: the scalar_spectral variant" in msg and "wavefront()" not in msg


def test_spectral_metal_matches_roughconductor():
    """A metal with n(λ), k(λ) (linear in λ over Mitsuba's 360-830 nm) through the bridge
    on a 16-point grid vs Mitsuba's roughconductor with the same n, k as irregular spectra
    (which Mitsuba interpolates linearly, exactly here): per-block Welch tests (Šidák).
    The bridge interpolates f_r instead; F's curvature in λ over 31 nm steps is far below
    the noise."""
    variant = _variant("llvm_ad_spectral")
    size, spp, k = _budget(variant)
    lo, hi, alpha = 360.0, 830.0, 0.3

    # gold-like: F₀ ≈ 0.37 at 360 nm, 0.97 at 830 nm
    def n_of(lam):
        return 1.5 - 1.35 * (lam - lo) / (hi - lo)

    def k_of(lam):
        return 1.8 + 2.7 * (lam - lo) / (hi - lo)

    model, grid = spectral_model("microfacet", np.linspace(lo, hi, 16), distribution="ggx",
                                 alpha=alpha, eta=n_of, k=k_of)
    native = {"type": "roughconductor", "distribution": "ggx", "alpha": alpha,
              "eta": {"type": "irregular", "wavelengths": f"{lo}, {hi}",
                      "values": f"{n_of(lo)}, {n_of(hi)}"},
              "k": {"type": "irregular", "wavelengths": f"{lo}, {hi}",
                    "values": f"{k_of(lo)}, {k_of(hi)}"}}
    kw = {"variant": variant, "size": size, "spp": spp, "k": k, "phi_l": math.radians(30.0),
          "ambient": 0.3}
    ours = np.stack([render_sphere_mitsuba(model, wavelengths=grid, seed=j, size=size,
                                           spp=spp, variant=variant, phi_l=kw["phi_l"],
                                           ambient=0.3) for j in range(k)])
    theirs = renders(native, **kw, seed0=500)
    p, level = worst_p(ours, b=theirs)
    assert p > level, (p, level)
    assert worst_p(1.05 * ours, b=theirs)[0] < level  # power
    # and the metal is coloured: a grey stand-in (its mean n, k) is rejected
    grey = brdfkit.model("microfacet", distribution="ggx", alpha=alpha, eta=0.825, k=3.15)
    assert worst_p(renders(grey, **kw, seed0=900), b=theirs)[0] < level


def test_scene_dict_plugin():
    """{"type": "brdfkit", …}: model names with parameters, comma lists for channels, pump;
    the loaded BSDF evaluates as the model built directly (f cos θ_L)."""
    variant = _variant("llvm_ad_rgb")
    n = 1 if variant.startswith("scalar") else 3
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.wi = mi.Vector3f(0.0, 0.6, 0.8)
    light = np.array([0.48, 0.0, 0.877])
    light /= np.linalg.norm(light)
    wo = mi.Vector3f(*light.tolist())
    cases = [
        ({"model": "modified-phong", "rho_d": 0.2, "rho_s": 0.5, "n": 20, "pump": 1},
         pump(brdfkit.model("modified-phong", rho_d=0.2, rho_s=0.5, n=20), "max")),
        ({"model": "diffuse", "rho_d": "0.1, 0.4, 0.7"},
         brdfkit.model("diffuse", rho_d=[0.1, 0.4, 0.7])),
    ]
    for props, model in cases:
        bsdf = mi.load_dict({"type": "brdfkit", **props})
        got = np.array(bsdf.eval(mi.BSDFContext(), si, wo)).reshape(3, -1)[:, 0]
        want = np.broadcast_to(model.eval(light, np.array([0.0, 0.6, 0.8])), (3,)) * light[2]
        np.testing.assert_allclose(got, want, rtol=1e-5)
        del bsdf
    # Mitsuba re-raises the ParameterError of the plugin's constructor as a RuntimeError
    with pytest.raises(RuntimeError, match='"model" is required'):
        mi.load_dict({"type": "brdfkit", "n": 20})
    gc.collect()


def test_cli_mitsuba_engine_agrees_with_direct(tmp_path):
    """`brdfkit render sphere --engine mitsuba` against the exact direct render of the same
    Lambertian sphere: the disc-interior mean (pixels away from the rim, where the
    pixel-area average equals the centre value to O(pixel²)) agrees within 2 % — the
    Monte-Carlo standard error at 64 spp × ~150 pixels is well below 0.5 %."""
    from click.testing import CliRunner

    from brdfkit.cli import main

    out = {}
    for engine, extra in (("direct", []), ("mitsuba", ["--spp", "64"])):
        path = tmp_path / f"{engine}.npy"
        res = CliRunner().invoke(main, ["render", "sphere", "lambert", "--phi-l", "30",
                                        "--size", "16", "--engine", engine, *extra,
                                        "--out", str(path), "--json"])
        assert res.exit_code == 0, res.output
        meta = json.loads(res.output)
        assert meta["engine"] == engine
        out[engine] = np.load(path)[..., 0]
    y, x = np.mgrid[0:16, 0:16]
    r = np.hypot((x + 0.5) / 8 - 1, 1 - (y + 0.5) / 8)
    inner = r < 0.8
    a, b = out["direct"][inner].mean(), out["mitsuba"][inner].mean()
    assert abs(b / a - 1) < 0.02, (a, b)


# --------------------------------------------------------------------------- traced route
def _interaction(view: np.ndarray, wavelengths: np.ndarray | None = None):
    si = dr.zeros(mi.SurfaceInteraction3f, view.shape[0])
    si.wi = mi.Vector3f(view.T.astype(np.float32))
    if wavelengths is not None:
        si.wavelengths = mi.Spectrum(wavelengths.T.astype(np.float32))
    return si


def test_traced_microfacet_against_roughconductor_and_numba():
    """The traced route (formulas rebound to Dr.Jit) pointwise: its eval against Mitsuba's
    own roughconductor (GGX, exact Smith G₁ and conductor Fresnel in both: Walter et al.
    2007, an external implementation) in llvm_ad_rgb and, with per-wavelength n, k, in
    llvm_ad_spectral; its sample/pdf against the Numba compilation of the same formulas
    (model.sample/pdf: the two compilations must agree to float32 rounding), also for
    Beckmann; and the route choice (microfacet traced, a pumped model not, RGB channels in a
    spectral variant not)."""
    rng = np.random.default_rng(11)
    n = 256
    view, light = _hemisphere(rng, n), _hemisphere(rng, n)
    mirror = view[: n // 2] * np.array([-1.0, -1.0, 1.0])  # mirror directions of V
    light[: n // 2] = mirror + rng.normal(scale=0.1, size=mirror.shape)  # the lobe itself
    light[:, 2] = np.abs(light[:, 2]) + 0.02
    light = (light / np.linalg.norm(light, axis=-1, keepdims=True)).astype(np.float32)
    light = light.astype(float)
    ctx = mi.BSDFContext()
    eta, kk, alpha = [0.2, 0.9, 1.1], [3.9, 2.4, 2.2], 0.3
    model = brdfkit.model("microfacet", distribution="ggx", alpha=alpha, eta=eta, k=kk)
    native = {"type": "roughconductor", "distribution": "ggx", "alpha": alpha}

    _variant("llvm_ad_rgb")
    ours = mitsuba_bsdf(model)
    assert ours.traced
    theirs = mi.load_dict({**native, "eta": {"type": "rgb", "value": eta},
                           "k": {"type": "rgb", "value": kk}})
    si, wo = _interaction(view), mi.Vector3f(light.T.astype(np.float32))
    a = np.array(ours.eval(ctx, si, wo))
    b = np.array(theirs.eval(ctx, si, wo))
    # float32: ~1e-5 relative after a few tens of operations; floor for tiny values
    np.testing.assert_allclose(a, b, rtol=1e-4, atol=1e-6 * b.max())
    assert np.abs(a - 1.05 * b).max() > 1e-3 * b.max()  # power: a 5 % error is seen
    np.testing.assert_allclose(np.array(ours.pdf(ctx, si, wo)), model.pdf(light, view),
                               rtol=1e-4, atol=1e-7)
    u = rng.random((n, 2)).astype(np.float32)
    bs, weight = ours.sample(ctx, si, 0.5, mi.Point2f(u.T))
    want_wi, want_p = model.sample(view, u.astype(float))
    np.testing.assert_allclose(np.array(bs.wo).T, want_wi, atol=2e-5)
    ok = want_wi[:, 2] > 0.0
    np.testing.assert_allclose(np.array(bs.pdf)[ok], want_p[ok], rtol=2e-4)
    want_w = model.eval(want_wi[ok], view[ok]) * want_wi[ok, 2:3] / want_p[ok, None]
    # floor: float32 directions within a few degrees of the horizon, where f cos/pdf is tiny
    np.testing.assert_allclose(np.array(weight).T[ok], want_w, rtol=2e-4,
                               atol=1e-6 * want_w.max())
    beck = brdfkit.model("microfacet", alpha=0.2, eta=1.5)
    tb = mitsuba_bsdf(beck)
    got = np.array(tb.eval(ctx, si, wo))[0]
    np.testing.assert_allclose(got, beck.eval(light, view) * light[:, 2], rtol=1e-4,
                               atol=1e-6 * got.max())
    # a model without formulas (a NumPy-only one) takes the wavefront route
    plain = _NumpyOnly()
    assert plain.formulas() is None
    with pytest.warns(WavefrontRouteWarning, match="no formulas"):
        assert not mitsuba_bsdf(plain).traced
    with pytest.raises(brdfkit.errors.ParameterError, match="route='traced' needs"):
        mitsuba_bsdf(plain, route="traced")
    del ours, tb
    gc.collect()

    # spectral: n, k linear in λ on a grid; Mitsuba's irregular spectra interpolate the same
    _variant("llvm_ad_spectral")
    grid = np.linspace(400.0, 700.0, 7)
    n_of, k_of = (lambda x: 0.3 + x / 1000.0), (lambda x: 4.0 - x / 300.0)
    metal, lam = spectral_model("microfacet", grid, distribution="ggx", alpha=alpha,
                                eta=n_of, k=k_of)
    ours = mitsuba_bsdf(metal, wavelengths=lam)
    assert ours.traced
    assert not mitsuba_bsdf(model).traced  # RGB channels in a spectral variant: wavefront

    def irregular(f):
        return {"type": "irregular", "wavelengths": "400, 700",
                "values": f"{f(400.0)}, {f(700.0)}"}

    theirs = mi.load_dict({**native, "eta": irregular(n_of), "k": irregular(k_of)})
    wl = rng.uniform(410.0, 690.0, (n, 4))
    si = _interaction(view, wl)
    a = np.array(ours.eval(ctx, si, wo))
    b = np.array(theirs.eval(ctx, si, wo))
    np.testing.assert_allclose(a, b, rtol=1e-4, atol=1e-6 * b.max())
    del ours

    # mono: the Rec. 709 luminance (0.212671, 0.715160, 0.072169) of the RGB f_r cos θ_L
    mono = _variant("llvm_ad_mono")
    if not mono.startswith("scalar"):
        ours = mitsuba_bsdf(model)
        assert ours.traced
        got = np.array(ours.eval(ctx, _interaction(view),
                                 mi.Vector3f(light.T.astype(np.float32)))).reshape(-1)
        want = model.eval(light, view) @ np.array([0.212671, 0.715160, 0.072169]) * light[:, 2]
        np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-6 * want.max())
        del ours
    gc.collect()


def test_stated_monte_carlo_error_is_the_deviation_from_the_exact_render():
    """SphereRender.mc_error (the per-pixel standard error of K independent passes) against
    the deviation of the Monte-Carlo image from the exact render of the same configuration.

    Reference (a second method): the direct engine on an 8× finer grid, averaged over each
    pixel's 8×8 sub-pixel centres — the pixel-area average the Monte-Carlo pixel estimates
    (box filter), to O((pixel/8)²). Over the pixels whose square lies inside the disc,
    z = (MC − exact)/mc_error is Student-t with K − 1 = 15 degrees of freedom (variance
    15/13 = 1.154; |z| > t_0.975 = 2.131 for 5 % of the pixels). Power: an error stated
    twice too large or too small, or the per-sample spread instead of the error of the
    mean, is rejected by the same bounds."""
    from brdfkit.render import render_sphere

    variant = _variant("llvm_ad_rgb")
    if variant.startswith("scalar"):
        pytest.skip("needs an llvm variant (128 spp)")
    model = brdfkit.model("modified-phong", rho_d=0.2, rho_s=0.5, n=20.0)
    size, sub, spp, k = 24, 8, 128, 16
    kw = {"phi_l": math.radians(30.0), "ambient": 0.3, "irradiance": 1.0}
    mc = render_sphere(model, size=size, engine="mitsuba", spp=spp, passes=k, seed=3, **kw)
    assert mc.status == 0 and mc.success and mc.passes == k
    assert mc.mc_error.shape == mc.radiance.shape
    exact = render_sphere(model, size=size * sub, **kw).radiance
    exact = exact.reshape(size, sub, size, sub, -1).mean(axis=(1, 3))
    c = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    cx, cy = np.meshgrid(c, -c)
    inside = np.hypot(np.abs(cx) + 1.0 / size, np.abs(cy) + 1.0 / size) < 1.0
    dev = (mc.radiance - exact)[inside][:, 0]  # grey model: the channels are equal
    se = mc.mc_error[inside][:, 0]
    assert np.all(se > 0.0)
    t975 = stats.t.ppf(0.975, k - 1)

    def consistent(z):
        return 0.75 < np.var(z) < 1.75 and 0.01 < np.mean(np.abs(z) > t975) < 0.10 \
            and abs(np.mean(z)) < 0.25

    assert consistent(dev / se), (np.var(dev / se), np.mean(np.abs(dev / se) > t975))
    for wrong in (2.0 * se, 0.5 * se, se * math.sqrt(spp)):
        assert not consistent(dev / wrong)


def test_one_pass_states_no_error_and_keeps_the_single_render():
    """passes=1: the image is render_sphere_mitsuba's for the same seed, bit for bit; no
    standard error can be estimated, and the status says so (undetermined)."""
    from brdfkit.render import render_sphere
    from brdfkit.status import STATUS

    _variant("llvm_ad_rgb")
    model = brdfkit.model("lambert", rho_d=0.5)
    r = render_sphere(model, size=8, engine="mitsuba", spp=4, passes=1, seed=5, phi_l=0.3)
    single = render_sphere_mitsuba(model, size=8, spp=4, seed=5, phi_l=0.3)
    np.testing.assert_array_equal(r.radiance, single)
    assert r.mc_error is None and r.status == STATUS["render"].UNDETERMINED
    assert not r.success and STATUS["render"].message(r.status) in r.message
    with pytest.raises(brdfkit.errors.ParameterError, match="passes must be"):
        render_sphere(model, size=8, engine="mitsuba", spp=4, passes=5, phi_l=0.3)
    with pytest.raises(brdfkit.errors.ParameterError, match="takes no samples"):
        render_sphere(model, size=8, passes=2, phi_l=0.3)


class _NumpyOnly(DerivedBRDF):
    """A Lambertian evaluated in NumPy only (no kernel, no formulas): the wavefront route's
    example."""

    def __init__(self):
        super().__init__(name="numpy-only", params=(), values={}, reciprocal=True)

    def eval(self, wi, wo):
        wi, wo = np.asarray(wi, dtype=float), np.asarray(wo, dtype=float)
        return np.where((wi[..., 2] > 0) & (wo[..., 2] > 0), 1.0 / math.pi, 0.0)
