"""User models in Mitsuba by the traced route, and their proxy sampler (issue 21).

A user's model (a ``.brdf`` file, a Python file) is a kernel formula and declared lobes;
:func:`brdfkit.user.proxy_sampler.proxy_formulas` gives it Formulas (its kernel, a
defensive cosine + GGX half-vector mixture as sampler and pdf) so the Mitsuba bridge
traces it like ``microfacet``. The models here are test-local stand-ins for
``FormulaBRDF`` (a DerivedBRDF whose kernel is a formula and whose ``formulas()`` is
``proxy_formulas(self)``): Walter GGX as a user kernel over microfacet's packed row, and
a coloured kernel that computes all three channels and selects the row's by a channel
index in its last entry (``select(p[K-1] == 0.0, r, select(p[K-1] == 1.0, g, b))``, the
GLSL translator's form).

References, each independent of the code under test:

- **Proxy α**: the closed-form GGX D written here, D(β)/D(0) = 1/2 at the lobe's
  half-width β (Lewis 1993 §3.2's half-angle definition).
- **Normalisation**: at θ_o = 0 the GGX part reaches every direction with ω_o·h =
  cos θ_h > 0, so the pdf integrates to 1 over the sphere; over the upper hemisphere
  to w_c + (1 − w_c)/(1 + α²) (P(tan²θ_h ≤ 1) under D cos θ_h, whose CDF in tan²θ_h
  is tan²θ_h/(α² + tan²θ_h), Walter et al. 2007 eq. 35) — by quadrature here.
- **Sampling**: the project's χ² test (:mod:`brdfkit.analysis.chi2`) of sample against
  pdf; its power: a pdf with the wrong mixture weight is rejected.
- **Traced = Numba**: the Dr.Jit trace of the formulas against their Numba compilation
  (``model.eval``, ``model.sample``, ``model.pdf``): two compilers, one code, equal to
  float32 rounding; the coloured kernel per channel against its three channels in
  NumPy; mono variants take the Rec. 709 luminance.
- **Images**: the traced render (default symbolic mode, no ``wavefront()``) against
  brdfkit's exact sphere render (the direct engine on an 8× finer grid averaged over
  each pixel: the pixel-area average Mitsuba's box filter estimates) with the block
  t-tests of tests/test_render_mitsuba.py, with their power (a factor 1.05 is
  rejected); and against the wavefront route of the same model, which draws the same
  directions from the same random numbers (the same sampler formula, compiled by
  Numba): the same image to float32 rounding.
- **Plugin**: ``{"type": "brdfkit", …}`` takes the traced route for such a model too
  (its spec resolution replaced by the test model: the spec kinds are tested with them).
"""

from __future__ import annotations

import gc
import math

import numpy as np
import pytest
from scipy import integrate

import brdfkit
from brdfkit._dual import formula, select
from brdfkit.analysis.chi2 import chi2_test
from brdfkit.errors import ParameterError
from brdfkit.halfangle import beta_from_trowbridge_reitz_c
from brdfkit.models import Lobe, Param
from brdfkit.models._base import DerivedBRDF
from brdfkit.models.microfacet import walter
from brdfkit.models.sampling import StrategySampled
from brdfkit.user.proxy_sampler import (
    ALPHA_MIN,
    COSINE_WEIGHT,
    ProxyStrategy,
    proxy_args,
    proxy_formulas,
)

INV_PI = 1.0 / math.pi


# --------------------------------------------------------------------------- user-like models
@formula
def user_ggx(ix, iy, iz, ox, oy, oz, p):
    """Walter GGX with F = 1 over microfacet's packed row (distribution, α, η, κ, scale)."""
    return walter(ix, iy, iz, ox, oy, oz, p, True, False)


@formula
def user_rgb(ix, iy, iz, ox, oy, oz, p):
    """ρ_c/π + GGX(α) on rows (ρ_r, ρ_g, ρ_b, α, c): every channel computed, row c's kept."""
    spec = walter(ix, iy, iz, ox, oy, oz, (0.0, p[3], 0.0, 0.0, 1.0), True, False)
    diffuse = select((iz > 0.0) & (oz > 0.0), INV_PI, 0.0)  # 0 below the horizon
    r = p[0] * diffuse + spec
    g = p[1] * diffuse + spec
    b = p[2] * diffuse + spec
    return select(p[4] == 0.0, r, select(p[4] == 1.0, g, b))


class UserLike(StrategySampled, DerivedBRDF):
    """A FormulaBRDF stand-in: a formula kernel, declared lobes, the proxy as its sampler
    in NumPy (so the wavefront route draws what the traced one does) and in formulas()."""

    def __init__(self, *, kernel, params, values, packed, lobes):
        self._lobes = list(lobes)
        super().__init__(name="user-like", params=params, values=values, reciprocal=True,
                         has_sampler=True, kernel=kernel, packed=packed)

    def lobes(self):
        return self._lobes

    def _strategy(self, wo):
        return ProxyStrategy.of(self)

    def formulas(self):
        return proxy_formulas(self)


ALPHA_PARAM = Param("alpha", 0.2, 1e-4, 4.0, "", "GGX roughness")


def user_ggx_model(alpha: float, *, lobes=None) -> UserLike:
    ref = brdfkit.model("microfacet", distribution="ggx", alpha=alpha)
    # the lobe declared truthfully: its half-width (D halves there)
    lobes = lobes or [Lobe("half", beta_from_trowbridge_reitz_c(alpha))]
    return UserLike(kernel=user_ggx, params=(ALPHA_PARAM,), values={"alpha": alpha},
                    packed=ref.packed, lobes=lobes)


def user_rgb_model(rho, alpha: float) -> UserLike:
    """Three rows (ρ_r, ρ_g, ρ_b, α, c); a grey ρ (a number): one row, channel index 0
    (the index column is then a Python float in the trace, its comparison a bool)."""
    grey = np.ndim(rho) == 0
    rgb = [float(rho)] * 3 if grey else [float(x) for x in rho]
    rows = [[*rgb, alpha, float(c)] for c in range(1 if grey else 3)]
    params = (Param("rho_d", 0.5, 0.0, 1.0, "", "diffuse colour", kind="colour"), ALPHA_PARAM)
    values = {"rho_d": rho if grey else list(rho), "alpha": alpha}
    return UserLike(kernel=user_rgb, params=params, values=values, packed=rows,
                    lobes=[Lobe("half", beta_from_trowbridge_reitz_c(alpha)),
                           Lobe("diffuse", math.pi / 2)])


def d_ggx(theta, alpha):
    """GGX D(θ_h) = α²/(π cos⁴θ (α² + tan²θ)²), written out (Walter et al. 2007 eq. 33)."""
    c = np.cos(theta)
    t2 = np.tan(theta) ** 2
    return alpha**2 / (math.pi * c**4 * (alpha**2 + t2) ** 2)


# --------------------------------------------------------------------------- the proxy
@pytest.mark.parametrize("beta", [1e-3, 0.05, 0.3, 1.0])
def test_proxy_alpha_halves_d_at_the_lobe_width(beta):
    m = user_ggx_model(0.2, lobes=[Lobe("half", beta)])
    alpha, w_c = proxy_args(m)
    assert w_c == COSINE_WEIGHT
    assert d_ggx(beta, alpha) / d_ggx(0.0, alpha) == pytest.approx(0.5, rel=1e-9)
    # a mirror lobe of width 2β (widths are at most π/2): half vectors within β
    if 2.0 * beta < math.pi / 2:
        a_m, _ = proxy_args(user_ggx_model(0.2, lobes=[Lobe("mirror", 2.0 * beta)]))
        assert a_m == pytest.approx(alpha, rel=1e-12)


def test_proxy_args_limits_and_errors():
    # a diffuse lobe (or one about the normal): the cosine alone
    for kind in ("diffuse", "normal"):
        assert proxy_args(user_ggx_model(0.2, lobes=[Lobe(kind, 0.3)]))[1] == 1.0
    # a half lobe wins over a sharper diffuse one (sharpest_lobe's rule)
    m = user_ggx_model(0.2, lobes=[Lobe("diffuse", 0.01), Lobe("half", 0.2)])
    assert proxy_args(m)[1] == COSINE_WEIGHT
    # narrower than float32 resolves: ALPHA_MIN; π/2 (the widest): finite, below 2^(-1/4)
    assert proxy_args(user_ggx_model(0.2, lobes=[Lobe("half", 1e-9)]))[0] == ALPHA_MIN
    wide = proxy_args(user_ggx_model(0.2, lobes=[Lobe("half", math.pi / 2)]))[0]
    assert 0.8 < wide < 2.0**-0.25
    m = user_ggx_model(0.3)
    form = proxy_formulas(m)
    assert form.eval is user_ggx and form.args == pytest.approx((0.3, COSINE_WEIGHT))
    m.kernel = None
    with pytest.raises(ParameterError, match="user-like has no kernel"):
        proxy_formulas(m)
    for bad, match in (({"alpha": 0.0}, "alpha must be"), ({"alpha": 0.1, "w_c": 0.0},
                                                          "w_c must lie in")):
        with pytest.raises(ParameterError, match=match):
            ProxyStrategy(**bad)


@pytest.mark.parametrize("alpha", [0.05, 0.3, 0.8])
@pytest.mark.parametrize("w_c", [COSINE_WEIGHT, 1.0])
def test_proxy_pdf_normalisation_at_normal_view(alpha, w_c):
    s = ProxyStrategy(alpha, w_c)
    wo = np.array([0.0, 0.0, 1.0])

    def ring(theta):  # 2π sin θ p(θ): the pdf is azimuth-independent for ω_o = n
        t = np.atleast_1d(theta)
        wi = np.stack([np.sin(t), np.zeros_like(t), np.cos(t)], axis=-1)
        return 2.0 * math.pi * np.sin(t) * s.pdf(wi, wo)

    # breakpoints at the lobe's scale (ω_i at 2θ_h)
    pts = [2.0 * math.atan(alpha * f) for f in (0.5, 1.0, 2.0, 4.0)]
    upper = integrate.quad(lambda t: ring(t)[0], 0.0, math.pi / 2, points=pts, limit=400,
                           epsabs=1e-12, epsrel=1e-11)[0]
    lower = integrate.quad(lambda t: ring(t)[0], math.pi / 2, math.pi, limit=400,
                           epsabs=1e-12, epsrel=1e-11)[0]
    assert upper == pytest.approx(w_c + (1.0 - w_c) / (1.0 + alpha**2), abs=1e-8)
    assert upper + lower == pytest.approx(1.0, abs=1e-8)


CHI2_CASES = [(a, th) for a in (0.05, 0.2, 0.6) for th in (0.0, 45.0, 80.0)]
N_CHI2 = len(CHI2_CASES) + 1


def _wo(theta_deg: float) -> np.ndarray:
    t, ph = math.radians(theta_deg), math.radians(23.0)  # azimuth 23°: no frame symmetry
    return np.array([math.sin(t) * math.cos(ph), math.sin(t) * math.sin(ph), math.cos(t)])


@pytest.mark.parametrize("alpha,theta", CHI2_CASES)
def test_proxy_sampler_chi2(alpha, theta):
    m = user_ggx_model(alpha)
    r = chi2_test(m, _wo(theta), n_samples=200_000, seed=int(1000 * alpha + theta),
                  alpha=0.01, n_tests=N_CHI2)
    assert r.passed, r.message
    assert r.pdf_integral <= 1.0 + 1e-3 and r.dof >= 50


def test_proxy_sampler_chi2_diffuse_and_power():
    # a diffuse lobe: the cosine alone
    m = user_ggx_model(0.3, lobes=[Lobe("diffuse", math.pi / 2)])
    r = chi2_test(m, _wo(45.0), n_samples=200_000, seed=5, alpha=0.01, n_tests=N_CHI2)
    assert r.passed, r.message

    class WrongWeight(UserLike):  # samples with w_c, claims w_c + 0.1
        def pdf(self, wi, wo):
            a, w = proxy_args(self)
            return ProxyStrategy(a, w + 0.1).pdf(*np.broadcast_arrays(wi, wo))

    bad = WrongWeight(kernel=user_ggx, params=(ALPHA_PARAM,), values={"alpha": 0.2},
                      packed=brdfkit.model("microfacet", distribution="ggx",
                                           alpha=0.2).packed,
                      lobes=[Lobe("half", beta_from_trowbridge_reitz_c(0.2))])
    assert not chi2_test(bad, _wo(45.0), n_samples=200_000, seed=6).passed


# --------------------------------------------------------------------------- Mitsuba
mi = pytest.importorskip("mitsuba")
dr = pytest.importorskip("drjit")

from traced_helpers import mirror_pairs as _directions  # noqa: E402
from traced_helpers import variant  # noqa: E402

from brdfkit.render.mitsuba_bridge import mitsuba_bsdf, wavefront  # noqa: E402
from brdfkit.render.mitsuba_sphere import sphere_scene  # noqa: E402


def _llvm(name: str) -> str:
    return variant(name, llvm=True)


def _si(view):
    si = dr.zeros(mi.SurfaceInteraction3f, view.shape[0])
    si.wi = mi.Vector3f(view.T.astype(np.float32))
    return si


MODELS = {"ggx": lambda: user_ggx_model(0.2), "rgb": lambda: user_rgb_model((0.7, 0.35, 0.1), 0.3),
          "index-grey": lambda: user_rgb_model(0.4, 0.3),
          # a diffuse lobe: the cosine alone (w_c = 1, the GGX lanes discarded but finite)
          "cosine-proxy": lambda: user_ggx_model(0.3, lobes=[Lobe("diffuse", math.pi / 2)])}


@pytest.mark.parametrize("which", list(MODELS))
def test_traced_user_model_pointwise(which):
    """eval/pdf/sample of the traced BSDF against the Numba compilation of the same formulas;
    the coloured kernel's channel-index column selects each channel."""
    _llvm("llvm_ad_rgb")
    model = MODELS[which]()
    bsdf = mitsuba_bsdf(model, route="traced")
    assert bsdf.traced
    rng = np.random.default_rng(3)
    n = 256
    view, light = _directions(rng, n)
    ctx, si, wo = mi.BSDFContext(), _si(view), mi.Vector3f(light.T.astype(np.float32))
    got = np.array(bsdf.eval(ctx, si, wo)).T  # (n, 3)
    want = np.broadcast_to(np.asarray(model.eval(light, view)).reshape(n, -1), (n, 3))
    want = want * light[:, 2:3]
    np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-6 * want.max())
    if which == "rgb":  # the channels are told apart (power), in the order of the rows
        assert np.all(got[:, 0] > got[:, 1]) and np.all(got[:, 1] > got[:, 2])
    np.testing.assert_allclose(np.array(bsdf.pdf(ctx, si, wo)), model.pdf(light, view),
                               rtol=1e-4, atol=1e-7)
    u = rng.random((n, 2)).astype(np.float32)
    bs, weight = bsdf.sample(ctx, si, 0.5, mi.Point2f(u.T))
    want_wi, want_p = model.sample(view, u.astype(float))
    assert np.mean(want_wi[:, 2] > 0.0) > 0.7  # most samples are checked below
    np.testing.assert_allclose(np.array(bs.wo).T, want_wi, atol=2e-5)
    ok = want_wi[:, 2] > 0.0
    np.testing.assert_allclose(np.array(bs.pdf)[ok], want_p[ok], rtol=2e-4)
    f = np.asarray(model.eval(want_wi[ok], view[ok])).reshape(ok.sum(), -1)
    want_w = np.broadcast_to(f * want_wi[ok, 2:3] / want_p[ok, None], (ok.sum(), 3))
    np.testing.assert_allclose(np.array(weight).T[ok], want_w, rtol=2e-4,
                               atol=1e-6 * want_w.max())
    del bsdf
    gc.collect()


def test_traced_coloured_user_model_in_mono_is_luminance():
    _llvm("llvm_ad_mono")
    model = user_rgb_model((0.7, 0.35, 0.1), 0.3)
    bsdf = mitsuba_bsdf(model)
    assert bsdf.traced
    view, light = _directions(np.random.default_rng(4), 64)
    got = np.array(bsdf.eval(mi.BSDFContext(), _si(view),
                             mi.Vector3f(light.T.astype(np.float32)))).reshape(-1)
    # Rec. 709 luminance of the RGB f_r cos θ_L
    want = model.eval(light, view) @ np.array([0.212671, 0.715160, 0.072169]) * light[:, 2]
    np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-6 * want.max())
    del bsdf
    gc.collect()


def _exact(model, *, size, sub=8, **kw):
    """The pixel-area average of the exact render (direct engine, sub×sub per pixel) and
    the mask of pixels whose square lies inside the disc."""
    from brdfkit.render import render_sphere

    img = render_sphere(model, size=size * sub, **kw).radiance
    img = img.reshape(size, sub, size, sub, -1).mean(axis=(1, 3))
    c = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    cx, cy = np.meshgrid(c, -c)
    inside = np.hypot(np.abs(cx) + 1.0 / size, np.abs(cy) + 1.0 / size) < 1.0
    return img, inside


@pytest.mark.parametrize("which", ["ggx", "rgb"])
def test_traced_user_model_image(which):
    """The traced render (symbolic mode, no wavefront()) against the exact sphere render
    within the Monte-Carlo error, and against the wavefront route: the same image."""
    from test_render_mitsuba import worst_p

    variant = _llvm("llvm_ad_rgb")
    model = MODELS[which]()
    size, spp, k = 24, 16, 6
    kw = {"phi_l": math.radians(30.0), "ambient": 0.3, "irradiance": 1.0}

    def scene(bsdf):
        return mi.load_dict(sphere_scene(bsdf, size=size, variant=variant, **kw))

    traced = mitsuba_bsdf(model)
    assert traced.traced
    s = scene(traced)
    assert dr.flag(dr.JitFlag.SymbolicCalls)  # the default mode: no wavefront() here
    imgs = np.stack([np.array(mi.render(s, spp=spp, seed=j)) for j in range(k)])
    del s, traced
    ref, inside = _exact(model, size=size, **kw)
    p, level = worst_p(imgs, ref, mask=inside)
    assert p > level, (p, level)
    assert worst_p(imgs, 1.05 * ref, mask=inside)[0] < level  # power
    gc.collect()
    # the wavefront route: model.sample/pdf/eval in NumPy (the same sampler formula)
    wave = mitsuba_bsdf(model, route="wavefront")
    assert not wave.traced
    s = scene(wave)
    with wavefront():
        same = np.stack([np.array(mi.render(s, spp=spp, seed=j)) for j in range(2)])
    del s, wave
    gc.collect()
    np.testing.assert_allclose(same, imgs[:2], rtol=0, atol=2e-5 * imgs.max())


def test_scene_dict_plugin_takes_the_traced_route(monkeypatch):
    """{"type": "brdfkit", "model": SPEC}: the plugin builds the model from its spec (the
    `.brdf`/`.py` spec kinds are the spec's; here the builder is replaced by the user-like
    model) and takes the traced route, evaluating as the model does."""
    import brdfkit.render.mitsuba_plugin as plugin

    _llvm("llvm_ad_rgb")
    model = user_rgb_model((0.7, 0.35, 0.1), 0.3)
    # the spec is read (Mitsuba rejects an unreferenced property) and resolved to the model
    monkeypatch.setattr(plugin, "_model_from_props",
                        lambda props: ({"user-like.py": model}[props["model"]], None))
    bsdf = mi.load_dict({"type": "brdfkit", "model": "user-like.py"})
    assert bsdf.traced
    view, light = _directions(np.random.default_rng(5), 16)
    got = np.array(bsdf.eval(mi.BSDFContext(), _si(view),
                             mi.Vector3f(light.T.astype(np.float32)))).T
    np.testing.assert_allclose(got, model.eval(light, view) * light[:, 2:3], rtol=1e-4)
    del bsdf
    gc.collect()
