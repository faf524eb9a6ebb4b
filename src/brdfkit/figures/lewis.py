"""
Lewis (1993) Figs. 5, 7, 8, 9, computed
=======================================

- ``lewis-fig5`` — specular integrals H_s(S) for F_s^P (eq. 5) and F_s^B (eq. 6).
- ``lewis-fig7`` — k_ρ of Phong, Blinn and Torrance–Sparrow with D1–D4 (F = 1).
- ``lewis-fig8`` — k_ρ of Neumann–Neumann and Minnaert shaders.
- ``lewis-fig9`` — k_ρ of the reciprocal Phong–Blinn shader (eq. 24).

All curves are integrated with :func:`brdfkit.analysis.albedo` (deterministic,
~1e-7). Lobe widths are given as Lewis's half-angle β (§3.1–3.4), converted
per model by :mod:`brdfkit.halfangle`. The paper does not print the exact β
or exponents used, so the values here are chosen to show the same behaviour.
"""

from __future__ import annotations

import math

import numpy as np

import brdfkit
from brdfkit.analysis import H_s, albedo

THETA_DEG = np.concatenate([np.linspace(0.0, 89.0, 90), [89.3, 89.6, 89.8, 89.9]])
BETAS_DEG = (5.0, 15.0, 30.0)


def _axes(title: str, ncols: int = 1, ylabel: str = r"$k_\rho$"):
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, ncols, figsize=(5.2 * ncols, 4.0), squeeze=False)
    for ax in axes[0]:
        ax.set_xlabel(r"incidence angle $\theta_i$ (degrees)")
        ax.set_ylabel(ylabel)
        ax.set_xlim(0, 90)
        ax.grid(alpha=0.3)
    fig.suptitle(title, fontsize=10)
    return fig, axes[0]


def _caption(fig, text: str) -> None:
    fig.text(0.01, -0.02, text, fontsize=7, ha="left", va="top", wrap=True)


def _curve(model) -> np.ndarray:
    return np.asarray(albedo(model, np.radians(THETA_DEG)).albedo)


def lewis_fig5():
    """H_s(θ_i) for Phong's F_s^P (left) and Blinn's F_s^B (right), several exponents."""
    fig, (a1, a2) = _axes("Lewis 1993, Fig. 5: specular integrals $H_s(\\mathbf{S})$", 2,
                          ylabel=r"$H_s(\mathbf{S})$ (sr)")
    for n in (1.0, 5.0, 20.0, 100.0, 1000.0):
        for ax, lobe in ((a1, "phong"), (a2, "blinn")):
            ax.plot(THETA_DEG, H_s(np.radians(THETA_DEG), n, lobe=lobe).albedo,
                    label=f"$n_s$ = {n:g}")
    a1.set_title(r"Phong $F_s^P = (\mathbf{R}\cdot\mathbf{V})^{n}$ (eq. 5)", fontsize=9)
    a2.set_title(r"Blinn $F_s^B = (\mathbf{N}\cdot\mathbf{H})^{n}$ (eq. 6)", fontsize=9)
    for ax in (a1, a2):
        ax.set_yscale("log")
        ax.legend(fontsize=7)
    _caption(fig, "Reproduces Lewis (1993) Fig. 5 by deterministic quadrature. H_s > 0 at "
             "every angle, so k_rho = k_d pi + k_s H_s/(N.S) (eq. 19) diverges as theta_i -> 90.")
    return fig


def lewis_fig7():
    """k_ρ of Phong, Blinn and Torrance–Sparrow T1–T4 (F = 1), β = 15°."""
    fig, (ax,) = _axes("Lewis 1993, Fig. 7: directional-hemispherical reflectance, "
                       r"$\beta$ = 15°")
    beta = math.radians(15.0)
    curves = [
        (r"$k_\rho^P/k_s$ Phong", brdfkit.model("phong", k_d=0.0, k_s=1.0, beta=beta)),
        (r"$k_\rho^B/k_s$ Blinn", brdfkit.model("blinn", k_d=0.0, k_s=1.0, beta=beta)),
        (r"$k_\rho^{T1}/b_1$ (D1 Phong)",
         brdfkit.model("torrance-sparrow", distribution="phong", b=1.0, beta=beta)),
        (r"$k_\rho^{T2}/b_2$ (D2 Gaussian)",
         brdfkit.model("torrance-sparrow", distribution="gaussian", b=1.0, beta=beta)),
        (r"$k_\rho^{T3}/b_3$ (D3 Trowbridge)",
         brdfkit.model("torrance-sparrow", distribution="trowbridge-reitz", b=1.0, beta=beta)),
        (r"$k_\rho^{T4}$ (D4 Beckmann)",
         brdfkit.model("torrance-sparrow", distribution="beckmann", beta=beta)),
    ]
    for label, m in curves:
        ax.plot(THETA_DEG, _curve(m), label=label)
    ax.set_yscale("log")
    ax.legend(fontsize=7)
    _caption(fig, "Reproduces Lewis (1993) Fig. 7 (F = 1, worst case). Phong and Blinn "
             "diverge like 1/cos(theta_i); the Torrance-Sparrow curves stay bounded because of G.")
    return fig


def lewis_fig8():
    """k_ρ/b of Neumann–Neumann and Minnaert shaders for several β."""
    fig, (ax,) = _axes("Lewis 1993, Fig. 8: Neumann-Neumann and Minnaert shaders",
                       ylabel=r"$k_\rho / b$")
    for bdeg in BETAS_DEG:
        b = math.radians(bdeg)
        ax.plot(THETA_DEG, _curve(brdfkit.model("neumann-neumann", b_N=1.0, beta=b)),
                label=rf"$k_\rho^N/b_N$, $\beta$ = {bdeg:g}°")
        ax.plot(THETA_DEG, _curve(brdfkit.model("minnaert", b_M=1.0, beta=b)), "--",
                label=rf"$k_\rho^M/b_M$, $\beta$ = {bdeg:g}°")
    ax.legend(fontsize=7)
    _caption(fig, "Reproduces Lewis (1993) Fig. 8: both are bounded (maximum at normal "
             "incidence), so b_N or b_M can be limited to conserve energy.")
    return fig


def lewis_fig9():
    """k_ρ^H/k_s of the reciprocal Phong–Blinn shader (eq. 24) for several β."""
    fig, (ax,) = _axes("Lewis 1993, Fig. 9: reciprocal Phong shader with Blinn's $F_s^B$",
                       ylabel=r"$k_\rho^H / k_s$")
    for bdeg in BETAS_DEG:
        m = brdfkit.model("phong-blinn-reciprocal", k_d=0.0, k_s=1.0, beta=math.radians(bdeg))
        ax.plot(THETA_DEG, _curve(m), label=rf"$\beta$ = {bdeg:g}°")
    ax.legend(fontsize=8)
    _caption(fig, "Reproduces Lewis (1993) Fig. 9: k_rho of f_r = k_d + k_s (N.H)^n (eq. 24) "
             "is bounded, so limiting k_s and k_d conserves energy.")
    return fig
