"""
Albedo pumping-up
=================

Neumann, Neumann & Szirmay-Kalos (1999, §3) turn a symmetric BRDF f into a
brighter one,

    f*(L, V) = f(L, V) / g(L, V),                                     (eq. 16)

with g symmetric and max(a(L), a(V)) ≤ g(L, V) ≤ 1 (eq. 17), where
a(L) = ∫ f(L, V) cos θ_V dω_V is the albedo (eq. 2). Two choices are given:
g₁ = max(a(L), a(V)) (eq. 20, ``"max"``) and the *controlled*
g₂ = max(a(L), a(V), N·V, N·L) (eq. 21, ``"controlled"``). :func:`pump`
applies either (or a user-supplied g) any number of times and returns a model
like any other: it evaluates through a compiled kernel, samples with the base
model's sampler, and can be analysed, fitted, rendered and pumped again.

The theorem (eqs. 18–19), derived
---------------------------------
Eq. (18) is garbled in print: its last integral runs over Ω although the text
says it runs over Ω_V = {V : a(V) > a(L)} (on Ω \\ Ω_V the max is a(L), not
a(V)); it is numbered "(1)"; and eq. (19) states a strict a*(L) < 1. The
correct argument is shorter. For f ≥ 0 and any g with g(L, V) ≥ a(L) > 0,

    a*(L) = ∫ f(L,V)/g(L,V) cos θ_V dω_V
          ≤ ∫ f(L,V)/a(L)  cos θ_V dω_V  = a(L)/a(L) = 1.

(The paper's decomposition is the equality
∫ f/max(a(L),a(V)) cos = 1 − ∫_{Ω_V} f (1/a(L) − 1/a(V)) cos ≤ 1.)
Nothing here needs f to be symmetric: symmetry of f *and* g is what makes f*
reciprocal, and max(a(L), a(V)) is the smallest symmetric g ≥ a(L).
The lower bound a*(L) ≥ a(L) follows from g ≤ 1. Two corrections to the
paper's wording follow:

- **a* < 1 is not strict.** Where a(L) is the largest albedo over all
  directions, Ω_V is empty and g₁ gives a*(L) = 1 exactly — not only when
  a(L) = 1 as §3 says. For the Phong and Blinn models the albedo peaks at
  normal incidence, so once pumped with g₁ they reflect *all* energy arriving
  along the normal (``tests/test_pumping.py`` checks a*(0) = 1).
- **Non-plausible bases.** §3 says a symmetric but energy-gaining base is made
  plausible by one pumping. That is true of g₁ = max(a(L), a(V)) *without*
  the cap g ≤ 1 (a*(L) ≤ 1 only needs g ≥ a(L)), but no g can satisfy eq. 17
  where a > 1: the interval [max(a(L), a(V)), 1] is empty. brdfkit therefore
  caps g at 1 only when the base conserves energy (then eq. 17 holds and
  a ≤ a* ≤ 1); for a base with a > 1 somewhere it uses the uncapped g
  (a* ≤ 1 everywhere, but a* < a where a > 1 — "pumping down"), emits a
  :class:`PumpingWarning`, and records ``capped = False``. A user-supplied g
  is held to eq. 17 and so cannot pump such a base.

What the controlled pumping bounds, derived
-------------------------------------------
Under a point light of intensity 4π at distance 1 the output radiance is
L_out(L, V) = f(L, V) cos θ_L (eq. 3). Since g₂ ≥ N·L = cos θ_L,

    L*_out(L, V) = f(L, V) cos θ_L / g₂(L, V) ≤ f(L, V),

and symmetrically f* cos θ_V ≤ f. So one controlled pumping bounds the new
radiance by the *base BRDF value* (not by the base radiance f cos θ_L, which
pumping raises by 1/g ≥ 1 — that is the point of it). For Phong and Blinn the
mirror value f(L, R(L)) is a constant c (= (n+2)/2π for the normalised
Phong), the radiance the base returns at normal incidence, so after one g₂
pumping the mirror radiance never exceeds its normal-incidence value: the
"super-metal" overshoot of g₁ (where L*_out = c cos θ/a(θ) and a(θ) ≪ cos θ
near grazing for Blinn) is impossible. For k ≥ 2 stages the same argument
gives only L⁽ᵏ⁾_out ≤ f⁽ᵏ⁻¹⁾(L, V), the previous stage's BRDF: at the mirror
direction
L⁽ᵏ⁾_out(θ) = c cos θ / ∏_{j<k} max(a_j(θ), cos θ), which stays ≤ c exactly
when ∏_{j<k} max(a_j(θ), cos θ) ≥ cos θ — not implied by eq. (21) (if every
a_j(θ) < cos θ the product is cosᵏθ and L⁽ᵏ⁾_out = c/cosᵏ⁻¹θ > c). The
Conclusions' "guarantees that the output radiance does not exceed the input
radiance" is therefore a theorem for one controlled pumping only, and it
fails for repeated ones: for the normalised reciprocal Phong (c = (n+2)/2π)
a(θ) ≥ cos θ holds exactly (the horizon only removes parts of the lobe with
cos θ_o < 0 from ∫ c cosⁿα cos θ_o dω = cos θ), pumping only raises a, so
g₂ = g₁ at every stage; with n = 20 the mirror radiance after 2, 3, 5
pumpings peaks at 1.36, 1.61, 1.91 × c (at θ ≈ 80°, 83°, 85°). For Blinn
(n = 20), whose albedo dips below cos θ, g₂ does differ from g₁ (g₁ gives
peaks of 1.69, 5.05, 10.99 × c after 1, 2, 3 pumpings: the super-metal).

Eq. (22) is close to *one* controlled pumping of Phong, not to its limit:
for n = 20 the best-fit c_n is 0.936 × (n+2)/2π after one pumping (median
relative difference of f over in-lobe pairs 7 %, largest 92 % at grazing
pairs; albedo equal to 4e-4 up to 60°, but 0.404 vs 0.540 at 89°), while
further pumpings move away (best c_n 1.18, 1.25 × the bound) because
repeated pumping drives the normalised Phong's albedo to 1 everywhere and
eq. (22)'s stays at 0.51 at 89.9°.

The albedo table
----------------
Each stage tabulates the albedo of its base once, with the albedo engine
(:func:`brdfkit.analysis.albedo`), on a grid uniform in w = √(1 − √(1 − cos θ))
over θ ∈ [0, 89.9°] — linear in θ at normal incidence, dense near grazing
where sharp lobes are cut by the horizon (see :class:`AlbedoTable`) — and
interpolates with a cubic spline. The grid is doubled until the spline,
checked against the engine at every interval midpoint, is within
``INTERP_TOL`` there. A pumped stage's albedo has kinks (for g₂: where the
previous table a(θ) crosses cos θ, since g switches from a(L) to N·L for all
V at once; the base's kinks carry over): :class:`PumpedBRDF` lists them in
``albedo_kink_mus`` and the next table is split there into pieces, each with
its own uniform grid and spline, so no interval straddles a kink (the
controlled Blinn n = 20 stage-3 table needs 54 intervals instead of > 512,
and builds in seconds); the lookup scans the few piece starts, still O(1). The stored table is
the spline **plus** a margin δ = 2 × (largest midpoint error) + ``ENGINE_ERR``
(5e-7), so it is an upper bound of the albedo and g ≥ a(L) holds — the
theorem's only requirement — in spite of rounding: a* ≤ 1 with no tolerance.
The total error of the table stays below 1e-5. Beyond 89.9° (the engine's
stated range) the table is extended by its last value; for the Phong family,
whose albedo falls toward grazing, that over-estimates a and stays safe.
Coloured models get one table per channel. Anisotropic bases (attribute
``isotropic`` False) are refused: their albedo is not a function of θ alone.

Public objects
--------------
- :func:`pump` — the operator.
- :class:`PumpedBRDF` — the result (a :class:`brdfkit.models.BRDF`).
- :class:`AlbedoTable` — a stage's tabulated albedo.
- :func:`build_albedo_table` — tabulate any model's albedo.
- :func:`from_dict` — rebuild a (pumped) model from ``to_dict()``.
- :func:`pump_sequence` — the model and its 1 … k times pumped versions.
- :func:`mirror_radiance` — f(L, R(L)) cos θ_L, the paper's output radiance.
- :class:`PumpingWarning`.
- :data:`G_CHOICES` — the built-in g names.

References
----------
- [Neumann1999] eqs. (2), (3), (16)–(22), §3, §3.1, §3.2, §5.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numba
import numpy as np

from brdfkit._array import as_directions
from brdfkit.errors import BrdfkitError, ParameterError
from brdfkit.models._base import BRDF

__all__ = [
    "G_CHOICES",
    "AlbedoTable",
    "PumpedBRDF",
    "PumpingWarning",
    "build_albedo_table",
    "from_dict",
    "mirror_radiance",
    "pump",
    "pump_sequence",
]

#: Built-in correction terms: name → (code used by the kernel, equation).
G_CHOICES = {"max": 0, "controlled": 1}
_G_ALIASES = {"g1": "max", "g_1": "max", "max": "max", "controlled": "controlled",
              "g2": "controlled", "g_2": "controlled"}
_G_EQ = {"max": "eq. (20) g1 = max(a(L), a(V))",
         "controlled": "eq. (21) g2 = max(a(L), a(V), N.V, N.L)"}

#: Largest angle of incidence the table is built and checked at (the albedo
#: engine's stated range); beyond it the table holds its last value.
THETA_TOP = math.radians(89.9)
#: Interpolation tolerance checked at the interval midpoints.
INTERP_TOL = 3e-6
#: Accuracy asked of the albedo engine. A pumped stage's integrand has kinks
#: on circles N·V = k where g switches branch; PumpedBRDF.albedo_kinks_nv
#: declares them to the engine as panel edges, which keeps its error estimate
#: honest (without them: 2.3e-7 actual vs 4e-8 estimated for the g₂-pumped
#: Blinn at 89°; ``test_engine_error_estimate_honest_with_declared_kinks``).
#: The engine bounds its own memory (``MAX_ANGLE_NODES``).
ENGINE_TOL = 1e-8
#: Error bound assumed for the engine's values (added to the table margin).
ENGINE_ERR = 5e-7
#: Angles per engine call (bounds the engine's memory at deep levels).
ENGINE_CHUNK = 8
#: g is never smaller than this: a zero albedo with f > 0 can only come from
#: rounding at the horizon, and dividing by it would give inf.
G_FLOOR = 1e-12


class PumpingWarning(UserWarning):
    """A pumping step cannot meet eq. (17) (the base gains energy somewhere)."""


# --------------------------------------------------------------------------- albedo table
@numba.njit(cache=True, inline="always")
def _table_lookup(p, off, mu):  # pragma: no cover - compiled
    """Albedo at cos θ = mu from the piecewise spline table stored at p[off:].

    Layout: m (number of pieces), then per piece (start w, intervals per unit w,
    first interval index, intervals), then 4 coefficients per interval. The pieces
    split [w(THETA_TOP), 1] at the albedo's kinks; each is uniform in w.
    """
    # w = sqrt(1 - sqrt(1 - mu)), see AlbedoTable; clamp: |wi| = 1 up to rounding
    r = 1.0 - mu
    w = math.sqrt(1.0 - math.sqrt(r)) if r > 0.0 else 1.0
    m = int(p[off])
    i = 0
    while i < m - 1 and w >= p[off + 1 + 4 * (i + 1)]:
        i += 1  # at most a few pieces: a short scan
    d = off + 1 + 4 * i
    nn = int(p[d + 3])
    x = (w - p[d]) * p[d + 1]
    if x < 0.0:
        x = 0.0  # beyond THETA_TOP: hold the last tabulated value (see module docstring)
    j = int(x)
    if j >= nn:
        j = nn - 1  # mu = 1 (normal incidence) or 1 + rounding: last interval
    t = x - j
    b = off + 1 + 4 * m + 4 * (int(p[d + 2]) + j)
    return ((p[b] * t + p[b + 1]) * t + p[b + 2]) * t + p[b + 3]


@dataclass(frozen=True)
class AlbedoTable:
    """The tabulated albedo of one model (one spline per channel).

    Attributes
    ----------
    coeffs : ndarray, shape (C, nn, 4)
        Per-interval cubic coefficients in the local variable t ∈ [0, 1]
        (highest power first), the margin ``delta`` already added; the
        intervals of all pieces, in order of w.
    breaks : ndarray, shape (m + 1,)
        Piece boundaries in w (``s_top`` … 1): the table is split at the
        albedo's kinks (the model's ``albedo_kink_mus``), with its own uniform
        grid and spline on each piece, so a kink never lies inside an interval.
    piece_nn : tuple of int
        Intervals of each piece.
    s_top : float
        w(THETA_TOP): the grid is uniform in w = √(1 − √(1 − cos θ)) on
        [s_top, 1]. This variable is linear in θ at normal incidence (where
        the albedo is even in θ, so the spline is clamped to zero slope there)
        and its square is linear in cos θ at grazing (cos θ = 2w² − w⁴), so
        the nodes crowd where sharp lobes meet the horizon.
    max_midpoint_error : ndarray, shape (C,)
        Largest |spline − engine| over the interval midpoints.
    delta : ndarray, shape (C,)
        Margin added so the table bounds the albedo from above.
    max_albedo : ndarray, shape (C,)
        Largest tabulated albedo (engine values at nodes and midpoints).
    theta_nodes : ndarray
        The angles of incidence of the nodes (radians).
    n_evaluations : int
        Albedo engine evaluations spent building the table.
    nondecreasing : ndarray of bool, shape (C,)
        Whether the spline is non-decreasing in cos θ on every interval (its
        derivative, a quadratic, checked at the ends and the vertex); then
        max(a(L), a(V)) = a(max(N·L, N·V)) and the kernel looks up once.
    coloured : bool
        Whether the model returns a channel axis.
    """

    coeffs: np.ndarray
    s_top: float
    breaks: np.ndarray
    piece_nn: tuple
    max_midpoint_error: np.ndarray
    delta: np.ndarray
    max_albedo: np.ndarray
    theta_nodes: np.ndarray
    n_evaluations: int
    coloured: bool
    nondecreasing: np.ndarray

    @property
    def n_intervals(self) -> int:
        """Number of spline intervals."""
        return self.coeffs.shape[1]

    def packed(self, c: int) -> np.ndarray:
        """Channel *c*'s coefficients flattened for the kernel."""
        m = len(self.piece_nn)
        d = []
        cum = 0
        for i, nn in enumerate(self.piece_nn):
            d += [self.breaks[i], nn / (self.breaks[i + 1] - self.breaks[i]), cum, nn]
            cum += nn
        return np.ascontiguousarray(np.concatenate([[float(m)], d, self.coeffs[c].reshape(-1)]))

    def __call__(self, theta) -> np.ndarray:
        """Tabulated albedo (an upper bound) at incidence angles *theta* (radians).

        Returns shape ``theta.shape`` or ``theta.shape + (C,)`` when coloured.
        """
        return self.at_cos(np.cos(np.asarray(theta, dtype=np.float64)))

    def at_cos(self, mu) -> np.ndarray:
        """Tabulated albedo at cos θ = *mu* (vectorised :func:`_table_lookup`)."""
        mu = np.asarray(mu, dtype=np.float64)
        w = _w_of_mu(mu)
        nns = np.array(self.piece_nn)
        i = np.clip(np.searchsorted(self.breaks[1:-1], w, side="right"), 0, nns.size - 1)
        start = self.breaks[i]
        x = np.maximum((w - start) * (nns[i] / (self.breaks[i + 1] - start)), 0.0)
        j = np.minimum(x.astype(np.int64), nns[i] - 1)
        t = (x - j)[..., None]
        j = j + np.concatenate([[0], np.cumsum(nns)[:-1]])[i]
        c = self.coeffs[:, j, :]  # (C, ..., 4)
        c = np.moveaxis(c, 0, -2)  # (..., C, 4)
        out = ((c[..., 0] * t + c[..., 1]) * t + c[..., 2]) * t + c[..., 3]
        return out if self.coloured else out[..., 0]


def _engine(model) -> Callable:
    """The albedo engine as ``theta -> (T,) or (T, C)`` for *model*."""
    try:
        from brdfkit.analysis import albedo
    except ImportError as exc:  # pragma: no cover - the engine ships with brdfkit
        raise BrdfkitError("pumping needs the albedo engine (brdfkit.analysis)") from exc
    def run(theta: np.ndarray) -> np.ndarray:
        # a model without a compiled kernel (custom g) is integrated as a callable, in the
        # frame of its lobes
        parts = [np.asarray(albedo(model, theta[i:i + ENGINE_CHUNK], tol=ENGINE_TOL).albedo,
                            dtype=np.float64) for i in range(0, len(theta), ENGINE_CHUNK)]
        return np.concatenate(parts, axis=0)

    return run


def build_albedo_table(model, *, tol: float = INTERP_TOL, nn_start: int = 16,
                       nn_max: int = 8192, kinks_mu=None) -> AlbedoTable:
    """Tabulate the albedo of *model* to interpolation tolerance *tol*.

    Parameters
    ----------
    model : BRDF
        An isotropic model (any registered or pumped model).
    tol : float, keyword-only
        Largest allowed |spline − engine| at the interval midpoints (relative
        to max(1, a) where the albedo exceeds 1).
    nn_start, nn_max : int, keyword-only
        First and largest number of intervals (of the whole range; each piece
        gets its share); the grid of each piece doubles in between.
    kinks_mu : sequence of float, keyword-only
        cos θ where the albedo has a kink; default ``model.albedo_kink_mus``
        (pumped models declare them). The table is split there into pieces
        with their own splines.

    Returns
    -------
    AlbedoTable

    Raises
    ------
    BrdfkitError
        If the albedo is not finite or the tolerance is not met with *nn_max*
        intervals.
    """
    if not (isinstance(tol, float | int) and 0.0 < tol < 1.0):
        raise ParameterError(f"build_albedo_table: tol must lie in (0, 1); got {tol!r}")
    run = _engine(model)
    s_top = float(_w_of_mu(math.cos(THETA_TOP)))
    if kinks_mu is None:
        kinks_mu = getattr(model, "albedo_kink_mus", ())
    kw = np.sort(_w_of_mu(np.asarray(kinks_mu, dtype=np.float64).reshape(-1)))
    breaks = [s_top]
    for x in kw:  # pieces at least 1e-3 wide in w (closer kinks: one piece, refined)
        if x - breaks[-1] > 1e-3 and 1.0 - x > 1e-3:
            breaks.append(float(x))
    breaks.append(1.0)
    breaks = np.array(breaks)

    def thetas(w):
        return np.arccos(np.clip(1.0 - (1.0 - w * w) ** 2, 0.0, 1.0))

    n_eval = 0
    all_coeffs, all_nodes, piece_nn, max_errs, maxes = [], [], [], [], []
    for lo, hi in zip(breaks[:-1], breaks[1:], strict=True):
        nn = max(4, int(round(nn_start * (hi - lo) / (1.0 - s_top))))
        s_nodes = np.linspace(lo, hi, nn + 1)
        vals = _as_2d(run(thetas(s_nodes)))
        n_eval += len(s_nodes)
        while True:
            s_mid = 0.5 * (s_nodes[:-1] + s_nodes[1:])
            mid = _as_2d(run(thetas(s_mid)))
            n_eval += len(s_mid)
            if not (np.all(np.isfinite(vals)) and np.all(np.isfinite(mid))):
                raise BrdfkitError(f"pumping: the albedo of {_label(model)} is not finite on "
                                   "[0, 89.9] deg; it cannot be tabulated")
            coeffs = _spline_coeffs(s_nodes, vals, zero_slope_end=hi == 1.0)
            interp = _eval_coeffs(coeffs, np.full(nn, 0.5))  # (nn, C) at the midpoints
            err = np.abs(interp - mid) / np.maximum(1.0, np.abs(mid))
            if np.all(err.max(axis=0) <= tol):
                break
            if 2 * nn > nn_max:
                worst = int(np.argmax(err.max(axis=1)))
                raise BrdfkitError(
                    f"pumping: could not tabulate the albedo of {_label(model)} to {tol:g} "
                    f"with {nn_max} intervals (error {err.max():.3g} at theta = "
                    f"{math.degrees(thetas(s_mid[worst])):.4f} deg)")
            # the midpoints become nodes of the doubled grid
            merged = np.empty((2 * nn + 1, vals.shape[1]))
            merged[0::2] = vals
            merged[1::2] = mid
            vals = merged
            nn *= 2
            s_nodes = np.linspace(lo, hi, nn + 1)
        all_coeffs.append(coeffs)
        all_nodes.append(s_nodes if not all_nodes else s_nodes[1:])
        piece_nn.append(nn)
        max_errs.append(np.abs(interp - mid).max(axis=0))
        maxes.append(np.maximum(vals.max(axis=0), mid.max(axis=0)))
    max_err = np.max(max_errs, axis=0)
    delta = 2.0 * max_err + ENGINE_ERR
    coeffs = np.concatenate(all_coeffs, axis=1)
    coeffs[:, :, 3] += delta[:, None]
    coloured = getattr(model, "n_channels", None) is not None
    return AlbedoTable(coeffs=coeffs, s_top=s_top, breaks=breaks, piece_nn=tuple(piece_nn),
                       max_midpoint_error=max_err, delta=delta,
                       max_albedo=np.max(maxes, axis=0),
                       theta_nodes=thetas(np.concatenate(all_nodes)), n_evaluations=n_eval,
                       coloured=coloured, nondecreasing=_nondecreasing(coeffs))


def _w_of_mu(mu) -> np.ndarray:
    """Table variable w = √(1 − √(1 − μ)) of μ = cos θ (clamped to [0, 1])."""
    r = np.clip(1.0 - np.asarray(mu, dtype=np.float64), 0.0, 1.0)
    return np.sqrt(1.0 - np.sqrt(r))


def _nondecreasing(coeffs: np.ndarray) -> np.ndarray:
    """Per channel: is every cubic non-decreasing on t ∈ [0, 1]? (derivative ≥ 0)."""
    c0, c1, c2 = coeffs[..., 0], coeffs[..., 1], coeffs[..., 2]
    d0 = c2  # derivative 3c0 t² + 2c1 t + c2 at t = 0
    d1 = 3.0 * c0 + 2.0 * c1 + c2  # at t = 1
    with np.errstate(divide="ignore", invalid="ignore"):
        tv = np.where(c0 != 0.0, -c1 / (3.0 * c0), -1.0)  # vertex of the quadratic
    inside = (tv > 0.0) & (tv < 1.0)
    dv = np.where(inside, 3.0 * c0 * tv * tv + 2.0 * c1 * tv + c2, 0.0)
    ok = (d0 >= 0.0) & (d1 >= 0.0) & (dv >= 0.0)
    return np.all(ok, axis=1)


def _as_2d(a: np.ndarray) -> np.ndarray:
    return a[:, None] if a.ndim == 1 else a


def _spline_coeffs(s: np.ndarray, vals: np.ndarray, *, zero_slope_end: bool = True
                   ) -> np.ndarray:
    """Cubic spline through (s, vals[:, c]) as (C, nn, 4) coefficients in t.

    Not-a-knot at grazing and at kinks; zero slope at normal incidence (s = 1),
    where the albedo of an isotropic model is an even function of θ and w is
    linear in θ.
    """
    from scipy.interpolate import CubicSpline

    h = s[1] - s[0]
    zero = np.zeros(vals.shape[1])
    bc = ("not-a-knot", (1, zero)) if zero_slope_end else "not-a-knot"
    cs = CubicSpline(s, vals, axis=0, bc_type=bc)
    c = cs.c  # (4, nn, C) in powers of (s - s_j), highest first
    scale = np.array([h**3, h**2, h, 1.0])[:, None, None]
    return np.ascontiguousarray(np.transpose(c * scale, (2, 1, 0)))


def _eval_coeffs(coeffs: np.ndarray, t: np.ndarray) -> np.ndarray:
    c = np.transpose(coeffs, (1, 0, 2))  # (nn, C, 4)
    t = t[:, None]
    return ((c[..., 0] * t + c[..., 1]) * t + c[..., 2]) * t + c[..., 3]


def _label(model) -> str:
    return getattr(model, "name", None) or repr(model)


# --------------------------------------------------------------------------- kernels
_KERNELS: dict = {}


def _pumped_kernel(base_kernel, g_code: int):
    """The compiled kernel f/g for *base_kernel* and built-in g (cached).

    Packed parameters of one channel (``p``), from the left: the base's
    parameters (K values), the table (see :func:`_table_lookup`), then the header
    ``[monotone, cap, s_top, nn, K]`` read from the right — so the layout nests and a
    pumped kernel can be pumped again.
    """
    key = (base_kernel, g_code)
    if key in _KERNELS:
        return _KERNELS[key]
    controlled = g_code == 1

    @numba.njit
    def kernel(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
        if iz <= 0.0 or oz <= 0.0:
            return 0.0
        m = p.shape[0]
        k = int(p[m - 1])
        f = base_kernel(ix, iy, iz, ox, oy, oz, p[:k])
        if f == 0.0:
            return 0.0  # nothing to pump (outside the lobe): skip the lookups
        if p[m - 5] != 0.0:
            # the tabulated albedo is non-decreasing in cos θ (checked at build time), so
            # max(a(L), a(V)) = a(max(N·L, N·V)): one lookup instead of two
            g = _table_lookup(p, k, iz if iz > oz else oz)
        else:
            a_i = _table_lookup(p, k, iz)
            a_o = _table_lookup(p, k, oz)
            g = a_i if a_i > a_o else a_o
        if controlled:
            if iz > g:
                g = iz
            if oz > g:
                g = oz
        if p[m - 4] != 0.0 and g > 1.0:
            g = 1.0  # eq. (17) g <= 1 (the table's margin may exceed 1 where a = 1)
        if g < G_FLOOR:
            g = G_FLOOR  # a = 0 with f > 0 only by rounding at the horizon; avoid inf
        return f / g

    _KERNELS[key] = kernel
    return kernel


def _g_max(wi, wo, a_i, a_o):
    return np.maximum(a_i, a_o)


def _g_controlled(wi, wo, a_i, a_o):
    g = np.maximum(a_i, a_o)
    cz = np.maximum(wi[..., 2], wo[..., 2])
    return np.maximum(g, cz[..., None] if g.ndim > cz.ndim else cz)


_G_NUMPY = {"max": _g_max, "controlled": _g_controlled}


# --------------------------------------------------------------------------- the model
class PumpedBRDF(BRDF):
    """f*(L, V) = f(L, V)/g(L, V): one pumping stage over a base model.

    Built by :func:`pump`; a :class:`~brdfkit.models.BRDF` like any other.
    The base's parameters pass through (:attr:`values`, :meth:`with_params`
    re-pumps with new values), :meth:`sample` and :meth:`pdf` are the base's
    (the pumped lobe has the same shape, only reweighted by 1/g ∈ [1, 1/a]),
    :meth:`lobes` are the base's.

    Attributes
    ----------
    base : BRDF
        The model this stage divides (itself possibly pumped).
    root : BRDF
        The original, unpumped model.
    g : str
        ``"max"``, ``"controlled"`` or ``"custom"``.
    table : AlbedoTable
        The base's tabulated albedo.
    capped : bool
        Whether g is capped at 1 (False only for a base that gains energy).
    stages : list of str
        The g of every stage, innermost first.
    """

    reciprocal = True

    def __init__(self, base: BRDF, g: str | Callable = "max", *, _g_fn: Callable | None = None):
        self.base = base
        self.root = base.root if isinstance(base, PumpedBRDF) else base
        self.g = g if isinstance(g, str) else "custom"
        self._g_callable = None if isinstance(g, str) else g
        self.stages = (base.stages if isinstance(base, PumpedBRDF) else []) + [self.g]
        self.params = self.root.params
        self.has_sampler = base.has_sampler
        self.width_param = self.root.width_param
        self.name = f"{self.root.name}+pump[{','.join(self.stages)}]"
        self.citation = (f"{self.root.citation}; pumped: Neumann et al. 1999 eq. (16) with "
                         + ", ".join(_G_EQ.get(s, "a user g (eq. 17)") for s in self.stages))
        self.summary = f"{self.root.name} with its albedo pumped up ({', '.join(self.stages)})"
        self._values = self.root._values
        self.n_channels = base.n_channels
        self.table = build_albedo_table(base)
        self.capped = bool(np.all(self.table.max_albedo - self.table.max_midpoint_error
                                  <= 1.0 + ENGINE_ERR))
        if not self.capped:
            if self._g_callable is not None:
                raise ParameterError(
                    f"pump: the albedo of {base.name} reaches {self.table.max_albedo.max():.6g} "
                    "> 1, so no g can satisfy eq. (17) max(a(L), a(V)) <= g <= 1; use "
                    "g='max', which drops the cap g <= 1 and still gives a* <= 1")
            warnings.warn(
                f"pump: the albedo of {base.name} exceeds 1 (max {self.table.max_albedo.max():.4g})"
                "; eq. (17) cannot hold there, so g is not capped at 1: a* <= 1 everywhere, but "
                "a* < a where a > 1", PumpingWarning, stacklevel=3)
        if self._g_callable is not None:
            _validate_g(self._g_callable, self._albedo_at_cos)
        base_kernel = getattr(base, "kernel", None)
        if base_kernel is not None and self._g_callable is None:
            self.kernel = _pumped_kernel(base_kernel, G_CHOICES[self.g])
        else:
            self.kernel = None
        self._packed = self._pack()
        self.albedo_kink_mus = self._kink_mus()

    def _kink_mus(self) -> tuple:
        """cos θ_L where this stage's albedo a*(θ_L) has a kink (for the next table).

        A branch switch of g that happens for every V at once as L moves makes a
        kink in a*(L): for g₂ where the tabulated a(L) crosses N·L = cos θ_L.
        Switches between a(L) and a(V) or N·V sweep over V smoothly and leave a*
        smooth. The base's kinks carry over (g uses a(L)).
        """
        from scipy.optimize import brentq

        out = list(getattr(self.base, "albedo_kink_mus", ()))
        if self.g == "controlled":
            grid = np.linspace(1e-6, 1.0, 2049)
            d = _as_2d(self._albedo_at_cos(grid)) - grid[:, None]
            for ch in range(d.shape[1]):
                sg = np.signbit(d[:, ch])
                for j in np.nonzero(sg[1:] != sg[:-1])[0]:
                    out.append(brentq(lambda m, ch=ch: float(_as_2d(
                        self._albedo_at_cos(np.array([m])))[0, ch] - m),
                        grid[j], grid[j + 1], xtol=1e-14))
        return tuple(sorted(set(round(float(m), 14) for m in out)))

    # ---------------------------------------------------------------- packing
    def _pack(self) -> np.ndarray:
        bp = np.asarray(self.base.packed)
        k = bp.shape[1]
        rows = []
        for c in range(bp.shape[0]):
            header = [1.0 if self.table.nondecreasing[c] else 0.0, 1.0 if self.capped else 0.0,
                      self.table.s_top, float(self.table.n_intervals), float(k)]
            rows.append(np.concatenate([bp[c], self.table.packed(c), header]))
        return np.ascontiguousarray(np.array(rows, dtype=np.float64))

    # -------------------------------------------------------------- evaluation
    def eval(self, wi, wo) -> np.ndarray:
        """Pumped BRDF f*(wi, wo) = f(wi, wo)/g(wi, wo) in 1/sr (see :meth:`BRDF.eval`)."""
        if self.kernel is not None:
            return super().eval(wi, wo)
        wi = as_directions(wi, "wi")
        wo = as_directions(wo, "wo")
        f = np.asarray(self.base.eval(wi, wo))
        a_i = self._albedo_at_cos(wi[..., 2])
        a_o = self._albedo_at_cos(wo[..., 2])
        g_fn = self._g_callable if self._g_callable is not None else _G_NUMPY[self.g]
        g = np.asarray(g_fn(wi, wo, a_i, a_o), dtype=np.float64)
        if self.capped:
            g = np.minimum(g, 1.0)
        g = np.maximum(g, G_FLOOR)  # see G_FLOOR
        return np.where(f > 0.0, f / np.where(f > 0.0, g, 1.0), 0.0)

    __call__ = eval

    def _albedo_at_cos(self, mu) -> np.ndarray:
        """Tabulated albedo (upper bound); capped at 1 for an energy-conserving base."""
        a = self.table.at_cos(mu)
        return np.minimum(a, 1.0) if self.capped else a

    def albedo_kinks_nv(self, theta) -> np.ndarray:
        """Levels k of N·V = cos θ_V where f*(L, ·) has a kink, for the albedo engine.

        g switches branch where two of its arguments are equal; all of them depend
        on V only through θ_V, so every kink is a circle N·V = k: a(V) = a(L)
        (k = cos θ_L and the other roots when a is not monotone), and for the
        controlled g₂ also N·V = a(L), a(V) = N·L and a(V) = N·V. Earlier stages'
        kinks are included. Returns shape (T, K), NaN where a level does not exist.
        """
        th = np.asarray(theta, dtype=np.float64).reshape(-1)
        mu_l = np.cos(th)
        grid = np.linspace(0.0, 1.0, 1025)  # cos θ_V; roots located to ~1e-3 then refined
        a_grid = _as_2d(self._albedo_at_cos(grid))  # (M, C)
        a_l = _as_2d(self._albedo_at_cos(mu_l))  # (T, C)
        cols: list[np.ndarray] = [mu_l]

        def roots(diff):  # diff (T, M): the crossings in cos θ_V by linear interpolation
            sgn = np.signbit(diff)
            out = []
            for r in range(diff.shape[0]):
                idx = np.nonzero(sgn[r, 1:] != sgn[r, :-1])[0][:3]
                row = np.full(3, np.nan)
                for q, j in enumerate(idx):
                    d0, d1 = diff[r, j], diff[r, j + 1]
                    row[q] = grid[j] + (grid[j + 1] - grid[j]) * d0 / (d0 - d1)
                out.append(row)
            return np.array(out).reshape(diff.shape[0], 3)

        for ch in range(a_grid.shape[1]):
            cols.append(roots(a_grid[None, :, ch] - a_l[:, ch:ch + 1]))
            if self.g == "controlled":
                cols.append(a_l[:, ch])
                cols.append(roots(a_grid[None, :, ch] - mu_l[:, None]))
                own = roots((a_grid[:, ch] - grid)[None, :])
                cols.append(np.broadcast_to(own, (th.size, own.shape[1])))
        if isinstance(self.base, PumpedBRDF) or callable(getattr(self.base, "albedo_kinks_nv",
                                                                 None)):
            cols.append(np.asarray(self.base.albedo_kinks_nv(th), dtype=np.float64)
                        .reshape(th.size, -1))
        kv = np.column_stack([np.asarray(c, dtype=np.float64).reshape(th.size, -1)
                              for c in cols])
        kv = np.where((kv > 0.0) & (kv < 1.0), kv, np.nan)
        # distinct levels first (a root of a(V) = a(L) is usually cos θ_L itself)
        kv = np.sort(np.round(kv, 12), axis=1)
        dup = np.zeros_like(kv, dtype=bool)
        dup[:, 1:] = np.abs(np.diff(kv, axis=1)) < 1e-9
        kv = np.where(dup, np.nan, kv)
        return np.sort(kv, axis=1)  # NaNs last

    def sample(self, wo, u):
        """The base model's sampler (the pdf is the base pdf)."""
        return self.base.sample(wo, u)

    def pdf(self, wi, wo):
        """The base model's pdf."""
        return self.base.pdf(wi, wo)

    def lobes(self):
        """The base model's lobes (f/g has the base's shape, reweighted by 1/g ∈ [1, 1/a])."""
        return self.base.lobes()

    # --------------------------------------------------------------- accessors
    def pump_chain(self) -> list[tuple[str | Callable, int]]:
        """The stages as run-length ``(g, times)`` pairs, innermost first."""
        chain: list = []
        node = self
        gs = []
        while isinstance(node, PumpedBRDF):
            gs.append(node._g_callable if node._g_callable is not None else node.g)
            node = node.base
        for g in reversed(gs):
            if chain and chain[-1][0] is g or (chain and isinstance(g, str) and chain[-1][0] == g):
                chain[-1] = (g, chain[-1][1] + 1)
            else:
                chain.append((g, 1))
        return chain

    def with_params(self, **changes) -> BRDF:
        """The same pumping applied to the root model with some parameters changed."""
        m = self.root.with_params(**changes)
        for g, k in self.pump_chain():
            m = pump(m, g, times=k)
        return m

    def to_dict(self) -> dict:
        """The root's dict plus ``"pump": {"g": ..., "times": k}`` (a list if stages differ)."""
        d = self.root.to_dict()
        chain = [{"g": g if isinstance(g, str) else "custom", "times": k}
                 for g, k in self.pump_chain()]
        d["pump"] = chain[0] if len(chain) == 1 else chain
        return d

    def __repr__(self) -> str:
        g = self.g if self._g_callable is None else self._g_callable
        return f"brdfkit.pumping.pump({self.base!r}, g={g!r}, times=1)"


def _validate_g(g: Callable, albedo_at_cos: Callable) -> None:
    """Check a user g against eq. (17) on a structured set of pairs; raise with a witness."""
    th = np.radians([0.0, 10.0, 30.0, 45.0, 60.0, 75.0, 85.0, 89.0, 89.9])
    dphi = np.radians([0.0, 45.0, 90.0, 135.0, 180.0])
    ti, to, dp = (x.ravel() for x in np.meshgrid(th, th, dphi, indexing="ij"))
    wi = np.stack([np.sin(ti), np.zeros_like(ti), np.cos(ti)], axis=-1)
    wo = np.stack([np.sin(to) * np.cos(dp), np.sin(to) * np.sin(dp), np.cos(to)], axis=-1)
    a_i = albedo_at_cos(wi[..., 2])
    a_o = albedo_at_cos(wo[..., 2])
    try:
        g_lv = np.asarray(g(wi, wo, a_i, a_o), dtype=np.float64)
        g_vl = np.asarray(g(wo, wi, a_o, a_i), dtype=np.float64)
        g_lv = np.broadcast_to(g_lv, np.broadcast_shapes(g_lv.shape, a_i.shape))
        g_vl = np.broadcast_to(g_vl, g_lv.shape)
    except BrdfkitError:
        raise
    except Exception as exc:  # a user callable can fail in any way; report it as bad input
        raise ParameterError(f"pump: the custom g(wi, wo, a_i, a_o) failed on arrays of "
                             f"shape {wi.shape}: {type(exc).__name__}: {exc}") from exc
    lower = np.maximum(a_i, a_o)
    checks = [
        ("g must be finite", ~np.isfinite(g_lv)),
        ("symmetry g(L, V) = g(V, L)", np.abs(g_lv - g_vl) > 1e-9 * np.maximum(1.0, np.abs(g_lv))),
        ("max(a(L), a(V)) <= g", g_lv < lower - 1e-9),
        ("g <= 1", g_lv > 1.0 + 1e-9),
    ]
    for what, bad in checks:
        if np.any(bad):
            idx = np.argwhere(bad)[0]
            j = int(idx[0])
            extra = (f", g(V, L) = {float(np.ravel(g_vl[j])[0]):.6g}" if "symmetry" in what
                     else f", max(a(L), a(V)) = {float(np.ravel(lower[j])[0]):.6g}")
            raise ParameterError(
                f"pump: the custom g violates eq. (17) ({what}): g(L, V) = "
                f"{float(np.ravel(g_lv[j])[0]):.6g}{extra} at L = (theta {math.degrees(ti[j]):g} "
                f"deg, phi 0 deg), V = (theta {math.degrees(to[j]):g} deg, phi "
                f"{math.degrees(dp[j]):g} deg)")


# --------------------------------------------------------------------------- operator
def pump(model: BRDF, g: str | Callable = "max", *, times: int = 1) -> BRDF:
    """Pump up the albedo of *model* (Neumann et al. 1999, eq. 16), *times* times.

    Parameters
    ----------
    model : BRDF
        A reciprocal model (``model.reciprocal`` true), registered or pumped.
    g : {"max", "controlled"} or callable
        ``"max"`` (also ``"g1"``): g₁ = max(a(L), a(V)), eq. (20);
        ``"controlled"`` (``"g2"``): g₂ = max(a(L), a(V), N·V, N·L), eq. (21).
        A callable ``g(wi, wo, a_i, a_o)`` (NumPy arrays; a_i, a_o are the
        tabulated albedos — upper bounds within 1e-5, capped at 1 for an
        energy-conserving base — with a trailing channel axis when coloured)
        must be symmetric with max(a_i, a_o) ≤ g ≤ 1 (eq. 17); it is checked
        on a structured set of pairs and evaluated in NumPy (slower).
    times : int, keyword-only
        Number of pumpings (≥ 0; 0 returns *model* itself).

    Returns
    -------
    BRDF
        A :class:`PumpedBRDF` (or *model* when ``times == 0``).

    Raises
    ------
    ParameterError
        Non-reciprocal base, unknown g, bad *times*, or a custom g that
        violates eq. (17) (the message names the condition and a pair).

    Warns
    -----
    PumpingWarning
        When the base's albedo exceeds 1 (eq. 17 cannot hold; see the module
        docstring).

    Examples
    --------
    >>> import brdfkit
    >>> from brdfkit.pumping import pump
    >>> m = pump(brdfkit.model("modified-phong", rho_d=0, rho_s=1, n=20), "controlled", times=2)
    """
    if not isinstance(model, BRDF):
        raise ParameterError(f"pump: model must be a brdfkit model (BRDF); got {type(model)!r}")
    if isinstance(times, bool) or not isinstance(times, int | np.integer) or times < 0:
        raise ParameterError(f"pump: times must be an integer >= 0; got {times!r}")
    if isinstance(g, str):
        key = g.strip().lower()
        if key not in _G_ALIASES:
            raise ParameterError(
                f"pump: g must be 'max' (g1, eq. 20), 'controlled' (g2, eq. 21) or a callable "
                f"g(wi, wo, a_i, a_o); got {g!r}")
        g = _G_ALIASES[key]
    elif not callable(g):
        raise ParameterError(f"pump: g must be a string or a callable; got {type(g)!r}")
    if not getattr(model, "isotropic", True):
        raise ParameterError(
            f"pump: {model.name} is anisotropic; the pumping tables the albedo as a function "
            "of the incidence angle only, which needs an isotropic base")
    if not getattr(model, "reciprocal", False):
        raise ParameterError(
            f"pump: {model.name} is not reciprocal (f(L, V) != f(V, L)); the pumped model "
            "f/g is reciprocal only for a symmetric base (Neumann et al. 1999 §3)")
    for _ in range(int(times)):
        model = PumpedBRDF(model, g)
    return model


def pump_sequence(model: BRDF, g: str | Callable = "max", *, times: int = 3) -> list[BRDF]:
    """``[model, pumped once, …, pumped times]`` (each stage built once)."""
    out = [model]
    for _ in range(int(times)):
        out.append(pump(out[-1], g))
    return out


def mirror_radiance(model, theta) -> np.ndarray:
    """Output radiance toward the mirror direction under a point light, eq. (3).

    A point source of intensity 4π at distance 1 in direction L at incidence
    *theta* (radians, azimuth 0), viewer at R(L): L_out = f(L, R(L)) cos θ_L
    (Neumann et al. §1.1 normalise the irradiance to cos θ_L).
    Shape ``theta.shape`` (+ ``(C,)`` when coloured).
    """
    th = np.asarray(theta, dtype=np.float64)
    wi = np.stack([np.sin(th), np.zeros_like(th), np.cos(th)], axis=-1)
    wo = wi * np.array([-1.0, -1.0, 1.0])
    f = np.asarray(model.eval(wi, wo))
    cos = np.cos(th)
    return f * (cos[..., None] if f.ndim > th.ndim else cos)


def from_dict(d: dict) -> BRDF:
    """Rebuild a model from :meth:`BRDF.to_dict` / :meth:`PumpedBRDF.to_dict` output."""
    from brdfkit.models import model as make

    if not isinstance(d, dict) or "model" not in d:
        raise ParameterError(f"from_dict: expected a dict with a 'model' key; got {d!r}")
    m = make(d["model"], **d.get("params", {}))
    chain = d.get("pump")
    if chain is None:
        return m
    for stage in ([chain] if isinstance(chain, dict) else chain):
        if stage.get("g") == "custom":
            raise ParameterError("from_dict: a custom g cannot be rebuilt from a dict")
        m = pump(m, stage.get("g", "max"), times=int(stage.get("times", 1)))
    return m
