"""
Fitting a model to a measured material
======================================

:func:`fit` adjusts a model's parameters (read from its ``params``
declaration: defaults, bounds, kinds — no second list) so that it matches a
target (any brdfkit model: a built-in material, a MERL ``.binary``
:class:`~brdfkit.data.MeasuredBRDF`, another model) on the MERL grid
(:mod:`brdfkit.fitting.samples`) under one of the losses of
:mod:`brdfkit.fitting.losses`, and returns a :class:`FitResult` with every
metric, the albedos and a convergence record.

Procedure
---------
Free parameters: every declared parameter except choices (kept as given),
optional ones that are None (e.g. no η: F = 1 stays so) and those in
``fixed``; colour parameters per channel of the target, scalars shared, lobe
parameters per lobe. A parameter that changes nothing on the samples (e.g. an
extinction coefficient without an η) is held and reported as ``inert``.
Linear parameters (colour parameters the model is affine in, found
numerically; see :mod:`brdfkit.fitting._problem`) are solved in closed form;
the others ("shape") are optimised over bounded reparametrisations
(:mod:`brdfkit.fitting._space`) with Nelder–Mead.

``procedure="nielsen"`` (Nielsen et al. 2015, "Fitting Results and
Observations"): (i) the linear parameters (ρ_d and k_s) in closed form at
the first guess; (ii) the shape parameters (s, α and η) with the linear ones
held; (iii) the shape parameters with the linear parameters whose basis
depends on the shape (k_s, not ρ_d: as the paper's stage (iii) frees s, α,
k_s). ``procedure="staged"`` (any model): (i) as above; (ii) the shape
parameters with the linear ones re-solved at every evaluation (variable
projection: exact for l1/l2/ngan); (iii) all free parameters jointly under the
loss. ``"auto"``: ``staged``. ``"direct"``: all free parameters jointly from
the first guess (one stage, no linear solve: the plain approach, for
comparison).

A pumped model (no linear parameters: g depends on them) is started from the fit of its
unpumped root (the root's own staged fit as stage (ii)), then stage (iii) optimises all its
parameters jointly. A one-times pumped model is evaluated during the fit through
:func:`brdfkit.pumping.surrogate.surrogate` (albedo tables per shape parameter value,
interpolated, linear parameters combined without a new table); the result, its metrics and
albedos are the exact model's, and ``convergence["surrogate"]`` records the surrogate's loss
at the result next to them, and, evaluations being cheap, all parameters get one run with
stage (ii)'s full steps before stage (iii)'s polish. Where the pumped model does not see a
common scale of its linear parameters (g₁: f/g is homogeneous of degree 0 in them), one per
channel is held at the root's value (``convergence["scale_held"]``;
:mod:`brdfkit.fitting._pumped`).

Stage (ii) runs from several starts: the data-driven first guess (the width
parameter from the measured peak's half-width β via the model's
``width_from_beta``, the other shape parameters at their defaults), the
declared defaults, and ``n_starts − 2`` random starts (z of the guess plus
N(0, 1), from ``numpy.random.default_rng(seed)``). Every run is recorded; once
two runs reach the same loss (relative difference ≤ :data:`CONSENSUS`) the
remaining starts are recorded as skipped.

The fit evaluates on one thread (``numba.set_num_threads(1)``, restored
after): for ~15,000 pairs the parallel driver's thread wake-ups cost more
than the work on a shared 2-core machine (measured: 16 ms vs 0.3 ms).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numba
import numpy as np
from scipy.optimize import minimize

from brdfkit.errors import BrdfkitError, ParameterError
from brdfkit.fitting._problem import Problem
from brdfkit.fitting._pumped import hold_scale
from brdfkit.fitting._space import Coord, as_vector, from_vector
from brdfkit.fitting.losses import LOSSES
from brdfkit.fitting.samples import (
    ALBEDO_THETA_DEG,
    DEFAULT_STRIDES,
    albedo_from_values,
    albedo_nodes,
    merl_samples,
)
from brdfkit.models import BRDF
from brdfkit.pumping import PumpedBRDF
from brdfkit.pumping.surrogate import surrogate

__all__ = ["fit", "FitResult", "PROCEDURES", "STATUS_MESSAGES"]

PROCEDURES = ("auto", "staged", "nielsen", "direct")
#: Status codes of a fit (FitResult.status).
CONVERGED, AT_BOUND, MAX_EVALS, NONFINITE = 0, 1, 2, 3
STATUS_MESSAGES = {
    CONVERGED: "converged",
    AT_BOUND: "converged with parameters at a bound of their declared range",
    MAX_EVALS: "evaluation limit reached before the tolerance",
    NONFINITE: "the fitted model is not finite on the samples",
}
#: Nelder–Mead stops when the losses at the simplex's vertices agree to this fraction of
#: the first guess's loss (stage ii; stage iii, a polish from a stationary point, at
#: FRTOL_POLISH). A criterion on the loss only: along flat directions (e.g. Lafortune's
#: common scale of C_xy, C_z against rho_s) there is no parameter tolerance to reach.
FRTOL, FRTOL_POLISH = 1e-6, 1e-5
#: Two stage-(ii) runs whose losses agree to this relative difference are one optimum.
CONSENSUS = 1e-4


@dataclass(frozen=True, eq=False)
class FitResult:
    """The outcome of :func:`fit`.

    Attributes
    ----------
    model : BRDF
        The fitted model (a model like any other).
    params : dict
        Its parameter values (JSON-ready: lists for per-channel values).
    loss : str
        The loss minimised; ``value`` its final value.
    metrics : dict
        Every loss of :data:`~brdfkit.fitting.losses.LOSSES` at the result.
    theta_deg : ndarray (T,)
        Incidence angles of the albedo curves.
    albedo_model, albedo_target : ndarray (T, C)
        Directional albedos (:func:`~brdfkit.fitting.samples.albedo_nodes`).
    albedo_rel_error : ndarray (T, C)
        (a_model − a_target) / a_target.
    convergence : dict
        ``procedure``, ``stages`` (name, parameters, evaluations, loss before/after,
        status), ``starts`` (every stage-(ii) run: start, end, loss), ``evaluations``,
        ``time_s``, ``at_bounds``, ``linear``, ``inert``, ``n_samples``.
    status, success, message :
        As :data:`STATUS_MESSAGES`; ``success`` is False only for NONFINITE.
    """

    model: BRDF
    params: dict
    loss: str
    value: float
    metrics: dict
    theta_deg: np.ndarray
    albedo_model: np.ndarray
    albedo_target: np.ndarray
    albedo_rel_error: np.ndarray
    convergence: dict = field(default_factory=dict)
    status: int = CONVERGED
    success: bool = True
    message: str = ""

    def to_dict(self) -> dict:
        """``{"model", "params", "metrics", "albedo", "convergence", ...}`` (JSON-ready;
        ``params`` can be passed back as ``-p NAME=VALUE``)."""
        d = self.model.to_dict()
        return {"model": d["model"], "params": d["params"],
                **({"pump": d["pump"]} if "pump" in d else {}),
                "loss": self.loss, "value": self.value, "metrics": dict(self.metrics),
                "albedo": {"theta_deg": self.theta_deg.tolist(),
                           "model": self.albedo_model.tolist(),
                           "target": self.albedo_target.tolist(),
                           "rel_error": self.albedo_rel_error.tolist()},
                "convergence": self.convergence, "status": self.status,
                "success": self.success, "message": self.message}


# --------------------------------------------------------------------------- helpers
def _measured_half_width(target) -> float:
    """Half-width (rad, in θ_h) of the target's specular peak: the profile of f·cos θ_i
    along θ_h at θ_d = 5°, φ_d = 90°, minus its floor, falls to half its value at θ_h → 0
    (the first bin centre). π/4 when there is no peak (a diffuse target)."""
    from brdfkit.data.merl import half_diff_to_directions

    u = (np.arange(90) + 0.5) / 90.0
    th = u * u * (0.5 * math.pi)
    wi, wo = half_diff_to_directions(th, np.full_like(th, math.radians(5.0)),
                                     np.full_like(th, 0.5 * math.pi))
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    wo /= np.linalg.norm(wo, axis=1, keepdims=True)
    f = np.asarray(target.eval(wi, wo)).reshape(90, -1).mean(axis=1)
    f = np.nan_to_num(f, nan=0.0)
    floor = float(np.min(f))
    peak = float(f[0]) - floor
    if not peak > 0.0:
        return math.pi / 4
    below = np.nonzero(f - floor < 0.5 * peak)[0]
    return float(th[below[0]]) if below.size else math.pi / 4


def _nelder_mead(fun, z0, steps, maxfev, scale, fatol):
    """Nelder–Mead from z0 with an initial simplex of the given steps; the loss is
    divided by *scale* (the loss at the first guess, before any stage: a change below
    FRTOL of it is negligible, also where the loss tends to 0 on exact data). A run that
    reaches *maxfev* is restarted once from its best point with a fresh simplex (the
    standard remedy for a collapsed simplex). Returns (z, value, n_evaluations,
    hit_limit: the restart reached the limit too)."""
    z0 = np.asarray(z0, dtype=np.float64)
    n = z0.size
    nfev = 0
    for _ in range(2):  # a run that hits the limit is restarted once from its best point
        simplex = np.vstack([z0] + [z0 + np.eye(n)[k] * steps[k] for k in range(n)])
        res = minimize(lambda z: fun(z) / scale, z0, method="Nelder-Mead",
                       options={"initial_simplex": simplex, "maxfev": maxfev, "xatol": math.inf,
                                "fatol": fatol, "adaptive": n > 2})
        nfev += int(res.nfev)
        if res.nfev < maxfev:
            break
        z0 = res.x
    return res.x, float(res.fun) * scale, nfev, res.nfev >= maxfev


def _free_coords(model, fixed, C):
    """(coords of every free scalar, names held, the values to start from)."""
    values = model.values
    coords = []
    for p in model.params:
        v = values[p.name]
        if p.kind == "choice" or p.name in fixed or (p.optional and v is None):
            continue
        if p.kind == "colour":
            arr = np.broadcast_to(np.atleast_1d(np.asarray(v, dtype=np.float64)), (C,)).copy()
            values[p.name] = arr if C > 1 else float(arr[0])
            coords += [Coord.for_param(p, c if C > 1 else None) for c in range(C)]
        elif p.kind == "lobes":
            arr = np.broadcast_to(np.atleast_1d(np.asarray(v, dtype=np.float64)),
                                  (model.n_lobes(),)).copy()
            values[p.name] = arr
            coords += [Coord.for_param(p, k) for k in range(arr.size)]
        else:
            coords.append(Coord.for_param(p))
    values.update(fixed)
    return coords, values


# --------------------------------------------------------------------------- fit
def fit(model: BRDF, target: BRDF, *, loss: str = "l1", procedure: str = "auto",
        fixed: dict | None = None, theta_max: float | None = None, seed: int = 0,
        n_starts: int = 3, strides=DEFAULT_STRIDES, max_evals: int = 200,
        progress=None) -> FitResult:
    """Fit *model*'s parameters to *target* (see the module docstring).

    Parameters
    ----------
    model : BRDF
        The model to fit (a registered model, a pumped one); its current values are
        the defaults of the parameters not otherwise set.
    target : BRDF
        What to fit: ``brdfkit.data.material(spec)``, a MeasuredBRDF, any model.
    loss : {"l1", "l2", "ngan", "log", "perceptual"}
        The loss minimised (:mod:`brdfkit.fitting.losses`; weights stated there).
    procedure : {"auto", "staged", "nielsen", "direct"}
    fixed : dict, optional
        Parameters held at the given values (validated by the model).
    theta_max : float, optional
        Keep only pairs with θ_i, θ_o ≤ theta_max (radians); e.g. ``math.radians(80)``.
    seed : int
        Seed of the random starts (the result is reproducible with it).
    n_starts : int
        Runs of stage (ii): guess, defaults, then n_starts − 2 random ones (≥ 1).
    strides : (int, int)
        Subsampling of the MERL grid (:func:`~brdfkit.fitting.samples.merl_samples`).
    max_evals : int
        Nelder–Mead evaluations per run of a stage (per free coordinate: × its count,
        at least this).
    progress : callable, optional
        ``progress(stage, evaluations, loss)`` after each finished stage (the explorer's
        and the CLI's progress display); it does not change the fit.

    Raises
    ------
    ParameterError
        Unknown loss or procedure, bad fixed values, n_starts < 1, non-model inputs.
    """
    if not isinstance(model, BRDF):
        raise ParameterError(f"fit: model must be a brdfkit model; got {type(model).__name__}")
    if not isinstance(target, BRDF):
        raise ParameterError(f"fit: target must be a brdfkit model or material (e.g. "
                             f"brdfkit.data.material('merl:nickel')); got "
                             f"{type(target).__name__}")
    if loss not in LOSSES:
        raise ParameterError(f"fit: loss must be one of {', '.join(LOSSES)}; got {loss!r}")
    if procedure not in PROCEDURES:
        raise ParameterError(f"fit: procedure must be one of {', '.join(PROCEDURES)}; got "
                             f"{procedure!r}")
    if not (isinstance(n_starts, int | np.integer) and n_starts >= 1):
        raise ParameterError(f"fit: n_starts must be an integer >= 1; got {n_starts!r}")
    fixed = dict(fixed or {})
    if fixed:
        model = model.with_params(**fixed)  # validates names and values
        fixed = {k: model.values[k] for k in fixed}
    threads = numba.get_num_threads()
    numba.set_num_threads(1)  # see the module docstring
    try:
        return _fit(model, target, loss, "staged" if procedure == "auto" else procedure,
                    fixed, theta_max, seed, n_starts, strides, max_evals, progress)
    finally:
        numba.set_num_threads(threads)


def _fit(model, target, loss, procedure, fixed, theta_max, seed, n_starts, strides,
         max_evals, progress=None) -> FitResult:
    t_start = time.perf_counter()
    rng = np.random.default_rng(seed)
    C = int(target.n_channels or 1)
    prob = Problem(model, target, merl_samples(strides=strides, theta_max=theta_max), loss, C)
    coords, values = _free_coords(model, fixed, C)
    record = {"procedure": procedure, "loss": loss, "seed": seed,
              "n_samples": len(prob.samples), "stages": [], "starts": []}
    # a one-times pumped model is evaluated through its surrogate (tables per shape
    # parameter, linear parameters combined: brdfkit.pumping.surrogate) until _result,
    # which evaluates the exact model
    fast = surrogate(model, [c.name for c in coords])
    if fast is not None:
        prob.model = fast

    # data-driven first guess: the lobe width from the measured peak
    beta = _measured_half_width(target)
    record["measured_half_width_deg"] = math.degrees(beta)
    wp = model.width_param
    if wp is not None and wp not in fixed and any(c.name == wp for c in coords):
        # a pumped model's width parameter is its root's (the lobe keeps its shape)
        root = model.root if isinstance(model, PumpedBRDF) else model
        # β clamped to (0, π/2) open, as width_from_beta requires: 1e-4 rad is a
        # mirror-like lobe, 1.4 rad (80°) a broad one
        w0 = float(root.width_from_beta(min(max(beta, 1e-4), 1.4)))
        values[wp] = np.full(np.shape(values[wp]), w0) if np.ndim(values[wp]) else w0

    # parameters that change nothing are held (and reported)
    inert = _inert(prob, coords, values)
    coords = [c for c in coords if c.name not in inert]
    record["inert"] = sorted(inert)

    # linear colour parameters (variable projection)
    linear = []
    if procedure != "direct":
        cand = [(p.name, min(1.0, p.upper)) for p in model.params
                if p.kind == "colour" and any(c.name == p.name for c in coords)]
        if cand and prob.is_affine(values, cand, rng):
            linear = cand
    lin_names = [n for n, _ in linear]
    record["linear"] = lin_names
    decl = {p.name: p for p in model.params}
    lo = np.array([decl[n].lower for n in lin_names])
    hi = np.array([decl[n].upper for n in lin_names])
    shape = [c for c in coords if c.name not in lin_names]
    if linear and shape:
        steps = np.array([c.step(_val(values, c)) for c in shape])
        prob.find_static(values, linear, from_vector(as_vector(values, shape) + steps, shape,
                                                     values))
    record["static_bases"] = sorted(k or "f0" for k in prob.static)

    def set_linear(vals, P):
        out = dict(vals)
        for k, n in enumerate(lin_names):
            out[n] = P[k].copy() if C > 1 else float(P[k, 0])
        return out

    def solve_at(vals, want_loss=False):
        got = prob.bases(vals, linear)
        if got is None:
            return (None, math.inf) if want_loss else None
        f0, B = got
        P = prob.solve_linear(f0, B, lo, hi, loss)
        out = set_linear(vals, P)
        if not want_loss:
            return out
        if loss == "perceptual":  # needs the model's albedo: evaluate it
            return out, prob.loss_at(out)
        # the model is affine in the linear parameters: its values from the bases
        pred = f0 + sum(Bk * P[k][None, :] for k, Bk in enumerate(B))
        return out, prob.loss_of(None, pred)

    def stage_record(name, params, n0, before, after, limit):
        record["stages"].append({"stage": name, "parameters": params,
                                 "evaluations": prob.n_evals - n0, "loss_before": before,
                                 "loss_after": after, "hit_limit": bool(limit)})
        if progress is not None:
            progress(name, prob.n_evals, after)

    hit_limit = False
    scale = prob.loss_at(values)
    if not (math.isfinite(scale) and scale > 0.0):
        scale = 1.0  # a target the first guess already matches exactly, or a refused guess
    # ---------------------------------------------------------------- stage (i)
    if linear:
        n0 = prob.n_evals
        before = prob.loss_at(values)
        solved = solve_at(values)
        if solved is not None:
            values = solved
        stage_record("i: linear (closed form)", lin_names, n0, before, prob.loss_at(values),
                     False)

    # a pumped model: its root fitted first (fast: linear parameters in closed form), the
    # root's optimum the start of the pumped model's joint stage (iii); rebuilding a pumped
    # model tabulates its albedo (~0.15 s), too slow for stage (ii)'s multi-start
    pumped_start = isinstance(model, PumpedBRDF) and procedure != "direct" and not linear
    if pumped_start:
        n0 = prob.n_evals
        before = prob.loss_at(values)
        root_fit = _fit(model.root.with_params(**{k: v for k, v in values.items()
                                                  if k in model.root.values}),
                        target, loss, procedure, fixed, theta_max, seed, n_starts, strides,
                        max_evals)
        start = {**values, **{k: (np.asarray(v, dtype=np.float64) if isinstance(v, list)
                                  else v) for k, v in root_fit.params.items()}}
        after = prob.loss_at(start)
        if after <= before:
            values = start
        # g1 pumping does not see a common scale of the linear parameters: held per channel
        held = hold_scale(prob, values, coords, [p.name for p in model.params
                                                 if p.kind == "colour"])
        if held:
            coords = [c for c in coords if c.label not in held]
            record["scale_held"] = held
        record["root_fit"] = {"convergence": root_fit.convergence, "value": root_fit.value}
        stage_record("ii: the unpumped root model (its own staged fit)",
                     [c.label for c in coords], n0, before, min(before, after), False)
        if fast is not None and coords:
            # evaluations are cheap through the surrogate: one run with stage (ii)'s full
            # steps before stage (iii)'s polish (which starts far from its optimum when the
            # root's optimum was rejected above)
            n0 = prob.n_evals
            before = prob.loss_at(values)
            z, val, _, limit = _nelder_mead(
                lambda z: prob.loss_at(from_vector(z, coords, values)), as_vector(values, coords),
                np.array([c.step(_val(values, c)) for c in coords]),
                max(max_evals, 60 * len(coords)), scale, FRTOL)
            if val <= before:
                values = from_vector(z, coords, values)
            hit_limit |= limit
            stage_record("ii: all (pumped, full steps)", [c.label for c in coords], n0, before,
                         min(val, before), limit)

    # ---------------------------------------------------------------- stage (ii)
    if procedure != "direct" and shape and not pumped_start:
        n0 = prob.n_evals
        before = prob.loss_at(values)
        budget = max(max_evals, 60 * len(shape))
        steps = np.array([c.step(_val(values, c)) for c in shape])
        starts = [("guess", as_vector(values, shape))]
        defaults = dict(values)
        for p in model.params:
            if p.name in {c.name for c in shape}:
                defaults[p.name] = (np.broadcast_to(np.asarray(p.default, float),
                                                    np.shape(values[p.name])).copy()
                                    if np.ndim(values[p.name]) else float(p.default))
        if n_starts >= 2:
            starts.append(("defaults", as_vector(defaults, shape)))
        for k in range(n_starts - 2):
            starts.append((f"random {k + 1}", starts[0][1] + rng.normal(0.0, 1.0, len(shape))))
        best = None
        agree = 0
        for label, z0 in starts[:n_starts]:
            if agree >= 1:
                # two runs from different starts reached the same loss (within CONSENSUS):
                # the remaining starts are recorded as skipped
                record["starts"].append({"start": label, "skipped": "consensus"})
                continue
            if procedure == "staged" and linear:
                def obj(z):
                    return solve_at(from_vector(z, shape, values), want_loss=True)[1]
            else:
                def obj(z):
                    return prob.loss_at(from_vector(z, shape, values))
            z, val, nfev, limit = _nelder_mead(obj, z0, steps, budget, scale, FRTOL)
            end = from_vector(z, shape, values)
            if procedure == "staged" and linear:
                end = solve_at(end) or end
            record["starts"].append({"start": label, "from": _jsonable(from_vector(
                z0, shape, values), coords), "to": _jsonable(end, coords), "loss": val,
                "evaluations": nfev, "hit_limit": bool(limit)})
            if best is not None and abs(val - best[0]) <= CONSENSUS * abs(best[0]):
                agree += 1
            if best is None or val < best[0]:
                best = (val, end, limit)
        values = best[1]
        hit_limit |= best[2]
        stage_record("ii: shape" + (" (linear re-solved)" if procedure == "staged" and linear
                                    else ""), [c.label for c in shape], n0, before, best[0],
                     best[2])

    # ---------------------------------------------------------------- stage (iii)
    if procedure == "nielsen" and linear:
        # the linear parameters whose basis depends on the shape (k_s, not rho_d)
        moving = _shape_dependent(prob, linear)
        free3 = shape + [c for c in coords if c.name in moving]
    else:
        free3 = coords
    if free3:
        n0 = prob.n_evals
        before = prob.loss_at(values)
        # a tenth of stage (ii)'s steps: stage (iii) starts near a stationary point
        steps = 0.1 * np.array([c.step(_val(values, c)) for c in free3])
        z, val, _, limit = _nelder_mead(lambda z: prob.loss_at(from_vector(z, free3, values)),
                                        as_vector(values, free3), steps,
                                        max(max_evals, 40 * len(free3)), scale, FRTOL_POLISH)
        if val <= before:
            values = from_vector(z, free3, values)
        hit_limit |= limit
        stage_record("iii: " + ("shape and shape-dependent linear" if procedure == "nielsen"
                                else "all"), [c.label for c in free3], n0, before,
                     min(val, before), limit)
    if fast is not None:
        record["surrogate"] = {"linear": list(fast.linear), "shape": list(fast.shape),
                               "loss": prob.loss_at(values), "tables_built": fast.n_tables,
                               "table_time_s": fast.table_time_s}
        prob.model = model  # the result: the exact pumped model
    return _result(prob, target, values, coords, record, hit_limit, t_start)


def _val(values, c):
    v = values[c.name]
    return float(v if c.index is None else np.asarray(v)[c.index])


def _jsonable(values, coords) -> dict:
    names = {c.name for c in coords}
    return {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in values.items()
            if k in names}


def _inert(prob, coords, values) -> set:
    """Names of parameters that change no sample value when moved by five z-steps, or
    that the model refuses to move alone."""
    _, base = prob.predict(values)
    out = set()
    for name in dict.fromkeys(c.name for c in coords):
        cs = [c for c in coords if c.name == name]
        z = as_vector(values, cs)
        steps = np.array([c.step(_val(values, c)) for c in cs])
        _, moved = prob.predict(from_vector(z + 5.0 * steps, cs, values))
        # held: no effect, or refused when moved alone (e.g. an extinction coefficient k
        # without an index eta: the model's own cross-parameter check)
        if moved is None or (base is not None and np.array_equal(base, moved)):
            out.add(name)
    return out


def _shape_dependent(prob, linear) -> set:
    """Linear parameters whose basis changes with the shape parameters (not static)."""
    return {n for n, _ in linear if n not in prob.static}


def _result(prob, target, values, coords, record, hit_limit, t_start) -> FitResult:
    m, pred = prob.predict(values)
    if m is None:  # unreachable: stage values come from evaluated, accepted models
        raise BrdfkitError("fit: the fitted parameters were refused by the model")
    metrics = {}
    for name in ("l1", "l2", "ngan", "log", "perceptual"):
        if name == "perceptual" and prob.albedo_t is None:
            p2 = Problem(prob.model, target, prob.samples, "perceptual", prob.C)
            metrics[name] = p2.loss_of(m, pred)
        else:
            metrics[name] = prob.loss_of(m, pred, name)
    wi, wo, wa, T = albedo_nodes(ALBEDO_THETA_DEG)
    a_m = albedo_from_values(prob._values(m, wi, wo), wa, T)
    a_t = albedo_from_values(prob._values(target, wi, wo), wa, T)
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(a_t > 0.0, (a_m - a_t) / a_t, np.nan)
    at_bounds = []
    for c in coords:
        side = c.at_bound(_val(values, c))
        if side:
            at_bounds.append({"parameter": c.label, "bound": side,
                              "value": c.lower if side == "lower" else c.upper})
    record.update(evaluations=prob.n_evals, refused=prob.n_invalid,
                  time_s=time.perf_counter() - t_start, at_bounds=at_bounds)
    if not np.all(np.isfinite(pred)) or not math.isfinite(metrics[prob.loss]):
        status = 3
    elif hit_limit:
        status = 2
    elif at_bounds:
        status = 1
    else:
        status = 0
    msg = STATUS_MESSAGES[status]
    if at_bounds:
        msg += " (" + ", ".join(f"{b['parameter']} at its {b['bound']} bound {b['value']:g}"
                                for b in at_bounds) + ")"
    d = m.to_dict()
    return FitResult(model=m, params=d["params"], loss=prob.loss, value=metrics[prob.loss],
                     metrics=metrics, theta_deg=np.asarray(ALBEDO_THETA_DEG), albedo_model=a_m,
                     albedo_target=a_t, albedo_rel_error=rel, convergence=record,
                     status=status, success=status != 3, message=msg)
