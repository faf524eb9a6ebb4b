"""
Figures of any model or material
================================

- ``slices`` — :func:`model_slices`: in-plane slices of f_r at several incidence
  angles and the directional albedo a(θ_i), for one model or several side by
  side (a measured material next to its fits, a model next to its pumped
  version).

Unlike the paper figures these take the models to draw: ``brdfkit figure
slices merl:nickel [--compare nielsen -p ...] --out FILE``.
"""

from __future__ import annotations

import numpy as np

from brdfkit.analysis import albedo
from brdfkit.errors import ParameterError

__all__ = ["model_slices", "SLICE_THETA_I_DEG"]

#: Default incidence angles of the slices, degrees.
SLICE_THETA_I_DEG = (0.0, 30.0, 60.0, 75.0)
_THETA_A_DEG = np.linspace(0.0, 89.0, 45)
#: Absolute accuracy of the plotted albedo: 1e-4 is below a line width on a 0–1 axis, and the
#: adaptive engine needs ~30× longer for 1e-7 on a sharp measured peak (merl:nickel: 76 s
#: against 2.4 s at 1e-5 and 0.25 s at 1e-4 for 30 angles on this machine).
_ALBEDO_TOL = 1e-4
_STYLES = ("-", "--", ":", "-.")


def _channel_mean(values: np.ndarray, n: int) -> np.ndarray:
    """Mean over the channel axis when there is one (RGB → one curve per model)."""
    v = np.asarray(values, dtype=np.float64).reshape(n, -1)
    return v.mean(axis=1)


def model_slices(*models, theta_i_deg=SLICE_THETA_I_DEG, n_points: int = 721,
                 phi_deg: float = 0.0):
    """In-plane slices f_r(θ_i; θ_o) and the albedo a(θ_i) of each model.

    Parameters
    ----------
    *models : BRDF
        One to four models; each keeps one line style across both panels.
    theta_i_deg : sequence of float, keyword-only
        Incidence angles of the slices, degrees in [0, 90).
    n_points : int, keyword-only
        Points per slice (view angle from −90° to 90° in the plane of incidence;
        negative = the light's side).
    phi_deg : float, keyword-only
        Azimuth of the plane of incidence, degrees (any finite value; default 0, the
        xz-plane), for the slices and the albedo; the title states it when a model is
        anisotropic or it is not 0 (an isotropic model's figure does not depend on it).

    Left: f_r in 1/sr on a log scale, in the plane of incidence (φ_o − φ_i = π
    for positive θ_o: the mirror side). Right: a(θ_i) from
    :func:`brdfkit.analysis.albedo` to 1e-4 absolute. Coloured models are drawn as the mean of
    their channels (stated in the axis label).
    """
    import matplotlib.pyplot as plt

    if not 1 <= len(models) <= len(_STYLES):
        raise ParameterError(f"model_slices: give 1 to {len(_STYLES)} models; got {len(models)}")
    th_i = np.asarray(theta_i_deg, dtype=np.float64).ravel()
    if th_i.size == 0 or not np.all((th_i >= 0.0) & (th_i < 90.0)):
        raise ParameterError(f"model_slices: theta_i_deg must be angles in [0, 90) degrees; "
                             f"got {list(np.asarray(theta_i_deg).ravel())}")
    try:
        phi = float(phi_deg)
    except (TypeError, ValueError):
        phi = float("nan")
    if not np.isfinite(phi):
        raise ParameterError(f"model_slices: phi_deg must be a finite number of degrees; got "
                             f"{phi_deg!r}")
    phi_deg = phi
    # the plane of incidence at azimuth phi: its in-plane axis (c, s, 0); at 0 exactly the
    # xz-plane (no rounding of cos/sin, so the figure is as it was before the azimuth)
    c, s = ((1.0, 0.0) if phi_deg == 0.0
            else (np.cos(np.radians(phi_deg)), np.sin(np.radians(phi_deg))))
    fig, (ax_s, ax_a) = plt.subplots(1, 2, figsize=(11.0, 4.2))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    t_o = np.radians(np.linspace(-89.9, 89.9, n_points))
    wo = np.stack([np.sin(t_o) * c, np.sin(t_o) * s if s else np.zeros_like(t_o),
                   np.cos(t_o)], axis=-1)
    for m, style in zip(models, _STYLES, strict=False):
        for k, t in enumerate(np.radians(th_i)):
            # the light at azimuth π (x < 0) so that the mirror direction has θ_o = +θ_i
            wi = np.array([-np.sin(t) * c, -np.sin(t) * s if s else 0.0, np.cos(t)])
            f = _channel_mean(m.eval(wi, wo), n_points)
            ax_s.semilogy(np.degrees(t_o), np.where(f > 0, f, np.nan), style,
                          color=colours[k % len(colours)], lw=1.2,
                          label=f"{m.name}, $\\theta_i$ = {np.degrees(t):g}°")
        a = albedo(m, np.radians(_THETA_A_DEG), phi=np.radians(phi_deg),
                   tol=_ALBEDO_TOL).albedo
        ax_a.plot(_THETA_A_DEG, _channel_mean(a, _THETA_A_DEG.size), style, color="k",
                  label=m.name)
    ax_s.set_xlabel(r"view angle $\theta_o$ in the plane of incidence (degrees; + = mirror side)")
    ax_s.set_ylabel(r"$f_r$ (1/sr; mean of channels)")
    ax_s.set_xlim(-90, 90)
    ax_s.grid(alpha=0.3, which="both")
    ax_s.legend(fontsize=6, ncol=1 + (len(models) > 1))
    ax_a.set_xlabel(r"incidence angle $\theta_i$ (degrees)")
    ax_a.set_ylabel(r"albedo $a(\theta_i)$ (mean of channels)")
    ax_a.set_xlim(0, 90)
    ax_a.set_ylim(bottom=0)
    ax_a.grid(alpha=0.3)
    ax_a.legend(fontsize=8)
    at = ("" if phi_deg == 0.0 and all(m.isotropic for m in models)
          else f" (plane of incidence at $\\phi_i$ = {phi_deg:g}°)")
    fig.suptitle("in-plane slices and directional albedo: " + ", ".join(m.name for m in models)
                 + at, fontsize=10)
    fig.tight_layout()
    return fig
