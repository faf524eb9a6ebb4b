"""Accuracy of the speed-ups in the microfacet kernels.

References are independent of the fast code: the erf form of Walter eq. (27)
evaluated with ``math.erf``/``math.exp`` (and, at large a, the asymptotic
series of erfc), and the straightforward per-factor evaluation of Walter
eq. (20) / Neumann eqs. (9)–(10) written out here in Python.
"""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest

import brdfkit
from brdfkit._kern import exp_nonpos
from brdfkit.models.microfacet import (
    G1_A_MAX,
    beckmann_g1_of_a,
    smith_g1_beckmann,
    smith_g1_beckmann_exact,
)

SQRT_PI = math.sqrt(math.pi)


@numba.njit(cache=False)
def _g1_many(a, out):  # pragma: no cover - compiled
    for i in range(a.size):
        out[i] = beckmann_g1_of_a(a[i])


def _g1_erf(a: float) -> float:
    """Walter eq. (27), G₁ = 2/(1 + erf a + e^{−a²}/(a√π)), with the math module."""
    return 2.0 / (1.0 + math.erf(a) + math.exp(-a * a) / (a * SQRT_PI))


def test_g1_table_matches_erf_form_on_a_million_points():
    rng = np.random.default_rng(2024)
    a = np.concatenate([
        rng.uniform(0.0, 6.5, 1_000_000),  # the tabulated range and beyond
        10.0 ** rng.uniform(-300.0, 0.0, 20_000),  # grazing: G₁ → 2a√π
        np.linspace(0.0, G1_A_MAX, 129)[1:],  # interval end points of the table
    ])
    out = np.empty_like(a)
    _g1_many(a, out)
    ref = np.array([_g1_erf(t) for t in a])
    rel = np.abs(out / ref - 1.0)
    assert rel.max() < 1e-13, (rel.max(), a[np.argmax(rel)])


def test_g1_is_exactly_one_beyond_the_cutoff():
    # 1 − G₁ = (e^{−a²}/(a√π) − erfc a)/2 + O(·) ≈ e^{−a²}/(4 a³ √π) by the asymptotic series
    # erfc a = e^{−a²}/(a√π) (1 − 1/(2a²) + …); at a = 6 this is 1.6e-19 < 2^{−53}.
    a = G1_A_MAX
    assert math.exp(-a * a) / (4.0 * a**3 * SQRT_PI) < 2.0**-53
    for t in (6.0, 6.0000001, 7.0, 50.0, 1e300, math.inf):
        assert beckmann_g1_of_a(t) == 1.0
    assert beckmann_g1_of_a(0.0) == 0.0


def test_smith_g1_wrapper_matches_exact_form():
    alpha = 0.3
    for cos_v in np.linspace(1e-12, 1.0, 2001):
        ref = smith_g1_beckmann_exact(cos_v, 1.0, alpha)
        got = smith_g1_beckmann(cos_v, 1.0, alpha)
        assert got == pytest.approx(ref, rel=1e-13, abs=0.0)
    assert smith_g1_beckmann(0.0, 1.0, alpha) == 0.0
    assert smith_g1_beckmann(0.5, -0.1, alpha) == 0.0  # χ⁺(v·h)


def _walter_reference(wi, wo, alpha):
    """Walter eq. (20) with F = 1, factor by factor (unit half vector, D eq. 25, G₁ eq. 27)."""
    out = np.zeros(len(wi))
    for j, (l, v) in enumerate(zip(wi, wo, strict=True)):
        if l[2] <= 0.0 or v[2] <= 0.0:
            continue
        h = (l + v) / np.linalg.norm(l + v)
        c = h[2]
        tan2 = (h[0] ** 2 + h[1] ** 2) / (c * c)  # the definition (no cancellation near 1)
        d = math.exp(-tan2 / alpha**2) / (math.pi * alpha**2 * c**4)
        g = 1.0
        for z in (l[2], v[2]):
            s = math.sqrt(max(0.0, 1.0 - z * z))
            g *= 1.0 if s == 0.0 else _g1_erf(z / (alpha * s))
        out[j] = d * g / (4.0 * l[2] * v[2])
    return out


@pytest.mark.parametrize("alpha", [0.01, 0.1, 0.5, 2.0])
def test_microfacet_fast_path_matches_factorwise_formula(alpha):
    rng = np.random.default_rng(7)
    n = 4000

    def hemi():
        z = rng.uniform(0.0, 1.0, n)
        phi = rng.uniform(0.0, 2.0 * np.pi, n)
        r = np.sqrt(1.0 - z * z)
        return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)

    wi, wo = hemi(), hemi()
    # the first quarter near the mirror direction
    wo[: n // 4] = wi[: n // 4] * [-1.0, -1.0, 1.0] + rng.normal(0, 0.02, (n // 4, 3))
    wo /= np.linalg.norm(wo, axis=-1, keepdims=True)
    wo[:, 2] = np.abs(wo[:, 2])
    got = brdfkit.model("microfacet", alpha=alpha).eval(wi, wo)
    ref = _walter_reference(wi, wo, alpha)
    # the exponent −tan²θ_h/α² is rounded differently (≤ ~4 ulp): e^x amplifies that by |x|
    tan2 = ((wi + wo)[:, 0] ** 2 + (wi + wo)[:, 1] ** 2) / (wi + wo)[:, 2] ** 2
    tol = 1e-13 + 1e-15 * tan2 / alpha**2
    big = ref > 1e-290
    assert np.all(np.abs(got[big] - ref[big]) <= tol[big] * ref[big])
    assert np.all(got[~big] <= 1e-280)


def test_fast_kernels_nan_free_at_and_below_horizon():
    grazing = [1.0, 0.0, 0.0]
    pairs = [
        ([1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]),
        ([1.0, 0.0, 1e-200], [-1.0, 0.0, 1e-200]),  # s_z² underflows, s_xy = 0
        ([1.0, 0.0, 1e-170], [1.0, 0.0, 1e-170]),
        ([0.0, 0.0, 1.0], [0.0, 0.0, 1.0]),
        ([0.6, 0.0, 0.8], grazing),
        ([0.6, 0.0, -0.8], [0.0, 0.0, 1.0]),
    ]
    wi = np.array([p[0] for p in pairs])
    wo = np.array([p[1] for p in pairs])
    for name, kw in (("microfacet", {}), ("microfacet", {"eta": 1.5}),
                     ("microfacet", {"alpha": 1e-3}), ("cook-torrance", {}),
                     ("cook-torrance", {"eta": 1.5})):
        f = brdfkit.model(name, **kw).eval(wi, wo)
        assert np.all(np.isfinite(f)) and np.all(f >= 0.0), (name, kw, f)
        assert f[0] == 0.0 and f[4] == 0.0 and f[5] == 0.0  # horizon / below it


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("name", ["microfacet", "modified-phong", "lambert"])
def test_eval_rejects_non_finite_directions_in_the_fused_pass(name, bad):
    # BRDF.eval tests finiteness inside the compiled loop (eval_pairs_checked), not with
    # np.isfinite beforehand; the error must still name the argument.
    from brdfkit.errors import BrdfkitError

    m = brdfkit.model(name)
    good = np.tile([0.0, 0.6, 0.8], (50, 1))
    for arg in ("wi", "wo"):
        v = good.copy()
        v[37, 1] = bad
        args = (v, good) if arg == "wi" else (good, v)
        with pytest.raises(BrdfkitError, match=f"{arg} contains NaN or infinite"):
            m.eval(*args)
    # broadcasting a single bad direction against many, and per-channel parameters
    with pytest.raises(BrdfkitError, match="wo contains"):
        m.eval(good, [0.0, bad, 1.0])
    if name == "microfacet":
        with pytest.raises(BrdfkitError, match="wi contains"):
            brdfkit.model(name, rho_s=[1.0, 0.5]).eval([bad, 0.0, 1.0], good)


def test_eval_pairs_checked_counts_bad_pairs_and_leaves_good_rows_exact():
    from brdfkit.models._base import eval_pairs, eval_pairs_checked

    m = brdfkit.model("microfacet", rho_s=[1.0, 0.5, 0.25])
    rng = np.random.default_rng(3)
    wi = rng.normal(size=(100, 3))
    wi /= np.linalg.norm(wi, axis=-1, keepdims=True)
    wo = np.abs(rng.normal(size=(100, 3)))
    wo /= np.linalg.norm(wo, axis=-1, keepdims=True)
    ref = np.empty((100, 3))
    eval_pairs(m.kernel, wi, wo, m.packed, ref)
    wi[[3, 50]] = [math.nan, 0.0, 1.0]
    wo[77, 2] = math.inf
    out = np.empty((100, 3))
    assert eval_pairs_checked(m.kernel, wi, wo, m.packed, out) == 3
    good = np.ones(100, bool)
    good[[3, 50, 77]] = False
    np.testing.assert_array_equal(out[good], ref[good])
    assert np.all(np.isnan(out[~good]))


@numba.njit(cache=False)
def _exp_many(x, out):  # pragma: no cover - compiled
    for i in range(x.size):
        out[i] = exp_nonpos(x[i])


def test_vectorisable_exp_matches_libm():
    # exp_nonpos replaces math.exp in the vectorised microfacet kernel (no SVML here)
    rng = np.random.default_rng(8)
    x = np.concatenate([-rng.uniform(0.0, 708.0, 200_000), -np.linspace(0.0, 760.0, 7601),
                        [-0.0, -1e-300, -745.2, -746.0, -1000.0, -math.inf]])
    out = np.empty_like(x)
    _exp_many(x, out)
    normal = x > -708.0
    ref = np.exp(x)
    assert np.max(np.abs(out[normal] / ref[normal] - 1.0)) <= 2.5e-16
    assert np.all(out[x == 0.0] == 1.0)
    assert np.all(out[x <= -746.0] == 0.0)
    sub = (x < -708.0) & (x > -745.0)  # subnormal results: one rounding to the subnormal grid
    assert np.all(np.abs(out[sub] - ref[sub]) <= 2.0 * 5e-324 + 1e-15 * ref[sub])


def test_distribution_objects_agree_with_the_kernels():
    # one distribution, one D: the NumPy object (sampling pdf) and the compiled functions
    from brdfkit.models.microfacet_distributions import d_beckmann, d_ggx, distribution

    rng = np.random.default_rng(4)
    for kind, d_kernel in (("beckmann", d_beckmann), ("ggx", d_ggx)):
        for alpha in (0.05, 0.5):
            dist = distribution(kind, alpha)
            h = dist.sample(rng.random((2000, 2)))
            assert np.allclose(np.linalg.norm(h, axis=-1), 1.0, atol=1e-14)
            ref = np.array([d_kernel(c, alpha) for c in h[:, 2]])
            big = ref > 1e-200
            np.testing.assert_allclose(dist.d(h)[big], ref[big], rtol=1e-9)
            np.testing.assert_allclose(dist.pdf(h), dist.d(h) * h[:, 2], rtol=1e-15)


#: Registered models whose model.eval keeps the checked (scalar) loop of their kernel, and
#: why: a lobe xⁿ with a real exponent per pair calls libm's pow on every lane (no SVML
#: here), measured slower in the vectorising loop than the scalar kernel (issue 23)
SCALAR_EVAL = {
    "phong-energy-conserving": "pow(x, n) per lane (real n): 28 vs 41 M evals/s scalar",
    "ashikhmin-shirley": "pow(N·H, e) with e per pair: 21 vs 23 M evals/s scalar",
    "he-torrance": "its D series' length depends on the pair (the formula's fixed length "
                   "is for the traced route)",
}


@pytest.mark.parametrize("name", sorted(brdfkit.models.MODELS))
def test_eval_runs_the_vectorising_loop(name):
    # the "vector"/"rgb" loops of models/_drivers are the generated modules holding a
    # `chunk` function (the inner loop LLVM vectorises); lafortune and nh-power-series ran
    # the scalar loop over their lobes before their unrolled formulas became their eval
    for example in type(brdfkit.model(name)).examples:
        m = brdfkit.model(name, **example)
        vector = m._driver is not None and "chunk" in m._driver.py_func.__globals__
        assert vector == (name not in SCALAR_EVAL), (name, example, SCALAR_EVAL.get(name))
