"""
Directional albedo by lobe-aware deterministic quadrature
=========================================================

a(ω_i) = ∫_Ω f_r(ω_i, ω_o) cos θ_o dω_o (Lewis's k_ρ, eq. 15; Neumann's
albedo) to ~1e-7 absolute, with an error estimate, for lobes as sharp as
Phong n = 10⁴ or Beckmann α = 0.01 and at incidence up to 89.999°.

Method
------
The outgoing hemisphere is parametrised by polar coordinates (t, φ) about
the axis of the model's sharpest lobe (:meth:`BRDF.lobes`):

- ``mirror`` lobes: about the mirror direction R of ω_i,
  ω_o = cos t R + sin t (cos φ e₁ + sin φ e₂), dω_o = sin t dt dφ;
- ``half`` lobes: over the half vector h = (sin t cos φ, sin t sin φ, cos t),
  ω_o = 2(ω_i·h)h − ω_i, dω_o = 4(ω_i·h) sin t dt dφ;
- ``diffuse`` / ``normal`` lobes: about the normal, dω_o = sin t dt dφ.

For each t the azimuths with ω_o above the horizon form one interval
[0, φ_max(t)] whose end is known in closed form (mirror: cos φ_max =
−cot t cot θ_i; half: cos φ_max = −cos θ_i cos 2t/(sin θ_i sin 2t)), so the
horizon cut never falls inside a quadrature panel. In half-vector space the
azimuths where the V-groove G = min(1, 2(N·H)(N·V)/(V·H), 2(N·H)(N·L)/(L·H))
switches branch are also break points (closed forms in :func:`_phi_breaks`); so are the
crests of a lobe elongated along the tangent axes (:meth:`BRDF.albedo_half_axes`) ± 3 crest
widths, and in t where a crest meets the horizon (:func:`_axis_breaks`, :func:`_t_breaks`).
The t axis is split at the horizon-tangency angles and graded geometrically
at w, 2w, 4w, 8w, then 32w, 128w … for lobe width w. Every panel uses a smoothstep change of
variable (which removes √-type endpoint singularities such as Ward's
1/√(N·V)) and a 15-point Gauss–Kronrod rule in t and in φ; the embedded
7-point Gauss rule gives an error estimate (a QUADPACK-type heuristic, see
:func:`_reduce`). If the
estimate exceeds the tolerance every panel is halved in both directions and
the angle recomputed (up to 5 times).

Models that declare both ``isotropic`` and ``mirror_symmetric`` are integrated over
φ ∈ [0, φ_max] and doubled (mirror symmetry about the plane of incidence); anisotropic
models, isotropic ones that are not even in φ_i − φ_o (an NBRDF net, a noisy measured
table) and plain callables over both halves.

Incidence azimuth. ω_i = (sin θ_i cos φ_i, sin θ_i sin φ_i, cos θ_i): the nodes are
generated for ω_i at azimuth 0 and rotated about the normal by φ_i, with ω_i, where f is
evaluated (the ``"albedo"`` loop of :mod:`brdfkit.models._drivers` and
:func:`_callable_evaluator`: the one seam). Every frame above (mirror, half vector,
normal) and every kink curve (N·V = N·L, the V-groove's, N·V = k) is built from ω_i and
the normal only, so the rotated nodes are exactly the nodes of ω_i at φ_i. An isotropic
model's albedo does not depend on φ_i (rotation invariance): it is recorded, not applied
(the numbers are those of φ_i = 0, bit for bit).

This is brdfkit's one albedo engine: every directional albedo brdfkit reports comes
from it. The other estimators are second methods beside it, each in its own module:
:func:`~brdfkit.analysis.monte_carlo.albedo_mc` (importance-sampled Monte Carlo, a
cross-check with a standard error), :func:`~brdfkit.analysis.hemispherical.
hemispherical_albedo` (ρ_hh, an outer rule over this engine) and
:func:`~brdfkit.analysis.specular_integral.H_s` (Lewis's H_s by its own 1-D quadrature).

Public objects
--------------
- :class:`AlbedoResult` — θ_i, φ_i, albedo, error estimate, status (``brdfkit.status``,
  kind ``albedo``), ``success`` and ``message``.
- :func:`albedo` — deterministic albedo of a model or callable.
- :func:`evaluate_pairs`, :func:`check_theta`, :func:`check_phi`, :func:`incident`,
  :func:`lobe_frame` — shared with the other estimators and the verdicts.
- :data:`CONVERGED`, :data:`MAX_LEVEL_REACHED`, :data:`NODE_CAP`, :data:`NONFINITE`,
  :data:`STATUS_MESSAGES` — the ``albedo`` codes of :data:`brdfkit.status.STATUS` and
  their messages with this engine's numbers.

References
----------
- [Lewis1993] eqs. (15)–(19), Fig. 5.
- [Neumann1999] §2, Fig. 1.
- R. Piessens et al., QUADPACK (1983): Gauss–Kronrod 7–15 and its error heuristic.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from brdfkit.analysis._node_pairs import own_loop_evaluator
from brdfkit.analysis.quadrature import (  # the compiled core
    _KINK_BITS,
    _MODE,
    _WGAUSS,
    _WK,
    _X,
    MAX_LEVEL,
    NORMAL,
    PARALLEL_NODES,
    _count_nodes,
    _gen_all_parallel,
    _gen_all_serial,
    _reduce_all_parallel,
    _reduce_all_serial,
)
from brdfkit.errors import BrdfkitError, ParameterError
from brdfkit.models._base import BRDF
from brdfkit.models._drivers import generic_loop, loop_driver
from brdfkit.status import STATUS

__all__ = ["AlbedoResult", "albedo", "evaluate_pairs", "check_theta", "check_phi", "incident",
           "lobe_frame", "STATUS_MESSAGES", "CONVERGED", "MAX_LEVEL_REACHED", "NODE_CAP",
           "NONFINITE"]



# The engine's loop over (θ_i, ω_o) nodes is the "albedo" loop of models/_drivers, generated
# per kernel and cached on disk (it was compiled in every process: 0.3-2 s per model).

#: :func:`brdfkit.models.eval_pairs` for the analyses: serial (cheaper to compile: ~0.3 s
#: per model instead of ~1 s for a prange loop), no direction checks (the analyses build
#: unit directions); the plain loop of models/_drivers with the kernel an argument.
_eval_pairs_serial = generic_loop("plain", parallel=False)


def evaluate_pairs(model, wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
    """f_r(wi, wo) for (N, 3) arrays → (N, C) (C = 1 for scalar models), values as computed
    (a non-finite value is returned, not hidden).

    Models with a compiled kernel run it directly (serial); other models through
    :meth:`~brdfkit.models.BRDF.eval`; plain callables are called.
    """
    wi = np.ascontiguousarray(np.broadcast_to(wi, np.broadcast_shapes(wi.shape, wo.shape)),
                              dtype=np.float64)
    wo = np.ascontiguousarray(np.broadcast_to(wo, wi.shape), dtype=np.float64)
    if isinstance(model, BRDF) and model.kernel is not None:
        P = np.ascontiguousarray(np.asarray(model.packed, dtype=np.float64))
        out = np.empty((wi.shape[0], P.shape[0]))
        _eval_pairs_serial(model.kernel, wi, wo, P, out)
        return out
    f = model.eval if isinstance(model, BRDF) else model
    return np.asarray(f(wi, wo), dtype=np.float64).reshape(wi.shape[0], -1)


#: Memory bounds of :func:`_integrate`: nodes evaluated per call of ``evaluate`` (about
#: 56 + 8C bytes each for a compiled model, ~3x that for a callable) and the most nodes one
#: angle may use. Level 5 of a sharp mirror lobe needs ~9e6 nodes per angle (a table of 64
#: angles at once allocated 19 GB before the bound); past the bound the previous level's
#: result and its error estimate are returned, with status NODE_CAP.
MAX_CHUNK_NODES = 3_000_000
MAX_ANGLE_NODES = 6_000_000

#: Status of one angle of an :class:`AlbedoResult`: the ``albedo`` codes of
#: :data:`brdfkit.status.STATUS` (kept as module names: tests and saved JSON use them).
#: Anything but CONVERGED means the error estimate is above the goal
#: (``max(tol, 1e-10·|a|)``) or, for NONFINITE, that there is no estimate at all.
_CODES = STATUS["albedo"]
CONVERGED, MAX_LEVEL_REACHED, NODE_CAP, NONFINITE = (
    _CODES.CONVERGED, _CODES.LIMIT, _CODES.NODE_CAP, _CODES.NONFINITE)
#: code → message: the status table's message with this engine's numbers.
STATUS_MESSAGES = {
    CONVERGED: _CODES.message(CONVERGED),
    MAX_LEVEL_REACHED: f"{_CODES.message(MAX_LEVEL_REACHED)}; {MAX_LEVEL} refinements",
    NODE_CAP: f"{_CODES.message(NODE_CAP)}; bound: {MAX_ANGLE_NODES:,} nodes per angle",
    NONFINITE: _CODES.message(NONFINITE),
}


def _integrate_chunk(evaluate, th, ph, mode, width, level, sym, kinks, kvs, azs, npieces, a,
                     e, bad, idx, tol) -> np.ndarray:
    """One level for the angles ``th`` at azimuths ``ph`` (results written to a[idx], e[idx];
    bad[idx] counts non-finite integrand values); returns the mask of angles whose error
    estimate is still above the goal."""
    th, kvs, azs = (np.ascontiguousarray(x) for x in (th, kvs, azs))
    lv = np.full(th.size, level, dtype=np.int64)
    # the slots from the very arrays the generator reads (the level loop's counts, from
    # per-angle scalars, differed by an interval in rare cases: written past the slots)
    counts = [_count_nodes(mode, th[j], width, level, sym, _X, kinks, kvs[j], azs[j])[0]
              for j in range(th.size)]
    offsets = np.zeros(th.size + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    total = int(offsets[-1])
    wo = np.empty((total, 3))
    wk = np.empty(total)
    wg = np.empty(total)
    piece = np.empty(total, dtype=np.int64)
    big = total >= PARALLEL_NODES
    gen = _gen_all_parallel if big else _gen_all_serial
    gen(mode, th, width, lv, sym, _X, _WK, _WGAUSS, offsets, wo, wk, wg, piece, kinks,
        kvs, azs)
    vals, nbad = evaluate(th, np.ascontiguousarray(ph), offsets, wo)
    vals = np.ascontiguousarray(vals, dtype=np.float64)
    del wo
    aa = np.empty((th.size, vals.shape[1]))
    ee = np.empty_like(aa)
    red = _reduce_all_parallel if big else _reduce_all_serial
    red(vals, wk, wg, piece, offsets, np.ascontiguousarray(npieces), aa, ee)
    a[idx] = aa
    e[idx] = ee
    bad[idx] += nbad
    return np.any(ee > np.maximum(tol, 1e-10 * np.abs(aa)), axis=1) & (nbad == 0)


def _integrate(evaluate, thetas: np.ndarray, phis: np.ndarray, mode: int, width: float,
               sym: bool, tol: float, n_channels: int, kinks: int = 0,
               levels_nv: np.ndarray | None = None, axes=None
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Level loop shared by the compiled and the callable paths.

    ``evaluate(thetas, phis, offsets, wo) -> (vals (N, C), n_bad (T,))`` evaluates f at the
    nodes (generated for azimuth 0, rotated by each angle's φ) and counts the non-finite
    values per angle. Returns (albedo, error, status); an angle with non-finite values has
    albedo NaN, error inf, status NONFINITE. ``axes``: the model's
    :meth:`~brdfkit.models.BRDF.albedo_half_axes` (or None).
    """
    n = thetas.size
    # per angle (φ_i, a_x, a_y, q) for quadrature._axis_breaks; a_x = NaN: no elongated lobe
    azs = np.column_stack([phis, np.broadcast_to(np.asarray(
        axes if axes is not None else (np.nan, np.nan, 0.0), dtype=np.float64), (n, 3))])
    kvs = (np.full((n, 0), np.nan) if levels_nv is None
           else np.asarray(levels_nv, dtype=np.float64))
    a = np.zeros((n, n_channels))
    e = np.full((n, n_channels), np.inf)
    bad = np.zeros(n, dtype=np.int64)
    status = np.full(n, CONVERGED, dtype=np.int8)
    todo = np.arange(n)
    for level in range(MAX_LEVEL + 1):
        counts = np.empty(todo.size, dtype=np.int64)
        npieces = np.empty(todo.size, dtype=np.int64)
        for k, t in enumerate(thetas[todo]):
            counts[k], npieces[k] = _count_nodes(mode, float(t), width, level, sym, _X, kinks,
                                                 kvs[todo[k]], azs[todo[k]])
        if level > 0:
            # memory bound: an angle whose next level needs more than MAX_ANGLE_NODES keeps
            # the previous level's estimate and its (larger, honest) error estimate
            fits = counts <= MAX_ANGLE_NODES
            status[todo[~fits]] = NODE_CAP
            todo, counts, npieces = todo[fits], counts[fits], npieces[fits]
            if todo.size == 0:
                break
        # angles in chunks of at most MAX_CHUNK_NODES nodes (one angle may exceed it alone)
        start = 0
        still = []
        while start < todo.size:
            stop = start + 1
            acc = int(counts[start])
            while stop < todo.size and acc + int(counts[stop]) <= MAX_CHUNK_NODES:
                acc += int(counts[stop])
                stop += 1
            idx = todo[start:stop]
            above = _integrate_chunk(evaluate, thetas[idx], phis[idx], mode, width, level, sym,
                                     kinks, kvs[idx], azs[idx], npieces[start:stop], a, e,
                                     bad, idx, tol)
            still.append(idx[above])
            start = stop
        todo = np.concatenate(still) if still else todo[:0]
        if todo.size == 0:
            break
    status[todo] = MAX_LEVEL_REACHED  # still above the goal after the last level
    nonfinite = bad > 0
    status[nonfinite] = NONFINITE
    a[nonfinite] = np.nan
    e[nonfinite] = np.inf
    return a, e, status


# --------------------------------------------------------------------------- public API
@dataclass(frozen=True)
class AlbedoResult:
    """Directional albedo at the incidence directions (θ_i, φ_i).

    Attributes
    ----------
    theta : ndarray
        θ_i in radians (shape of the input, broadcast with φ_i; 0-d for a scalar).
    albedo : ndarray
        a(θ_i), shape ``theta.shape`` or ``theta.shape + (C,)`` for coloured models.
    error : ndarray
        Error estimate (absolute), same shape as ``albedo``.
    status : ndarray of int8, shape ``theta.shape``
        Per angle: :data:`CONVERGED` (0), :data:`MAX_LEVEL_REACHED` (1),
        :data:`NODE_CAP` (2) or :data:`NONFINITE` (3) — ``brdfkit.status.STATUS["albedo"]``;
        :data:`STATUS_MESSAGES` says what each means. Only CONVERGED angles meet the
        tolerance.
    phi : ndarray
        The incidence azimuth φ_i in radians, shape ``theta.shape`` (0 unless given).
    anisotropic : bool
        The model declares itself anisotropic (``isotropic`` False): its albedo depends
        on φ_i, and :meth:`to_dict` always records it.
    success, message
        Whether every angle converged; one line saying which did not and why.
    """

    theta: np.ndarray
    albedo: np.ndarray
    error: np.ndarray
    status: np.ndarray | None = None
    phi: np.ndarray | float = 0.0
    anisotropic: bool = False

    def __post_init__(self):
        st = (np.zeros(np.shape(self.theta), dtype=np.int8) if self.status is None
              else np.asarray(self.status, dtype=np.int8).reshape(np.shape(self.theta)))
        object.__setattr__(self, "status", st)
        object.__setattr__(self, "phi", np.array(np.broadcast_to(
            np.asarray(self.phi, dtype=np.float64), np.shape(self.theta))))

    @property
    def success(self) -> bool:
        """True when every angle converged to the tolerance."""
        return bool(np.all([_CODES.success(c) for c in np.unique(self.status)]))

    @property
    def message(self) -> str:
        """One line: converged, or which angles did not and why."""
        if self.success:
            return STATUS_MESSAGES[CONVERGED]
        th = np.degrees(np.asarray(self.theta)).reshape(-1)
        ph = np.degrees(self.phi).reshape(-1)
        with_phi = bool(np.any(ph != 0.0))
        st = self.status.reshape(-1)
        parts = []
        for code in (MAX_LEVEL_REACHED, NODE_CAP, NONFINITE):
            where = np.flatnonzero(st == code)
            if where.size:
                shown = ", ".join((f"({th[k]:g}, {ph[k]:g})" if with_phi else f"{th[k]:g}")
                                  for k in where[:5]) + (" ..." if where.size > 5 else "")
                what = "(theta_i, phi_i)" if with_phi else "theta_i"
                parts.append(f"{what} = {shown} deg: {STATUS_MESSAGES[code]}")
        return "; ".join(parts)

    def to_dict(self) -> dict:
        """JSON-ready: θ in degrees, albedo and error (per-channel lists when coloured), and,
        when some angle did not converge, its ``status`` codes and ``message``; ``phi_deg``
        (φ_i in degrees, shaped as ``theta_deg``) for an anisotropic model or when some φ_i
        is not 0 (an isotropic model's JSON at φ_i = 0 is as it always was)."""
        d = {"theta_deg": np.degrees(self.theta).tolist()}
        if self.anisotropic or np.any(self.phi != 0.0):
            d["phi_deg"] = np.degrees(self.phi).tolist()
        d.update({"albedo": np.asarray(self.albedo).tolist(),
                  "error": np.asarray(self.error).tolist()})
        if not self.success:
            d["status"] = self.status.tolist()
            d["message"] = self.message
        return d


def lobe_frame(model) -> tuple[int, float]:
    """(mode, width) of the integration frame: the model's :meth:`~BRDF.sharpest_lobe`
    (normal frame, width π/2 for a plain callable)."""
    if not isinstance(model, BRDF):
        return NORMAL, math.pi / 2
    lobe = model.sharpest_lobe()
    return _MODE.get(lobe.kind, NORMAL), float(lobe.width)


def _kink_flags(model) -> int:
    """The node generators' bit flags for the model's declared :attr:`albedo_kinks`."""
    if not isinstance(model, BRDF):
        return 0
    unknown = set(model.albedo_kinks) - set(_KINK_BITS)
    if unknown:
        raise BrdfkitError(f"{model.name}: albedo_kinks {sorted(unknown)} are not known to the "
                           f"albedo engine; known: {', '.join(_KINK_BITS)}")
    flags = 0
    for k in model.albedo_kinks:
        flags |= _KINK_BITS[k]
    return flags


MAX_KINKS = 12


def _declared_levels(model, flat: np.ndarray) -> np.ndarray | None:
    """The model's :meth:`~BRDF.albedo_kinks_nv` levels, shape (T, K ≤ MAX_KINKS), or None."""
    if not isinstance(model, BRDF):
        return None
    kv = model.albedo_kinks_nv(flat)
    if kv is None:
        return None
    kv = np.asarray(kv, dtype=np.float64).reshape(flat.size, -1)
    if kv.shape[1] > MAX_KINKS:
        # keep the engine's break-point arrays small: the rest is left to refinement
        kv = kv[:, :MAX_KINKS]
    return np.ascontiguousarray(kv)


def check_theta(theta_i, name: str = "theta_i") -> np.ndarray:
    """*theta_i* as float64 radians in [0, π/2); :class:`ParameterError` naming *name*."""
    try:
        th = np.asarray(theta_i, dtype=np.float64)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a number or an array of numbers (radians in "
                             f"[0, pi/2)); got {theta_i!r}") from None
    if not np.all(np.isfinite(th)):
        raise ParameterError(f"{name} must be finite (radians)")
    if np.any((th < 0.0) | (th >= math.pi / 2)):
        bad = th[(th < 0.0) | (th >= math.pi / 2)].flat[0]
        raise ParameterError(
            f"{name} must lie in [0, pi/2) radians = [0, 90) degrees; got {bad!r} rad")
    return th


def check_phi(phi, name: str = "phi") -> np.ndarray:
    """*phi* (an azimuth) as float64 radians, any finite value (periodic);
    :class:`ParameterError` naming *name*."""
    try:
        ph = np.asarray(phi, dtype=np.float64)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a number or an array of numbers (an azimuth in "
                             f"radians, any finite value); got {phi!r}") from None
    if not np.all(np.isfinite(ph)):
        bad = ph[~np.isfinite(ph)].flat[0]
        raise ParameterError(f"{name} must be finite (an azimuth in radians, any finite "
                             f"value); got {bad!r}")
    return ph


def incident(theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """ω_i = (sin θ cos φ, sin θ sin φ, cos θ), shape ``broadcast(θ, φ) + (3,)``."""
    theta, phi = np.broadcast_arrays(np.asarray(theta, dtype=np.float64),
                                     np.asarray(phi, dtype=np.float64))
    s = np.sin(theta)
    return np.stack([s * np.cos(phi), s * np.sin(phi), np.cos(theta)], axis=-1)


def _broadcast_angles(th: np.ndarray, ph: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """θ_i and φ_i broadcast to one shape; :class:`ParameterError` when they do not."""
    try:
        shape = np.broadcast_shapes(th.shape, ph.shape)
    except ValueError:
        raise ParameterError(f"phi must be a number or an array that broadcasts with theta_i; "
                             f"got shapes {ph.shape} and {th.shape}") from None
    return (np.array(np.broadcast_to(th, shape)), np.array(np.broadcast_to(ph, shape)))


def _check_tol(tol: float) -> float:
    try:
        t = float(tol)
    except (TypeError, ValueError):
        raise ParameterError(f"tol must be a positive number; got {tol!r}") from None
    if not (t > 0.0 and math.isfinite(t)):
        raise ParameterError(f"tol must be a positive number; got {tol!r}")
    return t


def _check_model(model, func: str) -> None:
    if isinstance(model, BRDF) or (callable(model) and not isinstance(model, type)):
        return
    hint = (f" (build it first: brdfkit.model({model!r}))" if isinstance(model, str) else "")
    raise BrdfkitError(f"{func}: model must be a brdfkit model (BRDF) or a callable "
                       f"f(wi, wo); got {type(model).__name__} {model!r}{hint}")


def albedo(model, theta_i, *, phi=0.0, tol: float = 1e-7, mode: str | None = None,
           width: float | None = None) -> AlbedoResult:
    """Directional albedo a(θ_i, φ_i) = ∫ f_r(ω_i, ω_o) cos θ_o dω_o, deterministic.

    Parameters
    ----------
    model : BRDF or callable
        A brdfkit model (integrated through its compiled kernel, in the frame
        of its sharpest lobe, with the kinks it declares) or any callable
        ``f(wi, wo) -> array`` taking broadcastable (..., 3) arrays and
        returning (...) or (..., C). ω_i = (sin θ_i cos φ_i, sin θ_i sin φ_i, cos θ_i).
    theta_i : float or array_like
        Incidence angles in radians, in [0, π/2).
    phi : float or array_like, keyword-only
        Incidence azimuth φ_i in radians (default 0: ω_i in the xz-plane), any finite
        value, broadcast with *theta_i*. An anisotropic model (``isotropic`` False) and a
        callable are integrated with ω_i at φ_i; an isotropic model's albedo does not
        depend on it (the result records it; the numbers are those of φ_i = 0).
    tol : float, keyword-only
        Absolute accuracy goal (default 1e-7). Panels are halved until the
        error estimate meets it (or a relative 1e-10), at most 5 times.
    mode : {"diffuse", "mirror", "half"}, optional
        Override the integration frame (default: from
        :meth:`~brdfkit.models.BRDF.sharpest_lobe`; ``diffuse`` for callables).
    width : float, optional
        Override the lobe width (radians) that grades the panels.

    Returns
    -------
    AlbedoResult
        ``theta``, ``albedo``, ``error`` (absolute error estimate) and
        ``status`` per angle (``success`` when all converged; an angle that
        did not keeps its last estimate and says why; an integrand that is NaN
        or infinite at a node gives albedo NaN with status NONFINITE — it is
        never silently replaced). A model with a delta term (``has_delta``,
        e.g. He–Torrance) has its :meth:`~brdfkit.models.BRDF.specular_albedo`
        added, with no extra error.

    Notes
    -----
    The model protocol (:class:`~brdfkit.models.BRDF`) is all the engine reads:
    ``isotropic`` (φ_i not applied) and ``mirror_symmetric`` (with it: integrate half the
    azimuths and double), ``albedo_kinks``
    (``"nv=nl"``, ``"vgroove"``: closed-form curves made panel edges),
    ``albedo_kinks_nv(theta)`` (up to 12 levels k of circles N·V = k per angle,
    e.g. where a pumped model's g switches branch; edges in every frame, closed
    forms in :func:`_phi_breaks`), ``albedo_half_axes``, ``specular_albedo``. At
    most 6e6 nodes are used per angle (``MAX_ANGLE_NODES``).

    Examples
    --------
    >>> import brdfkit, numpy as np
    >>> from brdfkit.analysis import albedo
    >>> r = albedo(brdfkit.model("lambert", rho_d=0.5), np.radians([0, 60, 89]))
    >>> np.allclose(r.albedo, 0.5), r.success
    (True, True)
    """
    _check_model(model, "albedo")
    th, ph = _broadcast_angles(check_theta(theta_i), check_phi(phi))
    tol = _check_tol(tol)
    m_mode, m_width = lobe_frame(model)
    if mode is not None:
        if mode not in _MODE:
            raise ParameterError(f"mode must be one of {', '.join(_MODE)}; got {mode!r}")
        m_mode = _MODE[mode]
    if width is not None:
        try:
            w = float(width)
        except (TypeError, ValueError):
            w = float("nan")
        if not (w > 0.0 and math.isfinite(w)):
            raise ParameterError(f"width must be a finite number > 0 (radians); got {width!r}")
        m_width = w
    flat = np.ascontiguousarray(th.reshape(-1))
    anisotropic = isinstance(model, BRDF) and not model.isotropic
    # the azimuth applied: an isotropic model is rotation invariant, so its nodes stay at 0
    phis = (np.zeros(flat.size) if isinstance(model, BRDF) and model.isotropic
            else np.ascontiguousarray(ph.reshape(-1)))
    if isinstance(model, BRDF):
        if model._driver is not None and (model.n_channels or 1) > 1:
            # a model with its own loop over pairs computing every channel in one pass (an
            # NBRDF net: ~7x the per-channel kernel; a table: one bin search per pair)
            evaluate, n_channels = own_loop_evaluator(model)
        elif model.kernel is not None:
            P = np.ascontiguousarray(np.asarray(model.packed, dtype=np.float64))
            nodes = loop_driver(model.kernel, loop="albedo")

            def evaluate(th, ph, offsets, wo):
                vals = np.empty((wo.shape[0], P.shape[0]))
                bad = np.zeros(th.size, dtype=np.int64)
                nodes(P, th, ph, offsets, wo, vals, bad)
                return vals, bad

            n_channels = P.shape[0]
        else:
            evaluate, n_channels = _callable_evaluator(model.eval, "albedo: model.eval")
        # the half-azimuth shortcut (integrate φ_o on one side of the plane of incidence and
        # double) only for a model that declares both symmetries it rests on: rotation
        # invariance (φ_i = 0 stands for every φ_i) and evenness in φ_i − φ_o
        sym = bool(model.isotropic and model.mirror_symmetric)
        a, e, status = _integrate(evaluate, flat, phis, m_mode, m_width, sym, tol,
                                  n_channels, _kink_flags(model), _declared_levels(model, flat),
                                  model.albedo_half_axes())
        coloured = model.n_channels is not None
        extra = model.specular_albedo(flat)
        if extra is not None:
            a = a + np.asarray(extra, dtype=np.float64).reshape(flat.size, -1)
    else:
        evaluate, n_channels = _callable_evaluator(model, "albedo: the callable")
        a, e, status = _integrate(evaluate, flat, phis, m_mode, m_width, False, tol, n_channels)
        coloured = evaluate.coloured
    if coloured:
        shape = th.shape + (a.shape[1],)
    else:
        a, e = a[:, 0], e[:, 0]
        shape = th.shape
    return AlbedoResult(theta=th.copy(), albedo=a.reshape(shape), error=e.reshape(shape),
                        status=status.reshape(th.shape), phi=ph, anisotropic=anisotropic)


def _callable_evaluator(f: Callable, what: str):
    """(evaluate, n_channels) for a NumPy-evaluated f: nodes built in Numba, f vectorised."""

    def evaluate(th, ph, offsets, wo):
        idx = np.repeat(np.arange(th.size), np.diff(offsets))
        up = wo[:, 2] > 0.0  # unused slots and rounding below the horizon: not evaluated
        wi = incident(th[idx], ph[idx])[up]
        wo_up = wo[up]
        turn = ph[idx][up]
        if np.any(turn != 0.0):  # the nodes rotated with ω_i by φ_i about the normal
            c, s = np.cos(turn), np.sin(turn)
            wo_up = np.stack([c * wo_up[:, 0] - s * wo_up[:, 1], s * wo_up[:, 0]
                              + c * wo_up[:, 1], wo_up[:, 2]], axis=-1)
        got = np.asarray(f(wi, np.ascontiguousarray(wo_up)), dtype=np.float64)
        if got.shape[:1] != (wi.shape[0],) or got.ndim > 2:
            raise BrdfkitError(f"{what} returned shape {got.shape} for "
                               f"{wi.shape[0]} direction pairs; expected (N,) or (N, C)")
        evaluate.coloured = got.ndim == 2
        got = got.reshape(wi.shape[0], -1)
        finite = np.isfinite(got)
        # non-finite values are counted per angle (the angle's albedo becomes NaN) and
        # stored as 0 so that they cannot poison the other angles' sums
        bad = np.bincount(idx[up], weights=np.sum(~finite, axis=1),
                          minlength=th.size).astype(np.int64)
        vals = np.zeros((wo.shape[0], got.shape[1]))
        vals[up] = np.where(finite, got, 0.0)
        return vals, bad

    evaluate.coloured = False
    probe, _ = evaluate(np.array([0.0]), np.array([0.0]), np.array([0, 1]),
                        np.array([[0.0, 0.0, 1.0]]))
    return evaluate, probe.shape[1]
