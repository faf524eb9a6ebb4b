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
numerically for each candidate and then jointly — so a non-linear colour
parameter such as η does not stop ρ_d, k_s from being linear; see
:mod:`brdfkit.fitting._problem`) are solved in closed form; the others
("shape") are optimised over bounded reparametrisations
(:mod:`brdfkit.fitting._space`) with Nelder–Mead.

Stages of ``procedure="staged"`` (= ``"auto"``, any model):

(i) first guess and linear parameters: the width parameter (the model's
    ``width_param``) from the measured peak's half-width β (via
    ``width_from_beta``) and from the ladder β = 0.5°, 1°, …, 64°
    (:data:`~brdfkit.fitting._guess.BETA_LADDER_DEG`), each with the linear
    parameters solved; the width of least loss is kept (a measured peak alone can mislead: the clear
    coat of two-layer-silver gives β → 0, s ≈ 10⁶, a local optimum on the
    spike far from the broad lobe); the linear parameters solved there.
(ii) search over the shape parameters on a coarser grid
    (:data:`SEARCH_STRIDES`: ~2,700 samples, every θ_h and θ_d cell kept) with the
    linear ones re-solved at every evaluation (variable projection), from
    several starts: the guess; with free optional parameters (η), the same
    model without them fitted first (recursively) and its optimum with those
    parameters where they change the model least (the z of
    :data:`NEUTRAL_Z` of least loss; for η: η → 0, F = 1 under total internal
    reflection) — so a free optional parameter never makes the fit worse;
    for a parameter whose bounds are sub-models (``BRDF.fit_bound_starts``:
    Nielsen's α, 0 Phong-like, 1 Blinn-like) two starts near its bounds
    (:data:`BOUND_START_Z`), which always run — under ``procedure="nielsen"``
    the two sub-models at the bounds fitted first instead, their optima taken
    as they are, so that the α-mix is never worse than either end; the declared defaults (an
    optional parameter declared None keeps its value); ``n_starts − 2``
    random ones (z of the guess plus N(0, 1), from
    ``numpy.random.default_rng(seed)``) — ``n_starts`` starts in all besides the
    nested one, the bound starts first after the guess. Every run is
    recorded; once two runs reach the same loss (relative difference ≤
    :data:`CONSENSUS`) the remaining starts (but bound starts) are recorded
    as skipped. ``procedure="nielsen"`` compares the runs with their linear
    parameters re-solved.
(iii) polish on the fit's own samples from the best run: for l1, l2 and ngan
    the shape with the linear parameters re-solved — variable projection is
    exact for them (min over (shape, linear) = min over shape of the loss with
    the linear part solved), so this is the joint optimum, the final L1 solve
    run to convergence (:data:`IRLS_FINAL` steps); for log and perceptual
    (linear part solved under L2) all free parameters jointly under the loss.

``procedure="nielsen"`` (Nielsen et al. 2015, "Fitting Results and
Observations"): (i) as above (ρ_d and k_s); (ii) the shape parameters (s, α
and η) with the linear ones solved at each start and then held; (iii) the
shape parameters with the linear parameters whose basis depends on the shape
(k_s, not ρ_d: as the paper's stage (iii) frees s, α, k_s), jointly under
the loss. ``"direct"``: all free parameters jointly from the first guess (one
stage, no linear solve: the plain approach, for comparison).

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

Stopping and status: a Nelder–Mead run stops when its vertices' losses agree
to :data:`FRTOL` of the loss after stage (i), or after
:data:`~brdfkit.fitting._simplex.STALL_EVALS` evaluations per coordinate without
such an improvement (a flat valley, or a bound approached asymptotically in z);
its stop is checked by one restart from the best point. The status is set by
the last stage: MAX_EVALS when it reached its budget (a stage-(ii) search cut
by its budget and then polished to the tolerance is recorded but converged).
A polish cut by its budget is run once more (stage "iii'") with the
coordinates at (or indistinguishable from) a bound set there and held: it
converges where the crawl was towards a bound approached only asymptotically
in z; with none at a bound, once more with the search's (ten times larger)
steps, which travels along a long valley where the polish's small simplex
crawled. Bounds are checked after the last stage: a coordinate at a bound, or
one the loss cannot tell from a bound (moved there the loss rises by less than
:data:`BOUND_LOSS_RTOL` relative; the bound is taken if the loss falls), is
reported (``at_bounds``, status AT_BOUND, named in the message) — never a
plain "converged". Every stage record lists the coordinates at a bound after
it.

The fit evaluates on one thread (``models._drivers.numba_threads(1)``, restored
after): for ~15,000 pairs the parallel driver's thread wake-ups cost more
than the work on a shared 2-core machine (measured: 16 ms vs 0.3 ms).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from brdfkit.errors import BrdfkitError, ParameterError
from brdfkit.fitting import _guess
from brdfkit.fitting._problem import IRLS_ITERATIONS, Problem
from brdfkit.fitting._pumped import hold_scale
from brdfkit.fitting._simplex import search_simplex
from brdfkit.fitting._space import Z_MAX, Coord, as_vector, from_vector
from brdfkit.fitting.losses import LOSSES
from brdfkit.fitting.samples import (
    ALBEDO_THETA_DEG,
    DEFAULT_STRIDES,
    albedo_from_values,
    albedo_nodes,
    merl_samples,
)
from brdfkit.models import BRDF
from brdfkit.models._drivers import numba_threads
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
#: the loss after stage (i): FRTOL in the stage-(ii) search (the polish follows; the same
#: order as CONSENSUS), FRTOL_POLISH in stage (iii). A criterion on the loss only: along
#: flat directions (e.g. Lafortune's common scale of C_xy, C_z against rho_s) there is no
#: parameter tolerance to reach.
FRTOL, FRTOL_POLISH = 1e-4, 1e-5
#: Losses whose linear solve is exact (the L1 one by IRLS to convergence at the end).
EXACT_PROJECTION = ("l1", "l2", "ngan")
#: IRLS steps of the final L1 linear solve (the search's solves take IRLS_ITERATIONS,
#: warm-started).
IRLS_FINAL = 50
#: Two stage-(ii) runs whose losses agree to this relative difference are one optimum.
CONSENSUS = 1e-3
#: Least evaluation budget of a polish (else 100 per coordinate; it stops at convergence):
#: 200 was too few for Lafortune's (C_xy, n) on six MERL materials (light-red-paint: 406).
POLISH_MIN_EVALS = 600
_polish = lambda max_evals, free: max(max_evals, 100 * len(free), POLISH_MIN_EVALS)  # noqa: E731
#: Stage (ii) searches on this coarser merging of MERL bins (θ_d, φ_d): every θ_h bin and
#: the default's 10 θ_d cells kept (a Fresnel factor depends on θ_d; with 6 θ_d cells the
#: search misjudged red-fabric2's η fit), 4 φ_d cells instead of 12: 2,676 samples instead
#: of 8,134; stage (iii) polishes on the fit's own samples. The time per evaluation is then
#: mostly fixed costs (model set-up, linear solves), so coarser cells gain little.
SEARCH_STRIDES = (9, 45)
#: z of the optional parameters (e.g. η) tried at the nested model's optimum: the one
#: where the loss is least (where the parameter changes the model least) starts stage (ii).
NEUTRAL_Z = (-Z_MAX, -6.0, -2.0, 0.0, 2.0, 6.0, Z_MAX)
#: z (logit) of the starts near the bounds of BRDF.fit_bound_starts parameters: 1.8 % of
#: the range from the bound, where the logit's initial step (~2.8 in z) can still leave it.
BOUND_START_Z = 4.0
#: A coordinate whose move to its bound changes the final loss by less than this relative
#: amount is reported at that bound (the data cannot tell it from the bound).
BOUND_LOSS_RTOL = 1e-4


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
    with numba_threads(1):  # see the module docstring
        return _fit(model, target, loss, "staged" if procedure == "auto" else procedure,
                    fixed, theta_max, seed, n_starts, strides, max_evals, progress)


def _fit(model, target, loss, procedure, fixed, theta_max, seed, n_starts, strides,
         max_evals, progress=None) -> FitResult:
    t_start = time.perf_counter()
    rng = np.random.default_rng(seed)
    C = int(target.n_channels or 1)
    prob = Problem(model, target, merl_samples(strides=strides, theta_max=theta_max), loss, C)
    # stage (ii)'s search on a coarser grid (every θ_h bin kept); never finer than the fit's
    coarse = tuple(max(int(a), b) for a, b in zip(strides, SEARCH_STRIDES, strict=True))
    sp = (prob if coarse == tuple(int(a) for a in strides)
          else Problem(model, target, merl_samples(strides=coarse, theta_max=theta_max), loss, C))
    coords, values = _free_coords(model, fixed, C)
    record = {"procedure": procedure, "loss": loss, "seed": seed,
              "n_samples": len(prob.samples), "n_samples_search": len(sp.samples),
              "stages": [], "starts": []}
    # a gauge freedom of the model (BRDF.fit_gauge) is held at its given value, unless
    # that value is 0 (there the other coordinates no longer absorb it)
    gauge = [c for c in coords if c.label in model.fit_gauge and _val(values, c) != 0.0]
    if gauge:
        coords = [c for c in coords if c not in gauge]
        record["gauge_held"] = {c.label: _val(values, c) for c in gauge}
    # a one-times pumped model is evaluated through its surrogate (tables per shape
    # parameter, linear parameters combined: brdfkit.pumping.surrogate) until _result,
    # which evaluates the exact model
    fast = surrogate(model, [c.name for c in coords])
    if fast is not None:
        prob.model = fast
        sp.model = fast

    def n_evals():
        return prob.n_evals + (sp.n_evals if sp is not prob else 0)

    # data-driven first guess: the lobe width from the measured peak (refined below by a
    # scan of widths once the linear parameters are known)
    beta = _guess.measured_half_width(target)
    record["measured_half_width_deg"] = math.degrees(beta)
    wp = model.width_param
    scan_width = wp is not None and wp not in fixed and any(c.name == wp for c in coords)
    # a pumped model's width parameter is its root's (the lobe keeps its shape)
    width_from_beta = (model.root if isinstance(model, PumpedBRDF) else model).width_from_beta
    if scan_width:
        values = _guess.with_width(values, wp, width_from_beta, beta)

    # parameters that change nothing are held (and reported); tested on the search's
    # samples (every θ_h bin), as the linearity below: properties of the model, not of
    # the sample density, and a third of the cost
    inert = _inert(sp, coords, values)
    coords = [c for c in coords if c.name not in inert]
    record["inert"] = sorted(inert)

    # linear colour parameters (variable projection): each candidate tested alone, then the
    # affine ones jointly (a colour parameter the model is not affine in, e.g. η, is a
    # shape parameter and does not stop ρ_d, k_s from being solved in closed form)
    linear = []
    if procedure != "direct":
        cand = [(p.name, min(1.0, p.upper)) for p in model.params
                if p.kind == "colour" and any(c.name == p.name for c in coords)]
        # jointly first (affine jointly implies affine in each alone): one test, not K + 1
        if len(cand) > 1 and sp.is_affine(values, cand, rng):
            linear = cand
        else:
            cand = [c for c in cand if sp.is_affine(values, [c], rng)]
            if len(cand) == 1 or (cand and sp.is_affine(values, cand, rng)):
                linear = cand
    lin_names = [n for n, _ in linear]
    record["linear"] = lin_names
    decl = {p.name: p for p in model.params}
    lo = np.array([decl[n].lower for n in lin_names])
    hi = np.array([decl[n].upper for n in lin_names])
    shape = [c for c in coords if c.name not in lin_names]
    if linear and shape:
        steps = np.array([c.step(_val(values, c)) for c in shape])
        moved = from_vector(as_vector(values, shape) + steps, shape, values)
        for p in {id(prob): prob, id(sp): sp}.values():
            p.find_static(values, linear, moved)
    record["static_bases"] = sorted(k or "f0" for k in prob.static)

    def solve_at(p, vals, want_loss=False, iterations=IRLS_ITERATIONS):
        """*vals* with the linear parameters solved on problem *p* (and its loss)."""
        got = p.bases(vals, linear) if linear else None
        if got is None:
            return (None, math.inf) if want_loss else None
        f0, B = got
        P, value = p.solve_linear(f0, B, lo, hi, loss, iterations=iterations)
        out = dict(vals)
        for k, n in enumerate(lin_names):
            out[n] = P[k].copy() if C > 1 else float(P[k, 0])
        if not want_loss:
            return out
        if value is not None:  # l1, l2: computed with the solve
            return out, value
        if loss == "perceptual":  # needs the model's albedo: evaluate it
            return out, p.loss_at(out)
        # the model is affine in the linear parameters: its values from the bases
        pred = f0.copy()
        for k, Bk in enumerate(B):
            pred += Bk * P[k][None, :]
        return out, p.loss_of(None, pred)

    def search(p, free, v0, projecting, budget, steps, fatol):
        """Minimise over the coordinates *free* from *v0* on problem *p*, the linear
        parameters solved at every point (*projecting*) or held, by Nelder–Mead.
        Returns (values, loss, evaluations, hit_limit)."""
        def obj(z):
            v = from_vector(z, free, v0)
            return projected(p, v) if projecting else p.loss_at(v)
        z, val, nfev, limit = search_simplex(obj, as_vector(v0, free), steps, budget, scale,
                                           fatol)
        end = from_vector(z, free, v0)
        if projecting:
            end = solve_at(p, end) or end
        return end, val, nfev, limit

    def projected(p, vals):
        """Loss on *p* with the linear parameters solved (variable projection)."""
        return solve_at(p, vals, want_loss=True)[1] if linear else p.loss_at(vals)

    def stage_record(name, params, n0, before, after, limit, vals):
        record["stages"].append({"stage": name, "parameters": params,
                                 "evaluations": n_evals() - n0, "loss_before": before,
                                 "loss_after": after, "hit_limit": bool(limit),
                                 "at_bounds": [c.label for c in coords
                                               if c.at_bound(_val(vals, c))]})
        if progress is not None:
            progress(name, n_evals(), after)

    hit_limit = False
    best = None  # stage (ii)'s best run: (loss, values, hit_limit, start label)
    # ---------------------------------------------------------------- stage (i)
    if linear:
        n0 = n_evals()
        before = prob.loss_at(values)
        if scan_width:  # the width whose projected loss is least (module docstring)
            values, record["width_scan"] = _guess.scan_width(
                values, wp, width_from_beta, beta, lambda v: projected(sp, v))
        solved = solve_at(prob, values)
        if solved is not None:
            values = solved
        stage_record("i: linear (closed form)" + (", width scanned" if scan_width else ""),
                     lin_names, n0, before, prob.loss_at(values), False, values)

    # the loss scale of the stopping rule: the loss after stage (i), near the optimum's
    scale = prob.loss_at(values)
    if not (math.isfinite(scale) and scale > 0.0):
        scale = 1.0  # a target the first guess already matches exactly, or a refused guess

    # a pumped model: its root fitted first (fast: linear parameters in closed form), the
    # root's optimum the start of the pumped model's joint stage (iii); rebuilding a pumped
    # model tabulates its albedo (~0.15 s), too slow for stage (ii)'s multi-start
    pumped_start = isinstance(model, PumpedBRDF) and procedure != "direct" and not linear
    if pumped_start:
        n0 = n_evals()
        before = prob.loss_at(values)
        root_fit = _fit(model.root.with_params(**{k: v for k, v in values.items()
                                                  if k in model.root.values}),
                        target, loss, procedure, fixed, theta_max, seed, n_starts, strides,
                        max_evals)
        start = {**values, **root_fit.model.values}
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
                     [c.label for c in coords], n0, before, min(before, after), False, values)
        if fast is not None and coords:
            # evaluations are cheap through the surrogate: one run with stage (ii)'s full
            # steps before stage (iii)'s polish (which starts far from its optimum when the
            # root's optimum was rejected above)
            n0 = n_evals()
            before = prob.loss_at(values)
            z, val, _, limit = search_simplex(
                lambda z: prob.loss_at(from_vector(z, coords, values)), as_vector(values, coords),
                np.array([c.step(_val(values, c)) for c in coords]),
                max(max_evals, 60 * len(coords)), scale, FRTOL)
            if val <= before:
                values = from_vector(z, coords, values)
            hit_limit |= limit
            stage_record("ii: all (pumped, full steps)", [c.label for c in coords], n0, before,
                         min(val, before), limit, values)

    # ---------------------------------------------------------------- stage (ii)
    if procedure != "direct" and shape and not pumped_start:
        n0 = n_evals()
        before = prob.loss_at(values)
        budget = max(max_evals, 100 * len(shape))
        steps = np.array([c.step(_val(values, c)) for c in shape])
        shape_names = {c.name for c in shape}
        defaults = dict(values)
        for p in model.params:
            # an optional parameter declared None (e.g. η: no Fresnel) keeps its value
            if p.name in shape_names and p.default is not None:
                defaults[p.name] = (np.broadcast_to(np.asarray(p.default, float),
                                                    np.shape(values[p.name])).copy()
                                    if np.ndim(values[p.name]) else float(p.default))
        starts = [("guess", values)]
        # the same model without its optional parameters (e.g. η: F = 1) fitted first, its
        # optimum a start with those parameters where they change least: a free optional
        # parameter never makes the fit worse than leaving it out (nested models)
        nested = [p.name for p in model.params if p.optional and p.name in shape_names]
        if nested:
            inner = _fit(model.with_params(**{n: None for n in nested}), target, loss,
                         procedure, {k: v for k, v in fixed.items() if k not in nested},
                         theta_max, seed, n_starts, strides, max_evals)
            record["nested"] = {"without": nested, "value": inner.value,
                                "status": inner.status, "params": inner.params,
                                "evaluations": inner.convergence["evaluations"]}
            start = {**values, **{k: v for k, v in inner.model.values.items()
                                  if k not in nested}}
            opt = [c for c in shape if c.name in nested]
            best_z = min(NEUTRAL_Z, key=lambda zz: projected(
                sp, from_vector(np.full(len(opt), zz), opt, start)))
            starts.append(("nested: without " + ", ".join(nested),
                           from_vector(np.full(len(opt), best_z), opt, start)))
        # a parameter whose bounds are sub-models (BRDF.fit_bound_starts: Nielsen's α, 0
        # Phong, 1 Blinn–Phong) is started near each bound, always (not skipped by
        # consensus), in place of the defaults and random starts: a run from the middle can
        # settle in one end's basin while the other end fits better (20 of 100 MERL
        # materials), and the defaults are one arbitrary point where these are two
        # structured ones
        # Under procedure="nielsen" (the paper compares the α-mix with its two ends) each
        # end is fitted first instead, and its optimum, the parameter at the bound, is a
        # candidate as it is (no search from it): the mix is then never worse than either
        # end (it was on 6 of 100 materials with the starts near the bounds alone)
        bound_starts, prefit = [], {}
        for c in shape:
            if c.name not in model.fit_bound_starts or c.transform != "logit":
                continue
            for side, z in (("lower", -BOUND_START_Z), ("upper", BOUND_START_Z)):
                if procedure != "nielsen" or c.index is not None:
                    bound_starts.append((f"{c.label} near its {side} bound",
                                         from_vector([z], [c], values)))
                    continue
                x = c.lower if side == "lower" else c.upper
                end_fit = _fit(model.with_params(**{c.name: x}), target, loss, procedure,
                               {**fixed, c.name: x}, theta_max, seed, n_starts, strides,
                               max_evals)
                label = f"{c.label} = {x:g} fitted first"
                record.setdefault("bound_fits", {})[label] = {
                    "value": end_fit.value, "status": end_fit.status,
                    "evaluations": end_fit.convergence["evaluations"]}
                bound_starts.append((label, from_vector([np.sign(z) * Z_MAX], [c],
                                                        {**values, **end_fit.model.values})))
                prefit[label] = (c, np.sign(z) * BOUND_START_Z)
        starts += bound_starts
        if n_starts >= 2:
            starts.append(("defaults", defaults))
        z_guess = as_vector(values, shape)
        for k in range(n_starts - 2):
            starts.append((f"random {k + 1}", from_vector(
                z_guess + rng.normal(0.0, 1.0, len(shape)), shape, values)))
        starts = starts[:(max(n_starts, 1 + len(bound_starts)) if n_starts > 1 else 1)
                        + bool(nested)]
        always = {label for label, _ in bound_starts}  # run whatever the consensus
        best = None
        agree = 0
        for label, v0 in starts:
            if agree >= 1 and label not in always:
                # two runs from different starts reached the same loss (within CONSENSUS):
                # the remaining starts are recorded as skipped
                record["starts"].append({"start": label, "skipped": "consensus"})
                continue
            if label in prefit:  # an end fitted first: its optimum as it is
                end, val, nfev, limit = v0, math.nan, 0, False
            else:
                if linear and procedure == "nielsen":
                    # Nielsen's (ii): the linear parameters solved at the start, then held
                    v0 = solve_at(sp, v0) or v0
                end, val, nfev, limit = search(
                    sp, shape, v0, linear and procedure != "nielsen", budget,
                    # near a bound the logit's steps at the guess would hardly move it
                    np.array([c.step(_val(v0, c)) for c in shape]) if label in always
                    else steps, FRTOL)
            # the runs are compared on the fit's own samples with the linear parameters
            # re-solved, as stage (iii) will have them. On the search's grid a sharp lobe
            # can look better than it is (black-obsidian, Nielsen with η: α ≈ 0, s ≈ 2900
            # won at 0.00155 there, 0.00198 on the fit's samples, where α ≈ 0.84 gives
            # 0.00142); with the linear parameters held at the start's solution (nielsen),
            # a run that ended where those happened to fit won (green-fabric: η < 1, twice
            # the loss of the best shape)
            val_search = val
            # (the L1 solve to convergence: warm-started from the previous run's shape, the
            # search's three IRLS steps left an end fitted first at 0.0107 for its 0.00907)
            solved = (solve_at(prob, end, want_loss=True, iterations=IRLS_FINAL) if linear
                      else (end, prob.loss_at(end)))
            if solved[0] is not None:
                end, val = solved
            record["starts"].append({"start": label, "from": _jsonable(v0, coords),
                                     "to": _jsonable(end, coords), "loss": val,
                                     "loss_search": val_search, "evaluations": nfev,
                                     "hit_limit": bool(limit)})
            if best is not None and abs(val - best[0]) <= CONSENSUS * abs(best[0]):
                agree += 1
            if best is None or val < best[0]:
                best = (val, end, limit, label)
        values = best[1]
        hit_limit = best[2]  # superseded by stage (iii)'s: the last stage decides the status
        after = prob.loss_at(values)
        if linear:  # the linear parameters re-solved on the fit's own samples
            solved = solve_at(prob, values, want_loss=True)
            if solved[0] is not None and solved[1] <= after:
                values, after = solved
        stage_record("ii: shape" + (" (linear re-solved)" if procedure != "nielsen" and linear
                                    else "") + f" on {len(sp.samples)} samples",
                     [c.label for c in shape], n0, before, after, best[2], values)

    # ---------------------------------------------------------------- stage (iii)
    if procedure == "nielsen" and linear:
        # the linear parameters whose basis depends on the shape (k_s, not rho_d)
        moving = _shape_dependent(prob, linear)
        free3 = shape + [c for c in coords if c.name in moving]
    else:
        free3 = coords
    # variable projection is exact for l1, l2, ngan: min over (shape, linear) of the loss
    # is min over the shape of the loss with the linear parameters solved, so the staged
    # procedure's joint stage (iii) is the shape polished with them re-solved. Nielsen's
    # (iii) frees (s, α, η, k_s): the same, with ρ_d re-solved too (free in closed form).
    # Solved by a simplex over k_s and η per channel, it reached its budget on 80 of 600
    # study fits; with ρ_d held from stage (ii), the result depended on that path (the
    # α-mix ended 1.5 % worse than Blinn-Phong on green-fabric at the same s, α)
    projected3 = bool(procedure in ("staged", "nielsen") and linear and shape
                      and loss in EXACT_PROJECTION)
    if projected3:
        free3 = shape
    if free3:
        n0 = n_evals()
        before = prob.loss_at(values)
        start3 = values
        if best is not None and best[3] in prefit and any(c is prefit[best[3]][0] for c in free3):
            # an end fitted first won: the polish starts just inside its bound, where the
            # parameter can move (at the bound's z it cannot: the mix would stay the end);
            # its result is kept only if better than the end (val <= before below)
            c_end, z_end = prefit[best[3]]
            start3 = from_vector([z_end], [c_end], values)
        # a tenth of stage (ii)'s steps: stage (iii) starts near a stationary point
        steps = 0.1 * np.array([c.step(_val(start3, c)) for c in free3])
        end, val, _, limit = search(prob, free3, start3, projected3,
                                    _polish(max_evals, free3), steps, FRTOL_POLISH)
        if projected3:  # the final linear solve to convergence (IRLS_FINAL steps for l1)
            end = solve_at(prob, end, iterations=IRLS_FINAL) or end
            val = prob.loss_at(end)
        if val <= before:
            values = end
        # the final stage's stop decides: a stage-(ii) search cut by its budget and then
        # polished here to the tolerance is a converged result (its limit stays recorded)
        hit_limit = limit
        stage_record("iii: " + ("shape, linear re-solved (= all jointly)" if projected3
                                else "shape and shape-dependent linear" if procedure == "nielsen"
                                else "all"), [c.label for c in free3], n0, before,
                     min(val, before), limit, values)
    # linear parameters solved exactly in a box (variable projection to the end) sit at a
    # bound exactly when it is active: the exact test of _result finds them, not this one
    solved = set(lin_names) if projected3 else set()
    values, flat = _flat_to_bound(prob, values, [c for c in coords if c.name not in solved])
    if free3 and hit_limit:
        # the polish was still crawling, typically towards a bound approached only
        # asymptotically in z: the coordinates at (or indistinguishable from) a bound are
        # set there and held, and the polish is run once more over the others. With none
        # held, it is run once more with the search's steps: the polish's tenth-size simplex
        # crawls along a long valley (Lafortune's lobe turning horizontal, C_xy → −∞ with
        # ρ_s → 0, on blue-fabric: 5 % gained in 600 evaluations, still gaining)
        held = [c for c in free3 if c.label in flat or c.at_bound(_val(values, c))]
        rest = [c for c in free3 if c not in held]
        if rest:
            n0 = n_evals()
            before = prob.loss_at(values)
            start = values
            for c in held:
                side = flat[c.label][0] if c.label in flat else c.at_bound(_val(values, c))
                start = from_vector([Z_MAX if side == "upper" else -Z_MAX], [c], start)
            steps = (0.1 if held else 1.0) * np.array([c.step(_val(start, c)) for c in rest])
            end, val, _, limit = search(prob, rest, start, projected3,
                                        _polish(max_evals, rest), steps, FRTOL_POLISH)
            if projected3:
                end = solve_at(prob, end, iterations=IRLS_FINAL) or end
                val = prob.loss_at(end)
            if val <= before:
                values, hit_limit = end, limit
                values, flat = _flat_to_bound(prob, values,
                                              [c for c in coords if c.name not in solved])
            elif not limit:  # stopped by the tolerance without a gain: a converged point
                hit_limit = False
            stage_record("iii': polish " + ("with " + ", ".join(c.label for c in held)
                                            + " held at their bounds" if held
                                            else "again with the search's steps"),
                         [c.label for c in rest], n0, before, min(val, before), limit, values)
    record["evaluations_search"] = sp.n_evals if sp is not prob else 0
    if fast is not None:
        record["surrogate"] = {"linear": list(fast.linear), "shape": list(fast.shape),
                               "loss": prob.loss_at(values), "tables_built": fast.n_tables,
                               "table_time_s": fast.table_time_s}
        prob.model = model  # the result: the exact pumped model
    return _result(prob, target, values, coords, record, hit_limit, t_start, flat, n_evals())


def _flat_to_bound(prob, values, coords):
    """Coordinates the loss cannot tell from a bound: moved to the bound (z = ±Z_MAX)
    the loss rises by at most :data:`BOUND_LOSS_RTOL` relative (or falls: then the bound
    is taken). Returns (values, {label: (side, bound, relative loss change)})."""
    best = prob.loss_at(values)
    flat = {}
    if not math.isfinite(best):
        return values, flat
    for c in coords:
        for side, z in (("lower", -Z_MAX), ("upper", Z_MAX)):
            if c.transform == "identity" or (side == "upper" and math.isinf(c.upper)):
                continue
            if c.at_bound(_val(values, c)) == side:
                continue  # already there (reported by the exact test)
            moved = from_vector([z], [c], values)
            lb = prob.loss_at(moved)
            if lb <= best * (1.0 + BOUND_LOSS_RTOL):
                flat[c.label] = (side, c.to_x(z), (lb - best) / best if best > 0 else 0.0)
                if lb < best:
                    values, best = moved, lb
                break
    return values, flat


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


def _result(prob, target, values, coords, record, hit_limit, t_start, flat,
            evaluations) -> FitResult:
    m, pred = prob.predict(values)
    if m is None:  # unreachable: stage values come from evaluated, accepted models
        raise BrdfkitError("fit: the fitted parameters were refused by the model")
    metrics = {}
    for name in ("l1", "l2", "ngan", "log", "perceptual"):
        if name == "perceptual" and prob.albedo_t is None:
            metrics[name] = prob.perceptual(target).loss_of(m, pred)
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
                              "value": c.lower if side == "lower" else c.upper,
                              "fitted": _val(values, c)})
        elif c.label in flat:  # the loss cannot tell it from its bound (_flat_to_bound)
            side, _, change = flat[c.label]
            at_bounds.append({"parameter": c.label, "bound": side,
                              "value": c.lower if side == "lower" else c.upper,
                              "fitted": _val(values, c), "loss_change_at_bound": change})
    record.update(evaluations=evaluations, refused=prob.n_invalid,
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
        msg += " (" + ", ".join(
            f"{b['parameter']} " + ("at" if "loss_change_at_bound" not in b else
                                    f"= {b['fitted']:.4g}, indistinguishable from")
            + f" its {b['bound']} bound {b['value']:g}" for b in at_bounds) + ")"
    d = m.to_dict()
    return FitResult(model=m, params=d["params"], loss=prob.loss, value=metrics[prob.loss],
                     metrics=metrics, theta_deg=np.asarray(ALBEDO_THETA_DEG), albedo_model=a_m,
                     albedo_target=a_t, albedo_rel_error=rel, convergence=record,
                     status=status, success=status != 3, message=msg)
