"""
Importance sampling of measured materials from their own values
===============================================================

A measured table or a compact fit has no closed-form sampler. Here one is made
from the material's values: per viewing angle θ_o (12 nodes, 0…88°) a
density of the half vector over a (θ_h, ψ) grid (ψ the azimuth of h relative
to ω_o's), bilinear in (cos θ_h, ψ) between vertex values proportional to the
integrand of the albedo, f̄(ω_i(h), ω_o) cos θ_i · 4(ω_o·h) — f̄ the mean over
the RGB channels, 4(ω_o·h) the Jacobian dω_i/dω_h of the mirror map
ω_i = 2(ω_o·h)h − ω_o — averaged over ±ψ
(:class:`~brdfkit.models.tabulated_sampling.TabulatedHalfVector`). It is mixed
with the cosine (weight :data:`COSINE_WEIGHT`), so the density is positive
wherever f can be (the whole upper hemisphere), whatever the table missed.

Resolution: θ_h vertices graded like the χ² binning,
θ_k = w·(exp(s_k ln(1 + (π/2)/w)) − 1) with s_k uniform in [0, 1] and w the
half-width of the material's sharpest lobe (:meth:`~brdfkit.models.BRDF.sharpest_lobe`),
so the first cells are ~w/15 wide for a metal's narrow peak and nearly uniform
for a diffuse material; 16 uniform ψ cells over [0, π].

Why per θ_o and in (θ_h, ψ), not one θ_h marginal for all views: measured
(``benchmarks/bench_measured_sampling.py``, N = 20 000, std of the albedo
estimator): against cosine sampling the 2-D tables cut the standard deviation
by 21–120x for nickel, gray-plastic and nielsen:bluebook, 3–11x for
violet-rubber, 1–3x for the near-Lambertian rgl:spectralon; a single θ_h
marginal is as good at θ_i = 0 but 2–30x worse than the 2-D tables at 45° and
75°, and worse than the cosine itself for diffuse materials off normal
incidence (the marginal, built at θ_o = 0, misplaces the cosine lobe).

Cost: 12 × 65 × 17 vertices × 2 signs ≈ 26 500 evaluations of the material,
once, on the first ``sample``/``pdf`` (measured 35–70 ms per material on the
loaded 2-core development machine). Unmeasured bins (NaN from a ``nearest``
lookup) and negative values count as 0 in the table (no energy is claimed
where none was measured; the cosine component still reaches them).

Public objects
--------------
- :class:`TabulatedSampler` — mixin giving a model ``sample``/``pdf`` from its values.
- :func:`tabulated_strategy` — the strategy (cosine + tabulated half vector) of a model.
- :func:`half_vector_values` — the vertex values of one model (for other grids).
- :func:`theta_h_edges` — the graded θ_h grid.
- :data:`COSINE_WEIGHT`.

References
----------
- T. Hesterberg, *Weighted Average Importance Sampling and Defensive Mixture
  Distributions*, Technometrics 37(2), 1995 (the defensive cosine component).
- J. Lawrence, S. Rusinkiewicz, R. Ramamoorthi, *Efficient BRDF Importance
  Sampling Using a Factored Representation*, ACM TOG 23(3), 2004 (tabulated
  per-view densities of measured BRDFs).
"""

from __future__ import annotations

import math

import numpy as np

from brdfkit.errors import ParameterError
from brdfkit.models.sampling import COSINE, Mixture, Strategy, StrategySampled
from brdfkit.models.tabulated_sampling import TabulatedHalfVector

__all__ = ["TabulatedSampler", "tabulated_strategy", "half_vector_values", "theta_h_edges",
           "COSINE_WEIGHT", "N_THETA_O", "N_THETA_H", "N_PSI", "THETA_O_MAX_DEG"]

#: Mixture weight of the cosine component (defensive: bounds the estimator's weight
#: f cos θ_i/pdf by 1/0.1 of what the tabulated part alone gives where it is poor).
COSINE_WEIGHT = 0.1
#: Table resolution: θ_o nodes, θ_h cells, ψ cells.
N_THETA_O, N_THETA_H, N_PSI = 12, 64, 16
#: The last θ_o node (beyond it the last table is used).
THETA_O_MAX_DEG = 88.0


def theta_h_edges(width: float, n: int = N_THETA_H) -> np.ndarray:
    """θ_h grid vertices graded for a lobe of half-width *width* (module docstring)."""
    w = min(max(float(width), 1e-5), 0.5 * math.pi)  # clamp: a declared width outside (0, π/2]
    s = np.linspace(0.0, 1.0, n + 1)
    e = w * np.expm1(s * math.log1p(0.5 * math.pi / w))
    e[-1] = 0.5 * math.pi  # the last edge exactly (rounding of expm1)
    return e


def half_vector_values(model, theta_o, theta_h, psi) -> np.ndarray:
    """The albedo integrand over h, g = f̄ cos θ_i · 4(ω_o·h), at the grid vertices
    (J, K + 1, L + 1): ω_o at θ_o[j] (azimuth 0), h at (θ_h[k], ±ψ[l]) (the mean of both
    signs); 0 where ω_i or ω_o·h is at or below the horizon."""
    theta_o = np.asarray(theta_o, dtype=np.float64)
    T, PSI = np.meshgrid(theta_h, psi, indexing="ij")
    s, c = np.sin(T), np.cos(T)
    # every node and both signs of ψ in one evaluation: h (2, K + 1, L + 1), ω_o (J,)
    h = np.stack([np.broadcast_to(s * np.cos(PSI), (2, *T.shape)),
                  np.stack([s * np.sin(PSI), -s * np.sin(PSI)]),
                  np.broadcast_to(c, (2, *T.shape))], axis=-1).reshape(-1, 3)
    wo = np.stack([np.sin(theta_o), np.zeros(theta_o.size), np.cos(theta_o)], axis=-1)
    cos_oh = wo @ h.T  # (J, M)
    wi = 2.0 * cos_oh[..., None] * h[None] - wo[:, None, :]
    wi /= np.linalg.norm(wi, axis=-1, keepdims=True)  # unit to rounding
    up = (wi[..., 2] > 0.0) & (cos_oh > 0.0)
    wo_b = np.broadcast_to(wo[:, None, :], wi.shape)
    fr = np.asarray(model.eval(wi[up], wo_b[up]), dtype=np.float64)
    fbar = fr.reshape(fr.shape[0], -1).mean(axis=1)
    # unmeasured (NaN) and negative values claim no energy in the table
    fbar = np.where(np.isfinite(fbar) & (fbar > 0.0), fbar, 0.0)
    val = np.zeros(up.shape)
    val[up] = fbar * wi[up][:, 2] * 4.0 * cos_oh[up]
    return 0.5 * val.reshape(theta_o.size, 2, *T.shape).sum(axis=1)  # the mean over ±ψ


def tabulated_strategy(model, *, n_theta_o: int = N_THETA_O, n_theta_h: int = N_THETA_H,
                       n_psi: int = N_PSI, cosine_weight: float = COSINE_WEIGHT) -> Strategy:
    """Cosine + tabulated half-vector mixture for *model*, built from its values.

    Parameters (keyword-only)
    -------------------------
    n_theta_o, n_theta_h, n_psi : int
        Table resolution (θ_o nodes uniform on [0, 88°]; 1 node: θ_o = 0 only;
        ``n_theta_o = n_psi = 1``: the θ_o = 0 table, a θ_h marginal, for all views).
    cosine_weight : float
        Weight of the cosine component, in (0, 1].
    """
    for name, n in (("n_theta_o", n_theta_o), ("n_theta_h", n_theta_h), ("n_psi", n_psi)):
        if isinstance(n, bool) or not isinstance(n, int | np.integer) or n < 1:
            raise ParameterError(f"tabulated_strategy: {name} must be an integer >= 1; got "
                                 f"{n!r}")
    if not 0.0 < float(cosine_weight) <= 1.0:
        raise ParameterError(f"tabulated_strategy: cosine_weight must lie in (0, 1]; got "
                             f"{cosine_weight!r}")
    lobe = model.sharpest_lobe()
    width = lobe.width if lobe.kind == "half" else 0.5 * math.pi
    theta_o = np.radians(np.linspace(0.0, THETA_O_MAX_DEG, n_theta_o)) if n_theta_o > 1 \
        else np.zeros(1)
    th = theta_h_edges(width, n_theta_h)
    psi = np.linspace(0.0, math.pi, n_psi + 1)
    tab = TabulatedHalfVector(theta_o, th, psi, half_vector_values(model, theta_o, th, psi))
    return Mixture([COSINE, tab], [cosine_weight, 1.0 - cosine_weight])


class TabulatedSampler(StrategySampled):
    """Mixin (before the model's base class): ``sample``/``pdf`` from :func:`tabulated_strategy`,
    built on first use and kept. A model using it passes ``has_sampler=True``."""

    _tabulated: Strategy | None = None

    def _strategy(self, wo):
        if self._tabulated is None:
            self._tabulated = tabulated_strategy(self)
        return self._tabulated
