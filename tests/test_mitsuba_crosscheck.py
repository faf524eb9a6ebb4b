"""Cross-check of ``microfacet`` against Mitsuba 3's ``roughconductor`` (external implementation).

Mitsuba 3 (variant ``scalar_rgb``, float32) evaluates the same Walter et al. 2007
model: D (Beckmann or GGX), separable Smith masking, exact conductor Fresnel
with complex index eta + i k. Differences we account for explicitly:

- Mitsuba's ``BSDF.eval`` returns f_r cos θ_o (θ_o of its ``wo`` argument);
  we divide it out.
- Mitsuba's Beckmann G₁ is Walter's rational approximation (Walter et al.
  2007, eq. 27: (3.535a + 2.181a²)/(1 + 2.276a + 2.577a²) for a < 1.6, else 1;
  quoted error < 0.35 %), while brdfkit uses the exact erf form. The test
  multiplies our value by the ratio of the two G₁ products (computed here),
  and separately checks the raw agreement against the bound (1.0035)² − 1.
- GGX's G₁ is exact in both.
- ``sample_visible=False`` so that Mitsuba's sampler is not involved (only eval).

Tolerances: float32 has a relative precision of 6e-8 per operation; a few tens of
operations give ~1e-6 to 1e-5; 1e-4 relative is used, with an absolute floor
for values that are tiny relative to the lobe peak.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

mi = pytest.importorskip("mitsuba")

import brdfkit  # noqa: E402
from brdfkit.geometry import spherical_to_cartesian  # noqa: E402

ETA = [0.2, 0.9, 1.1]
K = [3.9, 2.4, 2.2]
ALPHAS = [0.05, 0.1, 0.3, 0.6]
N_PAIRS = 300


@pytest.fixture(scope="module")
def variant():
    mi.set_variant("scalar_rgb")
    return mi


MAX_THETA = math.radians(88.0)


def directions(rng, n, max_theta=MAX_THETA):
    # cos θ uniform in [cos max, 1]: uniform on the cap of the hemisphere
    z = rng.uniform(math.cos(max_theta), 1.0, n)
    phi = rng.uniform(0.0, 2 * math.pi, n)
    return spherical_to_cartesian(np.arccos(z), phi)


def pairs(rng, alpha):
    """Random pairs plus pairs near the specular lobe (so that the lobe itself is tested)."""
    wi = directions(rng, N_PAIRS)
    wo_random = directions(rng, N_PAIRS // 2)
    # near-mirror: perturb the mirror of wi by ~alpha
    mirror = wi[N_PAIRS // 2:] * np.array([-1.0, -1.0, 1.0])
    jitter = rng.normal(scale=alpha, size=mirror.shape)
    near = mirror + jitter
    near[:, 2] = np.abs(near[:, 2]) + 1e-3
    near /= np.linalg.norm(near, axis=-1, keepdims=True)
    return wi, np.concatenate([wo_random, near])


def mitsuba_eval(mi, distribution, alpha, wi, wo):
    bsdf = mi.load_dict({
        "type": "roughconductor",
        "distribution": distribution,
        "alpha": alpha,
        "eta": {"type": "rgb", "value": ETA},
        "k": {"type": "rgb", "value": K},
        "sample_visible": False,
    })
    ctx = mi.BSDFContext()
    out = np.empty((len(wi), 3))
    for j, (a, b) in enumerate(zip(wi, wo, strict=True)):
        si = mi.SurfaceInteraction3f()
        si.wi = mi.Vector3f(*map(float, a))
        v = bsdf.eval(ctx, si, mi.Vector3f(*map(float, b)))
        out[j] = [v[0], v[1], v[2]]
    return out / wo[:, 2:3]  # Mitsuba's eval includes cos θ_o: divide it out


def g1_exact(cos_v, alpha):
    """Exact Smith G1 for Beckmann (Walter eq. 27 before the fit), written out here."""
    from scipy.special import erf

    a = cos_v / (alpha * np.sqrt(1 - cos_v**2))
    return 2.0 / (1.0 + erf(a) + np.exp(-a * a) / (a * math.sqrt(math.pi)))


def g1_walter_rational(cos_v, alpha):
    """Walter et al. 2007 eq. (27), the approximation Mitsuba 3 uses for Beckmann."""
    a = cos_v / (alpha * np.sqrt(1 - cos_v**2))
    return np.where(a >= 1.6, 1.0, (3.535 * a + 2.181 * a * a) / (1 + 2.276 * a + 2.577 * a * a))


def compare(ours, theirs):
    peak = np.max(np.abs(theirs))
    err = np.abs(ours - theirs) / np.maximum(np.abs(theirs), 1e-6 * peak)
    return float(np.max(err))


@pytest.mark.parametrize("alpha", ALPHAS)
def test_ggx_matches_mitsuba(variant, alpha):
    rng = np.random.default_rng(int(alpha * 1000) + 1)
    wi, wo = pairs(rng, alpha)
    ours = brdfkit.model("microfacet", distribution="ggx", alpha=alpha, eta=ETA, k=K).eval(wi, wo)
    theirs = mitsuba_eval(variant, "ggx", alpha, wi, wo)
    assert np.max(theirs) > 0.1  # the lobe was hit
    assert compare(ours, theirs) < 1e-4


@pytest.mark.parametrize("alpha", ALPHAS)
def test_beckmann_matches_mitsuba(variant, alpha):
    rng = np.random.default_rng(int(alpha * 1000) + 2)
    wi, wo = pairs(rng, alpha)
    ours = brdfkit.model("microfacet", distribution="beckmann", alpha=alpha, eta=ETA,
                         k=K).eval(wi, wo)
    theirs = mitsuba_eval(variant, "beckmann", alpha, wi, wo)
    assert np.max(theirs) > 0.1
    # raw: within Walter's stated bound on the fit, for the two G1 factors
    assert compare(ours, theirs) < 1.0035**2 - 1.0
    # with our exact G1 replaced by Mitsuba's rational fit: float32-level agreement
    ratio = (g1_walter_rational(wi[:, 2], alpha) * g1_walter_rational(wo[:, 2], alpha)
             / (g1_exact(wi[:, 2], alpha) * g1_exact(wo[:, 2], alpha)))
    assert compare(ours * ratio[:, None], theirs) < 1e-4


def test_below_horizon_both_zero(variant):
    wi = np.array([[0.3, 0.0, -0.95393920141694566]])
    wo = np.array([[0.0, 0.0, 1.0]])
    ours = brdfkit.model("microfacet", alpha=0.3, eta=ETA, k=K).eval(wi, wo)
    theirs = mitsuba_eval(variant, "beckmann", 0.3, wi, wo)
    np.testing.assert_array_equal(ours, 0.0)
    np.testing.assert_array_equal(theirs, 0.0)
