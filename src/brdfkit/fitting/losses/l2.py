"""The L2 loss (Nielsen et al. 2015): (1/C) Σ_c Σ_j w_j (m_jc − y_jc)² / W."""

from __future__ import annotations

import numpy as np

from brdfkit.fitting.losses._base import Loss

__all__ = ["L2"]


class L2(Loss):
    name = "l2"
    reference = "Nielsen et al. 2015"
    exact_projection = True  # the linear part is a least-squares solve of this loss

    def value(self, m, y, w, *, mask=None, albedo_m=None, albedo_t=None) -> float:
        return float(np.sum(w[:, None] * (m - y) ** 2) / (np.sum(w) * y.shape[1]))

    def from_residual(self, total, w_sum, n_channels):
        return total / (w_sum * n_channels)
