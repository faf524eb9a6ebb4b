"""
Any brdfkit model as a Mitsuba 3 BSDF
=====================================

The formulas stay written once. Two routes, chosen per model (``route="auto"``):

- **traced** (models whose :meth:`~brdfkit.models.BRDF.formulas` are given;
  today ``microfacet``, GGX and Beckmann, with or without Fresnel): the
  formula functions that Numba compiles for ``model.eval``/``sample``/``pdf``
  (:mod:`brdfkit._dual`) are rebound to Dr.Jit and called from a Python BSDF
  that Dr.Jit traces into Mitsuba's kernel, in its default symbolic mode
  (:mod:`brdfkit.render.mitsuba_traced`). As fast as Mitsuba's own BSDFs.
- **wavefront** (every other model, the ``scalar_*`` variants, and RGB
  channels in a spectral variant): Mitsuba calls a Python BSDF with whole
  wavefronts (arrays of every path's directions) when Dr.Jit's symbolic loops,
  calls and conditionals are switched off (:func:`wavefront`), and the BSDF
  hands those arrays to ``model.eval``, ``model.sample`` and ``model.pdf`` as
  NumPy float64 arrays. Works for anything; 8-9× the time of Mitsuba's
  own BSDF at 256², 16 spp (see *Cost* below).

A BSDF's ``traced`` attribute says which route it takes. The design record
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

Colour and wavelengths
----------------------
Mitsuba's spectrum per path has 3 values (``*_rgb``), 1 (``*_mono``) or 4
wavelengths (``*_spectral``, at ``si.wavelengths`` in nm). A model's channels
(``model.n_channels``; None = grey) map to them as follows:

============================ ============== ================ ===================
model channels               rgb variants   mono variants    spectral variants
============================ ============== ================ ===================
grey (None or 1)             same value ×3  the value        same value ×4
3, no ``wavelengths``        R, G, B        luminance Y      sRGB upsampled
C on a ``wavelengths`` grid  error          error            interpolated at λ
============================ ============== ================ ===================

- *luminance*: Y = 0.212671 R + 0.715160 G + 0.072169 B (Rec. 709 / sRGB,
  Mitsuba's ``luminance``).
- *sRGB upsampled*: f(λ) = Σ_c f_c w_c(λ), with w_c = s_c/(s_R + s_G + s_B)
  and s_c the smooth spectrum Mitsuba's sRGB model (Jakob & Hanika 2019,
  ``srgb_model_fetch``/``srgb_model_eval``) gives the primary c. Linear in f
  (so Monte-Carlo averages stay unbiased, and unbounded f_r is fine), a grey
  f stays exactly flat; a coloured f develops under D65 to approximately its
  RGB (pure primaries are outside the gamut of smooth spectra; measured: a
  Lambertian (0.2, 0.5, 0.8) in a white furnace develops to (0.205, 0.500,
  0.805) ± 0.005). Mitsuba's own
  per-value upsampling (``srgb_model_fetch``) is scalar-only in Python.
- *wavelength grid* (per-wavelength parameters, e.g. a metal's n, k): the
  model is built with C channels, channel c holding the parameters at
  ``wavelengths[c]`` (nm, increasing); per path the wavefront route evaluates
  all C channels and interpolates f_r linearly in λ at each of the path's 4
  wavelengths (held constant outside the grid); the traced route interpolates
  the *parameters* (n, k) linearly at the path's wavelengths and evaluates
  once, as Mitsuba's ``irregular`` spectra do (exact for parameters linear in
  λ). Both are exact at the grid points; between them the error is that of
  linear interpolation, h²/8·|∂²f/∂λ²| (of f_r, or of n, k) for spacing h: exact for a grey
  model, and for metals at 5-10 nm spacing far below Monte-Carlo noise (the
  n, k data themselves are tabulated at a similar spacing). The cost grows
  with C (all channels evaluated per path): keep grids to tens of points.
  :func:`spectral_model` builds such a model from parameter callables of λ.

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

Variants
--------
``llvm_*`` variants need Debian's ``libllvm19`` (LLVM 15/16 load but abort on
microfacet kernels). :func:`use_variant` falls back to the matching
``scalar_*`` variant (``scalar_rgb`` for ``llvm_ad_mono``: the pip build has
no ``scalar_mono``) with a one-line warning saying why and how to fix it. In
scalar variants Mitsuba calls the BSDF once per path vertex from Python:
correct, and ~10⁴× slower (small images only).

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
  (nm; the channels' wavelengths), ``"pump": N`` (pump N times) and
  ``"pump_g": "max"|"controlled"``.

References
----------
- W. Jakob et al., *Mitsuba 3 renderer*, 2022 (``BSDF`` interface, docs
  "Custom plugins in Python").
- W. Jakob, J. Hanika, *A Low-Dimensional Function Space for Efficient
  Spectral Upsampling*, Computer Graphics Forum 38(2), 2019.
"""

from __future__ import annotations

import contextlib
import warnings
from collections.abc import Callable

import numpy as np

from brdfkit._specs import model as build_model
from brdfkit.colour import MITSUBA_LUMINANCE
from brdfkit.errors import BrdfkitError, ParameterError
from brdfkit.models import BRDF
from brdfkit.pumping import pump
from brdfkit.render.mitsuba_traced import traced_class, traced_supported

__all__ = ["FALLBACK", "ROUTES", "VARIANTS", "mitsuba_bsdf", "spectral_model", "use_variant",
           "wavefront"]

#: The variants the bridge supports, and the scalar variant each falls back to.
FALLBACK = {"llvm_ad_rgb": "scalar_rgb", "llvm_ad_mono": "scalar_rgb",
            "llvm_ad_spectral": "scalar_spectral", "scalar_rgb": "scalar_rgb",
            "scalar_spectral": "scalar_spectral"}
VARIANTS = tuple(FALLBACK)

#: Rec. 709 luminance weights of linear sRGB (Mitsuba's ``luminance``; ITU-R BT.709).
LUMINANCE = MITSUBA_LUMINANCE  # brdfkit.colour: as Mitsuba's own conversion (traced route)

_FLAGS = ("SymbolicLoops", "SymbolicCalls", "SymbolicConditionals")
_REGISTERED: set[str] = set()
_CLASSES: dict[str, type] = {}
_TRACED: dict[str, type] = {}


def _mitsuba():
    """Import Mitsuba and Dr.Jit, with an error saying how to install them."""
    try:
        import drjit as dr
        import mitsuba as mi
    except ImportError as exc:
        raise BrdfkitError(
            f"rendering through Mitsuba needs the packages mitsuba and drjit ({exc}); "
            "install them with: pip install mitsuba") from None
    return mi, dr


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
    if variant not in FALLBACK:
        raise ParameterError(
            f"variant must be one of {', '.join(VARIANTS)}; got {variant!r}")
    mi, dr = _mitsuba()
    try:
        mi.set_variant(variant)
        if variant.startswith("llvm"):
            # the LLVM backend starts lazily: compile and run one kernel to know it works
            x = mi.Float([1.0, 2.0])
            dr.eval(x * 2.0)
    except Exception as exc:  # Mitsuba/Dr.Jit raise plain exceptions for a missing LLVM
        used = FALLBACK[variant]
        reason = str(exc).strip().splitlines()[0][:160] if str(exc).strip() else type(exc).__name__
        warnings.warn(
            f"brdfkit: Mitsuba variant {variant} unavailable ({reason}); using {used} "
            "(slow) — fix: apt-get install libllvm19, or set DRJIT_LIBLLVM_PATH to "
            "libLLVM-19.so", RuntimeWarning, stacklevel=2)
        mi.set_variant(used)
        variant = used
    if variant not in _REGISTERED:
        mi.register_bsdf("brdfkit", lambda props, v=variant: _plugin(props, v))
        _REGISTERED.add(variant)
    return variant


@contextlib.contextmanager
def wavefront():
    """Dr.Jit's symbolic loops, calls and conditionals off inside the block, restored after.

    Mitsuba then runs its integrators wavefront by wavefront and calls the
    bridge's Python methods with evaluated arrays of every active path, which
    is what lets them call brdfkit's compiled kernels (a symbolic trace cannot
    leave Dr.Jit).
    """
    mi, dr = _mitsuba()
    old = {f: dr.flag(dr.JitFlag[f]) for f in _FLAGS}
    try:
        for f in _FLAGS:
            dr.set_flag(dr.JitFlag[f], False)
        yield
    finally:
        for f, v in old.items():
            dr.set_flag(dr.JitFlag[f], v)


# ----------------------------------------------------------------------- colour mapping
def _check_wavelengths(wavelengths, model: BRDF) -> np.ndarray | None:
    if wavelengths is None:
        return None
    lam = np.asarray(wavelengths, dtype=np.float64)
    n_c = model.n_channels or 1
    if lam.ndim != 1 or lam.size != n_c:
        raise ParameterError(
            f"wavelengths must be a 1-D sequence with one entry per channel of the model "
            f"({n_c}); got shape {lam.shape}")
    if not (np.all(np.isfinite(lam)) and np.all(lam > 0.0) and np.all(np.diff(lam) > 0.0)):
        raise ParameterError(
            f"wavelengths must be positive, finite and increasing (nm); got {lam.tolist()}")
    return lam


def _interp_lanes(grid: np.ndarray, f: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """f (M, C) on the λ grid (C,) interpolated linearly at lam (M, W); constant outside."""
    if grid.size == 1:
        return np.repeat(f[:, :1], lam.shape[1], axis=1)
    x = np.clip(lam, grid[0], grid[-1])  # constant beyond the grid's ends
    j = np.clip(np.searchsorted(grid, x, side="right") - 1, 0, grid.size - 2)
    t = (x - grid[j]) / (grid[j + 1] - grid[j])
    rows = np.arange(f.shape[0])[:, None]
    return (1.0 - t) * f[rows, j] + t * f[rows, j + 1]


class _ColourMap:
    """Maps a model's f_r channels to one variant's spectrum per lane (module docstring)."""

    def __init__(self, mi, variant: str, model: BRDF, grid: np.ndarray | None):
        self.mi = mi
        self.kind = "spectral" if "spectral" in variant else ("mono" if "mono" in variant
                                                              else "rgb")
        self.size = {"rgb": 3, "mono": 1, "spectral": 4}[self.kind]
        self.n_c = model.n_channels
        self.grid = grid
        self._basis: np.ndarray | None = None  # RGB basis spectra, built on first use
        if grid is not None and self.kind != "spectral":
            raise ParameterError(
                f"a model with per-wavelength channels (wavelengths given) needs a spectral "
                f"variant (llvm_ad_spectral or scalar_spectral); the variant is {variant}")
        if grid is None and self.n_c not in (None, 1, 3):
            raise ParameterError(
                f"a model with {self.n_c} channels needs wavelengths (nm, one per channel) "
                "unless it has 1 (grey) or 3 (RGB) channels")

    def __call__(self, f: np.ndarray, lam) -> np.ndarray:
        """f (M,) or (M, C) → (M, size); *lam* () → (M, 4) wavelengths (spectral only)."""
        f2 = f[:, None] if f.ndim == 1 else f
        m = f2.shape[0]
        if f2.shape[1] == 1:
            return np.repeat(f2, self.size, axis=1)
        if self.grid is not None:
            return _interp_lanes(self.grid, f2, lam())
        if self.kind == "rgb":
            return f2
        if self.kind == "mono":
            return (f2 @ LUMINANCE)[:, None]
        return self._upsample(f2, lam(), m)

    def _upsample(self, rgb: np.ndarray, lam: np.ndarray, m: int) -> np.ndarray:
        """Σ_c f_c w_c(λ) per lane (module docstring), w on a 1-nm table."""
        if self._basis is None:
            self._basis = _primary_basis(self.mi)
        w = np.stack([np.interp(lam, RGB_GRID, self._basis[c]) for c in range(3)], axis=-1)
        return np.einsum("mc,mwc->mw", rgb, w)


#: Wavelengths (nm) of the table of the RGB basis spectra: Mitsuba's visible range, 1 nm.
RGB_GRID = np.arange(360.0, 831.0)


def _primary_basis(mi) -> np.ndarray:
    """w_c(λ) on RGB_GRID, shape (3, L): the sRGB-model spectra of the primaries (Jakob &
    Hanika 2019, as Mitsuba fetches them) divided by their sum (a partition of unity)."""
    spectra = []
    scalar = mi.variant().startswith("scalar")
    for e in np.eye(3):
        coeff = mi.srgb_model_fetch(mi.ScalarColor3f(*e.tolist()))
        if scalar:
            vals = [float(mi.srgb_model_eval(coeff, mi.Spectrum(x, x, x, x))[0])
                    for x in RGB_GRID.tolist()]
        else:
            import drjit as dr  # only the llvm variants get here (FALLBACK's keys)

            lam = mi.Float(RGB_GRID.astype(np.float32))
            out = mi.srgb_model_eval(dr.llvm.ad.Array3f(*[float(x) for x in coeff]),
                                     mi.Spectrum(lam, lam, lam, lam))
            vals = np.array(out, dtype=np.float64).reshape(4, -1)[0]
        spectra.append(np.asarray(vals, dtype=np.float64))
    s = np.stack(spectra)
    return s / s.sum(axis=0)


# ----------------------------------------------------------------------- the BSDF class
def _vectors(v, n: int) -> np.ndarray:
    """A Dr.Jit 3-vector (scalar or array) as (n, 3) C-contiguous float64."""
    a = np.array(v, dtype=np.float64).reshape(3, -1)
    return np.ascontiguousarray(np.broadcast_to(a, (3, n)).T)


def _mask(active, n: int) -> np.ndarray:
    return np.broadcast_to(np.array(active, dtype=bool).reshape(-1), (n,))


def _width(dr, scalar: bool, *xs) -> int:
    """Lanes of a call: 1 in scalar variants, else the widest argument (literals are 1)."""
    return 1 if scalar else max(dr.width(x) for x in xs)


def _bsdf_class(variant: str) -> type:
    """The bridge's ``mi.BSDF`` subclass for the current *variant* (one per variant)."""
    if variant in _CLASSES:
        return _CLASSES[variant]
    mi, dr = _mitsuba()
    scalar = variant.startswith("scalar")

    def to_spectrum(vals: np.ndarray):
        if scalar:
            return mi.Spectrum(*vals[0].tolist())
        return mi.Spectrum(np.ascontiguousarray(vals.T, dtype=np.float32))

    def to_float(x: np.ndarray):
        return mi.Float(float(x[0])) if scalar else mi.Float(np.asarray(x, dtype=np.float32))

    def to_vector(w: np.ndarray):
        if scalar:
            return mi.Vector3f(*w[0].tolist())
        return mi.Vector3f(np.ascontiguousarray(w.T, dtype=np.float32))

    class BrdfkitBSDF(mi.BSDF):
        """A brdfkit model as a Mitsuba BSDF (see :mod:`brdfkit.render.mitsuba_bridge`)."""

        traced = False  # the wavefront route: render inside wavefront()

        def __init__(self, props, model: BRDF, wavelengths=None):
            mi.BSDF.__init__(self, props)
            self.model = model
            self.colour = _ColourMap(mi, variant, model, _check_wavelengths(wavelengths, model))
            flags = mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.DiffuseReflection
            self.m_flags = flags
            self.m_components = [flags]
            self.sampled_flags = mi.UInt32(+mi.BSDFFlags.GlossyReflection)

        # f_r·cos θ_L for the lanes ok, spectrum rows (M, size)
        def _value(self, light, view, lanes, ok):
            f = self.model.eval(light, view)
            return self.colour(f, lambda: lanes.wavelengths[ok]) * light[:, 2:3]

        def _pairs(self, si, wo, active):
            n = _width(dr, scalar, si.wi, si.wavelengths, wo, active)
            view = _vectors(si.wi, n)
            light = _vectors(wo, n)
            # one-sided: 0 below the horizon (brdfkit's convention, and Mitsuba's BSDFs')
            ok = _mask(active, n) & (view[:, 2] > 0.0) & (light[:, 2] > 0.0)
            return n, view, light, ok

        def eval(self, ctx, si, wo, active=True):
            n, view, light, ok = self._pairs(si, wo, active)
            out = np.zeros((n, self.colour.size))
            if ok.any():
                out[ok] = self._value(light[ok], view[ok], _Lanes(si, n), ok)
            return to_spectrum(out)

        def pdf(self, ctx, si, wo, active=True):
            n, view, light, ok = self._pairs(si, wo, active)
            p = np.zeros(n)
            if ok.any():
                p[ok] = self.model.pdf(light[ok], view[ok])
            return to_float(p)

        def eval_pdf(self, ctx, si, wo, active=True):
            n, view, light, ok = self._pairs(si, wo, active)
            out = np.zeros((n, self.colour.size))
            p = np.zeros(n)
            if ok.any():
                out[ok] = self._value(light[ok], view[ok], _Lanes(si, n), ok)
                p[ok] = self.model.pdf(light[ok], view[ok])
            return to_spectrum(out), to_float(p)

        def sample(self, ctx, si, sample1, sample2, active=True):
            n = _width(dr, scalar, si.wi, si.wavelengths, sample2, active)
            view = _vectors(si.wi, n)
            u = np.broadcast_to(np.array(sample2, dtype=np.float64).reshape(2, -1), (2, n)).T
            u = np.clip(u, 0.0, 1.0)  # float32 rounding of Mitsuba's samples (they are in [0, 1))
            ok = _mask(active, n) & (view[:, 2] > 0.0)
            light = np.zeros((n, 3))
            light[:, 2] = 1.0  # returned (with pdf 0, weight 0) where nothing is sampled
            p = np.zeros(n)
            weight = np.zeros((n, self.colour.size))
            if ok.any():
                wi_s, p_s = self.model.sample(view[ok], u[ok])
                light[ok] = wi_s
                p[ok] = p_s
                # a sample below the horizon or with pdf 0 carries no weight
                good = ok.copy()
                good[ok] = (p_s > 0.0) & (wi_s[:, 2] > 0.0) & np.isfinite(p_s)
                p[~good] = 0.0
                if good.any():
                    weight[good] = (self._value(light[good], view[good], _Lanes(si, n), good)
                                    / p[good][:, None])
            bs = dr.zeros(mi.BSDFSample3f, 1 if scalar else n)
            bs.wo = to_vector(light)
            bs.pdf = to_float(p)
            bs.eta = 1.0
            bs.sampled_type = self.sampled_flags
            bs.sampled_component = 0
            return bs, to_spectrum(weight)

        def eval_diffuse_reflectance(self, si, active=True):
            # Mitsuba uses it for AOVs and denoiser guides only; the albedo engine knows better
            return dr.zeros(mi.Spectrum, 1 if scalar else dr.width(si.wi))

        def traverse(self, callback):
            pass

        def parameters_changed(self, keys):
            pass

        def to_string(self):
            return f"BrdfkitBSDF[{self.model!r}]"

    _CLASSES[variant] = BrdfkitBSDF
    return BrdfkitBSDF


class _Lanes:
    """Lazy access to per-lane wavelengths of an interaction of width n."""

    def __init__(self, si, n: int):
        self.si = si
        self.n = n

    @property
    def wavelengths(self) -> np.ndarray:
        a = np.array(self.si.wavelengths, dtype=np.float64).reshape(4, -1)
        return np.ascontiguousarray(np.broadcast_to(a, (4, self.n)).T)


# ----------------------------------------------------------------------- construction
def _parse_value(name: str, value):
    """A property value: numbers as given, "a, b, c" strings as float lists."""
    if isinstance(value, str) and "," in value:
        try:
            return [float(x) for x in value.split(",")]
        except ValueError:
            raise ParameterError(
                f"brdfkit plugin: property {name!r} must be a number, a word or a "
                f"comma-separated list of numbers; got {value!r}") from None
    return value


def _model_from_props(props) -> tuple[BRDF, list | None]:
    """(model, wavelengths) from a scene dict's ``{"type": "brdfkit", …}`` properties."""
    if "model" not in props:
        raise ParameterError(
            'brdfkit plugin: property "model" is required (a model name such as '
            '"modified-phong" or a material spec such as "merl:nickel")')
    spec = str(props["model"])
    params: dict = {}
    wavelengths = None
    times = 0
    g = "max"
    for key in props.keys():
        value = _parse_value(key, props[key])
        if key in ("model", "id"):
            continue
        if key == "wavelengths":
            wavelengths = np.atleast_1d(np.asarray(value, dtype=np.float64))
        elif key == "pump":
            times = int(value)
        elif key == "pump_g":
            g = str(value)
        else:
            params[key] = value
    m = build_model(spec, **params)
    if times:
        m = pump(m, g, times=times)
    return m, wavelengths


ROUTES = ("auto", "traced", "wavefront")


def _make_bsdf(props, model: BRDF, wavelengths, variant: str, route: str):
    """The traced BSDF when *route* allows and the model supports it, else the wavefront one."""
    mi, dr = _mitsuba()
    grid = _check_wavelengths(wavelengths, model)
    _ColourMap(mi, variant, model, grid)  # validates channels against the variant
    if model.has_delta:
        warnings.warn(f"brdfkit: {model.name}'s specular delta term is not rendered "
                      "by the Mitsuba bridge (only its kernel)", RuntimeWarning, stacklevel=3)
    if route != "wavefront" and traced_supported(model, variant, grid):
        if variant not in _TRACED:
            _TRACED[variant] = traced_class(mi, dr, variant)
        return _TRACED[variant](props, model, grid)
    if route == "traced":
        raise ParameterError(
            f"route='traced' needs a model with formulas (model.formulas(); {model.name} has "
            f"{'them' if model.formulas() is not None else 'none'}), an llvm_* variant "
            f"(got {variant}) and grey, RGB or wavelength-grid channels; use route='auto'")
    return _bsdf_class(variant)(props, model=model, wavelengths=wavelengths)


def _plugin(props, variant: str):
    """The scene-dict plugin ``{"type": "brdfkit", …}`` (route "auto")."""
    model, wavelengths = _model_from_props(props)
    return _make_bsdf(props, model, wavelengths, variant, "auto")


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
        :func:`wavefront` in ``llvm_*`` variants.
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
    _check_wavelengths(lam, m)
    return m, lam


def irradiance_spectrum(value: float, *, variant: str, illuminant: str = "d65") -> dict | float:
    """An emitter's spectrum *value*: a plain float (D65 in spectral variants, white in
    RGB) or, with ``illuminant="flat"`` in a spectral variant, a flat spectrum."""
    if illuminant not in ("d65", "flat"):
        raise ParameterError(f"illuminant must be 'd65' or 'flat'; got {illuminant!r}")
    if illuminant == "flat" and "spectral" in variant:
        return {"type": "uniform", "value": float(value)}
    return float(value)
