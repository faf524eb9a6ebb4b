"""The L1 loss (Nielsen et al. 2015): (1/C) Σ_c Σ_j w_j |m_jc − y_jc| / W."""

from __future__ import annotations

import numpy as np

from brdfkit.fitting.losses._base import Loss

__all__ = ["L1"]


class L1(Loss):
    name = "l1"
    reference = "Nielsen et al. 2015"
    irls = True  # the linear part solved under L1 itself (IRLS): the projection is exact
    exact_projection = True

    def value(self, m, y, w, *, mask=None, albedo_m=None, albedo_t=None) -> float:
        return float(np.sum(w[:, None] * np.abs(m - y)) / (np.sum(w) * y.shape[1]))

    def from_residual(self, total, w_sum, n_channels):
        return total / (w_sum * n_channels)
