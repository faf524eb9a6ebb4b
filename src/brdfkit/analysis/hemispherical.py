"""
Hemispherical–hemispherical albedo ρ_hh (an outer rule over the albedo engine)
=============================================================================

ρ_hh = (1/π) ∫ a(ω_i) cos θ_i dω_i, the fraction of uniform incident radiance that is
reflected. With μ = cos θ_i = u², ρ_hh = ∫₀¹ a(μ) 2μ dμ = ∫₀¹ 4 a(u²) u³ du, computed
with n-point Gauss–Legendre in u (smooth even when a ∝ μ^−p near grazing) over the
directional albedos of the one engine (:func:`brdfkit.analysis.albedo`), and the
n/2-point rule for the error estimate.

An anisotropic model (``isotropic`` False) has a(θ_i, φ_i): ρ_hh = ∫₀¹ 4 ā(u²) u³ du with
ā(θ_i) = (1/2π) ∫ a(θ_i, φ_i) dφ_i, the mean over the incidence azimuth by the
trapezoidal rule on ``n_phi`` equally spaced azimuths (spectrally accurate for a smooth
periodic function); the rule on every other azimuth adds its difference to the error
estimate. An isotropic model's albedo does not depend on φ_i (one azimuth).

Public objects
--------------
- :class:`HemisphericalAlbedo` — value, error estimate, status (``brdfkit.status``, kind
  ``hemispherical``), ``success``, ``message``.
- :func:`hemispherical_albedo` — compute it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from brdfkit.analysis.albedo_engine import NONFINITE, _check_model, albedo
from brdfkit.errors import ParameterError
from brdfkit.models._base import BRDF
from brdfkit.status import STATUS

__all__ = ["HemisphericalAlbedo", "hemispherical_albedo"]

_CODES = STATUS["hemispherical"]


@dataclass(frozen=True)
class HemisphericalAlbedo:
    """ρ_hh of one model.

    Attributes
    ----------
    value : ndarray
        ρ_hh: 0-d, or (C,) for coloured models.
    error : ndarray
        Absolute error estimate, same shape (inf when a directional albedo did not
        converge: its estimate is not a bound).
    n : int
        Nodes of the outer Gauss–Legendre rule.
    status : int
        ``STATUS["hemispherical"]``: converged (0), limit (1: a directional albedo did
        not converge), nonfinite (3: a directional albedo is NaN).
    detail : str
        The engine's message when it did not converge (empty otherwise).
    """

    value: np.ndarray
    error: np.ndarray
    n: int
    status: int = 0
    detail: str = ""

    @property
    def success(self) -> bool:
        return _CODES.success(self.status)

    @property
    def message(self) -> str:
        """The status table's message, with the engine's when it did not converge."""
        return _CODES.describe(self.status, self.detail)

    def to_dict(self) -> dict:
        """JSON-ready: value and error (lists when coloured), n, status, success, message."""
        return {"value": np.asarray(self.value).tolist(),
                "error": np.asarray(self.error).tolist(), "n": self.n,
                "status": int(self.status), "success": self.success, "message": self.message}


def hemispherical_albedo(model, *, n: int = 48, n_phi: int = 16,
                         tol: float = 1e-7) -> HemisphericalAlbedo:
    """Hemispherical–hemispherical albedo ρ_hh = (1/π) ∫ a(ω_i) cos θ_i dω_i.

    With μ = cos θ_i = u², ρ_hh = ∫₀¹ a(μ) 2μ dμ = ∫₀¹ 4 a(u²) u³ du, computed with
    n-point Gauss–Legendre in u (smooth even when a ∝ μ^−p near grazing), and the
    n/2-point rule for the error estimate.

    Parameters
    ----------
    model : BRDF or callable
    n : int, keyword-only
        Nodes of the outer rule, in [2, 1000].
    n_phi : int, keyword-only
        Incidence azimuths of an anisotropic model's mean over φ_i (an even number in
        [2, 1000]; unused for isotropic models and callables, which are taken at φ_i = 0).
    tol : float, keyword-only
        Accuracy goal of each directional albedo.

    Returns
    -------
    HemisphericalAlbedo
        ``value`` and ``error`` (scalars or (C,) for coloured models); the error is
        |n-point − n/2-point| plus the weighted engine errors, infinite when an albedo
        did not converge (``status`` limit, or nonfinite when it is NaN).
    """
    _check_model(model, "hemispherical_albedo")
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or not 2 <= n <= 1000:
        # the n/2-point rule gives the error estimate, so n >= 2; 1000 nodes: far beyond the
        # accuracy of the albedo itself (a is smooth in u = sqrt(cos theta_i))
        raise ParameterError(f"hemispherical_albedo: n must be an integer in [2, 1000]; "
                             f"got {n!r}")
    if (isinstance(n_phi, bool) or not isinstance(n_phi, int | np.integer)
            or not 2 <= n_phi <= 1000 or n_phi % 2):
        # even: the rule on every other azimuth gives the error estimate
        raise ParameterError(f"hemispherical_albedo: n_phi must be an even integer in "
                             f"[2, 1000]; got {n_phi!r}")
    x, w = np.polynomial.legendre.leggauss(int(n))
    x2, w2 = np.polynomial.legendre.leggauss(int(n) // 2)
    us = np.concatenate([(x + 1) / 2, (x2 + 1) / 2])
    th = np.arccos(np.clip(us * us, 0.0, 1.0))
    th = np.minimum(th, math.pi / 2 - 1e-12)  # the node nearest grazing stays inside [0, π/2)
    azimuthal = isinstance(model, BRDF) and not model.isotropic
    n_az = int(n_phi) if azimuthal else 1
    phis = 2.0 * math.pi * np.arange(n_az) / n_az
    r = albedo(model, th[:, None], phi=phis[None, :], tol=tol)
    a_all = np.asarray(r.albedo)  # (angles, azimuths[, C])
    a = a_all.mean(axis=1)  # the trapezoidal rule of a periodic function
    # its error: the rule on every other azimuth (no extra evaluation)
    e_phi = np.abs(a - a_all[:, ::2].mean(axis=1)) if azimuthal else np.zeros_like(a)
    wt = 4.0 * us ** 3
    wt = wt.reshape(wt.shape + (1,) * (a.ndim - 1))
    aw = a * wt
    v1 = np.tensordot(w / 2, aw[: len(x)], axes=(0, 0))
    v2 = np.tensordot(w2 / 2, aw[len(x):], axes=(0, 0))
    ew = (np.asarray(r.error).max(axis=1) + e_phi)[: len(x)] * wt[: len(x)]
    err = np.abs(v1 - v2) + np.tensordot(w / 2, ew, axes=(0, 0))
    status, detail = _CODES.CONVERGED, ""
    if not r.success:  # an unconverged angle's estimate is not a bound
        err = np.full_like(err, np.inf)
        status = _CODES.NONFINITE if np.any(r.status == NONFINITE) else _CODES.LIMIT
        detail = r.message
    return HemisphericalAlbedo(value=v1, error=err, n=int(n), status=int(status),
                               detail=detail)
