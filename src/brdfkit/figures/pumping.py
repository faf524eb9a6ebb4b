"""
Neumann et al. (1999) Figs. 3–7, computed
=========================================

- ``neumann-fig3`` / ``neumann-fig4`` — albedo and mirror-direction output
  radiance of the reciprocal Phong / Blinn model (n = 20) and its versions
  pumped 1, 2, 3 times with g₁ = max(a(L), a(V)) (eq. 20).
- ``neumann-fig5`` / ``neumann-fig6`` — the same with the controlled
  g₂ = max(a(L), a(V), N·V, N·L) (eq. 21).
- ``neumann-fig7`` — albedo of eq. (22), c_n (R·V)ⁿ/max(N·L, N·V) with
  c_n = (n+2)/2π, for several n, and its output radiance for n = 100.

The models: reciprocal Phong = ``modified-phong`` with ρ_d = 0, ρ_s = 1
(c_Phong = (n+2)/2π, albedo 1 at normal incidence); reciprocal Blinn =
``phong-blinn-reciprocal`` with k_d = 0 and k_s = 1/a_B(0) so that its albedo
is also 1 at normal incidence (the paper does not print c_Blinn(n)).
Radiance: point light of intensity 4π at distance 1, viewer in the mirror
direction, L_out = f(L, R) cos θ_L (eq. 3).

Note (a result, not a plotting choice): for the normalised reciprocal Phong
the albedo satisfies a(θ) ≥ cos θ (the horizon only removes lobe parts with
negative cos θ_o from ∫ c cosⁿα cos θ_o dω = cos θ), and pumping only raises
it, so g₂ = g₁ at every stage: Fig. 5's Phong curves coincide with Fig. 3's.
"""

from __future__ import annotations

import numpy as np

import brdfkit
from brdfkit.analysis import albedo

THETA = np.concatenate([np.linspace(0.0, 88.0, 45), [89.0, 89.5, 89.9]])
N_PAPER = 20.0


def reciprocal_phong(n: float = N_PAPER):
    """Neumann's reciprocal Phong (eq. 6) with albedo 1 at normal incidence."""
    return brdfkit.model("modified-phong", rho_d=0.0, rho_s=1.0, n=n)


def reciprocal_blinn(n: float = N_PAPER):
    """Neumann's reciprocal Blinn (eq. 6) scaled to albedo 1 at normal incidence."""
    from brdfkit.models.phong import blinn_normal_albedo

    return brdfkit.model("phong-blinn-reciprocal", k_d=0.0,
                         k_s=1.0 / float(blinn_normal_albedo(n)), n=n)


def pumping_curves(model, g: str, times: int = 3, theta_deg=THETA) -> dict:
    """Albedo and mirror radiance of *model* pumped 0 … *times* times with *g*.

    Returns ``{"theta_deg", "albedo": (times+1, T), "radiance": (times+1, T)}``.
    """
    from brdfkit.pumping import mirror_radiance, pump_sequence

    th = np.radians(np.asarray(theta_deg, dtype=np.float64))
    stages = pump_sequence(model, g, times=times)
    alb = np.array([np.asarray(albedo(m, th).albedo) for m in stages])
    rad = np.array([mirror_radiance(m, th) for m in stages])
    return {"theta_deg": np.asarray(theta_deg), "albedo": alb, "radiance": rad}


def _two_panel(curves: dict, title: str, caption: str, *, ref_radiance: float | None = None):
    import matplotlib.pyplot as plt

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(10.4, 4.0))
    th = curves["theta_deg"]
    for k, (a, r) in enumerate(zip(curves["albedo"], curves["radiance"], strict=True)):
        label = "original" if k == 0 else f"pumped {k}x"
        style = "k-" if k == 0 else "-"
        ax.plot(th, a, style, label=label)
        ax2.plot(th, r, style, label=label)
    ax.plot(th, np.cos(np.radians(th)), ":", color="grey", label=r"$\cos\theta$")
    if ref_radiance is not None:
        ax2.axhline(ref_radiance, color="grey", ls="--", lw=0.8,
                    label="original at normal incidence")
    ax.set_xlabel(r"incidence angle $\theta_L$ (degrees)")
    ax.set_ylabel(r"albedo $a(\theta_L)$")
    ax2.set_xlabel(r"incidence angle $\theta_L$ (degrees)")
    ax2.set_ylabel(r"$L_{out} = f(L, R)\cos\theta_L$ (1/sr)")
    for a_ in (ax, ax2):
        a_.set_xlim(0, 90)
        a_.set_ylim(bottom=0)
        a_.grid(alpha=0.3)
        a_.legend(fontsize=7)
    ax.set_title("albedo", fontsize=9)
    ax2.set_title("output radiance, point light 4π at distance 1, viewer at R", fontsize=9)
    fig.suptitle(title, fontsize=10)
    fig.text(0.01, -0.02, caption, fontsize=7, ha="left", va="top", wrap=True)
    return fig


def _fig(model_fn, g: str, fig_no: int, model_label: str):
    m = model_fn()
    curves = pumping_curves(m, g, times=3)
    gname = ("g1 = max(a(L), a(V)) (eq. 20)" if g == "max"
             else "controlled g2 = max(a(L), a(V), N.V, N.L) (eq. 21)")
    peak = curves["radiance"].max(axis=1)
    a80 = [float(np.interp(80.0, curves["theta_deg"], a)) for a in curves["albedo"]]
    caption = (f"Reproduces Neumann et al. (1999) Fig. {fig_no}: {model_label} (n = 20), "
               f"original and pumped 1-3 times with {gname}. Albedo by deterministic "
               f"quadrature. a(80 deg) = " + ", ".join(f"{x:.3f}" for x in a80)
               + "; peak radiance = " + ", ".join(f"{x:.2f}" for x in peak)
               + " (original, 1x, 2x, 3x).")
    if g == "controlled" and model_label.startswith("reciprocal Phong"):
        caption += (" For this Phong a(theta) >= cos(theta), so g2 = g1 and the curves equal "
                    "Fig. 3's.")
    return _two_panel(curves, f"Neumann et al. 1999, Fig. {fig_no}: {model_label}, "
                      f"{'albedo pumping-up' if g == 'max' else 'controlled pumping-up'}",
                      caption, ref_radiance=float(curves["radiance"][0, 0]))


def neumann_fig3():
    """Reciprocal Phong (n = 20) pumped with g₁: albedo and mirror radiance."""
    return _fig(reciprocal_phong, "max", 3, "reciprocal Phong")


def neumann_fig4():
    """Reciprocal Blinn (n = 20) pumped with g₁: albedo and mirror radiance."""
    return _fig(reciprocal_blinn, "max", 4, "reciprocal Blinn")


def neumann_fig5():
    """Reciprocal Phong (n = 20) pumped with g₂: albedo and mirror radiance."""
    return _fig(reciprocal_phong, "controlled", 5, "reciprocal Phong")


def neumann_fig6():
    """Reciprocal Blinn (n = 20) pumped with g₂: albedo and mirror radiance."""
    return _fig(reciprocal_blinn, "controlled", 6, "reciprocal Blinn")


def neumann_fig7():
    """Eq. (22) with c_n = (n+2)/2π: albedo for several n, mirror radiance for n = 100."""
    import matplotlib.pyplot as plt

    from brdfkit.pumping import mirror_radiance

    th = THETA
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(10.4, 4.0))
    for n in (2.0, 5.0, 20.0, 100.0, 1000.0):
        m = brdfkit.model("neumann-phong", n=n)
        ax.plot(th, np.asarray(albedo(m, np.radians(th)).albedo), label=f"n = {n:g}")
    m100 = brdfkit.model("neumann-phong", n=100.0)
    ax2.plot(th, mirror_radiance(m100, np.radians(th)), label="eq. (22), n = 100")
    ph = reciprocal_phong(100.0)
    ax2.plot(th, mirror_radiance(ph, np.radians(th)), "k--", lw=0.8,
             label="reciprocal Phong, n = 100")
    ax.set_xlabel(r"incidence angle $\theta_L$ (degrees)")
    ax.set_ylabel(r"albedo $a(\theta_L)$")
    ax2.set_xlabel(r"incidence angle $\theta_L$ (degrees)")
    ax2.set_ylabel(r"$L_{out} = f(L, R)\cos\theta_L$ (1/sr)")
    for a_ in (ax, ax2):
        a_.set_xlim(0, 90)
        a_.set_ylim(bottom=0)
        a_.grid(alpha=0.3)
        a_.legend(fontsize=7)
    fig.suptitle("Neumann et al. 1999, Fig. 7: the model of eq. (22), "
                 r"$c_n (R\cdot V)^n/\max(N\cdot L, N\cdot V)$, $c_n = (n+2)/2\pi$", fontsize=10)
    fig.text(0.01, -0.02, "Reproduces Neumann et al. (1999) Fig. 7. Left: albedo for several n "
             "(deterministic quadrature). Right: output radiance toward the mirror direction "
             "under a point light of intensity 4 pi at distance 1 (eq. 3); for eq. (22) it is the "
             "constant c_n = (n+2)/2 pi, a perfect 'radiance mirror', while the reciprocal Phong "
             "darkens as cos(theta).", fontsize=7, ha="left", va="top", wrap=True)
    return fig
