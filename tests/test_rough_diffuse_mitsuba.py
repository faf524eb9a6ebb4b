"""EON and Oren–Nayar in Mitsuba 3 by the traced route (their formulas rebound to Dr.Jit).

References: the Numba compilation of the same formulas (``model.eval``/``sample``/``pdf``:
two compilations, float32 against float64, must agree to float32 rounding), and EON's
white furnace (ρ = 1: every pixel of a sphere under a uniform sky shows a = 1, closed
form, within the render's own stated Monte-Carlo standard error).
"""

from __future__ import annotations

import gc
import math

import numpy as np
import pytest

import brdfkit

mi = pytest.importorskip("mitsuba")
dr = pytest.importorskip("drjit")

from traced_helpers import float32_hemisphere as _hemisphere  # noqa: E402
from traced_helpers import variant as _variant  # noqa: E402

from brdfkit.render.mitsuba_bridge import mitsuba_bsdf  # noqa: E402
from brdfkit.render.mitsuba_sphere import render_sphere_mitsuba_passes  # noqa: E402


@pytest.mark.parametrize("name,params", [
    ("eon", {"rho": [0.2, 0.5, 0.9], "r": 0.8}),
    ("eon", {"rho": 0.7, "r": 0.4, "E_FON": "approx"}),
    ("oren-nayar", {"rho": [0.3, 0.6, 0.9], "sigma": 0.5}),
    ("oren-nayar", {"rho": 0.8, "sigma": 1.0, "form": "qualitative"}),
    ("fon", {"rho": 0.6, "r": 1.0}),
])
def test_traced_eval_sample_pdf_match_numba(name, params):
    variant = _variant("llvm_ad_rgb")
    if variant.startswith("scalar"):
        pytest.skip("no llvm variant: the traced route needs one")
    model = brdfkit.model(name, **params)
    bsdf = mitsuba_bsdf(model)
    assert bsdf.traced
    rng = np.random.default_rng(5)
    n = 256
    view, light = _hemisphere(rng, n), _hemisphere(rng, n)
    ctx = mi.BSDFContext()
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.wi = mi.Vector3f(view.T.astype(np.float32))
    wo = mi.Vector3f(light.T.astype(np.float32))
    got = np.array(bsdf.eval(ctx, si, wo)).T
    f = model.eval(light, view)
    want = np.broadcast_to((f if f.ndim == 2 else f[:, None]) * light[:, 2:3], got.shape)
    np.testing.assert_allclose(got, want, rtol=2e-5, atol=1e-7)
    assert np.abs(got - 1.01 * want).max() > 1e-4 * want.max()  # power: 1 % is seen
    np.testing.assert_allclose(np.array(bsdf.pdf(ctx, si, wo)), model.pdf(light, view),
                               rtol=1e-5, atol=1e-7)
    u = rng.random((n, 2)).astype(np.float32)
    bs, _ = bsdf.sample(ctx, si, 0.5, mi.Point2f(u.T))
    want_wi, want_p = model.sample(view, u.astype(float))
    np.testing.assert_allclose(np.array(bs.wo).T, want_wi, atol=2e-6)
    np.testing.assert_allclose(np.array(bs.pdf), want_p, rtol=2e-5, atol=1e-7)
    del bsdf
    gc.collect()


def test_eon_white_furnace_render():
    """ρ = 1, r = 1, uniform sky L_a = 1 and no light: every pixel inside the disc is 1;
    the pixels' deviations, in units of their stated standard errors, have mean ~0 and
    spread ~1 (Student t with K − 1 = 5 degrees of freedom: variance 5/3)."""
    variant = _variant("llvm_ad_rgb")
    if variant.startswith("scalar"):
        pytest.skip("no llvm variant: the traced route needs one")
    model = brdfkit.model("eon", rho=1.0, r=1.0)
    assert mitsuba_bsdf(model).traced
    size = 24
    img, err, k = render_sphere_mitsuba_passes(model, irradiance=0.0, ambient=1.0, size=size,
                                               spp=48, passes=6, seed=3, variant=variant)
    yy, xx = np.mgrid[0:size, 0:size]
    x = (2.0 * (xx + 0.5) / size - 1.0)
    y = (1.0 - 2.0 * (yy + 0.5) / size)
    inner = (x * x + y * y) < (1.0 - 2.0 * math.sqrt(2.0) / size) ** 2  # wholly inside
    z = (img[inner] - 1.0) / np.maximum(err[inner], 1e-12)
    assert abs(float(np.mean(img[inner])) - 1.0) < 5.0 * float(
        np.sqrt(np.sum(err[inner] ** 2))) / inner.sum() + 1e-6
    assert 0.5 < float(np.var(z)) < 3.5, float(np.var(z))
    # power: a sky of 1.02 (what an albedo of 1.02 would show) is rejected
    z2 = (img[inner] - 1.02) / np.maximum(err[inner], 1e-12)
    assert abs(float(np.mean(z2))) > 5.0 / math.sqrt(z2.size)
