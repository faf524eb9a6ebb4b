"""
The starts of stage (ii)'s multi-start search
=============================================

:func:`shape_starts` lists the runs of stage (ii) of a :class:`~brdfkit.fitting._run.FitRun`
(``procedure`` module docstring): the guess; with free optional parameters, the nested
model's optimum; starts near (or, under ``prefit_bound_ends``, fits at) the bounds of
``BRDF.fit_bound_starts`` parameters; the declared defaults; random ones.

Public objects
--------------
- :func:`shape_starts`; :data:`NEUTRAL_Z`, :data:`BOUND_START_Z`.
"""

from __future__ import annotations

import numpy as np

from brdfkit.fitting._space import Z_MAX

__all__ = ["shape_starts", "NEUTRAL_Z", "BOUND_START_Z"]

#: z of the optional parameters (e.g. η) tried at the nested model's optimum: the one
#: where the loss is least (where the parameter changes the model least) starts stage (ii).
NEUTRAL_Z = (-Z_MAX, -6.0, -2.0, 0.0, 2.0, 6.0, Z_MAX)
#: z (logit) of the starts near the bounds of BRDF.fit_bound_starts parameters: 1.8 % of
#: the range from the bound, where the logit's initial step (~2.8 in z) can still leave it.
BOUND_START_Z = 4.0


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


def _nested_start(run, nested):
    """The same model without its optional parameters *nested* (e.g. η: F = 1) fitted
    first, its optimum a start with those parameters where they change least: a free
    optional parameter never makes the fit worse than leaving it out (nested models)."""
    space, values = run.space, run.values
    inner = run.sub_fit(run.model.with_params(**{n: None for n in nested}),
                        {k: v for k, v in run.fixed.items() if k not in nested})
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
    shape, values = run.shape, run.values
    shape_names = {c.name for c in shape}
    defaults = _defaults(run, shape_names)
    starts = [("guess", values)]
    nested = [p.name for p in run.model.params if p.optional and p.name in shape_names]
    if nested:
        starts.append(_nested_start(run, nested))
    bound = _bound_starts(run)
    starts += bound
    n_starts = run.settings.n_starts
    if n_starts >= 2:
        starts.append(("defaults", defaults))
    z_guess = run.space.z(values, shape)
    for k in range(n_starts - 2):
        starts.append((f"random {k + 1}", run.space.point(
            z_guess + run.rng.normal(0.0, 1.0, len(shape)), shape, values)))
    starts = starts[:(max(n_starts, 1 + len(bound)) if n_starts > 1 else 1) + bool(nested)]
    return starts, {label for label, _ in bound}
