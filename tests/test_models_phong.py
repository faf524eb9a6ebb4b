"""Tests of the Phong family (:mod:`brdfkit.models.phong`).

Every reference comes from outside the code under test: a closed form derived
in a comment (Lewis 1993 eq. 16, hand-worked configurations, Beta-function
integrals), a defining identity of a paper (Lewis eqs. 19 and 22, Neumann
eq. 7, Nielsen eq. 3), or an independent SciPy quadrature of ``model.eval``
in the frame of the mirror direction.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, special

import brdfkit
from brdfkit.errors import ParameterError
from brdfkit.fresnel import fresnel_dielectric
from brdfkit.models.phong import blinn_normal_albedo, specular_integral

PHONG_FAMILY = ("modified-phong", "phong", "blinn", "phong-energy-conserving",
                "phong-blinn-reciprocal", "nh-power-series", "modified-blinn-phong",
                "lafortune", "neumann-phong", "nielsen")
X64, W64 = np.polynomial.legendre.leggauss(64)


def direction(theta, phi=0.0):
    return np.array([math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi),
                     math.cos(theta)])


def mirror(v):
    return np.array([-v[0], -v[1], v[2]])


def albedo(m, theta_i, *, width=0.2, sub=2):
    """∫ f(wi, wo) cos θ_o dω_o by product Gauss–Legendre in the frame of R, the mirror of wi.

    α is the angle from R, φ the azimuth about R (φ = 0 toward the normal).
    The horizon V_z = cos α cos θ_i + sin α sin θ_i cos φ = 0 is solved for φ so
    that the 64-point rule in φ sees a smooth integrand; in α the panels break
    at the lobe scale (multiples of *width*), where the horizon starts and stops
    cutting the ring (α = 90° ∓ θ_i) and at the Phong clamp R·V = 0 (α = 90°).
    """
    c, s = math.cos(theta_i), math.sin(theta_i)
    wi = np.array([s, 0.0, c])
    r_axis, t_axis, b_axis = mirror(wi), np.array([c, 0.0, s]), np.array([0.0, 1.0, 0.0])
    brk = {0.0, math.pi, 0.5 * math.pi, 0.5 * math.pi - theta_i, 0.5 * math.pi + theta_i,
           *[k * width for k in (0.5, 1.0, 2.0, 4.0, 8.0) if k * width < math.pi]}
    brk = np.array(sorted(brk))
    edges = np.unique(np.concatenate([np.linspace(a, b, sub + 1)
                                      for a, b in zip(brk[:-1], brk[1:], strict=True)]))
    a0, a1 = edges[:-1, None], edges[1:, None]
    al = (0.5 * (a1 - a0) * (X64 + 1.0) + a0).ravel()
    wa = (0.5 * (a1 - a0) * W64).ravel()
    ca, sa = np.cos(al), np.sin(al)
    den, num = sa * s, -ca * c
    x = np.where(den > 0.0, num / np.where(den > 0.0, den, 1.0),
                 np.where(num < 0.0, -np.inf, np.inf))
    phi_max = np.arccos(np.clip(x, -1.0, 1.0))  # x ≤ −1: whole ring up; x ≥ 1: none
    phi = 0.5 * phi_max[:, None] * (X64 + 1.0)
    v = ca[:, None, None] * r_axis + sa[:, None, None] * (
        np.cos(phi)[..., None] * t_axis + np.sin(phi)[..., None] * b_axis)
    f = np.asarray(m.eval(wi, v))
    f = f[..., 0] if f.ndim == 3 else f
    ring = phi_max * np.sum(W64 * f * np.maximum(v[..., 2], 0.0), axis=-1) * sa  # 2 half-rings
    return float(np.sum(wa * ring))


def normal_incidence_albedo(m, n):
    """2π ∫ f(N, V(θ)) cos θ sin θ dθ: the integrand depends on θ only when wi = N.

    Composite 64-point Gauss–Legendre (scipy's fixed_quad rule) on panels that
    break at multiples of the lobe width 1/√(n+1), so sharp lobes are resolved.
    """
    w = 1.0 / math.sqrt(n + 1.0)
    brk = sorted({0.0, 0.5 * math.pi, *[k * w for k in (0.5, 1.0, 2.0, 4.0, 8.0, 16.0)
                                         if k * w < 0.5 * math.pi]})

    def g(t):
        v = np.stack([np.sin(t), np.zeros_like(t), np.cos(t)], axis=-1)
        return m.eval(np.array([0.0, 0.0, 1.0]), v) * np.cos(t) * np.sin(t)
    return 2.0 * math.pi * sum(integrate.fixed_quad(g, a, b, n=64)[0]
                               for a, b in zip(brk[:-1], brk[1:], strict=True))


def h_s_reference(theta_i, n, lobe):
    """Lewis's H_s(S) = ∫ F_s(S, V) (N·V) dω_V by nested adaptive quadrature of the definition."""
    s_vec = direction(theta_i)
    r_vec = mirror(s_vec)

    def inner(tv):
        def fs(ph):
            v = direction(tv, ph)
            if lobe == "phong":
                x = float(r_vec @ v)
                return x**n if x > 0.0 else 0.0
            h = s_vec + v
            return (h[2] / np.linalg.norm(h)) ** n
        return 2.0 * integrate.quad(fs, 0.0, math.pi, epsabs=1e-14, epsrel=1e-12,
                                    limit=200)[0] * math.cos(tv) * math.sin(tv)
    return integrate.quad(inner, 0.0, 0.5 * math.pi, points=[theta_i], epsabs=1e-14,
                          epsrel=1e-11, limit=200)[0]


# --------------------------------------------------------------------------- modified Phong
@pytest.mark.parametrize("n", [1.0, 20.0, 1000.0])
def test_modified_phong_is_normalised_at_normal_incidence(n):
    # Lewis eq. (16): ∫ cos^γ θ dω = 2π/(γ+1), so ∫ (n+2)/2π cosⁿα cos θ dω = 1 when R = N.
    m = brdfkit.model("modified-phong", rho_d=0.0, rho_s=1.0, n=n)
    assert normal_incidence_albedo(m, n) == pytest.approx(1.0, rel=1e-8)


# --------------------------------------------------------------------------- Blinn normalisation
def blinn_closed_form(n):
    # Derived: with L = N, θ_o = 2θ_h, cos θ_o = 2h² − 1 and sin θ_o dθ_o = −4h dh, so
    # ∫ (N·H)ⁿ cos θ_o dω_o = 8π ∫_{1/√2}^1 h^{n+1}(2h² − 1) dh
    #                     = 8π [2(1 − 2^{−(n+4)/2})/(n+4) − (1 − 2^{−(n+2)/2})/(n+2)].
    return 8.0 * math.pi * (2.0 * (1.0 - 2.0 ** (-(n + 4.0) / 2.0)) / (n + 4.0)
                            - (1.0 - 2.0 ** (-(n + 2.0) / 2.0)) / (n + 2.0))


@pytest.mark.parametrize("n", [0.0, 1.0, 4.0, 20.0, 1000.0])
def test_blinn_normal_albedo_closed_form_matches_quadrature(n):
    m = brdfkit.model("phong-blinn-reciprocal", k_d=0.0, k_s=1.0, n=n)
    quad = normal_incidence_albedo(m, n)
    assert quad == pytest.approx(blinn_closed_form(n), rel=1e-9)
    assert blinn_normal_albedo(n) == pytest.approx(blinn_closed_form(n), rel=1e-13)


def test_modified_blinn_phong_factor_is_only_approximate():
    # Nielsen eq. (2) keeps Akenine-Möller's (n+8)/8π. Exact normal-incidence albedo of
    # ρ_s (n+8)/8π (N·H)ⁿ with ρ_s = 1, by quadrature of the model, against the closed form:
    # n = 0: 8/8π · π = 1 exactly; n = 4: 12·(2·(15/16)/8 − (7/8)/6) = 12·17/192 = 17/16.
    for n, expected in [(0.0, 1.0), (4.0, 17.0 / 16.0)]:
        m = brdfkit.model("modified-blinn-phong", rho_d=0.0, rho_s=1.0, n=n)
        assert normal_incidence_albedo(m, n) == pytest.approx(expected, rel=1e-9)
    # The approximation over-estimates for every n > 0: up to 7.5 % near n ≈ 8.8, and
    # (n+8)/(8π)·8πn/((n+2)(n+4)) → 1 + 2/n for large n.
    nn = np.linspace(0.05, 60.0, 1200)
    ratio = (nn + 8.0) / (8.0 * math.pi) * np.array([blinn_closed_form(x) for x in nn])
    assert np.all(ratio > 1.0)
    assert ratio.max() == pytest.approx(1.0752, abs=1e-4)
    assert 8.0 < nn[np.argmax(ratio)] < 9.5
    m = brdfkit.model("modified-blinn-phong", rho_d=0.0, rho_s=1.0, n=1000.0)
    assert normal_incidence_albedo(m, 1000.0) - 1.0 == pytest.approx(2.0 / 1000.0, rel=0.02)


# --------------------------------------------------------------------------- H_s and eq. (22)
@pytest.mark.parametrize("n", [1.0, 20.0, 1000.0, 1e6])
def test_specular_integral_closed_forms(n):
    # Lewis eq. (16) at θ_i = 0 (Phong: R = N): 2π/(n+2).
    assert specular_integral(0.0, n, "phong") == pytest.approx(2 * math.pi / (n + 2), rel=1e-12)
    # Blinn at θ_i = 0 is the normal-incidence albedo derived above.
    assert specular_integral(0.0, n, "blinn") == pytest.approx(blinn_closed_form(n), rel=1e-10)
    # θ_i = 90°, Blinn: V = 2(S·H)H − S with S on the horizon, V_z = 2 (S·H) cos γ; in H
    # coordinates ∫ cosⁿγ · 4(S·H)·2(S·H)cos γ ... = 4π ∫ h^{n+1}(1 − h²) dh = 8π/((n+2)(n+4)).
    assert specular_integral(0.5 * math.pi, n, "blinn") == pytest.approx(
        8 * math.pi / ((n + 2) * (n + 4)), rel=1e-9)
    if n <= 1000.0:  # scipy's Beta loses digits for huge arguments
        # θ_i = 90°, Phong: R on the horizon, ∫ cosⁿα · 2 sin α · sin α dα = B((n+1)/2, 3/2).
        assert specular_integral(0.5 * math.pi, n, "phong") == pytest.approx(
            special.beta((n + 1) / 2, 1.5), rel=1e-10)


@pytest.mark.parametrize("lobe", ["phong", "blinn"])
@pytest.mark.parametrize("n,theta_deg", [(20.0, 45.0), (20.0, 85.0), (150.0, 80.0)])
def test_specular_integral_against_nested_quadrature(lobe, n, theta_deg):
    t = math.radians(theta_deg)
    assert specular_integral(t, n, lobe) == pytest.approx(h_s_reference(t, n, lobe), rel=1e-9)


def test_specular_integral_zero_exponent_and_validation():
    # (N·H)^0 = 1 and 0^0 = 1: H_s = ∫ cos θ dω = π (Lewis eq. 16 with γ = 1).
    assert np.allclose(specular_integral(np.linspace(0, 1.5, 5), 0.0, "phong"), math.pi)
    # Blinn with n → 0⁺ has no clamp (N·H > 0 above the horizon): also π at every angle.
    assert np.allclose(specular_integral(np.linspace(0, 1.57, 7), 1e-12, "blinn"), math.pi,
                       rtol=1e-10)
    with pytest.raises(ParameterError, match="theta_i"):
        specular_integral(2.0, 1.0)
    with pytest.raises(ParameterError, match="lobe"):
        specular_integral(0.1, 1.0, "ward")


# Registered models whose BRDF is Lewis's F_s itself (no 1/(N·S)): Lafortune's lobe with
# C_xy = −1, C_z = 1 is max(0, R·V)ⁿ (shown in test_lafortune_mirror_coefficients_give_phong_lobe)
# and the reciprocal Phong–Blinn with k_d = 0, k_s = 1 is (N·H)ⁿ (eq. 24).
def fs_model(lobe, n):
    if lobe == "phong":
        return brdfkit.model("lafortune", rho_d=0.0, rho_s=1.0, C_xy=-1.0, C_z=1.0, n=n)
    return brdfkit.model("phong-blinn-reciprocal", k_d=0.0, k_s=1.0, n=n)


@pytest.mark.parametrize("lobe", ["phong", "blinn"])
@pytest.mark.parametrize("n", [0.0, 3.0, 50.0, 2000.0])
def test_H_s_against_the_albedo_engine(lobe, n):
    # Two independent methods: H_s (closed-form azimuth + tanh-sinh, models.specular) and
    # the albedo engine's lobe-frame Gauss–Kronrod over a registered model equal to F_s.
    from brdfkit.analysis import H_s
    from brdfkit.analysis import albedo as engine

    th = np.radians([0.0, 20.0, 50.0, 75.0, 85.0, 89.0, 89.9])
    hs = H_s(th, n, lobe=lobe)
    ref = engine(fs_model(lobe, n), th, tol=1e-10)
    np.testing.assert_allclose(hs.albedo, ref.albedo, rtol=0, atol=1e-9)
    # each method's error estimate covers the difference between the two
    assert np.all(np.abs(hs.albedo - ref.albedo) <= hs.error + ref.error + 1e-15)
    np.testing.assert_array_equal(hs.albedo, specular_integral(th, n, lobe))  # the one H_s


# H_s to 25 digits by mpmath (closed-form azimuth as in models.specular, the polar integral
# by mpmath's tanh-sinh, panels at the lobe scale); independent of float64 rounding.
H_S_25_DIGITS = [
    ("phong", 1e4, 1.5697963267948967, 2.832680678942615174783852e-6),
    ("phong", 1e4, 1.5707, 2.536436566816404401640749e-6),
    ("phong", 1e6, 1.5697963267948967, 6.806656593296028447356268e-9),
    ("phong", 1e6, 1.5707, 2.820861885819349964057917e-9),
    ("phong", 1e6, 0.3, 6.002544186798164958732352e-6),
    ("blinn", 20.0, 1.5697963267948967, 0.04785192611441420299644334),
    ("blinn", 1e4, 1.5697963267948967, 2.825139228951083325211351e-7),
    ("blinn", 1e6, 1.5697963267948967, 6.983130257470212330429058e-11),
]


@pytest.mark.parametrize("lobe,n,theta,ref", H_S_25_DIGITS)
def test_H_s_error_estimate_bounds_the_error(lobe, n, theta, ref):
    from brdfkit.models.specular import specular_integral_with_error

    v, e = specular_integral_with_error(theta, n, lobe)
    assert abs(v - ref) <= e
    assert e <= 2e-9 * ref  # and stays useful (≤ n·ε relative: pessimistic, but a bound)


@pytest.mark.parametrize("n", [1.0, 20.0, 1000.0, 1e6])
def test_H_s_error_estimate_at_closed_forms(n):
    from brdfkit.analysis import H_s

    # Lewis eq. (16) at θ_i = 0 and the grazing Blinn closed form (see above)
    r = H_s(np.array([0.0]), n, lobe="phong")
    assert abs(r.albedo[0] - 2 * math.pi / (n + 2)) <= r.error[0]
    r = H_s(np.array([0.5 * math.pi - 1e-15]), n, lobe="blinn")
    assert abs(r.albedo[0] - 8 * math.pi / ((n + 2) * (n + 4))) <= r.error[0] + 1e-13 * r.albedo[0]
    with pytest.raises(ParameterError, match="theta_i"):
        H_s(0.5 * math.pi, n)  # as every albedo: θ_i in [0, π/2)
    with pytest.raises(ParameterError, match="tol"):
        H_s(0.1, n, tol=0.0)


def test_moved_names_still_import_from_phong():
    # the split keeps `from brdfkit.models.phong import X` working for every public name
    from brdfkit.models import blinn, grazing, lafortune, sampling
    from brdfkit.models import phong as ph

    assert ph.Nielsen is grazing.Nielsen and ph.NeumannPhong is grazing.NeumannPhong
    assert ph.Lafortune is lafortune.Lafortune
    assert ph.PhongBlinnReciprocal is blinn.PhongBlinnReciprocal
    assert ph.NHPowerSeries is blinn.NHPowerSeries
    assert ph.ModifiedBlinnPhong is blinn.ModifiedBlinnPhong
    assert ph.sample_phong_lobe is sampling.sample_phong_lobe
    for name in ("lobe_pow", "blinn_normal_albedo", "specular_integral", "pdf_phong_lobe",
                 "sample_blinn_lobe", "pdf_blinn_lobe", "diffuse_fraction", "split_uniform"):
        assert callable(getattr(ph, name)), name
    with pytest.raises(AttributeError):
        ph.NoSuchModel  # noqa: B018


@pytest.mark.parametrize("lobe", ["phong", "blinn"])
@pytest.mark.parametrize("theta_deg", [0.0, 45.0, 80.0, 89.0])
def test_energy_conserving_phong_albedo_equals_k_rho(lobe, theta_deg):
    # Lewis eq. (22): dividing F_s by H_s(S) makes the albedo k_ρ at every θ_i.
    m = brdfkit.model("phong-energy-conserving", k_rho=0.7, k_sigma=0.8, n=20.0, lobe=lobe)
    a = albedo(m, math.radians(theta_deg), width=0.25)
    assert a == pytest.approx(0.7, rel=1e-8)


@pytest.mark.parametrize("n", [0.5, 20.0, 1e4])
@pytest.mark.parametrize("lobe", ["phong", "blinn"])
def test_energy_conserving_table_interpolation(n, lobe, rng):
    # The kernel interpolates a table of H_s; compare with F_s/H_s computed directly.
    m = brdfkit.model("phong-energy-conserving", k_rho=1.0, k_sigma=1.0, n=n, lobe=lobe)
    z = np.concatenate([rng.random(300) ** 4, [1e-12, 1e-9, 1.0]])
    wi = np.stack([np.sqrt(1 - z * z), np.zeros_like(z), z], axis=-1)
    wo = mirror(wi.T).T.copy()
    if lobe == "phong":
        fs = 1.0  # V = R: (R·V)ⁿ = 1
    else:
        h = wi + wo
        fs = (h[:, 2] / np.linalg.norm(h, axis=-1)) ** n
    direct = fs / specular_integral(np.arccos(z), n, lobe)
    np.testing.assert_allclose(m.eval(wi, wo), direct, rtol=1e-8)


# --------------------------------------------------------------------------- Lewis eqs. (8), (19)
@pytest.mark.parametrize("name,lobe", [("phong", "phong"), ("blinn", "blinn")])
@pytest.mark.parametrize("theta_deg", [70.0])
def test_phong_blinn_albedo_identity_eq19(name, lobe, theta_deg):
    # Lewis eq. (19): k_ρ = k_d π + k_s H_s(S)/(N·S); both sides by separate quadratures.
    k_d, k_s, n = 0.05, 0.8, 10.0
    m = brdfkit.model(name, k_d=k_d, k_s=k_s, n=n)
    t = math.radians(theta_deg)
    rhs = k_d * math.pi + k_s * h_s_reference(t, n, lobe) / math.cos(t)
    assert albedo(m, t, width=0.3) == pytest.approx(rhs, rel=1e-8)


@pytest.mark.parametrize("name", ["phong", "blinn"])
def test_phong_blinn_not_reciprocal_on_explicit_pair(name):
    # With k_d = 0, f(L,V)/f(V,L) = (N·V)/(N·L) because F_s (R·V or N·H) is symmetric:
    # θ_i = 60°, θ_o = 30° (opposite azimuths) gives cos 30°/cos 60° = √3.
    m = brdfkit.model(name, k_d=0.0, k_s=1.0, n=5.0)
    wi, wo = direction(math.radians(60.0)), direction(math.radians(30.0), math.pi)
    assert m.eval(wi, wo) / m.eval(wo, wi) == pytest.approx(math.sqrt(3.0), rel=1e-12)
    # the value itself: R·V = cos 30° (R at 60° on the far side, V at 30° there)
    if name == "phong":
        assert m.eval(wi, wo) == pytest.approx(math.cos(math.radians(30.0)) ** 5 / 0.5, rel=1e-12)


def test_phong_energy_conserving_not_reciprocal():
    m = brdfkit.model("phong-energy-conserving", k_sigma=1.0, n=10.0, lobe="phong")
    wi, wo = direction(math.radians(70.0)), direction(math.radians(20.0), math.pi)
    assert abs(m.eval(wi, wo) / m.eval(wo, wi) - 1.0) > 0.05


# --------------------------------------------------------------------------- Neumann eq. (22)
def test_neumann_phong_hand_computed_value():
    # n = 2, c_n = (n+2)/2π = 2/π; L at 30°, V at 45° on the other side:
    # R·V = sin30 sin45 + cos30 cos45 = cos 15°, (R·V)² = (2+√3)/4, max(N·L, N·V) = √3/2,
    # f = (2/π)·(2+√3)/4/(√3/2) = (2+√3)/(√3 π).
    m = brdfkit.model("neumann-phong", n=2.0)
    wi, wo = direction(math.radians(30.0)), direction(math.radians(45.0), math.pi)
    expected = (2.0 + math.sqrt(3.0)) / (math.sqrt(3.0) * math.pi)
    assert m.eval(wi, wo) == pytest.approx(expected, rel=1e-14)
    assert m.eval(wo, wi) == pytest.approx(expected, rel=1e-14)
    assert m.c_n() == pytest.approx(2.0 / math.pi)
    # an explicit c_n scales linearly (and may exceed the paper's bound)
    assert brdfkit.model("neumann-phong", n=2.0, c_n=10.0).eval(wi, wo) == pytest.approx(
        expected * 10.0 / (2.0 / math.pi), rel=1e-14)


def test_neumann_phong_reciprocal(rng, random_hemisphere):
    m = brdfkit.model("neumann-phong", n=7.5, c_n=[0.3, 1.0])
    wi, wo = random_hemisphere(rng, 5000), random_hemisphere(rng, 5000)
    np.testing.assert_allclose(m.eval(wi, wo), m.eval(wo, wi), rtol=1e-13, atol=0)


def test_neumann_phong_bound_is_necessary_not_sufficient():
    # Normal incidence: max(N·L, N·V) = 1, albedo = c_n 2π/(n+2) (Lewis eq. 16) = 1.
    m = brdfkit.model("neumann-phong", n=20.0)
    assert albedo(m, 0.0, width=0.2) == pytest.approx(1.0, rel=1e-9)
    assert albedo(m, math.radians(45.0), width=0.2) < 1.0
    # Paper error: at n = 0 (0⁰ = 1) with c_n = 2/2π = 1/π the albedo is
    # [2π(1 − cos θ_i) + π cos θ_i]/π = 2 − cos θ_i > 1 (derived in the model docstring).
    # F ≡ 1 here, so f depends on θ_o only: a 1-D quadrature about the normal, broken
    # where max(N·L, N·V) switches (θ_o = θ_i).
    m0 = brdfkit.model("neumann-phong", n=0.0)
    t_i = math.radians(60.0)

    def g(t):
        return float(m0.eval(direction(t_i), direction(t, 1.0))) * math.cos(t) * math.sin(t)
    a0 = 2.0 * math.pi * integrate.quad(g, 0.0, 0.5 * math.pi, points=[t_i], epsrel=1e-12)[0]
    assert a0 == pytest.approx(2.0 - math.cos(t_i), rel=1e-10)
    # and for small positive exponents the paper's c_n still gives albedo > 1 off the normal
    assert albedo(brdfkit.model("neumann-phong", n=0.1), math.radians(45.0), width=1.0) > 1.05
    assert albedo(brdfkit.model("neumann-phong", n=1.0), math.radians(13.0), width=0.7) > 1.0002
    # the bound sufficient for every n, c_n = (n+1)/2π, keeps it below 1
    m_ok = brdfkit.model("neumann-phong", n=0.1, c_n=1.1 / (2.0 * math.pi))
    assert albedo(m_ok, math.radians(45.0), width=1.0) < 1.0


# --------------------------------------------------------------------------- Lafortune
def test_lafortune_mirror_coefficients_give_phong_lobe(rng, random_hemisphere):
    # C_xy = −1, C_z = 1: −ix ox − iy oy + iz oz = R·V (R = (−ix, −iy, iz)).
    m = brdfkit.model("lafortune", rho_d=0.0, rho_s=1.0, C_xy=-1.0, C_z=1.0, n=13.0)
    wi, wo = random_hemisphere(rng, 4000), random_hemisphere(rng, 4000)
    rv = np.sum(mirror(wi.T).T * wo, axis=-1)
    np.testing.assert_allclose(m.eval(wi, wo), np.maximum(rv, 0.0) ** 13.0, rtol=1e-12,
                               atol=1e-300)


def test_lafortune_neumann_form_correspondence(rng, random_hemisphere):
    # Neumann eq. (7): c_L (R_x V_x + R_y V_y + s R_z V_z)ⁿ with R the mirror of L equals
    # Lafortune's [C_xy(ix ox + iy oy) + C_z iz oz]ⁿ for C_xy = −c, C_z = c·s, c = c_L^{1/n}.
    c_l, s, n = 3.0, 0.8, 10.0
    c = c_l ** (1.0 / n)
    m = brdfkit.model("lafortune", rho_d=0.1, rho_s=1.0, C_xy=-c, C_z=c * s, n=n)
    wi, wo = random_hemisphere(rng, 4000), random_hemisphere(rng, 4000)
    r = mirror(wi.T).T
    base = r[:, 0] * wo[:, 0] + r[:, 1] * wo[:, 1] + s * r[:, 2] * wo[:, 2]
    expected = 0.1 / math.pi + c_l * np.maximum(base, 0.0) ** n
    np.testing.assert_allclose(m.eval(wi, wo), expected, rtol=1e-12)


def test_lafortune_lobes_add_and_validate(rng, random_hemisphere):
    wi, wo = random_hemisphere(rng, 500), random_hemisphere(rng, 500)
    both = brdfkit.model("lafortune", rho_d=0.0, C_xy=[-1.0, 0.5], C_z=[0.9, 0.7], n=[8.0, 2.0])
    one = brdfkit.model("lafortune", rho_d=0.0, C_xy=-1.0, C_z=0.9, n=8.0)
    two = brdfkit.model("lafortune", rho_d=0.0, C_xy=0.5, C_z=0.7, n=2.0)
    np.testing.assert_allclose(both.eval(wi, wo), one.eval(wi, wo) + two.eval(wi, wo), rtol=1e-13)
    with pytest.raises(ParameterError, match="same length"):
        brdfkit.model("lafortune", C_xy=[-1.0, -0.5], n=[1.0, 2.0, 3.0])
    with pytest.raises(ParameterError, match="1e300"):
        brdfkit.model("lafortune", C_xy=-2.0, C_z=2.0, n=5000.0)


# --------------------------------------------------------------------------- Nielsen eq. (3)
def test_nielsen_limits(rng, random_hemisphere):
    wi, wo = random_hemisphere(rng, 4000), random_hemisphere(rng, 4000)
    rv = np.sum(mirror(wi.T).T * wo, axis=-1)
    h = wi + wo
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    # α = 0, no η: the unnormalised modified Phong of eq. (1), ρ_d/π + k_s max(0, R·V)^s
    m0 = brdfkit.model("nielsen", rho_d=0.3, k_s=2.5, s=7.0, alpha=0.0)
    np.testing.assert_allclose(m0.eval(wi, wo), 0.3 / math.pi + 2.5 * np.maximum(rv, 0) ** 7,
                               rtol=1e-12)
    # α = 1: ((N·H)⁴)^s = (N·H)^{4s}
    m1 = brdfkit.model("nielsen", rho_d=0.0, k_s=1.0, s=3.0, alpha=1.0)
    np.testing.assert_allclose(m1.eval(wi, wo), h[:, 2] ** 12, rtol=1e-12)
    # with η: k_s times the dielectric Fresnel factor at ω_i·ω_h
    m2 = brdfkit.model("nielsen", rho_d=0.0, k_s=1.0, s=3.0, alpha=1.0, eta=1.5)
    fres = fresnel_dielectric(np.sum(wi * h, axis=-1), 1.5)
    np.testing.assert_allclose(m2.eval(wi, wo), fres * h[:, 2] ** 12, rtol=1e-11)
    # reciprocal for a mixed α: R·V, N·H and ω_i·ω_h are symmetric
    m3 = brdfkit.model("nielsen", alpha=0.4, eta=[1.3, 1.7], s=30.0)
    np.testing.assert_allclose(m3.eval(wi, wo), m3.eval(wo, wi), rtol=1e-12)


# --------------------------------------------------------------------------- N·H power series
def test_nh_power_series_is_the_sum(rng, random_hemisphere):
    wi, wo = random_hemisphere(rng, 3000), random_hemisphere(rng, 3000)
    h = wi + wo
    nh = h[:, 2] / np.linalg.norm(h, axis=-1)
    m = brdfkit.model("nh-power-series", k_s=[0.1, 0.5, 5.0], n=[0.0, 10.0, 200.0])
    # Lewis §7: Σ k_i (N·H)^{n_i}; the n_0 = 0 term is the constant (diffuse) k_0
    np.testing.assert_allclose(m.eval(wi, wo), 0.1 + 0.5 * nh**10 + 5.0 * nh**200, rtol=1e-12)
    one = brdfkit.model("nh-power-series", k_s=2.0, n=30.0)
    ref = brdfkit.model("phong-blinn-reciprocal", k_d=0.0, k_s=2.0, n=30.0)
    np.testing.assert_allclose(one.eval(wi, wo), ref.eval(wi, wo), rtol=1e-14)


# --------------------------------------------------------------------------- every model
@pytest.mark.parametrize("name", PHONG_FAMILY)
def test_horizon_and_grazing(name):
    cls = brdfkit.MODELS[name]
    for ex in cls.examples:
        m = cls(**ex)
        up = direction(math.radians(40.0), 0.3)
        graze = [np.array([1.0, 0.0, 0.0]), np.array([math.sqrt(1 - 1e-24), 0.0, 1e-12]),
                 np.array([-math.sqrt(1 - 1e-24), 0.0, 1e-12])]
        below = [np.array([0.6, 0.0, -0.8]), np.array([0.0, 0.0, -1.0])]
        for g in graze + below:
            for wi, wo in [(g, up), (up, g), (g, mirror(g)), (g, g)]:
                f = np.asarray(m.eval(wi, wo))
                assert np.all(np.isfinite(f)) and np.all(f >= 0.0), (name, ex, wi, wo, f)
                if wi[2] <= 0.0 or wo[2] <= 0.0:
                    assert np.all(f == 0.0), (name, ex, wi, wo, f)


@pytest.mark.parametrize("name", PHONG_FAMILY)
def test_colour_channels_equal_scalar_runs(name, rng, random_hemisphere):
    cls = brdfkit.MODELS[name]
    colour = [p for p in cls.params if p.kind == "colour"]
    if not colour:
        pytest.skip(f"{name} has no per-channel parameter")
    wi, wo = random_hemisphere(rng, 1000), random_hemisphere(rng, 1000)
    wo[:10] = mirror(wi[:10].T).T  # include the lobe peak
    values = {}
    for p in colour:
        base = p.lower if math.isfinite(p.lower) else 0.0
        top = min(p.upper, base + 3.0)
        values[p.name] = list(np.linspace(base + 0.1 * (top - base), base + 0.9 * (top - base), 3))
    m = cls(**values)
    f = m.eval(wi, wo)
    assert f.shape == (1000, 3)
    for c in range(3):
        ms = cls(**{k: v[c] for k, v in values.items()})
        np.testing.assert_allclose(f[:, c], ms.eval(wi, wo), rtol=1e-14, atol=0)


@pytest.mark.parametrize("name", PHONG_FAMILY)
def test_out_of_range_parameters_raise(name):
    cls = brdfkit.MODELS[name]
    for p in cls.params:
        bad = ["nope"] if p.kind == "choice" else [p.lower - 1.0, math.nan]
        if p.kind != "choice" and math.isfinite(p.upper):
            bad.append(p.upper * 2.0 + 1.0)
        for v in bad:
            with pytest.raises(ParameterError, match=repr(p.name)):
                cls(**{p.name: v})


@pytest.mark.parametrize("name", [n for n in PHONG_FAMILY if brdfkit.MODELS[n].width_param])
def test_beta_gives_half_maximum_exponent(name):
    # Lewis §3.1: cosⁿβ = 1/2.
    cls = brdfkit.MODELS[name]
    m = cls(beta=math.radians(10.0))
    n = np.atleast_1d(m.values[cls.width_param])[0]
    assert math.cos(math.radians(10.0)) ** n == pytest.approx(0.5, rel=1e-12)


@pytest.mark.parametrize("name", [n for n in PHONG_FAMILY if brdfkit.MODELS[n].has_sampler])
def test_sampler_follows_its_pdf(name):
    chi2 = pytest.importorskip("brdfkit.analysis.chi2")
    cls = brdfkit.MODELS[name]
    for ex in cls.examples[:2]:
        m = cls(**ex)
        for theta in (0.4, 1.45):
            r = chi2.chi2_test(m, direction(theta, 0.3), n_samples=40_000, seed=7,
                               n_tests=4 * len(PHONG_FAMILY))
            assert r.passed, f"{name} {ex} θ_o={theta}: {r.message}"
