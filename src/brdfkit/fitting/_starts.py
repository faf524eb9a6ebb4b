"""
The starts of stage (ii)'s multi-start search
=============================================

:func:`shape_starts` lists the runs of stage (ii) of a :class:`~brdfkit.fitting._run.FitRun`
(``procedure`` module docstring): the guess; with free optional parameters, the nested
model's optimum; starts near (or, under ``prefit_bound_ends``, fits at) the bounds of
``BRDF.fit_bound_starts`` parameters; the declared defaults; random ones. A parameter that
starts at a bound of its range (e.g. a conductor's κ at its default 0) is first moved off
it (:func:`off_the_bounds`).

Public objects
--------------
- :func:`shape_starts`, :func:`off_the_bounds`; :data:`NEUTRAL_Z`, :data:`BOUND_START_Z`,
  :data:`SATURATED_Z`, :data:`OFF_BOUND_Z`.
"""

from __future__ import annotations

import numpy as np

from brdfkit.errors import ParameterError
from brdfkit.fitting._space import Z_MAX

__all__ = ["shape_starts", "off_the_bounds", "NEUTRAL_Z", "BOUND_START_Z", "SATURATED_Z",
           "OFF_BOUND_Z"]

#: z of the optional parameters (e.g. η) tried at the nested model's optimum: the one
#: where the loss is least (where the parameter changes the model least) starts stage (ii).
NEUTRAL_Z = (-Z_MAX, -6.0, -2.0, 0.0, 2.0, 6.0, Z_MAX)
#: z (logit) of the starts near the bounds of BRDF.fit_bound_starts parameters: 1.8 % of
#: the range from the bound, where the logit's initial step (~2.8 in z) can still leave it.
BOUND_START_Z = 4.0
#: |z| from which a coordinate's start counts as at its bound: σ(−20) = 2e-9, where the
#: simplex's largest initial step (~1.1 in z, Coord.step) changes the parameter by nothing
#: the loss sees (κ = 0 started at z = logit(1e-12) = −27.6 stayed at 1e-6 in every run).
SATURATED_Z = 20.0
#: z tried for a coordinate started at its bound: the bounds and a unit grid between ±6
#: (σ from 0.25 % to 99.75 %; κ of a log coordinate on [1e-6, 100]: a factor ~2.5 apart
#: over 0.07..14, fine enough to land in the basin of nickel's κ ≈ 3.7 at η = 1.8, which
#: NEUTRAL_Z's 0.01 and 11 straddle across a ridge at κ ≈ 10).
OFF_BOUND_Z = (-Z_MAX, *np.arange(-6.0, 7.0), Z_MAX)


def _defaults(run, shape_names) -> dict:
    """The current values with the shape parameters at their declared defaults."""
    values = run.values
    defaults = dict(values)
    for p in run.model.params:
        # an optional parameter declared None (e.g. η: no Fresnel) keeps its value
        if p.name in shape_names and p.default is not None:
            defaults[p.name] = (np.broadcast_to(np.asarray(p.default, float),
                                                np.shape(values[p.name])).copy()
                                if np.ndim(values[p.name]) else float(p.default))
    return defaults


def off_the_bounds(run, values: dict, *, inside: bool = False) -> dict:
    """*values* with each shape parameter whose coordinates all start at a bound of their
    range (|z| ≥ :data:`SATURATED_Z`) moved to the z of :data:`OFF_BOUND_Z` (the bounds
    included) whose projected loss on the search's samples is least: from the bound the
    simplex cannot move it (a conductor's κ at its default 0 stayed there whatever η; held
    η = 1.8 on nickel, κ ended at its floor with the albedo 92 % low). The start is never
    worse than at the bound, which is one of the candidates. *inside*: the best local
    minimum of the scan inside the range (else its least inside value), not a bound (the
    defaults' start: with the guess at a bound, the multi-start then tries an interior
    basin too; η = 1.8 held on nickel: κ = 100 at the guess's width, κ ≈ 3.7 the better
    optimum, 0.00975 against 0.00997)."""
    space = run.space
    for name in space.names(run.shape):
        cs = [c for c in run.shape if c.name == name]
        if not np.all(np.abs(space.z(values, cs)) >= SATURATED_Z):
            continue
        loss = [run.projected(run.sp, space.point(np.full(len(cs), zz), cs, values))
                for zz in OFF_BOUND_Z]
        if inside:  # the best basin inside: a local minimum of the scan, else the least
            inner = range(1, len(OFF_BOUND_Z) - 1)
            basins = [j for j in inner if loss[j] < loss[j - 1] and loss[j] < loss[j + 1]]
            pick = min(basins or inner, key=lambda j: loss[j])
        else:
            pick = int(np.argmin(loss))
        values = space.point(np.full(len(cs), OFF_BOUND_Z[pick]), cs, values)
    return values


def _nested_start(run, nested):
    """The same model without its optional parameters *nested* (e.g. η: F = 1) fitted
    first, its optimum a start with those parameters where they change least: a free
    optional parameter never makes the fit worse than leaving it out (nested models).
    None when the model refuses to leave them out (a held parameter needs one: κ held
    needs η), the record saying why."""
    space, values = run.space, run.values
    try:
        without = run.model.with_params(**{n: None for n in nested})
    except ParameterError as err:
        run.record.nested = {"without": nested, "refused": str(err)}
        return None
    inner = run.sub_fit(without, {k: v for k, v in run.fixed.items() if k not in nested})
    run.record.nested = {"without": nested, "value": inner.value, "status": inner.status,
                         "params": inner.params,
                         "evaluations": inner.convergence.evaluations}
    start = {**values, **{k: v for k, v in inner.model.values.items() if k not in nested}}
    opt = [c for c in run.shape if c.name in nested]
    best_z = min(NEUTRAL_Z, key=lambda zz: run.projected(
        run.sp, space.point(np.full(len(opt), zz), opt, start)))
    return ("nested: without " + ", ".join(nested),
            space.point(np.full(len(opt), best_z), opt, start))


def _bound_starts(run) -> list:
    """A parameter whose bounds are sub-models (BRDF.fit_bound_starts: Nielsen's α, 0
    Phong, 1 Blinn–Phong) is started near each bound, always (not skipped by consensus),
    in place of the defaults and random starts: a run from the middle can settle in one
    end's basin while the other end fits better (20 of 100 MERL materials), and the
    defaults are one arbitrary point where these are two structured ones. Under
    ``prefit_bound_ends`` (procedure "nielsen": the paper compares the α-mix with its two
    ends) each end is fitted first instead, and its optimum, the parameter at the bound, is
    a candidate as it is (no search from it): the mix is then never worse than either end
    (it was on 6 of 100 materials with the starts near the bounds alone)."""
    space, values, model = run.space, run.values, run.model
    out = []
    for c in run.shape:
        if c.name not in model.fit_bound_starts or c.transform != "logit":
            continue
        for side, z in (("lower", -BOUND_START_Z), ("upper", BOUND_START_Z)):
            if not run.procedure.prefit_bound_ends or c.index is not None:
                out.append((f"{c.label} near its {side} bound", space.point([z], [c], values)))
                continue
            x = c.lower if side == "lower" else c.upper
            end_fit = run.sub_fit(model.with_params(**{c.name: x}), {**run.fixed, c.name: x})
            label = f"{c.label} = {x:g} fitted first"
            if run.record.bound_fits is None:
                run.record.bound_fits = {}
            run.record.bound_fits[label] = {"value": end_fit.value, "status": end_fit.status,
                                            "evaluations": end_fit.convergence.evaluations}
            out.append((label, space.point([np.sign(z) * Z_MAX], [c],
                                           {**values, **end_fit.model.values})))
            run.prefit[label] = (c, np.sign(z) * BOUND_START_Z)
    return out


def shape_starts(run) -> tuple[list, set]:
    """The starts of stage (ii) of *run* as (label, values) pairs, and the labels run
    whatever the consensus (the bound starts). ``n_starts`` starts in all besides the
    nested one, the bound starts first after the guess; with ``n_starts == 1`` the guess
    (and the nested start) only."""
    shape = run.shape
    shape_names = {c.name for c in shape}
    values = off_the_bounds(run, run.values)
    defaults = off_the_bounds(run, _defaults(run, shape_names), inside=True)
    starts = [("guess", values)]
    nested = [p.name for p in run.model.params if p.optional and p.name in shape_names]
    inner = _nested_start(run, nested) if nested else None
    if inner is not None:
        starts.append(inner)
    bound = _bound_starts(run)
    starts += bound
    n_starts = run.settings.n_starts
    if n_starts >= 2:
        starts.append(("defaults", defaults))
    z_guess = run.space.z(values, shape)
    for k in range(n_starts - 2):
        starts.append((f"random {k + 1}", run.space.point(
            z_guess + run.rng.normal(0.0, 1.0, len(shape)), shape, values)))
    starts = starts[:(max(n_starts, 1 + len(bound)) if n_starts > 1 else 1)
                    + (inner is not None)]
    return starts, {label for label, _ in bound}
