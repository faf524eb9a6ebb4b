"""
The wavefront route of the Mitsuba bridge: a model's NumPy/Numba methods per wavefront
======================================================================================

For every model (and the ``scalar_*`` variants, and RGB channels in a spectral
variant), Mitsuba calls a Python BSDF with whole wavefronts (arrays of every
path's directions) when Dr.Jit's symbolic loops, calls and conditionals are
switched off (:func:`wavefront`), and the BSDF hands those arrays to
``model.eval``, ``model.sample`` and ``model.pdf`` as NumPy float64 arrays.
Works for anything; 8-9× the time of Mitsuba's own BSDF at 256², 16 spp (the
cost and its caveat: :mod:`brdfkit.render.mitsuba_bridge`). The conventions
where the two libraries meet are the bridge's (its module docstring); colours
map through :class:`~brdfkit.render.mitsuba_colour.ColourMap`.

Public objects
--------------
- :func:`wavefront` — context manager: Dr.Jit's symbolic modes off (required
  while rendering with a wavefront-route BSDF in ``llvm_*`` variants).
- :func:`wavefront_class` — the wavefront ``mi.BSDF`` subclass of a variant.
"""

from __future__ import annotations

import contextlib

import numpy as np

from brdfkit._cache import bounded_cache
from brdfkit.models import BRDF
from brdfkit.render.mitsuba_colour import ColourMap, check_wavelengths
from brdfkit.render.mitsuba_variants import VARIANTS, import_mitsuba

__all__ = ["wavefront", "wavefront_class"]

_FLAGS = ("SymbolicLoops", "SymbolicCalls", "SymbolicConditionals")
#: variant → the wavefront BSDF class (one per variant)
_CLASSES = bounded_cache("brdfkit.render.mitsuba_wavefront._CLASSES", maxsize=len(VARIANTS))


@contextlib.contextmanager
def wavefront():
    """Dr.Jit's symbolic loops, calls and conditionals off inside the block, restored after.

    Mitsuba then runs its integrators wavefront by wavefront and calls the
    bridge's Python methods with evaluated arrays of every active path, which
    is what lets them call brdfkit's compiled kernels (a symbolic trace cannot
    leave Dr.Jit).
    """
    mi, dr = import_mitsuba()
    old = {f: dr.flag(dr.JitFlag[f]) for f in _FLAGS}
    try:
        for f in _FLAGS:
            dr.set_flag(dr.JitFlag[f], False)
        yield
    finally:
        for f, v in old.items():
            dr.set_flag(dr.JitFlag[f], v)


def _vectors(v, n: int) -> np.ndarray:
    """A Dr.Jit 3-vector (scalar or array) as (n, 3) C-contiguous float64."""
    a = np.array(v, dtype=np.float64).reshape(3, -1)
    return np.ascontiguousarray(np.broadcast_to(a, (3, n)).T)


def _mask(active, n: int) -> np.ndarray:
    return np.broadcast_to(np.array(active, dtype=bool).reshape(-1), (n,))


def _width(dr, scalar: bool, *xs) -> int:
    """Lanes of a call: 1 in scalar variants, else the widest argument (literals are 1)."""
    return 1 if scalar else max(dr.width(x) for x in xs)


def wavefront_class(variant: str) -> type:
    """The bridge's ``mi.BSDF`` subclass for the current *variant* (one per variant)."""
    if variant in _CLASSES:
        return _CLASSES[variant]
    mi, dr = import_mitsuba()
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
            self.colour = ColourMap(mi, variant, model, check_wavelengths(wavelengths, model))
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
