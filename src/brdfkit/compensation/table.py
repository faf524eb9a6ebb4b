"""
The directional albedo E(μ) a compensation reads, and its average E_avg
=======================================================================

Both operators (:mod:`brdfkit.compensation.operator`) need the albedo E(μ) of the
base's white form (F = 1, :meth:`brdfkit.models.BRDF.fresnel_split`) on every
evaluated pair, and Kulla–Conty also its cosine-weighted average
E_avg = 2∫₀¹ E(μ) μ dμ. They are built in three steps, each reusing what pumping
already has (``docs/compensation.md``, "Tables and their accuracy"):

1. the albedo engine's values on the shared grid w = √(1 − √(1 − μ))
   (:func:`brdfkit.tables.w_of_mu`), interpolated by cubic splines refined until
   they meet :data:`TABLE_TOL` at every interval midpoint — pumping's
   :func:`~brdfkit.pumping.table.build_albedo_table` with ``margin=False``: the
   accurate interpolant, not pumping's upper bound;
2. the kernel's lookup of min(E, 1) (an upper bound of it within
   :data:`~brdfkit.tables.LUT_TOL`; the kernels clamp what they read at 1, so
   Ẽ ≥ min(E, 1) and 0 ≤ 1 − Ẽ): a single-level
   :class:`~brdfkit.tables.UniformLookup` in √μ (4 reads) for a table of one piece E
   never clamps (:func:`_uniform_lookup`), else the two-level
   :class:`~brdfkit.tables.Lookup` (:func:`_two_level`);
3. E_avg integrated *from the clamped lookup itself* (3-point Gauss–Legendre on each
   of its cubic pieces, exact where E·μ is a quartic). So the Kulla–Conty lobe's own
   normalisation 2∫(1 − Ẽ)μ dμ = 1 − E_avg holds with the Ẽ the kernel reads, and
   the compensated albedo is 1 + E − Ẽ ≤ 1: the furnace error is the table's
   pointwise error only, and never an excess.

Public objects
--------------
- :class:`CompensationTable` — E(μ) per channel, its lookups, E_avg, and their
  accuracy (status, success, message).
- :func:`compensation_table` — build it for a model.
- :data:`TABLE_TOL`, :data:`ENGINE_TOL`, :data:`E_FLOOR`.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from brdfkit.errors import ParameterError
from brdfkit.models._base import BRDF
from brdfkit.pumping.table import (
    THETA_TOP,
    AlbedoTable,
    _crossings,
    _engine,
    build_albedo_table,
)
from brdfkit.tables import (
    LUT_TOL,
    Lookup,
    UniformLookup,
    _as_2d,
    build_lookup,
    build_uniform_lookup,
    mu_of_w,
    theta_of_w,
    w_of_mu,
)

__all__ = ["E_FLOOR", "ENGINE_TOL", "TABLE_TOL", "CompensationTable", "compensation_table"]

#: Largest |spline − engine| allowed at the table's interval midpoints (absolute, E ≤ 1).
#: With the lookup's 5e-7 and the engine's 1e-7 this keeps the white furnace of a
#: Kulla–Conty compensated model within 2e-6 of 1, inside the issue's 1e-5.
TABLE_TOL = 1e-6
#: Accuracy asked of the albedo engine for the table's values. 1e-8 (pumping's) costs
#: 4-8× more engine time for GGX (0.33 s for α = 0.3 against 0.04 s at 1e-7) and is not
#: needed: the furnace budget is 1e-5 and TABLE_TOL already 1e-6
#: (benchmarks/bench_compensation.py measures both the time and the furnace).
ENGINE_TOL = 1e-7
#: Smallest stored E: the lookup needs a positive function, and Turquin divides by E. An
#: albedo this small comes only from rounding at the horizon of a sharp lobe.
E_FLOOR = 1e-12
#: Where the grazing piece below THETA_TOP ends (the value is held from there to the
#: horizon): E is smooth in w but behaves like √μ at the horizon, which the kernel's lookup
#: (cells uniform in μ) would need thousands of intervals for; held below 89.999°, a kink
#: the lookup makes a node (docs/compensation.md, "Tables and their accuracy").
THETA_HOLD = math.radians(89.999)
#: Gauss–Legendre nodes on [0, 1] exact for a quartic (E·μ on one cubic piece of the lookup).
_GL_X, _GL_W2 = np.polynomial.legendre.leggauss(3)
_GL_T, _GL_W = 0.5 * (_GL_X + 1.0), 0.5 * _GL_W2  # mapped from [−1, 1] to [0, 1]
#: Gauss–Legendre nodes on [0, 1] exact for degree 11: on one interval of a
#: UniformLookup, Ẽ(x) μ dμ/dx (x = √μ) is a cubic times 2x³, degree 6.
_GLW_X, _GLW_W2 = np.polynomial.legendre.leggauss(6)
_GLW_T, _GLW_W = 0.5 * (_GLW_X + 1.0), 0.5 * _GLW_W2
#: Most doublings of the single-level lookup's intervals from the spline's count (16×);
#: beyond, the two-level Lookup is used.
UNIFORM_MAX_HALVINGS = 4


@dataclass(frozen=True)
class CompensationTable:
    """E(μ) of a model (its white form), per channel, with E_avg and their accuracy.

    Attributes
    ----------
    spline : AlbedoTable
        The engine's values interpolated (pumping's builder, ``margin=False``).
    lookups : tuple of UniformLookup or of Lookup
        Per channel of E, the kernel's table of min(E, 1) (an upper bound within
        ``lookup_error``, relative; read clamped at 1).
    e_avg : ndarray (C,)
        2∫₀¹ min(Ẽ(μ), 1) μ dμ of the lookup.
    e_avg_error : ndarray (C,)
        |E_avg of the lookup − E_avg of the spline| (Gauss–Legendre, 64 nodes per grid
        piece): how far the lookup's average is from the engine's, an estimate of
        E_avg's error beside the engine's *engine_tol*.
    max_albedo : ndarray (C,)
        Largest E the engine found (before the clamp at 1).
    clamped : bool
        Whether E exceeded 1 somewhere (then E is clamped at 1: nothing is restored
        where the base already gains energy).
    interp_error : ndarray (C,)
        Largest |spline − engine| at the interval midpoints.
    lookup_error : float
        Largest relative |lookup − spline| at the lookup's check points (before its
        margin, which makes it a lower bound).
    engine_tol : float
        Accuracy asked of the albedo engine.
    seconds : float
        Time spent building (engine, spline, lookups, E_avg).
    """

    spline: AlbedoTable
    lookups: tuple
    e_avg: np.ndarray
    e_avg_error: np.ndarray
    max_albedo: np.ndarray
    clamped: bool
    interp_error: np.ndarray
    lookup_error: float
    engine_tol: float
    seconds: float

    @property
    def n_channels(self) -> int:
        """Channels of E (1 for a grey white form)."""
        return len(self.lookups)

    @property
    def uniform(self) -> bool:
        """Whether the lookups are single-level (:class:`~brdfkit.tables.UniformLookup`)."""
        return isinstance(self.lookups[0], UniformLookup)

    @property
    def max_error(self) -> float:
        """Bound of |Ẽ − E| the kernels see: spline + lookup (relative, E ≤ 1) + engine."""
        return float(np.max(self.interp_error) + self.lookup_error + self.engine_tol)

    @property
    def status(self) -> int:
        """0 (``converged``): the table met :data:`TABLE_TOL` (building raises otherwise)."""
        return 0

    @property
    def success(self) -> bool:
        """Whether the table may be used as stated (always, once built)."""
        return True

    @property
    def message(self) -> str:
        """One line with the table's accuracy."""
        clamp = (f"; E reaches {float(np.max(self.max_albedo)):.9g} > 1 and is clamped at 1"
                 if self.clamped else "")
        return (f"E(mu) tabulated on {self.spline.n_intervals} intervals: max midpoint error "
                f"{float(np.max(self.interp_error)):.2g}, lookup {self.lookup_error:.2g}, "
                f"engine tol {self.engine_tol:g}; E_avg = "
                + ", ".join(f"{e:.8f}" for e in self.e_avg)
                + f" (+- {float(np.max(self.e_avg_error)):.2g}){clamp}")

    def __call__(self, mu) -> np.ndarray:
        """Ẽ(μ) as the kernels read it (clamped at 1): shape ``mu.shape + (C,)``."""
        mu = np.asarray(mu, dtype=np.float64)
        return np.minimum(np.concatenate([lk(mu) for lk in self.lookups], axis=-1), 1.0)

    def to_dict(self) -> dict:
        """JSON-ready accuracy summary (the result's ``describe``)."""
        return {"e_avg": self.e_avg.tolist(), "e_avg_error": self.e_avg_error.tolist(),
                "max_albedo": self.max_albedo.tolist(), "clamped": self.clamped,
                "interp_error": self.interp_error.tolist(), "lookup_error": self.lookup_error,
                "engine_tol": self.engine_tol, "n_intervals": self.spline.n_intervals,
                "seconds": self.seconds, "status": self.status, "success": self.success,
                "message": self.message}


def _engine_tol(model: BRDF) -> float:
    """:data:`ENGINE_TOL`, or the smaller tolerance the model asks its albedo tables for
    (``albedo_engine_tol``: a kink the engine cannot be told of, e.g. the rough diffuse
    models' azimuth 90°, where the engine's estimate at ENGINE_TOL is not honest)."""
    tol = getattr(model, "albedo_engine_tol", None)
    return ENGINE_TOL if tol is None else min(ENGINE_TOL, float(tol))


def _grazing_piece(model: BRDF, spline: AlbedoTable):
    """E on [w(THETA_HOLD), w(THETA_TOP)]: the engine's values, a cubic spline in w.

    Pumping's table holds E(THETA_TOP) from 89.9° to the horizon; the compensations
    should not: Kulla–Conty's albedo is 1 + E − Ẽ, so a held value costs E(θ) − E(89.9°)
    beyond (8e-4 at 89.999° for GGX α = 0.5), and extending the table's first cubic cost
    1e-5 at 89.99°. The engine integrates there too (its accuracy stays *engine_tol*):
    8 intervals uniform in w, doubled until the midpoints meet :data:`TABLE_TOL` (at most
    64). Returns (CubicSpline, max midpoint error (C,), engine angles).
    """
    from scipy.interpolate import CubicSpline

    run = _engine(model, _engine_tol(model))
    w0, w1 = float(w_of_mu(math.cos(THETA_HOLD))), spline.s_top
    nn, n_eval = 8, 0
    while True:
        nodes = np.linspace(w0, w1, nn + 1)
        mids = 0.5 * (nodes[:-1] + nodes[1:])
        vals = _as_2d(run(theta_of_w(nodes)))
        ref = _as_2d(run(theta_of_w(mids)))
        n_eval += 2 * nn + 1
        cs = CubicSpline(nodes, vals, axis=0)
        err = np.max(np.abs(cs(mids) - ref), axis=0)
        if np.all(err <= TABLE_TOL) or nn >= 64:
            return cs, err, n_eval
        nn *= 2


def _spline_e(spline: AlbedoTable, grazing, mu) -> np.ndarray:
    """E at μ (T,) → (T, C): the table, the grazing piece (:func:`_grazing_piece`) below
    THETA_TOP, held from THETA_HOLD to the horizon."""
    mu = np.asarray(mu, dtype=np.float64)
    out = _as_2d(spline.at_cos(mu)).copy()
    below = mu < math.cos(THETA_TOP)
    if np.any(below):
        w = w_of_mu(np.maximum(mu[below], math.cos(THETA_HOLD)))  # held below THETA_HOLD
        out[below] = _as_2d(grazing(w))
    return out


def _lookup_average(lk: Lookup) -> float:
    """2∫₀¹ min(Ẽ(μ), 1) μ dμ of one channel's lookup, as the kernels read it.

    Cell j covers [j/M, (j+1)/M]; its pieces start at the anchor a₀ with spacing h
    (header), so the breakpoints are a₀ + i·h clipped to the cell; Ẽ·μ is a quartic
    in μ on each, integrated exactly by 3-point Gauss–Legendre (where the clamp at 1
    cuts a piece, within the lookup's margin ε ~ 1e-7 of it).
    """
    m = lk.n_cells
    edges = []
    for j in range(m):
        a0, inv_h, _, last = lk.header[j]
        x = a0 + np.arange(int(last) + 2) / inv_h
        edges.append(np.clip(x, j / m, (j + 1) / m))
    e = np.unique(np.concatenate(edges + [np.linspace(0.0, 1.0, m + 1)]))
    lo, width = e[:-1], np.diff(e)
    mu = lo[:, None] + width[:, None] * _GL_T[None, :]
    e = np.minimum(lk(mu)[..., 0], 1.0)  # clamp: as the kernels read it
    return float(np.sum(2.0 * mu * e * _GL_W[None, :] * width[:, None]))


def _uniform_average(lk: UniformLookup) -> float:
    """2∫₀¹ min(Ẽ, 1) μ dμ of a :class:`~brdfkit.tables.UniformLookup`, as the kernels
    read it: the held value on [0, μ_min] (Ẽ_min μ_min², μ_min = x_min²), 6-point
    Gauss–Legendre in x = √μ on each interval from x_min (exact: Ẽ μ dμ/dx = cubic · 2x³,
    degree 6; where the clamp at 1 cuts one, within the margin ε of it)."""
    e = np.unique(np.clip(lk.w0 + lk.h * np.arange(lk.n + 1), lk.w_min, 1.0))
    lo, width = e[:-1], np.diff(e)
    x = lo[:, None] + width[:, None] * _GLW_T[None, :]
    ee = np.minimum(lk.at_w(x)[..., 0], 1.0)  # clamp: as the kernels read it
    held = min(float(lk.at_w(np.array([lk.w_min]))[0, 0]), 1.0) * lk.w_min ** 4
    return held + float(np.sum(4.0 * x ** 3 * ee * _GLW_W[None, :] * width[:, None]))


def _uniform_lookup(spline: AlbedoTable, grazing, c: int):
    """Channel *c* of E as a single-level :class:`~brdfkit.tables.UniformLookup`, or None.

    Only for a single-piece table that E never clamps (no kink on [THETA_HOLD, 0°]):
    a grid uniform in x = √μ anchored at THETA_TOP, where the spline meets the grazing
    piece, extended below it by whole intervals past THETA_HOLD (below which the read's
    clamp holds the value); as many intervals as the spline's to start, doubled (at most
    UNIFORM_MAX_HALVINGS times) until the lookup is within LUT_TOL of E.
    """
    if len(spline.piece_nn) != 1:
        return None
    x_top = math.sqrt(math.cos(THETA_TOP))
    x_hold = math.sqrt(math.cos(THETA_HOLD))

    def e_x(x):
        mu = np.square(np.asarray(x, dtype=np.float64))
        e = _as_2d(spline.at_cos(np.maximum(mu, mu_of_w(spline.s_top))))[:, c:c + 1].copy()
        below = x < x_top
        e[below] = _as_2d(grazing(w_of_mu(mu[below])))[:, c:c + 1]
        return np.maximum(e, E_FLOOR)  # clamp: see E_FLOOR

    for r in range(UNIFORM_MAX_HALVINGS + 1):
        n_top = spline.piece_nn[0] << r
        h = (1.0 - x_top) / n_top
        n_ext = math.ceil((x_top - x_hold) / h - 1e-9)
        lk = build_uniform_lookup(e_x, w0=x_top - n_ext * h, h=h, n=n_ext + n_top,
                                  w_min=x_hold, bound="upper")
        if lk.max_error <= LUT_TOL:
            return lk
    return None


def _two_level(spline: AlbedoTable, grazing, c: int, clamped: bool) -> Lookup:
    """Channel *c* of min(E, 1) as the two-level :class:`~brdfkit.tables.Lookup` (a table
    of several pieces, or one E crosses 1 on): its kinks are the pieces' boundaries
    (where the grazing piece meets the table, THETA_TOP), where the value is held
    (THETA_HOLD) and where E crosses 1 (the clamp)."""
    ks = np.concatenate([mu_of_w(spline.breaks[:-1]), [math.cos(THETA_HOLD)]])
    if clamped:
        grid = np.linspace(0.0, 1.0, 4097)
        ks = np.concatenate([ks, _crossings(lambda m: _spline_e(
            spline, grazing, m)[:, c:c + 1] - 1.0, grid, _spline_e(
            spline, grazing, grid)[:, c:c + 1] - 1.0)])

    def e_of(mu):
        e = _spline_e(spline, grazing, mu)[:, c:c + 1]
        return np.clip(e, E_FLOOR, 1.0)  # clamp: see E_FLOOR and the docstring (E > 1)
    return build_lookup(e_of, kinks=ks, tol=LUT_TOL, bound="upper")


def _spline_average(spline: AlbedoTable, grazing) -> np.ndarray:
    """2∫₀¹ min(E, 1) μ dμ of the table and its grazing piece: 64 Gauss–Legendre nodes on
    each piece in w (dμ = 4w(1 − w²) dw), the held value on [0, w(THETA_HOLD)]."""
    x, wt = np.polynomial.legendre.leggauss(64)
    total = 0.0
    edges = np.concatenate([[0.0, float(w_of_mu(math.cos(THETA_HOLD)))], spline.breaks])
    for lo, hi in zip(edges[:-1], edges[1:], strict=True):
        w = lo + (hi - lo) * 0.5 * (x + 1.0)
        mu = mu_of_w(w)
        e = np.minimum(_spline_e(spline, grazing, mu), 1.0)
        jac = 4.0 * w * (1.0 - w * w) * (hi - lo) * 0.5
        total = total + np.sum((2.0 * mu * jac * wt)[:, None] * e, axis=0)
    return total


def compensation_table(model: BRDF, *, who: str = "compensate") -> CompensationTable:
    """Tabulate E(μ) of *model* (an isotropic model: give the white form) for a kernel.

    Parameters
    ----------
    model : BRDF
        Isotropic (its albedo a function of θ only); any model the albedo engine
        integrates, registered, measured or derived.
    who : str, keyword-only
        The operator named in the errors.

    Raises
    ------
    ParameterError
        An anisotropic model.
    BrdfkitError
        The albedo is not finite, or the spline cannot meet :data:`TABLE_TOL`.
    """
    if not model.isotropic:
        raise ParameterError(
            f"{who}: {model.name} is anisotropic; E(mu) is tabulated as a function of the "
            "incidence angle only, which needs an isotropic base (docs/compensation.md, "
            "'Anisotropic bases')")
    t0 = time.perf_counter()
    spline = build_albedo_table(model, tol=TABLE_TOL, engine_tol=_engine_tol(model), margin=False,
                                who=who)
    grazing, grazing_err, _ = _grazing_piece(model, spline)
    max_albedo = np.maximum(spline.max_albedo, np.max(_as_2d(grazing(grazing.x)), axis=0))
    clamped = bool(np.any(max_albedo > 1.0))
    # one kind of lookup for every channel (the kernel reads one): single-level when each
    # channel's E allows it, else the two-level Lookup
    lookups = [None if clamped else _uniform_lookup(spline, grazing, c)
               for c in range(max_albedo.size)]
    if any(lk is None for lk in lookups):
        lookups = [_two_level(spline, grazing, c, clamped) for c in range(max_albedo.size)]
    e_avg = np.array([_uniform_average(lk) if isinstance(lk, UniformLookup)
                      else _lookup_average(lk) for lk in lookups])
    e_avg_error = np.abs(e_avg - _spline_average(spline, grazing))
    return CompensationTable(
        spline=spline, lookups=tuple(lookups), e_avg=e_avg, e_avg_error=e_avg_error,
        max_albedo=max_albedo, clamped=clamped,
        interp_error=np.maximum(spline.max_midpoint_error, grazing_err),
        lookup_error=float(max(lk.max_error + lk.epsilon for lk in lookups)),
        engine_tol=_engine_tol(model), seconds=time.perf_counter() - t0)
