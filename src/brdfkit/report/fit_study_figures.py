"""
The fitting study's figures (docs/figures/study/)
=================================================

Drawn from the rows of :func:`brdfkit.fitting.study.read_study` by
:func:`brdfkit.report.fit_study.write_report`; each returns the path written
(atomically, :func:`brdfkit.figures.save_atomic`), or None when the study has
no rows for it.

Public objects
--------------
- :func:`alpha_figure` — histogram of the α-mix's fitted α, L1 and L2 fits.
- :func:`fig1_figure` — Nielsen's Fig. 1 materials: measured vs fitted in-plane slices.
- :func:`neumann_figure` — perceptual vs L2 maximal errors on the metals.
"""

from __future__ import annotations

import math

import numpy as np

from brdfkit.fitting.study import FIG1, NEUMANN_MODELS, in_plane_slice
from brdfkit.report._study_rows import _by_target, _f, _name, _ok, _params

__all__ = ["alpha_figure", "fig1_figure", "neumann_figure"]


def alpha_figure(study, path):
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.0, 3.4), layout="constrained")
    bins = np.linspace(0.0, 1.0, 11)
    for loss, colour, histtype, opacity in (("l1", "C0", "stepfilled", 0.5),
                                            ("l2", "C1", "step", 1.0)):
        a = [_params(r).get("alpha") for r in study.get(("nielsen", f"alpha-mix-{loss}"), [])
             if _ok(r)]
        a = [x for x in a if x is not None]
        ax.hist(a, bins=bins, histtype=histtype, alpha=opacity, color=colour, lw=1.5,
                label=f"{loss.upper()} fits ({len(a)})")
    from matplotlib.ticker import MaxNLocator

    ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_xlabel("α of the α-mix (0: Phong, 1: Blinn–Phong)")
    ax.set_ylabel("materials")
    ax.set_xlim(0.0, 1.0)
    ax.legend(frameon=False)
    ax.set_title("Nielsen eq. (3): fitted α", fontsize=10)
    return _save(fig, path)


def fig1_figure(study, path, theta_i=(30.0, 60.0)):
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter

    import brdfkit
    from brdfkit.spec import ModelSpec

    l1 = _by_target(study.get(("nielsen", "alpha-mix-l1"), []))
    l2 = _by_target(study.get(("nielsen", "alpha-mix-l2"), []))
    mats = [t for t in FIG1 if t in l1 and t in l2]
    if not mats:
        return None
    th = np.linspace(-85.0, 85.0, 681)
    fig, axes = plt.subplots(2, len(mats), figsize=(3.2 * len(mats), 5.6), squeeze=False,
                             layout="constrained")
    for j, t in enumerate(mats):
        target = brdfkit.data.material(t)
        m1, m2 = (ModelSpec.from_dict({"model": "nielsen", "params": _params(r[t])}).build()
                  for r in (l1, l2))
        for i, ti in enumerate(theta_i):
            ax = axes[i, j]
            y = in_plane_slice(target, ti, th)
            ax.plot(th, y, color="k", lw=1.6, label="measured (surrogate)")
            ax.plot(th, in_plane_slice(m1, ti, th), color="C0", lw=1.2, label="L1 fit")
            ax.plot(th, in_plane_slice(m2, ti, th), color="C1", lw=1.2, ls="--",
                    label="L2 fit")
            ax.set_yscale("log")
            top = float(np.nanmax(y))
            # log axis down to 1e-3 of the measured peak (the base of the lobe stays
            # visible), or to half the measured minimum when that is higher (flat materials)
            ax.set_ylim(max(top * 1e-3, 0.5 * float(np.nanmin(y))), top * 3.0)
            ax.axvline(ti, color="0.7", lw=0.6)
            ax.set_title(f"{_name(t)}, θ_i = {ti:g}°", fontsize=9)
            if i == 1:
                ax.set_xlabel("θ_o in the incidence plane (°; > 0: mirror side)", fontsize=8)
            if j == 0:
                ax.set_ylabel("f · cos θ_i (channel mean)", fontsize=8)
            ax.yaxis.set_minor_formatter(NullFormatter())  # short log ranges: no clutter
            ax.tick_params(labelsize=7)
    axes[0, 0].legend(fontsize=7, frameon=False, loc="lower left")
    fig.suptitle("α-mix fits (Fresnel, η free): L1 vs L2; grey line: mirror direction",
                 fontsize=10)
    return _save(fig, path)


def neumann_figure(study, path):
    import matplotlib.pyplot as plt

    series = []
    for model, label in NEUMANN_MODELS:
        for loss in ("perceptual", "l2"):
            rows = _by_target(study.get(("neumann", f"{model}-{loss}"), []))
            series.append((f"{label}, {loss}", rows))
    targets = sorted(set().union(*[set(r) for _, r in series]))
    if not targets:
        return None
    fig, axes = plt.subplots(1, 2, figsize=(10.0, 4.2), sharey=True, layout="constrained")
    width = 0.8 / len(series)
    x = np.arange(len(targets))
    for ax, key, title in ((axes[0], "e_point", "point light: max |ln(f̂ cos / f cos)|"),
                           (axes[1], "e_albedo", "sky light: max |ln(â / a)|")):
        for k, (label, rows) in enumerate(series):
            v = [_f(rows[t]["derived"][key]) if t in rows and rows[t].get("derived")
                 else math.nan for t in targets]
            ax.bar(x + (k - (len(series) - 1) / 2) * width, v, width, label=label,
                   color=f"C{k}", hatch="//" if "l2" in label else None, alpha=0.85)
        ax.set_xticks(x, [_name(t) for t in targets], rotation=30, ha="right", fontsize=8)
        ax.set_title(title, fontsize=9)
        ax.set_yscale("log")
    axes[0].set_ylabel("maximal log ratio (relative error ≈ e^x − 1)")
    # below the panels: inside, the legend covered the bars of the first materials
    fig.legend(*axes[1].get_legend_handles_labels(), fontsize=7, frameon=False, ncols=3,
               loc="outside lower center")
    fig.suptitle("Neumann §1.1 on the metals: perceptual vs L2 fits", fontsize=10)
    return _save(fig, path)


def _save(fig, path):
    import matplotlib.pyplot as plt

    from brdfkit.figures import save_atomic

    try:
        save_atomic(fig, path)
    finally:
        plt.close(fig)
    return path

