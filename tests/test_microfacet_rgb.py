"""The "rgb" kernels of ``microfacet`` and ``microfacet-anisotropic`` (issue 22 §5).

With three channels ``model.eval`` runs the ``"rgb"`` loop of ``models/_drivers.py``: D and
both G₁ once per pair (``walter_terms``/``walter_anisotropic_terms``) and each channel's
Fresnel factor and scale (``walter_channel``). The albedo engine, pumping, compensation and
the Mitsuba bridge run the per-channel kernel (``model.kernel``, one packed row per call).
Reference: that per-channel kernel in the checked loop (one pair, one channel per call),
which must agree bit for bit — the same operations in the same order — on random pairs and
on the edge cases (below the horizon, grazing, ω_i = −ω_o and the rescaled short
s = ω_i + ω_o, a GGX α whose 1/α² overflows, non-finite and non-unit directions: NaN rows).
The values themselves are checked against second implementations elsewhere
(``tests/test_microfacet_anisotropic.py::test_against_the_angles_form``,
``tests/test_fast_kernels.py``, ``tests/test_mitsuba_crosscheck.py``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import brdfkit
from brdfkit.models import microfacet as iso
from brdfkit.models import microfacet_anisotropic as aniso
from brdfkit.models._drivers import loop_driver

ETA, K = [0.2, 0.9, 1.1], [3.9, 2.4, 2.2]  # gold-like conductor, as the benchmarks
COLOURS = [
    {"eta": ETA, "k": K},                                   # RGB conductor
    {"eta": [1.5, 1.4, 1.3], "rho_s": [0.2, 0.7, 1.0]},     # RGB dielectric Fresnel, scale
    {"eta": 1.5, "k": [0.0, 1.0, 3.0]},                      # one η, three κ
    {"rho_s": [0.3, 0.6, 0.9]},                              # F = 1, coloured scale
]
SHAPES = {
    "microfacet": [{"alpha": 0.3}, {"alpha": 1e-8}, {"alpha": 2.5}],
    "microfacet-anisotropic": [{"alpha_x": 0.1, "alpha_y": 0.4}, {"alpha_x": 1e-4,
                                                                  "alpha_y": 4.0}],
}
CASES = [(name, dist, shape, colour) for name, shapes in SHAPES.items()
         for dist in ("ggx", "beckmann") for shape in shapes for colour in COLOURS]


def directions(rng, n):
    """n random unit vectors on the sphere (a third below the horizon), then edge cases."""
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    v[: 2 * n // 3, 2] = np.abs(v[: 2 * n // 3, 2])
    return v


def pairs(rng, n=6000):
    wi, wo = directions(rng, n), directions(rng, n)
    wo[: n // 4] = wi[: n // 4] * [-1.0, -1.0, 1.0] + rng.normal(scale=0.02, size=(n // 4, 3))
    wo[: n // 4] /= np.linalg.norm(wo[: n // 4], axis=-1, keepdims=True)  # near the mirror
    g = math.sqrt(1.0 - 1e-300)
    edge_i = [[g, 0.0, 1e-150], [1.0, 0.0, 0.0], [0.6, 0.0, 0.8], [0.0, 0.0, 1.0],
              [0.0, 0.6, 0.8], [math.nan, 0.0, 1.0], [0.0, 0.0, 2.0], [0.0, 0.0, 1.0]]
    edge_o = [[-g, 0.0, 1e-150], [-1.0, 0.0, 0.0], [-0.6, 0.0, 0.8], [0.0, 0.0, 1.0],
              [0.0, -0.6, -0.8], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, math.inf, 0.0]]
    return np.concatenate([wi, edge_i]), np.concatenate([wo, edge_o])


def per_channel(model, wi, wo):
    """model.kernel per pair and channel (the checked loop), NaN for rejected pairs."""
    out = np.empty((wi.shape[0], model.packed.shape[0]))
    loop_driver(model.kernel, loop="checked")(wi, wo, model.packed.copy(), out)
    return out


@pytest.mark.parametrize("name,dist,shape,colour", CASES)
def test_rgb_loop_is_the_per_channel_kernel(name, dist, shape, colour):
    m = brdfkit.model(name, distribution=dist, **shape, **colour)
    assert m.n_channels == 3
    table, n_packed = ((aniso._RGB_KERNELS, aniso.N_PACKED) if name != "microfacet"
                       else (iso._WALTER_RGB, iso.N_PACKED))
    key = (dist == "ggx", "eta" in colour)
    # the rgb loop is the one eval runs (else this test would compare a loop with itself)
    assert m._driver is loop_driver(table[key], loop="rgb", width=3 * n_packed)
    rng = np.random.default_rng(22)
    wi, wo = pairs(rng)
    with np.errstate(invalid="ignore"):
        got = np.asarray(m.eval(wi[:-3], wo[:-3]))  # eval raises on bad directions
    want = per_channel(m, wi, wo)
    # the lobe was hit (a near-mirror Beckmann lobe only by the pair at the mirror)
    assert np.count_nonzero(want[:-3] > 0.0) > (0 if min(shape.values()) < 1e-3 else 3000)
    assert np.array_equal(got, want[:-3])  # bit for bit, zeros and all
    # the rejected pairs (NaN, non-unit, inf) are NaN rows in both loops
    out = np.empty((wi.shape[0], 3))
    n_bad = m._driver(wi, wo, m.packed.copy(), out)
    assert n_bad == 3 and np.isnan(out[-3:]).all()
    assert np.array_equal(out, want, equal_nan=True)


@pytest.mark.parametrize("name", ["microfacet", "microfacet-anisotropic"])
@pytest.mark.parametrize("channels", [1, 2, 4])
def test_other_channel_counts_keep_the_vector_loop(name, channels):
    # the rgb loop is for three channels only; others run the per-channel vector loop
    m = brdfkit.model(name, distribution="ggx", eta=[1.2 + 0.1 * c for c in range(channels)],
                      k=[0.5 * c for c in range(channels)])
    kernel = m._kernel() if name != "microfacet" else iso._WALTER_KERNELS[(True, True)]
    assert m._driver is loop_driver(kernel, loop="vector")
    wi, wo = pairs(np.random.default_rng(5), 2000)
    got = np.asarray(m.eval(wi[:-3], wo[:-3])).reshape(len(wi) - 3, -1)
    assert np.array_equal(got, per_channel(m, wi, wo)[:-3])
