"""
The scale a pumped model does not see
=====================================

With g₁ = max(a(L), a(V)) (Neumann et al. 1999, eq. 20) and a root that is
linear in its colour parameters (modified Phong: f = ρ_d/π + ρ_s·lobe, so
a = ρ_d + ρ_s·a_s), scaling all linear parameters of a channel by t scales f
and g alike: f* = f/g does not change (the cap g ≤ 1 never acts, since it
applies only when a ≤ 1 everywhere). The pumped model sees only the ratios of
the linear parameters (for the Phong family its albedo at normal incidence,
where a peaks, is exactly 1 — ``docs/pumping.md``), so a fit that frees all
of them has a flat direction per channel: the optimiser drifts along it and
stops wherever a bound meets it, reporting a bound that means nothing.

:func:`hold_scale` tests this on the samples (the fit's prediction with all
linear parameters halved is the same to :data:`SCALE_RTOL`) and holds, per
channel, the largest linear parameter at its current value (the others then
carry the ratios, from 0 up to 1/(held value) ≥ 1 of it). The controlled g₂
(eq. 21, g ≥ N·L, N·V) is not scale-invariant where a < cos θ, and nothing is
held.
"""

from __future__ import annotations

import numpy as np

__all__ = ["SCALE_RTOL", "hold_scale"]

#: Relative agreement (largest difference over the largest value) of the predictions at
#: the linear parameters and at half of them that makes the common scale unobservable.
#: The surrogate's f/g is homogeneous to rounding; the exact model's to its tables' margins
#: (measured 7e-5 for modified Phong, n = 300); a real dependence changes the prediction by
#: O(1) somewhere (g2: a factor 2 where a/2 < cos θ).
SCALE_RTOL = 1e-3


def hold_scale(prob, values: dict, coords: list, linear) -> list:
    """Labels of the coordinates to hold (one per channel), or [] (module docstring).

    Parameters
    ----------
    prob : Problem
        The fit's problem (its model the pumped model or its surrogate).
    values : dict
        The current parameter values.
    coords : list of Coord
        The free coordinates.
    linear : sequence of str
        The root's linear (colour) parameters.
    """
    free = [c for c in coords if c.name in set(linear)]
    if not free:
        return []
    half = dict(values)
    for n in linear:
        if values[n] is None:
            continue  # an optional colour parameter not given (a microfacet's eta: F = 1)
        half[n] = np.asarray(values[n], dtype=np.float64) * 0.5 \
            if np.ndim(values[n]) else 0.5 * float(values[n])
    _, p1 = prob.predict(values)
    _, p2 = prob.predict(half)
    if p1 is None or p2 is None or not np.all(np.isfinite(p1)):
        return []
    scale = float(np.max(np.abs(p1)))
    if not (scale > 0.0 and float(np.max(np.abs(p1 - p2))) <= SCALE_RTOL * scale):
        return []
    held = []
    for ch in sorted({c.index for c in free}, key=lambda i: -1 if i is None else i):
        cs = [c for c in free if c.index == ch]
        big = max(cs, key=lambda c: float(np.ravel(values[c.name])[c.index or 0]))
        held.append(big.label)
    return held
