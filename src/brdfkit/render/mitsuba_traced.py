"""
The traced route of the Mitsuba bridge: a model's formulas inside Mitsuba's kernel
===================================================================================

For a model whose :meth:`~brdfkit.models.BRDF.formulas` are given, the bridge
does not call back into NumPy: the same formula functions that Numba compiles
for ``model.eval``/``sample``/``pdf`` are rebound to Dr.Jit's operations
(:func:`brdfkit._dual.drjit_version`) and called by a Python ``mi.BSDF`` whose
methods Dr.Jit traces into Mitsuba's megakernel in its default symbolic mode
(no :func:`~brdfkit.render.mitsuba_bridge.wavefront` needed, and no Python per
wavefront). See :mod:`brdfkit.render.mitsuba_bridge` for the conventions and
when this route is taken.

Parameters per path
-------------------
``model.packed`` holds one row of packed parameters per channel. Each column
that is the same in every channel becomes a Python float (so D, G and the
sampler stay single ``Float`` computations); a column that varies becomes

- a ``Color3f`` of the three channels (RGB variants; mono variants take the
  luminance of the resulting f_r, a linear map, as the wavefront route does),
- in spectral variants with a wavelength grid, the column interpolated
  linearly at the path's four wavelengths ``si.wavelengths`` (held constant
  beyond the grid's ends), a ``Spectrum``. This interpolates the *parameters*
  (a metal's n, k), as Mitsuba's own ``irregular`` spectra do, where the
  wavefront route interpolates f_r itself: both are linear interpolation
  between grid points, exact at them; they differ by O(h²) terms.

A kernel that computes every channel and keeps its row's by a channel index in the
row (a user model's: ``select(p[K-1] == 0.0, r, select(p[K-1] == 1.0, g, b))``, the
form of :mod:`brdfkit.user`'s kernels) works unchanged: the index column is the
``Color3f`` (0, 1, 2), its comparisons are 3-channel masks, and the selected f_r a
3-channel array (an ``Array3f``, which mono variants reduce to luminance as a
``Color3f``). In spectral variants such a model takes the wavefront route (RGB
channels); on a wavelength grid its index column would be interpolated, so give such
a model RGB channels only.

References
----------
- W. Jakob et al., *Mitsuba 3 renderer*, 2022 (``BSDF`` interface, "Custom
  plugins in Python"); Dr.Jit's symbolic and evaluated modes.
"""

from __future__ import annotations

import numpy as np

from brdfkit._dual import drjit_version
from brdfkit.models import BRDF
from brdfkit.render.mitsuba_rows import traced_row


def traced_supported(model: BRDF, variant: str, grid: np.ndarray | None) -> bool:
    """Whether :func:`traced_class` can render *model* in *variant* (else the wavefront
    route): the model gives formulas, the variant is an ``llvm_*`` one, and its channels
    are grey, RGB in an RGB or mono variant, or a wavelength grid in a spectral one."""
    form = model.formulas()
    if form is None or not variant.startswith("llvm"):
        return False
    n_c = model.n_channels or 1
    if getattr(form, "table", None):  # a gathered table: RGB or grey channels, no grid
        return grid is None and "spectral" not in variant and n_c in (1, 3)
    if n_c == 1:
        return True
    if "spectral" in variant:
        return grid is not None
    return grid is None and n_c == 3


def _columns(packed: np.ndarray) -> list:
    """Per packed column: a float when every channel has it, else the (C,) values."""
    rows = np.atleast_2d(np.asarray(packed, dtype=np.float64))
    return [float(c[0]) if np.all(c == c[0]) else c.copy() for c in rows.T]


def traced_class(mi, dr, variant: str) -> type:
    """The traced ``mi.BSDF`` subclass for the current (``llvm_*``) *variant*."""
    kind = "spectral" if "spectral" in variant else ("mono" if "mono" in variant else "rgb")

    def interp(grid: np.ndarray, values: np.ndarray, lam):
        """values on grid, linear in λ at *lam* (a Spectrum of wavelengths), constant outside."""
        x = dr.clip(lam, float(grid[0]), float(grid[-1]))  # constant beyond the grid's ends
        out = dr.zeros(mi.Spectrum) + float(values[0])
        for c in range(grid.size - 1):
            g0, g1, v0, v1 = (float(grid[c]), float(grid[c + 1]), float(values[c]),
                              float(values[c + 1]))
            seg = v0 + (x - g0) * ((v1 - v0) / (g1 - g0))
            out = dr.select(x >= g0, seg, out)  # the last segment starting at or below x
        return out

    class TracedBSDF(mi.BSDF):
        """A brdfkit model's formulas traced into Mitsuba (module docstring)."""

        traced = True

        def __init__(self, props, model: BRDF, grid: np.ndarray | None):
            mi.BSDF.__init__(self, props)
            form = model.formulas()
            self.model = model
            self.f_eval = drjit_version(form.eval)
            self.f_sample = drjit_version(form.sample)
            self.f_pdf = drjit_version(form.pdf)
            self.args = tuple(float(a) for a in form.args)
            self.grid = grid
            table = getattr(form, "table", None)  # TableFormulas: columns read by row_at
            self.columns = None if table else _columns(model.packed)
            if table and grid is None and kind != "spectral":
                # the table's columns one Dr.Jit array, read by dr.gather (mitsuba_rows)
                self.fixed = traced_row(mi, dr, model.packed, table)
            elif grid is None and kind != "spectral":
                # fixed per-channel values: colours built once
                self.fixed = tuple(c if isinstance(c, float) else mi.Color3f(*c.tolist())
                                   for c in self.columns)
            flags = mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.DiffuseReflection
            self.m_flags = flags
            self.m_components = [flags]

        def _params(self, si) -> tuple:
            if self.grid is None:
                return self.fixed if kind != "spectral" else tuple(self.columns)
            return tuple(c if isinstance(c, float) else interp(self.grid, c, si.wavelengths)
                         for c in self.columns)

        def _spectrum(self, f):
            """f_r (Float, Color3f or Spectrum) as this variant's Spectrum."""
            # three channels: a Color3f, or the Array3f that a select over a Color3f
            # column's comparison makes (a kernel choosing its channel by an index column)
            if kind == "mono" and dr.size_v(f) == 3:
                return mi.Spectrum(mi.luminance(f))
            return mi.Spectrum(f)

        def _value(self, si, light):
            v = si.wi
            f = self.f_eval(light.x, light.y, light.z, v.x, v.y, v.z, self._params(si))
            return self._spectrum(f) * light.z

        def _pdf(self, si, light):
            v = si.wi
            return self.f_pdf(light.x, light.y, light.z, v.x, v.y, v.z, *self.args)

        @staticmethod
        def _ok(si, light, active):
            # one-sided: 0 below the horizon (brdfkit's convention, and Mitsuba's BSDFs')
            return active & (si.wi.z > 0.0) & (light.z > 0.0)

        def eval(self, ctx, si, wo, active=True):
            return dr.select(self._ok(si, wo, active), self._value(si, wo), 0.0)

        def pdf(self, ctx, si, wo, active=True):
            return dr.select(self._ok(si, wo, active), self._pdf(si, wo), 0.0)

        def eval_pdf(self, ctx, si, wo, active=True):
            ok = self._ok(si, wo, active)
            return (dr.select(ok, self._value(si, wo), 0.0),
                    dr.select(ok, self._pdf(si, wo), 0.0))

        def sample(self, ctx, si, sample1, sample2, active=True):
            v = si.wi
            x, y, z = self.f_sample(v.x, v.y, v.z, sample2.x, sample2.y, *self.args)
            light = mi.Vector3f(x, y, z)
            p = self._pdf(si, light)
            # a sample below the horizon or with pdf 0 carries no weight
            ok = self._ok(si, light, active) & (p > 0.0)
            bs = dr.zeros(mi.BSDFSample3f)
            bs.wo = light
            bs.pdf = dr.select(ok, p, 0.0)
            bs.eta = 1.0
            bs.sampled_type = mi.UInt32(+mi.BSDFFlags.GlossyReflection)
            bs.sampled_component = 0
            weight = self._value(si, light) / dr.select(ok, p, 1.0)
            return bs, dr.select(ok, weight, 0.0)

        def eval_diffuse_reflectance(self, si, active=True):
            # Mitsuba uses it for AOVs and denoiser guides only
            return dr.zeros(mi.Spectrum)

        def traverse(self, callback):
            pass

        def parameters_changed(self, keys):
            pass

        def to_string(self):
            return f"BrdfkitBSDF[traced, {self.model!r}]"

    return TracedBSDF
