"""``ashikhmin-shirley``: Ashikhmin & Shirley 2000, eqs. (4) and (5), sampled as in §3.

References, each independent of the model's code:

- a second implementation written here in *angles* (θ, φ of ω_i, ω_o and h) from eq. (4)
  — √((n_u+1)(n_v+1))/(8π) cos θ_h^{n_u cos²φ_h + n_v sin²φ_h} F(k·h)/((k·h) max(μ_i, μ_o)),
  F = R_s + (1 − R_s)(1 − k·h)⁵ — and eq. (5);
- the closed form of the diffuse albedo: the albedo is linear in R_d, and
  a(R_d) − a(0) = R_d (1 − R_s)(1 − (1 − μ_i/2)⁵), because
  2 ∫₀¹ (28/23)(1 − (1 − μ/2)⁵) μ dμ = 1 (exactly: the integral is 23/56, computed here in
  rational arithmetic — the identity the paper's 28/23 is chosen for);
- reciprocity f(ω_i, ω_o) = f(ω_o, ω_i) (the paper's claim);
- the paper's energy claim, albedo ≤ 1 for R_s, R_d ≤ 1, by the albedo engine over
  exponents 0–10⁴, R_s ∈ [0, 1], R_d = 1 (the worst), θ_i to 89.9° and three azimuths:
  measured max 0.9960 (n_u = n_v = 1000, R_s = 1, θ_i = 0°; 0.9688 = 31/32 + the Schlick
  tail at R_s = 0);
- the half-vector sampler: its φ_h is the paper's per-quadrant
  arctan(√((n_u+1)/(n_v+1)) tan(πξ/2)), its density p_h integrates to 1, and χ² of the
  whole sampler at incidence azimuths ≠ 0.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

import brdfkit
from brdfkit.analysis import albedo
from brdfkit.analysis.chi2 import chi2_test
from brdfkit.models.ashikhmin_shirley import AshikhminShirleyHalf, as_half


def sph(theta, phi):
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi),
                     np.cos(theta)], -1)


def pairs(rng, n):
    wi = sph(np.arccos(rng.uniform(0.01, 1.0, n)), rng.uniform(0, 2 * math.pi, n))
    wo = sph(np.arccos(rng.uniform(0.01, 1.0, n)), rng.uniform(0, 2 * math.pi, n))
    near = wi[: n // 2] * [-1.0, -1.0, 1.0] + rng.normal(scale=0.1, size=(n // 2, 3))
    near[:, 2] = np.abs(near[:, 2]) + 0.01
    wo[: n // 2] = near / np.linalg.norm(near, axis=-1, keepdims=True)
    return wi, wo


def as_angles(wi, wo, nu, nv, rs, rd):
    """Eqs. (4) + (5) from angles (module docstring)."""
    t_i, t_o = np.arccos(wi[:, 2]), np.arccos(wo[:, 2])
    h = wi + wo
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    t_h = np.arctan2(np.hypot(h[:, 0], h[:, 1]), h[:, 2])
    p_h = np.arctan2(h[:, 1], h[:, 0])
    kh = np.cos(np.arccos(np.clip(np.sum(wi * h, -1), -1, 1)))
    expo = nu * np.cos(p_h) ** 2 + nv * np.sin(p_h) ** 2
    fres = rs + (1 - rs) * (1 - kh) ** 5
    spec = (math.sqrt((nu + 1) * (nv + 1)) / (8 * math.pi) * np.cos(t_h) ** expo * fres
            / (kh * np.maximum(np.cos(t_i), np.cos(t_o))))
    diff = (28 * rd / (23 * math.pi) * (1 - rs) * (1 - (1 - np.cos(t_i) / 2) ** 5)
            * (1 - (1 - np.cos(t_o) / 2) ** 5))
    return spec + diff


@pytest.mark.parametrize("nu,nv,rs,rd", [(10, 100, 0.05, 0.5), (1000, 10, 0.9, 0.1),
                                         (0, 0, 0.0, 1.0), (5000, 5000, 1.0, 0.0),
                                         (3, 300, 0.3, 0.7)])
def test_against_the_angles_form(nu, nv, rs, rd):
    rng = np.random.default_rng(nu + nv)
    wi, wo = pairs(rng, 5000)
    m = brdfkit.model("ashikhmin-shirley", n_u=nu, n_v=nv, R_s=rs, R_d=rd)
    want = as_angles(wi, wo, nu, nv, rs, rd)
    # cos θ_h^e: the angles' rounding is amplified by the exponent (e·δθ_h tan θ_h)
    np.testing.assert_allclose(m.eval(wi, wo), want, rtol=1e-9 * max(1.0, nu, nv) ** 0.5,
                               atol=1e-13 * want.max())


def test_n_u_acts_along_x():
    # h tilted along x by δ is damped by cos^{n_u}δ, along y by cos^{n_v}δ
    m = brdfkit.model("ashikhmin-shirley", n_u=1000.0, n_v=10.0, R_s=1.0, R_d=0.0)
    d = math.radians(5.0)
    wo = np.array([0.0, 0.0, 1.0])
    h_x, h_y = np.array([math.sin(d), 0.0, math.cos(d)]), np.array([0.0, math.sin(d), math.cos(d)])
    wi_x, wi_y = 2 * (wo @ h_x) * h_x - wo, 2 * (wo @ h_y) * h_y - wo
    assert m.eval(wi_x, wo) / m.eval(wi_y, wo) == pytest.approx(math.cos(d) ** 990, rel=1e-12)


def test_reciprocal():
    rng = np.random.default_rng(1)
    wi, wo = pairs(rng, 20000)
    for kw in ({}, {"n_u": 2000.0, "n_v": 3.0, "R_s": [0.9, 0.5, 0.1], "R_d": [0.2, 0.5, 0.9]}):
        m = brdfkit.model("ashikhmin-shirley", **kw)
        np.testing.assert_allclose(m.eval(wi, wo), m.eval(wo, wi), rtol=1e-15, atol=0.0)


def test_diffuse_normalisation_is_exact():
    # ∫₀¹ (1 − (1 − μ/2)⁵) μ dμ in rationals: expand (1 − μ/2)⁵ by the binomial theorem
    integral = Fraction(1, 2) - sum(Fraction(math.comb(5, j)) * Fraction(-1, 2) ** j
                                    / (j + 2) for j in range(6))
    assert integral == Fraction(23, 56)
    assert 2 * Fraction(28, 23) * integral == 1


@pytest.mark.parametrize("rs", [0.0, 0.3])
def test_diffuse_albedo_closed_form(rs):
    th = np.radians([0.0, 40.0, 70.0, 85.0, 89.5])
    kw = {"n_u": 10.0, "n_v": 300.0, "R_s": rs}
    a1 = albedo(brdfkit.model("ashikhmin-shirley", R_d=0.8, **kw), th, phi=0.4)
    a0 = albedo(brdfkit.model("ashikhmin-shirley", R_d=0.0, **kw), th, phi=0.4)
    want = 0.8 * (1 - rs) * (1 - (1 - np.cos(th) / 2) ** 5)
    assert np.all(np.abs(a1.albedo - a0.albedo - want) <= a1.error + a0.error + 1e-9)


def test_energy_bound():
    # the grid of the module docstring's measurement, thinned to the cases that came
    # closest to 1 in it and one per corner (exponents 0 and 10⁴, R_s = 0 and 1)
    th = np.radians([0.0, 30.0, 60.0, 80.0, 89.0, 89.9])
    worst = 0.0
    for nu, nv, rs, phi in ((0, 0, 0.0, 0.0), (10, 1000, 0.5, 0.25 * math.pi),
                            (1000, 1000, 1.0, 0.0), (10000, 10, 1.0, 0.5 * math.pi)):
        m = brdfkit.model("ashikhmin-shirley", n_u=nu, n_v=nv, R_s=rs, R_d=1.0)
        r = albedo(m, th, phi=phi)
        worst = max(worst, float(np.max(r.albedo + r.error)))
    assert worst <= 1.0
    assert worst > 0.996  # nearly reached: 0.99601 at R_s = 1, n = 1000, normal incidence


def test_half_vector_sampler_is_the_papers():
    nu, nv = 30.0, 700.0
    rng = np.random.default_rng(2)
    u = rng.random((20000, 2))
    hx, hy, hz = AshikhminShirleyHalf(nu, nv).sample(u).T  # NumPy version of as_half
    # Numba's libm pow against NumPy's: ~1e-13
    np.testing.assert_allclose([as_half(a, b, nu, nv) for a, b in u[:50]],
                               np.stack([hx, hy, hz], -1)[:50], rtol=1e-12, atol=1e-13)
    phi = np.mod(np.arctan2(hy, hx), 2 * math.pi)
    # the paper's φ = arctan(√((n_u+1)/(n_v+1)) tan(πξ/2)) in quadrant 0, mirrored into the
    # others: ξ = 4u₁ − q in quadrant q
    k = math.sqrt((nu + 1) / (nv + 1))
    q = np.floor(4 * u[:, 1])
    xi = 4 * u[:, 1] - q
    a = np.arctan(k * np.tan(0.5 * math.pi * xi))
    b = np.arctan(k * np.tan(0.5 * math.pi * (1 - xi)))
    want = np.select([q == 0, q == 1, q == 2], [a, math.pi - b, math.pi + a], 2 * math.pi - b)
    np.testing.assert_allclose(phi, want, atol=1e-9)
    # cos θ_h = (1 − u₀)^{1/(n_u cos²φ + n_v sin²φ + 1)}
    e = nu * np.cos(want) ** 2 + nv * np.sin(want) ** 2 + 1
    np.testing.assert_allclose(hz, (1 - u[:, 0]) ** (1 / e), rtol=1e-12)
    # p_h integrates to 1 over the hemisphere (product Gauss–Legendre in θ_h, φ_h)
    x, w = np.polynomial.legendre.leggauss(300)
    t, p = 0.25 * math.pi * (x + 1), math.pi * (x + 1)
    T, P = np.meshgrid(t, p, indexing="ij")
    val = AshikhminShirleyHalf(nu, nv).pdf(sph(T, P)) * np.sin(T)
    assert 0.25 * math.pi ** 2 * (w @ val @ w) == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize("phi_deg", [0.0, 67.0, 135.0, 290.0])
@pytest.mark.parametrize("ex", [{}, {"n_u": 1000.0, "n_v": 10.0, "R_s": 0.9, "R_d": 0.1}])
def test_chi2_at_azimuths(ex, phi_deg):
    m = brdfkit.model("ashikhmin-shirley", **ex)
    wo = sph(np.radians(50.0), np.radians(phi_deg))
    r = chi2_test(m, wo, n_samples=100_000, seed=int(phi_deg) + 5, alpha=0.01, n_tests=8)
    assert r.passed, r.message


def test_formulas_are_the_model():
    """The formulas the Mitsuba bridge traces, compiled by Numba, give the model's pdf and
    a sampler consistent with it (its samples' pdf is the model's pdf there)."""
    m = brdfkit.model("ashikhmin-shirley", n_u=20.0, n_v=400.0, R_d=0.3)
    f = m.formulas()
    rng = np.random.default_rng(4)
    wi, wo = pairs(rng, 200)
    p = m.packed[0]
    ev = [f.eval(*a, *b, p) for a, b in zip(wi, wo, strict=True)]
    np.testing.assert_allclose(ev, m.eval(wi, wo), rtol=1e-14)
    pd = [f.pdf(*a, *b, *f.args) for a, b in zip(wi, wo, strict=True)]
    np.testing.assert_allclose(pd, m.pdf(wi, wo), rtol=1e-12)
    u = rng.random((200, 2))
    drawn = np.array([f.sample(*b, *uu, *f.args) for b, uu in zip(wo, u, strict=True)])
    ok = drawn[:, 2] > 0
    np.testing.assert_allclose([f.pdf(*a, *b, *f.args) for a, b in zip(drawn[ok], wo[ok],
                                                                       strict=True)],
                               m.pdf(drawn[ok], wo[ok]), rtol=1e-12)
