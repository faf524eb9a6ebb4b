"""
Figure of one model's directional albedo (``brdfkit albedo --plot``)
====================================================================

:func:`albedo_figure` draws a(θ_i) = ∫ f_r cos θ_o dω_o of a model as a dense curve
(:data:`CURVE_THETA_DEG`, computed by the albedo engine to :data:`CURVE_TOL`, far below a
line's width) with the angles the user asked for marked on it (their values, computed to
the user's tolerance), one line per channel (R, G, B in red, green and blue), the bound
a = 1 of energy conservation as a dashed line, the axis from 0 to above both, and the
model's parameters and largest albedo in the title.

Public objects
--------------
- :func:`albedo_figure`, :data:`CURVE_THETA_DEG`, :data:`CURVE_TOL`.
"""

from __future__ import annotations

import numpy as np

__all__ = ["albedo_figure", "CURVE_THETA_DEG", "CURVE_TOL"]

#: The dense curve's incidence angles: every degree to 89°, then 89.5° and 89.9° (where
#: grazing behaviour — divergence, a dark rim — shows).
CURVE_THETA_DEG = tuple(float(t) for t in np.arange(0.0, 90.0, 1.0)) + (89.5, 89.9)
#: The curve's quadrature tolerance: 1e-5 absolute is a thousandth of a line's width on a
#: 0–1 axis 4 inches tall, and costs a fraction of the default 1e-7.
CURVE_TOL = 1e-5
#: Channel names and colours of an RGB model.
_RGB = (("R", "tab:red"), ("G", "tab:green"), ("B", "tab:blue"))


def _title(model, phi_deg) -> str:
    d = model.to_dict()
    params = ", ".join(f"{k}={_short(v)}" for k, v in d["params"].items() if v is not None)
    at = "" if phi_deg is None else f" at φ_i = {phi_deg:g}°"  # the name holds any operator
    return f"{model.name}{at}\n{params}" if params else f"{model.name}{at}"


def _short(v) -> str:
    if isinstance(v, list):
        return "(" + ", ".join(_short(x) for x in v) + ")"
    return f"{v:.4g}" if isinstance(v, float) else str(v)


def albedo_figure(model, theta_deg, albedo_values, *, phi_deg: float | None = None):
    """The albedo figure of *model* (module docstring): *theta_deg* (T,) are the angles
    asked for and *albedo_values* (T,) or (T, C) their albedos (the command's own numbers,
    marked on the curve); *phi_deg* the incidence azimuth when it matters (anisotropic
    models), else None. Returns a Matplotlib Figure."""
    import matplotlib.pyplot as plt

    from brdfkit.analysis import albedo

    th = np.asarray(theta_deg, dtype=np.float64).reshape(-1)
    a_asked = np.asarray(albedo_values, dtype=np.float64).reshape(th.size, -1)
    curve_th = np.union1d(np.asarray(CURVE_THETA_DEG), th)
    phi = 0.0 if phi_deg is None else np.radians(phi_deg)
    curve = np.asarray(albedo(model, np.radians(curve_th), phi=phi, tol=CURVE_TOL).albedo)
    curve = curve.reshape(curve_th.size, -1)
    n_c = curve.shape[1]
    styles = (_RGB if n_c == 3 else
              [(f"channel {c}", None) for c in range(n_c)] if n_c > 1 else [(None, "tab:blue")])
    fig, ax = plt.subplots(figsize=(6.0, 4.4))
    for c, (label, colour) in enumerate(styles):
        ax.plot(curve_th, curve[:, c], color=colour, lw=1.5, label=label)
        ax.plot(th, a_asked[:, c], ls="none", marker="o", ms=4.5, color=colour,
                markeredgecolor="black", markeredgewidth=0.6)
    ax.plot([], [], ls="none", marker="o", ms=4.5, color="white", markeredgecolor="black",
            label="asked angles")
    ax.axhline(1.0, color="0.35", ls="--", lw=1.0, label="a = 1 (energy conservation)")
    top = float(np.nanmax(np.concatenate([curve.ravel(), a_asked.ravel(), [1.0]])))
    ax.set_ylim(0.0, 1.08 * top)
    ax.set_xlim(0.0, 90.0)
    ax.set_xticks(np.arange(0, 91, 15))
    ax.set_xlabel(r"incidence angle $\theta_i$ (degrees)")
    ax.set_ylabel(r"directional albedo $a(\theta_i)$")
    k = np.unravel_index(int(np.nanargmax(curve)), curve.shape)
    ax.set_title(_title(model, phi_deg) + f"\nmax a = {curve[k]:.4g} at θ_i = "
                 f"{curve_th[k[0]]:g}°" + (" (exceeds 1)" if curve[k] > 1.0 else ""),
                 fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="best", framealpha=0.9)
    fig.tight_layout()
    return fig
