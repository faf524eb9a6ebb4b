"""
Nielsen et al. (2015) Fig. 1: measured and fitted spheres, computed
===================================================================

- ``nielsen-fig1`` — :func:`nielsen_fig1`: for two-layer-silver, violet-rubber,
  nickel and red-fabric2 (rows), the measured material (its MERL NBRDF surrogate)
  next to the L1 fits (Nielsen's three stages, :func:`brdfkit.fitting.fit`) of
  the α-mix (model ``nielsen``, eq. 3), its Phong variant (α = 0) and its
  Blinn–Phong variant (α = 1), all with Nielsen's Fresnel factor, η fitted per
  channel from :data:`ETA0` (η free, as in the paper's fits; ``--start eta=1.5`` on
  the command line).

Lighting, from the caption ("a directional light at glancing incidence (NE
hemisphere) and one at grazing incidence (SW hemisphere)"): two directional lights
of irradiance 1 on the sphere test configuration (V = +z), one at Φ_L = 60° from
the upper right (azimuth 45°), one at Φ_L = 85° from the lower left (azimuth
225°); the paper prints no angles, these are chosen. Exact renders
(:func:`brdfkit.render.render_sphere`, ``light_azimuth``), summed. One exposure
per row: the measured sphere's brightest pixel just unsaturated, held for its fits,
so brighter or darker fits show as such. Labels: "fitted to the MERL surrogate
(NBRDF)" (MERL data CC-BY-SA-4.0, Matusik et al. 2003).
"""

from __future__ import annotations

import math

import numpy as np

import brdfkit
from brdfkit.fitting import fit
from brdfkit.render import render_sphere, to_srgb8

__all__ = ["nielsen_fig1", "MATERIALS", "LIGHTS", "SIZE", "ETA0"]

#: Fig. 1 (a)–(d).
MATERIALS = ("two-layer-silver", "violet-rubber", "nickel", "red-fabric2")
#: (Φ_L, azimuth) of the two lights, degrees: glancing from NE, grazing from SW.
LIGHTS = ((60.0, 45.0), (85.0, 225.0))
SIZE = 160
#: Starting Fresnel index of the fits (η is fitted): a dielectric coat's typical value.
ETA0 = 1.5
#: The fitted models: label, parameters held fixed.
FITS = (("α-mix (eq. 3)", {}), ("Phong (α = 0)", {"alpha": 0.0}),
        ("Blinn–Phong (α = 1)", {"alpha": 1.0}))


def _render(m, size: int = SIZE) -> np.ndarray:
    out = 0.0
    for phi, az in LIGHTS:
        out = out + render_sphere(m, phi_l=math.radians(phi), light_azimuth=math.radians(az),
                                  size=size).radiance
    return np.nan_to_num(np.asarray(out, dtype=np.float64), nan=0.0)


def _fitted(name: str, label: str, fixed: dict, target, fits):
    """(model, L1) of one panel: from *fits* (already fitted: ``fits[name][label] =
    (params, L1)``, e.g. the fitting study's rows) when it has the panel, else fitted now."""
    if fits is not None and label in fits.get(name, {}):
        params, value = fits[name][label]
        return brdfkit.model("nielsen", **params), float(value)
    res = fit(brdfkit.model("nielsen", eta=ETA0, **fixed), target, loss="l1",
              procedure="nielsen", fixed=fixed or None)
    return res.model, float(res.value)


def nielsen_fig1(*, size: int = SIZE, fits: dict | None = None):
    """4 materials × (measured, α-mix, Phong, Blinn–Phong), two lights, L1 fits.

    *size*: side of each sphere in pixels. *fits*: fits made before (material name →
    {panel label of :data:`FITS` → (parameters of model ``nielsen``, L1)}), used instead of
    fitting again where given (``brdfkit reproduce`` passes the fitting study's).
    """
    import matplotlib.pyplot as plt

    from brdfkit.errors import ParameterError

    if not isinstance(size, int) or isinstance(size, bool) or not 16 <= size <= 2048:
        raise ParameterError(f"nielsen-fig1: size must be an integer in [16, 2048] (pixels); "
                             f"got {size!r}")

    cols = 1 + len(FITS)
    fig, axes = plt.subplots(len(MATERIALS), cols, figsize=(2.3 * cols, 2.5 * len(MATERIALS)),
                             squeeze=False)
    for r, name in enumerate(MATERIALS):
        target = brdfkit.model(f"merl:{name}")
        images = [(f"merl:{name}\n(NBRDF surrogate)", _render(target, size))]
        for label, fixed in FITS:
            model, value = _fitted(name, label, fixed, target, fits)
            images.append((f"{label}\nL1 = {value:.3g}", _render(model, size)))
        exposure = 1.0 / max(float(np.max(images[0][1])), 1e-300)
        for c, (label, rad) in enumerate(images):
            ax = axes[r, c]
            ax.imshow(to_srgb8(rad, exposure), interpolation="nearest")
            ax.set_xticks([])
            ax.set_yticks([])
            ax.set_title(label, fontsize=7)
    fig.suptitle("Nielsen et al. 2015, Fig. 1: measured (MERL surrogate) and L1-fitted Phong "
                 "variants (with Fresnel, η fitted)", fontsize=10)
    fig.text(0.01, 0.005, "Lights: Φ_L = 60° from the NE and 85° from the SW (chosen; the paper "
             "gives none); one exposure per row (the measured sphere's peak). Fitted to the "
             "MERL surrogate (NBRDF); MERL data CC-BY-SA-4.0.", fontsize=6)
    fig.tight_layout(rect=(0, 0.02, 1, 0.97))
    return fig
