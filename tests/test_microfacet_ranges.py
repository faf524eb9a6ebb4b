"""The microfacet-family kernels over their whole declared parameter range, and the
direction checks of BRDF.eval (issue 8).

References, independent of the code under test:
- Conductor Fresnel at normal incidence ((η − 1)² + κ²)/((η + 1)² + κ²) (Born & Wolf
  §14.2): → 1 as η, κ → 0, and R = 1 at grazing incidence.
- As α → 0 with F = 1 the albedo of Walter's BRDF at normal incidence tends to
  E[G₁(ω_o)] → 1: with ω_i = n, ω_o = 2(n·h)h − n, dω_o = 4 cos θ_h dω_h, so
  a = ∫ D(h) cos θ_h G₁(ω_o) dω_h and ∫ D cos θ_h dω_h = 1 (Walter eq. 4). The
  quadrature below is in the variable t = tan θ_h/α, written here, not the
  albedo engine's.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from click.testing import CliRunner

import brdfkit
from brdfkit.cli import main
from brdfkit.errors import BrdfkitError, ParameterError
from brdfkit.fresnel import fresnel_conductor
from brdfkit.models._base import UNIT_TOL, eval_pairs_checked
from brdfkit.models.microfacet import _microfacet


def _cli(*args):
    return CliRunner().invoke(main, list(args))


# --------------------------------------------------------------------------- Fresnel, tiny η
@pytest.mark.parametrize("eta", [1e-200, 1e-300, 1e-160, 5e-324])
def test_conductor_fresnel_finite_and_exact_for_tiny_eta(eta):
    c = np.array([0.0, 1e-300, 0.3, 0.7, 1.0])
    for k in (0.0, 1e-300, 0.5, 100.0):
        f = fresnel_conductor(c, eta, k)
        assert np.all(np.isfinite(f))
        # exact limit: R(c = 1) = ((η−1)² + κ²)/((η+1)² + κ²) = 1 − 4η/(…) = 1 in float64
        assert f[-1] == pytest.approx(((eta - 1) ** 2 + k**2) / ((eta + 1) ** 2 + k**2),
                                      rel=1e-15)
        assert f[0] == 1.0  # grazing


@pytest.mark.parametrize("name,eta", [("microfacet", "1e-200"), ("he-torrance", "1e-300")])
def test_cli_eval_tiny_eta_is_finite(name, eta):
    r = _cli("eval", name, "-p", f"eta={eta}", "--wi", "0,0", "--wo", "0,0", "--json")
    assert r.exit_code == 0, r.output
    assert "NaN" not in r.output and "null" not in r.output and "Infinity" not in r.output


def test_k_without_eta_is_refused():
    with pytest.raises(ParameterError, match="k needs eta: give eta"):
        brdfkit.model("microfacet", k=5.0)
    with pytest.raises(ParameterError, match="k needs eta"):
        brdfkit.model("microfacet", k=[0.0, 5.0, 0.0])
    brdfkit.model("microfacet", k=0.0)  # the default is fine
    brdfkit.model("microfacet", eta=0.2, k=3.9)


# --------------------------------------------------------------------------- tiny α
def test_alpha_lower_bound_is_stated_and_enforced():
    p = {q.name: q for q in brdfkit.MODELS["microfacet"].params}["alpha"]
    assert p.lower == 1e-8 and "1e-8" in p.doc
    for d in ("beckmann", "ggx"):
        with pytest.raises(ParameterError, match="alpha"):
            brdfkit.model("microfacet", distribution=d, alpha=1e-9)
        for a in (1e-170, 1e-100):
            with pytest.raises(ParameterError):
                brdfkit.model("microfacet", distribution=d, alpha=a)


def _albedo_normal_incidence(m, alpha, n_t=4000, n_phi=4):
    """a(0) = ∫ f(n, ω_o) cos θ_o dω_o in the half-vector variable t = tan θ_h/α.

    ω_o = 2 cos θ_h h − n; dω_o cos θ_o = 4 cos θ_h cos θ_o dω_h and dω_h =
    sin θ_h dθ_h dφ, θ_h = atan(α t), dθ_h = α dt/(1 + α²t²). The t-grid (Gauss-Legendre on
    [0, 40] after t = u²-stretching) resolves the lobe whatever α is; f is isotropic here, so
    a few φ suffice (the result must not depend on φ).
    """
    x, w = np.polynomial.legendre.leggauss(n_t)
    u = 0.5 * (x + 1.0) * math.sqrt(40.0)  # t = u², dt = 2u du
    t = u * u
    wt = w * 0.5 * math.sqrt(40.0) * 2.0 * u
    th = np.arctan(alpha * t)
    dth = alpha / (1.0 + (alpha * t) ** 2)
    total = 0.0
    for phi in np.linspace(0.0, 2 * np.pi, n_phi, endpoint=False):
        h = np.stack([np.sin(th) * np.cos(phi), np.sin(th) * np.sin(phi), np.cos(th)], -1)
        wo = 2.0 * np.cos(th)[:, None] * h - [0.0, 0.0, 1.0]
        wo /= np.linalg.norm(wo, axis=-1, keepdims=True)
        f = m.eval([0.0, 0.0, 1.0], wo)
        integrand = f * 4.0 * np.cos(th) * wo[:, 2] * np.sin(th) * dth
        total += np.sum(wt * integrand) * (2 * np.pi / n_phi)
    return total


@pytest.mark.parametrize("dist", ["beckmann", "ggx"])
@pytest.mark.parametrize("alpha", [1e-2, 1e-8])  # a glossy value and the lower bound (CI time)
def test_near_mirror_albedo_at_normal_incidence_is_one(dist, alpha):
    # the half-vector's tan²θ_h is formed from the components of ωi + ωo: with
    # (1 − cos²)/cos² the GGX albedo at α = 1e-8 was 2.10
    m = brdfkit.model("microfacet", distribution=dist, alpha=alpha)
    a = _albedo_normal_incidence(m, alpha)
    # the t-range [0, 40] misses the GGX tail ∫_{t>40} = 1/(1 + 40²) ≈ 6.2e-4; Beckmann's
    # tail is e^{−1600}; G₁(ω_o) = 1 − O(α²)
    expected = 1.0 - (1.0 / (1.0 + 1600.0) if dist == "ggx" else 0.0)
    assert a == pytest.approx(expected, abs=2e-4 if alpha > 1e-3 else 2e-6)


# --------------------------------------------------------------------------- whole range
_TH = np.array([0.0, 1e-9, 0.3, 1.0, 1.5, math.pi / 2 - 1e-9, math.pi / 2, math.pi / 2 + 1e-3,
                2.0])
_PH = np.array([0.0, 1e-12, 0.5, math.pi - 1e-12, math.pi])
_T, _P = np.meshgrid(_TH, _PH, indexing="ij")
_D = np.stack([np.sin(_T) * np.cos(_P), np.sin(_T) * np.sin(_P), np.cos(_T)], -1).reshape(-1, 3)
WI = np.repeat(_D, len(_D), 0)
WO = np.tile(_D, (len(_D), 1))

EXTREMES = [
    ("microfacet", {"alpha": 1e-8}), ("microfacet", {"alpha": 1e-8, "distribution": "ggx"}),
    ("microfacet", {"alpha": 4.0}), ("microfacet", {"alpha": 4.0, "distribution": "ggx"}),
    ("microfacet", {"alpha": 1e-8, "eta": 1e-200}),
    ("microfacet", {"alpha": 1e-8, "eta": 100.0, "k": 100.0}),
    ("microfacet", {"alpha": 1e-8, "distribution": "ggx", "eta": 5e-324}),
    ("cook-torrance", {"m": 1e-4}), ("cook-torrance", {"m": 100.0}),
    ("cook-torrance", {"m": 1e-4, "eta": 1e-300}), ("cook-torrance", {"m": 1e-4, "eta": 100.0}),
    ("torrance-sparrow", {"m": 1e-4}), ("torrance-sparrow", {"m": 100.0}),
    ("torrance-sparrow", {"distribution": "phong", "n": 1e6, "b": 1e3}),
    ("torrance-sparrow", {"distribution": "gaussian", "c": 1e-300}),
    ("torrance-sparrow", {"distribution": "gaussian", "c": 1e3}),
    ("torrance-sparrow", {"distribution": "trowbridge-reitz", "c": 1e-300}),
    ("torrance-sparrow", {"distribution": "trowbridge-reitz", "c": 1.0, "eta": 1e-300}),
    ("ward", {"m": 1e-4}), ("ward", {"m": 100.0}),
    ("he-torrance", {"sigma0": 1e-300, "tau": 1e-300}),
    ("he-torrance", {"sigma0": 10.0, "tau": 1000.0}),
    ("he-torrance", {"sigma0": 10.0, "tau": 1e-300, "eta": 1e-300, "k": 100.0}),
]


@pytest.mark.parametrize("name,params", EXTREMES)
def test_finite_at_bounds_horizon_and_below(name, params):
    v = brdfkit.model(name, **params).eval(WI, WO)
    assert np.all(np.isfinite(v)) and np.all(v >= 0.0)
    below = (WI[:, 2] <= 0.0) | (WO[:, 2] <= 0.0)
    assert np.all(v[below] == 0.0)


# --------------------------------------------------------------------------- directions
@pytest.mark.parametrize("name", ["microfacet", "modified-phong", "cook-torrance"])
def test_non_unit_directions_are_refused(name):
    m = brdfkit.model(name)
    msg = r"wi must hold unit vectors.*0\.001 of 1.*norm 2 .*normalise"
    with pytest.raises(BrdfkitError, match=msg):
        m.eval([0.0, 0.0, 2.0], [0.0, 0.0, 1.0])
    good = np.tile([0.0, 0.6, 0.8], (40, 1))
    bad = good.copy()
    bad[17] *= 1.01
    with pytest.raises(BrdfkitError, match=r"wo must hold unit vectors.*norm 1\.01.*index 17"):
        m.eval(good, bad)
    # float32-normalised directions (and hand-typed ones such as (0.2, 0, −0.98)) pass
    rng = np.random.default_rng(1)
    w = rng.normal(size=(1000, 3)).astype(np.float32)
    w /= np.linalg.norm(w, axis=-1, keepdims=True)
    w[:, 2] = np.abs(w[:, 2])
    assert np.all(np.abs(np.sum(w.astype(np.float64) ** 2, -1) - 1.0) < 1e-6 * 10)
    assert np.all(np.isfinite(m.eval(w, w[::-1])))
    m.eval([0.2, 0.0, -0.98], [0.0, 0.0, 1.0])
    assert UNIT_TOL == 1e-3


def test_non_broadcasting_shapes_name_both():
    m = brdfkit.model("microfacet")
    with pytest.raises(BrdfkitError, match=r"broadcast.*\(4, 3\).*\(5, 3\)"):
        m.eval(np.tile([0.0, 0.0, 1.0], (4, 1)), np.tile([0.0, 0.0, 1.0], (5, 1)))


# --------------------------------------------------------------------------- vectorised driver
@pytest.mark.parametrize("params", [  # each of the four kernels once (CI time)
    {}, {"distribution": "ggx", "alpha": 0.3}, {"eta": 1.5},
    {"distribution": "ggx", "eta": [0.2, 0.9, 1.1], "k": [3.9, 2.4, 2.2]},
])
def test_vectorised_driver_equals_generic_loop(params):
    m = brdfkit.model("microfacet", **params)
    assert m._driver is not None
    rng = np.random.default_rng(11)
    n = 10_007  # not a multiple of the chunk or of the vector width
    wi = rng.normal(size=(n, 3))
    wi /= np.linalg.norm(wi, axis=-1, keepdims=True)
    wo = rng.normal(size=(n, 3))
    wo /= np.linalg.norm(wo, axis=-1, keepdims=True)
    wo[: n // 3] = wi[: n // 3] * [-1.0, -1.0, 1.0]  # exact mirror pairs
    ref = np.empty((n, m.packed.shape[0]))
    assert eval_pairs_checked(_microfacet, wi, wo, m.packed, ref) == 0
    got = m.eval(wi, wo).reshape(n, -1)
    np.testing.assert_allclose(got, ref, rtol=1e-15, atol=0.0)
    wi[[5, 9000]] = [math.nan, 0.0, 1.0]
    out = np.empty_like(ref)
    assert m._driver(wi, wo, m.packed, out) == 2
    assert np.all(np.isnan(out[[5, 9000]]))
