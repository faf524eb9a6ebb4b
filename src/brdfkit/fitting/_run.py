"""
One fit, run stage by stage
===========================

:class:`FitRun` holds the state of one fit — its problems (the fit's samples and the
search's coarser ones), its :class:`~brdfkit.fitting._space.ParameterSpace`, the current
parameter values, the linear parameters, the best stage-(ii) run and the convergence
record — and has one method per stage. A procedure
(:data:`brdfkit.fitting.procedure.PROCEDURES`) is the list of the stages it runs, in
order, and a few options the stages read; :meth:`FitRun.run` runs them and builds the
:class:`~brdfkit.fitting._result.FitResult`. The stages and their constants are described
in :mod:`brdfkit.fitting.procedure`.

Public objects
--------------
- :class:`FitRun`, :class:`Settings`; the procedure's constants (:data:`FRTOL`, …).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from brdfkit.fitting import _guess
from brdfkit.fitting._problem import IRLS_ITERATIONS, Problem
from brdfkit.fitting._pumped import hold_scale
from brdfkit.fitting._records import Convergence, StageRecord, StartRecord
from brdfkit.fitting._result import FitResult, make_result
from brdfkit.fitting._simplex import search_simplex
from brdfkit.fitting._space import BOUND_LOSS_RTOL, Z_MAX, ParameterSpace
from brdfkit.fitting._starts import shape_starts
from brdfkit.fitting.losses import Loss
from brdfkit.fitting.samples import merl_samples
from brdfkit.pumping.surrogate import surrogate

__all__ = ["FitRun", "Settings", "STAGES", "FRTOL", "FRTOL_POLISH", "IRLS_FINAL",
           "CONSENSUS", "POLISH_MIN_EVALS", "SEARCH_STRIDES", "BOUND_LOSS_RTOL"]

#: Nelder–Mead stops when the losses at the simplex's vertices agree to this fraction of
#: the loss after stage (i): FRTOL in the stage-(ii) search (the polish follows; the same
#: order as CONSENSUS), FRTOL_POLISH in stage (iii). A criterion on the loss only: along
#: flat directions (e.g. Lafortune's common scale of C_xy, C_z against rho_s) there is no
#: parameter tolerance to reach.
FRTOL, FRTOL_POLISH = 1e-4, 1e-5
#: IRLS steps of the final L1 linear solve (the search's solves take IRLS_ITERATIONS,
#: warm-started).
IRLS_FINAL = 50
#: Two stage-(ii) runs whose losses agree to this relative difference are one optimum.
CONSENSUS = 1e-3
#: Least evaluation budget of a polish (else 100 per coordinate; it stops at convergence):
#: 200 was too few for Lafortune's (C_xy, n) on six MERL materials (light-red-paint: 406).
POLISH_MIN_EVALS = 600
#: Stage (ii) searches on this coarser merging of MERL bins (θ_d, φ_d): every θ_h bin and
#: the default's 10 θ_d cells kept (a Fresnel factor depends on θ_d; with 6 θ_d cells the
#: search misjudged red-fabric2's η fit), 4 φ_d cells instead of 12: 2,676 samples instead
#: of 8,134; stage (iii) polishes on the fit's own samples. The time per evaluation is then
#: mostly fixed costs (model set-up, linear solves), so coarser cells gain little.
SEARCH_STRIDES = (9, 45)
#: The stages a procedure may list, in the order they must run.
STAGES = ("first_guess", "hold_inert", "find_linear", "closed_form", "loss_scale",
          "root_start", "shape_search", "polish", "bound_polish")


def _polish_budget(max_evals, free):
    return max(max_evals, 100 * len(free), POLISH_MIN_EVALS)


@dataclass(frozen=True)
class Settings:
    """What a fit and its sub-fits (nested, bound ends, a derived model's base) share."""

    loss: Loss
    procedure: object  # brdfkit.fitting.procedure.Procedure
    theta_max: float | None
    seed: int
    n_starts: int
    strides: tuple
    max_evals: int


class FitRun:
    """One fit (module docstring): ``FitRun(model, target, settings, fixed).run()``."""

    def __init__(self, model, target, settings: Settings, fixed: dict, progress=None):
        self.t_start = time.perf_counter()
        self.model, self.target, self.settings = model, target, settings
        self.fixed, self.progress = fixed, progress
        self.procedure = settings.procedure
        self.objective = settings.loss
        self.rng = np.random.default_rng(settings.seed)
        self.C = C = int(target.n_channels or 1)
        self.space, self.values = ParameterSpace.of_model(model, fixed, C)
        # a gauge freedom of the model (BRDF.fit_gauge) is held at its given value, unless
        # that value is 0 (there the other coordinates no longer absorb it)
        gauge = self.space.gauges(model, self.values)
        self.space.hold(gauge)
        # a one-times pumped model is evaluated through its surrogate (tables per shape
        # parameter, linear parameters combined: brdfkit.pumping.surrogate) until the
        # result, which evaluates the exact model
        self.fast = surrogate(model, [c.name for c in self.space.coords])
        evaluated = model if self.fast is None else self.fast
        strides, theta_max = settings.strides, settings.theta_max
        self.prob = prob = Problem(evaluated, target, merl_samples(
            strides=strides, theta_max=theta_max), self.objective, C)
        # stage (ii)'s search on a coarser grid (every θ_h bin kept); never finer than the
        # fit's
        coarse = tuple(max(int(a), b) for a, b in zip(strides, SEARCH_STRIDES, strict=True))
        self.sp = (prob if coarse == tuple(int(a) for a in strides) else Problem(
            evaluated, target, merl_samples(strides=coarse, theta_max=theta_max),
            self.objective, C))
        self.record = Convergence(procedure=self.procedure.name, loss=self.objective.name,
                                  seed=settings.seed, n_samples=len(prob.samples),
                                  n_samples_search=len(self.sp.samples))
        if gauge:
            self.record.gauge_held = {c.label: self.space.x(self.values, c) for c in gauge}
        self.linear, self.lin_names = [], []
        self.lo = self.hi = np.array([])
        self.shape = list(self.space.coords)
        self.scale = 1.0
        self.hit_limit = False
        self.best = None  # stage (ii)'s best run: (loss, values, hit_limit, start label)
        self.prefit = {}  # label of an end fitted first → (its Coord, z of a start inside)
        self.derived_start = False
        self.free3, self.projected3 = [], False
        self.flat = {}

    # ------------------------------------------------------------------ running
    def run(self) -> FitResult:
        """Every stage of the procedure, then the result."""
        for stage in self.procedure.stages:
            getattr(self, stage)()
        self.record.evaluations_search = self.sp.n_evals if self.sp is not self.prob else 0
        result_prob = self.prob
        if self.fast is not None:
            fast = self.fast
            self.record.surrogate = {
                "linear": list(fast.linear), "shape": list(fast.shape),
                "loss": self.prob.loss_at(self.values), "tables_built": fast.n_tables,
                "table_time_s": fast.table_time_s}
            result_prob = self.prob.with_model(self.model)  # the result: the exact model
        return make_result(result_prob, self.target, self.space, self.values, self.record,
                           self.hit_limit, self.t_start, self.flat, self.n_evals())

    def sub_fit(self, model, fixed) -> FitResult:
        """A fit of another *model* (nested, an end, the base) with these settings."""
        return FitRun(model, self.target, self.settings, fixed).run()

    def n_evals(self) -> int:
        return self.prob.n_evals + (self.sp.n_evals if self.sp is not self.prob else 0)

    def stage_record(self, name, params, n0, before, after, limit, vals) -> None:
        self.record.stages.append(StageRecord(
            stage=name, parameters=params, evaluations=self.n_evals() - n0,
            loss_before=before, loss_after=after, hit_limit=bool(limit),
            at_bounds=self.space.at_bounds(vals)))
        if self.progress is not None:
            self.progress(name, self.n_evals(), after)

    # ------------------------------------------------------------------ tools
    def solve_at(self, p, vals, want_loss=False, iterations=IRLS_ITERATIONS):
        """*vals* with the linear parameters solved on problem *p* (and its loss)."""
        got = p.bases(vals, self.linear) if self.linear else None
        if got is None:
            return (None, math.inf) if want_loss else None
        f0, B = got
        P, value = p.solve_linear(f0, B, self.lo, self.hi, iterations=iterations)
        out = dict(vals)
        for k, n in enumerate(self.lin_names):
            out[n] = P[k].copy() if self.C > 1 else float(P[k, 0])
        if not want_loss:
            return out
        if value is not None:  # computed with the solve (Loss.from_residual)
            return out, value
        if self.objective.needs_albedo:  # needs the model's albedo: evaluate it
            return out, p.loss_at(out)
        # the model is affine in the linear parameters: its values from the bases
        pred = f0.copy()
        for k, Bk in enumerate(B):
            pred += Bk * P[k][None, :]
        return out, p.loss_of(None, pred)

    def projected(self, p, vals) -> float:
        """Loss on *p* with the linear parameters solved (variable projection)."""
        return self.solve_at(p, vals, want_loss=True)[1] if self.linear else p.loss_at(vals)

    def search(self, p, free, v0, projecting, budget, steps, fatol):
        """Minimise over the coordinates *free* from *v0* on problem *p*, the linear
        parameters solved at every point (*projecting*) or held, by Nelder–Mead.
        Returns (values, loss, evaluations, hit_limit)."""
        point = self.space.point

        def obj(z):
            v = point(z, free, v0)
            return self.projected(p, v) if projecting else p.loss_at(v)

        z, val, nfev, limit = search_simplex(obj, self.space.z(v0, free), steps, budget,
                                             self.scale, fatol)
        end = point(z, free, v0)
        if projecting:
            end = self.solve_at(p, end) or end
        return end, val, nfev, limit

    # ------------------------------------------------------------------ stages
    def first_guess(self) -> None:
        """The lobe width from the measured peak (refined by a scan of widths once the
        linear parameters are known: :meth:`closed_form`)."""
        model = self.model
        self.beta = _guess.measured_half_width(self.target)
        self.record.measured_half_width_deg = math.degrees(self.beta)
        wp = self.wp = model.width_param
        self.scan_width = (wp is not None and wp not in self.fixed
                           and any(c.name == wp for c in self.space.coords))
        # a derived model's width parameter is its base's (the lobe keeps its shape)
        base = model.fit_base if model.fit_base is not None else model
        self.width_from_beta = base.width_from_beta
        if self.scan_width:
            self.values = _guess.with_width(self.values, wp, self.width_from_beta, self.beta)

    def hold_inert(self) -> None:
        """Parameters that change nothing are held (and reported); tested on the search's
        samples (every θ_h bin), as the linearity: properties of the model, not of the
        sample density, and a third of the cost."""
        inert = self._inert(self.sp, self.space.coords, self.values)
        self.space.hold(c for c in self.space.coords if c.name in inert)
        self.record.inert = sorted(inert)
        self.shape = list(self.space.coords)

    def _inert(self, prob, coords, values) -> set:
        """Names of parameters that change no sample value when moved by five z-steps, or
        that the model refuses to move alone."""
        space = self.space
        _, base = prob.predict(values)
        out = set()
        for name in space.names(coords):
            cs = [c for c in coords if c.name == name]
            z = space.z(values, cs)
            _, moved = prob.predict(space.point(z + 5.0 * space.steps(values, cs), cs, values))
            # held: no effect, or refused when moved alone (e.g. an extinction coefficient k
            # without an index eta: the model's own cross-parameter check)
            if moved is None or (base is not None and np.array_equal(base, moved)):
                out.add(name)
        return out

    def find_linear(self) -> None:
        """Linear colour parameters (variable projection): each candidate tested alone, then
        the affine ones jointly (a colour parameter the model is not affine in, e.g. η, is
        a shape parameter and does not stop ρ_d, k_s from being solved in closed form)."""
        model, sp, values, rng = self.model, self.sp, self.values, self.rng
        coords = self.space.coords
        linear = []
        cand = [(p.name, min(1.0, p.upper)) for p in model.params
                if p.kind == "colour" and any(c.name == p.name for c in coords)]
        # jointly first (affine jointly implies affine in each alone): one test, not K + 1
        if len(cand) > 1 and sp.is_affine(values, cand, rng):
            linear = cand
        else:
            cand = [c for c in cand if sp.is_affine(values, [c], rng)]
            if len(cand) == 1 or (cand and sp.is_affine(values, cand, rng)):
                linear = cand
        self.linear = linear
        self.lin_names = lin_names = [n for n, _ in linear]
        self.record.linear = lin_names
        decl = {p.name: p for p in model.params}
        self.lo = np.array([decl[n].lower for n in lin_names])
        self.hi = np.array([decl[n].upper for n in lin_names])
        self.shape = shape = [c for c in coords if c.name not in lin_names]
        if linear and shape:
            moved = self.space.point(self.space.z(values, shape)
                                     + self.space.steps(values, shape), shape, values)
            for p in {id(self.prob): self.prob, id(sp): sp}.values():
                p.find_static(values, linear, moved)
        self.record.static_bases = sorted(k or "f0" for k in self.prob.static)

    def closed_form(self) -> None:
        """Stage (i): the linear parameters solved in closed form, after a scan of the
        width's first guess."""
        if not self.linear:
            return
        n0 = self.n_evals()
        before = self.prob.loss_at(self.values)
        if self.scan_width:  # the width whose projected loss is least (module docstring)
            self.values, self.record.width_scan = _guess.scan_width(
                self.values, self.wp, self.width_from_beta, self.beta,
                lambda v: self.projected(self.sp, v))
        solved = self.solve_at(self.prob, self.values)
        if solved is not None:
            self.values = solved
        self.stage_record("i: linear (closed form)" + (", width scanned" if self.scan_width
                                                       else ""),
                          self.lin_names, n0, before, self.prob.loss_at(self.values), False,
                          self.values)

    def loss_scale(self) -> None:
        """The loss scale of the stopping rule: the loss now (after stage (i)), near the
        optimum's."""
        scale = self.prob.loss_at(self.values)
        if not (math.isfinite(scale) and scale > 0.0):
            scale = 1.0  # a target the first guess already matches exactly, or a refused guess
        self.scale = scale

    def root_start(self) -> None:
        """A derived model (``BRDF.fit_base``) without linear parameters: its base fitted
        first (fast: linear parameters in closed form), the base's optimum the start of
        the joint stage (iii); rebuilding a pumped model tabulates its albedo (~0.15 s),
        too slow for stage (ii)'s multi-start."""
        model, prob, space = self.model, self.prob, self.space
        if model.fit_base is None or self.linear:
            return
        self.derived_start = True
        n0 = self.n_evals()
        before = prob.loss_at(self.values)
        base = model.fit_base
        root_fit = self.sub_fit(base.with_params(**{k: v for k, v in self.values.items()
                                                    if k in base.values}), self.fixed)
        start = {**self.values, **root_fit.model.values}
        after = prob.loss_at(start)
        if after <= before:
            self.values = start
        # g1 pumping does not see a common scale of the linear parameters: held per channel
        held = hold_scale(prob, self.values, space.coords, [p.name for p in model.params
                                                            if p.kind == "colour"])
        if held:
            space.hold(c for c in space.coords if c.label in held)
            self.record.scale_held = held
        self.record.root_fit = {"convergence": root_fit.convergence, "value": root_fit.value}
        self.stage_record("ii: the unpumped root model (its own staged fit)", space.labels(),
                          n0, before, min(before, after), False, self.values)
        if self.fast is not None and space.coords:
            # evaluations are cheap through the surrogate: one run with stage (ii)'s full
            # steps before stage (iii)'s polish (which starts far from its optimum when the
            # root's optimum was rejected above)
            coords, values = space.coords, self.values
            n0 = self.n_evals()
            before = prob.loss_at(values)
            z, val, _, limit = search_simplex(
                lambda z: prob.loss_at(space.point(z, coords, values)),
                space.z(values, coords), space.steps(values, coords),
                max(self.settings.max_evals, 60 * len(coords)), self.scale, FRTOL)
            if val <= before:
                self.values = space.point(z, coords, values)
            self.hit_limit |= limit
            self.stage_record("ii: all (pumped, full steps)", space.labels(), n0, before,
                              min(val, before), limit, self.values)

    def shape_search(self) -> None:
        """Stage (ii): a multi-start search over the shape parameters on the search's
        samples (:func:`brdfkit.fitting._starts.shape_starts`), the runs compared on the
        fit's own samples."""
        shape, prob, sp = self.shape, self.prob, self.sp
        if not shape or self.derived_start:
            return
        hold = self.procedure.hold_linear_in_search
        n0 = self.n_evals()
        before = prob.loss_at(self.values)
        budget = max(self.settings.max_evals, 100 * len(shape))
        starts, always = shape_starts(self)
        # at the guess (moved off a bound by shape_starts: the steps there, not at the bound)
        steps = self.space.steps(starts[0][1], shape)
        best = None
        agree = 0
        for label, v0 in starts:
            if agree >= 1 and label not in always:
                # two runs from different starts reached the same loss (within CONSENSUS):
                # the remaining starts are recorded as skipped
                self.record.starts.append(StartRecord(start=label, skipped="consensus"))
                continue
            if label in self.prefit:  # an end fitted first: its optimum as it is
                end, val, nfev, limit = v0, math.nan, 0, False
            else:
                if self.linear and hold:
                    # Nielsen's (ii): the linear parameters solved at the start, then held
                    v0 = self.solve_at(sp, v0) or v0
                end, val, nfev, limit = self.search(
                    sp, shape, v0, self.linear and not hold, budget,
                    # near a bound the logit's steps at the guess would hardly move it
                    self.space.steps(v0, shape) if label in always else steps, FRTOL)
            val, end, val_search = self._on_fit_samples(end, val)
            self.record.starts.append(StartRecord(
                start=label, start_values=self.space.jsonable(v0),
                end_values=self.space.jsonable(end), loss=val, loss_search=val_search,
                evaluations=nfev, hit_limit=bool(limit)))
            if best is not None and abs(val - best[0]) <= CONSENSUS * abs(best[0]):
                agree += 1
            if best is None or val < best[0]:
                best = (val, end, limit, label)
        self.best = best
        self.values = best[1]
        self.hit_limit = best[2]  # superseded by stage (iii)'s: the last stage decides
        after = prob.loss_at(self.values)
        if self.linear:  # the linear parameters re-solved on the fit's own samples
            solved = self.solve_at(prob, self.values, want_loss=True)
            if solved[0] is not None and solved[1] <= after:
                self.values, after = solved
        self.stage_record("ii: shape" + (" (linear re-solved)" if not hold and self.linear
                                         else "") + f" on {len(sp.samples)} samples",
                          self.space.labels(shape), n0, before, after, best[2], self.values)

    def _on_fit_samples(self, end, val):
        """A stage-(ii) run's end compared on the fit's own samples with the linear
        parameters re-solved, as stage (iii) will have them: (loss, end, loss on the
        search's samples). On the search's grid a sharp lobe can look better than it is
        (black-obsidian, Nielsen with η: α ≈ 0, s ≈ 2900 won at 0.00155 there, 0.00198 on
        the fit's samples, where α ≈ 0.84 gives 0.00142); with the linear parameters held
        at the start's solution (nielsen), a run that ended where those happened to fit
        won (green-fabric: η < 1, twice the loss of the best shape). The L1 solve to
        convergence: warm-started from the previous run's shape, the search's three IRLS
        steps left an end fitted first at 0.0107 for its 0.00907."""
        val_search = val
        solved = (self.solve_at(self.prob, end, want_loss=True, iterations=IRLS_FINAL)
                  if self.linear else (end, self.prob.loss_at(end)))
        if solved[0] is not None:
            end, val = solved
        return val, end, val_search

    def polish(self) -> None:
        """Stage (iii): the polish on the fit's own samples from the best run."""
        prob, space, linear = self.prob, self.space, self.linear
        if self.procedure.polish_frees == "shape-dependent" and linear:
            # the linear parameters whose basis depends on the shape (k_s, not rho_d)
            moving = {n for n, _ in linear if n not in prob.static}
            free3 = self.shape + [c for c in space.coords if c.name in moving]
        else:
            free3 = space.coords
        # variable projection is exact for l1, l2, ngan (Loss.exact_projection): min over
        # (shape, linear) of the loss is min over the shape of the loss with the linear
        # parameters solved, so stage (iii) is the shape polished with them re-solved.
        # Nielsen's (iii) frees (s, α, η, k_s): the same, with ρ_d re-solved too (free in
        # closed form). Solved by a simplex over k_s and η per channel, it reached its
        # budget on 80 of 600 study fits; with ρ_d held from stage (ii), the result
        # depended on that path (the α-mix ended 1.5 % worse than Blinn-Phong on
        # green-fabric at the same s, α)
        projected3 = bool(linear and self.shape and self.objective.exact_projection)
        if projected3:
            free3 = self.shape
        self.free3, self.projected3 = free3, projected3
        if not free3:
            return
        n0 = self.n_evals()
        before = prob.loss_at(self.values)
        start3 = self.values
        best = self.best
        if best is not None and best[3] in self.prefit and any(
                c is self.prefit[best[3]][0] for c in free3):
            # an end fitted first won: the polish starts just inside its bound, where the
            # parameter can move (at the bound's z it cannot: the mix would stay the end);
            # its result is kept only if better than the end (val <= before below)
            c_end, z_end = self.prefit[best[3]]
            start3 = space.point([z_end], [c_end], self.values)
        # a tenth of stage (ii)'s steps: stage (iii) starts near a stationary point
        steps = 0.1 * space.steps(start3, free3)
        end, val, limit = self._polish_run(free3, start3, steps)
        if val <= before:
            self.values = end
        # the final stage's stop decides: a stage-(ii) search cut by its budget and then
        # polished here to the tolerance is a converged result (its limit stays recorded)
        self.hit_limit = limit
        label = ("shape, linear re-solved (= all jointly)" if projected3
                 else self.procedure.polish_label)
        self.stage_record("iii: " + label, space.labels(free3), n0, before, min(val, before),
                          limit, self.values)

    def _polish_run(self, free, start, steps):
        """One polish run over *free* from *start*: (values, loss, hit_limit)."""
        end, val, _, limit = self.search(self.prob, free, start, self.projected3,
                                         _polish_budget(self.settings.max_evals, free), steps,
                                         FRTOL_POLISH)
        if self.projected3:  # the final linear solve to convergence (IRLS_FINAL for l1)
            end = self.solve_at(self.prob, end, iterations=IRLS_FINAL) or end
            val = self.prob.loss_at(end)
        return end, val, limit

    def bound_polish(self) -> None:
        """Bounds checked (:meth:`flat_to_bound`); a polish cut by its budget is run once
        more (stage "iii'"): the coordinates at (or indistinguishable from) a bound set
        there and held, the others polished; with none held, once more with the search's
        steps, which travel along a long valley where the polish's tenth-size simplex
        crawled (Lafortune's lobe turning horizontal, C_xy → −∞ with ρ_s → 0, on
        blue-fabric: 5 % gained in 600 evaluations, still gaining)."""
        space, free3 = self.space, self.free3
        # linear parameters solved exactly in a box (variable projection to the end) sit at
        # a bound exactly when it is active: the exact test of the result finds them
        solved = set(self.lin_names) if self.projected3 else set()
        checked = [c for c in space.coords if c.name not in solved]
        self.values, self.flat = self.flat_to_bound(self.values, checked)
        if not (free3 and self.hit_limit):
            return
        flat = self.flat
        held = [c for c in free3 if c.label in flat or c.at_bound(space.x(self.values, c))]
        rest = [c for c in free3 if c not in held]
        if not rest:
            return
        n0 = self.n_evals()
        before = self.prob.loss_at(self.values)
        start = self.values
        for c in held:  # at their bounds; an inert one held where it is
            side = flat[c.label][0] if c.label in flat else c.at_bound(space.x(self.values, c))
            if side != "inert":
                start = space.point([Z_MAX if side == "upper" else -Z_MAX], [c], start)
        steps = (0.1 if held else 1.0) * space.steps(start, rest)
        end, val, limit = self._polish_run(rest, start, steps)
        if val <= before:
            self.values, self.hit_limit = end, limit
            self.values, self.flat = self.flat_to_bound(self.values, checked)
        elif not limit:  # stopped by the tolerance without a gain: a converged point
            self.hit_limit = False
        self.stage_record("iii': polish " + ("with " + ", ".join(c.label for c in held)
                                             + " held at their bounds" if held
                                             else "again with the search's steps"),
                          space.labels(rest), n0, before, min(val, before), limit, self.values)

    def flat_to_bound(self, values, coords):
        """Coordinates the loss cannot tell from a bound: moved to the bound (z = ±Z_MAX)
        the loss rises by at most :data:`BOUND_LOSS_RTOL` relative (or falls: then the
        bound is taken). A coordinate the loss cannot tell from *either* bound (of a finite
        range, not at one) is ``"inert"``: the data do not determine it (e.g. the exponent
        of a lobe of zero weight), and it stays where it is. Returns (values, {label:
        (side, bound, relative loss change)}), side "lower", "upper" or "inert" (bound
        None, the larger of the two changes)."""
        prob, space = self.prob, self.space
        best = prob.loss_at(values)
        flat = {}
        if not math.isfinite(best):
            return values, flat
        for c in coords:
            if c.transform == "identity":
                continue
            sides = [(side, z) for side, z in (("lower", -Z_MAX), ("upper", Z_MAX))
                     if not (side == "upper" and math.isinf(c.upper))]
            at = c.at_bound(space.x(values, c))
            tried = []  # (side, z, moved values, loss there) for the sides not already at
            for side, z in sides:
                if at != side:  # already there: reported by the exact test
                    moved = space.point([z], [c], values)
                    tried.append((side, z, moved, prob.loss_at(moved)))
            level = [t for t in tried if t[3] <= best * (1.0 + BOUND_LOSS_RTOL)]
            if len(sides) == 2 and at is None and len(level) == 2:
                change = max(abs(t[3] - best) for t in level) / best if best > 0 else 0.0
                flat[c.label] = ("inert", None, change)
                continue
            if level:
                side, z, moved, lb = level[0]
                flat[c.label] = (side, c.to_x(z), (lb - best) / best if best > 0 else 0.0)
                if lb < best:
                    values, best = moved, lb
        return values, flat
