"""The log loss (Löw et al. 2012): (1/C) Σ_c Σ_j w_j (ln(1 + m_jc) − ln(1 + y_jc))² / W."""

from __future__ import annotations

import numpy as np

from brdfkit.fitting.losses._base import Loss

__all__ = ["Log"]


class Log(Loss):
    name = "log"
    reference = "Löw et al. 2012"
    # the linear part solved under L2 (an approximation: stage iii then frees every
    # parameter under the loss itself)

    def value(self, m, y, w, *, mask=None, albedo_m=None, albedo_t=None) -> float:
        # log1p of a negative m (a model below 0 is not a BRDF): clamped at 0 so the loss
        # stays finite; no registered model goes below 0
        d = np.log1p(np.maximum(m, 0.0)) - np.log1p(np.maximum(y, 0.0))
        return float(np.sum(w[:, None] * d * d) / (np.sum(w) * y.shape[1]))
