"""
Where a fit looks: MERL-grid samples, their measure, and an albedo quadrature
=============================================================================

Samples
-------
A fit compares model and target at the centres of MERL's bins (Matusik et
al. 2003; :func:`brdfkit.data.merl.bin_centres`): 90 θ_h bins with the
quadratic spacing θ_h = (u/90)²·π/2, 90 θ_d bins, 180 φ_d bins over [0, π)
(reciprocity folds φ_d ∈ [π, 2π) onto them). Each bin is weighted by its
measure in (ω_i, ω_o):

    dω_i dω_o = 4 cos θ_d dω_h dω_d                                   (1)

(for fixed ω_i, ω_o = 2(ω_i·h)h − ω_i gives dω_o = 4 (ω_i·h) dω_h, and
(ω_i, h) ↦ (h, ω_d) is a rotation of ω_i for each h, so it keeps the
measure; Rusinkiewicz 1998). With dω_h = sin θ_h dθ_h dφ_h, dω_d =
sin θ_d dθ_d dφ_d and φ_h integrated over 2π (isotropy), bin (a, b, c) with
edges θ_h ∈ [h_a, h_a+1], θ_d ∈ [d_b, d_b+1], φ_d ∈ [p_c, p_c+1] has the
exact measure

    W_abc = 8π (cos h_a − cos h_a+1) · ½(sin² d_b+1 − sin² d_b) · (p_c+1 − p_c)   (2)

Summed over all bins, (2) is 8π · 1 · ½ · π = 4π², the measure of the
pairs with h in the upper hemisphere folded to φ_d ∈ [0, π) (half of all
pairs of directions, (4π)²/2 = 8π², folded: 4π²). The pairs with both
directions above the horizon have measure (2π)² = 4π², folded 2π²: the
valid bins' weights sum to that up to the bins the horizon cuts
(tests/test_fitting.py checks both).

A sample is kept when both directions of its bin centre are above the
horizon (and, with ``theta_max``, both θ ≤ θ_max: Ngan et al. 2005 cut at
80°) and the target is finite there (a MERL file's unmeasured bins are
dropped, never read as 0).

Subsampling (speed)
-------------------
The full grid has 1,096,216 bins with both directions above the horizon.
:func:`merl_samples` merges bins
into cells — every θ_h bin is kept (the quadratic spacing is what resolves
sharp highlights), ``stride_d`` θ_d bins and ``stride_p`` φ_d bins per cell
— evaluated at the centre bin of each cell and weighted by the exact measure
(2) of the whole cell. Deterministic (no random choice). With odd-sized
cells' centres on bin centres — the default (9, 15): 10 θ_d × 12 φ_d cells,
centres at θ_d bins 4, 13, …, φ_d bins 7, 22, … — a MERL table is read at
exactly its stored bins. The default keeps ~8,000 samples.

Albedo quadrature
-----------------
The directional albedo a(θ_i) = ∫ f cos θ_o dω_o is integrated over the
half vector: ω_o = 2(ω_i·h)h − ω_i, dω_o = 4 (ω_i·h) dω_h, with θ_h =
u²·π/2 (midpoint rule in u, the MERL spacing, dense at h = n where every
mirror-centred lobe peaks) and midpoints in φ_h over the whole turn [0, 2π):
*n_phi* per half turn, 2·n_phi in all. Not [0, π] doubled: that assumes f even in
φ_h (mirror symmetry about the plane of incidence), which a rotation-invariant
model need not be (an NBRDF net: 1 % off at 80°, 2.8e-3 absolute on merl:nickel);
for an even f the whole-turn rule gives the same sum (its nodes are the half-turn
rule's and their mirror images). Model and target are integrated with the same
nodes.

Its error estimate (:func:`albedo_with_error`) compares the rule with three coarser
ones, each with a third of the nodes along u, along φ_h or along both — midpoints of cells
three times as wide, which are nodes of the fine rule (cell k's midpoint (k + ½)/16 is the
fine node 3k + 1 of 48), so they cost no evaluation. The sum of the three differences,
maximised over the curve's angles (per channel), is the estimate of every angle's error:
one difference at one angle can vanish by chance (the horizon's kink at grazing angles
makes the rule's convergence irregular: at single angles the true error was up to 42×
the both-axes difference, and up to 2.1× the sum of the three), while the curve's largest
sum exceeded every angle's true error by 9× or more on the 29 models measured (Lambertian,
modified Phong n = 1 … 300, Blinn, Ward, Nielsen, microfacet, Lafortune, Cook–Torrance,
Minnaert, Neumann–Neumann; the albedo engine to 10⁻⁹ as reference). A lobe narrower than
the coarse cells near h = n is resolved by neither rule and the estimate can then fall
short; a delta term (``BRDF.has_delta``) is not in f and not in the albedo
(``tests/test_fitting.py`` checks the bound on Lambertian and modified Phong albedos).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from brdfkit._cache import memo
from brdfkit.data.merl import SHAPE, half_diff_to_directions
from brdfkit.errors import ParameterError
from brdfkit.geometry import merl_theta_h

__all__ = ["Samples", "bin_measure", "merl_samples", "albedo_nodes", "albedo_from_values",
           "albedo_with_error", "DEFAULT_STRIDES", "ALBEDO_THETA_DEG", "ALBEDO_NODES",
           "ALBEDO_COARSENING"]

#: Default merging of bins per cell along (θ_d, φ_d) (θ_h is never merged).
DEFAULT_STRIDES = (9, 15)
#: Incidence angles of the reported albedo curves, degrees.
ALBEDO_THETA_DEG = tuple(float(t) for t in np.arange(0.0, 86.0, 5.0))
#: Nodes (along u = √(2θ_h/π), along φ_h) of the reported albedos' rule.
ALBEDO_NODES = (48, 24)
#: The error estimate's coarser rule has this many times fewer nodes along each axis
#: (odd, so that its midpoints are nodes of the fine rule; module docstring).
ALBEDO_COARSENING = 3


def _edges():
    """Bin edges (radians) along θ_h (quadratic), θ_d and φ_d."""
    u = np.arange(SHAPE[0] + 1) / SHAPE[0]
    h = merl_theta_h(u)
    d = np.arange(SHAPE[1] + 1) / SHAPE[1] * (0.5 * math.pi)
    p = np.arange(SHAPE[2] + 1) / SHAPE[2] * math.pi
    return h, d, p


def bin_measure(h_edges, d_edges, p_edges) -> np.ndarray:
    """Exact (ω_i, ω_o) measure (2) of the cells with the given edges, shape (H, D, P)."""
    wh = 8.0 * math.pi * (np.cos(h_edges[:-1]) - np.cos(h_edges[1:]))
    wd = 0.5 * (np.sin(d_edges[1:]) ** 2 - np.sin(d_edges[:-1]) ** 2)
    wp = np.diff(p_edges)
    return wh[:, None, None] * wd[None, :, None] * wp[None, None, :]


@dataclass(frozen=True, eq=False)
class Samples:
    """Sample pairs of a fit.

    Attributes
    ----------
    wi, wo : ndarray (N, 3)
        Directions at the cell centres (local frame, φ_h = 0).
    weight : ndarray (N,)
        Measure (2) of each cell in sr² (not normalised).
    cos_i : ndarray (N,)
        cos θ_i.
    """

    wi: np.ndarray
    wo: np.ndarray
    weight: np.ndarray
    cos_i: np.ndarray

    def __len__(self) -> int:
        return self.wi.shape[0]

    def subset(self, keep) -> Samples:
        """The samples where boolean *keep* is true."""
        return Samples(self.wi[keep], self.wo[keep], self.weight[keep], self.cos_i[keep])


def merl_samples(*, strides=DEFAULT_STRIDES, theta_max=None) -> Samples:
    """The MERL-grid samples (module docstring) with both directions above the horizon.

    Parameters
    ----------
    strides : (int, int)
        Bins merged per cell along θ_d (a divisor of 90) and φ_d (a divisor of 180);
        (1, 1): every bin.
    theta_max : float or None
        Keep only pairs with θ_i, θ_o ≤ theta_max (radians), e.g. 80° (Ngan et al. 2005).
    """
    sd, sp = (int(s) for s in strides)
    if sd < 1 or SHAPE[1] % sd or sp < 1 or SHAPE[2] % sp:
        raise ParameterError(f"strides must divide (90, 180) (theta_d, phi_d bins); got "
                             f"{tuple(strides)}")
    if theta_max is not None and not (0.0 < float(theta_max) <= 0.5 * math.pi):
        raise ParameterError(f"theta_max must lie in (0, pi/2] rad; got {theta_max!r}")
    return _merl_samples(sd, sp, None if theta_max is None else float(theta_max))


def _read_only(*arrays):
    for a in arrays:
        a.flags.writeable = False
    return arrays


# Memoised (every fit of a batch, and each fit's nested and root fits, uses the same few
# grids; building one costs ~3 ms): the arrays are shared, hence read-only.
@memo(maxsize=16)
def _merl_samples(sd: int, sp: int, theta_max: float | None) -> Samples:
    h, d, p = _edges()
    d_c, p_c = d[::sd], p[::sp]
    W = bin_measure(h, d_c, p_c)
    # the cell's centre: the centre of its middle bin (index coordinates i + ½)
    uh = (np.arange(SHAPE[0]) + 0.5) / SHAPE[0]
    th = uh * uh * (0.5 * math.pi)
    td = 0.5 * (d_c[:-1] + d_c[1:])
    pd = 0.5 * (p_c[:-1] + p_c[1:])
    TH, TD, PD = np.meshgrid(th, td, pd, indexing="ij")
    wi, wo = half_diff_to_directions(TH, TD, PD)
    wi = wi.reshape(-1, 3)
    wo = wo.reshape(-1, 3)
    W = W.reshape(-1)
    keep = (wi[:, 2] > 0.0) & (wo[:, 2] > 0.0)
    if theta_max is not None:
        c = math.cos(float(theta_max))
        keep &= (wi[:, 2] >= c) & (wo[:, 2] >= c)
    wi = np.ascontiguousarray(wi[keep])
    wo = np.ascontiguousarray(wo[keep])
    # renormalise: half_diff_to_directions is exact to rounding; the kernels' unit check
    # allows 1e-3, so this only removes the rounding
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    wo /= np.linalg.norm(wo, axis=1, keepdims=True)
    return Samples(*_read_only(wi, wo, W[keep], wi[:, 2].copy()))


def albedo_nodes(theta_deg=ALBEDO_THETA_DEG, *, n_u: int = 48, n_phi: int = 24):
    """Quadrature pairs of a(θ_i) (module docstring).

    Returns ``(wi, wo, w, T)``: pairs (T·n_u·2n_phi, 3) and weights w such that
    a(θ_t) ≈ Σ_k w_k f(wi_k, wo_k) over the t-th block of n_u·2n_phi pairs (w is 0
    where ω_o is below the horizon; such pairs are given ω_o = n to stay valid).
    The arrays are read-only (memoised: shared by every call with the same nodes).
    """
    theta = tuple(float(t) for t in np.atleast_1d(np.asarray(theta_deg, dtype=np.float64)))
    return _albedo_nodes(theta, int(n_u), int(n_phi))


@memo(maxsize=16)  # a few node sets per session (~1 MB each at the defaults)
def _albedo_nodes(theta_deg: tuple, n_u: int, n_phi: int):
    theta = np.radians(np.asarray(theta_deg, dtype=np.float64))
    u = (np.arange(n_u) + 0.5) / n_u
    th = merl_theta_h(u)
    dth = math.pi * u / n_u  # dθ_h = π u du
    ph = (np.arange(2 * n_phi) + 0.5) / n_phi * math.pi  # the whole turn (docstring)
    dph = math.pi / n_phi
    TH, PH = np.meshgrid(th, ph, indexing="ij")
    h = np.stack([np.sin(TH) * np.cos(PH), np.sin(TH) * np.sin(PH), np.cos(TH)], -1)
    dwh = (np.sin(TH) * dth[:, None] * dph).reshape(-1)
    h = h.reshape(-1, 3)
    wis, wos, ws = [], [], []
    for t in theta:
        wi = np.array([math.sin(t), 0.0, math.cos(t)])
        c = h @ wi
        wo = 2.0 * c[:, None] * h - wi
        ok = (wo[:, 2] > 0.0) & (c > 0.0)
        w = np.where(ok, 4.0 * c * dwh * np.maximum(wo[:, 2], 0.0), 0.0)
        wo = np.where(ok[:, None], wo, np.array([0.0, 0.0, 1.0]))
        wo /= np.linalg.norm(wo, axis=1, keepdims=True)
        wis.append(np.broadcast_to(wi, wo.shape))
        wos.append(wo)
        ws.append(w)
    return (*_read_only(np.ascontiguousarray(np.concatenate(wis)),
                        np.ascontiguousarray(np.concatenate(wos)), np.concatenate(ws)),
            theta.size)


def albedo_from_values(f, w, n_theta: int) -> np.ndarray:
    """a(θ_t) from values f (M, C) at :func:`albedo_nodes` pairs: shape (T, C)."""
    f = np.where(w[:, None] > 0.0, f, 0.0)  # below-horizon nodes carry no weight
    return (f * w[:, None]).reshape(n_theta, -1, f.shape[1]).sum(axis=1)


def albedo_with_error(f, w, n_theta: int, n_u: int, n_phi: int):
    """a(θ_t) from values f (M, C) at :func:`albedo_nodes` pairs of (*n_u*, *n_phi*) nodes,
    and its error estimate (module docstring): both (T, C), the estimate the same at every
    angle of a channel. *n_u* and *n_phi* must be multiples of :data:`ALBEDO_COARSENING`."""
    k = ALBEDO_COARSENING
    if n_u % k or n_phi % k:
        raise ParameterError(f"albedo_with_error: n_u and n_phi must be multiples of {k}; "
                             f"got {n_u}, {n_phi}")
    # the terms once; a as albedo_from_values computes it (the same operations, so the
    # same values)
    terms = np.where(w[:, None] > 0.0, f, 0.0) * w[:, None]
    C = terms.shape[1]
    a = terms.reshape(n_theta, -1, C).sum(axis=1)
    n_phi = 2 * n_phi  # nodes over the whole turn (albedo_nodes)
    t = terms.reshape(n_theta, n_u, n_phi, C)
    # the coarse cells' midpoints are fine nodes k·j + (k − 1)/2, their weights k (one
    # axis) or k² (both) times the fine ones' (du, dφ k times wider; the rest is evaluated
    # at the same node)
    mid = (k - 1) // 2
    # sums over φ (T, n_u, C), of every node and of every k-th, as matrix products (5×
    # faster than sums over a middle axis; the estimate does not need their rounding)
    every, kth = np.ones(n_phi), np.zeros(n_phi)
    kth[mid::k] = 1.0
    tp = t.transpose(0, 1, 3, 2)
    by_u, by_u_coarse_phi = tp @ every, tp @ kth
    coarse_u = k * by_u[:, mid::k].sum(axis=1)
    coarse_phi = k * by_u_coarse_phi.sum(axis=1)
    coarse_both = (k * k) * by_u_coarse_phi[:, mid::k].sum(axis=1)
    spread = np.abs(a - coarse_u) + np.abs(a - coarse_phi) + np.abs(a - coarse_both)
    return a, np.broadcast_to(spread.max(axis=0), a.shape).copy()
