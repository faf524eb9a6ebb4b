"""χ² goodness-of-fit of every model's sampler against its pdf (:mod:`brdfkit.analysis.chi2`).

Every registered model × each of its ``examples`` × θ_o ∈ {0°, 30°, 60°, 80°,
85°, 89°} (azimuth 23°, so no symmetry of the frame helps). The reference is
the model's own ``pdf``, integrated over each bin by quadrature; the overall
significance of the run is α = 0.01, split over all tests here by the Šidák
correction. Models without a dedicated sampler are tested through the base
class's cosine fallback.

The strategies of :mod:`brdfkit.models.sampling` are also tested alone: every
one mixed (with per-wo weights) into one sampler, their normalisation, and the
half-vector distributions against the microfacet samplers they will replace.

Tests of the test: a modified-Phong pdf whose normalisation uses n+2 instead of
n+1, a sampler drawing cosⁿ⁺¹ while the pdf claims cosⁿ, a sampler that
returns pdf 0 for samples with f > 0, and one that never visits half the
hemisphere must all FAIL.

``BRDFKIT_CHI2_SAMPLES`` overrides the sample count (default 200 000).
"""

from __future__ import annotations

import math
import os
import zlib

import numpy as np
import pytest

import brdfkit
from brdfkit.analysis.chi2 import SphereBinning, chi2_test, sidak_alpha
from brdfkit.geometry import pdf_cosine_hemisphere, reflect, sample_cosine_hemisphere
from brdfkit.models import Lobe
from brdfkit.models.diffuse import Lambert
from brdfkit.models.microfacet_distributions import GGX as GGXHalf
from brdfkit.models.microfacet_distributions import Beckmann as BeckmannHalf
from brdfkit.models.phong import ModifiedPhong, pdf_phong_lobe, sample_phong_lobe
from brdfkit.models.sampling import (
    COSINE,
    CosPowerAxis,
    CosPowerNormal,
    HalfVector,
    Mixture,
    PowerHalf,
    StrategySampled,
    blinn_lobe,
    phong_lobe,
)

THETAS_DEG = (0.0, 30.0, 60.0, 80.0, 85.0, 89.0)
PHI_O = math.radians(23.0)
N_SAMPLES = int(os.environ.get("BRDFKIT_CHI2_SAMPLES", "200000"))
ALPHA = 0.01

CASES = [
    pytest.param(cls, ex, th, id=f"{name}-ex{i}-{th:g}deg")
    for name, cls in brdfkit.MODELS.items()
    for i, ex in enumerate(cls.examples)
    for th in THETAS_DEG
]
N_TESTS = len(CASES)


def wo_at(theta_deg: float) -> np.ndarray:
    t = math.radians(theta_deg)
    return np.array([math.sin(t) * math.cos(PHI_O), math.sin(t) * math.sin(PHI_O), math.cos(t)])


def seed_for(*parts) -> int:
    return zlib.crc32(repr(parts).encode())


@pytest.mark.parametrize("cls,ex,theta", CASES)
def test_sampler_matches_pdf(cls, ex, theta):
    m = cls(**ex)
    r = chi2_test(m, wo_at(theta), n_samples=N_SAMPLES, seed=seed_for(cls.name, ex, theta),
                  alpha=ALPHA, n_tests=N_TESTS)
    assert r.passed, f"{cls.name} {ex} θo={theta}°: {r.message}"
    assert r.pdf_integral <= 1.0 + 1e-3
    # the fine grid must really be used (a sanity check on the binning, not the model)
    assert r.dof >= 50, r.dof


# --------------------------------------------------------------------------- the machinery
def test_sidak():
    # 1 − (1 − α)^(1/m): for m = 1 it is α; for m tests the family-wise level is α again.
    assert sidak_alpha(0.01, 1) == pytest.approx(0.01)
    a = sidak_alpha(0.01, 500)
    assert 1.0 - (1.0 - a) ** 500 == pytest.approx(0.01, rel=1e-12)


def test_binning_covers_the_sphere_and_integrates_known_densities():
    # ∫ of the uniform density 1/4π over all bins is 1; of cos⁺θ/π it is 1 (closed forms).
    b = SphereBinning(np.array([0.3, -0.2, 0.9]), 0.05, 40, 32)
    uni, _ = b.integrate(lambda w: np.full(w.shape[:-1], 1.0 / (4.0 * math.pi)))
    assert uni.sum() == pytest.approx(1.0, abs=1e-9)
    cos, _ = b.integrate(lambda w: np.maximum(w[..., 2], 0.0) / math.pi,
                         must_refine=b.straddles_horizon, force_depth=6)
    assert cos.sum() == pytest.approx(1.0, abs=2e-6)
    # every direction falls in exactly one bin, and bin indices are in range
    rng = np.random.default_rng(3)
    w = rng.normal(size=(10000, 3))
    w /= np.linalg.norm(w, axis=-1, keepdims=True)
    assert b.histogram(w).sum() == 10000
    # a sharp Phong lobe about the axis integrates to 1 (its closed-form normalisation)
    n = 5000.0
    lobe, unresolved = b.integrate(lambda w: pdf_phong_lobe(w @ b.axis, n))
    assert lobe.sum() == pytest.approx(1.0, abs=1e-6) and unresolved == 0


def test_resolution_follows_lobe_width():
    # Bins next to the axis are a small fraction of the lobe width.
    for width in (0.5, 0.05, 0.005):
        edges = SphereBinning(np.array([0.0, 0.0, 1.0]), width).theta_edges()
        assert edges[1] < width / 5
        assert edges[-1] == pytest.approx(math.pi)


# --------------------------------------------------------------------------- tests of the test
class WrongNormalisation(ModifiedPhong):
    """pdf with (n+2)/2π instead of the sampled lobe's (n+1)/2π."""

    def pdf(self, wi, wo):
        v = self._values
        p_d = 0.5
        cos_a = np.sum(np.asarray(wi) * reflect(wo), axis=-1)
        lobe = (v["n"] + 2.0) / (2.0 * np.pi) * np.maximum(cos_a, 0.0) ** v["n"]
        p = p_d * pdf_cosine_hemisphere(wi) + (1.0 - p_d) * lobe
        return np.where(np.asarray(wo)[..., 2] > 0.0, p, 0.0)

    def sample(self, wo, u):
        u = np.asarray(u, dtype=np.float64)
        wo = np.asarray(wo, dtype=np.float64)
        diffuse = u[..., 0] < 0.5
        u2 = np.stack([np.where(diffuse, 2 * u[..., 0], 2 * u[..., 0] - 1.0), u[..., 1]], -1)
        u2 = np.clip(u2, 0.0, 1.0)
        wi = np.where(diffuse[..., None], sample_cosine_hemisphere(u2),
                      sample_phong_lobe(np.broadcast_to(reflect(wo), u2.shape[:-1] + (3,)),
                                        self._values["n"], u2))
        return wi, self.pdf(wi, wo)


class WrongExponent(ModifiedPhong):
    """Samples the lobe cosⁿ⁺¹ while pdf claims cosⁿ (pdf() and sample() agree with each other)."""

    def sample(self, wo, u):
        wo = np.asarray(wo, dtype=np.float64)
        wi = sample_phong_lobe(np.broadcast_to(reflect(wo), np.shape(u)[:-1] + (3,)),
                               self._values["n"] + 1.0, np.asarray(u))
        return wi, self.pdf(wi, wo)

    def pdf(self, wi, wo):
        cos_a = np.sum(np.asarray(wi) * reflect(wo), axis=-1)
        return pdf_phong_lobe(cos_a, self._values["n"])


class DropsSamples(ModifiedPhong):
    """Returns pdf 0 for a third of the samples although f > 0 there."""

    def sample(self, wo, u):
        wi, p = super().sample(wo, u)
        return wi, np.where(np.asarray(u)[..., 1] < 1 / 3, 0.0, p)


class HalfSupport(ModifiedPhong):
    """Cosine sampler confined to y ≥ 0 with a matching pdf: χ²-consistent, support missing."""

    def sample(self, wo, u):
        wi = sample_cosine_hemisphere(np.asarray(u))
        wi[..., 1] = np.abs(wi[..., 1])
        return wi, self.pdf(wi, wo)

    def pdf(self, wi, wo):
        wi = np.asarray(wi)
        return np.where(wi[..., 1] >= 0.0, 2.0 * pdf_cosine_hemisphere(wi), 0.0)


@pytest.mark.parametrize("theta", [0.0, 30.0, 60.0])
def test_wrong_normalisation_fails(theta):
    m = WrongNormalisation(rho_d=0.3, rho_s=0.5, n=20.0)
    r = chi2_test(m, wo_at(theta), n_samples=N_SAMPLES, seed=1, alpha=ALPHA, n_tests=N_TESTS)
    assert not r.passed, r
    assert "chi2" in r.message or "integrates" in r.message


@pytest.mark.parametrize("theta", [0.0, 60.0])
def test_wrong_exponent_fails(theta):
    m = WrongExponent(rho_d=0.0, rho_s=1.0, n=20.0)
    r = chi2_test(m, wo_at(theta), n_samples=N_SAMPLES, seed=2, alpha=ALPHA, n_tests=N_TESTS)
    assert not r.passed and "chi2" in r.message, r
    assert r.p_value < 1e-12


def test_samples_with_pdf_zero_and_positive_f_fail():
    r = chi2_test(DropsSamples(), wo_at(30.0), n_samples=20_000, seed=3)
    assert not r.passed and "pdf 0 but f > 0" in r.message, r.message


def test_missing_support_fails():
    r = chi2_test(HalfSupport(), wo_at(30.0), n_samples=20_000, seed=4)
    assert not r.passed and "pdf is 0 where f > 0" in r.message, r.message


def test_correct_reference_passes():
    # The unmodified parent of the wrong samplers above passes at the same settings.
    r = chi2_test(ModifiedPhong(rho_d=0.3, rho_s=0.5, n=20.0), wo_at(30.0),
                  n_samples=N_SAMPLES, seed=1, alpha=ALPHA, n_tests=N_TESTS)
    assert r.passed, r.message


# --------------------------------------------------------------------------- the strategies
class StrategyMix(StrategySampled, Lambert):
    """Lambert's f with a sampler mixing every strategy of brdfkit.models.sampling, with
    weights that depend on wo: the χ² test checks the mixture's sample() against its pdf()."""

    def lobes(self):
        return [Lobe("half", 0.1)]

    def _strategy(self, wo):
        w_half = 0.2 + 0.3 * wo[..., 2]  # per-wo weights
        w = np.stack([0.2 + 0 * w_half, 0.15 + 0 * w_half, w_half, 0.65 - w_half - 0.0], -1)
        w = w / np.sum(w, axis=-1, keepdims=True)
        return Mixture([COSINE, CosPowerNormal(3.0), HalfVector(GGXHalf(0.2)),
                        Mixture([phong_lobe(40.0), blinn_lobe(200.0),
                                 HalfVector(BeckmannHalf(0.1))], [0.5, 0.3, 0.2])], w)


@pytest.mark.parametrize("theta", [0.0, 45.0, 85.0])
def test_every_strategy_in_a_mixture_passes(theta):
    r = chi2_test(StrategyMix(), wo_at(theta), n_samples=N_SAMPLES, seed=seed_for("mix", theta),
                  alpha=ALPHA, n_tests=N_TESTS)
    assert r.passed, r.message


@pytest.mark.parametrize("strategy", [COSINE, CosPowerNormal(0.5), CosPowerAxis(300.0),
                                      HalfVector(PowerHalf(50.0)), HalfVector(GGXHalf(0.3)),
                                      HalfVector(BeckmannHalf(0.05))], ids=repr)
def test_strategy_densities_integrate_to_one(strategy):
    # Over the whole sphere (directions below the horizon included): each is a density.
    wo = wo_at(60.0)
    b = SphereBinning(reflect(wo), 0.1, 40, 32)
    total, _ = b.integrate(lambda w: strategy.pdf(w, np.broadcast_to(wo, w.shape)),
                           max_depth=5, must_refine=b.straddles_horizon)
    tol = 2e-3 if isinstance(strategy, HalfVector) else 1e-6  # the 1/(4|wo·h|) point at −wo
    assert total.sum() == pytest.approx(1.0, abs=tol)


def test_half_vector_distributions_are_the_microfacet_objects():
    # one set of half-vector distributions: the sampling strategies and the microfacet
    # models use the same objects (microfacet_distributions.distribution)
    from brdfkit.models.microfacet_distributions import distribution

    assert isinstance(distribution("phong", 40.0), PowerHalf)
    u = np.random.default_rng(5).random((5000, 2))
    wo = wo_at(50.0)
    m = brdfkit.model("microfacet", distribution="ggx", alpha=0.3)
    wi, pdf = m.sample(wo, u)
    np.testing.assert_array_equal(wi, HalfVector(GGXHalf(0.3), fold=False).sample(wo, u))
    # the density: D cos θ_h/(4|wo·h|) with GGX's D (Walter eqs. 33, 14), written out here
    h = (wi + wo) / np.linalg.norm(wi + wo, axis=-1, keepdims=True)
    c = h[:, 2]
    t = 0.3**2 * c * c + (1.0 - c * c)
    expected = np.where(c > 0.0, 0.3**2 * c / (np.pi * t * t) / (4.0 * np.abs(h @ wo)), 0.0)
    np.testing.assert_allclose(pdf, expected, rtol=1e-9)


def test_mixture_consumes_one_uniform_pair_per_sample():
    # A one-component mixture draws exactly what the component draws from the same u, and
    # the modified-Phong sampler is the mixture of the cosine and the lobe (diffuse first).
    wo = wo_at(30.0)
    u = np.random.default_rng(6).random((4000, 2))
    lobe = phong_lobe(25.0)
    np.testing.assert_array_equal(Mixture([lobe], [1.0]).sample(wo, u), lobe.sample(wo, u))
    m = ModifiedPhong(rho_d=0.3, rho_s=0.3, n=25.0)  # p_d = 1/2
    wi, _ = m.sample(wo, u)
    first = u[:, 0] < 0.5
    ud = np.stack([2.0 * u[first, 0], u[first, 1]], -1)
    us = np.stack([2.0 * u[~first, 0] - 1.0, u[~first, 1]], -1)
    np.testing.assert_allclose(wi[first], COSINE.sample(wo, ud), rtol=1e-12)
    np.testing.assert_allclose(wi[~first], lobe.sample(wo, us), rtol=1e-12, atol=1e-15)
    # exponent 0: the lobe is constant, sampled by the cosine (the pdf integrates to 1)
    assert phong_lobe(0.0) is COSINE and blinn_lobe(0.0) is COSINE
