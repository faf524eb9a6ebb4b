"""A ``.brdf`` file's samplers and its Mitsuba routes (issue 21 §1 "Sampling", §3).

A file without a sampler is importance-sampled from its own values in NumPy (the
tabulated half-vector sampler of :class:`~brdfkit.user.model.FormulaBRDF`) and, on
Mitsuba's traced route, by the proxy formulas of :mod:`brdfkit.user.proxy_sampler`.

References, independent of the code under test:

- **Sampling**: the project's χ² test (:func:`brdfkit.analysis.chi2.chi2_test`, as in
  tests/test_sampling_chi2.py) of ``sample`` against ``pdf`` for the Walter GGX file at
  α = 0.1 and 0.5 and θ_o = 30°, 70° (azimuth 23°: no frame symmetry), for both samplers;
  its power: samples of the tabulated sampler labelled with the proxy's (normalised,
  different) density are rejected. The NumPy proxy is the formulas themselves: its
  directions and pdf against direct calls of ``formulas().sample``/``.pdf``.
- **Traced = the model**: the traced BSDF's eval (f cos θ), pdf and sample weight against
  the model's Numba evaluation of the same file, to float32 rounding; a coloured file's
  channels stay apart.
- **Images**: the traced render (Dr.Jit's symbolic mode, no ``wavefront()``) against the
  exact sphere render (the direct engine on an 8× finer grid averaged per pixel: the
  pixel-area average Mitsuba's box filter estimates), with the block t-tests of
  tests/test_render_mitsuba.py and their power (a factor 1.05 is rejected).
- **Plugin**: ``{"type": "brdfkit", "model": "/path/file.brdf", PARAM: VALUE}`` builds
  the file's model through the spec (no stand-in) and evaluates as ``brdfkit.model`` of
  the same file and values does.
"""

from __future__ import annotations

import gc
import math
from pathlib import Path

import numpy as np
import pytest

import brdfkit
from brdfkit.analysis.chi2 import chi2_test
from brdfkit.user.model import FormulaBRDF
from brdfkit.user.proxy_sampler import ProxyStrategy, proxy_pdf, proxy_sample

CORPUS = Path(__file__).parent / "brdf_files"
WALTER = CORPUS / "walter_ggx.brdf"
COOK_TORRANCE = CORPUS / "cook_torrance.brdf"  # colours base, F0; Beckmann D, V-groove G

CASES = [(a, th) for a in (0.1, 0.5) for th in (30.0, 70.0)]
N_TESTS = 2 * len(CASES)  # tabulated and proxy, one Šidák family


def wo_at(theta_deg: float) -> np.ndarray:
    t, ph = math.radians(theta_deg), math.radians(23.0)
    return np.array([math.sin(t) * math.cos(ph), math.sin(t) * math.sin(ph), math.cos(t)])


class ProxySampled(FormulaBRDF):
    """The file's model sampled in NumPy by its traced route's sampler (the proxy formulas,
    ``formulas().args``) instead of the tabulated one."""

    def _strategy(self, wo):
        return ProxyStrategy(*self.formulas().args)


class Mislabelled(FormulaBRDF):
    """Draws with the tabulated sampler but reports the proxy's density: both normalised,
    different — the χ² test must reject it."""

    def sample(self, wo, u):
        wi, _ = super().sample(wo, u)
        return wi, self.pdf(wi, wo)

    def pdf(self, wi, wo):
        return ProxyStrategy(*self.formulas().args).pdf(*np.broadcast_arrays(
            np.asarray(wi, float), np.asarray(wo, float)))


def file_model(cls, alpha):
    return cls(brdfkit.model(str(WALTER)).definition, alpha=alpha)


# --------------------------------------------------------------------------- χ²
@pytest.mark.parametrize("alpha, theta", CASES)
def test_tabulated_sampler_of_the_file_passes_chi2(alpha, theta):
    m = brdfkit.model(str(WALTER), alpha=alpha)
    assert m.definition.sampler is None  # no sampler in the file: sampled from its values
    r = chi2_test(m, wo_at(theta), n_samples=200_000, seed=int(100 * alpha + theta),
                  alpha=0.01, n_tests=N_TESTS)
    assert r.passed, r.message
    assert r.pdf_integral <= 1.0 + 1e-3 and r.dof >= 50


@pytest.mark.parametrize("alpha, theta", CASES)
def test_proxy_formulas_of_the_file_pass_chi2(alpha, theta):
    m = file_model(ProxySampled, alpha)
    f = m.formulas()
    assert f.eval is m.definition.kernel and f.sample is proxy_sample and f.pdf is proxy_pdf
    a, w_c = f.args
    assert 0.0 < w_c < 1.0  # a half-vector lobe: the GGX part is used
    if alpha == 0.1:  # the lobe estimate sees D·G/cos terms: its α near the file's
        assert a == pytest.approx(alpha, rel=0.15)
    wo = wo_at(theta)
    # the NumPy proxy is the formulas: directions and pdf against direct calls
    u = np.random.default_rng(7).random((16, 2))
    wi = ProxyStrategy(a, w_c).sample(np.broadcast_to(wo, (16, 3)), u)
    for k in range(16):
        np.testing.assert_allclose(wi[k], proxy_sample(*wo, *u[k], a, w_c), rtol=1e-12,
                                   atol=1e-15)
        assert float(m.pdf(wi[k], wo)) == pytest.approx(proxy_pdf(*wi[k], *wo, a, w_c),
                                                        rel=1e-12) or wi[k][2] <= 0.0
    r = chi2_test(m, wo, n_samples=200_000, seed=int(100 * alpha + theta) + 1, alpha=0.01,
                  n_tests=N_TESTS)
    assert r.passed, r.message


def test_chi2_rejects_the_wrong_density():
    m = file_model(Mislabelled, 0.5)
    assert not chi2_test(m, wo_at(30.0), n_samples=200_000, seed=3).passed


# --------------------------------------------------------------------------- Mitsuba
mi = pytest.importorskip("mitsuba")
dr = pytest.importorskip("drjit")

from test_user_traced import _directions, _llvm, _si  # noqa: E402 (the traced route's harness)

from brdfkit.render.mitsuba_bridge import mitsuba_bsdf  # noqa: E402
from brdfkit.render.mitsuba_sphere import sphere_scene  # noqa: E402

MODELS = {"walter": lambda: brdfkit.model(str(WALTER), alpha=0.3),
          "cook-torrance": lambda: brdfkit.model(str(COOK_TORRANCE), m=0.3,
                                                 base=[0.9, 0.5, 0.2])}


@pytest.mark.parametrize("which", list(MODELS))
def test_traced_file_pointwise(which):
    _llvm("llvm_ad_rgb")
    model = MODELS[which]()
    bsdf = mitsuba_bsdf(model)  # no route forced: a file's model takes the traced one
    assert bsdf.traced
    n = 256
    view, light = _directions(np.random.default_rng(3), n)
    ctx, si, wo = mi.BSDFContext(), _si(view), mi.Vector3f(light.T.astype(np.float32))
    got = np.array(bsdf.eval(ctx, si, wo)).T
    f = np.asarray(model.eval(light, view)).reshape(n, -1)
    want = np.broadcast_to(f * light[:, 2:3], (n, 3))
    np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-6 * want.max())
    if which == "cook-torrance":  # the colour channels stay apart, in order
        assert np.all(got[:, 0] > got[:, 2])
    np.testing.assert_allclose(np.array(bsdf.pdf(ctx, si, wo)),
                               ProxyStrategy(*model.formulas().args).pdf(light, view),
                               rtol=2e-4, atol=1e-7)
    u = np.random.default_rng(4).random((n, 2)).astype(np.float32)
    bs, weight = bsdf.sample(ctx, si, 0.5, mi.Point2f(u.T))
    wi, p = np.array(bs.wo).T.astype(float), np.array(bs.pdf).astype(float)
    ok = (wi[:, 2] > 1e-3) & (p > 0.0)
    assert ok.mean() > 0.7
    wi = wi[ok] / np.linalg.norm(wi[ok], axis=1, keepdims=True)
    fw = np.asarray(model.eval(wi, view[ok])).reshape(ok.sum(), -1) * wi[:, 2:3] / p[ok, None]
    np.testing.assert_allclose(np.array(weight).T[ok], np.broadcast_to(fw, (ok.sum(), 3)),
                               rtol=2e-3, atol=1e-5 * fw.max())
    del bsdf
    gc.collect()


def _exact(model, *, size, sub=8, **kw):
    from brdfkit.render import render_sphere

    img = render_sphere(model, size=size * sub, **kw).radiance
    img = img.reshape(size, sub, size, sub, -1).mean(axis=(1, 3))
    c = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    cx, cy = np.meshgrid(c, -c)
    inside = np.hypot(np.abs(cx) + 1.0 / size, np.abs(cy) + 1.0 / size) < 1.0
    return img, inside


@pytest.mark.parametrize("which", list(MODELS))
def test_traced_file_render_agrees_with_the_exact_sphere(which):
    from test_render_mitsuba import worst_p

    variant = _llvm("llvm_ad_rgb")
    model = MODELS[which]()
    size, spp, k = 24, 16, 6
    kw = {"phi_l": math.radians(30.0), "ambient": 0.3, "irradiance": 1.0}
    bsdf = mitsuba_bsdf(model)
    assert bsdf.traced
    scene = mi.load_dict(sphere_scene(bsdf, size=size, variant=variant, **kw))
    assert dr.flag(dr.JitFlag.SymbolicCalls)  # the default mode: no wavefront() context
    imgs = np.stack([np.array(mi.render(scene, spp=spp, seed=j)) for j in range(k)])
    del scene, bsdf
    gc.collect()
    ref, inside = _exact(model, size=size, **kw)
    ref = np.broadcast_to(ref, imgs.shape[1:])
    p, level = worst_p(imgs, ref, mask=inside)
    assert p > level, (p, level)
    assert worst_p(imgs, 1.05 * ref, mask=inside)[0] < level  # power


def test_scene_dict_plugin_takes_a_file():
    _llvm("llvm_ad_rgb")
    cases = [({"model": str(WALTER), "alpha": 0.3}, {"alpha": 0.3}),
             ({"model": str(COOK_TORRANCE), "m": 0.3, "base": "0.9, 0.5, 0.2"},
              {"m": 0.3, "base": [0.9, 0.5, 0.2]})]
    view, light = _directions(np.random.default_rng(5), 32)
    for props, values in cases:
        bsdf = mi.load_dict({"type": "brdfkit", **props})
        assert bsdf.traced
        model = brdfkit.model(props["model"], **values)
        got = np.array(bsdf.eval(mi.BSDFContext(), _si(view),
                                 mi.Vector3f(light.T.astype(np.float32)))).T
        f = np.asarray(model.eval(light, view)).reshape(32, -1)
        want = np.broadcast_to(f * light[:, 2:3], (32, 3))
        np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-6 * want.max())
        del bsdf
        gc.collect()
