"""
Fitting models to measured materials
====================================

Layer 3 (``docs/architecture.md``): uses models, analysis, data and pumping.

- :func:`~brdfkit.fitting.procedure.fit` — fit any model (pumped ones included) to
  any target; returns a :class:`~brdfkit.fitting.procedure.FitResult` with every
  metric, the albedos and a convergence record.
- :mod:`~brdfkit.fitting.losses` — the losses (one registered object each) and their
  weights.
- :mod:`~brdfkit.fitting.samples` — the MERL-grid samples, their measure, the
  albedo quadrature.
- :mod:`~brdfkit.fitting.batch` — batches of fits (``brdfkit fit … --out``):
  resumable, written row by row, local processes or a Dask cluster.

See ``docs/fitting.md``.
"""

from brdfkit.fitting.losses import LOSSES
from brdfkit.fitting.procedure import PROCEDURE_NAMES, STATUS_MESSAGES, FitResult, fit

#: Names of the procedures a fit accepts (brdfkit.fitting.procedure.PROCEDURES and "auto").
PROCEDURES = PROCEDURE_NAMES

__all__ = ["fit", "FitResult", "LOSSES", "PROCEDURES", "STATUS_MESSAGES"]
