"""Fresnel reflectance (brdfkit.fresnel) against textbook closed forms.

References (independent of the code under test):
- Normal incidence R = ((n1 - n2)/(n1 + n2))^2, and for a complex index
  ((n-1)^2 + k^2)/((n+1)^2 + k^2): Born & Wolf, *Principles of Optics*, §1.5.2
  and §14.2; Hecht, *Optics*, §4.6.
- The s/p amplitude coefficients from Snell's law,
  r_s = (cos i - n cos t)/(cos i + n cos t), r_p = (n cos i - cos t)/(n cos i + cos t),
  R = (|r_s|^2 + |r_p|^2)/2: Hecht §4.6 (Fresnel equations), written out below
  with sin t = sin i / n.
- Schlick 1994 eq. (24): F(1) = F0 (normal incidence) and F(0) = 1.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from brdfkit.fresnel import f0_from_eta, fresnel_conductor, fresnel_dielectric, fresnel_schlick

ETAS = [1.0001, 1.33, 1.5, 2.4, 4.0]


def snell_reflectance(cos_i: np.ndarray, n: complex) -> np.ndarray:
    """Unpolarised R from the s/p amplitudes, with the transmission angle from Snell's law."""
    cos_i = np.asarray(cos_i, dtype=np.float64)
    sin_i = np.sqrt(1.0 - cos_i**2)
    sin_t = sin_i / n
    cos_t = np.sqrt(1.0 - sin_t**2 + 0j)
    rs = (cos_i - n * cos_t) / (cos_i + n * cos_t)
    rp = (n * cos_i - cos_t) / (n * cos_i + cos_t)
    return 0.5 * (np.abs(rs) ** 2 + np.abs(rp) ** 2)


@pytest.mark.parametrize("eta", ETAS)
def test_normal_incidence(eta):
    expected = ((eta - 1.0) / (eta + 1.0)) ** 2
    assert fresnel_dielectric(1.0, eta) == pytest.approx(expected, rel=1e-12)
    assert f0_from_eta(eta) == pytest.approx(expected, rel=1e-14)


@pytest.mark.parametrize("eta", ETAS)
def test_grazing_is_total(eta):
    assert fresnel_dielectric(0.0, eta) == pytest.approx(1.0, abs=1e-12)
    assert fresnel_conductor(0.0, eta, 0.7) == pytest.approx(1.0, abs=1e-12)
    # and approaches it continuously
    assert fresnel_dielectric(1e-9, eta) == pytest.approx(1.0, abs=1e-5)


@pytest.mark.parametrize("eta", ETAS)
def test_dielectric_matches_snell_amplitudes(eta):
    cos_i = np.linspace(0.001, 1.0, 400)
    np.testing.assert_allclose(fresnel_dielectric(cos_i, eta), snell_reflectance(cos_i, eta),
                               rtol=1e-10, atol=1e-14)


@pytest.mark.parametrize("eta,k", [(0.2, 3.9), (1.1, 2.2), (2.5, 0.3), (0.05, 1.0)])
def test_conductor_matches_snell_amplitudes(eta, k):
    cos_i = np.linspace(0.001, 1.0, 400)
    np.testing.assert_allclose(fresnel_conductor(cos_i, eta, k),
                               snell_reflectance(cos_i, complex(eta, k)), rtol=1e-9, atol=1e-14)


@pytest.mark.parametrize("eta", ETAS)
def test_conductor_at_zero_extinction_is_dielectric(eta):
    cos_i = np.linspace(0.0, 1.0, 101)
    np.testing.assert_allclose(fresnel_conductor(cos_i, eta, 0.0), fresnel_dielectric(cos_i, eta),
                               rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("n,k", [(0.2, 3.9), (1.1, 2.2), (2.9, 3.0), (0.05, 4.2)])
def test_conductor_normal_incidence(n, k):
    expected = ((n - 1.0) ** 2 + k**2) / ((n + 1.0) ** 2 + k**2)
    assert fresnel_conductor(1.0, n, k) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("f0", [0.0, 0.04, 0.5, 1.0])
def test_schlick_end_points(f0):
    assert fresnel_schlick(1.0, f0) == pytest.approx(f0, abs=1e-15)
    assert fresnel_schlick(0.0, f0) == pytest.approx(1.0, abs=1e-15)


def test_schlick_between_f0_and_one_and_monotone():
    # From the formula F0 + (1 - F0)(1 - c)^5: F0 <= F <= 1, decreasing in c.
    cos_i = np.linspace(0.0, 1.0, 201)
    f = fresnel_schlick(cos_i, 0.04)
    assert np.all((f >= 0.04 - 1e-15) & (f <= 1.0 + 1e-15))
    assert np.all(np.diff(f) <= 1e-15)


@pytest.mark.parametrize("eta", [1 / 1.33, 1 / 1.5, 0.4])
def test_total_internal_reflection(eta):
    # eta < 1 (dense -> thin): total reflection past the critical angle sin c = eta.
    crit = math.asin(eta)
    beyond = np.cos(np.linspace(crit + 1e-6, math.pi / 2, 50))
    np.testing.assert_allclose(fresnel_dielectric(beyond, eta), 1.0, atol=1e-12)
    before = np.cos(np.linspace(0.0, crit - 1e-3, 50))
    r = fresnel_dielectric(before, eta)
    assert np.all(r < 1.0)
    np.testing.assert_allclose(r, snell_reflectance(before, eta), rtol=1e-9, atol=1e-14)


def test_monotone_for_dielectric_above_brewster_free_unpolarised():
    # Unpolarised R of a dielectric (eta > 1) increases monotonically from normal to grazing.
    theta = np.linspace(0.0, math.pi / 2, 500)
    r = fresnel_dielectric(np.cos(theta), 1.5)
    assert np.all(np.diff(r) > -1e-15)


def test_broadcasting_and_no_mutation():
    cos_i = np.array([[0.2], [0.9]])
    eta = np.array([1.3, 1.5, 1.7])
    before = cos_i.copy()
    out = fresnel_dielectric(cos_i, eta)
    assert out.shape == (2, 3)
    np.testing.assert_array_equal(cos_i, before)
    np.testing.assert_allclose(out[1], snell_reflectance(0.9, eta), rtol=1e-10)


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan")])
def test_bad_index(bad):
    with pytest.raises(ValueError, match="eta"):
        fresnel_dielectric(0.5, bad)
    with pytest.raises(ValueError, match="k"):
        fresnel_conductor(0.5, 1.5, -0.1)
    with pytest.raises(ValueError, match="f0"):
        fresnel_schlick(0.5, 1.5)


def test_one_dielectric_formula_serves_every_kernel():
    # Review finding: nielsen, torrance-sparrow/cook-torrance and the ABC surrogate each
    # carried a copy of the dielectric formula. Every formula with a dielectric Fresnel now
    # calls brdfkit.fresnel's, and no other registered formula has its code (a copy under
    # any name compiles to the same bytecode and constants).
    from brdfkit import _dual, fresnel
    from brdfkit.data import surrogate_formulas
    from brdfkit.models import grazing, vgroove

    one = fresnel._fresnel_dielectric_py
    for kernel in (grazing.nielsen, vgroove.torrance_sparrow, vgroove.cook_torrance,
                   surrogate_formulas.abc_formula):
        assert kernel.py_func.__globals__["fresnel_dielectric"] is fresnel._fresnel_dielectric
    copies = [f"{f.__module__}.{f.__qualname__}" for f in _dual._FORMULAS
              if f is not one and f.__code__.co_code == one.__code__.co_code
              and f.__code__.co_consts == one.__code__.co_consts]
    assert not copies, copies


@pytest.mark.parametrize("eta", [0.67, *ETAS])
def test_dielectric_formula_per_value_is_the_closed_form(eta):
    # the scalar formula the kernels inline (compiled alone), total internal reflection
    # (η < 1) included, against the Snell amplitudes of the module docstring
    from brdfkit.fresnel import _fresnel_dielectric

    cos_i = np.linspace(0.0, 1.0, 41)
    got = np.array([_fresnel_dielectric(c, eta) for c in cos_i])
    np.testing.assert_allclose(got, snell_reflectance(cos_i, eta), rtol=1e-12, atol=1e-14)
