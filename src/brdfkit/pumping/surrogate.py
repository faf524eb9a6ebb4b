"""
A fast stand-in for a pumped model whose parameters keep changing (fitting)
===========================================================================

``pump(root.with_params(**v))`` tabulates the root's albedo with the albedo
engine and builds the kernel's lookups: 0.1–0.8 s per parameter set, while a
fit evaluates hundreds of them. :func:`surrogate` returns a
:class:`PumpSurrogate`, an object with the two methods a fit calls,
``with_params(**v)`` and ``eval(wi, wo)``, whose instances evaluate a
**one-times** pumped model by its definition (Neumann et al. 1999, eq. 16
with eq. 20 or 21)::

    f*(L, V) = f(L, V) / g,   g = max(a(L), a(V))  [min 1 when a ≤ 1]  [max N·L, N·V for g₂]

with the root's compiled kernel for f and an albedo a assembled from
precomputed tables instead of a new table per parameter set:

1. **Linear parameters.** A root that is affine in colour parameters p_k
   jointly, f = f₀ + Σ_k p_k B_k (tested numerically on probe pairs, so no
   model is named), has the albedo a = a₀ + Σ_k p_k A_k, A_k the albedo of
   B_k, because the albedo is linear in f. The tables depend only on the
   other ("shape") parameters; p_k (per channel) are combined at evaluation,
   nothing to tabulate. For modified Phong a = ρ_d·1 + ρ_s·a_s(n, θ).
2. **Shape parameters** (at most :data:`MAX_SHAPE`, scalar): each basis albedo
   a₀, A_k is tabulated (:func:`~brdfkit.pumping.table.build_albedo_table`) at
   the nodes of a grid in u = ln x for exponent-like parameters (lower bound
   ≥ 0 and upper/lower ≥ 10³ or unbounded; spacing :data:`LOG_SPACING`) or
   u = x (finite range; :data:`LINEAR_DIVISIONS` intervals), and interpolated
   in u by 4-point Lagrange (tensor product in two dimensions). Nodes are
   built when first needed. Bases whose values on fixed probe pairs are the
   same at three shape values (modified Phong: ρ_d's Lambertian basis and the
   zero a₀) are tabulated once, at the node of the declared defaults.
3. **Cheaper tables.** Node tables are built to :data:`NODE_TOL` with the
   engine at :data:`NODE_ENGINE_TOL` (the exact model: 3e-6 and 1e-8) and
   read without their upper-bound margin (an estimate, not a bound: the
   surrogate only steers the optimiser). They are cached per process
   (:data:`NODE_CACHE_SIZE`), keyed on everything they depend on (root
   class, the parameters that do not vary, the node), so a batch of fits
   shares them.

Error: for modified Phong the surrogate's albedo is within
:data:`SURROGATE_ALBEDO_TOL` (absolute) of Lewis's H_s computed by its own
quadrature (``tests/test_pumping_surrogate.py``, n from 1.6 to 10⁵ between the
nodes; measured at most 8.7e-6, at n = 1.6); interpolation error alone (exact
node values, 60 random n in [0.5, 5e5]): 1.6e-6 at spacing 0.2, 8e-6 at 0.3.
A fit records the surrogate's loss at its result next to the exact one
(``FitResult.convergence["surrogate"]``); the result's model and metrics are
the exact pumped model's.

The values are a pure function of the parameters (the caches only save
work), so a fit through the surrogate gives the same result whatever was
fitted before it in the process.

Not covered (``surrogate`` returns None; the caller evaluates the exact
model): more than one pumping (the second table is the albedo of f/g, not
affine in anything), a custom g, more than two or per-channel shape
parameters.
"""

from __future__ import annotations

import math
import time

import numpy as np

from brdfkit._cache import bounded_cache
from brdfkit.errors import BrdfkitError
from brdfkit.pumping.operator import G_FLOOR, PumpedBRDF
from brdfkit.pumping.table import ENGINE_ERR, THETA_TOP, build_albedo_table
from brdfkit.tables import _as_2d, mu_of_w, w_of_mu

__all__ = ["LINEAR_DIVISIONS", "LOG_SPACING", "MAX_SHAPE", "NODE_CACHE_SIZE",
           "NODE_ENGINE_TOL", "NODE_TOL", "SURROGATE_ALBEDO_TOL", "PumpSurrogate",
           "surrogate"]

#: Grid spacing in ln x of exponent-like shape parameters (a factor e^0.3 = 1.35).
LOG_SPACING = 0.3
#: Grid intervals over the declared range of other (finite) shape parameters.
LINEAR_DIVISIONS = 32
#: Most shape parameters (a cell needs 4^d node tables).
MAX_SHAPE = 2
#: Interpolation tolerance of the node tables (the exact model's: INTERP_TOL = 3e-6).
NODE_TOL = 1e-5
#: Accuracy asked of the albedo engine for node tables (the exact model's: 1e-8); 4-5x
#: cheaper (measured on the modified-Phong specular basis, n = 2 … 2e5).
NODE_ENGINE_TOL = 1e-6
#: Stated bound of |a_surrogate − a| for modified Phong (tested; see the module docstring).
SURROGATE_ALBEDO_TOL = 5e-5
#: Node tables kept per process (each a few kB).
NODE_CACHE_SIZE = 1024
#: ln x of a lower bound 0 (an exponent of 1e-6 is 0 for every purpose).
LOG_FLOOR = 1e-6
#: Relative tolerance of the affinity test on the probe pairs.
AFFINE_RTOL = 1e-9
#: Incidence cosines at which the cap g ≤ 1 is decided (129 nodes uniform in the tables'
#: grid variable over [0, THETA_TOP]).
_MU_CHECK = mu_of_w(np.linspace(float(w_of_mu(math.cos(THETA_TOP))), 1.0, 129))

_NODE_CACHE = bounded_cache("brdfkit.pumping.surrogate._NODE_CACHE", maxsize=NODE_CACHE_SIZE)


def _freeze(v):
    return tuple(np.asarray(v, dtype=np.float64).ravel().tolist()) \
        if isinstance(v, np.ndarray | list) else v


def _probe_pairs() -> tuple[np.ndarray, np.ndarray]:
    """64 fixed pairs: 32 uniform on the hemisphere, 32 near the mirror direction (so a
    sharp lobe is seen), from a fixed seed."""
    rng = np.random.default_rng(20260101)
    def hemi(k):
        z = rng.uniform(0.05, 1.0, k)
        phi = rng.uniform(0.0, 2.0 * math.pi, k)
        r = np.sqrt(1.0 - z * z)
        return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)
    wi = hemi(64)
    wo = hemi(64)
    wo[32:] = wi[32:] * np.array([-1.0, -1.0, 1.0])  # the mirror direction
    return wi, wo


class _Grid:
    """The node grid of one shape parameter (see the module docstring)."""

    def __init__(self, name: str, lower: float, upper: float, log: bool):
        self.name, self.lower, self.upper, self.log = name, lower, upper, log
        if log:
            self.u_lo = math.log(max(lower, LOG_FLOOR))
            self.h = LOG_SPACING
            u_hi = math.log(upper) if math.isfinite(upper) else math.inf
        else:
            self.u_lo = lower
            self.h = (upper - lower) / LINEAR_DIVISIONS
            u_hi = upper
        # the last node index inside the range (None: unbounded)
        self.last = None if math.isinf(u_hi) else int(math.floor((u_hi - self.u_lo) / self.h
                                                                  + 1e-9))

    def stencil(self, x: float) -> tuple[int, np.ndarray]:
        """(first node index j0, Lagrange weights of nodes j0 … j0+3) at *x*."""
        u = math.log(max(x, LOG_FLOOR)) if self.log else x
        s = (u - self.u_lo) / self.h
        j0 = max(int(math.floor(s)) - 1, 0)
        if self.last is not None:
            j0 = min(j0, self.last - 3)  # a stencil shifted inside the range at its ends
        t = s - j0  # in [0, 3] inside the range
        w = np.array([-(t - 1.0) * (t - 2.0) * (t - 3.0) / 6.0,
                      t * (t - 2.0) * (t - 3.0) / 2.0,
                      -t * (t - 1.0) * (t - 3.0) / 2.0,
                      t * (t - 1.0) * (t - 2.0) / 6.0])
        return j0, w

    def x(self, j: int) -> float:
        u = self.u_lo + j * self.h
        x = math.exp(u) if self.log else u
        return min(max(x, self.lower), self.upper)  # rounding at the range's ends


class PumpSurrogate:
    """Fast stand-in for a one-times pumped model during a fit (module docstring).

    Built by :func:`surrogate`. ``with_params(**values)`` returns an object with
    ``eval(wi, wo)`` (and ``n_channels``); it raises the root's
    :class:`~brdfkit.errors.BrdfkitError` for refused values. Values of
    parameters outside ``linear`` and ``shape`` that differ from the model's
    are served by the exact model.

    Attributes
    ----------
    model : PumpedBRDF
        The exact model.
    linear, shape : tuple of str
        The parameters combined at evaluation and those interpolated over.
    n_tables, table_time_s : int, float
        Node tables built by this surrogate (cache misses) and the time spent.
    """

    def __init__(self, model: PumpedBRDF, linear: tuple, shape: tuple, grids: tuple):
        self.model = model
        self.root = model.root
        self.controlled = model.g == "controlled"
        self.linear = linear
        self.shape = shape
        self._grids = grids
        decl = {p.name: p for p in self.root.params}
        self._unit = {n: min(1.0, decl[n].upper) for n in linear}
        self._const = {k: v for k, v in self.root.values.items()
                       if k not in linear and k not in shape}
        self._const_key = tuple(sorted((k, _freeze(v)) for k, v in self._const.items()))
        # (cell, cosines) → the bases' albedos there: 256 keys bound the memory (a new set
        # of pairs per key)
        self._mu_cache = bounded_cache(None, maxsize=256)
        self._default_node = tuple(g.stencil(float(decl[g.name].default))[0] + 1
                                   for g in grids)
        self._static = _static_bases(self)
        self.n_tables = 0
        self.table_time_s = 0.0

    # ---------------------------------------------------------------- node tables
    def _basis_model(self, b: int, shape_vals: dict):
        """The root with linear parameter b − 1 at its unit and the others 0 (b = 0: all 0)."""
        lin = {n: (self._unit[n] if k == b - 1 else 0.0) for k, n in enumerate(self.linear)}
        return self.root.with_params(**self._const, **shape_vals, **lin)

    def _tables(self, node) -> list:
        """The tables of the shape-dependent bases at grid node *node* (a tuple of
        indices), or of the static bases (``node = "static"``, built at the node of the
        declared defaults); cached per process."""
        key = (type(self.root), self._const_key, self.shape, self.linear, self._static, node)
        got = _NODE_CACHE.get(key)
        if got is not None:
            return got
        t0 = time.perf_counter()
        at = self._default_node if node == "static" else node
        shape_vals = {g.name: g.x(j) for g, j in zip(self._grids, at, strict=True)}
        tables = [build_albedo_table(self._basis_model(b, shape_vals), tol=NODE_TOL,
                                     engine_tol=NODE_ENGINE_TOL)
                  for b in range(len(self._static)) if self._static[b] == (node == "static")]
        _NODE_CACHE[key] = tables
        self.n_tables += len(tables)
        self.table_time_s += time.perf_counter() - t0
        return tables

    @staticmethod
    def _read(tables, mu) -> np.ndarray:
        """(len(tables), M, Cb): the tables without their margin (an estimate of the
        albedo, not a bound)."""
        return np.stack([_as_2d(T.at_cos(mu)) - T.delta[None, :] for T in tables]) \
            if tables else np.empty((0, mu.size, 1))

    def _cell(self, values: dict) -> tuple[tuple, np.ndarray]:
        """(the first node of each dimension's stencil, the tensor-product weights (4^d,))."""
        j0s, w = [], np.ones(1)
        for g in self._grids:
            j0, wg = g.stencil(float(values[g.name]))
            j0s.append(j0)
            w = np.outer(w, wg).ravel()
        return tuple(j0s), w

    def _nodes(self, cell: tuple) -> list:
        out = [()]
        for j0 in cell:
            out = [node + (j0 + k,) for node in out for k in range(4)]
        return out

    def albedo(self, values: dict, mu, mu_key=None) -> np.ndarray:
        """The surrogate's albedo at cosines *mu* for parameter *values*: (M, C)."""
        mu = np.ascontiguousarray(np.clip(np.asarray(mu, dtype=np.float64).ravel(), 0.0, 1.0))
        if mu_key is None:
            mu_key = (mu.size, hash(mu.tobytes()))
        cell, w = self._cell(values)
        key = (cell, mu_key)
        stack = self._mu_cache.get(key)
        if stack is None:
            stack = np.stack([self._read(self._tables(node), mu) for node in self._nodes(cell)])
            self._mu_cache[key] = stack  # (4^d, dynamic bases, M, Cb)
        static = self._mu_cache.get(("static", mu_key))
        if static is None:
            static = self._mu_cache[("static", mu_key)] = self._read(self._tables("static"), mu)
        dyn = np.tensordot(w, stack, axes=1)  # the Lagrange interpolation
        R = [None] * len(self._static)
        i_dyn = i_st = 0
        for b, st in enumerate(self._static):
            if st:
                R[b], i_st = static[i_st], i_st + 1
            else:
                R[b], i_dyn = dyn[i_dyn], i_dyn + 1
        a = R[0]
        for k, n in enumerate(self.linear):  # a = a0 + sum_k p_k (R_k - R_0)/unit_k
            p = np.atleast_1d(np.asarray(values[n], dtype=np.float64))
            a = a + (R[k + 1] - R[0]) * (p / self._unit[n])[None, :]
        return a

    # ---------------------------------------------------------------- the fit's API
    def with_params(self, **values):
        """A surrogate instance (``eval``) at *values*; the exact pumped model when a
        parameter outside ``linear`` and ``shape`` differs from the model's."""
        merged = {**self.root.values, **values}
        for k, v in self._const.items():
            if _freeze(merged[k]) != _freeze(v):
                return self.model.with_params(**values)
        root = self.root.with_params(**values)  # validates (raises BrdfkitError)
        full = root.values
        for node in ["static"] + self._nodes(self._cell(full)[0]):
            self._tables(node)  # built here, so that a failure is a refusal
        capped = bool(np.all(self.albedo(full, _MU_CHECK, "check") <= 1.0 + ENGINE_ERR))
        return _Instance(self, root, full, capped)


class _Instance:
    """One parameter set of a :class:`PumpSurrogate` (``eval`` only)."""

    def __init__(self, owner: PumpSurrogate, root, values: dict, capped: bool):
        self._owner, self._root, self._values, self.capped = owner, root, values, capped
        self.n_channels = root.n_channels

    def eval(self, wi, wo) -> np.ndarray:
        """f*(wi, wo) (1/sr) as :meth:`PumpedBRDF.eval`, from the surrogate's albedo."""
        f = np.asarray(self._root.eval(wi, wo), dtype=np.float64)
        wi = np.asarray(wi, dtype=np.float64)
        wo = np.asarray(wo, dtype=np.float64)
        shape = np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1])
        mu_i = np.broadcast_to(wi[..., 2], shape).ravel()
        mu_o = np.broadcast_to(wo[..., 2], shape).ravel()
        mu = np.concatenate([mu_i, mu_o])
        a = self._owner.albedo(self._values, mu)  # (2M, C)
        M = mu_i.size
        g = np.maximum(a[:M], a[M:])
        if self.capped:
            g = np.minimum(g, 1.0)  # eq. (17) g <= 1 (as the exact model: a base with a <= 1)
        if self._owner.controlled:
            g = np.maximum(g, np.clip(np.maximum(mu_i, mu_o), 0.0, 1.0)[:, None])  # eq. (21)
        g = np.maximum(g, G_FLOOR)  # see G_FLOOR
        f2 = f.reshape(M, -1)
        out = np.where(f2 > 0.0, f2 / np.where(f2 > 0.0, g, 1.0), 0.0)
        return out.reshape(f.shape)


# --------------------------------------------------------------------------- factory
def surrogate(model, vary) -> PumpSurrogate | None:
    """A :class:`PumpSurrogate` of *model* for changes of the parameters *vary*, or None.

    Parameters
    ----------
    model : BRDF
        The model a fit will evaluate at many parameter sets.
    vary : iterable of str
        The parameters that will change (a fit's free parameters).

    Returns
    -------
    PumpSurrogate or None
        None when the surrogate does not apply: *model* is not a one-times pumped
        model with g ``"max"`` or ``"controlled"``, its root has no compiled kernel,
        or the parameters that are not linear are more than :data:`MAX_SHAPE`,
        per-channel, or lack a grid (an unbounded linear range); and when the root
        refuses its linear parameters at 0 (the bases).
    """
    if not isinstance(model, PumpedBRDF) or model.depth != 1 or model.g not in (
            "max", "controlled") or model.root.kernel is None:
        return None
    root = model.root
    decl = {p.name: p for p in root.params}
    vary = tuple(n for n in decl if n in set(vary))  # declared order
    cand = tuple(n for n in vary if decl[n].kind == "colour")
    try:
        linear = cand if cand and _affine(root, cand) else ()
    except BrdfkitError:
        linear = ()
    shape = tuple(n for n in vary if n not in linear)
    if len(shape) > MAX_SHAPE:
        return None
    grids = []
    for n in shape:
        p = decl[n]
        lo, hi = float(p.lower), float(p.upper)
        if p.kind != "scalar":
            return None
        if lo >= 0.0 and (math.isinf(hi) or (hi > 1.0 and hi / max(lo, LOG_FLOOR) >= 1e3)):
            grids.append(_Grid(n, lo, hi, True))
        elif math.isfinite(lo) and math.isfinite(hi) and hi > lo:
            grids.append(_Grid(n, lo, hi, False))
        else:
            return None
        if grids[-1].last is not None and grids[-1].last < 3:
            return None  # a range narrower than one stencil
    try:
        return PumpSurrogate(model, linear, shape, tuple(grids))
    except BrdfkitError:  # the root refuses a basis (its linear parameters at 0 or 1)
        return None


def _static_bases(sur: PumpSurrogate) -> tuple:
    """Per basis (a₀, then one per linear parameter): whether its values on the probe
    pairs are the same at three shape values (the node of the declared defaults and two
    nodes 1 and 5 grid steps away): tabulated once, not per node (e.g. the Lambertian basis
    of ρ_d and the zero a₀ of modified Phong), as :meth:`brdfkit.fitting._problem.Problem.
    find_static` does for the fit's bases."""
    if not sur._grids:
        return tuple(True for _ in range(len(sur.linear) + 1))
    wi, wo = _probe_pairs()
    nodes = [sur._default_node]
    for step in (1, 5):
        nodes.append(tuple(min(j + step, g.last) if g.last is not None else j + step
                           for g, j in zip(sur._grids, sur._default_node, strict=True)))
    out = []
    for b in range(len(sur.linear) + 1):
        vals = [np.asarray(sur._basis_model(b, {g.name: g.x(j) for g, j in zip(
            sur._grids, node, strict=True)}).eval(wi, wo)) for node in nodes]
        out.append(all(np.array_equal(vals[0], v) for v in vals[1:]))
    return tuple(out)


def _affine(root, linear) -> bool:
    """Whether *root* is affine in the *linear* parameters jointly on the probe pairs."""
    wi, wo = _probe_pairs()
    decl = {p.name: p for p in root.params}
    unit = {n: min(1.0, decl[n].upper) for n in linear}
    zero = {n: 0.0 for n in linear}

    def f(**lin):
        return _as_2d(np.asarray(root.with_params(**lin).eval(wi, wo), dtype=np.float64))

    f0 = f(**zero)
    B = [(f(**{**zero, n: unit[n]}) - f0) / unit[n] for n in linear]
    rng = np.random.default_rng(7)
    p = {n: float(unit[n] * (0.2 + 0.6 * rng.random())) for n in linear}  # inside the bounds
    expect = f0 + sum(B[k] * p[n] for k, n in enumerate(linear))
    got = f(**p)
    scale = max(float(np.max(np.abs(expect))), 1e-300)
    return bool(np.all(np.isfinite(got))) and float(np.max(np.abs(got - expect))) \
        <= AFFINE_RTOL * scale
