"""
The explorer's views, without a browser
=======================================

Each view is a function of a model and the shared incident direction
(θ_i, φ_i) returning JSON-ready data (lists) or a PNG: the web layer
(:mod:`brdfkit.explorer.app`) only draws them. Everything is evaluated with
the model's own compiled kernel — one formula, no shader copy.

Views
-----
==================  ============================================================
:func:`polar`       in-plane slice f(θ_o) in the plane of incidence, θ_o from
                    −90° (the light's side) to +90° (the mirror side)
:func:`lobe`        the 3-D lobe: r(ω_o) = f (or f·cos θ_o) over the hemisphere
:func:`curves`      f against θ_h (θ_d = θ_i, φ_d = 90°), against θ_d
                    (θ_h = 0) and against θ_o (the in-plane slice)
:func:`halfdiff`    θ_h × θ_d image at φ_d = 90° (log₁₀ f, the MERL layout)
:func:`sphere`      the lit sphere of the sphere test configuration (exact)
:func:`albedo_curve`  a(θ_i) at 90 angles to 1e-4 absolute, with its status
:func:`verdict`     the plausibility verdict (:func:`brdfkit.analysis.check`)
==================  ============================================================

Channels: ``"luminance"`` (Rec. 709 Y of RGB; the mean for other channel
counts, the value itself for grey models) or ``"rgb"`` (each channel).
``cosine=True`` multiplies by cos θ_o (the point-light response).
"""

from __future__ import annotations

import math

import numpy as np

from brdfkit.analysis import albedo, check
from brdfkit.colour import LUMINANCE
from brdfkit.errors import ParameterError
from brdfkit.geometry import from_rusinkiewicz, merl_theta_h

__all__ = ["polar", "lobe", "curves", "halfdiff", "sphere", "albedo_curve", "verdict",
           "channels", "png_bytes", "ALBEDO_TOL", "VERDICT_TOL", "LUMINANCE"]

#: Rec. 709 / sRGB luminance weights of linear R, G, B (re-exported from brdfkit.colour).
#: Absolute accuracy of the live albedo curve: below a pixel of a 0–1 plot a few hundred
#: pixels high, and 10-100x cheaper than the engine's 1e-7 default on glossy lobes.
ALBEDO_TOL = 1e-4


def _incident(theta_i: float, phi_i: float) -> np.ndarray:
    if not (0.0 <= theta_i < 0.5 * math.pi):
        raise ParameterError(f"theta_i must lie in [0, 90) degrees; got {math.degrees(theta_i):g}")
    return np.array([math.sin(theta_i) * math.cos(phi_i), math.sin(theta_i) * math.sin(phi_i),
                     math.cos(theta_i)])


def channels(values, mode: str = "luminance") -> list[list[float]]:
    """(N,) or (N, C) values → a list of curves: one (luminance) or one per channel."""
    v = np.asarray(values, dtype=np.float64)
    v = v.reshape(v.shape[0], -1) if v.ndim > 1 else v[:, None]
    if mode == "rgb" or v.shape[1] == 1:
        return [np.nan_to_num(v[:, c], nan=0.0).tolist() for c in range(v.shape[1])]
    if mode != "luminance":
        raise ParameterError(f"channel mode must be 'luminance' or 'rgb'; got {mode!r}")
    y = v @ LUMINANCE if v.shape[1] == 3 else v.mean(axis=1)
    return [np.nan_to_num(y, nan=0.0).tolist()]


def polar(model, theta_i: float, phi_i: float = 0.0, *, n: int = 181, cosine: bool = False,
          mode: str = "luminance") -> dict:
    """In-plane slice: ``{"theta_o_deg": [...], "values": [[...], ...]}``."""
    wi = _incident(theta_i, phi_i)
    t = np.radians(np.linspace(-89.5, 89.5, n))
    # positive θ_o on the mirror side: azimuth φ_i + π
    ph = phi_i + math.pi
    wo = np.stack([np.sin(t) * math.cos(ph), np.sin(t) * math.sin(ph), np.cos(t)], axis=-1)
    f = np.asarray(model.eval(wi, wo), dtype=np.float64)
    if cosine:
        f = f * (np.cos(t)[:, None] if f.ndim > 1 else np.cos(t))
    return {"theta_o_deg": np.degrees(t).round(3).tolist(), "values": channels(f, mode)}


def lobe(model, theta_i: float, phi_i: float = 0.0, *, n_theta: int = 24, n_phi: int = 48,
         cosine: bool = True) -> dict:
    """3-D lobe: vertices ``x, y, z`` (lists of n_theta × n_phi) with radius f·cos θ_o
    (or f), normalised to a maximum of 1, and the incident direction ``wi``."""
    wi = _incident(theta_i, phi_i)
    t = np.linspace(0.0, 0.5 * math.pi * 0.995, n_theta)
    p = np.linspace(0.0, 2.0 * math.pi, n_phi)
    T, P = np.meshgrid(t, p, indexing="ij")
    wo = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], axis=-1)
    f = np.asarray(model.eval(wi, wo.reshape(-1, 3)), dtype=np.float64)
    y = np.asarray(channels(f, "luminance")[0]).reshape(T.shape)
    r = y * np.cos(T) if cosine else y
    peak = float(np.max(r)) if np.max(r) > 0 else 1.0
    r = r / peak
    xyz = wo * r[..., None]
    return {"x": xyz[..., 0].round(5).tolist(), "y": xyz[..., 1].round(5).tolist(),
            "z": xyz[..., 2].round(5).tolist(), "wi": wi.round(6).tolist(), "peak": peak}


def curves(model, theta_i: float, phi_i: float = 0.0, *, n: int = 91, cosine: bool = False,
           mode: str = "luminance") -> dict:
    """f against θ_h (θ_d = θ_i, φ_d = 90°), θ_d (θ_h = 0) and θ_o (in-plane slice)."""
    _incident(theta_i, phi_i)
    x = np.radians(np.linspace(0.0, 89.5, n))
    out = {"angle_deg": np.degrees(x).round(3).tolist()}
    for key, (th, td) in {"theta_h": (x, np.full(n, theta_i)),
                          "theta_d": (np.zeros(n), x)}.items():
        wi, wo = from_rusinkiewicz(th, np.zeros(n), td, np.full(n, 0.5 * math.pi))
        f = np.asarray(model.eval(wi, wo), dtype=np.float64)
        if cosine:
            cz = np.clip(wo[:, 2], 0.0, None)
            f = f * (cz[:, None] if f.ndim > 1 else cz)
        out[key] = channels(f, mode)
    sl = polar(model, theta_i, phi_i, n=n, cosine=cosine, mode=mode)
    out["theta_o"] = {"theta_o_deg": sl["theta_o_deg"], "values": sl["values"]}
    return out


def _colormap(u: np.ndarray) -> np.ndarray:
    """Perceptually ordered map of u ∈ [0, 1] to RGB uint8 (Matplotlib's viridis)."""
    from matplotlib import colormaps

    return (colormaps["viridis"](np.clip(u, 0.0, 1.0))[..., :3] * 255.0 + 0.5).astype(np.uint8)


def png_bytes(rgb: np.ndarray) -> bytes:
    """uint8 (H, W, 3) → PNG file bytes (the renderer's own encoder, fast zlib level)."""
    from brdfkit.render.image import png_bytes as encode

    return encode(np.ascontiguousarray(rgb, dtype=np.uint8))


def halfdiff(model, *, size: int = 90, phi_d: float = 0.5 * math.pi, decades: float = 4.0):
    """θ_h (rows, downward) × θ_d (columns) image of log₁₀ f (luminance), the top
    *decades* mapped to the colour scale; returns (PNG bytes, {"vmin", "vmax"})."""
    u = (np.arange(size) + 0.5) / size
    th = merl_theta_h(u)  # MERL's quadratic θ_h spacing: detail near the peak
    td = u * 0.5 * math.pi
    TH, TD = np.meshgrid(th, td, indexing="ij")
    wi, wo = from_rusinkiewicz(TH.ravel(), np.zeros(TH.size), TD.ravel(),
                               np.full(TH.size, phi_d))
    y = np.asarray(channels(model.eval(wi, wo), "luminance")[0]).reshape(TH.shape)
    logy = np.log10(np.where(y > 0, y, np.nan))
    vmax = float(np.nanmax(logy)) if np.any(np.isfinite(logy)) else 0.0
    vmin = vmax - decades
    img = _colormap(np.nan_to_num((logy - vmin) / decades, nan=0.0))
    return png_bytes(img), {"vmin": vmin, "vmax": vmax}


def sphere(model, *, phi_l: float, ambient: float = 0.0, size: int = 256,
           exposure: float | None = None):
    """The lit sphere (exact, :func:`brdfkit.render.render_sphere`) as sRGB PNG bytes and
    ``{"exposure": ...}``; default exposure: the brightest pixel (the luminance of a
    coloured model) maps to 1, so every image uses the full range."""
    from brdfkit.render import render_sphere, to_srgb8

    # the ambient term ρ(V) to ALBEDO_TOL: a tenth of an 8-bit level at full exposure,
    # and seconds instead of minutes for a sharp measured peak
    r = render_sphere(model, phi_l=phi_l, ambient=ambient, size=size, rho_tol=ALBEDO_TOL)
    # NaN where a measured table has no value (unmeasured bins): shown black
    rad = np.nan_to_num(np.asarray(r.radiance, dtype=np.float64), nan=0.0, posinf=0.0)
    if exposure is None:
        peak = float(np.max(rad))
        exposure = 1.0 / peak if peak > 0 else 1.0
    img = to_srgb8(rad, exposure)
    if img.shape[-1] == 1:
        img = np.repeat(img, 3, axis=-1)
    return png_bytes(img), {"exposure": exposure}


def albedo_curve(model, *, n: int = 90, tol: float = ALBEDO_TOL, mode: str = "luminance",
                 phi: float = 0.0):
    """a(θ_i) at *n* angles in [0, 89.5]° and the incidence azimuth *phi* (radians; only an
    anisotropic model depends on it): ``{"theta_deg", "values", "error", "success"}``."""
    th = np.linspace(0.0, 89.5, n)
    r = albedo(model, np.radians(th), phi=phi, tol=tol)
    return {"theta_deg": th.round(4).tolist(), "values": channels(r.albedo, mode),
            "error": float(np.max(r.error)), "success": bool(np.all(r.success)),
            "message": r.message}


#: Albedo accuracy of the live verdict: 100x faster than check()'s 1e-7 default; check()
#: answers "undetermined" where the energy verdict is within this of 1, never more.
VERDICT_TOL = 1e-5


def verdict(model, *, tol: float = VERDICT_TOL, phi: float = 0.0) -> dict:
    """The plausibility verdict as ``brdfkit check --json`` prints it (albedo to *tol*, at
    the incidence azimuth *phi*, radians: only an anisotropic model's depends on it)."""
    return {**check(model, tol=tol, phi=0.0 if model.isotropic else phi).to_dict(), "tol": tol}
