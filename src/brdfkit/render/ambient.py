"""
The response to uniform ambient light, ρ(V), tabulated exactly enough
=====================================================================

Under a uniform radiance L_a over the hemisphere of N a surface reflects
toward V the radiance L_a·ρ(V) with (Lewis 1993 eq. 7, first term)

    ρ(V) = ∫_Ω f_r(L′, V) cos θ_L′ dω_L′,

an integral over the model's *first* argument (the light). brdfkit's albedo
engine (:func:`brdfkit.analysis.albedo`) integrates over the *second*
argument, a(θ_i) = ∫ f_r(ω_i, ω_o) cos θ_o dω_o. For a reciprocal model the
two are the same function of the angle (f(L′, V) = f(V, L′), Neumann et al.
1999 eq. 4): ρ(V) = a(θ_V). For a non-reciprocal model (Lewis's Phong and
Blinn shaders, eq. 8; the energy-conserving Phong shader, eq. 22) they
differ — a(θ) of Lewis's Phong diverges at grazing incidence (eq. 19) while
ρ(V) = k_d π + k_s ∫ F_s(L′, V) dω_L′ stays bounded (eq. 9) — so the engine
is given the *transposed* model f^T(ω_i, ω_o) = f(ω_o, ω_i)
(:func:`transposed`), whose albedo is ρ.

ρ depends only on θ_V (isotropic models: the angle between V and N). It is
tabulated on an adaptive grid of θ_V and interpolated with a cubic spline
(:func:`ambient_table`): the grid starts uniform and every interval whose
midpoint value differs from the spline by more than the tolerance is halved,
until none does. The error estimate stated is that largest midpoint
difference of the last pass plus the engine's own error estimate.

Public objects
--------------
- :func:`transposed` — f^T(ω_i, ω_o) = f(ω_o, ω_i) as a model.
- :class:`AmbientTable` — ρ(θ_V) on a grid, its spline, error and status.
- :func:`ambient_table` — build (or reuse from the per-model cache) a table.

References
----------
- [Lewis1993] eqs. (7), (9), (19), (22).
- [Neumann1999] eq. (4) (albedo of a symmetric BRDF).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from brdfkit._cache import bounded_cache
from brdfkit.analysis import albedo, stored
from brdfkit.errors import BrdfkitError, ParameterError
from brdfkit.models import BRDF, DerivedBRDF
from brdfkit.status import STATUS

__all__ = ["AmbientTable", "ambient_table", "transposed", "RHO_TOL", "MAX_TABLE_NODES"]

#: Default absolute accuracy goal of ρ(θ_V) (interpolation; the engine runs at a tenth of it).
#: 8-bit sRGB output resolves ~4e-3 of the peak; 1e-6 leaves the float EXR/NPY output
#: three orders below what any display shows while costing ~100 engine angles.
RHO_TOL = 1e-6
#: Most grid nodes of one table: a lobe so sharp that halving never meets the goal stops
#: here and says so (status), instead of running on.
MAX_TABLE_NODES = 4097
#: Nodes of the first, uniform grid (16 intervals of at most 5.6°).
_START_NODES = 17

#: kernel → its transposed compiled kernel: one per non-reciprocal model family rendered
#: (a few; each a small compiled function)
_SWAPPED = bounded_cache("brdfkit.render.ambient._SWAPPED", maxsize=64)


def _swapped_kernel(kernel):
    """The compiled kernel with its two directions exchanged (cached per kernel)."""
    if kernel not in _SWAPPED:
        @numba.njit
        def swapped(ix, iy, iz, ox, oy, oz, p):  # pragma: no cover - compiled
            return kernel(ox, oy, oz, ix, iy, iz, p)

        _SWAPPED[kernel] = swapped
    return _SWAPPED[kernel]


class TransposedBRDF(DerivedBRDF):
    """f^T(ω_i, ω_o) = f(ω_o, ω_i): the base model with its arguments exchanged.

    Built by :func:`transposed`. Its albedo at θ is the base model's response
    to uniform light seen from θ. It keeps the base's lobes (a mirror lobe of
    R(L)·V = R(V)·L and a half-vector lobe are symmetric in the two
    directions), its symmetric kinks (``"nv=nl"``, ``"vgroove"``) and its
    delta term (a mirror delta reflects uniform light into V with the
    specular albedo at θ_V); kinks declared per level of N·V
    (:meth:`~brdfkit.models.BRDF.albedo_kinks_nv`) lie in the other argument
    here and are not forwarded (the engine's refinement finds them).
    """

    def __init__(self, base: BRDF):
        self.base = base
        kernel = None if base.kernel is None else _swapped_kernel(base.kernel)
        super().__init__(name=f"{base.name}^T", params=base.params, values=base.values,
                         citation=base.citation, summary=f"{base.name} with wi and wo exchanged",
                         reciprocal=base.reciprocal, has_sampler=False,
                         isotropic=base.isotropic, mirror_symmetric=base.mirror_symmetric,
                         has_delta=base.has_delta, kernel=kernel,
                         packed=base.packed)
        self.albedo_kinks = base.albedo_kinks
        self.n_channels = base.n_channels  # a coloured base (a material) stays coloured
        if base._driver is not None:  # the base's own loop (all channels in one pass), swapped
            inner = base._driver

            def swapped_driver(wi, wo, data, out):
                return inner(wo, wi, data, out)

            self._driver = swapped_driver
            self._driver_data = base._driver_data

    def lobes(self):
        return self.base.lobes()

    def specular_albedo(self, theta_i):
        return self.base.specular_albedo(theta_i)

    def eval(self, wi, wo):
        if self.base.kernel is None:
            return self.base.eval(wo, wi)
        return super().eval(wi, wo)

    __call__ = eval

    def with_params(self, **changes) -> BRDF:
        return TransposedBRDF(self.base.with_params(**changes))

    def to_dict(self) -> dict:
        return {"transposed": self.base.to_dict()}

    def __repr__(self) -> str:
        return f"transposed({self.base!r})"


def transposed(model: BRDF) -> BRDF:
    """f^T(ω_i, ω_o) = f(ω_o, ω_i) as a model (the model itself when it is reciprocal)."""
    if not isinstance(model, BRDF):
        raise BrdfkitError(f"transposed: model must be a brdfkit model (BRDF); got "
                           f"{type(model).__name__}")
    return model if model.reciprocal else TransposedBRDF(model)


@dataclass(frozen=True)
class AmbientTable:
    """ρ(θ_V) on an adaptive grid of θ_V ∈ [0, θ_max] and its cubic spline.

    Attributes
    ----------
    theta : ndarray (K,)
        Grid of θ_V, radians, increasing from 0 to ``theta_max``.
    rho : ndarray (K, C)
        ρ at the nodes (C = 1 for a scalar model), from the albedo engine.
    error : float
        Absolute error estimate of the interpolated ρ anywhere in
        [0, θ_max]: the largest difference between the spline and the engine at
        the midpoints of the last refinement pass, plus the engine's largest
        error estimate at the nodes.
    tol : float
        The goal the grid was refined to.
    status : int
        ``brdfkit.status.STATUS["render"]``: converged (0: the goal was met and every
        engine angle converged) or limit (1: the error estimate is above the goal).
    detail : str
        One line: what was reached, or why not, with the numbers.
    success, message : bool, str
        The status's success; its message followed by ``detail``.
    """

    theta: np.ndarray
    rho: np.ndarray
    error: float
    tol: float
    status: int
    detail: str

    @property
    def success(self) -> bool:
        return STATUS["render"].success(self.status)

    @property
    def message(self) -> str:
        return STATUS["render"].describe(self.status, self.detail)

    def __post_init__(self):
        object.__setattr__(self, "_interp", _spline(self.theta, self.rho))

    @property
    def theta_max(self) -> float:
        return float(self.theta[-1])

    def __call__(self, theta) -> np.ndarray:
        """ρ at *theta* (radians in [0, θ_max]), shape ``theta.shape + (C,)``."""
        th = np.asarray(theta, dtype=np.float64)
        if th.size and not (th.min() >= 0.0 and th.max() <= self.theta_max * (1 + 1e-12)):
            raise ParameterError(f"theta must lie in [0, {self.theta_max!r}] rad (the table's "
                                 "range); build a table reaching further")
        return self._interp(th)


def _spline(theta, rho):
    """The cubic spline of ρ(θ_V) (SciPy's interpolate imported here: 0.5 s that every
    process importing brdfkit.render paid, the explorer's first view among them)."""
    from scipy.interpolate import CubicSpline

    # ρ is even in θ_V about 0 (V mirrored through N is the same configuration rotated by π
    # about N, for an isotropic model): zero slope at θ = 0; not-a-knot at θ_max
    return CubicSpline(theta, rho, axis=0, bc_type=((1, np.zeros(rho.shape[1])), "not-a-knot"))


#: model object → its tables (weak: they go with the model); 64 models, each table a
#: spline over at most MAX_TABLE_NODES nodes (≤ ~100 kB)
_CACHE = bounded_cache("brdfkit.render.ambient._CACHE", maxsize=64, weak=True)


def ambient_table(model: BRDF, *, theta_max: float, tol: float = RHO_TOL) -> AmbientTable:
    """ρ(θ_V) = ∫ f_r(L′, V) cos θ_L′ dω_L′ tabulated on [0, *theta_max*].

    Parameters
    ----------
    model : BRDF
        An isotropic brdfkit model (registered, pumped, measured, …).
    theta_max : float, keyword-only
        Largest θ_V needed, radians in (0, π/2).
    tol : float, keyword-only
        Absolute accuracy goal of the interpolated ρ (default :data:`RHO_TOL`);
        the engine's own goal is a tenth of it.

    Returns
    -------
    AmbientTable
        Kept on disk for a material (:mod:`brdfkit.analysis.stored`: per model numbers,
        *theta_max*, *tol* and code). Cached per model object: a later call with a
        *theta_max* and *tol* that an earlier table covers returns it.

    Raises
    ------
    ParameterError
        *theta_max* or *tol* out of range.
    BrdfkitError
        An anisotropic model (ρ then also depends on the azimuth of V).
    """
    if not isinstance(model, BRDF):
        raise BrdfkitError(f"ambient_table: model must be a brdfkit model (BRDF); got "
                           f"{type(model).__name__}")
    try:
        th_max = float(theta_max)
    except (TypeError, ValueError):
        th_max = math.nan
    if not 0.0 < th_max < math.pi / 2:
        raise ParameterError(f"theta_max must lie in (0, pi/2) radians; got {theta_max!r}")
    try:
        goal = float(tol)
    except (TypeError, ValueError):
        goal = math.nan
    if not (goal > 0.0 and math.isfinite(goal)):
        raise ParameterError(f"tol must be a positive number; got {tol!r}")
    if not model.isotropic:
        raise BrdfkitError(f"{model.name} is anisotropic: its response to ambient light depends "
                           "on the azimuth of V as well as theta_V, which brdfkit does not "
                           "tabulate yet; render it with ambient 0")
    for t in _CACHE.get(model, ()):
        if t.theta_max >= th_max and t.tol <= goal:
            return t
    key = stored.result_key("ambient", model, th_max, goal) if stored.keeps(model) else None
    table = _from_disk(key) if key else None
    if table is None:
        table = _build(transposed(model), th_max, goal)
        if key:  # a material's table is kept on disk (brdfkit.analysis.stored)
            stored.store(key, {"theta": table.theta, "rho": table.rho, "error": table.error,
                               "tol": table.tol, "status": table.status,
                               "detail": table.detail})
    _CACHE.setdefault(model, []).append(table)
    return table


def _from_disk(key: str) -> AmbientTable | None:
    hit = stored.load(key)
    if hit is None or set(hit) != {"theta", "rho", "error", "tol", "status", "detail"}:
        return None
    return AmbientTable(theta=hit["theta"], rho=hit["rho"], error=float(hit["error"]),
                        tol=float(hit["tol"]), status=int(hit["status"]),
                        detail=str(hit["detail"]))


def _build(target: BRDF, th_max: float, goal: float) -> AmbientTable:
    engine_tol = goal / 10.0
    theta = np.linspace(0.0, th_max, _START_NODES)
    r = albedo(target, theta, tol=engine_tol)
    rho = np.asarray(r.albedo).reshape(theta.size, -1)
    engine_err = float(np.max(r.error))
    converged = r.success
    todo = np.ones(theta.size - 1, dtype=bool)  # intervals still to check
    worst = 0.0
    while True:
        spline = _spline(theta, rho)
        mids = 0.5 * (theta[:-1] + theta[1:])[todo]
        rm = albedo(target, mids, tol=engine_tol)
        vm = np.asarray(rm.albedo).reshape(mids.size, -1)
        engine_err = max(engine_err, float(np.max(rm.error)))
        converged = converged and rm.success
        diff = np.max(np.abs(spline(mids) - vm), axis=1)
        bad = diff > goal
        worst = max(worst, float(np.max(diff[~bad], initial=0.0)))
        # every midpoint becomes a node (its value is known); the halves of the intervals
        # that missed the goal are checked again on the next pass
        theta_new = np.concatenate([theta, mids])
        order = np.argsort(theta_new, kind="stable")
        rho = np.concatenate([rho, vm])[order]
        is_mid = np.concatenate([np.zeros(theta.size, bool), np.ones(mids.size, bool)])[order]
        flag = np.concatenate([np.zeros(theta.size, bool), bad])[order]
        theta = theta_new[order]
        # interval k (between nodes k, k+1) is re-checked when one of its ends is a failed
        # midpoint
        todo = (flag[:-1] & is_mid[:-1]) | (flag[1:] & is_mid[1:])
        if not np.any(bad):
            break
        if theta.size + int(np.count_nonzero(todo)) > MAX_TABLE_NODES:
            worst = max(worst, float(np.max(diff)))
            break
    met = worst <= goal and converged
    error = worst + engine_err
    if met:
        message = (f"rho(theta_V) to {error:.2g} (goal {goal:g}) on {theta.size} nodes in "
                   f"[0, {math.degrees(th_max):.4g}] deg")
    elif not converged:
        message = (f"the albedo engine did not converge at some theta_V (error estimate "
                   f"{engine_err:.2g}); rho is its best estimate")
    else:
        message = (f"rho(theta_V) goal {goal:g} not met within {MAX_TABLE_NODES} nodes: "
                   f"error estimate {error:.2g}")
    codes = STATUS["render"]
    return AmbientTable(theta=theta, rho=rho, error=error, tol=goal,
                        status=codes.CONVERGED if met else codes.LIMIT, detail=message)
