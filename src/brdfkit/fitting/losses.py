"""
Fitting losses, with their weights
==================================

Notation: for sample j (a MERL cell, :mod:`brdfkit.fitting.samples`) and
channel c, y_jc = f̂(ω_i, ω_o)·cos θ_i is the target's cosine-weighted value
and m_jc = f(ω_i, ω_o)·cos θ_i the model's; w_j is the cell's measure in
(ω_i, ω_o) (eq. (2) there), W = Σ_j w_j. Every loss averages over the C
channels (so a grey and an RGB fit are on one scale) and over the measure
(dividing by W: a loss is a mean over the (ω_i, ω_o) domain, not a sum that
grows with the number of samples).

==========  =========================================================  =====================
name        value                                                      reference
==========  =========================================================  =====================
l1          (1/C) Σ_c Σ_j w_j |m_jc − y_jc| / W                        Nielsen et al. 2015
l2          (1/C) Σ_c Σ_j w_j (m_jc − y_jc)² / W                       Nielsen et al. 2015
ngan        √[(1/C) Σ_c Σ_j w_j (m_jc − y_jc)² / W] over θ_i, θ_o ≤    Ngan et al. 2005
            80° only (their cut-off, applied whatever ``theta_max``)   (bbm's nganL2)
log         (1/C) Σ_c Σ_j w_j (ln(1 + m_jc) − ln(1 + y_jc))² / W       Löw et al. 2012
perceptual  S_p(E_f, E_a) with E_f = M_p(|ln((m + τ_c)/(y + τ_c))|),   Neumann et al. 1999
            E_a = M_p over θ_t of |ln(a_m(θ_t)/a_t(θ_t))|              §1.1, §5
==========  =========================================================  =====================

Perceptual formulation (ours; the paper states the goal, not a formula):
Neumann et al. ask for the *maximal relative errors* of the cosine-weighted
BRDF (point-light response) and of the albedo (sky-light response),
minimised simultaneously, and justify the relative error by the
logarithmic response of vision. We measure a relative error as a log ratio
(|ln(m/y)| ≈ |m − y|/y for small errors, symmetric in over- and
under-estimation). τ_c = 10⁻² · (Σ_j w_j y_jc / W) is a floor: without it
the maximum is set by the darkest bins (a relative error of a value near 0
is unbounded; no observer sees it). The maxima are made smooth by the power
mean M_p(e) = (Σ w e^p / Σ w)^{1/p} with p = 8 (→ max as p → ∞; at p = 8
the largest errors dominate while the loss stays differentiable), over
samples (weights w_j) and over the albedo angles θ_t (equal weights); the
two are combined by the same power mean S_p(A, B) = ((A^p + B^p)/2)^{1/p}.
The albedos a_m, a_t are integrated with
:func:`brdfkit.fitting.samples.albedo_nodes` (θ_t = 0°, 10°, …, 80°).
"""

from __future__ import annotations

import numpy as np

__all__ = ["LOSSES", "loss_value", "P_SMOOTH", "TAU_REL", "NGAN_THETA_MAX_DEG"]

#: Loss names, in the order metrics are reported.
LOSSES = ("l1", "l2", "ngan", "log", "perceptual")
#: Power of the smooth maximum of the perceptual loss.
P_SMOOTH = 8.0
#: Floor of the perceptual relative error, as a fraction of the channel's mean y.
TAU_REL = 1e-2
#: Ngan et al.'s cut-off of θ_i and θ_o, degrees.
NGAN_THETA_MAX_DEG = 80.0


def _power_mean(e, w, p=P_SMOOTH):
    s = np.sum(w * e ** p) / np.sum(w)
    return float(s ** (1.0 / p))


def loss_value(name: str, m, y, w, *, ngan_mask=None, albedo_m=None, albedo_t=None) -> float:
    """The loss *name* (module docstring) of model values *m* against target *y*.

    Parameters
    ----------
    m, y : ndarray (N, C)
        Cosine-weighted values f·cos θ_i of model and target.
    w : ndarray (N,)
        Sample measures.
    ngan_mask : ndarray (N,) of bool
        Samples with θ_i, θ_o ≤ 80° (``ngan`` only).
    albedo_m, albedo_t : ndarray (T, C)
        Albedos of model and target (``perceptual`` only).
    """
    if name == "l1":
        return float(np.sum(w[:, None] * np.abs(m - y)) / (np.sum(w) * y.shape[1]))
    if name == "l2":
        return float(np.sum(w[:, None] * (m - y) ** 2) / (np.sum(w) * y.shape[1]))
    if name == "ngan":
        k = ngan_mask
        d = m[k] - y[k]
        # a search step to an extreme lobe (values ~1e160) squares to inf: the loss is then
        # inf, which the optimiser rejects; no warning for it
        with np.errstate(over="ignore"):
            return float(np.sqrt(np.sum(w[k, None] * d * d) / (np.sum(w[k]) * y.shape[1])))
    if name == "log":
        # log1p of a negative m (a model below 0 is not a BRDF): clamped at 0 so the loss
        # stays finite; no registered model goes below 0
        d = np.log1p(np.maximum(m, 0.0)) - np.log1p(np.maximum(y, 0.0))
        return float(np.sum(w[:, None] * d * d) / (np.sum(w) * y.shape[1]))
    if name == "perceptual":
        tau = TAU_REL * (w @ y) / np.sum(w)  # per channel
        # both clamped at 0 before the floor: the log ratio of a negative value is undefined
        e_f = np.abs(np.log((np.maximum(m, 0.0) + tau) / (np.maximum(y, 0.0) + tau)))
        ef = _power_mean(e_f, w[:, None] * np.ones_like(e_f))
        tiny = 1e-12  # an albedo of exactly 0 (a black model) has an infinite log ratio
        e_a = np.abs(np.log(np.maximum(albedo_m, tiny) / np.maximum(albedo_t, tiny)))
        ea = _power_mean(e_a, np.ones_like(e_a))
        return float((0.5 * (ef ** P_SMOOTH + ea ** P_SMOOTH)) ** (1.0 / P_SMOOTH))
    raise ValueError(name)  # unreachable: names are validated by fit()
