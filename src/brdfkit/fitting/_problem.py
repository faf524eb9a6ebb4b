"""
A fitting problem: samples, target values, model evaluation, linear solves
==========================================================================

:class:`Problem` holds what every stage of a fit needs: the samples and the
target's cosine-weighted values on them, the model to rebuild from parameter
values, the loss, and a counter of model evaluations.

Linear parameters (variable projection)
---------------------------------------
A colour parameter p_k is *linear* when the model is affine in it jointly
with the others: f = f₀ + Σ_k p_k B_k, with f₀ (all p_k = 0) and the bases
B_k (p_k = 1, the others 0) depending only on the remaining (shape)
parameters. This is tested numerically on the samples (a random combination
must equal f₀ + Σ c_k B_k to 10⁻⁶ of its largest value), so no model is named: ρ_d, ρ_s, k_s of
the Phong family, Ward and Lafortune pass; a pumped model (f/g, with g
depending on them) does not. For fixed shape parameters the linear ones are
solved per channel in closed form (:mod:`brdfkit.fitting._linear`): the
box-constrained least squares exactly, or L1 by iteratively reweighted least squares
from the L2 solution, warm-started from the previous solution
(:data:`IRLS_ITERATIONS` steps at most) — which of the two, over which samples
(``ngan``: θ_i, θ_o ≤ 80°, as its metric) and whether it is exact, is the loss's
(:class:`brdfkit.fitting.losses.Loss`; ``log`` and ``perceptual`` solve under L2, and
their stage iii then optimises everything under the loss itself).
"""

from __future__ import annotations

import copy
import math
import warnings

import numpy as np

from brdfkit.errors import BrdfkitError
from brdfkit.fitting.losses import Loss
from brdfkit.fitting.losses import loss as get_loss
from brdfkit.fitting.samples import albedo_from_values

__all__ = ["Problem", "IRLS_ITERATIONS"]

#: IRLS steps of the L1 linear solve.
IRLS_ITERATIONS = 3
#: Relative tolerance of the numerical linearity test.
LINEAR_RTOL = 1e-6


class Problem:
    """Samples, target and model of one fit (see the module docstring)."""

    def __init__(self, model, target, samples, loss: str | Loss, n_channels: int):
        self.model = model
        self.samples = samples
        self.objective = get_loss(loss)  # the Loss object (brdfkit.fitting.losses)
        self.loss = self.objective.name
        self.C = n_channels
        self.n_evals = 0
        self.n_invalid = 0
        self._warm = None  # the last linear solution (IRLS warm start)
        self.static: dict = {}  # shape-independent f₀ ('') and bases (by name)
        self._r_static = None  # y − f₀ for a static f₀
        s = samples
        self.w = s.weight
        self.cos = s.cos_i[:, None]
        y = self.evaluate(target, s.wi, s.wo)
        ok = np.all(np.isfinite(y), axis=1)
        if not np.any(ok):
            raise BrdfkitError("fit: the target is not finite at any sample (no measured bin)")
        if not np.all(ok):  # unmeasured bins of a MERL file: dropped, never read as 0
            self.samples = s = s.subset(ok)
            self.w, self.cos, y = s.weight, s.cos_i[:, None], y[ok]
        self.y = y * self.cos
        self._masks: dict = {}  # loss name → its sample mask on these samples
        self.mask = self.mask_of(self.objective)
        # the weights of the linear solve: over the loss's samples only (ngan: θ ≤ 80°)
        self.w_solve = (self.w if self.mask is None
                        else np.ascontiguousarray(self.w * self.mask))
        self._w_solve_sum = float(np.sum(self.w_solve))
        self.albedo_t = None
        if self.objective.needs_albedo:
            self._loss_albedo(target)

    def _loss_albedo(self, target) -> None:
        self._anodes = self.objective.albedo_nodes()
        wi, wo, wa, T = self._anodes
        self.albedo_t = albedo_from_values(self.evaluate(target, wi, wo), wa, T)

    def mask_of(self, loss: Loss):
        """*loss*'s sample mask on these samples (:meth:`Loss.sample_mask`), or None."""
        if loss.name not in self._masks:
            self._masks[loss.name] = loss.sample_mask(self.samples)
        return self._masks[loss.name]

    @property
    def ngan_mask(self):
        """The samples with θ_i, θ_o ≤ 80° (the ``ngan`` loss's mask)."""
        return self.mask_of(get_loss("ngan"))

    def under(self, loss: str | Loss, target) -> Problem:
        """This problem under another *loss* (the samples and target values shared, not
        evaluated again; the target's albedo computed if that loss needs it)."""
        loss = get_loss(loss)
        if loss is self.objective:
            return self
        other = copy.copy(self)
        other.objective, other.loss = loss, loss.name
        other.mask = other.mask_of(loss)
        other.w_solve = (self.w if other.mask is None
                         else np.ascontiguousarray(self.w * other.mask))
        other._w_solve_sum = float(np.sum(other.w_solve))
        if loss.needs_albedo:
            other._loss_albedo(target)
        return other

    def with_model(self, model) -> Problem:
        """This problem with another *model* to build (e.g. the exact model after a fit
        through a stand-in), the samples and target values shared."""
        other = copy.copy(self)
        other.model = model
        return other

    # ------------------------------------------------------------------ evaluation
    def evaluate(self, m, wi, wo, *, per_channel: bool = True) -> np.ndarray:
        """f at the pairs, (N, C); (N, 1) for a model without per-channel parameters when
        not *per_channel* (left to broadcast)."""
        f = np.asarray(m.eval(wi, wo), dtype=np.float64).reshape(wi.shape[0], -1)
        if per_channel and f.shape[1] == 1 and self.C > 1:
            f = np.repeat(f, self.C, axis=1)
        return f

    def build(self, values: dict):
        """The model with *values*, or None when the set-up refuses them."""
        with warnings.catch_warnings():
            # exploring parameters may pass through albedos above 1 (pumping warns):
            # expected during a search; the final model is checked and reported
            warnings.simplefilter("ignore")
            try:
                return self.model.with_params(**values)
            except BrdfkitError:
                self.n_invalid += 1
                return None

    def predict(self, values: dict, *, per_channel: bool = True):
        """(model, f·cos θ_i at the samples (N, C), or (N, 1) as :meth:`evaluate` says),
        or (None, None)."""
        m = self.build(values)
        if m is None:
            return None, None
        self.n_evals += 1
        return m, self.evaluate(m, self.samples.wi, self.samples.wo,
                                per_channel=per_channel) * self.cos

    def loss_of(self, m, pred, loss: str | Loss | None = None) -> float:
        """The loss (this problem's, or *loss*) of model *m* with predictions *pred*."""
        L = self.objective if loss is None else get_loss(loss)
        if pred is None or not np.all(np.isfinite(pred)):
            return math.inf
        am = None
        if L.needs_albedo:
            wi, wo, wa, T = self._anodes
            am = albedo_from_values(self.evaluate(m, wi, wo), wa, T)
        return L.value(pred, self.y, self.w, mask=self.mask_of(L), albedo_m=am,
                       albedo_t=self.albedo_t)

    def loss_at(self, values: dict) -> float:
        m, pred = self.predict(values)
        return self.loss_of(m, pred)

    # ------------------------------------------------------------------ linear part
    def bases(self, values: dict, linear) -> tuple | None:
        """(f₀, [B_k]) at the samples, cosine-weighted, each (N, C); None if refused.

        Terms in :attr:`static` (found not to depend on the shape parameters by
        :meth:`find_static`, e.g. the Lambertian basis of ρ_d) are reused, not
        re-evaluated."""
        zero = dict(values)
        for name, _ in linear:
            zero[name] = 0.0
        f0 = self.static.get("")
        if f0 is None:
            _, f0 = self.predict(zero)
            if f0 is None:
                return None
        B = []
        for name, unit in linear:
            Bk = self.static.get(name)
            if Bk is None:
                v = dict(zero)
                v[name] = unit
                # (N, 1) for a model without per-channel parameters left: broadcast by the
                # subtraction instead of repeated per channel first (the search's hot path)
                _, fk = self.predict(v, per_channel=False)
                if fk is None:
                    return None
                Bk = fk - f0 if unit == 1.0 else (fk - f0) / unit
            B.append(Bk)
        return f0, B

    def find_static(self, values: dict, linear, moved: dict) -> None:
        """Mark f₀ and the bases that are identical at *values* and at the shape
        parameters *moved* as static (evaluated once; see :meth:`bases`)."""
        self.static = {}
        self._r_static = None
        a = self.bases(values, linear)
        b = self.bases(moved, linear)
        if a is None or b is None:
            return
        if np.array_equal(a[0], b[0]):
            self.static[""] = a[0]
        for (name, _), Ba, Bb in zip(linear, a[1], b[1], strict=True):
            if np.array_equal(Ba, Bb):
                self.static[name] = Ba

    def is_affine(self, values: dict, linear, rng) -> bool:
        """Whether the model is affine in the *linear* parameters jointly (module doc)."""
        got = self.bases(values, linear)
        if got is None:
            return False
        f0, B = got
        v = dict(values)
        expect = f0.copy()
        for (name, unit), Bk in zip(linear, B, strict=True):
            c = unit * (0.2 + 0.6 * rng.random(self.C))  # inside the bounds, per channel
            v[name] = c if self.C > 1 else float(c[0])
            expect = expect + Bk * c[None, :]
        _, got_f = self.predict(v)
        if got_f is None or not np.all(np.isfinite(got_f)):
            return False
        scale = max(float(np.max(np.abs(expect))), 1e-300)
        return float(np.max(np.abs(got_f - expect))) <= LINEAR_RTOL * scale

    def solve_linear(self, f0, B, lo, hi, *,
                     iterations: int = IRLS_ITERATIONS) -> tuple[np.ndarray, float | None]:
        """Per-channel linear parameters P (K, C) under this problem's loss's solve
        (:meth:`brdfkit.fitting.losses.Loss.solve`: L1 by at most *iterations* IRLS steps,
        or L2, over the loss's samples), and the loss at P where the solve gives it (None
        otherwise: the value needs the prediction)."""
        K = len(B)
        start = (self._warm if self._warm is not None and self._warm.shape == (K, self.C)
                 else np.empty((0, 0)))
        if f0 is self.static.get(""):  # a shape-independent offset: y − f₀ once
            if self._r_static is None:
                self._r_static = np.ascontiguousarray(self.y - f0)
            R = self._r_static
        else:
            R = np.ascontiguousarray(self.y - f0)
        P, value = self.objective.solve(np.stack(B), R, self.w_solve, lo, hi,
                                        iterations=iterations, start=start,
                                        w_sum=self._w_solve_sum)
        self._warm = P.copy()
        return P, value
