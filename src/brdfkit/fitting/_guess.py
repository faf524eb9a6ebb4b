"""
The first guess of a fit: the lobe width from the measured peak and a ladder
=============================================================================

Used by stage (i) of :func:`brdfkit.fitting.fit` (:mod:`brdfkit.fitting.procedure`).

- :func:`measured_half_width` — the half-width of the target's specular peak.
- :func:`with_width` — parameter values with the width parameter set from a half-width.
- :func:`scan_width` — the half-width of least loss among the measured one and
  :data:`BETA_LADDER_DEG`.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["BETA_LADDER_DEG", "measured_half_width", "with_width", "scan_width"]

#: Half-widths (degrees) scanned for the first guess of the width parameter (with the
#: measured one): mirror-like to broad, a factor 2 apart.
BETA_LADDER_DEG = (0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0)


def measured_half_width(target) -> float:
    """Half-width (rad, in θ_h) of the target's specular peak: the profile of f·cos θ_i
    along θ_h at θ_d = 5°, φ_d = 90°, minus its floor, falls to half its value at θ_h → 0
    (the first bin centre). π/4 when there is no peak (a diffuse target)."""
    from brdfkit.data.merl import half_diff_to_directions

    u = (np.arange(90) + 0.5) / 90.0
    th = u * u * (0.5 * math.pi)
    wi, wo = half_diff_to_directions(th, np.full_like(th, math.radians(5.0)),
                                     np.full_like(th, 0.5 * math.pi))
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    wo /= np.linalg.norm(wo, axis=1, keepdims=True)
    f = np.asarray(target.eval(wi, wo)).reshape(90, -1).mean(axis=1)
    f = np.nan_to_num(f, nan=0.0)
    floor = float(np.min(f))
    peak = float(f[0]) - floor
    if not peak > 0.0:
        return math.pi / 4
    below = np.nonzero(f - floor < 0.5 * peak)[0]
    return float(th[below[0]]) if below.size else math.pi / 4


def with_width(values, wp, width_from_beta, beta):
    """*values* with the width parameter set from half-width *beta* (radians)."""
    # β clamped to (0, π/2) open, as width_from_beta requires: 1e-4 rad is a mirror-like
    # lobe, 1.4 rad (80°) a broad one
    w0 = float(width_from_beta(min(max(beta, 1e-4), 1.4)))
    out = dict(values)
    out[wp] = np.full(np.shape(values[wp]), w0) if np.ndim(values[wp]) else w0
    return out


def scan_width(values, wp, width_from_beta, beta, loss_of):
    """The first guess of the width: the measured half-width *beta* and the ladder
    :data:`BETA_LADDER_DEG`, each with the linear parameters solved (*loss_of*); the one of
    least loss. A measured peak can mislead (two-layer-silver: a mirror-like spike of its
    clear coat on a broad lobe gives s ≈ 10⁶, a local optimum far from the broad lobe)."""
    tried = []
    for b in (beta, *np.radians(BETA_LADDER_DEG)):
        v = with_width(values, wp, width_from_beta, float(b))
        tried.append((loss_of(v), math.degrees(float(b)), v))
    best = min(tried, key=lambda t: t[0])
    return best[2], [{"beta_deg": b, "loss": val} for val, b, _ in tried]
