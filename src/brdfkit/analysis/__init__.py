"""
Analysis: albedo, plausibility verdicts and Lewis's Table 2
===========================================================

Public objects
--------------
- :func:`albedo`, :class:`AlbedoResult` — deterministic directional albedo
  with an error estimate (:mod:`brdfkit.analysis.albedo`).
- :func:`albedo_mc` — importance-sampled Monte-Carlo albedo.
- :func:`hemispherical_albedo` — ρ_hh.
- :func:`H_s` — Lewis's specular integral (§4.1, Fig. 5).
- :func:`check`, :class:`Verdict` — reciprocity and energy verdicts
  (:mod:`brdfkit.analysis.plausibility`).
- :func:`table2` — Lewis's Table 2 regenerated for every registered model
  (:mod:`brdfkit.analysis.table2`).
"""

from brdfkit.analysis.albedo import AlbedoResult, H_s, albedo, albedo_mc, hemispherical_albedo

__all__ = ["AlbedoResult", "H_s", "albedo", "albedo_mc", "hemispherical_albedo"]

try:  # the verdict modules import lazily-heavy parts; keep albedo importable on its own
    from brdfkit.analysis.plausibility import Verdict, check  # noqa: F401

    __all__ += ["Verdict", "check"]
except ImportError:  # pragma: no cover - during development
    pass
