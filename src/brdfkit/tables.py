"""
Tables of functions of the incidence angle, shared by the models and the engines
================================================================================

Two things every tabulated function of θ (an albedo, Lewis's H_s, a pumped
model's divisor) needs, defined once:

1. **The grid variable** w = √(1 − √(1 − cos θ)) (:func:`w_of_mu`,
   :func:`mu_of_w`, :func:`theta_of_w`). Near the normal w ≈ 1 − θ/(2√2), linear
   in θ, so a function that is even in θ (an isotropic model's albedo; H_s, which
   has terms in θ^{n+2}, not smooth in cos θ for small n) is smooth in w there;
   near grazing w ≈ √(cos θ/2), so nodes uniform in w crowd where the horizon cuts
   a sharp lobe (cos θ = 2w² − w⁴). Tables uniform in w are the pumping's albedo
   tables (:class:`brdfkit.pumping.AlbedoTable`) and the nodes of the H_s table
   of ``phong-energy-conserving``. All three maps are written without
   cancellation (see each).
2. **The compiled lookup** (:class:`Lookup`, :func:`build_lookup`, the inlined
   :func:`_lookup`): a positive function of μ = cos θ stored for reading inside
   a model kernel, on every evaluated pair — no square root and no search, local
   cubics on a two-level grid whose nodes include the function's kinks, with a
   verified margin so that it bounds the function from a chosen side.

3. **The reads as formula primitives** (:func:`lookup`, :func:`lookup_w`,
   :func:`row_at`, registered with :func:`brdfkit._dual.primitive`): a formula
   (:mod:`brdfkit._dual`) that reads a table packed into its row calls them; Numba
   inlines :func:`_lookup` / :func:`_lookup_w`, Dr.Jit (the Mitsuba bridge's traced
   route) runs the same cubic read with ``dr.gather`` from the table rows held once
   as a Dr.Jit array (:class:`~brdfkit.traced_tables.TracedTables`, carried by the
   row a traced formula receives, :class:`~brdfkit.traced_tables.TableRow`;
   :mod:`brdfkit.traced_tables`).

This is a low layer: it imports NumPy, Numba, :mod:`brdfkit.errors`,
:mod:`brdfkit._kern`, :mod:`brdfkit._dual` and :mod:`brdfkit.traced_tables` only
(models and engines import it, never the reverse).

Public objects
--------------
- :func:`w_of_mu`, :func:`mu_of_w`, :func:`theta_of_w` — the grid variable.
- :class:`Lookup`, :func:`build_lookup` — the kernels' table of a function of cos θ.
- :func:`_lookup` — its compiled read (``@njit(inline="always")``, for kernels).
- :class:`UniformLookup`, :func:`build_uniform_lookup`, :func:`_lookup_w` — a
  single-level table uniform in √μ (4 reads, one square root, for a function smooth
  in √μ: a compensation's E(μ)).
- :func:`lookup`, :func:`lookup_w` — the two reads as formula primitives (the offset
  may be a float read from the row); :func:`row_at` — the row at a computed column (a
  bin of a measured table); :func:`row_from` — a row's tail, for a formula that wraps
  another's.
- :data:`LUT_TOL`, :data:`LUT_CELLS` — the lookup's default tolerance and cells.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numba
import numpy as np

from brdfkit._dual import primitive
from brdfkit._kern import clamp_unit, load_input
from brdfkit.errors import BrdfkitError, ParameterError
from brdfkit.traced_tables import lookup_drjit, lookup_w_drjit, row_at_drjit, row_from_drjit

__all__ = [
    "LUT_CELLS",
    "LUT_TOL",
    "Lookup",
    "UniformLookup",
    "build_lookup",
    "build_uniform_lookup",
    "lookup",
    "lookup_w",
    "row_at",
    "row_from",
    "mu_of_w",
    "theta_of_w",
    "w_of_mu",
]

#: Evaluation lookup (:class:`Lookup`): first-level cells, uniform in μ = cos θ.
LUT_CELLS = 64
#: Default relative tolerance of a lookup against the function it is built from (the
#: pumping's tables: its margin at most doubles it, well inside their 1e-5 budget).
LUT_TOL = 5e-7
#: Most intervals per cell; reached only by a cell with three kinks (the caps of
#: several pumping stages crossing 1 within 1e-4 of normal incidence), refined instead.
LUT_MAX_SUB = 4096
#: Check points per interval (the interpolant is compared with the function there).
LUT_CHECK = 8
#: Kinks closer than this are the same kink (found twice, e.g. by two stages).
LUT_KINK_MERGE = 1e-9


# --------------------------------------------------------------------------- grid variable
def w_of_mu(mu) -> np.ndarray:
    """Grid variable w = √(1 − √(1 − μ)) of μ = cos θ (μ clamped to [0, 1]).

    Written √(μ/(1 + √(1 − μ))) (1 − √(1 − μ) = μ/(1 + √(1 − μ))): the
    difference of the printed form loses all but a few digits at grazing, where
    μ → 0 and the tables are densest.
    """
    mu = np.clip(np.asarray(mu, dtype=np.float64), 0.0, 1.0)  # clamp: a cosine of unit vectors
    return np.sqrt(mu / (1.0 + np.sqrt(1.0 - mu)))


def mu_of_w(w) -> np.ndarray:
    """μ = cos θ of the grid variable *w* ∈ [0, 1]: 1 − (1 − w²)², written w²(2 − w²)
    (the difference of the first form cancels at grazing, w → 0)."""
    w2 = np.square(np.asarray(w, dtype=np.float64))
    return w2 * (2.0 - w2)


def theta_of_w(w) -> np.ndarray:
    """θ (radians) of the grid variable *w* ∈ [0, 1].

    1 − cos θ = 2 sin²(θ/2) = u², u = 1 − w² = (1 − w)(1 + w), so
    tan(θ/2) = u/√(2 − u²) and θ = 2 atan2(u, √(2 − u²)): no arccos of a cosine
    near 1 (which loses half the digits of a small θ), no 1 − w² (1 − w is
    exact near the normal, w → 1), 2 − u² ≥ 1, and θ = π/2 exactly at w = 0
    (atan2(1, 1) = π/4; an arcsin of the rounded 1/√2 falls 3e-16 short).
    """
    w = np.asarray(w, dtype=np.float64)
    u = (1.0 - w) * (1.0 + w)
    return 2.0 * np.arctan2(u, np.sqrt(2.0 - u * u))


def _as_2d(a: np.ndarray) -> np.ndarray:
    return a[:, None] if a.ndim == 1 else a


# --------------------------------------------------------------------------- compiled lookup
@numba.njit(cache=True, inline="always")
def _lookup(p, off, mu):  # pragma: no cover - compiled
    """Value at μ = *mu* of the piecewise-cubic :class:`Lookup` stored at ``p[off:]``.

    Two levels, no square root, no search: the cell is ``int(μ·M)``; inside it a
    uniform grid anchored at the cell's kink (see :class:`Lookup`). Branch-free (the
    clamps compile to selects) and every read a :func:`brdfkit._kern.load_input`, so
    that in the vectorising loop it compiles to gathers (a compensated model's kernel).
    """
    # clamp to [0, 1] (NaN to 0), no branch: only reached with 0 < mu <= 1 from the kernels up
    # to rounding (|ω| = 1), it keeps every index in range for any input
    mu = clamp_unit(mu)
    m = numba.int64(load_input(p, off))  # casts: int() is a call to an overload,
    # which the loop vectoriser meets before it is inlined
    j = numba.int64(mu * m)
    if j > m - 1:
        j = m - 1  # mu = 1: the last cell
    h = off + 1 + 4 * j
    y = (mu - load_input(p, h)) * load_input(p, h + 1)  # from the cell's anchor (>= 0)
    k = numba.int64(y)
    last = numba.int64(load_input(p, h + 3))
    if k > last:
        k = last  # the cell's last node (mu at the cell's upper edge)
    t = y - k
    b = off + numba.int64(load_input(p, h + 2)) + 4 * k
    return (((load_input(p, b) * t + load_input(p, b + 1)) * t + load_input(p, b + 2)) * t
            + load_input(p, b + 3))


@dataclass(frozen=True)
class Lookup:
    """A positive function of μ = cos θ ∈ [0, 1] stored for a fast kernel lookup.

    Kernels read it on every pair (a pumped model: its albedo tables or the product of
    a whole chain of stages, see :class:`brdfkit.pumping.PumpedBRDF`), so the lookup
    must cost less than the model itself: a square root (as in the grid variable
    :func:`w_of_mu`) or a search already costs a noticeable fraction of a Phong
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


# ------------------------------------------------------------- single-level lookup in √μ
@numba.njit(cache=True, inline="always")
def _lookup_w(p, off, mu):  # pragma: no cover - compiled
    """Value at μ = *mu* of the :class:`UniformLookup` stored at ``p[off:]``.

    One level: x = √μ (one square root), held at x_min below it (a select), the
    interval ``int((x − x₀)/h)`` clamped to
    [0, n − 1] by selects, then 4 reads and Horner. Branch-free and every read a
    :func:`brdfkit._kern.load_input`, as :func:`_lookup`, so it vectorises to gathers.
    """
    mu = clamp_unit(mu)  # [0, 1], NaN to 0: every index in range for any input
    w = math.sqrt(mu)
    w_min = load_input(p, off + 3)
    w = w if w > w_min else w_min  # held below x_min (the table's last angle)
    x = (w - load_input(p, off)) * load_input(p, off + 1)
    n = numba.int64(load_input(p, off + 2))  # casts: int() is a call (see _lookup)
    j = numba.int64(x)
    j = j if j < n - 1 else n - 1  # w = 1: the last interval
    j = j if j > 0 else 0  # rounding below w0
    t = x - j
    b = off + 4 + 4 * j
    return (((load_input(p, b) * t + load_input(p, b + 1)) * t + load_input(p, b + 2)) * t
            + load_input(p, b + 3))


@dataclass(frozen=True)
class UniformLookup:
    """A positive function of μ stored on one grid uniform in x = √μ.

    x behaves at grazing like the shared grid variable w = √(1 − √(1 − μ)) (x ≈ √2 w:
    a function like √μ there, a compensation's E, is smooth in it), and near the normal
    like μ (where an isotropic model's albedo is smooth in μ), for one square root (w
    costs two; measured: the square roots were ~0.25× of a GGX evaluation in
    Kulla–Conty's two reads). The class and its fields keep the name w for x.
    Intervals [w₀ + j h, w₀ + (j + 1) h], j < n, each with its cubic in t ∈ [0, 1]
    (the cubic through the function at t = 0, ⅓, ⅔, 1), the function held at its value
    at w_min below w_min. Read by :func:`_lookup_w` with 4 reads (the two-level
    :class:`Lookup` needs 8, 4 of them dependent on the other 4), for a function smooth
    in w on [w_min, 1] (a kink would need refinement of the whole grid). Scaled by
    (1 ± ε) like :class:`Lookup`, so it bounds the function from the side *bound*.

    Attributes: ``w0``, ``h``, ``n``, ``w_min``, ``data`` (C, n, 4), ``max_error``
    (largest relative error before the margin at ``LUT_CHECK`` points per interval),
    ``epsilon``, ``bound``.
    """

    w0: float
    h: float
    n: int
    w_min: float
    data: np.ndarray
    max_error: float
    epsilon: float
    bound: str

    @property
    def n_intervals(self) -> int:
        """Total number of intervals."""
        return self.n

    def packed(self, c: int) -> np.ndarray:
        """Channel *c* flattened for :func:`_lookup_w`."""
        return np.concatenate([[self.w0, 1.0 / self.h, float(self.n), self.w_min],
                               self.data[c].reshape(-1)])

    def at_w(self, w) -> np.ndarray:
        """The stored cubics at x = √μ = *w* (held below w_min): ``w.shape + (C,)``."""
        x = (np.maximum(np.asarray(w, dtype=np.float64), self.w_min) - self.w0) / self.h
        j = np.clip(x.astype(np.int64), 0, self.n - 1)
        d = self.data[:, j, :]  # (C, ..., 4)
        t = x - j
        out = ((d[..., 0] * t + d[..., 1]) * t + d[..., 2]) * t + d[..., 3]
        return np.moveaxis(out, 0, -1)

    def __call__(self, mu) -> np.ndarray:
        """Vectorised :func:`_lookup_w`: shape ``mu.shape + (C,)``."""
        mu = np.clip(np.nan_to_num(np.asarray(mu, dtype=np.float64), nan=0.0), 0.0, 1.0)
        return self.at_w(np.sqrt(mu))  # as _lookup_w computes it


def build_uniform_lookup(fn_w: Callable, *, w0: float, h: float, n: int, w_min: float,
                         bound: str = "upper") -> UniformLookup:
    """Tabulate *fn_w* (x = √μ of shape (T,) → positive (T, C)) as a :class:`UniformLookup`
    on the *n* intervals from *w0* with spacing *h* (w0 ≤ w_min, w0 + n h ≥ 1); the
    caller checks ``max_error`` against its tolerance. The bound is verified at every
    check point after the margin, as :func:`build_lookup`'s.
    """
    if bound not in ("upper", "lower"):
        raise ParameterError(
            f"build_uniform_lookup: bound must be 'upper' or 'lower'; got {bound!r}")
    x = w0 + h * np.arange(n)
    v = _as_2d(np.asarray(fn_w(np.append(x[:, None] + h * np.arange(3)[None, :] / 3.0,
                                         [w0 + n * h])), dtype=np.float64))
    # check points inside [w_min, 1] only (the first interval starts below w_min)
    t_chk = (np.arange(LUT_CHECK) + 0.5) / LUT_CHECK
    xc = np.clip(x[:, None] + h * t_chk[None, :], w_min, 1.0)
    tc = (xc - x[:, None]) / h
    c = _as_2d(np.asarray(fn_w(xc.reshape(-1)), dtype=np.float64)).reshape(n, LUT_CHECK, -1)
    if not (np.all(np.isfinite(v)) and np.all(v > 0.0) and np.all(np.isfinite(c))
            and np.all(c > 0.0)):
        raise BrdfkitError("build_uniform_lookup: the function must be finite and positive")
    cub = _cubics(v)
    worst = float(np.max(np.abs(_horner(cub, tc) - c) / c))
    sign = 1.0 if bound == "upper" else -1.0
    eps = 4.0 * np.finfo(float).eps
    for _ in range(8):  # margin: twice the largest deficit, then verified
        deficit = float(np.max(sign * (c - _horner(cub * (1.0 + sign * eps), tc)) / c))
        if deficit <= 0.0:
            break
        eps += 2.0 * deficit
    else:  # pragma: no cover - the deficit shrinks geometrically
        raise BrdfkitError("build_uniform_lookup: could not make the lookup a bound")
    data = np.ascontiguousarray(np.transpose(cub * (1.0 + sign * eps), (1, 0, 2)))
    return UniformLookup(w0=float(w0), h=float(h), n=int(n), w_min=float(w_min), data=data,
                         max_error=worst, epsilon=eps, bound=bound)


# --------------------------------------------------------- the reads as formula primitives
@numba.njit(cache=True, inline="always")
def lookup(p, off, mu):  # pragma: no cover - compiled
    """:func:`_lookup` for formulas (:mod:`brdfkit._dual`): *off* may be a float read from
    the row (a stage's offset in a pumped model's trailer). Dr.Jit: :func:`_lookup_drjit`."""
    return _lookup(p, numba.int64(off), mu)


@numba.njit(cache=True, inline="always")
def lookup_w(p, off, mu):  # pragma: no cover - compiled
    """:func:`_lookup_w` for formulas, as :func:`lookup`. Dr.Jit: :func:`_lookup_w_drjit`."""
    return _lookup_w(p, numba.int64(off), mu)


@numba.njit(cache=True, inline="always")
def row_from(p, n):  # pragma: no cover - compiled
    """The row *p* from column *n* on (a view): a formula that passes a model's row on to
    another model's formula after its own columns (:mod:`brdfkit.render.metals`'s Fresnel
    weighting). Dr.Jit: the tuple's tail, a :class:`TableRow` keeping its tables."""
    return p[n:]


@numba.njit(cache=True, inline="always")
def row_at(p, i):  # pragma: no cover - compiled
    """``p[i]`` for a float *i* holding an exact integer index (a formula's computed bin:
    a measured material's table, NPF's factors). Dr.Jit: the traced row's tables gathered
    at *i*, 0 outside them (:meth:`~brdfkit.traced_tables.TracedTables.gather`)."""
    return p[int(i)]


primitive(lookup, lookup_drjit)
primitive(lookup_w, lookup_w_drjit)
primitive(row_at, row_at_drjit)
primitive(row_from, row_from_drjit)
