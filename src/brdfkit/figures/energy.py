"""
"Energy against reciprocity" (issue 22 §3), computed
====================================================

- ``energy-reciprocity`` — for GGX over α ∈ [0.05, 1] and for a Phong lobe
  (``modified-phong``, ρ_d = 0, ρ_s = 1) over its exponent n, at white settings (F = 1):
  plain, Kulla–Conty, Turquin, and Neumann's pumping with g₁ (``max``)
  and g₂ (``controlled``). Each point is one model:

  - **energy axis**: the white-furnace deviation max |1 − a(θ_i)| over θ_i ≤ 89° (check's
    grid 0, 3, …, 87, 89°; :func:`~brdfkit.analysis.energy_verdict.furnace_deviation`),
    log scale; a filled marker is a loss (a < 1), an open one a gain (a > 1); values within
    the albedo engine's error estimate are drawn at that estimate (the engine cannot tell
    them from 0) with a grey marker;
  - **reciprocity axis**: check's max relative asymmetry |f(L,V) − f(V,L)| / max
    (:func:`~brdfkit.analysis.plausibility.reciprocity`), log scale; an exactly
    reciprocal formula (asymmetry 0) is drawn in a strip left of the axis, one column
    per method.

The series are data (:data:`FAMILIES`, :data:`METHODS`, :data:`SERIES`): a base spec in
the dict form of :class:`brdfkit.ModelSpec`, the swept parameter, and per method the
operator keys added to it. Run time: 34 s for the 88 models on the shared 2-core
machine (measured, warm Numba cache), the compensation and pumping tables included (each
model builds its own; nothing is cached across calls).

Public objects
--------------
- :func:`energy_reciprocity` — the figure.
- :func:`energy_reciprocity_data` — its numbers (one dict per point).
- :data:`FAMILIES`, :data:`METHODS`, :data:`SERIES`, :data:`ALPHAS`, :data:`EXPONENTS`.

References
----------
- Kulla & Conty 2017; Turquin 2019; [Neumann1999] eqs. (16)–(21); Walter et al. 2007.
"""

from __future__ import annotations

import numpy as np

from brdfkit.analysis.energy_verdict import FURNACE_TOL
from brdfkit.analysis.energy_verdict import energy_reciprocity as _point
from brdfkit.analysis.plausibility import RECIPROCITY_TOL
from brdfkit.spec import ModelSpec

__all__ = ["ALPHAS", "EXPONENTS", "FAMILIES", "METHODS", "SERIES", "energy_reciprocity",
           "energy_reciprocity_data"]

#: GGX roughness values, log-spaced over [0.05, 1].
ALPHAS = tuple(float(a) for a in np.round(np.geomspace(0.05, 1.0, 9), 4))
#: Phong exponents, from a near-diffuse lobe to a sharp one.
EXPONENTS = (1.0, 3.0, 10.0, 30.0, 100.0, 300.0, 1000.0)
#: family → (base spec, swept parameter, default values).
FAMILIES = {
    "GGX": ({"model": "microfacet", "params": {"distribution": "ggx"}}, "alpha", ALPHAS),
    "Phong": ({"model": "modified-phong", "params": {"rho_d": 0.0, "rho_s": 1.0}}, "n",
              EXPONENTS),
}
#: method → the operator keys added to the base spec (dict form).
METHODS = {
    "plain": {},
    "Kulla-Conty": {"compensate": {"method": "kulla-conty"}},
    "Turquin": {"compensate": {"method": "turquin"}},
    "pump g1": {"pump": {"g": "max", "times": 1}},
    "pump g2": {"pump": {"g": "controlled", "times": 1}},
}
#: (family, methods drawn for it).
SERIES = (
    ("GGX", ("plain", "Kulla-Conty", "Turquin", "pump g1", "pump g2")),
    ("Phong", ("plain", "Kulla-Conty", "Turquin", "pump g1", "pump g2")),
)
_STYLE = {"plain": ("k", "o"), "Kulla-Conty": ("tab:blue", "s"), "Turquin": ("tab:red", "D"),
          "pump g1": ("tab:green", "^"), "pump g2": ("tab:purple", "v")}


def energy_reciprocity_data(*, alphas=None, exponents=None, progress=None) -> list[dict]:
    """One dict per point: ``family``, ``method``, ``param``, ``value``, ``spec`` (dict
    form), and :func:`~brdfkit.analysis.energy_verdict.energy_reciprocity`'s
    ``deviation``, ``theta_deg``, ``error``, ``asymmetry``. *alphas*, *exponents*
    override the sweeps (default :data:`ALPHAS`, :data:`EXPONENTS`); *progress* is
    called as ``progress(done, total, what)``."""
    sweeps = {"GGX": ALPHAS if alphas is None else tuple(alphas),
              "Phong": EXPONENTS if exponents is None else tuple(exponents)}
    jobs = []
    for family, methods in SERIES:
        base, param, _ = FAMILIES[family]
        for method in methods:
            for value in sweeps[family]:
                spec = {**base, "params": {**base["params"], param: float(value)},
                        **METHODS[method]}
                jobs.append((family, method, param, float(value), spec))
    out = []
    for k, (family, method, param, value, spec) in enumerate(jobs):
        if progress is not None:
            progress(k, len(jobs), f"{family} {method} {param}={value:g}")
        model = ModelSpec.from_dict(spec).build()
        out.append({"family": family, "method": method, "param": param, "value": value,
                    "spec": spec, **_point(model)})
    if progress is not None:
        progress(len(jobs), len(jobs), "")
    return out


def energy_reciprocity(*, alphas=None, exponents=None):
    """The figure (module docstring): per family of :data:`SERIES`, a narrow strip for the
    exactly reciprocal points (asymmetry 0, one column per method) beside the log axis."""
    import matplotlib.pyplot as plt

    points = energy_reciprocity_data(alphas=alphas, exponents=exponents)
    fig, axes = plt.subplots(1, 2 * len(SERIES), figsize=(12.0, 5.0), sharey=True,
                             gridspec_kw={"width_ratios": [1.3, 5.0] * len(SERIES),
                                          "wspace": 0.04})
    for k, (family, methods) in enumerate(SERIES):
        strip, ax = axes[2 * k], axes[2 * k + 1]
        for method in methods:
            pts = [p for p in points if p["family"] == family and p["method"] == method]
            _draw_series(strip, ax, pts, method, methods.index(method))
        param = FAMILIES[family][1]
        ax.axvline(RECIPROCITY_TOL, color="grey", ls="--", lw=0.8)
        for a_ in (strip, ax):  # the "a = 1" criterion of the table
            a_.axhline(FURNACE_TOL, color="grey", ls=":", lw=0.8)
        ax.text(2e-17, FURNACE_TOL * 1.3, "a = 1 criterion 1e-5", fontsize=6, color="grey")
        ax.text(RECIPROCITY_TOL * 1.5, 0.98, "reciprocity\ntolerance 1e-6", fontsize=6,
                color="grey", va="top", transform=ax.get_xaxis_transform())
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlim(1e-17, 3.0)
        ax.set_xlabel("reciprocity error: max |f(L,V) - f(V,L)| / max(f(L,V), f(V,L))",
                      fontsize=8)
        strip.set_xlim(-0.7, len(methods) - 0.3)
        strip.set_xticks([len(methods) / 2 - 0.5], ["exactly\n0"], fontsize=7)
        strip.tick_params(axis="x", length=0)
        strip.spines["right"].set_linestyle(":")
        ax.spines["left"].set_linestyle(":")
        ax.tick_params(axis="y", which="both", left=False)
        sweep = "alpha in [0.05, 1]" if family == "GGX" else "modified-phong, n in [1, 1000]"
        ax.set_title(f"{family} ({sweep}, white); end labels: {param}", fontsize=9)
        for a_ in (strip, ax):
            a_.grid(alpha=0.3, which="both", lw=0.4)
        ax.legend(fontsize=7, loc="upper center")
    axes[0].set_ylabel(r"white furnace: max $|1 - a(\theta)|$ over $\theta \leq 89°$")
    fig.suptitle("Energy against reciprocity: compensation (Kulla-Conty, Turquin) beside "
                 "Neumann's pumping (g1, g2)", fontsize=10)
    fig.text(0.01, 0.005, "filled: loss (a < 1); open: gain (a > 1); grey: within the albedo "
             "engine's error estimate, drawn at that estimate. Computed by brdfkit "
             "(brdfkit figure energy-reciprocity).", fontsize=7, ha="left", va="bottom")
    fig.subplots_adjust(left=0.075, right=0.99, top=0.88, bottom=0.14)
    return fig


def _draw_series(strip, ax, pts: list[dict], method: str, column: int) -> None:
    """Points of exactly 0 asymmetry in *strip* (at x = *column*), the others on *ax*."""
    colour, marker = _STYLE[method]
    resolved = [abs(p["deviation"]) > p["error"] for p in pts]
    # a deviation within the error estimate is drawn at the estimate (floored at 1e-16,
    # below which nothing of float64 is resolved)
    y = [abs(p["deviation"]) if r else max(p["error"], 1e-16)
         for p, r in zip(pts, resolved, strict=True)]
    zero = [p["asymmetry"] <= 0.0 for p in pts]
    for target, keep in ((strip, True), (ax, False)):
        idx = [i for i, z in enumerate(zero) if z == keep]
        if not idx:
            continue
        xs = [float(column) if keep else pts[i]["asymmetry"] for i in idx]
        target.plot(xs, [y[i] for i in idx], "-", color=colour, lw=0.8, alpha=0.6)
        for i, xi in zip(idx, xs, strict=True):
            r = resolved[i]
            face = "none" if (pts[i]["deviation"] < 0.0 and r) else (colour if r else
                                                                      "lightgrey")
            target.plot([xi], [y[i]], marker, color=colour if r else "grey", mfc=face, ms=5)
        for i, xi in ((idx[0], xs[0]), (idx[-1], xs[-1])):
            target.annotate(f"{pts[i]['value']:g}", (xi, y[i]), textcoords="offset points",
                            xytext=(4, 1), fontsize=6, color=colour)
    ax.plot([], [], marker + "-", color=colour, lw=0.8, ms=5, label=method)
