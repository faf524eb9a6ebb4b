"""
The albedo table of a pumping stage
===================================

Each stage tabulates the albedo of its base once, with the albedo engine, on a
grid uniform in the shared variable w = √(1 − √(1 − cos θ))
(:func:`brdfkit.tables.w_of_mu`), split at the albedo's declared kinks, and
interpolates with cubic splines plus a margin that makes the table an upper
bound of the albedo (``docs/pumping.md``, "The albedo table"). With
``margin=False`` the same builder gives the accurate interpolant itself, which
the compensation operators tabulate E(μ) with (:mod:`brdfkit.compensation`).

Public objects
--------------
- :class:`AlbedoTable` — a stage's tabulated albedo.
- :func:`build_albedo_table` — tabulate any isotropic model's albedo.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from brdfkit.errors import BrdfkitError, ParameterError
from brdfkit.models._base import BRDF
from brdfkit.tables import _as_2d, mu_of_w, theta_of_w, w_of_mu

__all__ = ["ENGINE_ERR", "ENGINE_TOL", "INTERP_TOL", "THETA_TOP", "AlbedoTable",
           "build_albedo_table"]

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
        w(THETA_TOP): the grid is uniform in w = √(1 − √(1 − cos θ)) (the
        shared :func:`brdfkit.tables.w_of_mu`) on [s_top, 1]. This variable is
        linear in θ at normal incidence (where the albedo is even in θ, so the
        spline is clamped to zero slope there) and its square is linear in
        cos θ at grazing (cos θ = 2w² − w⁴), so the nodes crowd where sharp
        lobes meet the horizon.
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
        w = w_of_mu(mu)
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


def _engine(model, tol: float = ENGINE_TOL) -> Callable:
    """The albedo engine as ``theta -> (T,) or (T, C)`` for *model*, to accuracy *tol*."""
    from brdfkit.analysis import albedo  # imported when used (a pumping builds it; start-up)

    def run(theta: np.ndarray) -> np.ndarray:
        # a model without a compiled kernel (custom g) is integrated through its eval, in
        # the frame of its lobes
        parts = [np.asarray(albedo(model, theta[i:i + ENGINE_CHUNK], tol=tol).albedo,
                            dtype=np.float64) for i in range(0, len(theta), ENGINE_CHUNK)]
        return np.concatenate(parts, axis=0)

    return run


def build_albedo_table(model, *, tol: float = INTERP_TOL, nn_start: int = 16,
                       nn_max: int = 8192, kinks_mu=None,
                       engine_tol: float = ENGINE_TOL, margin: bool = True,
                       who: str = "pumping") -> AlbedoTable:
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
    engine_tol : float, keyword-only
        Accuracy asked of the albedo engine (default :data:`ENGINE_TOL`; the margin
        still assumes :data:`ENGINE_ERR`, so a looser value is for approximate
        tables only, e.g. :mod:`brdfkit.pumping.surrogate`'s).
    margin : bool, keyword-only
        True (pumping): add ``delta`` = 2·max_midpoint_error + :data:`ENGINE_ERR`, so the
        table bounds the albedo from above. False: ``delta`` = 0, the interpolant itself
        (error ``max_midpoint_error`` at the midpoints, plus the engine's *engine_tol*).
    who : str, keyword-only
        The operator named in the errors.

    Returns
    -------
    AlbedoTable

    Raises
    ------
    BrdfkitError
        If the albedo is not finite or the tolerance is not met with *nn_max*
        intervals.
    """
    if not isinstance(model, BRDF):
        raise ParameterError(
            f"build_albedo_table: model must be a brdfkit model (BRDF); got {type(model)!r}")
    if not (isinstance(tol, float | int) and 0.0 < tol < 1.0):
        raise ParameterError(f"build_albedo_table: tol must lie in (0, 1); got {tol!r}")
    if not (isinstance(engine_tol, float | int) and 0.0 < engine_tol < 1.0):
        raise ParameterError(
            f"build_albedo_table: engine_tol must lie in (0, 1); got {engine_tol!r}")
    run = _engine(model, engine_tol)
    s_top = float(w_of_mu(math.cos(THETA_TOP)))
    if kinks_mu is None:
        kinks_mu = model.albedo_kink_mus
    kw = np.sort(w_of_mu(np.asarray(kinks_mu, dtype=np.float64).reshape(-1)))
    breaks = [s_top]
    for x in kw:  # pieces at least 1e-3 wide in w (closer kinks: one piece, refined)
        if x - breaks[-1] > 1e-3 and 1.0 - x > 1e-3:
            breaks.append(float(x))
    breaks.append(1.0)
    breaks = np.array(breaks)

    n_eval = 0
    all_coeffs, all_nodes, piece_nn, max_errs, maxes = [], [], [], [], []
    for lo, hi in zip(breaks[:-1], breaks[1:], strict=True):
        nn = max(4, int(round(nn_start * (hi - lo) / (1.0 - s_top))))
        s_nodes = np.linspace(lo, hi, nn + 1)
        vals = _as_2d(run(theta_of_w(s_nodes)))
        n_eval += len(s_nodes)
        while True:
            s_mid = 0.5 * (s_nodes[:-1] + s_nodes[1:])
            mid = _as_2d(run(theta_of_w(s_mid)))
            n_eval += len(s_mid)
            if not (np.all(np.isfinite(vals)) and np.all(np.isfinite(mid))):
                raise BrdfkitError(f"{who}: the albedo of {model.name} is not finite on "
                                   "[0, 89.9] deg; it cannot be tabulated")
            coeffs = _spline_coeffs(s_nodes, vals, zero_slope_end=hi == 1.0)
            interp = _eval_coeffs(coeffs, np.full(nn, 0.5))  # (nn, C) at the midpoints
            err = np.abs(interp - mid) / np.maximum(1.0, np.abs(mid))
            if np.all(err.max(axis=0) <= tol):
                break
            if 2 * nn > nn_max:
                worst = int(np.argmax(err.max(axis=1)))
                raise BrdfkitError(
                    f"{who}: could not tabulate the albedo of {model.name} to {tol:g} "
                    f"with {nn_max} intervals (error {err.max():.3g} at theta = "
                    f"{math.degrees(theta_of_w(s_mid[worst])):.4f} deg)")
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
    delta = 2.0 * max_err + ENGINE_ERR if margin else np.zeros_like(max_err)
    coeffs = np.concatenate(all_coeffs, axis=1)
    coeffs[:, :, 3] += delta[:, None]
    coloured = model.n_channels is not None
    return AlbedoTable(coeffs=coeffs, s_top=s_top, breaks=breaks, piece_nn=tuple(piece_nn),
                       max_midpoint_error=max_err, delta=delta,
                       max_albedo=np.max(maxes, axis=0),
                       theta_nodes=theta_of_w(np.concatenate(all_nodes)), n_evaluations=n_eval,
                       coloured=coloured)


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
    a = _as_2d(albedo_at_cos(mu_of_w(w)))
    return np.max(np.maximum.accumulate(a, axis=0) - a, axis=0)


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


