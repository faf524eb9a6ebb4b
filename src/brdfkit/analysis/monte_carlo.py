"""
Directional albedo by importance-sampled Monte Carlo (a second method)
=====================================================================

The cross-check of the albedo engine (:func:`brdfkit.analysis.albedo`): an unbiased
estimate with its standard error, from the model's own sampler mixed with cosine
sampling. It shares nothing with the engine's quadrature (nodes, panels, kinks), only the
evaluation of f_r (:func:`~brdfkit.analysis.albedo_engine.evaluate_pairs`), so agreement
within a few standard errors is evidence for both (``tests/test_albedo.py``); it also
tests the samplers (a biased sampler disagrees). Its result is an
:class:`~brdfkit.analysis.albedo_engine.AlbedoResult` with the same status codes.

Public objects
--------------
- :func:`albedo_mc` — importance-sampled Monte-Carlo albedo with its standard error.
"""

from __future__ import annotations

import math

import numpy as np

from brdfkit.analysis.albedo_engine import (
    CONVERGED,
    NONFINITE,
    AlbedoResult,
    _broadcast_angles,
    _check_model,
    check_phi,
    check_theta,
    evaluate_pairs,
    incident,
)
from brdfkit.errors import ParameterError
from brdfkit.models._base import BRDF

__all__ = ["albedo_mc"]


def _check_rng(rng) -> np.random.Generator:
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None or (isinstance(rng, int | np.integer) and not isinstance(rng, bool)
                       and rng >= 0):
        return np.random.default_rng(rng)
    raise ParameterError(f"rng must be a seed (an integer >= 0), a numpy.random.Generator "
                         f"or None; got {type(rng).__name__} {rng!r}")


def albedo_mc(model, theta_i, *, phi=0.0, n_samples: int = 100_000, rng=None,
              defensive: float = 0.1) -> AlbedoResult:
    """Importance-sampled Monte-Carlo albedo with its standard error.

    Directions are drawn from the mixture (1 − δ)·model.sample(·| ω_i) + δ·cos θ/π
    (δ = ``defensive``; the cosine part keeps the estimator unbiased where the
    model's sampler misses part of the support), and the estimator is
    f(ω_i, ω) cos θ / pdf_mix(ω). Callables use cosine sampling only.

    Parameters
    ----------
    model : BRDF or callable
    theta_i : float or array_like
        Radians in [0, π/2).
    phi : float or array_like, keyword-only
        Incidence azimuth in radians (any finite value, broadcast with *theta_i*; default
        0), applied to every model (ω_i = (sin θ cos φ, sin θ sin φ, cos θ)).
    n_samples : int, keyword-only
        Samples per angle (≥ 2).
    rng : int or numpy.random.Generator, keyword-only
        Seed or generator (required for reproducibility; None draws fresh entropy).
    defensive : float, keyword-only
        Weight of the cosine component in (0, 1].

    Returns
    -------
    AlbedoResult
        ``error`` is the standard error of the mean (1σ); status NONFINITE
        (albedo NaN) where a sample's value was NaN or infinite.
    """
    from brdfkit.geometry import pdf_cosine_hemisphere, sample_cosine_hemisphere

    _check_model(model, "albedo_mc")
    th, ph = _broadcast_angles(check_theta(theta_i), check_phi(phi))
    if isinstance(n_samples, bool) or not isinstance(n_samples, int | np.integer) \
            or n_samples < 2:
        raise ParameterError(f"n_samples must be an integer >= 2; got {n_samples!r}")
    n_samples = int(n_samples)
    try:
        defensive = float(defensive)
    except (TypeError, ValueError):
        defensive = float("nan")
    if not (0.0 < defensive <= 1.0):
        raise ParameterError(f"defensive must lie in (0, 1]; got {defensive!r}")
    gen = _check_rng(rng)
    has_sampler = isinstance(model, BRDF) and model.has_sampler
    if not has_sampler:
        defensive = 1.0
    vals_a, vals_e, status = [], [], []
    for theta, azimuth in zip(th.reshape(-1), ph.reshape(-1), strict=True):
        wi = incident(theta, azimuth)
        u = gen.random((n_samples, 2))
        pick = gen.random(n_samples) < defensive
        w = sample_cosine_hemisphere(u)
        if has_sampler:
            ws, _ = model.sample(np.broadcast_to(wi, (n_samples, 3)), u)
            w = np.where(pick[:, None], w, ws)
        wib = np.broadcast_to(wi, w.shape)
        pdf = defensive * pdf_cosine_hemisphere(w)
        if has_sampler:
            pdf = pdf + (1.0 - defensive) * model.pdf(w, wib)
        up = (w[:, 2] > 0.0) & (pdf > 0.0)
        w_safe = np.where(up[:, None], w, np.array([0.0, 0.0, 1.0]))
        f = evaluate_pairs(model, wib, w_safe)
        est = np.where(up[:, None], f * (w_safe[:, 2] / np.where(up, pdf, 1.0))[:, None], 0.0)
        ok = bool(np.all(np.isfinite(est)))
        vals_a.append(est.mean(axis=0) if ok else np.full(est.shape[1], np.nan))
        vals_e.append(est.std(axis=0, ddof=1) / math.sqrt(n_samples) if ok
                      else np.full(est.shape[1], np.inf))
        status.append(CONVERGED if ok else NONFINITE)
    a = np.array(vals_a)
    e = np.array(vals_e)
    extra = model.specular_albedo(th.reshape(-1)) if isinstance(model, BRDF) else None
    if extra is not None:
        a = a + np.asarray(extra, dtype=np.float64).reshape(a.shape[0], -1)
    status = np.array(status, dtype=np.int8).reshape(th.shape)
    coloured = model.n_channels is not None if isinstance(model, BRDF) else a.shape[1] > 1
    aniso = {"phi": ph, "anisotropic": isinstance(model, BRDF) and not model.isotropic}
    if not coloured and a.shape[1] == 1:
        return AlbedoResult(th.copy(), a[:, 0].reshape(th.shape), e[:, 0].reshape(th.shape),
                            status, **aniso)
    return AlbedoResult(th.copy(), a.reshape(th.shape + (-1,)), e.reshape(th.shape + (-1,)),
                        status, **aniso)
