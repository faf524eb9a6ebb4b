"""
Figure of a fit: in-plane slices measured vs fitted, and the two albedo curves
==============================================================================

:func:`fit_figure` draws, for a :class:`~brdfkit.fitting.FitResult` and its
target, f_r in the plane of incidence (as ``figure slices`` does: ω_o in the
xz-plane, signed θ_o: negative on the side of ω_i, positive towards the mirror
direction) at several θ_i (coloured along viridis, so no slice shares a colour
with a channel), measured (solid) vs fitted (dashed), on a log scale, with the
channels averaged; and the directional albedos a(θ_i) of target and model per
channel in red, green and blue (the fit's own albedo curves,
``FitResult.albedo_*``). Used by ``brdfkit fit --plot``.
"""

from __future__ import annotations

import numpy as np

__all__ = ["fit_figure", "SLICE_THETA_DEG"]

#: Incidence angles of the in-plane slices, degrees.
SLICE_THETA_DEG = (0.0, 20.0, 40.0, 60.0, 75.0)


def _slice(model, theta_i, theta_o):
    wi = np.array([np.sin(theta_i), 0.0, np.cos(theta_i)])
    # signed θ_o: positive on the far side of the normal (where the mirror direction is)
    wo = np.stack([-np.sin(theta_o), np.zeros_like(theta_o), np.cos(theta_o)], axis=-1)
    f = np.asarray(model.eval(np.broadcast_to(wi, wo.shape), wo)).reshape(theta_o.size, -1)
    return np.nanmean(f, axis=1)


def fit_figure(result, target, *, title: str | None = None):
    """The figure of a fit (module docstring); returns a Matplotlib Figure."""
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11.0, 4.4))
    theta_o = np.radians(np.linspace(-89.0, 89.0, 713))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    # the slices along viridis (dark blue to yellow): none is the red, green or blue of a
    # channel in the albedo panel
    shades = plt.get_cmap("viridis")(np.linspace(0.0, 0.85, len(SLICE_THETA_DEG)))
    lo = np.inf
    for k, t in enumerate(SLICE_THETA_DEG):
        c = shades[k]
        y_t = _slice(target, np.radians(t), theta_o)
        y_m = _slice(result.model, np.radians(t), theta_o)
        ax.plot(np.degrees(theta_o), y_t, color=c, lw=1.6, label=f"θ_i = {t:g}° measured")
        ax.plot(np.degrees(theta_o), y_m, color=c, lw=1.2, ls="--", label="fitted")
        pos = np.concatenate([y_t[y_t > 0], y_m[y_m > 0]])
        if pos.size:
            lo = min(lo, float(np.percentile(pos, 1)))
    ax.set_yscale("log")
    if np.isfinite(lo):
        ax.set_ylim(bottom=0.5 * lo)
    ax.set_xlabel("signed θ_o in the plane of incidence (deg; + = mirror side)")
    ax.set_ylabel("f_r (channel mean, 1/sr)")
    ax.set_title("in-plane slices: measured (solid) vs fitted (dashed)")
    ax.legend(fontsize=7, ncol=2)
    th = result.theta_deg
    names = ("R", "G", "B") if result.albedo_target.shape[1] == 3 else \
        tuple(str(c) for c in range(result.albedo_target.shape[1]))
    for c, nm in enumerate(names):
        col = ("tab:red", "tab:green", "tab:blue")[c] if len(names) == 3 else colours[c]
        bx.plot(th, result.albedo_target[:, c], color=col, lw=1.6, label=f"{nm} measured")
        bx.plot(th, result.albedo_model[:, c], color=col, lw=1.2, ls="--", label=f"{nm} fitted")
    bx.set_xlabel("θ_i (deg)")
    bx.set_ylabel("directional albedo a(θ_i)")
    bx.set_ylim(bottom=0.0)
    bx.set_title("albedo: measured (solid) vs fitted (dashed)")
    bx.legend(fontsize=7, ncol=2)
    d = result.model.to_dict()
    fig.suptitle(title or f"{d['model']} fitted to {target.name} ({result.loss}: "
                 f"{result.value:.4g}; {result.message})", fontsize=9)
    fig.tight_layout()
    return fig
