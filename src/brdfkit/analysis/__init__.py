"""
Analysis: albedo, plausibility verdicts and Lewis's Table 2
===========================================================

Public objects
--------------
- :func:`albedo`, :class:`AlbedoResult` — deterministic directional albedo
  with an error estimate and a status per angle (module
  :mod:`brdfkit.analysis.albedo_engine`; its compiled core is
  :mod:`brdfkit.analysis.quadrature`).
- :func:`albedo_mc` — importance-sampled Monte-Carlo albedo, a second method
  (:mod:`brdfkit.analysis.monte_carlo`).
- :func:`hemispherical_albedo`, :class:`HemisphericalAlbedo` — ρ_hh over the engine
  (:mod:`brdfkit.analysis.hemispherical`).
- :func:`H_s` — Lewis's specular integral (§4.1, Fig. 5;
  :mod:`brdfkit.analysis.specular_integral`).
- :func:`check`, :class:`Verdict` — reciprocity and energy verdicts
  (:mod:`brdfkit.analysis.plausibility`).
- :func:`table2` — Lewis's Table 2 regenerated for every registered model
  (:mod:`brdfkit.analysis.lewis_table2`).
- :mod:`brdfkit.analysis.energy_verdict` — one row of the energy table (issue 22):
  check's verdict with the white furnace, E_avg and each number's accuracy.

References
----------
- [Lewis1993] eqs. (15)–(24), Figs. 5, 7–9, Table 2.
- [Neumann1999] §1.2, §2.1, Fig. 1.
"""

from brdfkit.analysis.albedo_engine import AlbedoResult, albedo
from brdfkit.analysis.hemispherical import HemisphericalAlbedo, hemispherical_albedo
from brdfkit.analysis.lewis_table2 import table2
from brdfkit.analysis.monte_carlo import albedo_mc
from brdfkit.analysis.plausibility import Verdict, check
from brdfkit.analysis.specular_integral import H_s

__all__ = ["AlbedoResult", "H_s", "HemisphericalAlbedo", "Verdict", "albedo", "albedo_mc",
           "check", "hemispherical_albedo", "table2"]
