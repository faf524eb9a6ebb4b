"""
Importance-sampling strategies
==============================

One set of composable strategies from which the models' :meth:`~brdfkit.models.BRDF.sample`
and :meth:`~brdfkit.models.BRDF.pdf` are built. A strategy draws ω_i for given
ω_o from two uniform numbers per sample and states the solid-angle density of
what it draws over the *whole sphere* of ω_i (a strategy may draw directions
below the horizon; the BRDF is 0 there and the caller discards them):

- :class:`Cosine` — cos θ_i/π about the normal (Malley's method); the
  fallback of :class:`~brdfkit.models.BRDF`.
- :class:`CosPowerNormal` — (q+1)/(2π) cos^q θ_i about the normal (q > −1),
  upper hemisphere: separable models peaked at the normal (Minnaert,
  Neumann–Neumann).
- :class:`CosPowerAxis` — (n+1)/(2π) max(0, cos α)ⁿ about an axis that
  depends on ω_o: the mirror direction of ω_o (Phong's R·V lobe) or any other
  (Lafortune's (C_xy o_x, C_xy o_y, C_z o_z)).
- :class:`HalfVector` — a half vector h drawn about the normal from a
  :class:`HalfVectorDistribution`, ω_i the mirror of ω_o about h; density
  p_h(h)/(4|ω_o·h|) (the Jacobian of ω_i = 2(ω_o·h)h − ω_o). Distributions:
  :class:`PowerHalf` ((N·H)ⁿ, Blinn) here; Beckmann and GGX are the
  distribution objects of :mod:`brdfkit.models.microfacet_distributions`
  (each holds D, its sampler and pdf; Walter et al. 2007).
- :class:`Mixture` — Σ_k w_k p_k with weights that may depend on ω_o.

:func:`phong_lobe` and :func:`blinn_lobe` build the lobe strategies (the
cosine for exponent 0, where the lobe is constant: 0⁰ = 1).

A model uses them through the mixin :class:`StrategySampled`: it defines
``_strategy(wo) -> Strategy``; ``sample`` and ``pdf`` validate their
arguments, draw, and give density 0 when ω_o is below the horizon.

Random numbers: every strategy reads exactly (u₀, u₁) per sample. A
:class:`Mixture` picks component k from u₀ (the first k whose cumulative
weight exceeds u₀) and rescales u₀ to [0, 1) within that component's
interval, so a mixture consumes the same stream as one strategy.

The same as formulas (:mod:`brdfkit._dual`; Numba and Mitsuba's traced BSDFs):
:func:`malley` (the cosine), :func:`lobes_sample` and :func:`lobes_pdf` (the mixture
of the cosine, the cosⁿ lobe about the mirror of ω_o and the N·H lobe that the Phong
family's models sample: the directions of :class:`Mixture` of :data:`COSINE`,
:func:`phong_lobe` and :func:`blinn_lobe` for the same (u₀, u₁), and its density).

Lower-level functions (arrays in, arrays out, no validation):
:func:`sample_phong_lobe`, :func:`pdf_phong_lobe` (cosⁿ about an axis),
:func:`sample_blinn_lobe`, :func:`pdf_blinn_lobe` (N·H power through the
half vector), :func:`diffuse_fraction`, :func:`split_uniform`,
:func:`normalised_weights`, :func:`log_mixture_weights`.

References
----------
- T. Malley, 1988 (cosine sampling by lifting the unit disk).
- [Lafortune1994] E. P. Lafortune, Y. D. Willems, *Using the modified Phong
  reflectance model for physically based rendering*, 1994 (cosⁿ lobe sampling).
- [Walter2007] B. Walter et al., *Microfacet Models for Refraction through
  Rough Surfaces*, EGSR 2007, eqs. (28), (35), (14) (half-vector sampling and
  its Jacobian).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from brdfkit._array import as_directions, as_uniform, stack
from brdfkit._dual import absolute as abs_
from brdfkit._dual import cos, formula, maximum, minimum, power, select, sin, sqrt
from brdfkit.geometry import (
    local_to_world,
    pdf_cosine_hemisphere,
    reflect,
    sample_cosine_hemisphere,
)

__all__ = [
    "Strategy", "Cosine", "COSINE", "CosPowerNormal", "CosPowerAxis", "HalfVector",
    "HalfVectorDistribution", "PowerHalf", "Mixture",
    "StrategySampled", "phong_lobe", "blinn_lobe", "sample_phong_lobe", "pdf_phong_lobe",
    "sample_blinn_lobe", "pdf_blinn_lobe", "diffuse_fraction", "split_uniform",
    "normalised_weights", "log_mixture_weights", "malley", "half_pdf_terms",
    "cos_power_normal_sample",
    "cos_power_normal_pdf",
]

_NORMAL = np.array([0.0, 0.0, 1.0])


# --------------------------------------------------------------------------- functions
def sample_phong_lobe(axis: np.ndarray, n: float, u: np.ndarray) -> np.ndarray:
    """Direction about *axis* with density (n+1)/(2π) cosⁿα on the sphere.

    Inverting the CDF of cosⁿα sinα gives cos α = u₀^{1/(n+1)}.
    """
    cos_a = u[..., 0] ** (1.0 / (n + 1.0))
    sin_a = np.sqrt(np.maximum(0.0, 1.0 - cos_a * cos_a))  # clamp: rounding near cos_a = 1
    phi = 2.0 * np.pi * u[..., 1]
    local = stack(sin_a * np.cos(phi), sin_a * np.sin(phi), cos_a)
    return local_to_world(local, axis)


def pdf_phong_lobe(cos_alpha: np.ndarray, n: float) -> np.ndarray:
    """Density of :func:`sample_phong_lobe`, (n+1)/(2π) max(0, cos α)ⁿ."""
    return (n + 1.0) / (2.0 * np.pi) * np.maximum(cos_alpha, 0.0) ** n


def sample_blinn_lobe(wo: np.ndarray, n: float, u: np.ndarray) -> np.ndarray:
    """wi = mirror of *wo* about h, h drawn about the normal with density (n+1)/(2π) cosⁿθ_h.

    The map h ↦ wi = 2(wo·h)h − wo has Jacobian dω_i/dω_h = 4|wo·h|, so wi has
    density p_h/(4|wo·h|) (:func:`pdf_blinn_lobe`). Where wo·h < 0 the
    direction lands below the horizon (the BRDF is 0 there).
    """
    return HalfVector(PowerHalf(n)).sample(wo, u)


def pdf_blinn_lobe(wi: np.ndarray, wo: np.ndarray, n: float) -> np.ndarray:
    """Solid-angle density of :func:`sample_blinn_lobe` over the full sphere of wi."""
    return HalfVector(PowerHalf(n)).pdf(wi, wo)


def diffuse_fraction(rho_d, rho_s) -> float:
    """Probability of picking the diffuse lobe in a diffuse + specular mixture.

    Proportional to the channel-mean reflectances; 1/2 when both are zero.
    """
    d = float(np.mean(rho_d))
    s = float(np.mean(rho_s))
    return 0.5 if d + s <= 0.0 else d / (d + s)


def split_uniform(u0: np.ndarray, p: float) -> tuple[np.ndarray, np.ndarray]:
    """Pick the first lobe where u₀ < p and rescale u₀ to [0, 1) in both branches."""
    first = u0 < p
    if p <= 0.0:
        return np.zeros_like(u0, dtype=bool), u0
    if p >= 1.0:
        return np.ones_like(u0, dtype=bool), u0
    return first, np.where(first, u0 / p, (u0 - p) / (1.0 - p))


def normalised_weights(weights) -> np.ndarray:
    """Mixture weights: negative ones clipped to 0, scaled to sum 1 (all equal if none > 0)."""
    w = np.maximum(np.asarray(weights, dtype=np.float64), 0.0)
    s = float(np.sum(w))
    return np.full(w.shape, 1.0 / w.size) if s <= 0.0 else w / s


def _shape(wo: np.ndarray, u: np.ndarray) -> tuple[int, ...]:
    return np.broadcast_shapes(wo.shape[:-1], u.shape[:-1])


# --------------------------------------------------------------------------- strategies
class Strategy:
    """A sampling strategy: :meth:`sample` draws ω_i, :meth:`pdf` is its density.

    Both take broadcastable arrays (wo (..., 3), u (..., 2), wi (..., 3))
    that are already validated; ``sample`` returns ω_i of the broadcast
    shape, ``pdf`` the solid-angle density over the whole sphere (it does not
    test whether ω_o is above the horizon: :class:`StrategySampled` does).
    """

    def sample(self, wo: np.ndarray, u: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def pdf(self, wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
        raise NotImplementedError


class Cosine(Strategy):
    """cos θ_i/π on the upper hemisphere (Malley's method), independent of ω_o."""

    def sample(self, wo, u):
        return np.broadcast_to(sample_cosine_hemisphere(u), (*_shape(wo, u), 3))

    def pdf(self, wi, wo):
        return pdf_cosine_hemisphere(wi)

    def __repr__(self) -> str:
        return "Cosine()"


#: The cosine strategy (stateless; shared).
COSINE = Cosine()


class CosPowerNormal(Strategy):
    """(q+1)/(2π) cos^q θ_i on the upper hemisphere (q > −1): cos θ_i = u₀^{1/(q+1)}.

    The inverse CDF of cos^q θ sin θ, sampled in the local frame directly (the
    axis is the normal). Exact for f cos θ_i ∝ cos^q θ_i (Minnaert) and a
    dominating density for the Neumann–Neumann lacquer.
    """

    def __init__(self, q: float):
        self.q = float(q)

    def sample(self, wo, u):
        cos_t = u[..., 0] ** (1.0 / (self.q + 1.0))
        sin_t = np.sqrt(np.maximum(0.0, 1.0 - cos_t * cos_t))  # clamp: rounding at cos_t = 1
        phi = 2.0 * np.pi * u[..., 1]
        wi = stack(sin_t * np.cos(phi), sin_t * np.sin(phi), cos_t)
        return np.broadcast_to(wi, np.broadcast_shapes(wi.shape, wo.shape))

    def pdf(self, wi, wo):
        c = wi[..., 2]
        with np.errstate(divide="ignore"):
            p = (self.q + 1.0) / (2.0 * np.pi) * np.where(c > 0.0, c, 1.0) ** self.q
        return np.where(c > 0.0, p, 0.0)

    def __repr__(self) -> str:
        return f"CosPowerNormal({self.q:g})"


class CosPowerAxis(Strategy):
    """(n+1)/(2π) max(0, cos α)ⁿ about ``axis(wo)`` (:func:`sample_phong_lobe`).

    Parameters
    ----------
    n : float
        Exponent (> 0; use :func:`phong_lobe`, which gives the cosine for 0).
    axis : callable, optional
        ω_o (..., 3) → unit axis (..., 3); default: the mirror direction of ω_o
        (the Phong lobe, a function of R·V).
    """

    def __init__(self, n: float, axis: Callable[[np.ndarray], np.ndarray] | None = None):
        self.n = float(n)
        self.axis = axis

    def _axis(self, wo):
        return reflect(wo) if self.axis is None else self.axis(wo)

    def sample(self, wo, u):
        shape = (*_shape(wo, u), 3)
        return np.broadcast_to(
            sample_phong_lobe(np.broadcast_to(self._axis(wo), shape), self.n, u), shape)

    def pdf(self, wi, wo):
        return pdf_phong_lobe(np.sum(wi * self._axis(wo), axis=-1), self.n)

    def __repr__(self) -> str:
        return f"CosPowerAxis({self.n:g}{'' if self.axis is None else ', axis=...'})"


class HalfVectorDistribution:
    """A density p_h of half vectors (microfacet normals) about the normal.

    ``sample(u)`` returns unit vectors h (..., 3) in the upper hemisphere from
    uniform numbers u (..., 2); ``pdf(h)`` is their solid-angle density at unit
    vectors h (0 for h_z ≤ 0). Taking h itself (not cos θ_h) lets a
    distribution form tan²θ_h = |h_xy|²/h_z² without cancellation near the
    normal (the microfacet distributions do).
    """

    def sample(self, u: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def pdf(self, h: np.ndarray) -> np.ndarray:
        raise NotImplementedError


class PowerHalf(HalfVectorDistribution):
    """(n+1)/(2π) cosⁿθ_h: the Blinn (N·H)ⁿ lobe and Lewis's D₁; cos θ_h = u₀^{1/(n+1)}."""

    def __init__(self, n: float):
        self.n = float(n)

    def sample(self, u):
        return sample_phong_lobe(_NORMAL, self.n, u)

    def pdf(self, h):
        return pdf_phong_lobe(h[..., 2], self.n)

    def __repr__(self) -> str:
        return f"PowerHalf({self.n:g})"


class HalfVector(Strategy):
    """ω_i = 2(ω_o·h)h − ω_o with h drawn from *distribution*; density p_h(h)/(4|ω_o·h|).

    Where ω_o·h < 0 the direction lands below the horizon (the BRDF is 0
    there). ``fold`` chooses how :meth:`pdf` reads such directions back:
    True (default) takes the upper one of ±(ω_i + ω_o)/|ω_i + ω_o| as h, so
    the density is exact over the whole sphere; False takes
    (ω_i + ω_o)/|ω_i + ω_o| as it is, so directions reached with ω_o·h < 0
    get density 0 (they are then discarded like any other pdf-0 sample —
    the convention of the microfacet samplers).
    """

    def __init__(self, distribution: HalfVectorDistribution, *, fold: bool = True):
        self.distribution = distribution
        self.fold = bool(fold)

    def sample(self, wo, u):
        h = self.distribution.sample(u)
        h = np.broadcast_to(h, np.broadcast_shapes(h.shape, wo.shape))
        return 2.0 * np.sum(wo * h, axis=-1, keepdims=True) * h - wo

    def pdf(self, wi, wo):
        h = wi + wo
        norm = np.linalg.norm(h, axis=-1)
        ok = norm > 0.0
        h = h / np.where(ok, norm, 1.0)[..., None]
        if self.fold:
            # the sampled h is in the upper hemisphere; wi + wo is ±h, so take the upper one
            h = np.where(h[..., 2:3] < 0.0, -h, h)
        cos_oh = np.abs(np.sum(wo * h, axis=-1))
        ok &= cos_oh > 0.0
        p = self.distribution.pdf(h) / (4.0 * np.where(ok, cos_oh, 1.0))
        return np.where(ok, p, 0.0)

    def __repr__(self) -> str:
        return f"HalfVector({self.distribution!r}{'' if self.fold else ', fold=False'})"


class Mixture(Strategy):
    """Σ_k w_k p_k: component k drawn with probability w_k.

    Parameters
    ----------
    components : sequence of Strategy
    weights : array_like, shape (K,) or (..., K)
        Non-negative, summing to 1 (per ω_o when they depend on it: the
        leading axes broadcast against ω_o's). A zero-weight component is
        never drawn.
    """

    def __init__(self, components: Sequence[Strategy], weights):
        self.components = list(components)
        self.weights = np.asarray(weights, dtype=np.float64)
        if self.weights.shape[-1:] != (len(self.components),):
            raise ValueError(f"{len(self.components)} components but weights of shape "
                             f"{self.weights.shape}")

    def sample(self, wo, u):
        comps = self.components
        shape = _shape(wo, u)
        wo = np.broadcast_to(wo, (*shape, 3))
        u = np.broadcast_to(u, (*shape, 2))
        w = np.broadcast_to(self.weights, (*shape, len(comps)))
        cum = np.cumsum(w, axis=-1)
        u0 = u[..., 0]
        k = np.minimum(np.sum(cum <= u0[..., None], axis=-1), len(comps) - 1)
        # never pick a zero-weight component (u₀ = 1 or rounding in the cumulative sum)
        k = np.where(np.take_along_axis(w, k[..., None], -1)[..., 0] > 0.0, k,
                     np.argmax(w, axis=-1))
        lo = np.take_along_axis(cum - w, k[..., None], -1)[..., 0]
        wk = np.take_along_axis(w, k[..., None], -1)[..., 0]
        # rescale u₀ within the picked component's interval (clip: rounding)
        u0r = np.clip((u0 - lo) / np.where(wk > 0.0, wk, 1.0), 0.0, 1.0)
        ur = np.stack([u0r, u[..., 1]], axis=-1)
        wi = np.empty((*shape, 3))
        for j, comp in enumerate(comps):
            sel = k == j
            if np.any(sel):
                wi[sel] = np.broadcast_to(comp.sample(wo, ur), (*shape, 3))[sel]
        return wi

    def pdf(self, wi, wo):
        shape = np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1])
        w = np.broadcast_to(self.weights, (*shape, len(self.components)))
        p = np.zeros(shape)
        for j, comp in enumerate(self.components):
            wj = w[..., j]
            if np.any(wj > 0.0):
                p = p + wj * comp.pdf(wi, wo)
        return p

    def __repr__(self) -> str:
        return f"Mixture({self.components!r}, weights of shape {self.weights.shape})"


def phong_lobe(n: float, axis: Callable[[np.ndarray], np.ndarray] | None = None) -> Strategy:
    """The cosⁿ lobe about ``axis(wo)`` (default: the mirror of ω_o); the cosine for n = 0.

    A lobe with exponent 0 is constant over the hemisphere (0⁰ = 1), so
    f cos θ_i ∝ cos θ_i and the cosine samples it exactly.
    """
    return COSINE if n == 0.0 else CosPowerAxis(n, axis)


def blinn_lobe(n: float) -> Strategy:
    """The (N·H)ⁿ lobe through the half vector (:class:`PowerHalf`); the cosine for n = 0."""
    return COSINE if n == 0.0 else HalfVector(PowerHalf(n))


# --------------------------------------------------------------------------- models
class StrategySampled:
    """Mixin for models sampled by a :class:`Strategy` (put it before ``BRDF``).

    The model defines ``_strategy(wo) -> Strategy`` (*wo* validated, shape
    (..., 3); weights of a :class:`Mixture` may depend on it). :meth:`sample`
    and :meth:`pdf` follow the :class:`~brdfkit.models.BRDF` contract.
    """

    has_sampler = True

    def _strategy(self, wo: np.ndarray) -> Strategy:
        raise NotImplementedError

    def sample(self, wo, u):
        """Draw wi given wo from *u* ∈ [0, 1]² (..., 2); returns ``(wi, pdf)``."""
        wo = as_directions(wo, "wo")
        u = as_uniform(u)
        wi = self._strategy(wo).sample(wo, u)
        if not wi.flags.writeable:
            wi = wi.copy()  # a broadcast view: the caller gets its own array
        return wi, self.pdf(wi, wo)

    def pdf(self, wi, wo):
        """Solid-angle density of :meth:`sample`; 0 when wo is below the horizon."""
        wi = as_directions(wi, "wi")
        wo = as_directions(wo, "wo")
        p = self._strategy(wo).pdf(wi, wo)
        return np.where(wo[..., 2] > 0.0, p, 0.0)


def log_mixture_weights(logw: Sequence[np.ndarray]) -> np.ndarray:
    """Per-ω_o mixture weights from their logarithms (..., K), normalised without overflow.

    Where every weight is 0 (all logs −inf) the first component gets weight 1.
    """
    logw = np.stack(list(logw), axis=-1)
    top = np.max(logw, axis=-1, keepdims=True)
    none = ~np.isfinite(top)
    with np.errstate(invalid="ignore"):
        w = np.exp(logw - np.where(none, 0.0, top))
    w = np.where(none, np.eye(logw.shape[-1])[0], w)
    return w / np.sum(w, axis=-1, keepdims=True)


_PI = math.pi
_TWO_PI = 2.0 * math.pi  # a module constant: formulas read no attributes (brdfkit._dual)


@formula
def malley(u0, u1):
    """Malley's method as a formula (:mod:`brdfkit._dual`): a uniform point of the unit disk,
    radius √u₀ and angle 2πu₁, lifted to the hemisphere (density cos θ/π); the cosine
    component of the formula samplers (Disney, Ashikhmin–Shirley, the user models' proxy)."""
    r = sqrt(u0)
    phi = _TWO_PI * u1
    return r * cos(phi), r * sin(phi), sqrt(maximum(1.0 - u0, 0.0))  # clamp: rounding at the rim


@formula
def axis_lobe(ax, ay, az, n, u0, u1):
    """:func:`sample_phong_lobe` as a formula: cos α = u₀^{1/(n+1)} about the unit axis a,
    in the frame of :func:`brdfkit.geometry.frame_around` (Duff et al. 2017)."""
    cos_a = power(u0, 1.0 / (n + 1.0))
    sin_a = sqrt(maximum(0.0, 1.0 - cos_a * cos_a))  # clamp: rounding near cos_a = 1
    phi = _TWO_PI * u1
    lx = sin_a * cos(phi)
    ly = sin_a * sin(phi)
    sign = select(az >= 0.0, 1.0, -1.0)
    p = -1.0 / (sign + az)
    q = ax * ay * p
    return (lx * (1.0 + sign * ax * ax * p) + ly * q + cos_a * ax,
            lx * (sign * q) + ly * (sign + ay * ay * p) + cos_a * ay,
            lx * (-sign * ax) + ly * (-ay) + cos_a * az)


@formula
def _pick(u0, c, w, k):
    """Component k's share of u₀ in :func:`lobes_sample`: ((u₀ − (c_k − w_k))/w_k, clipped)."""
    return minimum(maximum((u0 - (c - w)) / select(w > 0.0, w, 1.0), 0.0), 1.0)


@formula
def lobes_sample(ox, oy, oz, u0, u1, w_c, w_p, w_b, n_p, n_b):
    """ω_i from (u₀, u₁) by :class:`Mixture` ([COSINE, phong_lobe(n_p), blinn_lobe(n_b)],
    weights (w_c, w_p, w_b)), a formula: the same pick and rescaled u₀ (the first component
    whose cumulative weight exceeds u₀; a zero-weight pick replaced by the largest weight),
    the same directions (all three evaluated, one selected; an exponent 0 is the cosine)."""
    c1 = w_c
    c2 = c1 + w_p
    c3 = c2 + w_b
    k = minimum(select(c1 <= u0, 1.0, 0.0) + select(c2 <= u0, 1.0, 0.0)
                + select(c3 <= u0, 1.0, 0.0), 2.0)
    wk = select(k == 0.0, w_c, select(k == 1.0, w_p, w_b))
    top = select((w_c >= w_p) & (w_c >= w_b), 0.0, select(w_p >= w_b, 1.0, 2.0))  # argmax
    k = select(wk > 0.0, k, top)
    ur = select(k == 0.0, _pick(u0, c1, w_c, k),
                select(k == 1.0, _pick(u0, c2, w_p, k), _pick(u0, c3, w_b, k)))
    cx, cy, cz = malley(ur, u1)
    # the cosⁿ lobe about the mirror of ω_o (reflect: (−o_x, −o_y, o_z))
    px, py, pz = axis_lobe(-ox, -oy, oz, n_p, ur, u1)
    # the N·H lobe: h about the normal (frame_around(+z) is the identity), ω_i its mirror
    hx, hy, hz = axis_lobe(0.0, 0.0, 1.0, n_b, ur, u1)
    d = 2.0 * (ox * hx + oy * hy + oz * hz)
    bx = d * hx - ox
    by = d * hy - oy
    bz = d * hz - oz
    cos_p = (k == 0.0) | ((k == 1.0) & (n_p == 0.0)) | ((k == 2.0) & (n_b == 0.0))
    lobe_p = k == 1.0
    return (select(cos_p, cx, select(lobe_p, px, bx)), select(cos_p, cy, select(lobe_p, py, by)),
            select(cos_p, cz, select(lobe_p, pz, bz)))


@formula
def half_pdf_terms(ix, iy, iz, ox, oy, oz):
    """(h_z, 4|ω_o·h|, ok) of :meth:`HalfVector.pdf` (fold): h the upper one of
    ±(ω_i + ω_o)/|ω_i + ω_o|; the density of a half-vector lobe p_h(h) is p_h/(4|ω_o·h|)
    where ok (a sum and a cosine > 0; elsewhere 0), the divisor 4 where not ok (finite)."""
    sx = ix + ox
    sy = iy + oy
    sz = iz + oz
    norm = sqrt(sx * sx + sy * sy + sz * sz)
    ok = norm > 0.0
    m = select(ok, norm, 1.0) * select(sz < 0.0, -1.0, 1.0)  # the upper h (fold)
    hx = sx / m
    hy = sy / m
    hz = sz / m
    cos_oh = abs_(ox * hx + oy * hy + oz * hz)
    ok = ok & (cos_oh > 0.0)
    return hz, 4.0 * select(ok, cos_oh, 1.0), ok


@formula
def lobes_pdf(ix, iy, iz, ox, oy, oz, w_c, w_p, w_b, n_p, n_b):
    """Density of :func:`lobes_sample` over the sphere (:meth:`Mixture.pdf`, 0 when ω_o is at
    or below the horizon): w_c cos⁺θ_i/π + w_p (n_p+1)/(2π) max(0, ω_i·R(ω_o))^{n_p}
    + w_b (n_b+1)/(2π) (N·h)^{n_b}/(4|ω_o·h|), h the upper one of ±(ω_i + ω_o)/|ω_i + ω_o|
    (:class:`HalfVector`, fold); an exponent 0 is the cosine's density."""
    p_cos = maximum(iz, 0.0) / _PI  # pdf_cosine_hemisphere's operations
    p_phong = (n_p + 1.0) / _TWO_PI * power(maximum(-ix * ox - iy * oy + iz * oz, 0.0), n_p)
    hz, denom, ok = half_pdf_terms(ix, iy, iz, ox, oy, oz)
    p_half = select(ok, (n_b + 1.0) / _TWO_PI * power(maximum(hz, 0.0), n_b) / denom, 0.0)
    p = (w_c * p_cos + w_p * select(n_p == 0.0, p_cos, p_phong)
         + w_b * select(n_b == 0.0, p_cos, p_half))
    return select(oz > 0.0, p, 0.0)



@formula
def cos_power_normal_sample(ox, oy, oz, u0, u1, q):
    """:class:`CosPowerNormal` ``(q)`` as a formula: cos θ_i = u₀^{1/(q+1)}, φ = 2πu₁ (the same
    directions as its ``sample``)."""
    cos_t = power(u0, 1.0 / (q + 1.0))
    sin_t = sqrt(maximum(0.0, 1.0 - cos_t * cos_t))  # clamp: rounding at cos_t = 1
    phi = _TWO_PI * u1
    return sin_t * cos(phi), sin_t * sin(phi), cos_t


@formula
def cos_power_normal_pdf(ix, iy, iz, ox, oy, oz, q):
    """Its density (q+1)/(2π) cos^q θ_i for θ_i < 90°, else 0; 0 when ω_o is at or below the
    horizon (:class:`StrategySampled`)."""
    up = iz > 0.0
    p = (q + 1.0) / _TWO_PI * power(select(up, iz, 1.0), q)  # 1: the discarded lane finite
    return select(up & (oz > 0.0), p, 0.0)
