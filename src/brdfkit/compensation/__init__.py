"""
Energy compensation
===================

A microfacet lobe models one scattering event: the energy that real surfaces
send back after bounces between facets is missing, most at high roughness (the
white furnace of GGX at α = 1 reads E_avg ≈ 0.38). Production rendering restores
it with one of two operators, both applied here to **any** isotropic model whose
albedo the engine computes:

- **Kulla & Conty 2017** (``"kulla-conty"``): f = f_base + f_ms,
  f_ms = F_ms (1 − E(μ_o))(1 − E(μ_i))/(π (1 − E_avg)), with
  F_ms = F_avg² E_avg/(1 − F_avg (1 − E_avg)) for a coloured Fresnel factor
  (the sum of the bounces); reciprocal when the base is;
- **Turquin 2019** (``"turquin"``): f = f_base (1 + F₀ (1 − E(μ_i))/E(μ_i)), the
  factor taken at ω_i, the direction brdfkit's albedo holds fixed; not reciprocal.

E is the albedo of the base's white (F = 1) form
(:meth:`brdfkit.models.BRDF.fresnel_split`), tabulated by the albedo engine on
the shared grid (:mod:`brdfkit.compensation.table`). :func:`compensate` returns a
model like any other: evaluated by a compiled kernel, sampled, analysed, pumped
(Kulla–Conty), fitted, rendered. Theory, derivations and accuracy:
``docs/compensation.md``.

Modules
-------
- :mod:`brdfkit.compensation.operator` — :func:`compensate`, :class:`CompensatedBRDF`,
  the registry :data:`METHODS`.
- :mod:`brdfkit.compensation.table` — :class:`CompensationTable`: E(μ), E_avg and
  their accuracy.
- :mod:`brdfkit.compensation.kernels` — the compiled kernels.

Public objects
--------------
- :func:`compensate`, :func:`compensation_method`, :data:`METHODS`, :class:`Method`.
- :class:`CompensatedBRDF`, :class:`CompensationWarning`.
- :class:`CompensationTable`, :func:`compensation_table`, :data:`TABLE_TOL`,
  :data:`ENGINE_TOL`.

References
----------
- C. Kulla, A. Conty, *Revisiting Physically Based Shading at Imageworks*, SIGGRAPH
  2017 course "Physically Based Shading in Theory and Practice" (energy compensation,
  F_avg and F_ms).
- E. Turquin, *Practical multiple scattering compensation for microfacet models*,
  Industrial Light & Magic technical report, 2019 (eq. 10).
"""

from brdfkit.compensation.operator import (
    METHODS,
    CompensatedBRDF,
    CompensationWarning,
    Method,
    compensate,
    compensation_method,
)
from brdfkit.compensation.table import (
    ENGINE_TOL,
    TABLE_TOL,
    CompensationTable,
    compensation_table,
)

__all__ = [
    "ENGINE_TOL",
    "METHODS",
    "TABLE_TOL",
    "CompensatedBRDF",
    "CompensationTable",
    "CompensationWarning",
    "Method",
    "compensate",
    "compensation_method",
    "compensation_table",
]
