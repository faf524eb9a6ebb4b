"""
A closed-form importance sampler for models that have none: the proxy mixture
==============================================================================

A user's model (a ``.brdf`` file, a Python file) is a formula for f_r and
nothing else. NumPy's engines sample it from its own values (the tabulated
half-vector sampler of :mod:`brdfkit.data.sampler`); Mitsuba's traced route
needs the sampler *as formulas* (:mod:`brdfkit._dual`) so that Dr.Jit traces
it into the kernel with f_r. This module gives one, built from what every
model declares — its sharpest lobe (:meth:`~brdfkit.models.BRDF.sharpest_lobe`):

    p(ω_i | ω_o) = w_c · cos⁺θ_i/π + (1 − w_c) · D(h) cos θ_h / (4 |ω_o·h|),

a defensive mixture (Hesterberg 1995) of the cosine-weighted hemisphere and
GGX half-vector sampling (Walter et al. 2007, eqs. 35 and 14: the very
formulas of ``microfacet``, :func:`~brdfkit.models.microfacet.walter_sample`
and :func:`~brdfkit.models.microfacet.walter_pdf`, with GGX), whose α is
derived from the lobe:

============  ======================================================================
lobe kind     proxy
============  ======================================================================
``half``      α = GGX's α whose D falls to half its peak at the lobe's half-width β
              (:func:`brdfkit.halfangle.trowbridge_reitz_c_from_beta`: Lewis's D₃
              is the GGX lobe), clamped to [:data:`ALPHA_MIN`, 2^(−1/4)); w_c =
              :data:`COSINE_WEIGHT`
``mirror``    the same with β/2 (a lobe about the mirror direction of half-width β
              in ω_i has half vectors within ≈ β/2 of the normal: ω_i turns twice as
              fast as h, as :func:`brdfkit.analysis.chi2.lobe_axis_and_width` reads it)
``diffuse``,  the cosine alone (w_c = 1): a broad lobe, or one about the normal, which
``normal``    a half-vector lobe does not follow for oblique views
============  ======================================================================

The component is chosen from u₀ as :class:`brdfkit.models.sampling.Mixture`
does (the cosine when u₀ < w_c, u₀ rescaled into its component's interval),
with both components evaluated and :func:`~brdfkit._dual.select` (the formula
contract forbids branches on values). The density is over the whole sphere of
ω_i (GGX directions reached with ω_o·h < 0, or below the horizon, are
discarded by the caller, as for ``microfacet``); 0 when ω_o is at or below the
horizon.

Why w_c = :data:`COSINE_WEIGHT` = 0.2, measured (``benchmarks/bench_user_render.py
--weights``: standard deviation per sample of the albedo estimator f cos θ_i/p, 400 000
samples at θ_o = 0°, 45°, 80°, w_c from 0.02 to 0.5): the cosine part bounds the weight
by π f/w_c wherever the GGX part misses (a diffuse base the sharpest lobe does not name,
a lobe narrower than declared) and costs at most a factor 1/(1 − w_c) in the pdf of a
lobe the GGX part matches. Over four cases (GGX α = 0.2 with the exact proxy; the same
plus a Lambertian 0.3; a proxy 2× too wide; 2× too narrow) the worst ratio of the
standard deviation to the best w_c of its row is 1.36 at w_c = 0.2 (the exact proxy at
θ_o = 0°, where 0.02 is best), 1.37 at 0.15, 1.71 at 0.1 (GGX + Lambert at 45°, where
0.3 is best) and 1.69 at 0.3: 0.15–0.2 is the minimax, and 0.2 favours what user files
usually are, a glossy lobe over a diffuse base.

Layer 1 (docs/architecture.md): it needs only the model protocol and ``microfacet``'s
formulas, so the data layer's measured materials and surrogates use it as the user's
models do; the same on NumPy arrays, :class:`brdfkit.user.proxy_sampler.ProxyStrategy`,
runs through the user layer's generated sampler loops.

Public objects
--------------
- :func:`proxy_formulas` — a model's :class:`~brdfkit._dual.Formulas`: its own
  kernel, the proxy's sampler and pdf, ``args = (alpha, w_c)``.
- :func:`proxy_args` — ``(alpha, w_c)`` of a model (from its sharpest lobe).
- :func:`proxy_sample`, :func:`proxy_pdf` — the sampler and its density, formulas
  (Numba functions; their Dr.Jit versions by :func:`brdfkit._dual.drjit_version`).
- :data:`COSINE_WEIGHT`, :data:`ALPHA_MIN`.

References
----------
- T. Hesterberg, *Weighted Average Importance Sampling and Defensive Mixture
  Distributions*, Technometrics 37(2), 1995.
- B. Walter, S. Marschner, H. Li, K. Torrance, *Microfacet Models for Refraction
  through Rough Surfaces*, EGSR 2007, eqs. (14), (33), (35).
- T. Malley, 1988 (cosine sampling by lifting the unit disk).
- [Lewis1993] §3.2 (the half-angle of D₃, the GGX lobe).
"""

from __future__ import annotations

import math

from brdfkit._dual import Formulas, formula, maximum, minimum, select
from brdfkit.errors import ParameterError
from brdfkit.halfangle import trowbridge_reitz_c_from_beta
from brdfkit.models.microfacet import walter_pdf, walter_sample
from brdfkit.models.sampling import malley

__all__ = ["proxy_formulas", "proxy_args", "proxy_sample", "proxy_pdf", "COSINE_WEIGHT",
           "ALPHA_MIN"]

#: Weight of the cosine component (module docstring: the measurement behind it).
COSINE_WEIGHT = 0.2
#: Smallest proxy α: narrower lobes are sampled with this one (Mitsuba clamps its own
#: microfacet α at 1e-4 too; below it float32 half vectors no longer resolve the lobe).
ALPHA_MIN = 1e-4
#: The α of a pure-cosine proxy (w_c = 1): unused, any finite value keeps the discarded
#: GGX lanes finite.
ALPHA_DIFFUSE = 1.0
#: Largest half-width converted: D₃'s half-angle exists for β < π/2 only (α → 2^(−1/4)).
_BETA_MAX = 0.5 * math.pi - 1e-6
INV_PI = 1.0 / math.pi
#: Floor of the GGX component's weight 1 − w_c as a divisor: w_c = 1 rescales u₀ to
#: −inf/… in the discarded GGX lane, then clamped to 0 (finite); 1e-30 is a normal
#: float32 number, so the floor holds in Mitsuba's single-precision variants too.
_TINY = 1e-30


def proxy_args(model) -> tuple[float, float]:
    """``(alpha, w_c)`` of the proxy for *model*, from ``model.sharpest_lobe()`` (module
    docstring: half → α of the half-width, mirror → of half the width, else the cosine)."""
    lobe = model.sharpest_lobe()
    if lobe.kind == "half":
        beta = float(lobe.width)
    elif lobe.kind == "mirror":
        beta = 0.5 * float(lobe.width)  # ω_i turns twice as fast as h about the mirror
    else:
        return ALPHA_DIFFUSE, 1.0
    beta = min(beta, _BETA_MAX)  # sharpest_lobe gives (0, π/2]; π/2 itself has no D₃ β
    return max(float(trowbridge_reitz_c_from_beta(beta)), ALPHA_MIN), COSINE_WEIGHT


def proxy_formulas(model) -> Formulas:
    """*model*'s formulas for the Mitsuba traced route: ``eval`` its own ``kernel`` (a
    formula over its packed row), ``sample``/``pdf`` the proxy mixture, ``args`` from
    :func:`proxy_args`."""
    kernel = model.kernel
    if kernel is None:
        raise ParameterError(f"proxy_formulas: {model.name} has no kernel (a formula of "
                             "(ix, iy, iz, ox, oy, oz, p)) to trace")
    return Formulas(eval=kernel, sample=proxy_sample, pdf=proxy_pdf, args=proxy_args(model))


# --------------------------------------------------------------------------- the formulas
@formula
def proxy_sample(ox, oy, oz, u0, u1, alpha, w_c):
    """ω_i from (u₀, u₁) ∈ [0, 1)²: the cosine when u₀ < w_c, else GGX half-vector
    sampling (:func:`~brdfkit.models.microfacet.walter_sample`), u₀ rescaled into the
    chosen component's interval (both evaluated, :func:`~brdfkit._dual.select`)."""
    pick_cos = u0 < w_c
    uc = minimum(u0 / w_c, 1.0)  # clamp: rounding of the rescaled u₀
    ug = maximum((u0 - w_c) / maximum(1.0 - w_c, _TINY), 0.0)  # ≥ 0: see _TINY
    cx, cy, cz = malley(uc, u1)
    gx, gy, gz = walter_sample(ox, oy, oz, ug, u1, alpha, True)
    return select(pick_cos, cx, gx), select(pick_cos, cy, gy), select(pick_cos, cz, gz)


@formula
def proxy_pdf(ix, iy, iz, ox, oy, oz, alpha, w_c):
    """Solid-angle density of :func:`proxy_sample` over the sphere of ω_i:
    w_c cos⁺θ_i/π + (1 − w_c) D(h) cos θ_h/(4|ω_o·h|); 0 when ω_o is at or below
    the horizon."""
    pc = maximum(iz, 0.0) * INV_PI
    pg = walter_pdf(ix, iy, iz, ox, oy, oz, alpha, True)
    return select(oz > 0.0, w_c * pc + (1.0 - w_c) * pg, 0.0)
