"""The diffuse family, Ward and Cook–Torrance as formulas (:mod:`brdfkit._dual`).

One formula per model is both the Numba kernel of ``model.eval`` (the vectorised loop) and,
rebound to Dr.Jit, the Mitsuba bridge's traced BSDF; its sampler and pdf likewise.

References (independent of the code under test):

- the closed forms, written here in NumPy from the papers: ρ_d/π (Lambert); Lewis 1993
  §3.3 (Neumann–Neumann), §3.4 and §4.3 (Minnaert); Neumann et al. 1999 eq. (8) (Ward)
  and eqs. (9)–(10) (Cook–Torrance);
- Mitsuba's own ``diffuse`` plugin (an external implementation) for ``lambert``;
- Mitsuba's χ² harness (``mitsuba.chi2``) for the traced samplers of ``ward`` and
  ``cook-torrance``.
"""

from __future__ import annotations

import gc

import numpy as np
import pytest

import brdfkit
from brdfkit._dual import numpy_version

MODELS = ("lambert", "neumann-neumann", "minnaert", "minnaert-energy-conserving", "ward",
          "cook-torrance", "torrance-sparrow")
CASES = [(name, k, ex) for name in MODELS
         for k, ex in enumerate(brdfkit.model(name).examples)]
IDS = [f"{name}-{k}" for name, k, _ in CASES]


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _pairs(rng, n=400):
    """Random pairs over the sphere (half of them below the horizon) plus θ = 90° and the
    mirror configuration, where the lobes peak."""
    wi = _unit(rng.normal(size=(n, 3)))
    wo = _unit(rng.normal(size=(n, 3)))
    wo[: n // 2, 2] = np.abs(wo[: n // 2, 2])
    wi[: n // 4] = wo[: n // 4] * np.array([-1.0, -1.0, 1.0])  # mirror of wo
    wi[n // 4: n // 4 + 8, 2] = 0.0  # θ_i = 90°
    wi = _unit(wi)
    wo[n // 4 + 8: n // 4 + 16, 2] = 0.0  # θ_o = 90°
    return wi, _unit(wo)


def _closed_form(name, v, wi, wo):
    """f_r from the papers (module docstring), NumPy, per channel (…, C) or (…)."""
    ci, co = wi[..., 2], wo[..., 2]
    live = (ci > 0) & (co > 0)
    ci_, co_ = np.where(live, ci, 1.0), np.where(live, co, 1.0)
    if name == "lambert":
        f = np.asarray(v["rho_d"]) / np.pi * np.ones_like(ci)[..., None]
    elif name == "neumann-neumann":
        f = np.asarray(v["b_N"]) * np.exp(-v["s"] * (1 / ci_ + 1 / co_ - 2))[..., None]
    elif name == "minnaert":
        f = np.asarray(v["b_M"]) * ((ci_ * co_) ** (v["k"] - 1))[..., None]
    elif name == "minnaert-energy-conserving":
        f = np.asarray(v["k_rho"]) * (v["k"] + 1) / (2 * np.pi) * (
            (ci_ * co_) ** (v["k"] - 1))[..., None]
    else:
        h = _unit(wi + wo)
        hz = np.where(live, h[..., 2], 1.0)
        tan2 = (h[..., 0] ** 2 + h[..., 1] ** 2) / hz**2
        m = v["m"]
        if name == "ward":  # Neumann eq. (8)
            f = (np.asarray(v["rho_d"]) / np.pi + np.asarray(v["rho_s"])
                 * (np.exp(-tan2 / m**2) / (4 * np.pi * m**2 * np.sqrt(ci_ * co_)))[..., None])
        else:  # V-groove G: Neumann eq. (10), Lewis §3.2
            vh = np.sum(wo * h, axis=-1)
            g = np.minimum(1.0, np.minimum(2 * hz * co_ / vh, 2 * hz * ci_ / vh))
            d = np.exp(-tan2 / m**2) / (4 * np.pi * m**2 * hz**4)  # Neumann eq. (9), D₄/π
            if name == "torrance-sparrow":  # Lewis eq. (10): F G D/(π N·S N·V), D₁–D₄
                b, c, dist = v["b"], v["c"], v["distribution"]
                d = {"phong": lambda: b * hz ** v["n"],
                     "gaussian": lambda: b * np.exp(-(c * np.arccos(np.minimum(hz, 1))) ** 2),
                     "trowbridge-reitz": lambda: b * (c * c / (hz**2 * (c * c - 1) + 1)) ** 2,
                     "beckmann": lambda: np.pi * d}[dist]() / np.pi
                scale = 1.0
            else:
                scale = np.asarray(v["rho_s"])
            f = (d * g / (ci_ * co_))[..., None] * scale
            if v["eta"] is not None:
                f = f * brdfkit.fresnel.fresnel_dielectric(vh[..., None], np.asarray(v["eta"]))
    f = np.where(live[..., None], f, 0.0)
    return f


@pytest.mark.parametrize("name,k,ex", CASES, ids=IDS)
def test_formula_kernel_equals_paper_and_eval(name, k, ex, rng):
    """The model's formula (compiled by Numba, called pair by pair) and ``model.eval`` (its
    vectorised loop) against the paper's closed form; 0 at and below the horizon."""
    model = brdfkit.model(name, **ex)
    form = model.formulas()
    assert form is not None
    wi, wo = _pairs(rng)
    got = model.eval(wi, wo)
    got2 = got if got.ndim == 2 else got[:, None]
    want = _closed_form(name, model._values, wi, wo)
    want = np.broadcast_to(want, got2.shape)
    np.testing.assert_allclose(got2, want, rtol=1e-10, atol=1e-300)
    # the same formula evaluated by NumPy (brdfkit._dual.numpy_version; another libm: its
    # exp/acos differ by an ulp, amplified up to 700× by e^{−(cα)²}, hence 1e-11)
    as_numpy = numpy_version(form.eval)
    with np.errstate(all="ignore"):  # the discarded lanes of the selects
        for c in range(model.packed.shape[0]):
            one = as_numpy(*wi.T, *wo.T, model.packed[c])
            np.testing.assert_allclose(np.broadcast_to(one, got2[:, c].shape), got2[:, c],
                                       rtol=1e-11, atol=1e-300)
    below = (wi[:, 2] <= 0) | (wo[:, 2] <= 0)
    assert below.any() and np.all(got2[below] == 0.0)


# --------------------------------------------------------------------------- Mitsuba
mi = pytest.importorskip("mitsuba")
dr = pytest.importorskip("drjit")

from traced_helpers import float32_hemisphere as _hemisphere  # noqa: E402
from traced_helpers import mitsuba_chi2, variant  # noqa: E402

from brdfkit.render.mitsuba_bridge import mitsuba_bsdf  # noqa: E402


def _variant(name):
    return variant(name, llvm=True)


def _si(view):
    si = dr.zeros(mi.SurfaceInteraction3f, view.shape[0])
    si.wi = mi.Vector3f(view.T.astype(np.float32))
    return si


def _rtol(model):
    """float32 tolerance of the traced eval: 2e-4 (tens of operations), or the float32
    rounding (ε = 2⁻²⁴ relative, of a cosine near 1) amplified by the lobe: e^{−tan²δ/m²}
    formed from 1 − cos²δ (as the float64 kernels, for equal rounding), |Δ| ≤ 4ε/m²;
    cos^n: nε; e^{−(cα)²} with α = acos: 4c²ε."""
    v, eps = model._values, 2.0**-24
    if "m" not in v:
        return 2e-4
    amp = 4.0 / v["m"] ** 2
    if v.get("distribution") == "phong":
        amp = 2.0 * v["n"]
    elif v.get("distribution") == "gaussian":
        amp = 4.0 * v["c"] ** 2
    elif v.get("distribution") == "trowbridge-reitz":
        amp = 4.0 / v["c"] ** 2
    return max(2e-4, amp * eps)


@pytest.mark.parametrize("name,k,ex", CASES, ids=IDS)
def test_traced_eval_sample_pdf_equal_numpy(name, k, ex):
    """The traced BSDF (formulas rebound to Dr.Jit, llvm_ad_rgb, float32) against
    ``model.eval``/``sample``/``pdf`` (float64): eval (f cos θ), pdf, and the directions
    drawn from the same u."""
    _variant("llvm_ad_rgb")
    rng = np.random.default_rng(5 + k)
    model = brdfkit.model(name, **ex)
    n = 256
    view, light = _hemisphere(rng, n), _hemisphere(rng, n)
    light[: n // 2] = view[: n // 2] * np.array([-1.0, -1.0, 1.0])  # the mirror: the lobe
    ours = mitsuba_bsdf(model)
    assert ours.traced
    ctx = mi.BSDFContext()
    si, wo = _si(view), mi.Vector3f(light.T.astype(np.float32))
    got = np.array(ours.eval(ctx, si, wo)).T
    want = model.eval(light, view)
    want = (want if want.ndim == 2 else want[:, None]) * light[:, 2:3]
    np.testing.assert_allclose(got, np.broadcast_to(want, got.shape), rtol=_rtol(model),
                               atol=1e-6 * want.max())
    np.testing.assert_allclose(np.array(ours.pdf(ctx, si, wo)), model.pdf(light, view),
                               rtol=_rtol(model), atol=1e-6 * model.pdf(light, view).max())
    u = rng.random((n, 2)).astype(np.float32)
    bs, _ = ours.sample(ctx, si, 0.5, mi.Point2f(u.T))
    want_wi, want_p = model.sample(view, u.astype(float))
    # float32 sin θ = √(1 − cos²θ) of the narrow cos^q lobes (q = 200): ~1e-5 absolute
    np.testing.assert_allclose(np.array(bs.wo).T, want_wi, atol=1e-4)
    ok = want_wi[:, 2] > 0.05  # away from the horizon, where float32 pdfs are tiny
    np.testing.assert_allclose(np.array(bs.pdf)[ok], want_p[ok], rtol=_rtol(model))
    del ours
    gc.collect()


def test_traced_lambert_against_mitsuba_diffuse():
    """lambert traced against Mitsuba's own ``diffuse`` plugin (ρ/π cos θ, an external
    implementation), pointwise, with the same reflectance; a 1 % larger ρ is seen."""
    _variant("llvm_ad_rgb")
    rng = np.random.default_rng(3)
    rho = [0.2, 0.5, 0.8]
    ours = mitsuba_bsdf(brdfkit.model("lambert", rho_d=rho))
    assert ours.traced
    theirs = mi.load_dict({"type": "diffuse", "reflectance": {"type": "rgb", "value": rho}})
    view, light = _hemisphere(rng, 512), _hemisphere(rng, 512)
    ctx, si = mi.BSDFContext(), _si(view)
    wo = mi.Vector3f(light.T.astype(np.float32))
    a = np.array(ours.eval(ctx, si, wo))
    b = np.array(theirs.eval(ctx, si, wo))
    np.testing.assert_allclose(a, b, rtol=1e-6)
    assert np.abs(a - 1.01 * b).max() > 1e-3 * b.max()  # power
    np.testing.assert_allclose(np.array(ours.pdf(ctx, si, wo)),
                               np.array(theirs.pdf(ctx, si, wo)), rtol=1e-6)
    del ours, theirs
    gc.collect()


@pytest.mark.parametrize("props,wi", [
    ({"model": "ward", "rho_d": 0.2, "rho_s": 0.4, "m": 0.3}, [0.6, 0.0, 0.8]),
    ({"model": "cook-torrance", "m": 0.5, "eta": 1.5}, [0.0, 0.8, 0.6]),
])
def test_chi2_traced_sampler(props, wi):
    """Mitsuba's own χ² goodness-of-fit test of the traced sample() against its pdf()."""
    _variant("llvm_ad_rgb")
    name = props["model"]
    assert mitsuba_bsdf(brdfkit.model(name, **{k: v for k, v in props.items()
                                               if k != "model"})).traced
    mitsuba_chi2(props, wi)
