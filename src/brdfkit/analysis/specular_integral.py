"""
Lewis's specular integral H_s (a second method beside the albedo engine)
=======================================================================

H_s(S) = ∫ F_s(S, V) (N·V) dω_V, the albedo of Lewis's specular function alone (§4.1,
Fig. 5), by the one H_s implementation of :mod:`brdfkit.models.specular` (azimuth in
closed form, tanh-sinh in the polar angle), not by the albedo engine; the tests compare
the two (``tests/test_models_phong.py``). Its result is an
:class:`~brdfkit.analysis.albedo_engine.AlbedoResult` with the ``albedo`` status codes.

Public objects
--------------
- :func:`H_s` — Lewis's specular integral with its error estimate.

References
----------
- [Lewis1993] eqs. (15)–(19), Fig. 5.
"""

from __future__ import annotations

import math

import numpy as np

from brdfkit.analysis.albedo_engine import (
    CONVERGED,
    MAX_LEVEL_REACHED,
    AlbedoResult,
    _check_tol,
    check_theta,
)
from brdfkit.errors import ParameterError
from brdfkit.models.specular import specular_integral_with_error

__all__ = ["H_s"]


def H_s(theta_i, n: float, *, lobe: str = "phong", tol: float = 1e-8) -> AlbedoResult:
    """Lewis's specular integral H_s(S) = ∫ F_s(S, V) (N·V) dω_V (§4.1, Fig. 5).

    The albedo of Lewis's specular function alone, computed by the one H_s
    implementation, :func:`brdfkit.models.specular.specular_integral_with_error`
    (azimuth in closed form, tanh-sinh in the polar angle; ~1e-11 relative),
    not by the albedo engine. (The engine gives the same numbers for the
    registered models whose BRDF is F_s itself: ``lafortune`` with ρ_d = 0,
    ρ_s = 1, C_xy = −1, C_z = 1 is F_s^P, ``phong-blinn-reciprocal`` with
    k_d = 0, k_s = 1 is F_s^B; the tests compare the two.)

    Parameters
    ----------
    theta_i : float or array_like
        Incidence angle(s) of S, radians in [0, π/2).
    n : float
        Specular exponent n_s ≥ 0.
    lobe : {"phong", "blinn"}, keyword-only
        F_s^P = max(0, R·V)^n (eq. 5) or F_s^B = (N·H)^n (eq. 6).
    tol : float, keyword-only
        Absolute accuracy goal (> 0). The quadrature's own accuracy (~1e-11
        relative, H_s ≤ π) meets any goal above ~1e-10; ``error`` states what
        was reached.

    Returns
    -------
    AlbedoResult
        ``albedo`` holds H_s, ``error`` its absolute error estimate (the
        difference from the rule of twice the step plus rounding, a bound in
        practice). Lewis eq. (19): k_ρ = k_d π + k_s H_s/(N·S). At θ_i = 0
        with the Phong lobe, H_s = 2π/(n + 2) (eq. 16 with γ = n + 1).
    """
    if lobe not in ("phong", "blinn"):
        raise ParameterError(f"lobe must be 'phong' or 'blinn'; got {lobe!r}")
    try:
        n_val = float(n)
    except (TypeError, ValueError):
        n_val = float("nan")
    if not (n_val >= 0.0 and math.isfinite(n_val)):
        raise ParameterError(f"n must be a finite number >= 0; got {n!r}")
    th = check_theta(theta_i)
    tol = _check_tol(tol)
    value, error = specular_integral_with_error(th, n_val, lobe)
    # the same goal as the engine's: the tolerance or 1e-10 relative
    met = np.asarray(error) <= np.maximum(tol, 1e-10 * np.abs(value))
    status = np.where(met, CONVERGED, MAX_LEVEL_REACHED).astype(np.int8)
    return AlbedoResult(theta=th.copy(), albedo=value, error=error, status=status)
