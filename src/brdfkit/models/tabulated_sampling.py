"""
Half-vector sampling from a tabulated density
=============================================

:class:`TabulatedHalfVector` is a :class:`~brdfkit.models.sampling.Strategy`
for materials known only through values — a measured table, a neural fit — for
which no closed-form sampler exists. It holds, for a few viewing angles θ_o
(the *nodes*), a density of the half vector h over a grid in (θ_h, ψ),
ψ = φ_h − φ_o the azimuth of h relative to ω_o's (folded to |ψ| ∈ [0, π]:
the table is even in ψ, as an isotropic BRDF is), **bilinear** in
(x, ψ) = (cos θ_h, ψ) within each cell between its four vertex values —
continuous, so that quadratures of the density (the χ² test's expected
counts) converge, which a piecewise-constant table's jumps defeat. ω_i is the
mirror of ω_o about h, ω_i = 2(ω_o·h)h − ω_o, as in
:class:`~brdfkit.models.sampling.HalfVector`.

Density. dΩ_h = dx dψ, so with V_j the vertex values of table j scaled so that
∫∫ V_j dx dψ over [0, 1] × [0, π] is ½ (the other half: ψ < 0), the density of
h is the bilinear interpolant of V_j, mixed over the nodes,

    p_h(h | ω_o) = Σ_j w_j(θ_o) V_j(cos θ_h, |ψ|),

with node weights w_j(θ_o) linear between the two nodes around θ_o (clamped
beyond the last node: θ_o past it uses the last table); that of ω_i is
p_h/(4|ω_o·h|) (the Jacobian of the mirror map; Walter et al. 2007,
eq. (14)). Directions with ω_o·h < 0 land below the horizon; as in
:class:`~brdfkit.models.sampling.HalfVector` (``fold=True``) the density reads
them back through the upper one of ±(ω_i + ω_o)/|ω_i + ω_o|, so it is exact
over the whole sphere of ω_i.

Sampling, from (u₀, u₁) as every strategy: u₀ picks the node (probability
w_j, rescaled to [0, 1) as :class:`~brdfkit.models.sampling.Mixture` does),
then the cell by inverting table j's cumulative cell masses (rescaled again),
then x within the cell from the bilinear density's x-marginal (linear:
:func:`sample_linear`); u₁ < ½ picks ψ ≥ 0, and u₁ rescaled draws ψ from the
conditional density given x (linear again).

The table is what the caller makes of its material (for the data layer's
construction see :mod:`brdfkit.data.sampling`). A density that is 0 where
the BRDF is not must be mixed with one that covers the hemisphere (the
cosine): this class claims nothing about the BRDF's support.

Public objects
--------------
- :class:`TabulatedHalfVector` — the strategy.
- :func:`sample_linear` — inverse CDF of a linear density on [0, 1].

References
----------
- [Walter2007] B. Walter et al., *Microfacet Models for Refraction through
  Rough Surfaces*, EGSR 2007, eq. (14) (the Jacobian 1/(4|ω_o·h|)).
- M. Pharr, W. Jakob, G. Humphreys, *Physically Based Rendering*, 4th ed.,
  §A.5 (sampling tabulated 1-D distributions by their CDF; linear and bilinear
  densities, §A.5.1, §A.5.2).
"""

from __future__ import annotations

import math

import numpy as np

from brdfkit.errors import ParameterError
from brdfkit.models.sampling import Strategy

__all__ = ["TabulatedHalfVector", "sample_linear"]

#: The largest double below 1: a uniform number u ∈ [0, 1] is clipped to it before a
#: cumulative-sum search, so u = 1 still picks a cell of positive probability.
_BELOW_ONE = float(np.nextafter(1.0, 0.0))


def sample_linear(u: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """t ∈ [0, 1] with density ∝ (1 − t)a + tb (a, b ≥ 0), by inverting its CDF.

    F(t) = (2at + (b − a)t²)/(a + b) = u solves to t = u(a + b)/(a + √((1 − u)a² + ub²))
    (the root without cancellation; PBRT 4th ed. §A.5.1); uniform where a = b = 0.
    """
    den = a + np.sqrt((1.0 - u) * a * a + u * b * b)
    ok = den > 0.0
    t = np.where(ok, u * (a + b) / np.where(ok, den, 1.0), u)
    return np.clip(t, 0.0, 1.0)  # clip: rounding


def _check_edges(edges, name: str, top: float) -> np.ndarray:
    e = np.asarray(edges, dtype=np.float64)
    if e.ndim != 1 or e.size < 2 or not np.all(np.isfinite(e)) or e[0] != 0.0 \
            or not np.all(np.diff(e) > 0.0) or abs(e[-1] - top) > 1e-12:
        raise ParameterError(f"TabulatedHalfVector: {name} must be increasing, from 0 to "
                             f"{top:.17g}; got {e!r}")
    e = e.copy()
    e[-1] = top
    return e


class TabulatedHalfVector(Strategy):
    """Half vectors drawn from per-θ_o bilinear tables (module docstring).

    Parameters
    ----------
    theta_o : array_like, shape (J,)
        Viewing angles of the tables (radians), increasing, from 0, below π/2.
    theta_h : array_like, shape (K + 1,)
        Grid vertices in θ_h, increasing from 0 to π/2.
    psi : array_like, shape (L + 1,)
        Grid vertices in |ψ| = |φ_h − φ_o|, increasing from 0 to π.
    values : array_like, shape (J, K + 1, L + 1)
        Non-negative density of h at the vertices, up to a factor per table. A
        table with no positive value is replaced by a constant (uniform h on the
        upper hemisphere).
    """

    def __init__(self, theta_o, theta_h, psi, values):
        self.theta_o = np.asarray(theta_o, dtype=np.float64)
        t = self.theta_o
        if t.ndim != 1 or t.size < 1 or not np.all(np.isfinite(t)) or t[0] != 0.0 \
                or not np.all(np.diff(t) > 0.0) or t[-1] >= 0.5 * math.pi:
            raise ParameterError(f"TabulatedHalfVector: theta_o must be increasing, from 0, "
                                 f"below pi/2; got {t!r}")
        self.theta_h = _check_edges(theta_h, "theta_h", 0.5 * math.pi)
        self.psi = _check_edges(psi, "psi", math.pi)
        J, K1, L1 = t.size, self.theta_h.size, self.psi.size
        V = np.asarray(values, dtype=np.float64)
        if V.shape != (J, K1, L1):
            raise ParameterError(f"TabulatedHalfVector: values must have shape {(J, K1, L1)} "
                                 f"(theta_o, theta_h, psi vertices); got {V.shape}")
        if not np.all(np.isfinite(V)) or np.any(V < 0.0):
            raise ParameterError("TabulatedHalfVector: values must be finite and >= 0")
        # in x = cos θ_h (ascending: x = 0 at θ_h = π/2, 1 at the pole), where dΩ = dx dψ
        x = np.cos(self.theta_h[::-1])
        x[0] = 0.0  # cos(π/2) is 6e-17 in floating point; the hemisphere ends at 0
        self._x = x
        V = V[:, ::-1, :]
        V = np.where(V.reshape(J, -1).max(axis=1)[:, None, None] > 0.0, V, 1.0)
        # cell masses (J, K, L): Δx Δψ × the mean of the four vertices (the bilinear integral)
        corners = V[:, :-1, :-1] + V[:, 1:, :-1] + V[:, :-1, 1:] + V[:, 1:, 1:]
        M = 0.25 * corners * np.diff(x)[None, :, None] * np.diff(self.psi)[None, None, :]
        total = M.reshape(J, -1).sum(axis=1)
        self._V = V / (2.0 * total[:, None, None])  # p_h at the vertices (the 2: ±ψ)
        P = (M / total[:, None, None]).reshape(J, -1)
        self._P = P
        self._cdf = np.cumsum(P, axis=1)
        self._cdf[:, -1] = 1.0  # the last cell closes the table (rounding in the sum)

    # ------------------------------------------------------------------ helpers
    def _nodes(self, cos_theta_o: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Lower node j₀ and weight w of node j₀ + 1 for each θ_o (w = 0 past the last)."""
        theta = np.arccos(np.clip(cos_theta_o, -1.0, 1.0))  # clip: rounding of unit vectors
        J = self.theta_o.size
        if J == 1:
            return np.zeros(theta.shape, dtype=np.int64), np.zeros(theta.shape)
        # fractional node index; np.interp clamps θ_o beyond the last node to J − 1
        x = np.interp(theta, self.theta_o, np.arange(J, dtype=np.float64))
        j0 = np.minimum(x.astype(np.int64), J - 2)
        return j0, x - j0

    @staticmethod
    def _azimuth(v: np.ndarray) -> np.ndarray:
        return np.arctan2(v[..., 1], v[..., 0])  # atan2(0, 0) = 0: the normal has azimuth 0

    def _density(self, j, a, b, t, s):
        """p_h of table j at cell (a, b), local coordinates (t, s) ∈ [0, 1]² (bilinear)."""
        V = self._V
        lo = (1.0 - t) * V[j, a, b] + t * V[j, a + 1, b]
        hi = (1.0 - t) * V[j, a, b + 1] + t * V[j, a + 1, b + 1]
        return (1.0 - s) * lo + s * hi

    # ------------------------------------------------------------------ strategy
    def sample(self, wo, u):
        shape = np.broadcast_shapes(wo.shape[:-1], u.shape[:-1])
        wo = np.broadcast_to(wo, (*shape, 3)).reshape(-1, 3)
        u = np.broadcast_to(u, (*shape, 2)).reshape(-1, 2)
        j0, w1 = self._nodes(wo[:, 2])
        u0 = np.clip(u[:, 0], 0.0, _BELOW_ONE)
        # the node: j₀ with probability 1 − w₁, j₀ + 1 with w₁; u₀ rescaled in each branch
        upper = u0 >= 1.0 - w1
        j = j0 + upper
        u0 = np.where(upper, (u0 - (1.0 - w1)) / np.where(upper, w1, 1.0),
                      u0 / np.where(upper, 1.0, 1.0 - w1))
        u0 = np.clip(u0, 0.0, _BELOW_ONE)  # clip: rounding of the rescaling
        cell = np.empty(u0.shape, dtype=np.int64)
        for jj in np.unique(j):
            sel = j == jj
            cell[sel] = np.searchsorted(self._cdf[jj], u0[sel], side="right")
        n_cells = self._cdf.shape[1]
        cell = np.minimum(cell, n_cells - 1)  # u₀ < 1 = cdf[−1]: only rounding reaches it
        p_cell = self._P[j, cell]
        lo = self._cdf[j, cell] - p_cell
        v = np.clip((u0 - lo) / np.where(p_cell > 0.0, p_cell, 1.0), 0.0, 1.0)  # clip: rounding
        a, b = np.divmod(cell, self.psi.size - 1)
        V = self._V
        # x: the marginal of the bilinear cell is linear between the ψ-averaged edges
        t = sample_linear(v, V[j, a, b] + V[j, a, b + 1], V[j, a + 1, b] + V[j, a + 1, b + 1])
        positive = u[:, 1] < 0.5
        u1 = np.clip(np.where(positive, 2.0 * u[:, 1], 2.0 * u[:, 1] - 1.0), 0.0, 1.0)
        # ψ given x: linear between the densities at the cell's two ψ edges
        s = sample_linear(u1, (1.0 - t) * V[j, a, b] + t * V[j, a + 1, b],
                          (1.0 - t) * V[j, a, b + 1] + t * V[j, a + 1, b + 1])
        x = self._x
        cos_h = np.minimum(x[a] + t * (x[a + 1] - x[a]), 1.0)  # min: rounding at the pole
        sin_h = np.sqrt(np.maximum(0.0, 1.0 - cos_h * cos_h))  # clamp: rounding at cos_h = 1
        psi = self.psi[b] + s * (self.psi[b + 1] - self.psi[b])
        phi_h = self._azimuth(wo) + np.where(positive, psi, -psi)
        h = np.stack([sin_h * np.cos(phi_h), sin_h * np.sin(phi_h), cos_h], axis=-1)
        wi = 2.0 * np.sum(wo * h, axis=-1, keepdims=True) * h - wo
        return wi.reshape(*shape, 3)

    def pdf(self, wi, wo):
        shape = np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1])
        wi = np.broadcast_to(wi, (*shape, 3)).reshape(-1, 3)
        wo = np.broadcast_to(wo, (*shape, 3)).reshape(-1, 3)
        h = wi + wo
        norm = np.linalg.norm(h, axis=-1)
        ok = norm > 0.0
        h = h / np.where(ok, norm, 1.0)[:, None]
        # the sampled h is in the upper hemisphere; wi + wo is ±h, so take the upper one
        h = np.where(h[:, 2:3] < 0.0, -h, h)
        cos_oh = np.abs(np.sum(wo * h, axis=-1))
        ok &= cos_oh > 0.0
        x = self._x
        K, L = x.size - 1, self.psi.size - 1
        a = np.clip(np.searchsorted(x, h[:, 2], side="right") - 1, 0, K - 1)
        t = np.clip((h[:, 2] - x[a]) / (x[a + 1] - x[a]), 0.0, 1.0)  # clip: rounding
        psi = np.abs(np.mod(self._azimuth(h) - self._azimuth(wo) + math.pi, 2.0 * math.pi)
                     - math.pi)
        b = np.clip(np.searchsorted(self.psi, psi, side="right") - 1, 0, L - 1)
        s = np.clip((psi - self.psi[b]) / (self.psi[b + 1] - self.psi[b]), 0.0, 1.0)
        j0, w1 = self._nodes(wo[:, 2])
        j1 = np.minimum(j0 + 1, self.theta_o.size - 1)
        p_h = (1.0 - w1) * self._density(j0, a, b, t, s) + w1 * self._density(j1, a, b, t, s)
        p = p_h / (4.0 * np.where(ok, cos_oh, 1.0))
        return np.where(ok, p, 0.0).reshape(shape)

    def __repr__(self) -> str:
        J, K1, L1 = self._V.shape
        return (f"TabulatedHalfVector({J} theta_o nodes x {K1 - 1} theta_h x {L1 - 1} psi "
                "cells, bilinear)")
