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

Losses as objects
-----------------
Each loss is one small class in its own module (:class:`~brdfkit.fitting.losses._base.Loss`:
its value, its sample mask, its linear solve, whether that solve makes variable
projection exact, whether it needs albedos), listed once in :data:`REGISTRY`;
:func:`loss` is the dispatcher, whose error lists the names. A new loss is one module
here and one entry in :data:`REGISTRY` (``docs/architecture.md``, "How to add a loss").

Public objects
--------------
- :data:`REGISTRY` — name → :class:`Loss` instance, in the order metrics are reported.
- :data:`LOSSES` — the names (the CLI's ``--loss`` choices).
- :func:`loss` — the dispatcher.
- :func:`loss_value` — the value of a loss given by name.
- :class:`Loss` and the losses :class:`L1`, :class:`L2`, :class:`Ngan`, :class:`Log`,
  :class:`Perceptual`; constants :data:`P_SMOOTH`, :data:`TAU_REL`,
  :data:`NGAN_THETA_MAX_DEG`.
"""

from __future__ import annotations

from brdfkit.errors import ParameterError
from brdfkit.fitting.losses._base import Loss
from brdfkit.fitting.losses.l1 import L1
from brdfkit.fitting.losses.l2 import L2
from brdfkit.fitting.losses.log import Log
from brdfkit.fitting.losses.ngan import NGAN_THETA_MAX_DEG, Ngan
from brdfkit.fitting.losses.perceptual import P_SMOOTH, TAU_REL, Perceptual

__all__ = ["REGISTRY", "LOSSES", "loss", "loss_value", "Loss", "L1", "L2", "Ngan", "Log",
           "Perceptual", "P_SMOOTH", "TAU_REL", "NGAN_THETA_MAX_DEG"]

#: Every loss, by name, in the order metrics are reported.
REGISTRY: dict[str, Loss] = {L.name: L() for L in (L1, L2, Ngan, Log, Perceptual)}
#: Loss names, in the order metrics are reported.
LOSSES = tuple(REGISTRY)


def loss(name) -> Loss:
    """The loss *name* (a :class:`Loss` is returned as it is); the error lists the names."""
    if isinstance(name, Loss):
        return name
    try:
        return REGISTRY[name]
    except (KeyError, TypeError):
        raise ParameterError(f"fit: loss must be one of {', '.join(LOSSES)}; got "
                             f"{name!r}") from None


def loss_value(name: str, m, y, w, *, ngan_mask=None, albedo_m=None, albedo_t=None) -> float:
    """The loss *name* (module docstring) of model values *m* against target *y*.

    Parameters
    ----------
    m, y : ndarray (N, C)
        Cosine-weighted values f·cos θ_i of model and target.
    w : ndarray (N,)
        Sample measures.
    ngan_mask : ndarray (N,) of bool
        The loss's sample mask (:meth:`Loss.sample_mask`; ``ngan``: θ_i, θ_o ≤ 80°).
    albedo_m, albedo_t : ndarray (T, C)
        Albedos of model and target (``perceptual`` only).
    """
    return loss(name).value(m, y, w, mask=ngan_mask, albedo_m=albedo_m, albedo_t=albedo_t)
