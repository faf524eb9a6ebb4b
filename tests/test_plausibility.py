"""Verdicts of every model of Lewis's Table 2 and Neumann's Fig. 1.

Each test states the independent (asymptotic) reason for the verdict it expects,
derived from the model's formula, not from the code's output.
"""

from __future__ import annotations

import json

import numpy as np
from click.testing import CliRunner

import brdfkit
from brdfkit.analysis import check
from brdfkit.analysis.plausibility import divergence_rate
from brdfkit.cli import main


def test_phong_diverges_like_inverse_cosine():
    """Lewis eq. (19): k_ρ = k_d π + k_s H_s(S)/(N·S). H_s → a positive constant as
    θ_i → 90° (the part of the lobe about R above the horizon), so k_ρ ∝ (cos θ_i)^−1: p = 1.
    F_s^P(S,V)/(N·S) ≠ F_s^P(V,S)/(N·V): not reciprocal (Lewis §5.1)."""
    v = check(brdfkit.model("phong", k_d=0.1, k_s=1.0, n=20.0))
    assert v.energy == "diverges" and abs(v.divergence_exponent - 1.0) < 0.02
    assert not v.reciprocal and v.max_scale is None


def test_blinn_diverges_like_inverse_cosine():
    """Blinn: H_s → ∫ (N·H)ⁿ (N·V) dω over the half-space map at grazing, a positive
    constant, so k_ρ ∝ (cos θ_i)^−1 as for Phong (Lewis Fig. 5 right)."""
    v = check(brdfkit.model("blinn", k_d=0.0, k_s=1.0, n=20.0))
    assert v.energy == "diverges" and abs(v.divergence_exponent - 1.0) < 0.02
    assert not v.reciprocal


def test_energy_conserving_phong():
    """Lewis eq. (22): k_ρ = k_ρ[(1−k_σ) + k_σ H_s/H_s] = k_ρ ≤ 1 at every angle by
    construction; the 1/H_s(S) factor is not symmetric in (S, V): not reciprocal (§5.1)."""
    v = check(brdfkit.model("phong-energy-conserving", k_rho=0.8, k_sigma=0.5, n=20.0))
    assert v.energy == "conserves" and abs(v.max_albedo - 0.8) < 1e-6
    assert not v.reciprocal


def test_torrance_sparrow_bounded_and_reciprocal():
    """Lewis §4.2: with G ≤ 2(N·H)(N·S)/(S·H), f (N·V) dω_V = D G (S·H)/(N·S) dω_H/… is
    bounded by 2 D (N·H), so k_ρ stays bounded (Beckmann, F = 1: ≤ 1 since D is a
    normalised distribution of projected area and G ≤ 1). FGD/(π N·S N·V) is symmetric."""
    v = check(brdfkit.model("torrance-sparrow", distribution="beckmann", m=0.1))
    assert v.reciprocal and v.energy == "conserves"
    assert v.max_albedo <= 1.0 + 1e-6


def test_neumann_neumann_conserves_and_peaks_at_normal():
    """f = b_N exp{−s(1/N·S + 1/N·V − 2)} ≤ b_N: k_ρ ≤ π b_N < 1 for b_N = 0.25; the V
    dependence exp(−s/N·V) is maximal at V = N for every S (Lewis §3.3 objection)."""
    v = check(brdfkit.model("neumann-neumann", b_N=0.25, s=0.5))
    assert v.reciprocal and v.energy == "conserves" and v.peaks_at_normal


def test_minnaert_conserves_and_peaks_at_normal():
    """k_ρ = b_M (N·S)^{k−1} 2π/(k+1) ≤ 2π b_M/(k+1) for k ≥ 1 (= 0.42 for b_M = 0.2, k = 2);
    (N·V)^{k−1} peaks at V = N (Lewis §3.4)."""
    v = check(brdfkit.model("minnaert", b_M=0.2, k=2.0))
    assert v.reciprocal and v.energy == "conserves" and v.peaks_at_normal
    assert abs(v.max_albedo - 2 * np.pi * 0.2 / 3) < 1e-6


def test_minnaert_below_one_diverges_with_rate():
    """k < 1: k_ρ ∝ (N·S)^{k−1} = (cos θ_i)^{−(1−k)}: diverges with p = 1 − k = 0.3."""
    v = check(brdfkit.model("minnaert", b_M=0.2, k=0.7))
    assert v.energy == "diverges" and abs(v.divergence_exponent - 0.3) < 0.01


def test_reciprocal_phong_blinn_bounded():
    """Lewis eq. (24): f = k_d + k_s (N·H)ⁿ ≤ k_d + k_s, so k_ρ ≤ π (k_d + k_s): bounded;
    symmetric in (S, V). With k_s = 1 it exceeds 1 at normal incidence and max_scale =
    1/max k_ρ makes it conserve (Lewis §6)."""
    v = check(brdfkit.model("phong-blinn-reciprocal", k_d=0.1, k_s=1.0, n=20.0))
    assert v.reciprocal and v.energy == "exceeds"
    assert abs(v.max_scale * v.max_albedo - 1.0) < 1e-12
    scaled = check(brdfkit.model("phong-blinn-reciprocal", k_d=0.1 * v.max_scale * 0.999,
                                 k_s=v.max_scale * 0.999, n=20.0))
    assert scaled.energy == "conserves"


def test_ward_diverges_like_inverse_sqrt():
    """Neumann eq. (8): with dω_V = 4(V·H) dω_H, a = (N·L)^−½ ∫ D √(N·V) 4(L·H) dω_H/(4π m²)
    and the integral tends to a positive constant (half the H-lobe keeps V above the
    horizon): p = 1/2, as Neumann §2.1 (eq. 14) argues."""
    v = check(brdfkit.model("ward", rho_d=0.0, rho_s=1.0, m=0.1))
    assert v.energy == "diverges" and abs(v.divergence_exponent - 0.5) < 0.02


def test_cook_torrance_bounded_contrary_to_neumann():
    """Neumann §2.1 (eq. 15) claims a ∝ (N·L)^−1, assuming G = 1 on a fixed 'critical
    region'. But G ≤ 2(N·H)(N·L)/(L·H), so a = ∫ D G (L·H)/(N·L) dω_H ≤ ∫ 2 D (N·H) dω_H = 2:
    bounded. The G = 1 region {L·H ≤ 2(N·H)(N·L)} shrinks with N·L. In the limit
    G → 2(N·H)(N·L)/(L·H) on the half of the lobe with V above the horizon, giving
    a → ∫_{h_x>0} 2 D (N·H) dω_H = 1."""
    v = check(brdfkit.model("cook-torrance", m=0.1))
    assert v.energy != "diverges" and v.divergence_exponent is None
    assert abs(v.grazing[89.999] - 1.0) < 1e-3
    assert v.reciprocal


def test_neumann_fig1_phong_darkens():
    """Reciprocal normalised Phong n = 150 (Neumann eq. 6): as θ_i → 90° the lobe about R
    is cut in half by the horizon and cos θ_o → O(1/√n) on it, so a → O(n^−½) ≈ 0.03 ≪ 1."""
    v = check(brdfkit.model("modified-phong", rho_d=0.0, rho_s=1.0, n=150.0))
    assert v.energy == "conserves" and v.grazing[89.9] < 0.1
    assert any("dark at grazing" in n for n in v.notes)


def test_neumann_fig1_he_torrance_darkens():
    """He–Torrance (σ₀ = 0.1, τ = 1.7): its shadowing S(θ_i) → 0 at grazing incidence, so
    both the delta and the directional-diffuse terms vanish: a(89.9°) ≪ max a."""
    v = check(brdfkit.model("he-torrance", sigma0=0.1, tau=1.7))
    assert v.energy != "diverges" and v.grazing[89.9] < 0.5 * v.max_albedo


def test_divergence_rate_on_power_law():
    """Slopes of an exact power law a = c (cos θ)^−p are p."""
    th = np.array([89.0, 89.9, 89.99])
    a = 2.0 * np.cos(np.radians(th)) ** -0.7
    assert np.allclose(divergence_rate(a, th), 0.7)


def test_check_cli_json():
    r = CliRunner().invoke(main, ["check", "ward", "-p", "m=0.1", "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.output)
    for key in ("model", "params", "reciprocal", "max_asymmetry", "energy", "max_albedo",
                "theta_max_deg", "divergence_exponent", "max_scale", "notes"):
        assert key in d
    assert d["energy"] == "diverges" and d["model"] == "ward"


def test_check_cli_bad_parameter():
    r = CliRunner().invoke(main, ["check", "ward", "-p", "m=-1"])
    assert r.exit_code == 2
