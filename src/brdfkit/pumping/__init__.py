"""
Albedo pumping-up
=================

Neumann, Neumann & Szirmay-Kalos (1999, §3) turn a symmetric BRDF f into a
brighter one, f*(L, V) = f(L, V)/g(L, V) (eq. 16), with g symmetric and
max(a(L), a(V)) ≤ g ≤ 1 (eq. 17), a the albedo (eq. 2): g₁ = max(a(L), a(V))
(eq. 20, ``"max"``) or the controlled g₂ = max(a(L), a(V), N·V, N·L) (eq. 21,
``"controlled"``). :func:`pump` applies either (or a user g) up to
:data:`MAX_TIMES` times and returns a model like any other: it evaluates
through a compiled kernel, samples with the base model's sampler, and can be
analysed, fitted, rendered and pumped again.

The derivation lives in ``docs/pumping.md``: the theorem a ≤ a* ≤ 1 (eqs.
18–19) re-derived, with the corrections to the paper (a* < 1 is not strict;
no g meets eq. 17 for an energy-gaining base, which brdfkit pumps with the
uncapped g₁ and a :class:`PumpingWarning`); what the controlled pumping bounds
(one pumping only, not repeated ones); the paper's n = 20 observations
quantified; eq. (22) against pumping; the albedo tables; and "Evaluation: one
lookup for a whole chain" (how k stages collapse into one lookup).

Modules
-------
- :mod:`brdfkit.pumping.operator` — :func:`pump`, :class:`PumpedBRDF`, g validation.
- :mod:`brdfkit.pumping.table` — :class:`AlbedoTable`, :func:`build_albedo_table`.
- :mod:`brdfkit.pumping.kernels` — the compiled chain and stage kernels.
- :mod:`brdfkit.pumping.surrogate` — :func:`~brdfkit.pumping.surrogate.surrogate`, the fast
  stand-in for a one-times pumped model that a fit evaluates (basis albedo tables per
  shape-parameter node, linear parameters combined; ``docs/pumping.md``, "Fitting a pumped
  model").
- :mod:`brdfkit.pumping.draft` — :func:`~brdfkit.pumping.draft.draft_pump`, the same
  stages on coarser tables (within 0.5 %): what the explorer draws while a slider moves.
- :mod:`brdfkit.tables` (shared with the models) — the grid variable and the
  compiled :class:`~brdfkit.tables.Lookup` the kernels read.

Public objects
--------------
- :func:`pump` — the operator.
- :class:`PumpedBRDF` — the result (a :class:`brdfkit.models.DerivedBRDF`).
- :class:`AlbedoTable`, :func:`build_albedo_table` — a stage's tabulated albedo.
- :class:`Lookup`, :func:`build_lookup` — the kernels' table of a function of
  cos θ (defined in :mod:`brdfkit.tables`).
- :func:`from_dict` — rebuild a (pumped) model from ``to_dict()``.
- :func:`pump_sequence` — the model and its 1 … k times pumped versions.
- :func:`mirror_radiance` — f(L, R(L)) cos θ_L, the paper's output radiance.
- :class:`PumpingWarning`.
- :data:`G_CHOICES` — the built-in g names; :data:`MAX_TIMES` — most pumpings.

References
----------
- [Neumann1999] eqs. (2), (3), (16)–(22), §3, §3.1, §3.2, §5.
"""

from brdfkit.pumping.operator import (
    CHAIN_DIP_TOL,
    G_CHOICES,
    G_FLOOR,
    MAX_TIMES,
    PumpedBRDF,
    PumpingWarning,
    from_dict,
    mirror_radiance,
    pump,
    pump_sequence,
)
from brdfkit.pumping.table import (
    ENGINE_ERR,
    ENGINE_TOL,
    INTERP_TOL,
    THETA_TOP,
    AlbedoTable,
    build_albedo_table,
)
from brdfkit.tables import LUT_CELLS, LUT_TOL, Lookup, build_lookup

__all__ = [
    "CHAIN_DIP_TOL",
    "ENGINE_ERR",
    "ENGINE_TOL",
    "G_CHOICES",
    "G_FLOOR",
    "INTERP_TOL",
    "LUT_CELLS",
    "LUT_TOL",
    "MAX_TIMES",
    "THETA_TOP",
    "AlbedoTable",
    "Lookup",
    "PumpedBRDF",
    "PumpingWarning",
    "build_albedo_table",
    "build_lookup",
    "from_dict",
    "mirror_radiance",
    "pump",
    "pump_sequence",
]
