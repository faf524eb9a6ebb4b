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

Tables and parameters
---------------------
A model whose formulas read tables (``Formulas.tables = K``: a pumped model's albedo
lookups, a measured material's bins) gets its first K columns as above and the rest as
one Dr.Jit array, gathered from by the table primitives of :mod:`brdfkit.tables`
(:class:`~brdfkit.traced_tables.TableRow`, the one design for tables in the trace); a
table per wavelength of a grid is not traced (:func:`wavefront_reason`). ``traverse`` lists the
model's scalar and grey/RGB colour parameters by name, as Dr.Jit values in the row the
eval formula reads (differentiable unless the model has tables, which are rebuilt in
NumPy); ``parameters_changed`` rebuilds the model (``with_params``) and its sampler's
arguments. Design record: ``docs/architecture.md``, "Tables in the trace".

References
----------
- W. Jakob et al., *Mitsuba 3 renderer*, 2022 (``BSDF`` interface, "Custom
  plugins in Python"); Dr.Jit's symbolic and evaluated modes.
"""

from __future__ import annotations

import numpy as np

from brdfkit._dual import drjit_version
from brdfkit.models import BRDF
from brdfkit.traced_tables import TableRow, TracedTables


def traced_supported(model: BRDF, variant: str, grid: np.ndarray | None) -> bool:
    """Whether :func:`traced_class` can render *model* in *variant* (else the wavefront
    route): :func:`wavefront_reason` is None."""
    return wavefront_reason(model, variant, grid) is None


def wavefront_reason(model: BRDF, variant: str, grid: np.ndarray | None) -> str | None:
    """Why *model* cannot take the traced route in *variant* (one line), or None when it
    can: the model gives formulas, the variant is an ``llvm_*`` one, and its channels are
    grey, RGB in an RGB or mono variant, or a wavelength grid in a spectral one (a model
    with tables: grey in a spectral variant)."""
    form = model.formulas()
    if form is None:
        return f"{model.name}: no formulas (eval/sample/pdf are NumPy/Numba only)"
    if not variant.startswith("llvm"):
        return f"{model.name}: the {variant} variant (the traced route needs an llvm_* one)"
    n_c = model.n_channels or 1
    if n_c == 1:
        return None
    if "spectral" in variant:
        if grid is None:
            return (f"{model.name}: RGB channels in a spectral variant (give its "
                    "parameters on a wavelength grid: spectral_model)")
        if form.tables is not None and not np.all(
                model.packed[:, form.tables:] == model.packed[:1, form.tables:]):
            return (f"{model.name}: per-wavelength tables (a table read per grid point and "
                    "path is not traced)")
        return None
    if grid is None and n_c == 3:
        return None
    return f"{model.name}: {n_c} channels in {variant} (the traced route takes 1 or 3)"


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
            self.grid = grid
            flags = mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.DiffuseReflection
            self.m_flags = flags
            self.m_components = [flags]
            self._bind(model)
            # the exposed parameters (traverse): name → (column, Dr.Jit value)
            self.exposed = {name: (col, _exposed_value(mi, self.columns[col]))
                            for name, col in _parameter_columns(model, self.columns, kind)}

        def _bind(self, model: BRDF):
            """The model's formulas, sampler arguments, columns and tables."""
            form = model.formulas()
            self.model = model
            self.f_eval = drjit_version(form.eval)
            self.f_sample = drjit_version(form.sample)
            self.f_pdf = drjit_version(form.pdf)
            self.args = tuple(float(a) for a in form.args)
            packed = np.atleast_2d(model.packed)
            self.columns = _columns(packed[:, :form.tables])
            self.tables = None if form.tables is None else TracedTables(
                packed, form.tables, mi.Float, _combine)
            self.differentiable = form.tables is None  # a table of the parameters: no gradient
            if self.grid is None and kind != "spectral":
                # fixed per-channel values: colours built once
                self.fixed = tuple(c if isinstance(c, float) else mi.Color3f(*c.tolist())
                                   for c in self.columns)

        def _params(self, si) -> tuple:
            if self.grid is None:
                row = list(self.fixed if kind != "spectral" else self.columns)
            else:
                row = [c if isinstance(c, float) else interp(self.grid, c, si.wavelengths)
                       for c in self.columns]
            for col, value in self.exposed.values():
                row[col] = value  # a Dr.Jit variable: traverse's, gradients flow from it
            return tuple(row) if self.tables is None else TableRow(row, self.tables)

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
            # the scalar (and grey or RGB colour) parameters eval reads, by the model's
            # names; differentiable unless the model holds tables of them (rebuilt, no
            # gradient through them: parameters_changed)
            flag = (mi.ParamFlags.Differentiable if self.differentiable
                    else mi.ParamFlags.NonDifferentiable)
            for name, (_, value) in self.exposed.items():
                callback.put(name, value, +flag)

        def parameters_changed(self, keys):
            changed = {k: v for k, v in self.exposed.items() if k in keys or not keys}
            if not changed:
                return
            values = {k: _value_of(v) for k, (_, v) in changed.items()}
            # the model with the new values: its tables, sampler arguments and other
            # columns rebuilt (the exposed Dr.Jit values stay the ones eval reads)
            self._bind(self.model.with_params(**values))

        def to_string(self):
            return f"BrdfkitBSDF[traced, {self.model!r}]"

    def _combine(values: list):
        """Per-channel lookups as the row's colour (one: as it is)."""
        return values[0] if len(values) == 1 else mi.Color3f(*values)

    return TracedBSDF


def _parameter_columns(model: BRDF, columns: list, kind: str) -> list:
    """(name, column) of the model's scalar and colour parameters in their default packed
    slots (:func:`brdfkit.models._params.packed_indices`) whose column holds exactly the
    parameter's value in every channel (a model packing otherwise exposes fewer), and is a
    float or, outside spectral variants, three channels."""
    out = []
    for col, p in enumerate(model.params):
        if p.kind == "lobes" or col >= len(columns):
            break
        if p.kind not in ("scalar", "colour") or model.values.get(p.name) is None:
            continue
        value = np.broadcast_to(np.asarray(model.values[p.name], dtype=np.float64),
                                (np.atleast_2d(model.packed).shape[0],))
        c = columns[col]
        if isinstance(c, float) and np.all(value == c) or (
                kind != "spectral" and not isinstance(c, float) and c.size == 3
                and np.array_equal(c, value)):
            out.append((p.name, col))
    return out


def _exposed_value(mi, column):
    """A column as the Dr.Jit value traverse exposes: a Float, or a Color3f."""
    return mi.Float(column) if isinstance(column, float) else mi.Color3f(*column.tolist())


def _value_of(value):
    """An exposed Dr.Jit value as the model's parameter value (a float or 3 floats)."""
    a = np.array(value, dtype=np.float64).reshape(-1)
    return float(a[0]) if a.size == 1 else a.tolist()
