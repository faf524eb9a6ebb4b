"""
Lewis (1993) Figs. 3, 4, 6, 10: spheres on the test configuration, computed
===========================================================================

Grids of spheres rendered exactly on Lewis's test configuration (Fig. 2;
:func:`brdfkit.render.render_sphere`): one directional light at Φ_L from the
viewer, no ambient light, irradiance 1.

- ``lewis-fig3`` — the Phong shader with Blinn's F_s^B (eq. 8 with eq. 6,
  model ``blinn``), k_d = 1 − k_s (§3.1).
- ``lewis-fig4`` — Neumann–Neumann (§3.3) and Minnaert (§3.4) shaders,
  b_N = b_M = 1; Φ_L ≤ 60° as in the paper (§6: Fig. 4 "doesn't even bother
  showing Φ_L > 60°").
- ``lewis-fig6`` — the energy-conserving Phong shader with F_s^B (eq. 22,
  model ``phong-energy-conserving``), k_ρ = 1 (§4.1).
- ``lewis-fig10`` — the reciprocal Phong shader with F_s^B (eq. 24, model
  ``phong-blinn-reciprocal``), k_d = 1 − k_s (§6).

Rows and columns: the paper names the variables (Φ_L × k_s or k_σ × β) but
not their values, so these are chosen: Φ_L ∈ {0°, 30°, 60°, 90°, 120°}
(Fig. 4: {0°, 30°, 60°}), k_s or k_σ ∈ {0, 0.5, 1} and β ∈ {5°, 15°, 30°}
(one row for k_s = 0 or k_σ = 0, where β changes nothing), β converted to
each model's exponent by :mod:`brdfkit.halfangle`.

Exposure (one for the whole figure, Lewis §3.3): the largest radiance of the
Φ_L = 0 spheres is shown just unsaturated, and that factor is held for every
sphere. In Fig. 6 the factor comes from the k_σ = 0 (purely diffuse) spheres,
so that, as Lewis notes, the highly specular parts saturate "in order to show
the diffuse parts".
"""

from __future__ import annotations

import math

import numpy as np

import brdfkit
from brdfkit.render import render_sphere, to_srgb8

PHI_DEG = (0.0, 30.0, 60.0, 90.0, 120.0)
PHI_DEG_FIG4 = (0.0, 30.0, 60.0)
BETA_DEG = (5.0, 15.0, 30.0)
COEFFS = (0.5, 1.0)  # k_s or k_σ of the rows with a specular lobe (plus one row at 0)
#: Side of each sphere in pixels.
SIZE = 128


def _grid(title: str, rows: list[tuple[str, object]], phis, caption: str,
          exposure_rows=None):
    """Render rows × Φ_L, one exposure: 1/peak of the Φ_L = 0 spheres of *exposure_rows*
    (row indices; default all rows)."""
    import matplotlib.pyplot as plt

    renders = [[render_sphere(m, phi_l=math.radians(p), size=SIZE) for p in phis]
               for _, m in rows]
    ref = range(len(rows)) if exposure_rows is None else exposure_rows
    peak = max(renders[i][phis.index(0.0)].peak for i in ref)
    k = 1.0 / peak  # peak > 0: every Φ_L = 0 sphere here is lit head-on
    nr, nc = len(rows), len(phis)
    # inches: cell side, gap between cells, margins for row labels, titles and caption
    cell, gap, left, top, bottom = 1.2, 0.05, 1.1, 0.75, 0.45
    width = left + nc * cell + (nc - 1) * gap + 0.1
    height = top + nr * cell + (nr - 1) * gap + bottom
    fig, axes = plt.subplots(nr, nc, figsize=(width, height), squeeze=False, facecolor="white")
    fig.subplots_adjust(left=left / width, right=1 - 0.1 / width, top=1 - top / height,
                        bottom=bottom / height, wspace=gap / cell, hspace=gap / cell)
    for i, (label, _) in enumerate(rows):
        for j, p in enumerate(phis):
            img = to_srgb8(renders[i][j].radiance, k)
            if img.shape[2] == 1:
                img = np.repeat(img, 3, axis=2)
            ax = axes[i, j]
            ax.imshow(img, interpolation="nearest")
            ax.set_xticks([])
            ax.set_yticks([])
            for spine in ax.spines.values():
                spine.set_visible(False)
            if i == 0:
                ax.set_title(rf"$\Phi_L$ = {p:g}°", fontsize=8)
            if j == 0:
                ax.set_ylabel(label, fontsize=7, rotation=0, ha="right", va="center")
    fig.suptitle(title, fontsize=9, y=1 - 0.2 / height)
    fig.text(0.01, 0.8 * bottom / height,
             caption + f" Exposure: display = sRGB(min(1, {k:.4g} x radiance)), the same for "
             "every sphere (1/peak of the Phi_L = 0 spheres"
             + ("" if exposure_rows is None else " with no specular part") + ").",
             fontsize=6, ha="left", va="top", wrap=True)
    return fig


def _kd_ks_rows(name: str, coeff: str, other: str | None) -> list:
    """Rows: coeff = 0 once, then coeff ∈ COEFFS × β (other = 1 − coeff when given)."""

    def params(c):
        return {coeff: c, other: 1.0 - c} if other else {coeff: c}

    sym = {"k_s": "k_s", "k_sigma": r"k_\sigma"}[coeff]
    extra = {"k_sigma": {"k_rho": 1.0, "lobe": "blinn"}}.get(coeff, {})
    rows = [(f"${sym}$ = 0", brdfkit.model(name, **extra, **params(0.0)))]
    for c in COEFFS:
        for b in BETA_DEG:
            rows.append((f"${sym}$ = {c:g}\n" + rf"$\beta$ = {b:g}°",
                         brdfkit.model(name, **extra, **params(c), beta=math.radians(b))))
    return rows


def lewis_fig3():
    """Phong shader with Blinn's F_s^B (``blinn``): Φ_L × (k_s, β), k_d = 1 − k_s."""
    return _grid("Lewis 1993, Fig. 3: Phong shader with Blinn's $F_s^B$ "
                 r"($f_r = k_d + k_s F_s^B/(\mathbf{N}\cdot\mathbf{S})$, $k_d = 1 - k_s$)",
                 _kd_ks_rows("blinn", "k_s", "k_d"), list(PHI_DEG),
                 "Reproduces Lewis (1993) Fig. 3, computed exactly (no ambient light). The "
                 "highlight keeps its brightness as Phi_L grows: the 1/(N.S) of eq. 8 cancels "
                 "the cosine.")


def lewis_fig4():
    """Neumann–Neumann and Minnaert shaders: Φ_L ≤ 60° × (shader, β)."""
    rows = []
    for b in BETA_DEG:
        rows.append(("Neumann-\nNeumann\n" + rf"$\beta$ = {b:g}°",
                     brdfkit.model("neumann-neumann", b_N=1.0, beta=math.radians(b))))
    for b in BETA_DEG:
        rows.append(("Minnaert\n" + rf"$\beta$ = {b:g}°",
                     brdfkit.model("minnaert", b_M=1.0, beta=math.radians(b))))
    return _grid("Lewis 1993, Fig. 4: Neumann-Neumann and Minnaert shaders "
                 r"($b_N = b_M = 1$)", rows, list(PHI_DEG_FIG4),
                 "Reproduces Lewis (1993) Fig. 4, computed exactly (no ambient light). The image "
                 "dims as Phi_L grows and the limb (N.V = 0) is always dark; the two shaders "
                 "are hard to tell apart.")


def lewis_fig6():
    """Energy-conserving Phong shader with F_s^B (eq. 22), k_ρ = 1: Φ_L × (k_σ, β)."""
    return _grid("Lewis 1993, Fig. 6: energy-conserving Phong shader with $F_s^B$ "
                 r"(eq. 22, $k_\rho = 1$)", _kd_ks_rows("phong-energy-conserving", "k_sigma",
                                                        None),
                 list(PHI_DEG),
                 "Reproduces Lewis (1993) Fig. 6, computed exactly (no ambient light). As in the "
                 "paper the highly specular parts saturate so that the diffuse parts show.",
                 exposure_rows=[0])


def lewis_fig10():
    """Reciprocal Phong shader with F_s^B (eq. 24): Φ_L × (k_s, β), k_d = 1 − k_s."""
    return _grid("Lewis 1993, Fig. 10: reciprocal Phong shader "
                 r"($f_r = k_d + k_s F_s^B$, eq. 24, $k_d = 1 - k_s$)",
                 _kd_ks_rows("phong-blinn-reciprocal", "k_s", "k_d"), list(PHI_DEG),
                 "Reproduces Lewis (1993) Fig. 10, computed exactly (no ambient light). Like "
                 "Fig. 3, but dimmer at large Phi_L (no 1/(N.S) in the specular term).")
