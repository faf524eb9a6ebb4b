"""
Any brdfkit model as a Mitsuba 3 BSDF
=====================================

The formulas stay written once. Two routes, chosen per model (``route="auto"``):

- **traced** (models whose :meth:`~brdfkit.models.BRDF.formulas` are given:
  ``microfacet``, user models, pumped models of those with their tables read
  in the trace, :func:`brdfkit.tables.lookup`): the
  formula functions that Numba compiles for ``model.eval``/``sample``/``pdf``
  (:mod:`brdfkit._dual`) are rebound to Dr.Jit and called from a Python BSDF
  that Dr.Jit traces into Mitsuba's kernel, in its default symbolic mode
  (:mod:`brdfkit.render.mitsuba_traced`). As fast as Mitsuba's own BSDFs.
- **wavefront** (the fallback: a model without formulas, the ``scalar_*``
  variants, RGB channels in a spectral variant, tables per wavelength; the
  BSDF's ``route_reason`` and a :class:`WavefrontRouteWarning` say which, in
  one line): Mitsuba calls a Python BSDF with whole
  wavefronts (arrays of every path's directions) when Dr.Jit's symbolic loops,
  calls and conditionals are switched off (:func:`wavefront`), and the BSDF
  hands those arrays to ``model.eval``, ``model.sample`` and ``model.pdf`` as
  NumPy float64 arrays. Works for anything; 8-9× the time of Mitsuba's
  own BSDF at 256², 16 spp (see *Cost* below).

A BSDF's ``traced`` attribute says which route it takes. In ``*_ad_*`` variants a
traced BSDF lists the model's parameters by name for ``mi.traverse``
(:mod:`brdfkit.render.mitsuba_traced`). The design record
(why, the formula contract) is in ``docs/architecture.md``.

Conventions (where the two libraries meet)
------------------------------------------
- brdfkit: ``eval(wi, wo)``, ``wi`` toward the light, ``wo`` toward the
  viewer, both away from the surface, f_r without the cosine.
- Mitsuba: ``BSDF.eval(ctx, si, wo)`` with ``si.wi`` toward the viewer (the
  previous path vertex) and ``wo`` the sampled direction (toward the light),
  both in the local shading frame (normal +z, brdfkit's x axis = Mitsuba's
  tangent ``s``); it returns f_r·cos θ of its ``wo``.
- So Mitsuba's ``eval(si.wi = V, wo = L)`` = brdfkit ``eval(wi=L, wo=V)``·L_z,
  ``sample`` draws L given V with brdfkit's ``model.sample(wo=V, u)``, and
  ``pdf(si.wi = V, wo = L)`` = ``model.pdf(wi=L, wo=V)``. The bridge is
  one-sided as brdfkit's models (0 when either direction is below the
  horizon), like Mitsuba's own BSDFs.

Colour and wavelengths: :mod:`brdfkit.render.mitsuba_colour` (grey, RGB,
luminance in mono variants, sRGB upsampled in spectral ones, or channels on a
wavelength grid interpolated at each path's wavelengths).

Cost, and a caveat
------------------
Measured (``benchmarks/bench_render_mitsuba.py``, 256² sphere, 16 spp, GGX
α = 0.2 conductor, medians of 5 renders in one process, two runs on a 2-core
machine at load 5-9), as ratios to Mitsuba's own symbolic ``roughconductor``
(same α, η, κ, spp, run): the traced ``microfacet`` 1.00-1.07× in
``llvm_ad_rgb`` and 0.45-0.59× in ``llvm_ad_spectral`` (n, k on a 16-point
grid; ``roughconductor`` reads them as ``irregular`` spectra); the wavefront
route 7.8-9.4× and 3.5-3.9× (the wavefront mode alone makes
``roughconductor`` 2.5-5.1× slower). The images agree within Monte-Carlo
noise, and the two routes give the same image to 5e-7 from the same seeds
(one sampler formula).
While a wavefront-route BSDF object is alive, Dr.Jit's symbolic calls trace it
too and fail ("remains dirty"): render scenes with native or traced BSDFs
inside :func:`wavefront` as well, or drop the wavefront objects (``del`` +
``gc.collect()``) first. Traced BSDFs render in either mode.

Modules
-------
One job each: :mod:`~brdfkit.render.mitsuba_variants` (the variants and their
scalar fallback when LLVM is missing), :mod:`~brdfkit.render.mitsuba_colour`
(channels to spectra), :mod:`~brdfkit.render.mitsuba_wavefront` and
:mod:`~brdfkit.render.mitsuba_traced` (the two routes' BSDF classes),
:mod:`~brdfkit.render.mitsuba_plugin` (the scene-dict plugin). This module
chooses the route and is the public entry point.

Public objects
--------------
- :func:`use_variant` — set a Mitsuba variant (with the fallback) and register
  the ``brdfkit`` plugin in it.
- :func:`wavefront` — context manager: Dr.Jit's symbolic modes off (required
  while rendering with a wavefront-route BSDF in ``llvm_*`` variants).
- :func:`mitsuba_bsdf` — a model object as a Mitsuba BSDF object (for a scene
  dict: ``{"type": "sphere", "bsdf": mitsuba_bsdf(model)}``), by the traced
  route where possible (``route=`` to choose).
- :func:`spectral_model` — a model with per-wavelength parameters on a grid.
- The scene-dict plugin ``{"type": "brdfkit", "model": SPEC, PARAM: VALUE,
  …}``: ``SPEC`` a model name or material spec (``brdfkit.model(spec,
  **params)``), per-channel values as comma-separated strings
  (``"eta": "0.2, 0.9, 1.1"``), optional ``"wavelengths": "450, 550, 650"``
  (nm; the channels' wavelengths), ``"pump": "max"|"controlled"`` and
  ``"times": K`` — the flat form of :class:`brdfkit.spec.ModelSpec`; the old
  ``"pump": N`` (pump N times) with ``"pump_g"`` is still read.

References
----------
- W. Jakob et al., *Mitsuba 3 renderer*, 2022 (``BSDF`` interface, docs
  "Custom plugins in Python").
- W. Jakob, J. Hanika, *A Low-Dimensional Function Space for Efficient
  Spectral Upsampling*, Computer Graphics Forum 38(2), 2019.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable

import numpy as np

from brdfkit._cache import bounded_cache
from brdfkit.errors import ParameterError
from brdfkit.models import BRDF
from brdfkit.render.mitsuba_colour import ColourMap, check_wavelengths
from brdfkit.render.mitsuba_plugin import register_plugin
from brdfkit.render.mitsuba_traced import traced_class, wavefront_reason
from brdfkit.render.mitsuba_variants import FALLBACK, VARIANTS, select_variant
from brdfkit.render.mitsuba_variants import import_mitsuba as _mitsuba
from brdfkit.render.mitsuba_wavefront import wavefront, wavefront_class
from brdfkit.spec import model as build_model

__all__ = ["FALLBACK", "ROUTES", "VARIANTS", "WavefrontRouteWarning", "mitsuba_bsdf",
           "spectral_model", "use_variant", "wavefront", "MAX_LANES", "MAX_SAMPLES",
           "MITSUBA_MAX_SIZE", "SEED_LIMIT", "check_seed", "check_samples", "render_bounded"]

#: Most paths (pixels x samples per pixel) of one ``mi.render`` call when the image has
#: fewer pixels; a render with more is split into calls of fewer samples per pixel
#: (:func:`render_bounded`). Mitsuba traces every path of a call at once: measured ~600
#: bytes per path for the wavefront route (lambert, 16² px x 65536 spp in 8 passes of
#: 2^21 paths: 1.4 GB), so 2^20 paths keep a call near 0.6 GB.
MAX_LANES = 2**20
#: Most samples (pixels x samples per pixel) of one render. Measured on 2 cores: the
#: wavefront route traces ~0.26 M samples/s (lambert, 512² x 64 spp: 65 s), the traced
#: route (microfacet) ~3 M/s, so 2^30 samples take ~70 min and ~6 min; beyond, a render
#: runs for hours or days (4096² x 65536 spp: ~130 years of the wavefront route).
MAX_SAMPLES = 2**30
#: Largest image side of a Mitsuba render: one sample per pixel of a 2048² image is 4.2 M
#: paths in one call (~2.5 GB at the measured 600 bytes per path; a whole render of 2048²,
#: 8 spp in 8 passes peaked at 3.0 GB, measured); 4096² would take 10 GB.
MITSUBA_MAX_SIZE = 2048
#: Mitsuba's seeds are 32-bit unsigned integers: 0 <= seed < SEED_LIMIT.
SEED_LIMIT = 2**32
#: Seed step between the calls of a split render (the golden-ratio constant of 32-bit
#: hashing: the calls' seeds stay distinct and far from seed + small k of other passes).
_SEED_STEP = 0x9E3779B9


def check_seed(seed, name: str = "seed") -> int:
    """*seed* as an int in [0, :data:`SEED_LIMIT`); :class:`ParameterError` naming *name*."""
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) \
            or not 0 <= seed < SEED_LIMIT:
        raise ParameterError(f"{name} must be an integer from 0 to {SEED_LIMIT - 1} "
                             f"(Mitsuba's seeds are 32-bit); got {seed!r}")
    return int(seed)


def check_samples(pixels: int, spp: int, *, size_name: str = "size") -> None:
    """*pixels* x *spp* at most :data:`MAX_SAMPLES`; the error states the cost."""
    if int(pixels) * int(spp) > MAX_SAMPLES:
        raise ParameterError(
            f"{size_name} and spp: {int(pixels)} pixels x {int(spp)} samples per pixel = "
            f"{int(pixels) * int(spp):.3g} samples; at most MAX_SAMPLES = 2^30 = "
            f"{MAX_SAMPLES:.3g} per render (~70 min at the measured 0.26 M samples/s of the "
            f"wavefront route on 2 cores); lower spp to {max(1, MAX_SAMPLES // int(pixels))} "
            f"or fewer, or the size")


def render_bounded(scene, *, spp: int, seed: int, pixels: int) -> np.ndarray:
    """``mi.render(scene, spp, seed)`` as float64, in calls of at most
    max(:data:`MAX_LANES`, *pixels*) paths: a render of more is split into calls of
    fewer samples per pixel (seeds seed, seed + step, … mod 2^32) and their images
    combined as the sample-weighted mean (what one call would estimate). A render that
    fits in one call is exactly ``mi.render(scene, spp=spp, seed=seed)``."""
    mi, _ = _mitsuba()
    spp, seed, pixels = int(spp), int(seed), max(1, int(pixels))
    per_call = max(1, MAX_LANES // pixels)
    if spp <= per_call:
        return np.array(mi.render(scene, spp=spp, seed=seed), dtype=np.float64)
    total, done, call = None, 0, 0
    while done < spp:
        n = min(per_call, spp - done)
        image = np.array(mi.render(scene, spp=n, seed=(seed + call * _SEED_STEP) % SEED_LIMIT),
                         dtype=np.float64)
        total = n * image if total is None else total + n * image
        done += n
        call += 1
    return total / spp

#: variant → the traced BSDF class (one per variant)
_TRACED = bounded_cache("brdfkit.render.mitsuba_bridge._TRACED", maxsize=len(VARIANTS))


def use_variant(variant: str = "llvm_ad_rgb") -> str:
    """Set Mitsuba's *variant* (or its scalar fallback) and register the plugin there.

    Parameters
    ----------
    variant : str
        One of :data:`VARIANTS`.

    Returns
    -------
    str
        The variant in use: *variant*, or ``FALLBACK[variant]`` when an
        ``llvm_*`` variant cannot start (no usable LLVM); a one-line
        :class:`RuntimeWarning` then says why and how to fix it.
    """
    variant = select_variant(variant, stacklevel=2)
    register_plugin(variant, _make_bsdf)
    return variant


ROUTES = ("auto", "traced", "wavefront")


def _make_bsdf(props, model: BRDF, wavelengths, variant: str, route: str):
    """The traced BSDF when *route* allows and the model supports it, else the wavefront one."""
    mi, dr = _mitsuba()
    grid = check_wavelengths(wavelengths, model)
    ColourMap(mi, variant, model, grid)  # validates channels against the variant
    if model.has_delta:
        warnings.warn(f"brdfkit: {model.name}'s specular delta term is not rendered "
                      "by the Mitsuba bridge (only its kernel)", RuntimeWarning, stacklevel=3)
    reason = wavefront_reason(model, variant, grid)
    if route != "wavefront" and reason is None:
        if variant not in _TRACED:
            _TRACED[variant] = traced_class(mi, dr, variant)
        bsdf = _TRACED[variant](props, model, grid)
        bsdf.route_reason = None
        return bsdf
    if route == "traced":
        raise ParameterError(
            f"route='traced' needs a model with formulas (model.formulas()), an llvm_* "
            f"variant and grey, RGB or wavelength-grid channels: {reason}; use route='auto'")
    bsdf = wavefront_class(variant)(props, model=model, wavelengths=wavelengths)
    if route == "wavefront":
        bsdf.route_reason = "route='wavefront' asked for"
        return bsdf
    bsdf.route_reason = f"{reason}: the wavefront route"
    if variant.startswith("llvm"):
        bsdf.route_reason += (", 3-9x slower than traced; render inside "
                              "brdfkit.render.mitsuba_bridge.wavefront()")
    warnings.warn(f"brdfkit: {bsdf.route_reason}", WavefrontRouteWarning, stacklevel=3)
    return bsdf


class WavefrontRouteWarning(UserWarning):
    """A model takes the bridge's wavefront route (the one-line reason: ``route_reason``)."""


def mitsuba_bsdf(model: BRDF, *, wavelengths=None, variant: str | None = None,
                 route: str = "auto"):
    """*model* as a Mitsuba BSDF object of the current (or given) variant.

    Parameters
    ----------
    model : BRDF
        Any brdfkit model: registered, pumped, measured (anything with
        ``eval``, ``sample``, ``pdf``).
    wavelengths : array_like, optional
        nm, one per channel of *model*, increasing: the channels are spectral
        samples, interpolated per path at ``si.wavelengths`` (spectral
        variants only). None: grey or RGB channels (module docstring).
    variant : str, optional
        Switch to this variant first (:func:`use_variant`, with its fallback);
        None: the current Mitsuba variant (which must be one of
        :data:`VARIANTS`).
    route : {"auto", "traced", "wavefront"}
        ``auto``: the traced route when the model gives formulas and the
        variant and channels allow it (module docstring), else the wavefront
        route; ``traced`` insists (ParameterError otherwise); ``wavefront``
        always calls the model's NumPy/Numba methods per wavefront.

    Returns
    -------
    mitsuba.BSDF
        Usable as a value in a scene dict (``"bsdf": mitsuba_bsdf(model)``),
        in ``mi.chi2.BSDFAdapter``-style tests, or directly. Its attribute
        ``traced`` says which route it takes: False means render inside
        :func:`wavefront` in ``llvm_*`` variants; ``route_reason`` says why in
        one line (None when traced), also given as a
        :class:`WavefrontRouteWarning` when ``route="auto"`` falls back.
    """
    if not isinstance(model, BRDF):
        raise ParameterError(f"model must be a brdfkit model (BRDF); got {type(model)!r}")
    if route not in ROUTES:
        raise ParameterError(f"route must be one of {', '.join(ROUTES)}; got {route!r}")
    mi, _ = _mitsuba()
    if variant is not None:
        variant = use_variant(variant)
    else:
        variant = mi.variant()
        if variant not in FALLBACK:
            raise ParameterError(
                f"the current Mitsuba variant must be one of {', '.join(VARIANTS)}; it is "
                f"{variant!r} (call brdfkit.render.mitsuba_bridge.use_variant first)")
        use_variant(variant)
    return _make_bsdf(mi.Properties("brdfkit"), model, wavelengths, mi.variant(), route)


def spectral_model(name: str, wavelengths, **params) -> tuple[BRDF, np.ndarray]:
    """A model whose parameters vary with wavelength, as channels on a grid.

    Parameters
    ----------
    name : str
        Model name or material spec (``brdfkit.model``).
    wavelengths : array_like
        The grid, nm, increasing (tens of points: every path evaluates all).
    **params
        Values, or callables of λ (nm, float64 array) returning one value per
        wavelength (e.g. a metal's ``eta=lambda lam: n(lam)``,
        ``k=lambda lam: k(lam)``).

    Returns
    -------
    (BRDF, ndarray)
        The model with one channel per wavelength and the grid, for
        ``mitsuba_bsdf(model, wavelengths=grid)``.
    """
    lam = np.asarray(wavelengths, dtype=np.float64)
    if lam.ndim != 1 or lam.size < 2:
        raise ParameterError(
            f"wavelengths must be a 1-D sequence of at least 2 values (nm); got {lam!r}")
    values = {}
    for key, v in params.items():
        if isinstance(v, Callable):
            arr = np.asarray(v(lam.copy()), dtype=np.float64)
            if arr.shape != lam.shape:
                raise ParameterError(
                    f"parameter {key!r}: the callable must return one value per wavelength "
                    f"(shape {lam.shape}); got shape {arr.shape}")
            values[key] = arr
        else:
            values[key] = v
    m = build_model(name, **values)
    if m.n_channels != lam.size:
        raise ParameterError(
            f"spectral_model: at least one colour parameter must be given per wavelength "
            f"(as a callable or a sequence of {lam.size}); the model has "
            f"{m.n_channels or 1} channel(s)")
    check_wavelengths(lam, m)
    return m, lam


def irradiance_spectrum(value: float, *, variant: str, illuminant: str = "d65") -> dict | float:
    """An emitter's spectrum *value*: a plain float (D65 in spectral variants, white in
    RGB) or, with ``illuminant="flat"`` in a spectral variant, a flat spectrum."""
    if illuminant not in ("d65", "flat"):
        raise ParameterError(f"illuminant must be 'd65' or 'flat'; got {illuminant!r}")
    if illuminant == "flat" and "spectral" in variant:
        return {"type": "uniform", "value": float(value)}
    return float(value)
