"""The Phong family as formulas (:mod:`brdfkit._dual`): eval, sampler and pdf.

``modified-phong``, ``phong``, ``blinn``, ``phong-blinn-reciprocal``,
``modified-blinn-phong``, ``neumann-phong``, ``nielsen``, ``nh-power-series`` and
``lafortune`` (the last two generated for their number of lobes:
:mod:`brdfkit.models.lobe_series`) give
``BRDF.formulas()``: one formula per model is the Numba kernel of ``model.eval`` and
the function Mitsuba traces. Checked here, for every example of each model:

- the compiled formula against the papers' closed forms written again in NumPy
  (Nielsen eqs. 1-3, Lewis eqs. 5, 6, 8, 24 and §7, Neumann eqs. 7 and 22; references
  below), also
  at θ = 90° and below the horizon (0 there);
- the formula sampler against ``model.sample`` (its NumPy strategies: ``Mixture`` of
  ``COSINE``, ``CosPowerAxis``, ``HalfVector(PowerHalf)``) for the same (u₀, u₁), and
  the formula pdf against ``model.pdf``;
- the Dr.Jit-traced versions inside Mitsuba (``llvm_ad_rgb``): eval, pdf and sample
  against the float64 NumPy/Numba values to float32 rounding, and that the bridge takes
  the traced route (no ``wavefront()`` needed);
- Mitsuba's own χ² harness on the traced sampler of a Blinn model, of ``nielsen``
  (cosine + cosˢ mirror lobe + N·H lobe), of a three-term ``nh-power-series`` and of a
  two-lobe ``lafortune`` (per-ω_o weights, an off-specular and a retro-reflective lobe).
  ``modified-phong`` and ``phong`` go through the same harness in
  tests/test_render_mitsuba.py, now on the traced route.
"""

from __future__ import annotations

import gc
import math
import warnings

import numpy as np
import pytest
from traced_helpers import mitsuba_chi2

import brdfkit

MODELS = ("modified-phong", "phong", "blinn", "phong-blinn-reciprocal",
          "modified-blinn-phong", "neumann-phong", "nielsen", "nh-power-series", "lafortune")
CASES = [(name, j) for name in MODELS
         for j in range(len(type(brdfkit.model(name)).examples))]


def _model(name: str, j: int):
    return brdfkit.model(name, **type(brdfkit.model(name)).examples[j])


def _pairs(rng, k: int = 400):
    """Random pairs: wo upper, wi anywhere (a third below), θ_i = 90° and mirror pairs."""
    def unit(v):
        return v / np.linalg.norm(v, axis=-1, keepdims=True)

    wo = unit(rng.normal(size=(k, 3)))
    wo[:, 2] = np.abs(wo[:, 2])
    wi = unit(rng.normal(size=(k, 3)))
    wi[: 2 * k // 3, 2] = np.abs(wi[: 2 * k // 3, 2])
    wi[:40, 2] = 0.0  # θ_i = 90° exactly
    wi[:40] = unit(wi[:40])
    wi[40:120] = unit(wo[40:120] * [-1.0, -1.0, 1.0] + rng.normal(scale=0.05, size=(80, 3)))
    return wi, wo


def _n_max(v: dict) -> float:
    """The largest exponent (n, per lobe for the series; s of nielsen)."""
    return max(float(np.max(v.get("n", 0.0))), float(v.get("s", 0.0)))


# --------------------------------------------------------------------------- references
def _reference(name: str, v: dict, wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
    """f_r from the papers' equations in NumPy (float64), for channel values *v*."""
    nl, nv = wi[:, 2], wo[:, 2]
    rv = 2.0 * nl * nv - np.sum(wi * wo, axis=-1)  # R·V, R the mirror of L about N
    s = wi + wo
    nh = s[:, 2] / np.linalg.norm(s, axis=-1)  # N·H

    def lobe(x, n):
        return np.where(x > 0.0, np.maximum(x, 0.0) ** n, 1.0 if n == 0.0 else 0.0)

    if name == "modified-phong":  # Nielsen eq. (1)
        f = v["rho_d"] / math.pi + v["rho_s"] * (v["n"] + 2.0) / (2.0 * math.pi) * lobe(rv, v["n"])
    elif name in ("phong", "blinn"):  # Lewis eq. (8) with (5) / (6); N·L floored at 1e-300
        c = rv if name == "phong" else nh
        f = v["k_d"] + v["k_s"] * lobe(c, v["n"]) / np.maximum(nl, 1e-300)
    elif name == "phong-blinn-reciprocal":  # Lewis eq. (24)
        f = v["k_d"] + v["k_s"] * lobe(nh, v["n"])
    elif name == "modified-blinn-phong":  # Nielsen eq. (2)
        f = v["rho_d"] / math.pi + v["rho_s"] * (v["n"] + 8.0) / (8.0 * math.pi) * lobe(nh, v["n"])
    elif name == "nh-power-series":  # Lewis §7: Σ_i k_i (N·H)^{n_i}
        f = sum(k * lobe(nh, n) for k, n in zip(v["k_s"], v["n"], strict=True))
    elif name == "lafortune":  # Neumann eq. (7): ρ_d/π + ρ_s Σ_j (C_xy L_xy·V_xy + C_z L_z V_z)^n
        xy = wi[:, 0] * wo[:, 0] + wi[:, 1] * wo[:, 1]
        f = v["rho_d"] / math.pi + v["rho_s"] * sum(
            lobe(cxy * xy + cz * nl * nv, n)
            for cxy, cz, n in zip(v["C_xy"], v["C_z"], v["n"], strict=True))
    elif name == "neumann-phong":  # Neumann eq. (22), c_n = (n+2)/2π by default
        c_n = (v["n"] + 2.0) / (2.0 * math.pi) if v["c_n"] is None else v["c_n"]
        f = c_n * lobe(rv, v["n"]) / np.maximum(np.maximum(nl, nv), 1e-300)
    else:  # nielsen, eq. (3): F(ω_i·h) of the dielectric (brdfkit.fresnel, an ufunc)
        base = (1.0 - v["alpha"]) * rv + v["alpha"] * nh ** 4
        fr = 1.0 if v["eta"] is None else brdfkit.fresnel.fresnel_dielectric(
            0.5 * np.linalg.norm(s, axis=-1), v["eta"])
        f = v["rho_d"] / math.pi + v["k_s"] * fr * lobe(base, v["s"])
    return np.where((nl > 0.0) & (nv > 0.0), f, 0.0)


@pytest.mark.parametrize("name,j", CASES)
def test_formula_eval_is_the_closed_form(name, j):
    """The compiled formula (Formulas.eval, called per pair with one channel's packed row)
    and model.eval against the closed form; θ_i = 90° and below the horizon included."""
    m = _model(name, j)
    form = m.formulas()
    assert form is not None  # the Phong family gives formulas (None before)
    wi, wo = _pairs(np.random.default_rng(j + 17 * len(name)))
    v = m.channel_values(0)
    # a base rounded differently (R·V, (N·H)⁴) by a few ulp, raised to n: ~n·1e-15 relative
    rtol = max(1e-12, 2e-15 * _n_max(v))
    for c in range(m.packed.shape[0]):
        ref = _reference(name, m.channel_values(c), wi, wo)
        got = np.array([form.eval(*wi[k], *wo[k], m.packed[c]) for k in range(len(wi))])
        np.testing.assert_allclose(got, ref, rtol=rtol, atol=0.0)
        ev = m.eval(wi, wo)
        np.testing.assert_array_equal(ev if ev.ndim == 1 else ev[:, c], got)
    assert np.all(got[wi[:, 2] < 0.0] == 0.0) and np.all(np.isfinite(got))


@pytest.mark.parametrize("name,j", CASES)
def test_formula_sampler_is_the_strategy(name, j):
    """The formula sampler draws model.sample's directions (its NumPy Mixture strategy) for
    the same (u₀, u₁); the formula pdf is model.pdf, 0 for wo below the horizon."""
    m = _model(name, j)
    form = m.formulas()
    rng = np.random.default_rng(5 + j)
    _, wo = _pairs(rng, 300)
    u = rng.random((300, 2))
    wi, p = m.sample(wo, u)
    got = np.array([form.sample(*wo[k], *u[k], *form.args) for k in range(300)])
    # 1e-13: sin/cos of NumPy vs libm, and u₀^{1/(n+1)} near 1 for n up to 2·10⁴
    np.testing.assert_allclose(got, wi, rtol=0.0, atol=1e-12)
    gp = np.array([form.pdf(*wi[k], *wo[k], *form.args) for k in range(300)])
    np.testing.assert_allclose(gp, p, rtol=1e-12, atol=0.0)
    below = wo * [1.0, 1.0, -1.0]
    assert form.pdf(*wi[0], *below[0], *form.args) == 0.0


# --------------------------------------------------------------------------- Mitsuba, traced
mi = pytest.importorskip("mitsuba")
dr = pytest.importorskip("drjit")

from brdfkit.render.mitsuba_bridge import mitsuba_bsdf, use_variant  # noqa: E402


def _llvm_rgb() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        if not use_variant("llvm_ad_rgb").startswith("llvm"):
            pytest.skip("Mitsuba's llvm_ad_rgb variant does not run here")


def _f32(w: np.ndarray) -> np.ndarray:
    """Directions as the traced BSDF sees them (float32), back in float64."""
    return w.astype(np.float32).astype(float)


@pytest.mark.parametrize("name,j", CASES)
def test_traced_matches_numpy(name, j):
    """The bridge takes the traced route and its eval (f_r cos θ_i), pdf and sample equal
    the float64 model to float32 rounding (same float32 directions on both sides)."""
    _llvm_rgb()
    m = _model(name, j)
    ours = mitsuba_bsdf(m)
    assert ours.traced
    rng = np.random.default_rng(29 + j)
    wi, wo = _pairs(rng, 256)
    wi, wo = _f32(wi), _f32(wo)
    wo[:, 2] = np.maximum(wo[:, 2], 0.05)  # view above the horizon (Mitsuba's si.wi)
    wo = _f32(wo / np.linalg.norm(wo, axis=-1, keepdims=True))
    si = dr.zeros(mi.SurfaceInteraction3f, len(wo))
    si.wi = mi.Vector3f(wo.T.astype(np.float32))
    ctx = mi.BSDFContext()
    # float32 carries ~6e-8 relative per operation; a power n amplifies a base's error n
    # times: rtol 1e-4 up to n ≈ 100, 2e-7·n beyond (nielsen's N·H lobe has exponent 4s)
    v = m.channel_values(0)
    n_max = max(_n_max(v), 4.0 * float(v.get("s", 0.0)))
    rtol = max(1e-4, 2e-7 * n_max)
    f = m.eval(wi, wo)
    want = (f if f.ndim == 2 else f[:, None]) * np.maximum(wi[:, 2:3], 0.0)
    got = np.array(ours.eval(ctx, si, mi.Vector3f(wi.T.astype(np.float32)))).T
    np.testing.assert_allclose(got, np.broadcast_to(want, got.shape), rtol=rtol,
                               atol=1e-6 * want.max())
    # the bridge's pdf is 0 for ω_i at or below the horizon (Mitsuba's reflection
    # convention: such a sample is discarded); compared above it
    up = wi[:, 2] > 0.0
    got_p = np.array(ours.pdf(ctx, si, mi.Vector3f(wi.T.astype(np.float32))))
    np.testing.assert_allclose(got_p[up], m.pdf(wi, wo)[up], rtol=rtol, atol=1e-6)
    assert np.all(got_p[~up] == 0.0)
    u = _f32(rng.random((256, 2)))
    bs, _ = ours.sample(ctx, si, 0.5, mi.Point2f(u.T.astype(np.float32)))
    want_wi, _ = m.sample(wo, u)
    # atol: float32 sin θ from 1 − cos²θ near the lobe's axis (n up to 2·10⁴)
    np.testing.assert_allclose(np.array(bs.wo).T, want_wi, atol=2e-4)
    del ours
    gc.collect()


@pytest.mark.parametrize("props,wi", [
    ({"model": "modified-blinn-phong", "rho_d": 0.3, "rho_s": 0.6, "n": 30.0}, [0.6, 0.0, 0.8]),
    ({"model": "nielsen", "rho_d": 0.2, "k_s": 2.0, "s": 12.0, "alpha": 0.5, "eta": 1.5},
     [0.0, 0.6, 0.8]),
])
def test_chi2_traced_sampler(props, wi):
    """Mitsuba's own χ² goodness-of-fit test (mitsuba.chi2, as in test_render_mitsuba.py)
    of the traced sample() against the traced pdf()."""
    _llvm_rgb()
    params = {k: v for k, v in props.items() if k != "model"}
    assert mitsuba_bsdf(brdfkit.model(props["model"], **params)).traced
    mitsuba_chi2(props, wi)


@pytest.mark.parametrize("name,params,wi", [
    ("nh-power-series", {"k_s": [0.1, 0.5, 5.0], "n": [0.0, 10.0, 200.0]}, [0.6, 0.0, 0.8]),
    ("lafortune", {"rho_d": 0.2, "rho_s": 0.5, "C_xy": [-1.2, 0.6], "C_z": [0.8, 0.5],
                   "n": [15.0, 3.0]}, [0.0, 0.6, 0.8]),
])
def test_chi2_traced_lobe_series_sampler(name, params, wi):
    """Mitsuba's χ² harness on the traced sampler of the generated lobe sums (the bridge's
    BSDF given directly: the plugin's flat properties take no per-lobe lists)."""
    _llvm_rgb()
    from mitsuba.chi2 import ChiSquareTest, SphericalDomain

    bsdf = mitsuba_bsdf(brdfkit.model(name, **params))
    assert bsdf.traced

    def context(n):
        si = dr.zeros(mi.SurfaceInteraction3f, n)
        si.wi = wi
        return si, mi.BSDFContext()

    def sample_func(sample):
        si, ctx = context(dr.width(sample))
        bs, weight = bsdf.sample(ctx, si, sample[0], mi.Vector2f([sample[1], sample[2]]))
        w = dr.full(mi.Float, 1.0, dr.width(weight))
        w[dr.all(weight == 0)] = 0
        return bs.wo, w

    def pdf_func(wo):
        si, ctx = context(dr.width(wo))
        return bsdf.pdf(ctx, si, wo)

    chi2 = ChiSquareTest(domain=SphericalDomain(), sample_func=sample_func,
                         pdf_func=pdf_func, sample_dim=3, res=51, ires=4,
                         sample_count=200_000)
    assert chi2.run(), chi2.messages
    gc.collect()
