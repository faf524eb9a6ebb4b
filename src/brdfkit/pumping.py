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
peaks of 1.69, 5.05, 10.99 × c after 1, 2, 3 pumpings: the super-metal; g₂
gives exactly c at every angle after one pumping — f* = c cos θ/cos θ — and
then 6.66 and 17.4 × c at 85.9° after 2 and 3).

The paper's n = 20 observations (§3.2), quantified as the
hemispherical–hemispherical albedo ρ_hh after k = 0 … 5 controlled pumpings
(``tests/test_pumping.py::test_paper_observations_n20``): Phong 0.669, 0.903,
0.975, 0.993, 0.997, 0.999 — gains 0.234, 0.072, 0.017, 0.005, so "worth
pumping 2 or 3 times" holds (a(80°): 0.200, 0.638, 0.870, 0.949, 0.978,
0.990). Blinn 0.550, 0.665, 0.848, 0.942, 0.979, 0.991 — gains 0.115, 0.183,
0.094, 0.036, 0.013: the *first* controlled pumping is the one held back (g₂ =
N·L wherever a < cos θ), the second gains more, and the albedo tends to 1.
So "the albedo of the Blinn model does not significantly increase with the
second and consecutive pumping-up operations" and "the process will converge
to an albedo that is below the constant 1" do not hold for eq. (21) as
printed: after one controlled pumping a* ≥ cos θ almost everywhere, g₂ = g₁
from then on, and the radiance bound is lost with it (above).

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
(:func:`brdfkit.analysis.albedo`), on a grid uniform in w = √(1 − √(1 − cos
θ)) over θ ∈ [0, 89.9°] — linear in θ at normal incidence, dense near grazing
where sharp lobes are cut by the horizon (see :class:`AlbedoTable`) — and
interpolates with a cubic spline. The grid is doubled until the spline,
checked against the engine at every interval midpoint, is within
``INTERP_TOL`` there. A pumped stage's albedo has kinks (for g₂: where the
previous table a(θ) crosses cos θ, since g switches from a(L) to N·L for all V
at once; the base's kinks carry over): :class:`PumpedBRDF` lists them in
``albedo_kink_mus`` and the next table is split there into pieces, each with
its own uniform grid and spline, so no interval straddles a kink (the
controlled Blinn n = 20 stage-3 table needs 54 intervals instead of > 512, and
builds in seconds). The stored table is the spline **plus** a margin δ = 2 ×
(largest midpoint error) + ``ENGINE_ERR`` (5e-7), so it is an upper bound of
the albedo and g ≥ a(L) holds — the theorem's only requirement — in spite of
rounding: a* ≤ 1 with no tolerance. The total error of the table stays below
1e-5. Beyond 89.9° (the engine's stated range) the table is extended by its
last value; for the Phong family, whose albedo falls toward grazing, that
over-estimates a and stays safe.
Coloured models get one table per channel. Anisotropic bases (attribute
``isotropic`` False) are refused: their albedo is not a function of θ alone.

Evaluation: one lookup for a whole chain
----------------------------------------
The kernel of a pumped model runs on every pair, so its table reads must cost
less than the base model (issue target: ≤ 1.3 × the base's time). The spline
above, in w, needs two square roots and a piece search per read; the kernels
instead read a :class:`Lookup` derived from it: local cubics in μ = cos θ on
two levels (cell ``int(μ·M)``, then a uniform grid inside the cell, anchored
so that the function's kinks are nodes), within ``LUT_TOL`` (5e-7, relative)
of the table, with a margin that keeps the bound on the safe side. And when
the tabulated albedo is non-decreasing in cos θ — the Phong and Blinn
families, but not a Fresnel rise at grazing — max(a(L), a(V)) =
a(max(N·L, N·V)), and N·L, N·V enter g₂ the same way, so every stage's g is a
function of μ = max(N·L, N·V) alone and k stages collapse into

    f⁽ᵏ⁾(L, V) = f(L, V) · q(μ),   q(μ) = 1 / ∏ⱼ gⱼ(μ),

one lookup however many pumpings (:class:`PumpedBRDF` attribute ``chained``;
where a table dips by up to ``CHAIN_DIP_TOL`` while cos θ grows — a rounding
ripple — its g is raised by the depth of the dip, which keeps
max(a(L), a(V)) ≤ g(max(N·L, N·V)) without adding kinks). A stage whose
albedo is not monotone wraps the previous kernel with two lookups, as
eq. (20) is written. The lookup of q bounds it from below, the lookup of a
from above, and the cap g ≤ 1 is re-applied in the kernel after the read
(the margin may cross it), so the kernel's f* never exceeds the
stage-by-stage definition with the tables (a* ≤ 1 is kept) and pumping never
lowers f. Finally a pumped model evaluates through its own compiled loop
with the kernel inlined (:func:`brdfkit.models._base.checked_driver`): called
through the generic loop, the composite kernel stayed an out-of-line call.

Public objects
--------------
- :func:`pump` — the operator.
- :class:`PumpedBRDF` — the result (a :class:`brdfkit.models.BRDF`).
- :class:`AlbedoTable` — a stage's tabulated albedo.
- :func:`build_albedo_table` — tabulate any model's albedo.
- :class:`Lookup`, :func:`build_lookup` — the kernels' fast table of a function of cos θ.
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
from brdfkit.models._base import BRDF, checked_driver

__all__ = [
    "G_CHOICES",
    "AlbedoTable",
    "Lookup",
    "PumpedBRDF",
    "PumpingWarning",
    "build_albedo_table",
    "build_lookup",
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
#: Evaluation lookup (:class:`Lookup`): first-level cells, uniform in μ = cos θ.
LUT_CELLS = 64
#: Relative tolerance of the lookup against the stage tables it is built from
#: (its margin at most doubles it: the total stays well inside the 1e-5 budget).
LUT_TOL = 5e-7
#: Most intervals per cell; reached only by a cell with three kinks (the caps of
#: several stages crossing 1 within 1e-4 of normal incidence), refined instead.
LUT_MAX_SUB = 4096
#: Check points per interval (the interpolant is compared with the function there).
LUT_CHECK = 8
#: A stage joins a chain (one lookup for all stages) when its tabulated albedo is
#: non-decreasing in cos θ up to dips this small (g is raised by the dip, so it only
#: grows: a rounding ripple of the table at normal incidence, ~1e-9, not a real
#: minimum such as a Fresnel rise at grazing, ~1e-2; small enough to keep the total
#: error of g within 1e-5).
CHAIN_DIP_TOL = 1e-6
#: Kinks closer than this are the same kink (found twice, e.g. by two stages).
LUT_KINK_MERGE = 1e-9
#: g is never smaller than this: a zero albedo with f > 0 can only come from
#: rounding at the horizon, and dividing by it would give inf.
G_FLOOR = 1e-12


class PumpingWarning(UserWarning):
    """A pumping step cannot meet eq. (17) (the base gains energy somewhere)."""


# --------------------------------------------------------------------------- albedo table
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

    @property
    def n_intervals(self) -> int:
        """Number of spline intervals."""
        return self.coeffs.shape[1]

    def __call__(self, theta) -> np.ndarray:
        """Tabulated albedo (an upper bound) at incidence angles *theta* (radians).

        Returns shape ``theta.shape`` or ``theta.shape + (C,)`` when coloured.
        """
        return self.at_cos(np.cos(np.asarray(theta, dtype=np.float64)))

    def at_cos(self, mu) -> np.ndarray:
        """Tabulated albedo at cos θ = *mu* (NumPy; kernels read a :class:`Lookup` of it)."""
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
                       coloured=coloured)


def _w_of_mu(mu) -> np.ndarray:
    """Table variable w = √(1 − √(1 − μ)) of μ = cos θ (clamped to [0, 1])."""
    r = np.clip(1.0 - np.asarray(mu, dtype=np.float64), 0.0, 1.0)
    return np.sqrt(1.0 - np.sqrt(r))


def _crossings(fn: Callable, grid: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Roots of *fn* (μ → (T, C)) bracketed by sign changes of *values* = fn(grid)."""
    from scipy.optimize import brentq

    out = []
    for ch in range(values.shape[1]):
        sg = np.signbit(values[:, ch])
        for j in np.nonzero(sg[1:] != sg[:-1])[0]:
            out.append(brentq(lambda m, ch=ch: float(fn(np.array([m]))[0, ch]),
                              grid[j], grid[j + 1], xtol=1e-15))
    return np.array(out, dtype=np.float64)


def _dips(albedo_at_cos: Callable, n: int = 1 << 15) -> np.ndarray:
    """Per channel, max over μ₁ < μ₂ of a(μ₁) − a(μ₂): how far the albedo falls while
    cos θ grows (0 for a non-decreasing one), on a grid dense at grazing like the
    table's variable."""
    w = np.linspace(0.0, 1.0, n)
    a = _as_2d(albedo_at_cos(1.0 - (1.0 - w * w) ** 2))
    return np.max(np.maximum.accumulate(a, axis=0) - a, axis=0)


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


# --------------------------------------------------------------------------- evaluation lookup
@numba.njit(cache=True, inline="always")
def _lookup(p, off, mu):  # pragma: no cover - compiled
    """Value at μ = *mu* of the piecewise-cubic :class:`Lookup` stored at ``p[off:]``.

    Two levels, no square root, no search: the cell is ``int(μ·M)``; inside it a
    uniform grid anchored at the cell's kink (see :class:`Lookup`).
    """
    if not mu >= 0.0:
        mu = 0.0  # only reached with mu > 0 from the kernels; keeps the index >= 0 regardless
    if mu > 1.0:
        mu = 1.0  # |ω| = 1 up to rounding (or an unnormalised input): keep the index in range
    m = int(p[off])
    j = int(mu * m)
    if j > m - 1:
        j = m - 1  # mu = 1: the last cell
    h = off + 1 + 4 * j
    y = (mu - p[h]) * p[h + 1]  # grid coordinate from the cell's anchor (>= 0 by construction)
    k = int(y)
    last = int(p[h + 3])
    if k > last:
        k = last  # the cell's last node (mu at the cell's upper edge)
    t = y - k
    b = off + int(p[h + 2]) + 4 * k
    return ((p[b] * t + p[b + 1]) * t + p[b + 2]) * t + p[b + 3]


@dataclass(frozen=True)
class Lookup:
    """A positive function of μ = cos θ ∈ [0, 1] stored for a fast kernel lookup.

    The kernels of pumped models evaluate the albedo tables (or the product of a whole
    chain of stages, see :class:`PumpedBRDF`) on every pair, so the lookup must cost
    less than the base model: a square root (as in the table variable of
    :class:`AlbedoTable`) or a search already costs a noticeable fraction of a Phong
    evaluation. Here μ ∈ [0, 1] is split into ``M`` equal cells (the cell is
    ``int(μ·M)``); each cell holds a uniform grid of its own spacing h, with on every
    interval the cubic through the function at t = 0, ⅓, ⅔, 1 (local: no interval's
    cubic depends on its neighbours, so a kink at a node stays sharp; continuous, since
    neighbours share the node value), refined until it is within ``tol`` of the
    function, relative, at ``LUT_CHECK`` points per interval. The grid is anchored at
    the function's kink in that cell if it has one — nodes at anchor + i·h — so that a
    kink (where g₂ switches to N·L, where g reaches the cap 1, where the source table
    has a piece boundary or ends at 89.9°) is always a node and never costs refinement
    (two per cell; a third costs refinement). The stored cubics are scaled by (1 ± ε), ε
    twice the largest relative deficit found (then verified), so the lookup bounds the
    function from the requested side. Cubics rather than straight lines: at ``LUT_TOL``
    = 5e-7 a linear table of the n = 20 Phong's q needs 2370 intervals (38 KB), and in
    some runs on a shared machine pumped evaluation took 1.3–1.5× the base while the
    base itself was unaffected, as when the table is evicted from L1; the cubics need 74
    intervals (2.4 KB, plus 2 KB of cell headers).

    Attributes
    ----------
    n_cells : int
        M.
    header : ndarray, shape (M, 4)
        Per cell: anchor μ_a (≤ the cell's lower edge), 1/h, offset of the
        cell's first interval (relative to the start of the packed lookup),
        index of its last interval.
    data : ndarray, shape (C, n, 4)
        Per channel and interval: the cubic's coefficients in the local
        t ∈ [0, 1], highest power first.
    max_error : float
        Largest relative |interpolant − function| over the check points
        (before the margin).
    epsilon : float
        The margin's relative size.
    bound : str
        ``"upper"`` or ``"lower"``.
    """

    n_cells: int
    header: np.ndarray
    data: np.ndarray
    max_error: float
    epsilon: float
    bound: str

    @property
    def n_intervals(self) -> int:
        """Total number of intervals."""
        return self.data.shape[1]

    def packed(self, c: int) -> np.ndarray:
        """Channel *c* flattened for :func:`_lookup`."""
        return np.concatenate([[float(self.n_cells)], self.header.reshape(-1),
                               self.data[c].reshape(-1)])

    def __call__(self, mu) -> np.ndarray:
        """Vectorised :func:`_lookup`: shape ``mu.shape + (C,)``."""
        mu = np.clip(np.nan_to_num(np.asarray(mu, dtype=np.float64), nan=0.0), 0.0, 1.0)
        j = np.minimum((mu * self.n_cells).astype(np.int64), self.n_cells - 1)
        hd = self.header[j]
        y = (mu - hd[..., 0]) * hd[..., 1]
        k = np.minimum(y.astype(np.int64), hd[..., 3].astype(np.int64))
        b = (hd[..., 2].astype(np.int64) - (1 + 4 * self.n_cells)) // 4 + k
        d = self.data[:, b, :]  # (C, ..., 4)
        t = y - k
        out = ((d[..., 0] * t + d[..., 1]) * t + d[..., 2]) * t + d[..., 3]
        return np.moveaxis(out, 0, -1)


def build_lookup(fn: Callable, *, kinks=(), tol: float = LUT_TOL, bound: str = "upper",
                 n_cells: int = LUT_CELLS) -> Lookup:
    """Tabulate *fn* (μ of shape (T,) → positive values of shape (T, C)) as a :class:`Lookup`.

    Parameters
    ----------
    fn : callable
        Vectorised function of μ = cos θ ∈ [0, 1], positive and finite.
    kinks : array_like, keyword-only
        μ where *fn* is not smooth; they become grid nodes (up to two per
        cell: the grid is anchored at the first and its spacing divides the
        gap to the second; a third is refined around, up to ``LUT_MAX_SUB``
        intervals). Kinks closer than ``LUT_KINK_MERGE`` count as one.
    tol : float, keyword-only
        Relative tolerance of the interpolant at the check points.
    bound : {"upper", "lower"}, keyword-only
        The side from which the stored lookup bounds *fn*.

    Returns
    -------
    Lookup
        Meets *tol* unless a cell would need more than ``LUT_MAX_SUB``
        intervals; the margin then absorbs the larger error (``max_error``).
        The bound is verified at every check point after the margin.
    """
    if bound not in ("upper", "lower"):
        raise ParameterError(f"build_lookup: bound must be 'upper' or 'lower'; got {bound!r}")
    kinks = np.unique(np.asarray([k for k in np.ravel(kinks) if 0.0 < k < 1.0], dtype=np.float64))
    if kinks.size > 1:  # the same kink found twice (e.g. by two stages): once
        kinks = kinks[np.concatenate([[True], np.diff(kinks) > LUT_KINK_MERGE])]
    m = int(n_cells)
    kinks_of: dict = {}
    for kk in kinks:
        kinks_of.setdefault(min(int(kk * m), m - 1), []).append(float(kk))
    lo = np.arange(m) / m
    hi = np.arange(1, m + 1) / m
    t_chk = (np.arange(LUT_CHECK) + 0.5) / LUT_CHECK
    nsub = np.ones(m, dtype=np.int64)
    pending = np.arange(m)
    cells: dict = {}
    worst = 0.0
    while pending.size:
        nodes, chk, spans = [], [], []
        for j in pending:
            h = (hi[j] - lo[j]) / nsub[j]
            ks = kinks_of.get(int(j), [])
            if len(ks) >= 2:  # both kinks on nodes: h divides their gap
                h = (ks[1] - ks[0]) / math.ceil((ks[1] - ks[0]) / h)
            a0 = lo[j] if not ks else ks[0] - math.ceil((ks[0] - lo[j]) / h - 1e-9) * h
            n_int = max(1, math.ceil((hi[j] - a0) / h - 1e-9))
            x = a0 + h * np.arange(n_int + 1)
            nodes.append(a0 + h * np.arange(3 * n_int + 1) / 3.0)  # t = 0, 1/3, 2/3, 1
            # check points inside the cell only (an anchored grid starts below it)
            xc = np.clip(x[:-1, None] + h * t_chk[None, :], lo[j], hi[j])
            chk.append(xc.reshape(-1))
            spans.append((a0, h, n_int, (xc - x[:-1, None]) / h))
        v_all = _as_2d(np.asarray(fn(np.concatenate(nodes)), dtype=np.float64))
        c_all = _as_2d(np.asarray(fn(np.concatenate(chk)), dtype=np.float64))
        if not (np.all(np.isfinite(v_all)) and np.all(v_all > 0.0)
                and np.all(np.isfinite(c_all)) and np.all(c_all > 0.0)):
            raise BrdfkitError("build_lookup: the function must be finite and positive on [0, 1]")
        iv = ic = 0
        still = []
        for j, (a0, h, n_int, tc) in zip(pending, spans, strict=True):
            v = _cubics(v_all[iv:iv + 3 * n_int + 1])
            c = c_all[ic:ic + n_int * LUT_CHECK].reshape(n_int, LUT_CHECK, -1)
            iv += 3 * n_int + 1
            ic += n_int * LUT_CHECK
            err = float(np.max(np.abs(_horner(v, tc) - c) / c))
            if err <= tol or nsub[j] >= LUT_MAX_SUB:
                cells[int(j)] = (a0, h, v, c, tc)
                worst = max(worst, err)
            else:
                nsub[j] *= 2
                still.append(j)
        pending = np.array(still, dtype=np.int64)

    def stored(v, eps):
        return v * (1.0 + eps if bound == "upper" else 1.0 - eps)

    # margin: twice the largest deficit, then verified at every check point
    sign = 1.0 if bound == "upper" else -1.0
    eps = 4.0 * np.finfo(float).eps
    for _ in range(8):
        deficit = max(float(np.max(sign * (c - _horner(stored(v, eps), tc)) / c))
                      for _, _, v, c, tc in cells.values())
        if deficit <= 0.0:
            break
        eps += 2.0 * deficit
    else:  # pragma: no cover - the deficit shrinks geometrically
        raise BrdfkitError("build_lookup: could not make the lookup a bound of the function")
    header = np.empty((m, 4))
    data = []
    pos = 1 + 4 * m
    for j in range(m):
        a0, h, v, _, _ = cells[j]
        data.append(stored(v, eps))  # (n_int, C, 4)
        header[j] = (a0, 1.0 / h, pos, len(v) - 1)
        pos += 4 * len(v)
    data = np.ascontiguousarray(np.transpose(np.concatenate(data, axis=0), (1, 0, 2)))
    return Lookup(n_cells=m, header=header, data=data, max_error=worst, epsilon=eps,
                  bound=bound)


#: Coefficients (t³, t², t, 1) of the cubic through values at t = 0, 1/3, 2/3, 1.
_CUBIC_FROM_THIRDS = np.linalg.inv(np.vander(np.arange(4) / 3.0, 4))


def _cubics(v: np.ndarray) -> np.ndarray:
    """Per interval, the cubic through v at t = 0, ⅓, ⅔, 1: v (3n+1, C) → (n, C, 4)."""
    n = (v.shape[0] - 1) // 3
    y = np.stack([v[0:3 * n:3], v[1:3 * n:3], v[2:3 * n:3], v[3::3]], axis=-1)  # (n, C, 4)
    return y @ _CUBIC_FROM_THIRDS.T


def _horner(coef: np.ndarray, tc: np.ndarray) -> np.ndarray:
    """Cubics coef (n, C, 4) at local coordinates tc (n, L) → (n, L, C)."""
    c = coef[:, None, :, :]
    t = tc[:, :, None]
    return ((c[..., 0] * t + c[..., 1]) * t + c[..., 2]) * t + c[..., 3]


# --------------------------------------------------------------------------- kernels
_KERNELS: dict = {}


def _chain_kernel(root_kernel, k: int, capped: bool):
    """(kernel, driver) for f·q(max(N·L, N·V)), a chain of monotone stages (cached).

    Packed parameters of one channel (``p``): the root model's K parameters,
    then the :class:`Lookup` of q = 1/∏ g_j at the constant offset K (then
    possibly later stages' lookups and the offsets trailer, see
    :meth:`PumpedBRDF._pack`). The root kernel reads its parameters from the
    front of ``p`` — no slicing, and a compile-time offset: both measurably
    cheaper than reading the offset from ``p`` and slicing. *capped*: every
    stage caps g at 1, so q ≥ 1 exactly (the lookup's margin may dip below 1
    where q = 1; raising it back keeps q̃ ≤ q because q ≥ 1 there).
    """
    key = (root_kernel, "chain", k, capped)
    if key not in _KERNELS:
        @numba.njit(inline="always")  # inlined into its own driver (checked_driver)
        def kernel(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
            f = root_kernel(ix, iy, iz, ox, oy, oz, p)  # 0 below the horizon
            if f == 0.0:
                return 0.0  # nothing to pump (outside the lobe, below the horizon)
            q = _lookup(p, k, iz if iz > oz else oz)
            if capped and q < 1.0:
                q = 1.0  # eq. (17) g <= 1 for every stage
            return f * q

        _KERNELS[key] = kernel, checked_driver(kernel)
    return _KERNELS[key]


def _stage_kernel(base_kernel, controlled: bool, capped: bool, depth: int):
    """(kernel, driver) for f/g of stage number *depth*, two albedo lookups (cached).

    The base kernel (pumped or not) reads the same packed row ``p``; this
    stage's :class:`Lookup` starts at ``p[len(p) - depth]`` (the offsets trailer
    of :meth:`PumpedBRDF._pack`), so stages nest without slicing. *capped*:
    g ≤ 1 (eq. 17) is applied after the lookup (whose margin may exceed 1
    where a = 1).
    """
    key = (base_kernel, "stage", controlled, capped, depth)
    if key not in _KERNELS:
        @numba.njit(inline="always")  # inlined into its own driver (checked_driver)
        def kernel(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
            f = base_kernel(ix, iy, iz, ox, oy, oz, p)  # 0 below the horizon
            if f == 0.0:
                return 0.0
            off = int(p[p.shape[0] - depth])
            a_i = _lookup(p, off, iz)
            a_o = _lookup(p, off, oz)
            g = a_i if a_i > a_o else a_o
            if capped and g > 1.0:
                g = 1.0  # eq. (17) g <= 1
            if controlled:
                if iz > g:
                    g = iz
                if oz > g:
                    g = oz
            return f / g

        _KERNELS[key] = kernel, checked_driver(kernel)
    return _KERNELS[key]


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
    depth : int
        ``len(stages)``.
    chained : bool
        Whether this stage and all below it have non-decreasing albedos, so
        the kernel is f_root · q(max(N·L, N·V)) with one lookup (module
        docstring, "Evaluation"); otherwise the kernel wraps the base's
        with two lookups of this stage's albedo.
    lookups : tuple of Lookup
        Per channel: q of the chain (``chained``) or this stage's capped
        albedo; empty for a custom g (evaluated in NumPy from ``table``).
    """

    reciprocal = True

    def __init__(self, base: BRDF, g: str | Callable = "max", *, _g_fn: Callable | None = None):
        self.base = base
        self.root = base.root if isinstance(base, PumpedBRDF) else base
        self.g = g if isinstance(g, str) else "custom"
        self._g_callable = None if isinstance(g, str) else g
        self.stages = (base.stages if isinstance(base, PumpedBRDF) else []) + [self.g]
        self.depth = len(self.stages)
        self.params = self.root.params
        self.has_sampler = base.has_sampler
        self.width_param = self.root.width_param
        self.name = f"{self.root.name}+pump[{','.join(self.stages)}]"
        self.citation = (f"{self.root.citation}; pumped: Neumann et al. 1999 eq. (16) with "
                         + ", ".join(_G_EQ.get(s, "a user g (eq. 17)") for s in self.stages))
        self.summary = f"{self.root.name} with its albedo pumped up ({', '.join(self.stages)})"
        self._values = self.root._values
        self.n_channels = base.n_channels
        self._n_rows = np.asarray(base.packed).shape[0]  # 1, or the number of channels
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
        self.lookups: tuple = ()
        self.chained = False
        self._chain: tuple = ()
        if base_kernel is not None and self._g_callable is None:
            parent_chained = not isinstance(base, PumpedBRDF) or base.chained
            self._dip = _dips(self._albedo_at_cos)
            if parent_chained and np.all(self._dip <= CHAIN_DIP_TOL):
                # every stage so far has a non-decreasing albedo: the whole chain is
                # f_root · q(max(N·L, N·V)) with one lookup (see the class docstring)
                self.chained = True
                self._chain = (base._chain if isinstance(base, PumpedBRDF) else ()) + (self,)
                # one lookup per channel (each with its own grid and margin, so a coloured
                # model pumps exactly like its channels pumped one by one)
                self.lookups = tuple(
                    build_lookup(lambda mu, c=c: self._chain_q(mu)[:, c:c + 1], bound="lower",
                                 kinks=np.concatenate([s._divisor_kinks(c) for s in self._chain]))
                    for c in range(self._n_rows))
                self.kernel, self._driver = _chain_kernel(
                    self.root.kernel, np.asarray(self.root.packed).shape[1],
                    all(s.capped for s in self._chain))
            else:
                self.lookups = tuple(
                    build_lookup(lambda mu, c=c: np.maximum(
                        _as_2d(self.table.at_cos(mu))[:, c:c + 1], G_FLOOR),
                        bound="upper", kinks=self._divisor_kinks(c, table_only=True))
                    for c in range(self._n_rows))
                self.kernel, self._driver = _stage_kernel(
                    base_kernel, self.g == "controlled", self.capped, self.depth)
        else:
            self.kernel = self._driver = None
        self._packed = self._pack()
        self.albedo_kink_mus = self._kink_mus()

    def _kink_mus(self) -> tuple:
        """cos θ_L where this stage's albedo a*(θ_L) has a kink (for the next table).

        A branch switch of g that happens for every V at once as L moves makes a
        kink in a*(L): for g₂ where the tabulated a(L) crosses N·L = cos θ_L.
        Switches between a(L) and a(V) or N·V sweep over V smoothly and leave a*
        smooth. The base's kinks carry over (g uses a(L)).
        """
        out = list(getattr(self.base, "albedo_kink_mus", ()))
        if self.g == "controlled":
            grid = np.linspace(1e-6, 1.0, 2049)

            def diff(m):
                return _as_2d(self._albedo_at_cos(m)) - m[:, None]

            out += list(_crossings(diff, grid, diff(grid)))
        return tuple(sorted(set(round(float(m), 14) for m in out)))

    # ------------------------------------------------------- evaluation lookup
    def _divisor(self, mu) -> np.ndarray:
        """This stage's g as a function of μ = max(N·L, N·V), shape (T, C).

        The table plus its dip d (≤ CHAIN_DIP_TOL; 0 when non-decreasing), so that
        max(a(L), a(V)) ≤ g(max(N·L, N·V)), capped at 1 (eq. 17; each stage, as
        the definition — capping only the product would dent the next stage's
        albedo near normal incidence, where the tables, upper bounds, exceed 1 by
        their margin), raised to μ for g₂ (eq. 21), floored at G_FLOOR.
        """
        mu = np.asarray(mu, dtype=np.float64)
        g = _as_2d(self.table.at_cos(mu)) + self._dip
        if self.capped:
            g = np.minimum(g, 1.0)
        if self.g == "controlled":
            g = np.maximum(g, np.clip(mu, 0.0, 1.0)[:, None])
        return np.maximum(g, G_FLOOR)

    def _chain_q(self, mu) -> np.ndarray:
        """q(μ) = 1/∏ g_j(μ) over the chained stages, shape (T, C)."""
        q = 1.0 / self._chain[0]._divisor(mu)
        for stage in self._chain[1:]:
            q = q / stage._divisor(mu)
        return q

    def _divisor_kinks(self, c: int, table_only: bool = False) -> np.ndarray:
        """μ where channel *c* of this stage's g(μ) is not smooth: the table's piece
        boundaries and its end at THETA_TOP and, unless *table_only* (the albedo
        lookup of an unchained stage, capped in its kernel), where it reaches the
        cap 1 and (g₂) where it crosses μ."""
        w = self.table.breaks[:-1]
        out = [1.0 - (1.0 - w * w) ** 2]
        if table_only:
            return out[0]
        dip = float(self._dip[c])

        def a(m):  # as in _divisor
            return _as_2d(self.table.at_cos(m))[:, c:c + 1] + dip

        grid = np.linspace(0.0, 1.0, 4097)
        a_grid = a(grid)
        cap = 1.0 if self.capped else np.inf
        if self.capped:
            out.append(_crossings(lambda m: a(m) - 1.0, grid, a_grid - 1.0))
        if self.g == "controlled":
            out.append(_crossings(lambda m: np.minimum(a(m), cap) - m[:, None], grid,
                                  np.minimum(a_grid, cap) - grid[:, None]))
        return np.concatenate(out)

    # ---------------------------------------------------------------- packing
    def _pack(self) -> np.ndarray:
        """Packed rows for the kernel: root parameters, lookups, offsets trailer.

        Layout of channel c: the root's K parameters; the lookup of the last
        chained stage (at offset K, read by :func:`_chain_kernel`); the lookup
        of every later (unchained) stage; then a trailer of ``depth`` offsets,
        ``p[len(p) - d]`` = start of stage d's lookup (0 for chained stages),
        read by :func:`_stage_kernel`. Every nested kernel reads this one row.
        """
        if self.kernel is None:
            return np.asarray(self.base.packed)  # not used by a kernel
        chain = []
        node = self
        while isinstance(node, PumpedBRDF):
            chain.append(node)
            node = node.base
        chain.reverse()  # stage 1 … depth
        root = np.asarray(self.root.packed)
        last_chained = max((s for s in chain if s.chained), key=lambda s: s.depth, default=None)
        rows = []
        for c in range(root.shape[0]):
            parts = [root[c]]
            pos = root.shape[1]
            offsets = np.zeros(self.depth)
            for stage in chain:
                if stage.chained and stage is not last_chained:
                    continue  # superseded by the last chained stage's product lookup
                offsets[stage.depth - 1] = 0.0 if stage.chained else pos
                block = stage.lookups[c].packed(0)
                parts.append(block)
                pos += block.size
            rows.append((parts, offsets[::-1]))  # p[len(p) - d] is stage d's offset
        # channels' lookups differ in length: pad before the trailer
        width = max(sum(x.size for x in parts) for parts, _ in rows)
        return np.ascontiguousarray(np.array(
            [np.concatenate(parts + [np.zeros(width - sum(x.size for x in parts)), trailer])
             for parts, trailer in rows], dtype=np.float64))

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
