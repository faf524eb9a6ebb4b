"""
The result of a fit
===================

:class:`FitResult` (re-exported by :mod:`brdfkit.fitting.procedure`) and
:func:`make_result`, which builds it after the last stage: every metric, the albedos with
their error estimates, the coordinates at a bound, the status.

Status (``brdfkit.status.STATUS["fit"]``): ``nonfinite`` when the fitted model is not
finite on the samples; else ``limit`` when the last stage reached its evaluation budget;
else ``at_bound`` when a coordinate is at (or indistinguishable from) a bound, named in
the message; else ``converged``.

Public objects
--------------
- :class:`FitResult`, :func:`make_result`.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from brdfkit.errors import BrdfkitError
from brdfkit.fitting._records import AtBound, Convergence
from brdfkit.fitting._space import BOUND_LOSS_RTOL
from brdfkit.fitting.losses import REGISTRY
from brdfkit.fitting.samples import ALBEDO_NODES, ALBEDO_THETA_DEG, albedo_nodes, albedo_with_error
from brdfkit.fresnel import fresnel_conductor
from brdfkit.models import BRDF
from brdfkit.status import STATUS

__all__ = ["FitResult", "make_result", "FIT_STATUS", "ALBEDO_FAR_RTOL", "albedo_far"]

#: The status codes of a fit.
FIT_STATUS = STATUS["fit"]
#: A fit whose directional albedo differs from the target's by more than this relative
#: amount at some reported angle (any channel) is flagged in its message: a quarter is far
#: beyond the surrogates' own albedo error (≤ 1.5 % against the curator's 180×360
#: estimates, tests/test_data_surrogates.py) and the reported rule's error estimate, so it
#: is the model's shape, not noise (Nielsen's model on merl:nickel: 0.011 vs 0.17 at 85°).
ALBEDO_FAR_RTOL = 0.25


@dataclass(frozen=True, eq=False)
class FitResult:
    """The outcome of :func:`~brdfkit.fitting.procedure.fit`.

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
        Directional albedos (:func:`~brdfkit.fitting.samples.albedo_nodes`, 48 × 24
        nodes per angle).
    albedo_rel_error : ndarray (T, C)
        (a_model − a_target) / a_target.
    convergence : Convergence
        ``procedure``, ``stages`` (name, parameters, evaluations, loss before/after,
        status), ``starts`` (every stage-(ii) run: start, end, loss), ``evaluations``,
        ``time_s``, ``at_bounds``, ``linear``, ``inert``, ``n_samples``
        (:class:`~brdfkit.fitting._records.Convergence`; reads like a dict).
    status, success, message :
        As ``brdfkit.status.STATUS["fit"]``; ``success`` is False only for ``nonfinite``.
    albedo_model_error, albedo_target_error : ndarray (T, C)
        Error estimates of ``albedo_model`` and ``albedo_target``
        (:func:`~brdfkit.fitting.samples.albedo_with_error`: the difference from the
        rule with a third of the nodes per axis, a bound for smooth integrands).
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
    convergence: Convergence | dict = field(default_factory=dict)
    status: int = FIT_STATUS.CONVERGED
    success: bool = True
    message: str = ""
    albedo_model_error: np.ndarray | None = None
    albedo_target_error: np.ndarray | None = None

    def to_dict(self) -> dict:
        """``{"model", "params", "metrics", "albedo", "convergence", ...}`` (JSON-ready;
        ``params`` can be passed back as ``-p NAME=VALUE``). ``albedo`` holds
        ``model_error`` and ``target_error`` (after the other keys) where the result has
        them."""
        d = self.model.to_dict()
        albedo = {"theta_deg": self.theta_deg.tolist(), "model": self.albedo_model.tolist(),
                  "target": self.albedo_target.tolist(),
                  "rel_error": self.albedo_rel_error.tolist()}
        if self.albedo_model_error is not None:
            albedo["model_error"] = self.albedo_model_error.tolist()
        if self.albedo_target_error is not None:
            albedo["target_error"] = self.albedo_target_error.tolist()
        conv = self.convergence
        return {"model": d["model"], "params": d["params"],
                **{k: d[k] for k in ("compensate", "pump") if k in d},
                "loss": self.loss, "value": self.value, "metrics": dict(self.metrics),
                "albedo": albedo,
                "convergence": conv.to_dict() if isinstance(conv, Convergence) else conv,
                "status": self.status, "success": self.success, "message": self.message}


def _at_bounds(space, values, flat) -> list[AtBound]:
    out = []
    for c in space.coords:
        x = space.x(values, c)
        side = c.at_bound(x)
        if side:
            out.append(AtBound(c.label, side, c.lower if side == "lower" else c.upper, x))
        elif c.label in flat and flat[c.label][0] != "inert":
            # the loss cannot tell it from its bound (FitRun.flat_to_bound)
            side, _, change = flat[c.label]
            out.append(AtBound(c.label, side, c.lower if side == "lower" else c.upper, x,
                               loss_change_at_bound=change))
    return out


def albedo_far(theta_deg, a_model, a_target, rel) -> str:
    """The flag of a fit whose albedo is far from the target's (:data:`ALBEDO_FAR_RTOL`):
    where the relative difference is largest, with both albedos; "" when it is not."""
    r = np.abs(np.nan_to_num(np.asarray(rel, dtype=np.float64), nan=0.0))
    r = r.reshape(len(theta_deg), -1)
    if not r.size or float(r.max()) <= ALBEDO_FAR_RTOL:
        return ""
    k, c = np.unravel_index(int(np.argmax(r)), r.shape)
    am = np.asarray(a_model).reshape(r.shape)[k, c]
    at = np.asarray(a_target).reshape(r.shape)[k, c]
    channel = f", channel {'RGB'[c] if r.shape[1] == 3 else c}" if r.shape[1] > 1 else ""
    return (f"the fitted albedo is far from the target's: {100 * r[k, c]:.0f} % off at "
            f"theta_i = {theta_deg[k]:g} deg{channel} (model {am:.3g}, target {at:.3g}; "
            f"flagged above {100 * ALBEDO_FAR_RTOL:.0f} %)")


def _inert(space, values, flat) -> list[tuple[str, float, float, float]]:
    """(label, fitted value, lower, upper) of the coordinates the loss cannot tell from
    either bound (FitRun.flat_to_bound's "inert"): the data do not determine them."""
    return [(c.label, space.x(values, c), c.lower, c.upper) for c in space.coords
            if flat.get(c.label, ("",))[0] == "inert"]


def eta_k_note(model, space, at_bounds) -> str:
    """The note of a fit whose Fresnel index η and extinction κ were both fitted and one of
    them ended at a bound: for a conductor only F(θ) is observable, and (η, κ) pairs of
    equal F₀ = ((η − 1)² + κ²)/((η + 1)² + κ²) give nearly the same F(θ), so the fit may
    trade one for the other (merl:nickel: η ≈ 23 with κ at 0, a dielectric-like Fresnel
    with F₀ ≈ 0.85 imitating a metal). The values are then not the material's (η, κ); the
    note gives the F₀ they do determine. "" when it does not apply."""
    free = {c.name for c in space.coords}
    bounded = {b.parameter.split("[")[0] for b in at_bounds}
    values = model.to_dict()["params"]
    eta, k = values.get("eta"), values.get("k")
    if not {"eta", "k"} <= free or not bounded & {"eta", "k"} or eta is None or k is None:
        return ""
    f0 = np.atleast_1d(fresnel_conductor(1.0, eta, k))
    which = next(b for b in at_bounds if b.parameter.split("[")[0] in ("eta", "k"))
    name = which.parameter.split("[")[0]
    other = "eta" if name == "k" else "k"

    def fmt(v):
        return "/".join(f"{x:.3g}" for x in np.atleast_1d(v))
    return (f"{other} = {fmt(values[other])} with {name} at its {which.bound} bound: "
            f"F0 = {fmt(f0)}; a conductor's (eta, k) are nearly interchangeable at "
            "equal F0 = ((eta-1)^2+k^2)/((eta+1)^2+k^2), so these are not the material's; "
            "hold one (-p k=VALUE or -p eta=VALUE) to read the other")


def _status(pred, value, hit_limit, at_bounds) -> int:
    if not np.all(np.isfinite(pred)) or not math.isfinite(value):
        return FIT_STATUS.NONFINITE
    if hit_limit:
        return FIT_STATUS.LIMIT
    return FIT_STATUS.AT_BOUND if at_bounds else FIT_STATUS.CONVERGED


def make_result(prob, target, space, values, record: Convergence, hit_limit, t_start, flat,
                evaluations) -> FitResult:
    """The :class:`FitResult` of the fit whose problem is *prob* (its model the exact
    one) at *values* (module docstring)."""
    m, pred = prob.predict(values)
    if m is None:  # unreachable: stage values come from evaluated, accepted models
        raise BrdfkitError("fit: the fitted parameters were refused by the model")
    metrics = {}
    for name, L in REGISTRY.items():
        if L.needs_albedo and prob.albedo_t is None:  # the target's albedo is computed
            metrics[name] = prob.under(L, target).loss_of(m, pred)
        else:
            metrics[name] = prob.loss_of(m, pred, L)
    n_u, n_phi = ALBEDO_NODES
    wi, wo, wa, T = albedo_nodes(ALBEDO_THETA_DEG, n_u=n_u, n_phi=n_phi)
    a_m, e_m = albedo_with_error(prob.evaluate(m, wi, wo), wa, T, n_u, n_phi)
    a_t, e_t = albedo_with_error(prob.evaluate(target, wi, wo), wa, T, n_u, n_phi)
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(a_t > 0.0, (a_m - a_t) / a_t, np.nan)
    at_bounds = _at_bounds(space, values, flat)
    record.evaluations, record.refused = evaluations, prob.n_invalid
    record.time_s = time.perf_counter() - t_start
    record.at_bounds = at_bounds
    status = _status(pred, metrics[prob.loss], hit_limit, at_bounds)
    msg = FIT_STATUS.message(status)
    if at_bounds:
        msg += " (" + ", ".join(
            f"{b.parameter} = {b.fitted:.4g}, " + ("at" if b.loss_change_at_bound is None else
                                                   "indistinguishable from")
            + f" its {b.bound} bound {b.value:g}" for b in at_bounds) + ")"
    inert = _inert(space, values, flat)
    if inert:
        record.inert = sorted(set(record.inert) | {label for label, *_ in inert})
        msg += ("; inert (moved to either bound of its range the loss changes by less than "
                f"{BOUND_LOSS_RTOL:g} relative: the data do not determine it, e.g. the shape "
                "of a lobe of zero weight): " + ", ".join(
                    f"{label} = {x:.4g} in [{lo:g}, {hi:g}]" for label, x, lo, hi in inert))
    trade = eta_k_note(m, space, at_bounds)
    if trade:
        msg += "; " + trade
    far = albedo_far(ALBEDO_THETA_DEG, a_m, a_t, rel)
    if far:
        msg += "; " + far
    d = m.to_dict()
    return FitResult(model=m, params=d["params"], loss=prob.loss, value=metrics[prob.loss],
                     metrics=metrics, theta_deg=np.asarray(ALBEDO_THETA_DEG),
                     albedo_model=a_m, albedo_target=a_t, albedo_rel_error=rel,
                     convergence=record, status=status, success=FIT_STATUS.success(status),
                     message=msg, albedo_model_error=e_m, albedo_target_error=e_t)
