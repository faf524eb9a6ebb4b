"""Diffuse and separable models: lambert, neumann-neumann, minnaert,
minnaert-energy-conserving.

Every reference is independent of the model code:
- albedos by scipy quadrature of ``model.eval`` (a second method) against the
  closed forms derived in the docstrings: Lambert ρ_d; Neumann–Neumann
  2π b_N e^{2s − s/cos θ_i} E₃(s) (E₃ from scipy.special.expn); Minnaert
  2π b_M cos^{k−1}θ_i/(k+1); energy-conserving Minnaert k_ρ cos^{k−1}θ_i
  (Lewis §4.3, eq. after Fig. 8);
- the formulas of Lewis §3.3, §3.4, §4.3 typed into the tests;
- the moments of the Minnaert sampling density (k+1)/(2π) cos^k θ:
  E[cos θ] = (k+1)/(k+2).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, special

import brdfkit
from brdfkit.errors import ParameterError
from brdfkit.geometry import spherical_to_cartesian

NORMAL = np.array([0.0, 0.0, 1.0])


def albedo_quad(model, theta_i, phi_o_samples=(0.0,)):
    """a(θ_i) = ∫ f cos θ_o dω_o by scipy quad in θ_o (separable models: f independent of φ_o).

    The φ-independence is itself checked in ``test_separable_no_azimuth_dependence``.
    """
    wi = spherical_to_cartesian(theta_i, 0.0)

    def integrand(t):
        return float(model.eval(wi, spherical_to_cartesian(t, phi_o_samples[0]))) * math.cos(t) \
            * math.sin(t)

    val, _ = integrate.quad(integrand, 0.0, math.pi / 2, limit=200, epsabs=1e-12, epsrel=1e-9)
    return 2.0 * math.pi * val


# ----------------------------------------------------------------------------- lambert
@pytest.mark.parametrize("theta_i", [0.0, 0.7, 1.5])
def test_lambert_albedo(theta_i):
    assert albedo_quad(brdfkit.model("lambert", rho_d=0.6), theta_i) == pytest.approx(0.6, rel=1e-9)


# ----------------------------------------------------------------------------- Neumann-Neumann
@pytest.mark.parametrize("s", [0.05, 0.5, 3.0])
@pytest.mark.parametrize("theta_i", [0.0, 0.6, 1.2, 1.55])
def test_neumann_neumann_albedo_closed_form(s, theta_i):
    b_n = 0.3
    model = brdfkit.model("neumann-neumann", b_N=b_n, s=s)
    expected = 2 * math.pi * b_n * math.exp(2 * s - s / math.cos(theta_i)) * special.expn(3, s)
    assert albedo_quad(model, theta_i) == pytest.approx(expected, rel=1e-7)


def test_neumann_neumann_formula_points():
    # Lewis §3.3: b_N exp{-s (1/(N.S) + 1/(N.V) - 2)}, typed in here.
    model = brdfkit.model("neumann-neumann", b_N=0.4, s=0.7)
    wi = spherical_to_cartesian(0.5, 0.2)
    wo = spherical_to_cartesian(1.1, 2.0)
    expected = 0.4 * math.exp(-0.7 * (1 / math.cos(0.5) + 1 / math.cos(1.1) - 2))
    assert model.eval(wi, wo) == pytest.approx(expected, rel=1e-13)
    assert model.eval(NORMAL, NORMAL) == pytest.approx(0.4, rel=1e-15)  # b_N at S = V = N
    # s = 0: a clear lacquer, the Lambertian b_N everywhere
    assert brdfkit.model("neumann-neumann", b_N=0.2, s=0.0).eval(wi, wo) == 0.2


# ----------------------------------------------------------------------------- Minnaert
@pytest.mark.parametrize("k", [0.3, 1.0, 2.5, 40.0])
@pytest.mark.parametrize("theta_i", [0.0, 0.8, 1.4])
def test_minnaert_albedo_closed_form(k, theta_i):
    model = brdfkit.model("minnaert", b_M=0.15, k=k)
    expected = 2 * math.pi * 0.15 * math.cos(theta_i) ** (k - 1) / (k + 1)
    assert albedo_quad(model, theta_i) == pytest.approx(expected, rel=1e-7)


@pytest.mark.parametrize("k", [0.5, 1.0, 3.0, 200.0])
@pytest.mark.parametrize("theta_i", [0.0, 0.9, 1.45])
def test_minnaert_energy_conserving_albedo(k, theta_i):
    # Lewis §4.3: a(θ_i) = k_rho cos^{k-1} θ_i (derived; the quadrature is the reference method)
    model = brdfkit.model("minnaert-energy-conserving", k_rho=0.7, k=k)
    assert albedo_quad(model, theta_i) == pytest.approx(0.7 * math.cos(theta_i) ** (k - 1),
                                                        rel=1e-7)


def test_lewis_energy_claim_needs_k_at_least_one():
    # Lewis §4.3: "any value of k_rho between 0 and 1 will guarantee energy conservation".
    # For k < 1 the albedo k_rho cos^{k-1} θ_i exceeds 1 once cos θ_i < k_rho^{1/(1-k)}:
    # with k = 0.5, k_rho = 0.5 that is cos θ_i < 0.25, i.e. θ_i > 75.5 deg.
    model = brdfkit.model("minnaert-energy-conserving", k_rho=0.5, k=0.5)
    assert albedo_quad(model, math.radians(80.0)) > 1.1
    # ... and for k >= 1 it never does:
    model = brdfkit.model("minnaert-energy-conserving", k_rho=1.0, k=1.5)
    assert max(albedo_quad(model, t) for t in (0.0, 1.0, 1.5, 1.57)) <= 1.0 + 1e-9


def test_minnaert_formula_points():
    # Lewis §3.4: b_M ((N.S)(N.V))^{k-1}; §4.3: k_rho (k+1)/(2 pi) ((N.S)(N.V))^{k-1}
    wi = spherical_to_cartesian(0.4, 1.0)
    wo = spherical_to_cartesian(0.9, -2.0)
    prod = math.cos(0.4) * math.cos(0.9)
    m = brdfkit.model("minnaert", b_M=0.3, k=1.7)
    assert m.eval(wi, wo) == pytest.approx(0.3 * prod**0.7, rel=1e-13)
    m = brdfkit.model("minnaert-energy-conserving", k_rho=0.3, k=1.7)
    assert m.eval(wi, wo) == pytest.approx(0.3 * 2.7 / (2 * math.pi) * prod**0.7, rel=1e-13)
    m = brdfkit.model("minnaert", b_M=0.3, k=1.0)  # k = 1: Lambertian b_M
    assert m.eval(wi, wo) == pytest.approx(0.3, rel=1e-15)


# ----------------------------------------------------------------------------- Minnaert sampling
@pytest.mark.parametrize("name", ["minnaert", "minnaert-energy-conserving"])
@pytest.mark.parametrize("k", [0.5, 2.0, 50.0])
def test_minnaert_sampling_is_exact(name, k, rng):
    model = brdfkit.model(name, k=k)
    wo = spherical_to_cartesian(0.7, 0.4)
    wi, pdf = model.sample(wo, rng.random((200_000, 2)))
    np.testing.assert_allclose(pdf, model.pdf(wi, wo), rtol=1e-12)
    # E[cos θ] = (k+1)/(k+2) under the density (k+1)/(2π) cos^k θ (closed form)
    se = np.std(wi[:, 2]) / math.sqrt(len(wi))
    assert abs(np.mean(wi[:, 2]) - (k + 1) / (k + 2)) < 5 * se + 1e-12
    # f cos θ_i / pdf is constant = the albedo (reciprocity: a(θ_o) seen from wo)
    w = model.eval(wi, wo) * wi[:, 2] / pdf
    ok = pdf > 0
    np.testing.assert_allclose(w[ok], albedo_quad(model, 0.7), rtol=1e-6)


@pytest.mark.parametrize("k", [0.5, 3.0])
def test_minnaert_pdf_normalised(k):
    model = brdfkit.model("minnaert", k=k)
    wo = spherical_to_cartesian(0.3, 0.0)

    def integrand(t):
        return float(model.pdf(spherical_to_cartesian(t, 0.0), wo)) * math.sin(t)

    val, _ = integrate.quad(integrand, 0.0, math.pi, points=[math.pi / 2], limit=200)
    assert 2 * math.pi * val == pytest.approx(1.0, rel=1e-9)


@pytest.mark.parametrize("s", [0.0, 0.3, 5.0, 200.0])
def test_neumann_neumann_sampler(s, rng):
    # Draws from (s+2)/(2π) cos^{s+1}; the weights f cos/pdf are bounded by their value at
    # cos θ_i = 1 (see the docstring), and their mean is the closed-form albedo.
    model = brdfkit.model("neumann-neumann", b_N=0.3, s=s)
    wo = spherical_to_cartesian(0.5, 1.0)
    wi, pdf = model.sample(wo, rng.random((200_000, 2)))
    np.testing.assert_allclose(pdf, model.pdf(wi, wo), rtol=1e-12)
    se_ref = np.std(wi[:, 2]) / math.sqrt(len(wi))
    assert abs(np.mean(wi[:, 2]) - (s + 2) / (s + 3)) < 5 * se_ref + 1e-12  # E[cos] closed form
    ok = pdf > 0
    w = np.where(ok, model.eval(wi, wo) * wi[:, 2] / np.where(ok, pdf, 1.0), 0.0)
    w_max = float(model.eval(NORMAL, wo)) * 2 * math.pi / (s + 2)
    assert np.max(w) <= w_max * (1 + 1e-12)
    expected = 2 * math.pi * 0.3 * math.exp(2 * s - s / math.cos(0.5)) * special.expn(3, s) \
        if s > 0 else 0.3 * math.pi
    se = np.std(w) / math.sqrt(len(w))
    assert abs(np.mean(w) - expected) < 5 * se + 1e-12


# ----------------------------------------------------------------------------- common physics
SEPARABLE = [
    ("neumann-neumann", {"b_N": 0.3, "s": 0.8}),
    ("minnaert", {"b_M": 0.2, "k": 0.6}),
    ("minnaert", {"b_M": 0.2, "k": 3.0}),
    ("minnaert-energy-conserving", {"k_rho": 0.9, "k": 0.4}),
    ("minnaert-energy-conserving", {"k_rho": 0.9, "k": 8.0}),
]


@pytest.mark.parametrize("name,params", SEPARABLE)
def test_reciprocal_and_separable(name, params, rng, random_hemisphere):
    model = brdfkit.model(name, **params)
    wi = random_hemisphere(rng, 300)
    wo = random_hemisphere(rng, 300)
    np.testing.assert_allclose(model.eval(wi, wo), model.eval(wo, wi), rtol=1e-13)
    # separable: f(S, V) f(S', V') = f(S, V') f(S', V)
    wi2 = wi[::-1]
    wo2 = wo[::-1]
    np.testing.assert_allclose(model.eval(wi, wo) * model.eval(wi2, wo2),
                               model.eval(wi, wo2) * model.eval(wi2, wo), rtol=1e-11)


@pytest.mark.parametrize("name,params", SEPARABLE)
def test_separable_no_azimuth_dependence(name, params):
    model = brdfkit.model(name, **params)
    wi = spherical_to_cartesian(0.6, 0.0)
    vals = model.eval(wi, spherical_to_cartesian(0.9, np.linspace(0, 2 * np.pi, 13)))
    np.testing.assert_allclose(vals, vals[0], rtol=1e-14)


@pytest.mark.parametrize("name,params", SEPARABLE)
def test_horizon(name, params):
    model = brdfkit.model(name, **params)
    up = spherical_to_cartesian(0.3, 0.0)
    below = np.array([0.2, 0.0, -0.98])
    horizon = np.array([1.0, 0.0, 0.0])
    near = np.array([[math.sqrt(1 - 1e-300**2), 0.0, 1e-300], [1.0, 0.0, 5e-324]])
    assert model.eval(below, up) == 0.0 and model.eval(up, below) == 0.0
    assert model.eval(horizon, up) == 0.0 and model.eval(horizon, horizon) == 0.0
    v = model.eval(near, near[::-1])
    assert np.all(np.isfinite(v)) and np.all(v >= 0.0)
    v = model.eval(near, up)
    assert np.all(np.isfinite(v)) and np.all(v >= 0.0)


def test_minnaert_k_below_one_grows_toward_horizon():
    # k < 1: (N.S N.V)^{k-1} grows without bound as N.V -> 0 (finite but large near 90 deg).
    model = brdfkit.model("minnaert", b_M=0.1, k=0.5)
    vals = model.eval(NORMAL, spherical_to_cartesian(np.array([0.0, 1.0, 1.5, 1.5707]), 0.0))
    assert np.all(np.diff(vals) > 0)


def test_colour_broadcasting():
    model = brdfkit.model("neumann-neumann", b_N=[0.1, 0.2, 0.3], s=0.5)
    wi = spherical_to_cartesian(np.array([0.1, 0.5]), 0.0)[:, None, :]  # (2, 1, 3)
    wo = spherical_to_cartesian(np.array([0.2, 0.4, 0.6]), 1.0)  # (3, 3)
    out = model.eval(wi, wo)
    assert out.shape == (2, 3, 3)
    grey = brdfkit.model("neumann-neumann", b_N=1.0, s=0.5).eval(wi, wo)
    np.testing.assert_allclose(out, grey[..., None] * np.array([0.1, 0.2, 0.3]), rtol=1e-14)
    m = brdfkit.model("minnaert-energy-conserving", k_rho=[0.2, 0.4], k=2.0)
    assert m.eval(NORMAL, NORMAL).shape == (2,)


def test_parameter_errors():
    with pytest.raises(ParameterError, match=r"'s' must lie in \[0, 1e\+07\]; got -1"):
        brdfkit.model("neumann-neumann", s=-1.0)
    with pytest.raises(ParameterError, match=r"'k' must lie in \(0, 1e\+07\]; got 0"):
        brdfkit.model("minnaert", k=0.0)
    with pytest.raises(ParameterError, match=r"'k_rho' must lie in \[0, 1\]; got 1.5"):
        brdfkit.model("minnaert-energy-conserving", k_rho=1.5)
    with pytest.raises(ParameterError, match="beta"):
        brdfkit.model("minnaert", beta=2.0)
    with pytest.raises(ParameterError, match="unknown parameter 'n'"):
        brdfkit.model("minnaert", n=3.0)


def test_lobe_hints():
    (lobe,) = brdfkit.model("minnaert", beta=0.4).lobes()
    assert lobe.kind == "normal" and lobe.width == pytest.approx(0.4, rel=1e-12)
    (lobe,) = brdfkit.model("neumann-neumann", beta=0.25).lobes()
    assert lobe.width == pytest.approx(0.25, rel=1e-12)
    (lobe,) = brdfkit.model("minnaert", k=0.7).lobes()  # no peak at the normal: broad
    assert lobe.width == pytest.approx(math.pi / 2)
