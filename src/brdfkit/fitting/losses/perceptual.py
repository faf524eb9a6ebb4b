"""Neumann et al. 1999's perceptually based loss (§1.1, §5; our formulation, in
:mod:`brdfkit.fitting.losses`): S_p(E_f, E_a), E_f = M_p(|ln((m + τ_c)/(y + τ_c))|) over the
samples, E_a = M_p over θ_t of |ln(a_m(θ_t)/a_t(θ_t))|."""

from __future__ import annotations

import numpy as np

from brdfkit.fitting.losses._base import Loss

__all__ = ["P_SMOOTH", "TAU_REL", "PERCEPTUAL_THETA_DEG", "Perceptual"]

#: Power of the smooth maximum of the perceptual loss.
P_SMOOTH = 8.0
#: Floor of the perceptual relative error, as a fraction of the channel's mean y.
TAU_REL = 1e-2
#: θ_i of the albedo term (degrees); its quadrature has 24 × 12 nodes per angle.
PERCEPTUAL_THETA_DEG = tuple(float(t) for t in range(0, 81, 10))


def _power_mean(e, w, p=P_SMOOTH):
    s = np.sum(w * e ** p) / np.sum(w)
    return float(s ** (1.0 / p))


class Perceptual(Loss):
    name = "perceptual"
    reference = "Neumann et al. 1999 §1.1"
    needs_albedo = True  # the linear part solved under L2; stage iii frees everything

    def value(self, m, y, w, *, mask=None, albedo_m=None, albedo_t=None) -> float:
        tau = TAU_REL * (w @ y) / np.sum(w)  # per channel
        # both clamped at 0 before the floor: the log ratio of a negative value is undefined
        e_f = np.abs(np.log((np.maximum(m, 0.0) + tau) / (np.maximum(y, 0.0) + tau)))
        ef = _power_mean(e_f, w[:, None] * np.ones_like(e_f))
        tiny = 1e-12  # an albedo of exactly 0 (a black model) has an infinite log ratio
        e_a = np.abs(np.log(np.maximum(albedo_m, tiny) / np.maximum(albedo_t, tiny)))
        ea = _power_mean(e_a, np.ones_like(e_a))
        return float((0.5 * (ef ** P_SMOOTH + ea ** P_SMOOTH)) ** (1.0 / P_SMOOTH))

    def albedo_nodes(self):
        from brdfkit.fitting.samples import albedo_nodes

        return albedo_nodes(PERCEPTUAL_THETA_DEG, n_u=24, n_phi=12)
