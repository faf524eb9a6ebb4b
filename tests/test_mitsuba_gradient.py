"""brdfkit parameters in Mitsuba's differentiable rendering (issue 23): ``mi.traverse``.

A traced brdfkit BSDF exposes the model's scalar (and grey/RGB colour) parameters by
their names (``alpha``, ``rho_s``, …) as differentiable Dr.Jit values that its eval
formula reads, so ``dr.backward`` of a rendered image reaches them; ``params.update()``
rebuilds the sampler's arguments (and a derived model's tables) from the new values.

References, each independent of the gradient under test:

- **Central finite difference** of two forward renders with the same seed (α ± h): the
  derivative of the same estimator by a second method. The directional light's term
  uses the same pixel samples in both renders, so its FD is the derivative up to O(h²);
  the constant environment's term is importance-sampled by the BSDF's sampler, whose
  directions move with α in the FD renders but are held (detached pdf) by Mitsuba's
  ``prb`` integrator, so the two agree only in expectation. Measured over seeds 0-3
  (h = 0.005 and 0.02, 16² px, 64 spp): AD/FD − 1 within ±0.65 %, while the gradient
  itself varies by ±1 % from seed to seed; the tolerance, 3 %, is ~4 of those standard
  deviations (σ ≈ 0.8 %) and far from any plausible mistake (a parameter that does not
  reach the trace gives 0; a wrong column, a different derivative).
- **Linearity**: microfacet's f_r is proportional to its scale ρ_s, so the image mean is
  ρ_s times a constant and its derivative is mean/ρ_s (the forward renders at two ρ_s are
  exactly proportional). ``prb``'s adjoint pass is not bit-identical to its primal one:
  Mitsuba's own ``roughconductor`` in this scene (``specular_reflectance`` 0.8) gives
  AD/(mean/ρ) − 1 = 7e-4 (1.7e-3 without the sky), measured; ours 4.6e-4. Tolerance 5e-3.
"""

from __future__ import annotations

import gc
import warnings

import numpy as np
import pytest

import brdfkit

mi = pytest.importorskip("mitsuba")
dr = pytest.importorskip("drjit")

from brdfkit.render.mitsuba_bridge import mitsuba_bsdf, use_variant  # noqa: E402

SIZE, SPP, SEED = 16, 64, 3
SKY = 0.2  # the constant sky's radiance (BSDF-sampled light)
ALPHA, RHO_S, H = 0.3, 0.8, 0.01
#: AD against FD, relative (module docstring: ~4 σ of the seed-to-seed spread)
TOL = 0.03
#: AD against mean/ρ_s, relative (module docstring: prb's own adjoint/primal mismatch)
TOL_LINEAR = 5e-3


@pytest.fixture(scope="module")
def variant():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        v = use_variant("llvm_ad_rgb")
    if v != "llvm_ad_rgb":
        pytest.skip("no LLVM: differentiable rendering needs llvm_ad_rgb")
    return v


def _scene(bsdf):
    """A 16² view of a rectangle under a directional light and a dim constant sky (not
    seen directly: every pixel is light reflected by the BSDF)."""
    return mi.load_dict({
        "type": "scene", "integrator": {"type": "prb", "max_depth": 2, "hide_emitters": True},
        "sensor": {"type": "perspective", "fov": 40,
                   "to_world": mi.ScalarTransform4f().look_at(origin=[0, -2, 3],
                                                              target=[0, 0, 0], up=[0, 0, 1]),
                   "film": {"type": "hdrfilm", "width": SIZE, "height": SIZE,
                            "rfilter": {"type": "box"}},
                   "sampler": {"type": "independent"}},
        "light": {"type": "directional", "direction": [0, -1, -1.2], "irradiance": 1.0},
        "sky": {"type": "constant", "radiance": SKY},
        "rect": {"type": "rectangle", "bsdf": bsdf}})


def _mean(scene, params=None) -> float:
    img = mi.render(scene, params, spp=SPP, seed=SEED) if params is not None else \
        mi.render(scene, spp=SPP, seed=SEED)
    return float(np.array(img, dtype=np.float64).mean())


def test_traverse_exposes_the_parameters_and_update_rebuilds(variant):
    bsdf = mitsuba_bsdf(brdfkit.model("microfacet", alpha=ALPHA, rho_s=RHO_S))
    scene = _scene(bsdf)
    params = mi.traverse(scene)
    for name in ("alpha", "rho_s"):
        assert f"rect.bsdf.{name}" in params
        # Mitsuba's flags: Differentiable is 0, the absence of NonDifferentiable
        assert not params.flags(f"rect.bsdf.{name}") & +mi.ParamFlags.NonDifferentiable
    params["rect.bsdf.alpha"] = mi.Float(0.25)
    params.update()
    assert bsdf.model.values["alpha"] == pytest.approx(0.25)  # the model rebuilt
    assert bsdf.args == pytest.approx((0.25,), rel=1e-6)  # the sampler's α follows
    del scene, params, bsdf
    gc.collect()


def test_image_gradient_matches_finite_differences(variant):
    scene = _scene(mitsuba_bsdf(brdfkit.model("microfacet", alpha=ALPHA, rho_s=RHO_S)))
    params = mi.traverse(scene)
    key = "rect.bsdf.alpha"
    dr.enable_grad(params[key])
    params.update()
    img = mi.render(scene, params, spp=SPP, seed=SEED)
    dr.backward(dr.mean(img, axis=None))
    ad = float(np.array(dr.grad(params[key])).reshape(-1)[0])
    values = []
    for a in (ALPHA + H, ALPHA - H):
        params[key] = mi.Float(a)
        params.update()
        values.append(_mean(scene))
    fd = (values[0] - values[1]) / (2.0 * H)
    assert abs(fd) > 0.1 * np.mean(values)  # the highlight does depend on α
    assert ad == pytest.approx(fd, rel=TOL), (ad, fd)

    # ρ_s: the image is linear in it, d mean/d ρ_s = mean/ρ_s
    params[key] = mi.Float(ALPHA)
    key = "rect.bsdf.rho_s"
    dr.enable_grad(params[key])
    params.update()
    img = mi.render(scene, params, spp=SPP, seed=SEED)
    mean = float(np.array(img, dtype=np.float64).mean())
    dr.backward(dr.mean(img, axis=None))
    grad = float(np.array(dr.grad(params[key])).reshape(-1)[0])
    assert grad == pytest.approx(mean / RHO_S, rel=TOL_LINEAR)
    del scene, params
    gc.collect()
