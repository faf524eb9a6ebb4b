"""
Reflectance models
==================

One module per family; every model is registered in :data:`MODELS`.

- :mod:`~brdfkit.models.diffuse` — Lambert, Neumann–Neumann, Minnaert.
- :mod:`~brdfkit.models.rough_diffuse` — Oren–Nayar (full, qualitative), FON;
  :mod:`~brdfkit.models.eon` — EON and its clipped-LTC sampler.
- :mod:`~brdfkit.models.phong` — normalised Phong and Lewis's Phong, Blinn and
  energy-conserving shaders (R·V lobes, and N·H divided by N·L).
- :mod:`~brdfkit.models.blinn` — reciprocal N·H lobes: Lewis's reciprocal
  Phong–Blinn and N·H power series, Nielsen's modified Blinn–Phong.
- :mod:`~brdfkit.models.lafortune` — Lafortune's generalised cosine lobes.
- :mod:`~brdfkit.models.grazing` — Neumann et al.'s eq. (22) and Nielsen et
  al.'s eq. (3), Phong variants for grazing angles.
- :mod:`~brdfkit.models.microfacet` — the Walter et al. microfacet model;
  :mod:`~brdfkit.models.vgroove` — Torrance–Sparrow and Cook–Torrance;
  :mod:`~brdfkit.models.ward` — Ward; :mod:`~brdfkit.models.he_torrance` —
  He–Torrance–Sillion–Greenberg.
- :mod:`~brdfkit.models.microfacet_anisotropic` — Walter's model with the anisotropic
  GGX/Beckmann of :mod:`~brdfkit.models.anisotropic_distributions`;
  :mod:`~brdfkit.models.ashikhmin_shirley` — Ashikhmin & Shirley's anisotropic Phong.
- :mod:`~brdfkit.models.disney` — Burley's (2012) principled BRDF.

Shared by the families: :mod:`~brdfkit.models.sampling` (importance-sampling
strategies), :mod:`~brdfkit.models.specular` (Lewis's H_s),
:mod:`~brdfkit.models._params` (parameters declared once), :mod:`~brdfkit.models._drivers`
(the one loop generator).
"""

from brdfkit.models._base import BRDF, DerivedBRDF, FresnelSplit, Lobe, Param, eval_pairs
from brdfkit.models._registry import MODELS, model, model_names, register, resolve

# Importing the family modules registers their models, in this order: the order of
# `brdfkit models`, of the README's model table and of Table 2.
# isort: off
from brdfkit.models import diffuse, phong, blinn, lafortune, grazing  # noqa: E402,F401,I001
from brdfkit.models import rough_diffuse, eon  # noqa: E402,F401,I001
from brdfkit.models import microfacet, vgroove, ward, he_torrance  # noqa: E402,F401,I001
from brdfkit.models import microfacet_anisotropic, ashikhmin_shirley  # noqa: E402,F401,I001
from brdfkit.models import disney  # noqa: E402,F401,I001
# isort: on

__all__ = ["BRDF", "DerivedBRDF", "FresnelSplit", "Lobe", "MODELS", "Param", "eval_pairs",
           "model", "model_names", "register", "resolve"]
