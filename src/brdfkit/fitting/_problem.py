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
box-constrained least squares exactly (``l2``; ``ngan`` over its samples with θ_i, θ_o ≤
80°, as its metric; also the inner solve
for ``log`` and ``perceptual``, whose stage iii then optimises everything
under the loss itself), L1 (``l1``) by iteratively reweighted least squares
from the L2 solution, warm-started from the previous solution
(:data:`IRLS_ITERATIONS` steps at most).
"""

from __future__ import annotations

import copy
import math
import warnings

import numpy as np

from brdfkit.errors import BrdfkitError
from brdfkit.fitting._linear import solve_channels
from brdfkit.fitting.losses import NGAN_THETA_MAX_DEG, loss_value
from brdfkit.fitting.samples import albedo_from_values, albedo_nodes

__all__ = ["Problem", "IRLS_ITERATIONS"]

#: IRLS steps of the L1 linear solve.
IRLS_ITERATIONS = 3
#: Relative tolerance of the numerical linearity test.
LINEAR_RTOL = 1e-6
#: θ_i of the albedo term of the perceptual loss (degrees) and its node counts.
PERCEPTUAL_THETA_DEG = tuple(float(t) for t in range(0, 81, 10))


class Problem:
    """Samples, target and model of one fit (see the module docstring)."""

    def __init__(self, model, target, samples, loss: str, n_channels: int):
        self.model = model
        self.samples = samples
        self.loss = loss
        self.C = n_channels
        self.n_evals = 0
        self.n_invalid = 0
        self._warm = None  # the last linear solution (IRLS warm start)
        self.static: dict = {}  # shape-independent f₀ ('') and bases (by name)
        self._r_static = None  # y − f₀ for a static f₀
        s = samples
        self.w = s.weight
        self.cos = s.cos_i[:, None]
        y = self._values(target, s.wi, s.wo)
        ok = np.all(np.isfinite(y), axis=1)
        if not np.any(ok):
            raise BrdfkitError("fit: the target is not finite at any sample (no measured bin)")
        if not np.all(ok):  # unmeasured bins of a MERL file: dropped, never read as 0
            self.samples = s = s.subset(ok)
            self.w, self.cos, y = s.weight, s.cos_i[:, None], y[ok]
        self.y = y * self.cos
        self.ngan_mask = ((s.wi[:, 2] >= math.cos(math.radians(NGAN_THETA_MAX_DEG)))
                          & (s.wo[:, 2] >= math.cos(math.radians(NGAN_THETA_MAX_DEG))))
        # the weights of the linear solve: Ngan's metric is over θ_i, θ_o ≤ 80° only, so its
        # solve is too (with all samples the "exact" projection was not: the Lafortune anchor
        # fits of red-plastic ended at L 0.0104 where their own shape's optimum is 0.0087)
        self.w_solve = (np.ascontiguousarray(self.w * self.ngan_mask) if loss == "ngan"
                        else self.w)
        self._w_solve_sum = float(np.sum(self.w_solve))
        self.albedo_t = None
        if loss == "perceptual":
            self._perceptual_albedo(target)

    def _perceptual_albedo(self, target) -> None:
        self._anodes = albedo_nodes(PERCEPTUAL_THETA_DEG, n_u=24, n_phi=12)
        wi, wo, wa, T = self._anodes
        self.albedo_t = albedo_from_values(self._values(target, wi, wo), wa, T)

    def perceptual(self, target) -> Problem:
        """This problem under the ``perceptual`` loss (the samples and target values
        shared, not evaluated again)."""
        if self.loss == "perceptual":
            return self
        other = copy.copy(self)
        other.loss = "perceptual"
        other._perceptual_albedo(target)
        return other

    # ------------------------------------------------------------------ evaluation
    def _values(self, m, wi, wo, *, per_channel: bool = True) -> np.ndarray:
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
        """(model, f·cos θ_i at the samples (N, C), or (N, 1) as :meth:`_values` says),
        or (None, None)."""
        m = self.build(values)
        if m is None:
            return None, None
        self.n_evals += 1
        return m, self._values(m, self.samples.wi, self.samples.wo,
                               per_channel=per_channel) * self.cos

    def loss_of(self, m, pred, loss: str | None = None) -> float:
        loss = loss or self.loss
        if pred is None or not np.all(np.isfinite(pred)):
            return math.inf
        am = None
        if loss == "perceptual":
            wi, wo, wa, T = self._anodes
            am = albedo_from_values(self._values(m, wi, wo), wa, T)
        return loss_value(loss, pred, self.y, self.w, ngan_mask=self.ngan_mask,
                          albedo_m=am, albedo_t=self.albedo_t)

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

    def solve_linear(self, f0, B, lo, hi, loss: str, *,
                     iterations: int = IRLS_ITERATIONS) -> tuple[np.ndarray, float | None]:
        """Per-channel linear parameters P (K, C) minimising the L1 (``l1``, at most
        *iterations* IRLS steps) or L2 (other losses) norm, and the loss at P for ``l1``,
        ``l2`` and ``ngan`` (None for the others: their value needs the prediction)
        (:func:`brdfkit.fitting._linear.solve_channels`)."""
        K = len(B)
        start = (self._warm if self._warm is not None and self._warm.shape == (K, self.C)
                 else np.empty((0, 0)))
        if f0 is self.static.get(""):  # a shape-independent offset: y − f₀ once
            if self._r_static is None:
                self._r_static = np.ascontiguousarray(self.y - f0)
            R = self._r_static
        else:
            R = np.ascontiguousarray(self.y - f0)
        P, total = solve_channels(np.stack(B), R, self.w_solve, lo, hi, loss == "l1", iterations,
                                  start)
        self._warm = P.copy()
        # the normalisation of losses.loss_value: Σ w |d| / (Σ w · C), for ngan over its
        # samples (w_solve) and its square root
        if loss not in ("l1", "l2", "ngan"):
            return P, None
        value = total / (self._w_solve_sum * self.C)
        return P, (math.sqrt(value) if loss == "ngan" else value)
