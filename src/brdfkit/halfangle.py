"""
Half-angle conversions
======================

Lewis (1993) characterises every lobe by its half-angle β: the angle at which
the lobe "drops to half its peak" (Lewis §3.1, after Blinn 1977). Each
function here converts β (radians) to a model's width parameter, derived from
that definition.

Public objects
--------------
- :func:`exponent_from_beta`, :func:`beta_from_exponent` — cosⁿβ = 1/2.
"""

from __future__ import annotations

import numpy as np

__all__ = ["exponent_from_beta", "beta_from_exponent"]


def _check_beta(beta) -> np.ndarray:
    b = np.asarray(beta, dtype=np.float64)
    if np.any(~((b > 0.0) & (b < np.pi / 2))):
        raise ValueError(f"beta (half-angle) must lie in (0, pi/2) radians; got {beta!r}")
    return b


def exponent_from_beta(beta):
    """Phong/Blinn exponent (and Lewis's c₁) with cosⁿβ = 1/2: n = −ln 2 / ln cos β."""
    b = _check_beta(beta)
    return -np.log(2.0) / np.log(np.cos(b))


def beta_from_exponent(n):
    """Inverse of :func:`exponent_from_beta`: β = arccos(2^(−1/n))."""
    n = np.asarray(n, dtype=np.float64)
    if np.any(~(n > 0.0)):
        raise ValueError(f"n must be > 0; got {n!r}")
    return np.arccos(2.0 ** (-1.0 / n))
