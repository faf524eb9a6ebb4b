"""Ngan et al. 2005's cosine-weighted RMS (bbm's nganL2):
√[(1/C) Σ_c Σ_j w_j (m_jc − y_jc)² / W] over the samples with θ_i, θ_o ≤ 80° only (their
cut-off, applied whatever ``theta_max``)."""

from __future__ import annotations

import math

import numpy as np

from brdfkit.fitting.losses._base import Loss

__all__ = ["NGAN_THETA_MAX_DEG", "Ngan"]

#: Ngan et al.'s cut-off of θ_i and θ_o, degrees.
NGAN_THETA_MAX_DEG = 80.0


class Ngan(Loss):
    name = "ngan"
    reference = "Ngan et al. 2005"
    # the linear part is a least-squares solve over the same samples (sample_mask): with
    # all samples the "exact" projection was not (the Lafortune anchor fits of red-plastic
    # ended at 0.0104 where their own shape's optimum is 0.0087)
    exact_projection = True

    def value(self, m, y, w, *, mask=None, albedo_m=None, albedo_t=None) -> float:
        k = mask
        d = m[k] - y[k]
        # a search step to an extreme lobe (values ~1e160) squares to inf: the loss is then
        # inf, which the optimiser rejects; no warning for it
        with np.errstate(over="ignore"):
            return float(np.sqrt(np.sum(w[k, None] * d * d) / (np.sum(w[k]) * y.shape[1])))

    def sample_mask(self, samples):
        c = math.cos(math.radians(NGAN_THETA_MAX_DEG))
        return (samples.wi[:, 2] >= c) & (samples.wo[:, 2] >= c)

    def from_residual(self, total, w_sum, n_channels):
        return math.sqrt(total / (w_sum * n_channels))
