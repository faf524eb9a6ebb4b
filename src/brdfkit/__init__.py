"""
brdfkit — physically plausible reflectance models
==================================================

Evaluate analytic BRDFs, measure their albedo, certify whether they are
physically plausible, pump up their albedo, fit them to measured materials
and show them.

Conventions (stated once, here)
-------------------------------
- **Frame.** Local shading frame with the surface normal ``n = +z``.
- **Directions** are unit vectors in float64 arrays of shape ``(..., 3)``.
  Both point *away* from the surface: ``wi`` toward the light (Lewis's S,
  Neumann's L, Nielsen's ω_i) and ``wo`` toward the viewer (V, ω_o).
  ``eval`` refuses (:class:`BrdfkitError` naming ``wi``/``wo``, the norm and
  the fix) a direction whose squared norm differs from 1 by more than
  ``brdfkit.models._base.UNIT_TOL`` = 1e-3 — tested in the compiled pass, at
  no measurable cost. That catches scaled vectors and unnormalised sums while
  float32 data (|‖w‖² − 1| ≲ 4e-7) and hand-typed directions such as
  (0.2, 0, −0.98) pass; brdfkit never renormalises, the kernels take the
  components as given. ``wi`` and ``wo`` broadcast against each other
  (leading axes), or the error names both shapes.
- **BRDF.** ``model.eval(wi, wo)`` returns f_r in 1/sr **without** the cosine
  factor (pbrt's choice). Mitsuba's ``BSDF.eval`` includes cos θ_o; where the
  two meet (tests, benchmarks, rendering) the conversion is written out.
- **Below the horizon** (cos θ_i ≤ 0 or cos θ_o ≤ 0) the BRDF is 0, never NaN.
- **Colour.** Reflectance parameters may be given per channel (RGB or a
  spectrum); they broadcast against a trailing channel axis, and a coloured
  model returns ``(..., C)``. A model with only scalar parameters returns
  ``(...)``.
- **Angles** are radians in the API; the command line takes degrees and says
  so.
- **Albedo** a(ω_i) = ∫ f_r(ω_i, ω_o) cos θ_o dω_o (Lewis's k_ρ, Neumann's a).
- **Randomness.** Monte-Carlo code takes an explicit seed or
  :class:`numpy.random.Generator`; samplers take the uniform numbers ``u``.

Public objects
--------------
- :func:`brdfkit.model` — build a registered model by name, or a measured
  material by its spec (``merl:nickel``, ``rgl:NAME``, ``nielsen:NAME``, a
  ``.binary`` path): the one dispatcher (:mod:`brdfkit.spec`).
- :func:`brdfkit.model_params` — the parameter declarations a spec accepts.
- :func:`brdfkit.compensate` — energy compensation of a model (Kulla–Conty,
  Turquin; :mod:`brdfkit.compensation`, ``docs/compensation.md``).
- :class:`brdfkit.ModelSpec` — what to build, its parameters and the operators
  applied to it, from the command line's words or a dict (:mod:`brdfkit.spec`).
- :func:`brdfkit.material` / :func:`brdfkit.materials` — the built-in
  measured materials (:mod:`brdfkit.data`).
- :data:`brdfkit.MODELS` — the registry: canonical name → model class.
- :func:`brdfkit.model_names` — the canonical names.
- :func:`brdfkit.clear_caches` / :func:`brdfkit.cache_info` — every in-process cache
  (bounded, registered: :mod:`brdfkit._cache`).
- :mod:`brdfkit.geometry`, :mod:`brdfkit.fresnel`, :mod:`brdfkit.halfangle`
  — the shared parts the models are built from.

References
----------
- [Lewis1993] R. R. Lewis, *Making Shaders More Physically Plausible*, 1993.
- [Neumann1999] L. Neumann, A. Neumann, L. Szirmay-Kalos, *Reflectance Models
  by Pumping up the Albedo Function*, 1999.
- [Nielsen2015] J. B. Nielsen, J. R. Frisvad, K. Conradsen, H. Aanæs,
  *Addressing Grazing Angle Reflections in Phong Models*.
- [Walter2007] B. Walter, S. R. Marschner, H. Li, K. E. Torrance,
  *Microfacet Models for Refraction through Rough Surfaces*, EGSR 2007.
"""

from brdfkit._cache import cache_info, clear_caches
from brdfkit.data import material, materials
from brdfkit.errors import BrdfkitError, ParameterError, UnknownModelError
from brdfkit.models import BRDF, MODELS, Param, model_names
from brdfkit.spec import ModelSpec, model, model_params

__all__ = [
    "BRDF",
    "MODELS",
    "ModelSpec",
    "BrdfkitError",
    "Param",
    "ParameterError",
    "UnknownModelError",
    "cache_info",
    "clear_caches",
    "compensate",
    "material",
    "materials",
    "model",
    "model_names",
    "model_params",
]

__version__ = "0.1.0"


def compensate(model, method: str = "kulla-conty"):
    """:func:`brdfkit.compensation.compensate`: *model* with its lost energy restored by
    *method* (``"kulla-conty"`` or ``"turquin"``). Imported on first use, like pumping
    (``import brdfkit`` does not pay for the albedo engine)."""
    from brdfkit.compensation import compensate as _compensate

    return _compensate(model, method)
