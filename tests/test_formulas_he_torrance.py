"""he-torrance as formulas (:mod:`brdfkit._dual`): fixed-length σ and D's series, traced.

References (independent of the code under test):

- σ: HTSG's equation √(π/2) u = A e^{−u²/2} (u = z₀/σ₀) solved in closed form by SciPy's
  Lambert W (u² = W(B²), B = A√(2/π); ``scipy.special.lambertw``, another implementation),
  and the kernel's safeguarded Newton (:func:`htsg_sigma`) where it converges;
- the series: the truncated sum written again here (a Python loop of N terms) against the
  kernel's :func:`htsg_series` (summed outward from the Poisson mode to 1e-12 relative),
  for the claimed bound |T_N − T| ≤ 1e-12·T(g, 0) at every g ≤ (4πσ₀)²;
- f_r: the float64 kernel (``model.eval``); the sampler: ``model.sample``/``pdf`` (NumPy
  ``Mixture``); in Mitsuba (float32) the traced BSDF against them (the traced and
  wavefront routes' images from one seed: tests/test_mitsuba_derived.py).
"""

from __future__ import annotations

import gc
import math
import warnings

import numpy as np
import pytest
from scipy.special import lambertw

import brdfkit
from brdfkit.models.he_torrance import (
    SERIES_MAX_TERMS,
    _htsg_k,
    htsg_k_shadow_formula,
    htsg_series,
    htsg_shadow,
    htsg_sigma,
    htsg_sigma_of_coef_formula,
    series_terms,
)

EXAMPLES = type(brdfkit.model("he-torrance")).examples


def _sigma_lambert(cos_i, cos_r, sigma0, tau):
    """σ₀/√(1 + u²), u² = W(B²) by SciPy (B² formed in logs, W's asymptotic series where
    B² overflows: W(x) = L − ln L + ln L/L + …, L = ln x, error O((ln L/L)²) < 1e-5 only
    for L > 700, so such cases are compared with that tolerance)."""
    a = 0.25 * (_htsg_k(cos_i, sigma0, tau) + _htsg_k(cos_r, sigma0, tau))
    if a <= 0.0:
        return sigma0, 0.0
    big_l = 2.0 * math.log(a) + math.log(2.0 / math.pi)
    if big_l < 700.0:
        w = float(lambertw(math.exp(big_l)).real)
        tol = 1e-13
    else:
        ll = math.log(big_l)
        w = big_l - ll + ll / big_l + ll * (ll - 2.0) / (2.0 * big_l * big_l)
        tol = 1e-8
    return sigma0 / math.sqrt(1.0 + w), tol


def _sigma_formula(cos_i, cos_r, sigma0, tau):
    """σ as the kernel and the traced formula compute it: A from each direction's K."""
    k_i, _ = htsg_k_shadow_formula(cos_i, sigma0, tau)
    k_r, _ = htsg_k_shadow_formula(cos_r, sigma0, tau)
    return htsg_sigma_of_coef_formula(0.25 * (k_i + k_r), sigma0)


def test_sigma_formula_is_the_lambert_w_root():
    """The fixed four Newton steps give HTSG's root to ~1e-15 over σ₀, τ across their
    declared ranges and cosines from the horizon (1e-300) to the normal; the kernel's
    Newton agrees where it converges (A < 1e30: for A ≳ 1e57, cosines within ~1e-57 of
    the horizon, its 100 steps of ≈ 1/u from u = hi/2 stop short of the root)."""
    worst = 0.0
    for s0 in (1e-3, 0.02, 0.1, 0.3, 2.0, 10.0):
        for tau in (0.01, 1.7, 10.0, 1000.0):
            for ci in (1e-300, 1e-60, 1e-12, 1e-5, 0.01, 0.3, 0.9, 1.0):
                for cr in (1e-8, 0.2, 0.99, 1.0):
                    want, tol = _sigma_lambert(ci, cr, s0, tau)
                    got = _sigma_formula(ci, cr, s0, tau)
                    assert got == pytest.approx(want, rel=tol), (s0, tau, ci, cr)
                    a = 0.25 * (_htsg_k(ci, s0, tau) + _htsg_k(cr, s0, tau))
                    if a < 1e30:
                        kern = htsg_sigma(ci, cr, s0, tau)
                        worst = max(worst, abs(got - kern) / kern)
    assert worst < 1e-13, worst


@pytest.mark.parametrize("sigma0", [0.02, 0.1, 0.3])
def test_series_length_meets_its_bound(sigma0):
    """N = series_terms((4πσ₀)²) terms of T = S/g: |T_N − T| ≤ 1e-12·T(g, 0) for g up to
    (4πσ₀)² and a from 0 to 1e4; half as many terms miss it at g = (4πσ₀)² (power)."""
    g_max = (4.0 * math.pi * sigma0) ** 2
    n = series_terms(g_max)
    assert n <= SERIES_MAX_TERMS

    def t_n(g, a, terms):
        w, t = math.exp(-g), 0.0
        for m in range(1, terms + 1):
            w = w if m == 1 else w * g / m
            t += w / m * math.exp(-a / m)
        return t

    for g in np.linspace(0.0, g_max, 9)[1:]:
        ref0 = htsg_series(g, 0.0) / g
        for a in (0.0, 0.5, 5.0, 50.0, 1e4):
            assert abs(t_n(g, a, n) - htsg_series(g, a) / g) <= 1e-12 * ref0, (g, a)
    ref = htsg_series(g_max, 0.0) / g_max
    assert ref - t_n(g_max, 0.0, n // 2) > 1e-12 * ref


def _pairs(rng, k=300):
    def unit(v):
        return v / np.linalg.norm(v, axis=-1, keepdims=True)

    wo = unit(rng.normal(size=(k, 3)))
    wo[:, 2] = np.abs(wo[:, 2])
    wi = unit(rng.normal(size=(k, 3)))
    wi[: k // 3] = wo[: k // 3] * [-1.0, -1.0, 1.0]  # the specular peak
    return wi, wo


@pytest.mark.parametrize("j", range(len(EXAMPLES)))
def test_formula_equals_kernel_and_sampler(j):
    """The compiled formula against model.eval (1e-12 of the lobe's peak: the series bound
    and σ's ~1e-15), 0 below the horizon; the formula sampler and pdf (ward_sample's
    cosine + Beckmann mixture) against model.sample/pdf for the same u."""
    m = brdfkit.model("he-torrance", **EXAMPLES[j])
    form = m.formulas()
    assert form is not None  # None before (a wavefront_reason)
    rng = np.random.default_rng(11 + j)
    wi, wo = _pairs(rng)
    wi[-20:, 2] *= -1.0  # below the horizon
    ev = m.eval(wi, wo)
    ev = ev if ev.ndim == 2 else ev[:, None]
    for c in range(m.packed.shape[0]):
        got = np.array([form.eval(*wi[k], *wo[k], m.packed[c]) for k in range(len(wi))])
        np.testing.assert_allclose(got, ev[:, c], rtol=1e-10, atol=1e-12 * ev[:, c].max())
        assert np.all(got[wi[:, 2] <= 0.0] == 0.0)
    u = rng.random((len(wo), 2))
    want, p = m.sample(wo, u)
    got = np.array([form.sample(*wo[k], *u[k], *form.args) for k in range(len(wo))])
    np.testing.assert_allclose(got, want, atol=1e-12)
    gp = np.array([form.pdf(*want[k], *wo[k], *form.args) for k in range(len(wo))])
    np.testing.assert_allclose(gp, p, rtol=1e-12)


def test_rough_beyond_the_series_length_takes_the_wavefront_route():
    """σ₀ = 1 needs more than SERIES_MAX_TERMS terms: no formulas (the wavefront route)."""
    assert series_terms((4.0 * math.pi) ** 2) > SERIES_MAX_TERMS
    assert brdfkit.model("he-torrance", sigma0=1.0, tau=10.0).formulas() is None


# --------------------------------------------------------------------------- Mitsuba
mi = pytest.importorskip("mitsuba")
dr = pytest.importorskip("drjit")

from brdfkit.render.mitsuba_bridge import (  # noqa: E402
    WavefrontRouteWarning,
    mitsuba_bsdf,
    use_variant,
)


def _llvm_rgb() -> str:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        v = use_variant("llvm_ad_rgb")
    if not v.startswith("llvm"):
        pytest.skip("the traced route needs an llvm variant")
    return v


def _bsdf(model, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # its delta spike is not rendered
        return mitsuba_bsdf(model, **kw)


@pytest.mark.parametrize("j", range(len(EXAMPLES)))
def test_traced_matches_numba(j):
    """The traced BSDF (float32, erfc by Numerical Recipes' 1.2e-7 fit) against the float64
    kernel: eval (f cos θ_i), pdf and directions from the same u."""
    _llvm_rgb()
    m = brdfkit.model("he-torrance", **EXAMPLES[j])
    ours = _bsdf(m)
    assert ours.traced
    rng = np.random.default_rng(3 + j)
    wi, wo = _pairs(rng, 256)
    wi[:, 2] = np.maximum(np.abs(wi[:, 2]), 0.05)
    wo[:, 2] = np.maximum(wo[:, 2], 0.05)
    wi = (wi / np.linalg.norm(wi, axis=-1, keepdims=True)).astype(np.float32).astype(float)
    wo = (wo / np.linalg.norm(wo, axis=-1, keepdims=True)).astype(np.float32).astype(float)
    si = dr.zeros(mi.SurfaceInteraction3f, len(wo))
    si.wi = mi.Vector3f(wo.T.astype(np.float32))
    ctx = mi.BSDFContext()
    light = mi.Vector3f(wi.T.astype(np.float32))
    got = np.array(ours.eval(ctx, si, light)).T
    f = m.eval(wi, wo)
    want = (f if f.ndim == 2 else f[:, None]) * wi[:, 2:3]
    # float32: ~40 operations and the series' e^{−a/m} (a up to ~10²: 1e-5 relative)
    np.testing.assert_allclose(got, np.broadcast_to(want, got.shape), rtol=2e-4,
                               atol=1e-6 * want.max())
    np.testing.assert_allclose(np.array(ours.pdf(ctx, si, light)), m.pdf(wi, wo),
                               rtol=2e-4, atol=1e-7)
    u = rng.random((256, 2)).astype(np.float32)
    bs, _ = ours.sample(ctx, si, 0.5, mi.Point2f(u.T))
    np.testing.assert_allclose(np.array(bs.wo).T, m.sample(wo, u.astype(float))[0], atol=2e-5)
    del ours
    gc.collect()


def test_rough_beyond_the_series_says_why():
    """σ₀ = 1 (no formulas): the wavefront route, with a one-line reason. The traced and
    wavefront renders of he-torrance are compared in tests/test_mitsuba_derived.py."""
    _llvm_rgb()
    rough = brdfkit.model("he-torrance", sigma0=1.0, tau=10.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        with pytest.warns(WavefrontRouteWarning, match="he-torrance: no formulas"):
            b = mitsuba_bsdf(rough)
    assert not b.traced and "\n" not in b.route_reason
    del b
    gc.collect()


def test_shared_erfc_equals_the_separate_k_and_shadow():
    """K and S of a direction from one erfc (htsg_k_shadow_formula, the kernel's and the
    traced route's) equal the branching reference functions _htsg_k and htsg_shadow, each
    with its own erfc of the same argument, bit for bit at cosines ≥ 1e-300 (TINY_COS); and
    σ from them is the Lambert-W root of SciPy (reference above)."""
    for s0 in (1e-3, 0.1, 0.3, 10.0):
        for tau in (0.01, 1.7, 1000.0):
            for c in (1e-300, 1e-12, 1e-5, 0.01, 0.3, 0.9, 1.0):
                k, s = htsg_k_shadow_formula(c, s0, tau)
                assert k == _htsg_k(c, s0, tau), (s0, tau, c)
                assert s == htsg_shadow(c, s0, tau), (s0, tau, c)
                want, tol = _sigma_lambert(c, 0.5, s0, tau)
                assert _sigma_formula(c, 0.5, s0, tau) == pytest.approx(want, rel=tol), \
                    (s0, tau, c)
