"""
Nielsen, Frisvad, Conradsen, Aanæs (2015), "Addressing Grazing Angle Reflections in Phong
Models": its claims as records
=========================================================================================

The formula claims (eqs. 1–3) are computed with the albedo engine and the models; the
fitting claims come from the fitting study (:mod:`brdfkit.report.claims_study`) and its
per-material table (:func:`brdfkit.report.fit_study_verdicts.nielsen_table`).
"""

from __future__ import annotations

import math

import numpy as np

from brdfkit.report.claim_record import Claim, Outcome
from brdfkit.report.claims_study import read_shipped_study, study_claim

__all__ = ["CLAIMS"]

PAPER = "nielsen"
EXPONENTS = (1.0, 4.0, 10.0, 100.0, 1000.0)


# ----------------------------------------------------------------- eqs. (1), (2)
def _normal_albedo(name):
    def compute(ctx):
        import brdfkit
        from brdfkit.analysis import albedo

        out = {}
        for s in EXPONENTS:
            m = brdfkit.model(name, rho_d=0.0, rho_s=1.0, n=s)
            r = albedo(m, [0.0])
            out[f"{s:g}"] = float(np.asarray(r.albedo, dtype=float)[0])
        return {"model": name, "albedo_at_normal_incidence": out}
    return compute


def _normalisation_rule(numbers, tol) -> Outcome:
    a = numbers["albedo_at_normal_incidence"]
    off = {s: v for s, v in a.items() if abs(v - 1.0) > tol}
    text = ("albedo of the specular term with ρ_s = 1 at θ_i = 0: " + ", ".join(
        f"s = {s}: {v:.6f}" for s, v in a.items()))
    if not off:
        return Outcome("confirmed", text + ".")
    return Outcome("confirmed with a correction", text + f" (rule: |a − 1| ≤ {tol:g}).",
                   "(s + 8)/(8π) is an approximation of the normalisation of (N·H)^s (exact "
                   "for s → ∞); ρ_s is the normal-incidence albedo only with the exact factor "
                   "1/∫(N·H)^s cos θ dω, e.g. " + ", ".join(
                       f"s = {s}: ({s} + 8)/(8π) ÷ {v:.6f}" for s, v in off.items())
                   + ("; with ρ_s = 1 the albedo exceeds 1 (energy is created) at s = "
                      + ", ".join(s for s, v in off.items() if v > 1.0)
                      if any(v > 1.0 for v in off.values()) else ""))


# ----------------------------------------------------------------- eq. (3): the factor 4
def _factor4(ctx):
    out = {}
    for s in (10.0, 100.0, 1000.0):
        beta_p = math.acos(0.5 ** (1.0 / s))  # (R·V)^s = 1/2 at θ_v = β, S = N
        # (N·H)^(k s) = 1/2 at the same θ_v: N·H = cos(θ_v/2) with S = N
        k = math.log(0.5) / (s * math.log(math.cos(beta_p / 2.0)))
        out[f"{s:g}"] = {"half_width_deg": math.degrees(beta_p), "blinn_exponent_ratio": k}
    return {"s": out}


def _factor4_rule(numbers, tol) -> Outcome:
    d = numbers["s"]
    ok = all(abs(v["blinn_exponent_ratio"] / 4.0 - 1.0) <= tol for v in d.values())
    return Outcome("confirmed" if ok else "refuted",
                   "at normal incidence, the Blinn–Phong exponent with the same half width as "
                   "Phong's s: " + ", ".join(f"s = {s}: {v['blinn_exponent_ratio']:.4f} s "
                                              f"(half width {v['half_width_deg']:.2f}°)"
                                              for s, v in d.items()) + ".")


# ----------------------------------------------------------------- Fig. 1 examples
def _fig1(ctx):
    from brdfkit.report.fit_study_verdicts import BETTER_MARGIN, nielsen_table

    rows = {r["target"]: r for r in nielsen_table(read_shipped_study(ctx.study_dir), "l1")}
    out = {}
    for name in ("two-layer-silver", "nickel"):
        r = rows.get(f"merl:{name}")
        out[name] = (None if r is None else
                     {"l1_phong": r["phong"], "l1_blinn_phong": r["blinn-phong"],
                      "kind": r["kind"]})
    return {"materials": out, "margin": BETTER_MARGIN}


def _fig1_rule(material, paper_kind):
    def rule(numbers, tol):
        r = numbers["materials"][material]
        if r is None:
            return Outcome("undetermined", f"the study's batches hold no L1 fits of "
                           f"{material}")
        text = (f"{material}: L1 Phong {r['l1_phong']:.4g}, Blinn–Phong "
                f"{r['l1_blinn_phong']:.4g} → {r['kind']} (a variant wins when lower by more "
                f"than {100 * numbers['margin']:g} %; fits to the MERL surrogate)")
        return Outcome("confirmed" if r["kind"] == paper_kind else "refuted", text + ".")
    return rule


_S1 = "Common Phong variants (eqs. 1–2)"
_S3 = "The new variant (eq. 3)"
_SF = "Fitting results (Fig. 1, the L1 norm, the procedure)"

CLAIMS = (
    Claim("nielsen-eq1-normalisation", PAPER, "eq. (1)",
          "In the modified Phong model ρ_s (s + 2)/(2π) (ω_r·ω_o)^s, ρ_s is the specular "
          "reflectance.",
          "albedo engine of modified-phong (ρ_d = 0, ρ_s = 1) at θ_i = 0 for s = 1, 4, 10, "
          "100, 1000; rule: |a − 1| ≤ tol.",
          _normal_albedo("modified-phong"), _normalisation_rule, 1e-6, _S1),
    Claim("nielsen-eq2-normalisation", PAPER, "eq. (2)",
          "In the modified Blinn–Phong model ρ_s (s + 8)/(8π) (ω_h·n)^s, ρ_s is the specular "
          "reflectance.",
          "albedo engine of modified-blinn-phong (ρ_d = 0, ρ_s = 1) at θ_i = 0 for s = 1, 4, "
          "10, 100, 1000; rule: |a − 1| ≤ tol.",
          _normal_albedo("modified-blinn-phong"), _normalisation_rule, 1e-2, _S1),
    Claim("nielsen-eq3-factor-4", PAPER, "eq. (3)",
          "The Phong exponent is roughly 4 times stronger than the Blinn–Phong exponent, "
          "hence (ω_h·n)^4 in the mix.",
          "closed form at normal incidence (ω_r = n, ω_h·n = cos(θ_o/2)): the Blinn–Phong "
          "exponent whose half width equals that of (ω_r·ω_o)^s, for s = 10, 100, 1000; "
          "rule: within tol of 4 s.", _factor4, _factor4_rule, 0.05, _S3),
    Claim("nielsen-fig1a-silver-phong", PAPER, "Fig. 1(a)",
          "The reflectance at grazing angles of two-layer-silver is Phong-like (Phong fits "
          "it best).",
          "the study's L1 fits of Phong and Blinn–Phong (both with Fresnel, η free) to the "
          "MERL surrogate.", _fig1, _fig1_rule("two-layer-silver", "Phong"), None, _SF),
    Claim("nielsen-fig1c-nickel-blinn", PAPER, "Fig. 1(c)",
          "The reflectance at grazing angles of nickel is Blinn–Phong-like.",
          "the study's L1 fits of Phong and Blinn–Phong (both with Fresnel, η free) to the "
          "MERL surrogate.", _fig1, _fig1_rule("nickel", "Blinn–Phong"), None, _SF),
    study_claim(id="nielsen-both-kinds", paper=PAPER, location="Comparison to measured BRDFs",
                section=_SF,
                statement="Some materials are fitted best by the Phong variant (1), others by "
                "the Blinn–Phong variant (2)."),
    study_claim(id="nielsen-alpha-mix-better", paper=PAPER, location="Our Phong model variant",
                section=_S3,
                statement="The new variant (eq. 3) fits better to a broader range of "
                "materials."),
    study_claim(id="nielsen-l1-l2", paper=PAPER, location="Fitting results", section=_SF,
                statement="L² fits the lobe to the tops of the specular highlights, L¹ roughly "
                "to their base."),
    study_claim(id="nielsen-robust", paper=PAPER, location="Fitting results, stages (i)–(iii)",
                section=_SF,
                statement="The three-stage procedure gives robust convergence for all the "
                "BRDFs measured by Matusik et al."),
)
