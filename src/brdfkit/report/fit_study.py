"""
The fitting study's report: docs/fitting-study.md and docs/figures/study/
========================================================================

:func:`write_report` reads the files of :func:`brdfkit.fitting.study.run_study`
and writes a Markdown report whose every table and every verdict on a paper's
claim is computed from those files here (no number or "supported" is typed by
hand): each claim of the papers is stated with a test on the numbers, and the
test's outcome is printed with the counts it rests on.

Public objects
--------------
- :func:`write_report` — the report and its figures.
- :func:`claims` — the verdict of every claim, from the study's rows (tested on its own).
"""

from __future__ import annotations

import json
import math
import os
from collections import Counter

import numpy as np

from brdfkit.fitting.study import (
    FIG1,
    METAL_WORDS,
    NEUMANN_MODELS,
    NGAN_CONVENTIONS,
    in_plane_slice,
    is_metal,
    read_study,
    study_batches,
)
from brdfkit.status import STATUS

__all__ = ["write_report", "claims", "nielsen_table", "FULL_MATERIALS"]

_LABEL = dict(NEUMANN_MODELS)

#: Materials of the full study (every MERL material).
FULL_MATERIALS = 100
NIELSEN_VARIANTS = ("phong", "blinn-phong", "alpha-mix")
VARIANT_LABEL = {"phong": "Phong (α = 0)", "blinn-phong": "Blinn–Phong (α = 1)",
                 "alpha-mix": "α-mix"}
#: The α-mix nests Phong (α = 0) and Blinn–Phong (α = 1): its L1 should never be larger
#: than theirs; it "fits better" when it is smaller by more than this relative margin
#: (differences below it are optimiser noise, not a better model).
BETTER_MARGIN = 0.01


def _f(x) -> float:
    """A CSV cell as a float (NaN when empty)."""
    try:
        return float(x)
    except (TypeError, ValueError):
        return math.nan


def _params(row) -> dict:
    return json.loads(row["params"]) if row.get("params") else {}


def _name(spec: str) -> str:
    return str(spec).rsplit(":", 1)[-1]


def _ok(row) -> bool:
    return row.get("status") in ("ok", "not-converged")


def _by_target(rows) -> dict:
    return {r["target"]: r for r in rows if _ok(r)}


# --------------------------------------------------------------------------- tables
def nielsen_table(study: dict, loss: str = "l1") -> list[dict]:
    """Per material: the *loss* value of each Nielsen variant, the best, α of the α-mix."""
    fits = {v: _by_target(study.get(("nielsen", f"{v}-{loss}"), [])) for v in NIELSEN_VARIANTS}
    out = []
    for t in sorted(set().union(*[set(f) for f in fits.values()])):
        row = {"target": t}
        for v in NIELSEN_VARIANTS:
            row[v] = _f(fits[v][t][f"metric_{loss}"]) if t in fits[v] else math.nan
        vals = {v: row[v] for v in NIELSEN_VARIANTS if math.isfinite(row[v])}
        row["best"] = min(vals, key=vals.get) if vals else ""
        # Phong-like or Blinn–Phong-like: one below the other by more than BETTER_MARGIN,
        # else a tie (the data do not tell the two lobes apart)
        p, b = row["phong"], row["blinn-phong"]
        m = 1 - BETTER_MARGIN
        row["kind"] = "Phong" if p < m * b else "Blinn–Phong" if b < m * p else "tie"
        row["tie"] = row["kind"] == "tie"
        # the α-mix's gain over the better of the two (< 0: the optimiser missed a nested fit)
        row["gain"] = 1.0 - row["alpha-mix"] / min(p, b)
        row["alpha"] = (_params(fits["alpha-mix"][t]).get("alpha", math.nan)
                        if t in fits["alpha-mix"] else math.nan)
        out.append(row)
    return out


def claims(study: dict) -> list[dict]:
    """Each paper claim with its test on the numbers: ``{"paper", "claim", "test",
    "verdict" ("supported", "not supported", "partly supported" or "no data"), "evidence"}``.
    """
    out = []
    t1 = [r for r in nielsen_table(study, "l1") if r["best"]]
    # N1: Phong-like and Blinn–Phong-like materials both exist
    if t1:
        m = 1 - BETTER_MARGIN
        ph = [r["target"] for r in t1 if r["phong"] < m * r["blinn-phong"]]
        bl = [r["target"] for r in t1 if r["blinn-phong"] < m * r["phong"]]
        verdict = "supported" if ph and bl else "not supported"
        fig = {r["target"]: ("Phong" if r["target"] in ph else "Blinn–Phong"
                             if r["target"] in bl else "tie (< 1 %)")
               for r in t1 if r["target"] in (FIG1[0], FIG1[2])}
        paper = {FIG1[0]: "Phong", FIG1[2]: "Blinn–Phong"}
        agree = [t for t in fig if fig[t] == paper[t]]
        ev = (f"L1: Phong more than {BETTER_MARGIN:.0%} below Blinn–Phong on {len(ph)} of "
              f"{len(t1)} materials, Blinn–Phong more than {BETTER_MARGIN:.0%} below Phong on "
              f"{len(bl)}, within {BETTER_MARGIN:.0%} (a tie) on {len(t1) - len(ph) - len(bl)}."
              " The paper's examples: "
              + ", ".join(f"{_name(t)} → {fig[t]} (paper: {paper[t]})" for t in fig)
              + (f"; {len(agree)} of {len(fig)} agree." if fig else "."))
        out.append({"paper": "Nielsen 2015", "claim": "some materials are fitted best by "
                    "Phong (Fig. 1a two-layer-silver), others by Blinn–Phong (Fig. 1c nickel)",
                    "test": "L1 of Phong vs Blinn–Phong (both with Fresnel, η free) per "
                    "material; each is better by > 1 % somewhere",
                    "verdict": verdict, "evidence": ev})
        better = [r for r in t1 if r["alpha-mix"] < (1 - BETTER_MARGIN)
                  * min(r["phong"], r["blinn-phong"])]
        worse = [r for r in t1 if r["alpha-mix"] > (1 + BETTER_MARGIN)
                 * min(r["phong"], r["blinn-phong"])]
        verdict = ("supported" if len(better) > len(t1) / 2 and not worse else
                   "partly supported" if better else "not supported")
        ev = (f"α-mix L1 more than {BETTER_MARGIN:.0%} below the better of Phong and "
              f"Blinn–Phong on {len(better)} of {len(t1)} materials; more than "
              f"{BETTER_MARGIN:.0%} above it (an optimiser failure: the α-mix contains both) "
              f"on {len(worse)}" + (" (" + ", ".join(_name(r["target"]) for r in worse) + ")"
                                    if worse else "") + ".")
        out.append({"paper": "Nielsen 2015", "claim": "the α-mix (eq. 3) fits better to a "
                    "broader range of materials", "test": "α-mix L1 below min(Phong, "
                    "Blinn–Phong) by > 1 % on most materials, and never above it",
                    "verdict": verdict, "evidence": ev})
    pos = lobe_positions(study)
    if pos:
        top = [p for p in pos if abs(math.log(p["top_l2"])) < abs(math.log(p["top_l1"]))]
        base = [p for p in pos if abs(math.log(p["base_l1"])) < abs(math.log(p["base_l2"]))]
        n = len(pos)
        both = [p for p in top if p in base]
        verdict = ("supported" if len(both) > n / 2 else
                   "partly supported" if top or base else "not supported")
        ev = (f"in the incidence plane at θ_i = 30° (α-mix fits): the L2 fit is closer to the "
              f"measured peak height than the L1 fit on {len(top)} of {n} materials; the L1 "
              f"fit is closer to the measured lobe's width at its base on {len(base)} of {n};"
              f" both on {len(both)}.")
        out.append({"paper": "Nielsen 2015", "claim": "L2 fits the lobe to the tops of the "
                    "specular highlights, L1 roughly to their base", "test": "|ln(top ratio)|"
                    " smaller for L2 and |ln(base-width ratio)| smaller for L1",
                    "verdict": verdict, "evidence": ev})
    conv = [(k, r) for k, rows in study.items() if k[0] == "nielsen" for r in rows]
    if conv:
        bad = [(k, r) for k, r in conv if not _ok(r) or _fit_status(r) in (2, 3)]
        bounds = [(k, r) for k, r in conv if _fit_status(r) == 1]
        verdict = "supported" if not bad else "not supported"
        ev = (f"{len(conv) - len(bad)} of {len(conv)} Nielsen fits converged (status 0 or 1); "
              f"{len(bad)} stopped at the evaluation limit, failed or are not finite; "
              f"{len(bounds)} converged with a parameter at a bound.")
        out.append({"paper": "Nielsen 2015", "claim": "the three-stage procedure gives robust "
                    "convergence for all MERL BRDFs", "test": "no fit at the evaluation limit,"
                    " failed or non-finite", "verdict": verdict, "evidence": ev})
    out += _neumann_claims(study)
    return out


def _fit_status(row) -> int:
    s = _f(row.get("fit_status"))
    if math.isfinite(s):
        return int(s)
    # rows written before fit_status existed: read the message
    msg = str(row.get("message", ""))
    for code, text in STATUS["fit"].messages.items():
        if msg.startswith(text):
            return code
    return -1


def _neumann_claims(study) -> list[dict]:
    out = []
    pairs = []
    for plain, _ in NEUMANN_MODELS:
        per = _by_target(study.get(("neumann", f"{plain}-perceptual"), []))
        l2 = _by_target(study.get(("neumann", f"{plain}-l2"), []))
        for t in sorted(set(per) & set(l2)):
            dp, dl = per[t].get("derived"), l2[t].get("derived")
            if dp and dl:
                pairs.append((plain, t, max(_f(dp["e_point"]), _f(dp["e_albedo"])),
                              max(_f(dl["e_point"]), _f(dl["e_albedo"]))))
    if pairs:
        won = [p for p in pairs if p[2] < p[3]]
        verdict = ("supported" if len(won) == len(pairs) else
                   "partly supported" if won else "not supported")
        out.append({"paper": "Neumann 1999 §1.1", "claim": "perceptual fitting (both maximal "
                    "relative errors, point light and sky light, minimised together) gives "
                    "smaller maximal relative errors than least squares", "test": "max(e_point,"
                    " e_albedo) of the perceptual fit below that of the L2 fit", "verdict":
                    verdict, "evidence": f"{len(won)} of {len(pairs)} (model, metal) pairs: "
                    + ", ".join(f"{_name(t)} ({_LABEL[m]}) "
                                f"{a:.3g} vs {b:.3g}" for m, t, a, b in pairs) + "."})
    for stem, label in NEUMANN_MODELS[1:]:
        rows = []
        for loss in ("perceptual", "l2"):
            plain = _by_target(study.get(("neumann", f"phong-{loss}"), []))
            pumped = _by_target(study.get(("neumann", f"{stem}-{loss}"), []))
            for t in sorted(set(plain) & set(pumped)):
                rows.append((loss, t, _f(pumped[t][f"metric_{loss}"]),
                             _f(plain[t][f"metric_{loss}"])))
        if not rows:
            continue
        won = [r for r in rows if r[2] < r[3]]
        verdict = ("supported" if len(won) == len(rows) else
                   "partly supported" if won else "not supported")
        gain = np.median([1.0 - a / b for _, _, a, b in rows if b > 0]) if rows else math.nan
        out.append({"paper": "Neumann 1999 §3, §6", "claim": "pumping up the albedo makes "
                    "Phong fit metals better (a better energy mirror at grazing angles)",
                    "test": f"the one-times {label} fit has a smaller loss than "
                    "the plain fit under the same loss", "verdict": verdict, "evidence":
                    f"{len(won)} of {len(rows)} (loss, metal) pairs; median relative gain "
                    f"{100 * gain:.1f} %: "
                    + ", ".join(f"{_name(t)} {loss} {a:.4g} vs {b:.4g}"
                                for loss, t, a, b in rows) + "."})
    return out


def lobe_positions(study) -> list[dict]:
    """Per material with α-mix fits under both losses: top and base ratios of each."""
    l1 = _by_target(study.get(("nielsen", "alpha-mix-l1"), []))
    l2 = _by_target(study.get(("nielsen", "alpha-mix-l2"), []))
    out = []
    for t in sorted(set(l1) & set(l2)):
        d1, d2 = l1[t].get("derived"), l2[t].get("derived")
        if not (d1 and d2):
            continue
        p = {"target": t, "top_l1": _f(d1["top_ratio"]), "top_l2": _f(d2["top_ratio"]),
             "base_l1": _f(d1["base_ratio"]), "base_l2": _f(d2["base_ratio"])}
        if all(math.isfinite(v) and v > 0 for k, v in p.items() if k != "target"):
            out.append(p)
    return out


# --------------------------------------------------------------------------- figures
def _alpha_figure(study, path):
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


def _fig1_figure(study, path, theta_i=(30.0, 60.0)):
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter

    import brdfkit

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
        m1 = brdfkit.model("nielsen", **_params(l1[t]))
        m2 = brdfkit.model("nielsen", **_params(l2[t]))
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


def _neumann_figure(study, path):
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


# --------------------------------------------------------------------------- markdown
def _num(x, fmt=".4g") -> str:
    return "—" if not (isinstance(x, float | int) and math.isfinite(x)) else format(x, fmt)


def _table(header, rows) -> list[str]:
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    # a "|" inside a cell (|ln x|) would end the cell: escaped
    out += ["| " + " | ".join(str(c).replace("|", "\\|") for c in r) + " |" for r in rows]
    return out


def _anchor_rows(directory) -> list[dict]:
    import csv

    comp = os.path.join(os.fspath(directory), "anchors", "ngan-comparison.csv")
    if not os.path.exists(comp):
        return []
    with open(comp, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def _materials(study) -> list[str]:
    return sorted({r["target"] for rows in study.values() for r in rows})


def _timings(study) -> list[dict]:
    out = []
    for (part, name), rows in study.items():
        s = [_f(r.get("seconds")) for r in rows if _ok(r)]
        s = [x for x in s if math.isfinite(x)]
        d = [_f(r["derived"].get("job_seconds")) for r in rows if r.get("derived")]
        d = [x for x in d if math.isfinite(x)]
        if s:
            out.append({"batch": f"{part}/{name}", "part": part, "n": len(s),
                        "median": float(np.median(s)), "mean": float(np.mean(s)),
                        "total": float(np.sum(s)),
                        "derived_median": float(np.median(d)) if d else math.nan})
    return out


def _full_counts(ngan_names=None) -> dict:
    """Materials per part in the full study: all MERL, its metals, the Ngan overlap."""
    from brdfkit.fitting.batch import expand_targets

    merl = expand_targets(["merl:all"])
    n_ngan = (sum(1 for t in merl if _name(t) in ngan_names) if ngan_names is not None
              else 86)  # SOURCES.md §6: 86 of today's 100 names are in Ngan's table
    return {"nielsen": len(merl), "neumann": sum(map(is_metal, merl)), "anchors": n_ngan}


def write_report(directory, *, out="docs/fitting-study.md", figures="docs/figures/study",
                 ngan_names=None, commands=None) -> str:
    """Write the report of the study under *directory* to *out*, figures to *figures*.

    Returns *out*. ``commands`` (lines) replaces the default "how to remake" block."""
    from brdfkit._io import write_atomic

    study = read_study(directory)
    os.makedirs(figures, exist_ok=True)
    rel = os.path.relpath(figures, os.path.dirname(os.path.abspath(out)))
    mats = _materials(study)
    n = len(mats)
    L: list[str] = ["# Fitting study: what the papers claim, answered by computation", ""]
    if n < FULL_MATERIALS:
        L += [f"> **Subset run: {n} of {FULL_MATERIALS} MERL materials** ("
              + ", ".join(_name(t) for t in mats) + "). Every number below describes only "
              "these materials; it is not the study's result. Remake the full study with the "
              "commands at the end.", ""]
    L += ["Generated by `scripts/fit_study.py report` from the batch files of "
          "`scripts/fit_study.py run` (`brdfkit.fitting.study`, `brdfkit.report.fit_study`): "
          "every table and every verdict below is computed from those files. The targets are "
          "brdfkit's built-in MERL surrogates (`merl:NAME`, see `docs/fitting.md`), not the "
          "measured tables: where a verdict differs from a paper, the surrogate may be the "
          "cause as much as the model.", ""]
    # ------------------------------------------------------------------ verdicts
    L += ["## The claims and the verdicts", ""]
    arows = _anchor_rows(directory)
    cl = claims(study)
    if arows:
        good = [r for r in arows if _f(r["ratio"]) <= 1.0]
        cl.append({"paper": "Ngan 2005 (issue 10 §5)", "claim": "our Lafortune fits are at "
                   "least as good as Ngan et al.'s published ones under their own metric",
                   "test": "ours / theirs ≤ 1 on every material (same surrogate, loss ngan)",
                   "verdict": "supported" if len(good) == len(arows) else "not supported",
                   "evidence": f"{len(good)} of {len(arows)} materials; ratios "
                   + ", ".join(f"{_name(r['target'])} {_f(r['ratio']):.3f}" for r in arows)
                   + f" (their table read as '{arows[0]['convention']}')."})
    L += _table(["paper", "claim", "test", "verdict", "evidence"],
                [(c["paper"], c["claim"], c["test"], f"**{c['verdict']}**", c["evidence"])
                 for c in cl])
    L += [""]
    # ------------------------------------------------------------------ Nielsen
    t1 = nielsen_table(study, "l1")
    if t1:
        L += ["## Nielsen et al. 2015: Phong, Blinn–Phong and the α-mix (L1, Fresnel, η free)",
              "", "All three are `nielsen` (eq. 3) with Fresnel (η fitted per channel from "
              "1.5): Phong holds α = 0, Blinn–Phong α = 1. Procedure `nielsen` (stages i–iii)."
              " Lowest L1 per material in bold.", ""]
        t2 = {r["target"]: r for r in nielsen_table(study, "l2")}
        rows = []
        for r in t1:
            cells = [(_num(r[v]) if v != r["best"] else f"**{_num(r[v])}**")
                     for v in NIELSEN_VARIANTS]
            rows.append([_name(r["target"]), *cells, r["kind"], _num(100 * r["gain"], ".2f"),
                         _num(r["alpha"], ".3f"),
                         _num(t2.get(r["target"], {}).get("alpha", math.nan), ".3f")])
        L += _table(["material", "L1 Phong", "L1 Blinn–Phong", "L1 α-mix",
                     "Phong vs Blinn–Phong (> 1 %)", "α-mix gain (%)", "α (L1)", "α (L2)"],
                    rows)
        cnt = Counter(r["best"] for r in t1 if r["best"])
        kinds = Counter(r["kind"] for r in t1)
        L += ["", "Lowest L1 per material: " + ", ".join(
            f"{VARIANT_LABEL[v]} {cnt.get(v, 0)}" for v in NIELSEN_VARIANTS)
            + ". Phong below Blinn–Phong by more than 1 %: " + str(kinds.get("Phong", 0))
            + "; Blinn–Phong below Phong by more than 1 %: " + str(kinds.get("Blinn–Phong", 0))
            + f"; ties: {kinds.get('tie', 0)}. α-mix gain: 1 − L1(α-mix) / min(L1 Phong, L1 "
            "Blinn–Phong); it nests both (α = 0, 1), so a negative gain is an optimiser "
            "failure.", ""]
        p = _alpha_figure(study, os.path.join(figures, "alpha-histogram.png"))
        ties = [r for r in t1 if r["tie"]]
        L += [f"![α of the α-mix fits]({rel}/{os.path.basename(p)})", "",
              f"Where Phong and Blinn–Phong tie (L1 within 1 %: {len(ties)} of {len(t1)} "
              "materials" + (": " + ", ".join(_name(r["target"]) for r in ties) if ties
                             else "") + "), the data do not determine α: its value there "
              "says nothing about the material.", ""]
        pos = lobe_positions(study)
        if pos:
            L += ["### L1 vs L2: where the fitted lobe sits", "",
                  "In the incidence plane at θ_i = 30°: *top* = fitted / measured f·cos θ_i "
                  "at the measured peak; *base* = width of the fitted slice above the measured "
                  "lobe's base level (floor + 10 % of its height) / the measured width. 1 is "
                  "exact for both.", ""]
            L += _table(["material", "top L1", "top L2", "base L1", "base L2"],
                        [[_name(p["target"]), _num(p["top_l1"], ".3f"),
                          _num(p["top_l2"], ".3f"), _num(p["base_l1"], ".3f"),
                          _num(p["base_l2"], ".3f")] for p in pos])
            L += [""]
        p = _fig1_figure(study, os.path.join(figures, "nielsen-fig1-slices.png"))
        if p:
            L += ["The four materials of Nielsen's Fig. 1 (those in this run): measured "
                  "(surrogate) and the α-mix's L1 and L2 fits, log scale.", "",
                  f"![Fig. 1 materials: in-plane slices]({rel}/{os.path.basename(p)})", ""]
    # ------------------------------------------------------------------ Neumann
    neu = [(k, rows) for k, rows in study.items() if k[0] == "neumann"]
    if neu:
        L += ["## Neumann et al. 1999: perceptual vs L2 fits, pumped vs plain Phong (metals)",
              "", "Metals: MERL names containing one of " + ", ".join(f"`{w}`" for w in
                                                                     METAL_WORDS)
              + " and not `paint`. e_point = max |ln((f̂ cos θ_i + τ)/(f cos θ_i + τ))| over "
              "the fit's samples (τ: the perceptual loss's floor), e_albedo = max |ln(â/a)| "
              "over θ_i = 0…80° (true maxima, not the smooth means optimised).", "",
              "Pumped once with g₁ = max(a(L), a(V)) (eq. 20) the model's albedo at normal "
              "incidence is 1 whatever ρ_d, ρ_s are (f/g₁ does not see their common scale; "
              "the fit holds it), so it cannot match a metal's level; with the controlled "
              "g₂ = max(a(L), a(V), N·L, N·V) (eq. 21) the scale is kept. Both are fitted.", ""]
        rows = []
        for model, label in NEUMANN_MODELS:
            for loss in ("perceptual", "l2"):
                for t, r in sorted(_by_target(study.get(("neumann", f"{model}-{loss}"),
                                                        [])).items()):
                    d = r.get("derived") or {}
                    rows.append([_name(t), label,
                                 loss, _num(_f(d.get("e_point")), ".3f"),
                                 _num(_f(d.get("e_albedo")), ".3f"),
                                 _num(_f(r.get("metric_perceptual")), ".4g"),
                                 _num(_f(r.get("metric_l2")), ".4g")])
        rows.sort(key=lambda c: (c[0], c[1], c[2]))
        L += _table(["metal", "model", "fitted with", "e_point", "e_albedo", "perceptual",
                     "l2"], rows)
        p = _neumann_figure(study, os.path.join(figures, "neumann-errors.png"))
        if p:
            L += ["", f"![perceptual vs L2 errors]({rel}/{os.path.basename(p)})"]
        per = [r.get("derived") for k, rr in neu if k[1].endswith("-perceptual") for r in rr
               if _ok(r) and r.get("derived")]
        if per:
            dom = sum(_f(d["e_point"]) > _f(d["e_albedo"]) for d in per)
            L += ["", f"In {dom} of {len(per)} perceptual fits the point-light error exceeds "
                  "the albedo error; where it does, the loss's smooth maximum (power mean, "
                  "p = 8) is set by the point-light term, and the fit trades albedo accuracy "
                  "for it — the perceptual fit's albedo error can then exceed the L2 fit's."]
        L += [""]
    # ------------------------------------------------------------------ anchors
    if arows:
        conv = arows[0]["convention"]
        L += ["## Anchors: our Lafortune fits vs Ngan et al. 2005's published parameters",
              "", "Both evaluated on the same surrogate under Ngan's metric (loss `ngan`: "
              "cosine-weighted RMS over θ_i, θ_o ≤ 80°). Ngan's table is read at run time "
              "(GPL; never copied), G and B × 1.15, 1.66 (SOURCES.md §6). How the table's "
              "unit (C_xy, C_z) enter the lobe is not stated. Three readings: *as-printed* "
              "ρ_s (C_xy (u_x v_x + u_y v_y) + C_z u_z v_z)ⁿ; *peak-one* (C_xy, C_z) divided "
              "by max(|C_xy|, |C_z|); *normalised* peak-one with ρ_s·(n + 2)/(2π). The "
              "reading used is the one "
              f"with the smallest median metric over these materials (most favourable to "
              f"their parameters): **{conv}**. Ratio ≤ 1: ours at least as good.", ""]
        L += _table(["material", "ours", "theirs", "ratio",
                     *[f"theirs ({c})" for c in NGAN_CONVENTIONS]],
                    [[_name(r["target"]), _num(_f(r["ours"])), _num(_f(r["theirs"])),
                      _num(_f(r["ratio"]), ".3f"),
                      *[_num(_f(r[f"theirs_{c}"])) for c in NGAN_CONVENTIONS]]
                     for r in arows])
        good = sum(_f(r["ratio"]) <= 1.0 for r in arows)
        L += ["", f"Ours at least as good on {good} of {len(arows)} materials "
              f"({'every one' if good == len(arows) else 'not every one'}).", ""]
    # ------------------------------------------------------------------ plausibility
    L += ["## Plausibility of the fitted models and convergence", "",
          "Every fitted model through `brdfkit check` (`brdfkit.analysis.plausibility.check`, "
          "albedo tolerance 1e-5): energy verdict; *at a bound*: a fitted parameter at a bound "
          "of its declared range; status: the fit's own (0 converged, 1 converged at a bound, "
          "2 evaluation limit, 3 non-finite).", ""]
    rows = []
    for (part, name), rr in sorted(study.items()):
        fits = [r for r in rr if _ok(r)]
        energy = Counter((r.get("derived") or {}).get("energy", "not derived") for r in fits)
        status = Counter(_fit_status(r) for r in fits)
        at_b = sum(1 for r in fits if json.loads(r.get("at_bounds") or "[]"))
        rows.append([f"{part}/{name}", len(rr), energy.get("conserves", 0),
                     energy.get("exceeds", 0), energy.get("diverges", 0),
                     energy.get("undetermined", 0) + energy.get("not derived", 0), at_b,
                     " ".join(f"{k}:{status.get(k, 0)}" for k in (0, 1, 2, 3)),
                     len(rr) - len(fits)])
    L += _table(["batch", "fits", "conserves", "exceeds", "diverges", "undetermined / not "
                 "derived", "at a bound", "status 0:1:2:3", "errors"], rows)
    L += [""]
    # ------------------------------------------------------------------ timings
    tim = _timings(study)
    if tim:
        full = _full_counts(ngan_names)
        L += ["## Timings and the predicted full-study time", "",
              "Wall seconds per fit inside one worker, measured while a second worker (and "
              "other jobs: 2 cores shared, load ≈ 5) ran, and per derived row (the check of "
              "the fitted model dominates). Predicted: (median per fit + median per derived "
              "row) × the full study's fits of that batch ÷ 2 workers.", ""]
        rows, total = [], 0.0
        for t in tim:
            nf = full[t["part"]]
            pred = (t["median"] + (t["derived_median"] if math.isfinite(t["derived_median"])
                                   else 0.0)) * nf / 2.0
            total += pred
            rows.append([t["batch"], t["n"], _num(t["median"], ".1f"), _num(t["mean"], ".1f"),
                         _num(t["derived_median"], ".1f"), nf, _num(pred / 60.0, ".1f")])
        L += _table(["batch", "fits here", "median s/fit", "mean s/fit", "median s/derived",
                     "fits in full study", "predicted min (--workers 2)"], rows)
        timed = {t["batch"] for t in tim}
        missing = [f"{b.part}/{b.name}" for b in study_batches(mats, ngan_names=ngan_names)
                   if b.targets and f"{b.part}/{b.name}" not in timed]
        if missing:
            L += ["", "**Not timed** (no finished fit in this run, so left out of the "
                  "prediction): " + ", ".join(f"`{m}`" for m in missing) + "."]
        n_merl = full["nielsen"]
        l1 = sum(t["median"] for t in tim if t["part"] == "nielsen"
                 and t["batch"].endswith("-l1")) * n_merl / 2.0 / 60.0
        allp = sum(t["median"] for t in tim if t["part"] == "nielsen") * n_merl / 2.0 / 60.0
        L += ["", f"Predicted full study: **{total / 60:.0f} min** with `--workers 2`. Issue "
              f"10 §6 asks ≤ 10 min for the {n_merl}-material × 3-model Nielsen study (L1): "
              f"by these medians it takes {l1:.0f} min (all six Nielsen batches, L1 and L2: "
              f"{allp:.0f} min; both without the derived rows).", ""]
    # ------------------------------------------------------------------ commands
    ngan_arg = "--ngan ../shared/data/measured/merl_fits_lafortune_ngan2005.csv"
    here = os.path.relpath(os.fspath(directory))
    L += ["## Remake", "", "From the repository root (Ngan's table is read from `../shared/`;"
          " `--ngan PATH` or `BRDFKIT_NGAN_CSV` point elsewhere). Fits and derived rows are "
          "resumable: re-run the same command to continue; delete the directory (or one "
          "part's folder and its `derived/` files) to refit after a change of the fitting "
          "code.", "", "```bash"]
    if commands:
        L += list(commands)
    else:
        if n < FULL_MATERIALS:
            L += ["# this subset run",
                  f"PYTHONPATH=src python scripts/fit_study.py run --dir {here} --materials "
                  + ",".join(mats) + f" --workers 2 {ngan_arg}",
                  f"PYTHONPATH=src python scripts/fit_study.py report --dir {here}", ""]
        L += ["# the full study (every MERL material)",
              f"PYTHONPATH=src python scripts/fit_study.py run --dir {here} --materials "
              f"merl:all --workers 2 {ngan_arg}",
              f"PYTHONPATH=src python scripts/fit_study.py report --dir {here}"]
    L += ["```", ""]
    text = "\n".join(L)
    write_atomic(out, lambda fh: fh.write(text.encode("utf-8")))
    return out
