"""
Reflectance models
==================

One module per family; every model is registered in :data:`MODELS`.

- :mod:`~brdfkit.models.diffuse` — Lambert, Neumann–Neumann, Minnaert.
- :mod:`~brdfkit.models.phong` — the Phong family of all three papers.
- :mod:`~brdfkit.models.microfacet` — Torrance–Sparrow, Cook–Torrance, Ward,
  He–Torrance and the modern Walter et al. microfacet model.
"""

# Importing the family modules registers their models.
from brdfkit.models import diffuse, microfacet, phong  # noqa: E402,F401,I001
from brdfkit.models._base import BRDF, Lobe, Param, eval_pairs
from brdfkit.models._registry import MODELS, model, model_names, register, resolve

__all__ = ["BRDF", "Lobe", "MODELS", "Param", "eval_pairs", "model", "model_names", "register",
           "resolve"]
