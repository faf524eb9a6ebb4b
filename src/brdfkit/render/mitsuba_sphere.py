"""
The sphere test configuration by Monte Carlo through Mitsuba 3
==============================================================

Lewis (1993, Fig. 2)'s configuration, as issue 11 §1 states it, rendered by
Mitsuba's path tracer with any brdfkit model as the sphere's BSDF (through
:mod:`brdfkit.render.mitsuba_bridge`):

- the unit sphere at the origin, seen by an orthographic camera from +z
  (V = +z everywhere) whose S×S film covers x, y ∈ [−1, 1] (row r, column c:
  x increases with c, y decreases with r — the direct render's layout);
- a directional emitter of irradiance E travelling along −L, L = (sin Φ_L, 0,
  cos Φ_L) the direction toward the light;
- a constant environment of radiance L_a (the ambient term), hidden from the
  camera (pixels off the sphere are 0, as in the direct render).

The expected value of a pixel is the *pixel-area average* (box filter of
radius ½ pixel) of E·f_r(L, V)·max(N·L, 0) + L_a·ρ(V), ρ(V) = ∫ f_r(L′, V)
cos θ_L′ dω_L′; the direct render evaluates the same at pixel centres. The
two differ by O(pixel²) curvature terms inside the disc and by the partial
coverage of the silhouette pixels. The integrator is Mitsuba's ``path`` with
``max_depth = 2`` (camera vertex + one bounce: all the light of a convex
object under these emitters), with multiple importance sampling of the
emitters and the bridge's sampler.

The Monte-Carlo standard error per pixel (:func:`render_sphere_mitsuba_passes`): the
spp are rendered in K independent passes (seeds K·seed + k), of n_k samples each; the
image is the sample-weighted mean x̄ = Σ n_k x_k / N of the pass images, and, since
Var(x_k) = σ²/n_k for a pixel whose samples have variance σ²,
s² = Σ n_k (x_k − x̄)² / (K − 1) is an unbiased estimate of σ², so the standard error of
the mean is s/√N (K − 1 degrees of freedom). Mitsuba's own ``moment`` integrator gives
per-pixel second moments only in CIE XYZ, whose RGB variances would need the
covariances it does not store; the passes need nothing from Mitsuba. With a box filter
of radius ½ pixel every sample lands in exactly one pixel, so a pass image is the plain
mean of its n_k samples, as the estimate assumes.

Public objects
--------------
- :func:`render_sphere_mitsuba` — the image, linear radiance (S, S, C).
- :func:`render_sphere_mitsuba_passes` — the image of K passes and its per-pixel
  standard error.
- :func:`sphere_scene` — the scene dict (for custom renders and benchmarks).
"""

from __future__ import annotations

import contextlib
import math

import numpy as np

from brdfkit.errors import ParameterError
from brdfkit.models import BRDF
from brdfkit.render.mitsuba_bridge import (
    MITSUBA_MAX_SIZE,
    _mitsuba,
    check_samples,
    check_seed,
    irradiance_spectrum,
    mitsuba_bsdf,
    render_bounded,
    use_variant,
    wavefront,
)

__all__ = ["render_sphere_mitsuba", "render_sphere_mitsuba_passes", "sphere_scene",
           "DEFAULT_PASSES"]

#: Camera distance from the origin along +z (any value > 1 works for an orthographic view).
CAMERA_Z = 3.0
#: Passes of :func:`render_sphere_mitsuba_passes` (fewer when spp is smaller): 8 passes
#: give the standard error with 7 degrees of freedom (its own relative error ~27 %) for
#: ~1.5-2x the time of one pass of all the samples (llvm_ad_rgb, 128², 64 spp).
DEFAULT_PASSES = 8


def sphere_scene(bsdf, *, phi_l: float, irradiance: float = 1.0, ambient: float = 0.0,
                 size: int = 256, variant: str = "llvm_ad_rgb", illuminant: str = "d65",
                 max_depth: int = 2) -> dict:
    """The scene dict of the sphere test configuration with *bsdf* on the sphere.

    *bsdf*: any Mitsuba BSDF object or dict (a bridge object from
    :func:`~brdfkit.render.mitsuba_bridge.mitsuba_bsdf`, or a native one such
    as ``{"type": "roughconductor", …}`` for comparisons). Other parameters as
    :func:`render_sphere_mitsuba`.
    """
    mi, _ = _mitsuba()
    # Mitsuba's orthographic camera maps its film to [-1, 1]² of its local x, y; looking
    # from +z at the origin with up +y, image columns increase with world x and rows
    # decrease with world y (checked in tests/test_render_mitsuba.py with Φ_L = 45°).
    to_world = mi.ScalarTransform4f().look_at(origin=[0.0, 0.0, CAMERA_Z],
                                              target=[0.0, 0.0, 0.0], up=[0.0, 1.0, 0.0])
    light = [math.sin(phi_l), 0.0, math.cos(phi_l)]
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": int(max_depth), "hide_emitters": True},
        "sensor": {
            "type": "orthographic",
            "to_world": to_world,
            "film": {"type": "hdrfilm", "width": int(size), "height": int(size),
                     "rfilter": {"type": "box"},
                     "pixel_format": "luminance" if "mono" in variant else "rgb",
                     "sample_border": False},
            "sampler": {"type": "independent"},
        },
        "sphere": {"type": "sphere", "center": [0.0, 0.0, 0.0], "radius": 1.0, "bsdf": bsdf},
    }
    if irradiance > 0.0:
        scene["sun"] = {"type": "directional", "direction": [-x for x in light],
                        "irradiance": irradiance_spectrum(irradiance, variant=variant,
                                                          illuminant=illuminant)}
    if ambient > 0.0:
        scene["sky"] = {"type": "constant",
                        "radiance": irradiance_spectrum(ambient, variant=variant,
                                                        illuminant=illuminant)}
    return scene


def render_sphere_mitsuba(model: BRDF, *, phi_l: float = 0.0, ambient: float = 0.0,
                          irradiance: float = 1.0, size: int = 256, spp: int = 16,
                          seed: int = 0, variant: str = "llvm_ad_rgb",
                          wavelengths=None, illuminant: str = "d65") -> np.ndarray:
    """The sphere test configuration by Monte Carlo through Mitsuba 3.

    Parameters (keyword-only after *model*)
    ---------------------------------------
    model : BRDF
        Any brdfkit model (registered, pumped, measured).
    phi_l : float
        Φ_L, radians in [−π/2, π/2]: L = (sin Φ_L, 0, cos Φ_L).
    ambient : float
        L_a ≥ 0, the radiance of the uniform environment.
    irradiance : float
        E ≥ 0 of the directional light (on a surface facing it).
    size : int
        S, the image is S×S pixels (1 … :data:`~brdfkit.render.mitsuba_bridge.MITSUBA_MAX_SIZE`
        = 2048).
    spp : int
        Samples per pixel (1 … 65536, and S² × spp at most
        :data:`~brdfkit.render.mitsuba_bridge.MAX_SAMPLES` = 2^30); the noise falls as
        1/√spp. Memory is bounded: a render of more than 2^20 paths is split into calls
        (:func:`~brdfkit.render.mitsuba_bridge.render_bounded`).
    seed : int
        Mitsuba's sampler seed, 0 … 2^32 − 1 (the render is deterministic given it).
    variant : str
        ``llvm_ad_rgb`` (default), ``llvm_ad_mono``, ``llvm_ad_spectral`` or a
        ``scalar_*`` one (slow); an unavailable ``llvm_*`` variant falls back
        with a warning (:func:`~brdfkit.render.mitsuba_bridge.use_variant`).
    wavelengths : array_like, optional
        The model's channels as spectral samples (nm), spectral variants only.
    illuminant : {"d65", "flat"}
        The emitters' spectrum in spectral variants: D65 (Mitsuba's reading of
        a plain number: it develops to RGB white, like the RGB variants) or a
        flat spectrum. Ignored in RGB and mono variants.

    Returns
    -------
    ndarray, shape (S, S, C), float64
        Linear radiance per pixel (pixel-area average, module docstring); C = 3
        (RGB; spectral variants developed to linear sRGB by Mitsuba's film) or
        1 (mono).
    """
    _check_args(model, phi_l=phi_l, ambient=ambient, irradiance=irradiance, size=size,
                spp=spp, seed=seed)
    return _render(model, [(int(spp), int(seed))], phi_l=phi_l, ambient=ambient,
                   irradiance=irradiance, size=size, variant=variant,
                   wavelengths=wavelengths, illuminant=illuminant)[0]


def render_sphere_mitsuba_passes(model: BRDF, *, phi_l: float = 0.0, ambient: float = 0.0,
                                 irradiance: float = 1.0, size: int = 256, spp: int = 64,
                                 seed: int = 0, passes: int | None = None,
                                 variant: str = "llvm_ad_rgb", wavelengths=None,
                                 illuminant: str = "d65"):
    """The sphere by Monte Carlo in K independent passes, with its standard error.

    Parameters as :func:`render_sphere_mitsuba`, and *passes* K (default
    :data:`DEFAULT_PASSES`, at most *spp*): the spp are split into K near-equal passes
    rendered with seeds K·seed + k (k = 0 … K − 1).

    Returns
    -------
    (image, stderr, passes) : ndarray (S, S, C), ndarray (S, S, C) or None, int
        The sample-weighted mean of the passes, the per-pixel standard error of that
        mean (module docstring; None for one pass, which cannot estimate it), and K.
        With K = 1 the image is :func:`render_sphere_mitsuba`'s for the same seed.
    """
    _check_args(model, phi_l=phi_l, ambient=ambient, irradiance=irradiance, size=size,
                spp=spp, seed=seed)
    k = min(DEFAULT_PASSES, int(spp)) if passes is None else passes
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 1 <= k <= spp:
        raise ParameterError(f"passes must be an integer in [1, spp = {spp}]; got {passes!r}")
    k = int(k)
    counts = [int(spp) // k + (1 if j < int(spp) % k else 0) for j in range(k)]
    jobs = [(n, (k * int(seed) + j) % 2**32) for j, n in enumerate(counts)]  # Mitsuba: uint32
    images = _render_each(model, jobs, phi_l=phi_l, ambient=ambient, irradiance=irradiance,
                          size=size, variant=variant, wavelengths=wavelengths,
                          illuminant=illuminant)
    if k == 1:
        return next(images), None, 1
    # the sample-weighted mean and sum of squares, one pass image at a time (West 1979's
    # weighted update), so that memory holds a few images, not K of them: S = sum n_k
    # (x_k - mean)^2 after the last pass, s^2 = S / (K - 1) (module docstring)
    mean, ss, total = None, None, 0.0
    for n_k, image in zip(counts, images, strict=True):
        total += n_k
        if mean is None:
            mean, ss = image, np.zeros_like(image)
            continue
        delta = image - mean
        mean += (n_k / total) * delta
        ss += n_k * delta * (image - mean)
    return mean, np.sqrt(ss / (k - 1) / total), k


def _check_args(model, *, phi_l, ambient, irradiance, size, spp, seed) -> None:
    if not isinstance(model, BRDF):
        raise ParameterError(f"model must be a brdfkit model (BRDF); got {type(model)!r}")
    checks = (("phi_l", phi_l, -math.pi / 2, math.pi / 2), ("ambient", ambient, 0.0, math.inf),
              ("irradiance", irradiance, 0.0, math.inf))
    for name, value, lo, hi in checks:
        if not (isinstance(value, (int, float)) and lo <= value <= hi and math.isfinite(value)):
            raise ParameterError(f"{name} must be a finite number in [{lo:g}, {hi:g}]; "
                                 f"got {value!r}")
    for name, value, lo, hi in (("size", size, 1, MITSUBA_MAX_SIZE), ("spp", spp, 1, 65536)):
        if not (isinstance(value, (int, np.integer)) and lo <= value <= hi):
            raise ParameterError(f"{name} must be an integer in [{lo}, {hi}]; got {value!r}")
    check_seed(seed)
    check_samples(int(size) ** 2, spp)


def _render(model, jobs, *, phi_l, ambient, irradiance, size, variant, wavelengths,
            illuminant) -> list[np.ndarray]:
    """One scene, rendered once per (spp, seed) of *jobs*: images (S, S, C) float64."""
    return list(_render_each(model, jobs, phi_l=phi_l, ambient=ambient, irradiance=irradiance,
                             size=size, variant=variant, wavelengths=wavelengths,
                             illuminant=illuminant))


def _render_each(model, jobs, *, phi_l, ambient, irradiance, size, variant, wavelengths,
                 illuminant):
    """As :func:`_render`, one image at a time (a generator: only the image being used is
    held)."""
    mi, _ = _mitsuba()
    used = use_variant(variant)
    bsdf = mitsuba_bsdf(model, wavelengths=wavelengths)
    scene = mi.load_dict(sphere_scene(bsdf, phi_l=phi_l, irradiance=irradiance,
                                      ambient=ambient, size=size, variant=used,
                                      illuminant=illuminant))
    # the traced route renders in Dr.Jit's default symbolic mode, the other one per wavefront
    for spp, seed in jobs:
        with contextlib.nullcontext() if bsdf.traced else wavefront():
            out = render_bounded(scene, spp=spp, seed=seed, pixels=int(size) ** 2)
        yield out[:, :, None] if out.ndim == 2 else out
