"""
A draft of a pumped model: the same stages on coarser albedo tables
===================================================================

:func:`pump` tabulates each stage's albedo to :data:`~brdfkit.pumping.table.INTERP_TOL`
(3e-6) with the engine at :data:`~brdfkit.pumping.table.ENGINE_TOL` (1e-8): 0.3-1 s for
``modified-phong`` pumped twice, nearly all of it in the albedo engine. A live view
(the explorer's slider, issue 23) needs a new parameter drawn within 0.1 s; it draws
:func:`draft_pump` first, the same operator on tables built to :data:`DRAFT_TABLE_TOL`
with the engine at :data:`DRAFT_ENGINE_TOL` (5-15x cheaper), and the exact model
after it. The draft's values are within :data:`DRAFT_REL_TOL` (relative) of the exact
pumped model's (``tests/test_explorer_draft.py``); it is drawn, never analysed: its
table's margin assumes the exact engine's error, so its albedo may exceed 1 by about
DRAFT_TABLE_TOL.
"""

from __future__ import annotations

from brdfkit.models._base import BRDF
from brdfkit.pumping.operator import PumpedBRDF, _check_times
from brdfkit.pumping.table import build_albedo_table

__all__ = ["DRAFT_ENGINE_TOL", "DRAFT_NN_START", "DRAFT_REL_TOL", "DRAFT_TABLE_TOL",
           "draft_pump"]

#: Interpolation tolerance of a draft's albedo tables (the exact: 3e-6): 1e-3 of an
#: albedo, a third of a pixel of the explorer's 0-1 albedo plot (~300 pixels high).
DRAFT_TABLE_TOL = 1e-3
#: Albedo engine accuracy of a draft's tables (the exact: 1e-8): ten times finer than
#: DRAFT_TABLE_TOL, so that the interpolation error dominates.
DRAFT_ENGINE_TOL = 1e-4
#: Intervals a draft's table starts from (the exact: 16), doubled until DRAFT_TABLE_TOL
#: holds: 17 engine calls where 8 intervals suffice (modified-phong's first stage).
DRAFT_NN_START = 8
#: The draft's stated accuracy: |f_draft − f| ≤ DRAFT_REL_TOL · f. f/g moves by the
#: relative error of g, and the tables' error is ≤ 2·DRAFT_TABLE_TOL + the engine's
#: (absolute): measured ≤ 3.2e-3 for modified-phong n = 5-500 twice pumped; half a
#: percent is below what the explorer's plots show, and the exact model follows.
DRAFT_REL_TOL = 5e-3


def draft_pump(model: BRDF, g: str = "max", *, times: int = 1) -> BRDF:
    """*model* pumped *times* times with g ``"max"`` or ``"controlled"`` as
    :func:`~brdfkit.pumping.pump` does (Neumann et al. 1999, eqs. 16, 20, 21), on albedo
    tables to :data:`DRAFT_TABLE_TOL` (module docstring: a draft to draw, not to analyse)."""
    _check_times("draft_pump", model, times)
    for _ in range(int(times)):
        table = build_albedo_table(model, tol=DRAFT_TABLE_TOL, engine_tol=DRAFT_ENGINE_TOL,
                                   nn_start=DRAFT_NN_START)
        model = PumpedBRDF(model, g, table=table)
    return model
