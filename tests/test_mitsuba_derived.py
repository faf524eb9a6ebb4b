"""Derived models on the Mitsuba bridge's traced route: tables read in the trace (issue 23).

A pumped model's kernel is its root's times a table lookup (``brdfkit.tables.lookup``);
its formulas are the root's eval formula composed with the lookup, whose Dr.Jit side
gathers from the packed table rows. References, each independent of the trace:

- **Traced = Numba**: the Dr.Jit trace of the composed formula against ``model.eval``,
  the Numba kernel composed separately (``pumping.kernels.chain_kernel`` /
  ``stage_kernel``, reading the table with ``tables._lookup`` in float64): two compilers,
  two compositions, one table, equal to float32 rounding (1e-4 relative, the bound the
  microfacet traced tests use). Power: the same comparison against the *unpumped* root
  fails (the table factor is in the trace).
- **The lookup alone**: the primitive's Dr.Jit read against the float64
  :class:`~brdfkit.tables.Lookup` / :class:`~brdfkit.tables.UniformLookup` at random μ,
  and at the cell edges and μ = 0, 1 (the clamps).
- **Sampler**: the root's (the pumped lobe is the root's reweighted by 1/g): traced
  sample/pdf against the root's ``model.sample``/``pdf``.
- **Images**: the traced render (default symbolic mode, no ``wavefront()``) against the
  wavefront route of the same model (``model.eval`` and ``model.sample`` in NumPy/Numba)
  from the same seed: the same directions, so the same image to float32 rounding.
- **The fallback says why**: a model without formulas takes the wavefront route with a
  one-line :class:`WavefrontRouteWarning` and ``route_reason``.

Roots: microfacet (Beckmann with Fresnel, GGX conductor: their albedo rises at grazing,
so every stage is an unchained one, two lookups), a test-local user-like modified Phong
(a formula kernel with the proxy sampler: monotone albedo, so a chained stage, one
lookup), and every reciprocal Phong-family (and Lambert) model that gives formulas when
this runs (pumped Phong is then tested with no change here).
"""

from __future__ import annotations

import gc
import math
import warnings

import numpy as np
import pytest

import brdfkit
from brdfkit._dual import formula, maximum, power, select
from brdfkit.models import Lobe, Param
from brdfkit.models._base import DerivedBRDF
from brdfkit.models.sampling import StrategySampled
from brdfkit.pumping import pump
from brdfkit.tables import build_lookup, build_uniform_lookup, lookup, lookup_w
from brdfkit.user.proxy_sampler import ProxyStrategy, proxy_formulas

mi = pytest.importorskip("mitsuba")
dr = pytest.importorskip("drjit")

from traced_helpers import float32_hemisphere as _hemisphere  # noqa: E402
from traced_helpers import variant as _variant  # noqa: E402

from brdfkit.render.mitsuba_bridge import (  # noqa: E402
    WavefrontRouteWarning,
    mitsuba_bsdf,
    wavefront,
)
from brdfkit.render.mitsuba_sphere import sphere_scene  # noqa: E402

INV_PI = 1.0 / math.pi
INV_2PI = 0.5 / math.pi


@formula
def user_phong(ix, iy, iz, ox, oy, oz, p):
    """ρ_d/π + ρ_s (n + 2)/(2π) max(R(ω_o)·ω_i, 0)^n over rows (ρ_d, ρ_s, n)."""
    live = (iz > 0.0) & (oz > 0.0)  # 0 below the horizon
    cos_r = maximum(2.0 * oz * iz - (ox * ix + oy * iy + oz * iz), 0.0)
    f = p[0] * INV_PI + p[1] * (p[2] + 2.0) * INV_2PI * power(cos_r, p[2])
    return select(live, f, 0.0)


class UserPhong(StrategySampled, DerivedBRDF):
    """A FormulaBRDF stand-in (tests/test_user_traced.py): formula kernel, proxy sampler."""

    def __init__(self, rho_d: float, rho_s: float, n: float):
        params = (Param("rho_d", 0.2, 0.0, 1.0, "", "diffuse"),
                  Param("rho_s", 0.5, 0.0, 1.0, "", "specular"),
                  Param("n", 20.0, 0.0, 1e4, "", "exponent"))
        super().__init__(name="user-phong", params=params,
                         values={"rho_d": rho_d, "rho_s": rho_s, "n": n}, reciprocal=True,
                         has_sampler=True, kernel=user_phong, packed=[[rho_d, rho_s, n]])

    def lobes(self):
        return [Lobe("mirror", math.sqrt(2.0 / 20.0)), Lobe("diffuse", math.pi / 2)]

    def _strategy(self, wo):
        return ProxyStrategy.of(self)

    def formulas(self):
        return proxy_formulas(self)


def _registered_with_formulas() -> list:
    """Reciprocal Phong-family and diffuse models (default parameters) that give formulas
    when this runs (the ports of issue 23 land separately)."""
    out = []
    for name in ("modified-phong", "phong-blinn-reciprocal", "modified-blinn-phong",
                 "lafortune", "lambert"):
        m = brdfkit.model(name)
        if m.formulas() is not None and m.reciprocal and m.isotropic:
            out.append(pytest.param(name, id=f"{name}-max"))
    return out


def _root(name: str):
    if name == "microfacet-beckmann":
        return brdfkit.model("microfacet", alpha=0.3, eta=1.5)
    if name == "microfacet-ggx-rgb":
        return brdfkit.model("microfacet", distribution="ggx", alpha=0.4,
                             eta=[0.2, 0.9, 1.1], k=[3.9, 2.4, 2.2])
    if name == "user-phong":
        return UserPhong(0.2, 0.5, 20.0)
    return brdfkit.model(name)


ROOTS = [pytest.param("microfacet-beckmann", "controlled", 1, id="beckmann-controlled"),
         pytest.param("microfacet-ggx-rgb", "max", 1, id="ggx-rgb-max"),
         pytest.param("user-phong", "max", 2, id="user-phong-max-x2")]
ROOTS += [pytest.param(p.values[0], "max", 1, id=p.id) for p in _registered_with_formulas()]


def _interaction(view: np.ndarray):
    si = dr.zeros(mi.SurfaceInteraction3f, view.shape[0])
    si.wi = mi.Vector3f(view.T.astype(np.float32))
    return si


@pytest.mark.parametrize(("root", "g", "times"), ROOTS)
def test_pumped_traced_matches_numba_and_samples_the_root(root, g, times):
    _variant("llvm_ad_rgb", llvm=True)
    base = _root(root)
    model = pump(base, g, times=times)
    assert model.formulas() is not None and model.formulas().tables == base.packed.shape[1]
    if root == "user-phong":
        assert model.chained  # the one-lookup composition (monotone albedo)
    elif root.startswith("microfacet"):
        assert not model.chained  # two lookups per stage (the albedo rises at grazing)
    ours = mitsuba_bsdf(model)
    assert ours.traced and ours.route_reason is None
    rng = np.random.default_rng(5)
    n = 512
    view, light = _hemisphere(rng, n), _hemisphere(rng, n)
    light[: n // 2] = view[: n // 2] * np.array([-1.0, -1.0, 1.0])  # the mirror lobe itself
    ctx = mi.BSDFContext()
    si, wo = _interaction(view), mi.Vector3f(light.T.astype(np.float32))
    got = np.array(ours.eval(ctx, si, wo)).T  # (n, 3): grey models repeat their channel
    want = np.asarray(model.eval(light, view)).reshape(n, -1) * light[:, 2:3]
    np.testing.assert_allclose(got, np.broadcast_to(want, got.shape), rtol=1e-4,
                               atol=1e-6 * want.max())
    root_f = np.asarray(base.eval(light, view)).reshape(n, -1) * light[:, 2:3]
    assert np.abs(got - root_f).max() > 1e-2 * root_f.max()  # power: the pump is in it
    # the root's sampler and pdf
    np.testing.assert_allclose(np.array(ours.pdf(ctx, si, wo)), base.pdf(light, view),
                               rtol=1e-4, atol=1e-7)
    u = rng.random((n, 2)).astype(np.float32)
    bs, _ = ours.sample(ctx, si, 0.5, mi.Point2f(u.T))
    want_wi, _ = base.sample(view, u.astype(float))
    np.testing.assert_allclose(np.array(bs.wo).T, want_wi, atol=2e-5)
    del ours
    gc.collect()


@pytest.mark.parametrize("kw", [
    {"distribution": "ggx", "alpha": 0.5, "eta": [0.2, 0.9, 1.1], "k": [3.9, 2.4, 2.2]},
    {"alpha": 0.3}], ids=["ggx-conductor-rgb", "beckmann-white"])
@pytest.mark.parametrize("method", ["turquin", "kulla-conty"])
def test_compensated_traced_matches_numba(kw, method):
    """Turquin's and Kulla–Conty's compensation (Ẽ read with lookup/lookup_w in the trace)
    against model.eval (the Numba kernel composed separately); the sampler: Turquin's the
    base's, Kulla–Conty's the mixture of the cosine and the base's sampler (its weight's Ẽ
    a polynomial, in NumPy and in the trace): traced pdf and directions = model.pdf and
    model.sample for the same u. (Kulla–Conty fell back to the wavefront route before.)"""
    _variant("llvm_ad_rgb", llvm=True)
    base = brdfkit.model("microfacet", **kw)
    model = brdfkit.compensate(base, method)
    ours = mitsuba_bsdf(model)
    assert ours.traced and ours.route_reason is None
    rng = np.random.default_rng(8)
    n = 512
    view, light = _hemisphere(rng, n), _hemisphere(rng, n)
    ctx = mi.BSDFContext()
    si, wo = _interaction(view), mi.Vector3f(light.T.astype(np.float32))
    got = np.array(ours.eval(ctx, si, wo)).T
    want = np.asarray(model.eval(light, view)).reshape(n, -1) * light[:, 2:3]
    np.testing.assert_allclose(got, np.broadcast_to(want, got.shape), rtol=1e-4,
                               atol=1e-6 * want.max())
    plain = np.asarray(base.eval(light, view)).reshape(n, -1) * light[:, 2:3]
    # power: the compensation is in it (Kulla–Conty's f_ms is small beside a peak)
    assert np.abs(got - plain).max() > 0.5 * np.abs(want - plain).max() > 1e-3
    np.testing.assert_allclose(np.array(ours.pdf(ctx, si, wo)), model.pdf(light, view),
                               rtol=1e-4, atol=1e-7)
    u = rng.random((n, 2)).astype(np.float32)
    bs, _ = ours.sample(ctx, si, 0.5, mi.Point2f(u.T))
    want_wi, _ = model.sample(view, u.astype(float))
    np.testing.assert_allclose(np.array(bs.wo).T, want_wi, atol=2e-5)
    if method == "kulla-conty":  # power: the cosine component is sampled too
        assert np.abs(model.pdf(light, view) - base.pdf(light, view)).max() > 1e-3
    del ours
    gc.collect()


def test_kulla_conty_traced_sampler_chi2():
    """Mitsuba's χ² harness on the traced Kulla–Conty sampler (cosine + GGX, weighted per
    ω_o) against its traced pdf."""
    _variant("llvm_ad_rgb")
    from mitsuba.chi2 import BSDFAdapter, ChiSquareTest, SphericalDomain

    props = {"type": "brdfkit", "model": "microfacet", "distribution": "ggx", "alpha": 0.6,
             "compensate": "kulla-conty"}
    sample_func, pdf_func = BSDFAdapter("brdfkit", props, wi=[0.6, 0.0, 0.8])
    chi2 = ChiSquareTest(domain=SphericalDomain(), sample_func=sample_func,
                         pdf_func=pdf_func, sample_dim=3, res=51, ires=4,
                         sample_count=200_000)
    assert chi2.run(), chi2.messages
    gc.collect()


@pytest.mark.parametrize("uniform", [False, True], ids=["two-level", "uniform-in-sqrt-mu"])
def test_lookup_primitive_gathers_what_the_table_holds(uniform):
    """The primitive's Dr.Jit read (through a pumped-like composition's row) against the
    float64 table object, per channel (three different tables)."""
    from brdfkit._dual import compose, drjit_version
    from brdfkit.traced_tables import TableRow, TracedTables

    _variant("llvm_ad_rgb")
    fns = [lambda m, a=a: (1.0 + a * m * m + 0.1 * np.sqrt(m))[:, None] for a in (0.5, 1.0, 2.0)]
    if uniform:
        tables = [build_uniform_lookup(lambda w, f=f: f(w * w), w0=0.0, h=1.0 / 16, n=16,
                                       w_min=0.0) for f in fns]
    else:
        tables = [build_lookup(f, kinks=[0.3]) for f in fns]
    blocks = [t.packed(0) for t in tables]
    width = max(b.size for b in blocks)
    k = 2  # two parameter columns before the tables
    rows = np.array([np.concatenate([[1.0, 2.0], b, np.zeros(width - b.size)]) for b in blocks])
    read = drjit_version(compose(_read_w if uniform else _read, k=k))
    mu = np.concatenate([np.random.default_rng(3).random(200), np.arange(65) / 64.0,
                         [0.0, 1.0, 1e-7]])
    row = TableRow([1.0, 2.0], TracedTables(rows, k, mi.Float, lambda v: mi.Color3f(*v)))
    got = np.array(read(mi.Float(mu.astype(np.float32)), row)).T
    want = np.stack([t(mu.astype(np.float32).astype(float))[:, 0] for t in tables], -1)
    np.testing.assert_allclose(got, want, rtol=2e-6 * 8)  # float32 Horner on ~1-3 values
    # a parameter; a column from the tables on: per channel when they differ, else a float
    assert row[0] == 1.0 and row[-1] == tuple(rows[:, -1]) and row[2] == rows[0, 2]


k = 0  # the tables' column, bound by compose in the two templates below


def _read(mu, p):
    return lookup(p, k, mu)


def _read_w(mu, p):
    return lookup_w(p, k, mu)


def test_fallback_says_why_in_one_line():
    """A model without formulas takes the wavefront route with a one-line reason."""
    _variant("llvm_ad_rgb")
    plain = _Plain()
    with pytest.warns(WavefrontRouteWarning) as rec:
        b = mitsuba_bsdf(plain)
    assert not b.traced
    msg = str(rec[0].message)
    assert "\n" not in msg and "plain: no formulas" in msg and "wavefront()" in msg
    assert b.route_reason in msg
    with warnings.catch_warnings():
        warnings.simplefilter("error", WavefrontRouteWarning)
        forced = mitsuba_bsdf(brdfkit.model("microfacet"), route="wavefront")  # asked: silent
    assert forced.route_reason == "route='wavefront' asked for"
    del b, forced
    gc.collect()


class _Plain(DerivedBRDF):
    """A NumPy-only Lambertian (no kernel, no formulas)."""

    def __init__(self):
        super().__init__(name="plain", params=(), values={}, reciprocal=True)

    def eval(self, wi, wo):
        wi, wo = np.asarray(wi, dtype=float), np.asarray(wo, dtype=float)
        return np.where((wi[..., 2] > 0) & (wo[..., 2] > 0), INV_PI, 0.0)


def _routes_model(name: str):
    if name == "pumped-microfacet":
        return pump(brdfkit.model("microfacet", alpha=0.3, eta=1.5), "controlled")
    return brdfkit.model("he-torrance", sigma0=0.1, tau=1.7, rho_d=0.2)  # (its formulas
    # have fixed-length σ and series: tests/test_formulas_he_torrance.py)


@pytest.mark.parametrize("name", ["pumped-microfacet", "he-torrance"])
def test_traced_render_equals_the_wavefront_render(name):
    """Same seed, same sampler formula: the two routes render the same image (the
    wavefront route evaluates the float64 Numba kernel)."""
    variant = _variant("llvm_ad_rgb", llvm=True)
    model = _routes_model(name)

    def render(route):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # he-torrance's delta: not rendered
            bsdf = mitsuba_bsdf(model, route=route)
        scene = mi.load_dict(sphere_scene(bsdf, phi_l=0.5, ambient=0.3, size=16,
                                          variant=variant))
        if bsdf.traced:
            img = np.array(mi.render(scene, spp=16, seed=7), dtype=float)
        else:
            with wavefront():
                img = np.array(mi.render(scene, spp=16, seed=7), dtype=float)
        del scene, bsdf
        gc.collect()
        return img

    traced = render("auto")
    wave = render("wavefront")
    assert traced.max() > 0.05
    # float32 rounding of the two compilations, amplified where a sample is grazing
    np.testing.assert_allclose(traced, wave, rtol=1e-3, atol=1e-5 * wave.max())
    if name == "pumped-microfacet":
        unpumped = brdfkit.model("microfacet", alpha=0.3, eta=1.5)
        assert np.abs(traced - _render_plain(unpumped, variant)).max() > 1e-2 * traced.max()


def _render_plain(model, variant):
    bsdf = mitsuba_bsdf(model)
    scene = mi.load_dict(sphere_scene(bsdf, phi_l=0.5, ambient=0.3, size=16, variant=variant))
    img = np.array(mi.render(scene, spp=16, seed=7), dtype=float)
    del scene, bsdf
    gc.collect()
    return img


@pytest.mark.parametrize("kw", [
    {}, {"lobe": "phong"}, {"n": 0.0},
    {"k_rho": [0.9, 0.6, 0.3], "k_sigma": [0.2, 0.5, 0.8], "n": 5.0, "lobe": "phong"},
    {"k_sigma": 1.0, "n": 200.0}], ids=["blinn", "phong", "n0", "rgb-phong", "blinn-lobe-only"])
def test_phong_energy_conserving_traced(kw):
    """Lewis eq. (22) (H_s read in the trace) against model.eval, and its mixture sampler
    formulas against model.sample/pdf (the NumPy Mixture of the cosine and the lobe): the
    same directions and densities to float32 rounding; the formula's Numba compilation
    against model.eval (float64)."""
    _variant("llvm_ad_rgb", llvm=True)
    model = brdfkit.model("phong-energy-conserving", **kw)
    form = model.formulas()
    ours = mitsuba_bsdf(model)
    assert ours.traced
    rng = np.random.default_rng(2)
    n = 400
    view, light = _hemisphere(rng, n), _hemisphere(rng, n)
    light[: n // 2] = view[: n // 2] * np.array([-1.0, -1.0, 1.0])  # the lobe's peak
    ctx = mi.BSDFContext()
    si, wo = _interaction(view), mi.Vector3f(light.T.astype(np.float32))
    want = np.asarray(model.eval(light, view)).reshape(n, -1)
    got = np.array(ours.eval(ctx, si, wo)).T
    np.testing.assert_allclose(got, np.broadcast_to(want * light[:, 2:3], got.shape),
                               rtol=2e-4, atol=1e-6 * want.max())
    np.testing.assert_allclose(np.array(ours.pdf(ctx, si, wo)), model.pdf(light, view),
                               rtol=2e-4, atol=1e-6 * model.pdf(light, view).max())
    u = rng.random((n, 2)).astype(np.float32)
    bs, _ = ours.sample(ctx, si, 0.5, mi.Point2f(u.T))
    want_wi, _ = model.sample(view, u.astype(float))
    np.testing.assert_allclose(np.array(bs.wo).T, want_wi, atol=2e-5)
    row = model.packed[0]
    numba_f = [form.eval(*light[j], *view[j], row) for j in range(8)]
    np.testing.assert_allclose(numba_f, want[:8, 0], rtol=1e-12)
    del ours
    gc.collect()
