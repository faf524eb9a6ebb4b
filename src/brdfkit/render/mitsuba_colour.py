"""
Colour mapping of the Mitsuba bridge: a model's channels to a variant's spectrum
================================================================================

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
  :func:`~brdfkit.render.mitsuba_bridge.spectral_model` builds such a model from
  parameter callables of λ.

Public objects
--------------
- :data:`LUMINANCE`, :data:`RGB_GRID` — Rec. 709 weights; the grid of the RGB basis table.
- :func:`check_wavelengths` — a model's channel wavelengths, validated.
- :class:`ColourMap` — f_r channels → one variant's spectrum per lane (the table above).

References
----------
- W. Jakob, J. Hanika, *A Low-Dimensional Function Space for Efficient
  Spectral Upsampling*, Computer Graphics Forum 38(2), 2019.
"""

from __future__ import annotations

import numpy as np

from brdfkit.colour import MITSUBA_LUMINANCE
from brdfkit.errors import ParameterError
from brdfkit.models import BRDF

__all__ = ["LUMINANCE", "RGB_GRID", "ColourMap", "check_wavelengths"]

#: Rec. 709 luminance weights of linear sRGB (Mitsuba's ``luminance``; ITU-R BT.709).
LUMINANCE = MITSUBA_LUMINANCE  # brdfkit.colour: as Mitsuba's own conversion (traced route)


def check_wavelengths(wavelengths, model: BRDF) -> np.ndarray | None:
    """*wavelengths* (nm, one per channel of *model*, increasing) as an array; None stays."""
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


class ColourMap:
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
