"""Geometry of the local frame (brdfkit.geometry).

References: the definitions themselves (spherical coordinates, mirror
reflection R = 2n(n.v) - v, the bisector), Rusinkiewicz 1998 §3 (the half
vector maps to the pole; the construction is invertible), and the closed-form
moments of the hemisphere densities: for pdf cos(theta)/pi,
E[cos theta] = int cos^2 theta / pi dw = 2/3; for the uniform density 1/(2 pi),
E[cos theta] = 1/2 and E[cos^2 theta] = 1/3.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from brdfkit.errors import BrdfkitError
from brdfkit.geometry import (
    cartesian_to_spherical,
    frame_around,
    from_rusinkiewicz,
    half_vector,
    pdf_cosine_hemisphere,
    pdf_uniform_hemisphere,
    reflect,
    sample_cosine_hemisphere,
    sample_uniform_hemisphere,
    spherical_to_cartesian,
    to_rusinkiewicz,
)


def test_spherical_round_trip(rng):
    theta = rng.uniform(0.0, math.pi, 1000)
    phi = rng.uniform(-math.pi, math.pi, 1000)
    v = spherical_to_cartesian(theta, phi)
    np.testing.assert_allclose(np.linalg.norm(v, axis=-1), 1.0, rtol=1e-14)
    t2, p2 = cartesian_to_spherical(v)
    np.testing.assert_allclose(t2, theta, atol=1e-12)
    np.testing.assert_allclose(np.cos(p2 - phi), 1.0, atol=1e-12)


def test_spherical_poles_and_horizon():
    t, _ = cartesian_to_spherical(np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]))
    np.testing.assert_allclose(t, [0.0, math.pi], atol=0)
    # near the pole theta keeps its digits (arctan2 form): theta = 1e-9 exactly recovered
    v = spherical_to_cartesian(1e-9, 0.3)
    assert cartesian_to_spherical(v)[0] == pytest.approx(1e-9, rel=1e-12)
    v = spherical_to_cartesian(math.pi / 2, 1.0)
    assert v[2] == pytest.approx(0.0, abs=1e-16)
    assert cartesian_to_spherical(v)[0] == pytest.approx(math.pi / 2, abs=1e-15)


def test_reflect(rng, random_hemisphere):
    v = random_hemisphere(rng, 500)
    r = reflect(v)
    n = np.array([0.0, 0.0, 1.0])
    expected = 2.0 * (v @ n)[:, None] * n - v  # R = 2 n (n.v) - v
    np.testing.assert_allclose(r, expected, atol=1e-15)
    np.testing.assert_allclose(reflect(r), v, atol=1e-15)  # an involution
    before = v.copy()
    reflect(v)
    np.testing.assert_array_equal(v, before)  # no mutation


def test_half_vector(rng, random_hemisphere):
    wi = random_hemisphere(rng, 500)
    wo = random_hemisphere(rng, 500)
    h = half_vector(wi, wo)
    np.testing.assert_allclose(np.linalg.norm(h, axis=-1), 1.0, rtol=1e-14)
    # bisector: equal angles to wi and wo
    np.testing.assert_allclose(np.sum(h * wi, -1), np.sum(h * wo, -1), atol=1e-14)
    # the mirror of wi about h is wo
    np.testing.assert_allclose(2.0 * np.sum(h * wi, -1)[:, None] * h - wi, wo, atol=1e-13)


def test_half_vector_degenerate():
    v = np.array([0.3, -0.4, math.sqrt(1 - 0.25)])
    h = half_vector(v, -v)  # undefined bisector: the normal is returned, no NaN
    np.testing.assert_array_equal(h, [0.0, 0.0, 1.0])
    h = half_vector(np.array([1.0, 0.0, 0.0]), np.array([-1.0, 0.0, 0.0]))
    assert np.all(np.isfinite(h))


def test_rusinkiewicz_round_trip_random(rng, random_hemisphere):
    wi = random_hemisphere(rng, 2000)
    wo = random_hemisphere(rng, 2000)
    th, ph, td, pd = to_rusinkiewicz(wi, wo)
    assert np.all((th >= 0) & (th <= math.pi / 2 + 1e-12))
    assert np.all((td >= 0) & (td <= math.pi / 2 + 1e-12))
    # theta_h is the angle of the bisector; theta_d the angle between wi and the bisector
    h = half_vector(wi, wo)
    np.testing.assert_allclose(np.cos(th), h[:, 2], atol=1e-12)
    np.testing.assert_allclose(np.cos(td), np.sum(wi * h, -1), atol=1e-12)
    wi2, wo2 = from_rusinkiewicz(th, ph, td, pd)
    np.testing.assert_allclose(wi2, wi, atol=1e-12)
    np.testing.assert_allclose(wo2, wo, atol=1e-12)


@pytest.mark.parametrize(
    "wi,wo",
    [
        ([0.0, 0.0, 1.0], [0.0, 0.0, 1.0]),  # both at the pole
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),  # pole and horizon
        ([1.0, 0.0, 0.0], [-1.0, 0.0, 1e-12]),  # both (almost) at the horizon, mirror pair
        ([0.0, 1.0, 0.0], [0.0, 1.0, 0.0]),  # the same horizon direction
        ([0.6, 0.0, 0.8], [-0.6, 0.0, 0.8]),  # mirror pair: theta_h = 0
    ],
)
def test_rusinkiewicz_round_trip_special(wi, wo):
    wi = np.asarray(wi, float)
    wo = np.asarray(wo, float)
    wi = wi / np.linalg.norm(wi)
    wo = wo / np.linalg.norm(wo)
    angles = to_rusinkiewicz(wi, wo)
    assert all(np.all(np.isfinite(a)) for a in angles)
    wi2, wo2 = from_rusinkiewicz(*angles)
    np.testing.assert_allclose(wi2, wi, atol=1e-9)
    np.testing.assert_allclose(wo2, wo, atol=1e-9)


def test_cosine_sampling_moments(rng):
    w = sample_cosine_hemisphere(rng.random((400_000, 2)))
    np.testing.assert_allclose(np.linalg.norm(w, axis=-1), 1.0, rtol=1e-12)
    assert np.all(w[:, 2] >= 0.0)
    # E[cos] = 2/3 and E[cos^2] = 1/2 (closed forms); the MC standard error is ~ 4e-4.
    assert np.mean(w[:, 2]) == pytest.approx(2.0 / 3.0, abs=2e-3)
    assert np.mean(w[:, 2] ** 2) == pytest.approx(0.5, abs=2e-3)
    # azimuth uniform: E[x] = E[y] = 0
    assert abs(np.mean(w[:, 0])) < 3e-3 and abs(np.mean(w[:, 1])) < 3e-3
    np.testing.assert_allclose(pdf_cosine_hemisphere(w), w[:, 2] / math.pi)


def test_uniform_sampling_moments(rng):
    w = sample_uniform_hemisphere(rng.random((400_000, 2)))
    np.testing.assert_allclose(np.linalg.norm(w, axis=-1), 1.0, rtol=1e-12)
    assert np.mean(w[:, 2]) == pytest.approx(0.5, abs=2e-3)
    assert np.mean(w[:, 2] ** 2) == pytest.approx(1.0 / 3.0, abs=2e-3)
    np.testing.assert_allclose(pdf_uniform_hemisphere(w), 1.0 / (2.0 * math.pi))
    assert pdf_uniform_hemisphere(np.array([0.0, 0.0, -1.0])) == 0.0


def test_sampling_extreme_uniforms():
    u = np.array([[0.0, 0.0], [1.0, 1.0], [1.0, 0.5], [0.0, 0.999]])
    for sampler in (sample_cosine_hemisphere, sample_uniform_hemisphere):
        w = sampler(u)
        assert np.all(np.isfinite(w))
        np.testing.assert_allclose(np.linalg.norm(w, axis=-1), 1.0, rtol=1e-12)


def test_frame_around_is_orthonormal(rng):
    a = np.concatenate([spherical_to_cartesian(rng.uniform(0, math.pi, 500),
                                               rng.uniform(-math.pi, math.pi, 500)),
                        np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]])])
    t, b, n = frame_around(a)
    for x, y in ((t, b), (t, n), (b, n)):
        np.testing.assert_allclose(np.sum(x * y, -1), 0.0, atol=1e-13)
    for x in (t, b, n):
        np.testing.assert_allclose(np.linalg.norm(x, axis=-1), 1.0, rtol=1e-13)
    np.testing.assert_allclose(np.cross(t, b), n, atol=1e-13)  # right-handed


def test_bad_directions():
    with pytest.raises(BrdfkitError, match=r"shape \(\.\.\., 3\)"):
        reflect(np.zeros((4, 2)))
    with pytest.raises(BrdfkitError, match="NaN"):
        half_vector(np.array([np.nan, 0, 1.0]), np.array([0, 0, 1.0]))
    with pytest.raises(BrdfkitError, match=r"\[0, 1\]"):
        sample_cosine_hemisphere(np.array([[0.5, 1.5]]))
