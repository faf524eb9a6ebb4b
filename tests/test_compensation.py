"""Tests of the energy compensation operators and of the protocol they read.

Reference values: the Fresnel moments against scipy.integrate.quad of the
definition F_avg = 2∫₀¹ F(μ) μ dμ (Kulla & Conty 2017); a model's Fresnel split
against the definition f = F · f_white evaluated pair by pair with
:func:`brdfkit.fresnel.fresnel_conductor` at ω_i·h (Walter 2007 eq. 20).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

import brdfkit
from brdfkit.fresnel import fresnel_conductor, fresnel_moments
from brdfkit.models import FresnelSplit


def _dirs(theta, phi=0.0):
    theta = np.asarray(theta, dtype=float)
    phi = np.broadcast_to(np.asarray(phi, dtype=float), theta.shape)
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi),
                     np.cos(theta)], axis=-1)


def _random_pairs(n, seed):
    rng = np.random.default_rng(seed)
    ti = np.arccos(rng.uniform(0.0, 1.0, n))
    to = np.arccos(rng.uniform(0.0, 1.0, n))
    return _dirs(ti, 0.0), _dirs(to, rng.uniform(0.0, 2 * np.pi, n))


# ================================================================== the Fresnel split protocol
# quad's roundoff warning near 1e-15: its answer agrees with the rule to 1e-13 either way
@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")
@pytest.mark.parametrize("eta,k", [(1.5, 0.0), (0.2, 3.9), (0.7, 0.0), (0.7, 0.01),
                                   (1.0001, 0.0), (50.0, 0.0)])
def test_fresnel_moments_against_quad(eta, k):
    """F_avg = 2∫F μ dμ by adaptive quadrature (split at the critical cosine for η < 1)."""
    f0, f_avg = fresnel_moments(eta, k)
    mu_c = np.sqrt(max(1.0 - eta * eta, 0.0))
    ref = quad(lambda m: 2 * m * fresnel_conductor(m, eta, k), 0.0, 1.0,
               points=[mu_c] if mu_c > 0 else None, epsabs=1e-15, epsrel=1e-14, limit=400)[0]
    assert abs(f_avg[0] - ref) < 1e-12
    assert f0[0] == pytest.approx(float(fresnel_conductor(1.0, eta, k)), abs=1e-15)


def test_default_split_is_none():
    assert brdfkit.model("modified-phong").fresnel_split() is None
    assert brdfkit.model("microfacet", alpha=0.3).fresnel_split() is None  # F = 1, ρ_s = 1


def test_microfacet_split_is_the_definition():
    """f = ρ_s F(ω_i·h) f_white pair by pair; f0 = ρ_s F(1), f_avg = ρ_s · 2∫F μ dμ."""
    eta, k, rho = np.array([0.2, 0.9, 1.1]), np.array([3.9, 2.4, 2.2]), np.array([1, 0.9, 0.8])
    m = brdfkit.model("microfacet", distribution="ggx", alpha=0.3, eta=eta, k=k, rho_s=rho)
    split = m.fresnel_split()
    assert isinstance(split, FresnelSplit)
    assert split.white.fresnel_split() is None
    wi, wo = _random_pairs(2000, 3)
    h = wi + wo
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    cos_d = np.einsum("ij,ij->i", wi, h)[:, None]
    ref = rho * fresnel_conductor(cos_d, eta, k) * split.white.eval(wi, wo)[:, None]
    np.testing.assert_allclose(m.eval(wi, wo), ref, rtol=1e-12, atol=1e-300)
    for c in range(3):
        ref_avg = quad(lambda mu, c=c: 2 * mu * fresnel_conductor(mu, eta[c], k[c]), 0, 1,
                       epsabs=1e-15)[0]
        assert split.f_avg[c] == pytest.approx(rho[c] * ref_avg, abs=1e-12)
        assert split.f0[c] == pytest.approx(rho[c] * fresnel_conductor(1.0, eta[c], k[c]))


@pytest.mark.parametrize("name", ["cook-torrance", "torrance-sparrow"])
def test_dielectric_split(name):
    """The V-groove models: F the dielectric reflectance of η (κ = 0), white with no η."""
    m = brdfkit.model(name, eta=1.5)
    split = m.fresnel_split()
    wi, wo = _random_pairs(500, 4)
    h = wi + wo
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    f = fresnel_conductor(np.einsum("ij,ij->i", wi, h), 1.5, 0.0)
    np.testing.assert_allclose(m.eval(wi, wo), f * split.white.eval(wi, wo), rtol=1e-12)
    assert split.f0[0] == pytest.approx(0.04, abs=1e-15)  # ((1.5 − 1)/(1.5 + 1))²
