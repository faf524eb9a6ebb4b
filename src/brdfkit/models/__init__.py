"""
Reflectance models
==================

One module per family; every model is registered in :data:`MODELS`.

- :mod:`~brdfkit.models.diffuse` — Lambert, Neumann–Neumann, Minnaert.
- :mod:`~brdfkit.models.phong` — the Phong family of all three papers.
- :mod:`~brdfkit.models.microfacet` — Torrance–Sparrow, Cook–Torrance, Ward,
  He–Torrance and the modern Walter et al. microfacet model.
"""

from brdfkit.models._base import BRDF, DerivedBRDF, Lobe, Param, eval_pairs
from brdfkit.models._registry import MODELS, model, model_names, register, resolve

# Importing the family modules registers their models, in this order: the order of
# `brdfkit models`, of the README's model table and of Table 2.
# isort: off
from brdfkit.models import diffuse, phong, microfacet  # noqa: E402,F401
# isort: on

__all__ = ["BRDF", "DerivedBRDF", "Lobe", "MODELS", "Param", "eval_pairs", "model", "model_names", "register",
           "resolve"]
