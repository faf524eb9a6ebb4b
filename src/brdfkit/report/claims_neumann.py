"""
Neumann, Neumann, Szirmay-Kalos (1999), "Reflectance Models by Pumping up the Albedo
Function": its claims as records
====================================================================================

As :mod:`brdfkit.report.claims_lewis`: each claim states the paper's words and where, the
computation (the albedo engine, the pumping operator, ρ_hh, the mirror radiance of
eq. 3) and the rule of its verdict; :data:`CLAIMS` lists them in the paper's order. The
fitting claims (§1.1, §3/§6 on metals) come from the fitting study
(:mod:`brdfkit.report.claims_study`).
"""

from __future__ import annotations

import math

import numpy as np

from brdfkit.report.claim_record import Claim, Outcome
from brdfkit.report.claims_study import study_claim

__all__ = ["CLAIMS"]

PAPER = "neumann"
#: A pumping "is worth it" when it adds ≥ 5 % of the incident energy to ρ_hh and adds
#: "not significantly" when < 2 % (stated criteria, as in tests/test_pumping.py).
WORTH, INSIGNIFICANT = 0.05, 0.02
#: cos θ_i at which a divergence exponent is read: a ∝ (N·L)^−p.
GRAZING_COS = (1e-2, 1e-3, 1e-4)


def _phong(n=20.0):
    import brdfkit

    return brdfkit.model("modified-phong", rho_d=0.0, rho_s=1.0, n=float(n))


def _blinn(n=20.0):
    """Neumann's reciprocal Blinn (eq. 6) scaled to albedo 1 at normal incidence."""
    from brdfkit.figures.pumping import reciprocal_blinn

    return reciprocal_blinn(n)


def _slope(a) -> float:
    """p of a ∝ (N·L)^−p from the last two of :data:`GRAZING_COS`."""
    return float(math.log(a[-1] / a[-2]) / math.log(GRAZING_COS[-2] / GRAZING_COS[-1]))


# ----------------------------------------------------------------- §2.1 eqs. (14), (15)
def _divergence(name, **params):
    def compute(ctx):
        import brdfkit
        from brdfkit.analysis import albedo

        m = brdfkit.model(name, **params)
        a = np.asarray(albedo(m, np.arccos(GRAZING_COS)).albedo, dtype=float)
        return {"model": name, "params": params, "cos_theta_i": list(GRAZING_COS),
                "albedo": a.tolist(), "exponent_p": _slope(a)}
    return compute


def _ward_rule(numbers, tol) -> Outcome:
    p = numbers["exponent_p"]
    text = (f"a(θ_i) at N·L = {', '.join(f'{c:g}' for c in numbers['cos_theta_i'])}: "
            f"{', '.join(f'{x:.4g}' for x in numbers['albedo'])}; a ∝ (N·L)^−p with p = "
            f"{p:.3f} (eq. 14: p = 1/2)")
    return Outcome("confirmed" if abs(p - 0.5) <= tol else "refuted", text + ".")


def _cook_rule(numbers, tol) -> Outcome:
    p = numbers["exponent_p"]
    a = numbers["albedo"]
    text = (f"a(θ_i) at N·L = {', '.join(f'{c:g}' for c in numbers['cos_theta_i'])}: "
            f"{', '.join(f'{x:.6g}' for x in a)}; a ∝ (N·L)^−p with p = {p:.3g} (eq. 15: "
            "p = 1)")
    if abs(p - 1.0) <= tol:
        return Outcome("confirmed", text + ".")
    return Outcome("refuted", text + ": bounded, tending to 1. The proof's 'critical "
                   "region' where G = 1 shrinks with N·L (G ≤ 2(N·H)(N·L)/(L·H)), so a ≤ "
                   "∫ 2 D (N·H) dω_h = 2: eq. (12) cannot hold on a fixed region.")


# ----------------------------------------------------------------- §1.2 the cosine limit
def _cos_limit(ctx):
    from brdfkit.analysis import albedo

    theta = np.array([30.0, 60.0, 80.0])
    out = {}
    for n in (20.0, 500.0, 5000.0):
        a = np.asarray(albedo(_phong(n), np.radians(theta)).albedo, dtype=float)
        out[f"{n:g}"] = (a - np.cos(np.radians(theta))).tolist()
    return {"theta_deg": theta.tolist(), "albedo_minus_cos": out}


def _cos_limit_rule(numbers, tol) -> Outcome:
    d = numbers["albedo_minus_cos"]
    worst = {n: max(abs(x) for x in v) for n, v in d.items()}
    ws = list(worst.values())
    ok = all(b < a for a, b in zip(ws, ws[1:], strict=False)) and ws[-1] <= tol
    return Outcome("confirmed" if ok else "refuted",
                   "max |a(θ) − cos θ| over θ_i = 30, 60, 80° of the reciprocal Phong "
                   "(ρ_s = 1): " + ", ".join(f"n = {n}: {w:.2e}" for n, w in worst.items())
                   + " (decreasing towards 0).")


# ----------------------------------------------------------------- §2, Fig. 1 darkening
def _darkening(ctx):
    import brdfkit
    from brdfkit.analysis import albedo

    theta = np.radians([0.0, 45.0, 70.0, 85.0, 89.9])
    models = {"Phong n = 150": _phong(150.0),
              "He–Torrance σ₀ = 0.1, τ = 1.7": brdfkit.model("he-torrance")}
    return {"theta_deg": [0.0, 45.0, 70.0, 85.0, 89.9],
            "albedo": {k: np.asarray(albedo(m, theta).albedo, dtype=float).tolist()
                       for k, m in models.items()}}


def _darkening_rule(numbers, tol) -> Outcome:
    a = numbers["albedo"]
    ok = all(v[-1] < tol * max(v) for v in a.values())
    return Outcome("confirmed" if ok else "refuted", "a(θ_i) at " + ", ".join(
        f"{t:g}°" for t in numbers["theta_deg"]) + ": " + "; ".join(
        f"{k}: " + ", ".join(f"{x:.3g}" for x in v) for k, v in a.items())
        + f" (rule: a(89.9°) < {tol:g} × max).")


# ----------------------------------------------------------------- §3 eq. (19)
def _eq19(ctx):
    from brdfkit.analysis import albedo
    from brdfkit.pumping import pump

    theta = np.radians(np.linspace(0.0, 89.0, 9))
    out = {}
    for label, base in (("Phong n = 20", _phong()), ("Blinn n = 20", _blinn())):
        a = np.asarray(albedo(base, theta).albedo, dtype=float)
        b = np.asarray(albedo(pump(base, "max"), theta).albedo, dtype=float)
        out[label] = {"a": a.tolist(), "a_star": b.tolist()}
    return {"theta_deg": np.degrees(theta).tolist(), "models": out}


def _eq19_rule(numbers, tol) -> Outcome:
    ok, parts = True, []
    for k, v in numbers["models"].items():
        a_base, a_star = np.array(v["a"]), np.array(v["a_star"])
        below = a_base < 1.0 - tol  # where a = 1 the paper's Ω_V is empty and a* = a = 1
        ok &= bool(np.all(a_base[below] < a_star[below]) and np.all(a_star <= 1.0 + tol)
                   and np.all(np.abs(a_star[~below] - 1.0) <= tol))
        parts.append(f"{k}: a = {', '.join(f'{x:.3f}' for x in a_base)}; a* = "
                     f"{', '.join(f'{x:.3f}' for x in a_star)}; max a* = "
                     f"{np.max(a_star):.7f}")
    return Outcome("confirmed" if ok else "refuted",
                   "θ_i = 0…89° (9 angles), pumped once with g₁: " + "; ".join(parts)
                   + " (where a = 1, at normal incidence, a* = 1 as the paper says).")


# ----------------------------------------------------------------- §3.1/§3.2 ρ_hh sequences
def _rho_sequence(base_fn, g):
    def compute(ctx):
        from brdfkit.analysis import hemispherical_albedo
        from brdfkit.pumping import pump_sequence

        seq = pump_sequence(base_fn(), g, times=3)
        rho = [float(hemispherical_albedo(m, n=24).value) for m in seq]
        return {"g": g, "rho_hh": rho, "gains": np.diff(rho).tolist()}
    return compute


def _converge_rule(numbers, tol) -> Outcome:
    gaps = [1.0 - r for r in numbers["rho_hh"]]
    ok = all(b < a * tol for a, b in zip(gaps, gaps[1:], strict=False))
    return Outcome("confirmed" if ok else "refuted",
                   "ρ_hh after 0…3 pumpings with g₁: " + ", ".join(
                       f"{r:.4f}" for r in numbers["rho_hh"]) + "; 1 − ρ_hh shrinks by "
                   + ", ".join(f"×{b / a:.2f}" for a, b in zip(gaps, gaps[1:], strict=False))
                   + f" per pumping (rule: each < ×{tol:g}).")


def _phong_worth_rule(numbers, tol) -> Outcome:
    g = numbers["gains"]
    ok = g[0] > WORTH and g[1] > WORTH and g[2] < INSIGNIFICANT
    return Outcome("confirmed" if ok else "refuted",
                   "ρ_hh after 0…3 controlled pumpings: " + ", ".join(
                       f"{r:.4f}" for r in numbers["rho_hh"]) + "; gains " + ", ".join(
                       f"{x:.4f}" for x in g) + f" (worth it: > {WORTH:g}; not "
                   f"significant: < {INSIGNIFICANT:g}).")


def _blinn_second_rule(numbers, tol) -> Outcome:
    g = numbers["gains"]
    ok = g[1] < INSIGNIFICANT and g[2] < INSIGNIFICANT
    text = ("ρ_hh after 0…3 controlled pumpings: " + ", ".join(
        f"{r:.4f}" for r in numbers["rho_hh"]) + "; gains " + ", ".join(
        f"{x:.4f}" for x in g) + f" (not significant: < {INSIGNIFICANT:g})")
    if ok:
        return Outcome("confirmed", text + ".")
    return Outcome("refuted", text + ": the first controlled pumping is the one held back "
                   "(g₂ = N·L wherever a < cos θ); after it a* ≥ cos θ almost everywhere, "
                   "g₂ = g₁, and the albedo tends to 1.")


# ----------------------------------------------------------------- §3.2/§5 the radiance bound
def _mirror_bound(ctx):
    from brdfkit.pumping import mirror_radiance, pump_sequence

    th = np.radians(np.linspace(0.0, 89.9, 400))
    out = {}
    for label, base in (("Blinn n = 20", _blinn()), ("Phong n = 20", _phong())):
        seq = pump_sequence(base, "controlled", times=2)
        c = float(np.asarray(mirror_radiance(base, [0.0]))[0])
        out[label] = [float(np.max(mirror_radiance(m, th))) / c for m in seq[1:]]
    return {"peak_over_c": out, "stages": [1, 2]}


def _mirror_bound_rule(numbers, tol) -> Outcome:
    p = numbers["peak_over_c"]
    one = all(v[0] <= 1.0 + tol for v in p.values())
    two = all(v[1] <= 1.0 + tol for v in p.values())
    text = ("largest mirror radiance f(L, R) cos θ_L over θ_L ≤ 89.9°, ÷ its normal-"
            "incidence value c: " + "; ".join(
                f"{k}: one controlled pumping {v[0]:.4f}, two {v[1]:.3f}" for k, v in p.items()))
    if one and two:
        return Outcome("confirmed", text + ".")
    if one:
        return Outcome("confirmed with a correction", text + ".",
                       "the bound L_out ≤ f(L, V) holds for ONE controlled pumping (g₂ ≥ N·L); "
                       "repeated pumpings lose it (g₂ = g₁ once a ≥ cos θ)")
    return Outcome("refuted", text + ".")


# ----------------------------------------------------------------- §3.1 super-metal (g₁)
def _super_metal(ctx):
    from brdfkit.pumping import mirror_radiance, pump_sequence

    th = np.radians(np.linspace(0.0, 89.9, 400))
    base = _blinn()
    c = float(np.asarray(mirror_radiance(base, [0.0]))[0])
    seq = pump_sequence(base, "max", times=3)
    return {"peak_over_c": [float(np.max(mirror_radiance(m, th))) / c for m in seq],
            "pumpings": [0, 1, 2, 3]}


def _super_metal_rule(numbers, tol) -> Outcome:
    p = numbers["peak_over_c"]
    ok = p[-1] > 1.0 + tol and all(b > a for a, b in zip(p, p[1:], strict=False))
    return Outcome("confirmed" if ok else "refuted",
                   "largest mirror radiance f(L, R) cos θ_L of the reciprocal Blinn (n = 20) ÷ "
                   "its normal-incidence value, after 0…3 pumpings with g₁: " + ", ".join(
                       f"{x:.3f}" for x in p) + f" (rule: growing, above 1 + {tol:g}).")


# ----------------------------------------------------------------- §4 Fig. 8 brighter
def _fig8_brighter(ctx):
    from brdfkit.colour import LUMINANCE
    from brdfkit.figures.neumann_fig8 import EXPONENTS, fig8_panels
    from brdfkit.render.metals import spectral_to_linear_srgb

    size, spp = (96, 8) if not ctx.full else (320, 16)
    res = fig8_panels(spp=spp, size=size, seed=0, progress=False)
    mean = {}
    for (pumped, n), img in res["images"].items():
        rgb = np.nan_to_num(np.asarray(spectral_to_linear_srgb(img), dtype=float))
        mean[f"{'pumped' if pumped else 'plain'} n={n:g}"] = float(np.mean(rgb @ LUMINANCE))
    return {"size": size, "spp": spp, "seed": 0, "mean_luminance": mean,
            "ratio_pumped_over_plain": {f"{n:g}": mean[f"pumped n={n:g}"]
                                        / mean[f"plain n={n:g}"] for n in EXPONENTS}}


def _fig8_brighter_rule(numbers, tol) -> Outcome:
    r = numbers["ratio_pumped_over_plain"]
    ok = all(v > 1.0 + tol for v in r.values())
    return Outcome("confirmed" if ok else "refuted",
                   f"mean luminance of the tank image (Monte Carlo, {numbers['size']} px, "
                   f"{numbers['spp']} spp, seed {numbers['seed']}), pumped once ÷ plain: "
                   + ", ".join(f"n = {n}: {v:.3f}" for n, v in r.items())
                   + f" (rule: > 1 + {tol:g} for both exponents).")


# ----------------------------------------------------------------- §3.2 eq. (22)
def _eq22(ctx):
    import brdfkit
    from brdfkit.analysis import albedo

    theta = np.radians(np.linspace(0.0, 89.9, 180))
    out = {}
    for n in (1.0, 2.0, 5.0, 20.0, 100.0):
        m = brdfkit.model("neumann-phong", c_n=(n + 2) / (2 * math.pi), n=n)
        r = albedo(m, theta)
        a = np.asarray(r.albedo, dtype=float)
        i = int(np.argmax(a))
        out[f"{n:g}"] = {"max_albedo": float(a[i]), "at_deg": float(np.degrees(theta[i])),
                         "error": float(np.max(np.asarray(r.error, dtype=float)))}
    return {"n": out}


def _eq22_rule(numbers, tol) -> Outcome:
    d = numbers["n"]
    bad = {n: v for n, v in d.items() if v["max_albedo"] > 1.0 + tol}
    text = ("max albedo of eq. (22) with c_n = (n + 2)/2π: " + ", ".join(
        f"n = {n}: {v['max_albedo']:.6f} at {v['at_deg']:.1f}° (±{v['error']:.0e})"
        for n, v in d.items()))
    if not bad:
        return Outcome("confirmed", text + ".")
    if all(float(n) < 20.0 for n in bad):  # the paper's figures use n ≥ 20
        return Outcome("confirmed with a correction", text + ".", "; ".join(
            f"at n = {n} the bound must be c_n ≤ (n + 2)/(2π · {v['max_albedo']:.6f})"
            for n, v in bad.items()) + " (the albedo exceeds 1 at oblique incidence)")
    return Outcome("refuted", text + ".")


_S1 = "§1 Introduction: perceptual fitting, plausible models"
_S2 = "§2 The energy reflectivity of classical models"
_S3 = "§3 Albedo pumping-up"
_S5 = "§3.2, §5 Controlled pumping, conclusions"

CLAIMS = (
    Claim("neumann-1.2-cos-limit", PAPER, "§1.2",
          "If n goes to infinity the albedo of the (reciprocal) Phong model follows the "
          "cosine function.",
          "albedo engine of the normalised reciprocal Phong (eq. 6, ρ_s = 1) at θ_i = 30, "
          "60, 80° for n = 20, 500, 5000; rule: |a − cos θ| decreases with n and is ≤ tol "
          "at n = 5000.", _cos_limit, _cos_limit_rule, 0.01, _S1),
    Claim("neumann-2-fig1-darkening", PAPER, "§2, Fig. 1",
          "The albedo of Phong (n = 150) and He–Torrance (σ₀ = 0.1, τ = 1.7) badly decreases "
          "for greater incident angles (Fresnel = 1).",
          "albedo engine at θ_i = 0…89.9°; rule: a(89.9°) < tol × max a.",
          _darkening, _darkening_rule, 0.5, _S2),
    Claim("neumann-2.1-ward-diverges", PAPER, "§2.1, eq. (14)",
          "The Ward model's albedo diverges at grazing angles, like (N·L)^−1/2.",
          "albedo engine of ward (m = 0.1, ρ_s = 1) at N·L = 1e-2, 1e-3, 1e-4; exponent p of "
          "a ∝ (N·L)^−p from the last two; rule: |p − 1/2| ≤ tol.",
          _divergence("ward"), _ward_rule, 0.05, _S2),
    Claim("neumann-2.1-cook-diverges", PAPER, "§2.1, eq. (15)",
          "The Cook–Torrance model's albedo diverges at grazing angles, like (N·L)^−1 "
          "(F = 1).",
          "albedo engine of cook-torrance (m = 0.1, F = 1) at N·L = 1e-2, 1e-3, 1e-4; exponent "
          "p of a ∝ (N·L)^−p; rule: |p − 1| ≤ tol.",
          _divergence("cook-torrance"), _cook_rule, 0.1, _S2),
    Claim("neumann-3-eq19", PAPER, "§3, eqs. (16)–(19)",
          "Pumping up with g₁ = max(a(L), a(V)) raises the albedo and keeps it below 1: "
          "a(L) < a*(L) < 1.",
          "albedo engine of the reciprocal Phong and Blinn (n = 20) before and after one "
          "pumping at 9 angles; rule: a < a* ≤ 1 + tol.", _eq19, _eq19_rule, 1e-6, _S3),
    Claim("neumann-3.1-converges-to-1", PAPER, "§3.1, Fig. 3",
          "The albedos resulting from recursive pumping-ups (g₁) converge to the albedo of "
          "the ideal mirror (constant 1).",
          "ρ_hh (24-point Gauss–Legendre over the albedo engine) of the reciprocal Phong "
          "n = 20 pumped 0…3 times with g₁; rule: 1 − ρ_hh shrinks by a factor < tol at "
          "every pumping.", _rho_sequence(_phong, "max"), _converge_rule, 0.5, _S3),
    Claim("neumann-3.1-super-metal", PAPER, "§3.1, Fig. 4",
          "After several pumping-up operations (g₁) the output radiance can significantly "
          "exceed the received irradiance: the mirror image gets brighter than the original "
          "(off-specular peak; a super-metal for Blinn).",
          "mirror radiance f(L, R(L)) cos θ_L (eq. 3) of the reciprocal Blinn n = 20 pumped "
          "0…3 times with g₁, θ_L ≤ 89.9°, ÷ its normal-incidence value; rule: it grows with "
          "each pumping and exceeds 1 + tol.", _super_metal, _super_metal_rule, 0.05, _S3),
    Claim("neumann-4-fig8-brighter", PAPER, "§4, Fig. 8",
          "Pumping-up makes the image (metals under point lights and sky light) brighter; "
          "with n = 5000 the original Phong model is a bad energy mirror, which pumping "
          "eliminates.",
          "the Fig. 8 scene rendered by Monte Carlo through Mitsuba (96 px, 8 spp, seed 0; "
          "--full 320 px, 16 spp), mean luminance of the pumped-once image ÷ the plain one "
          "for n = 20 and 5000; rule: > 1 + tol.", _fig8_brighter, _fig8_brighter_rule,
          0.02, "§4 Simulation results"),
    Claim("neumann-3.2-phong-worth", PAPER, "§3.2",
          "For n = 20 the Phong model is worth (controlled) pumping-up 2 or 3 times.",
          "ρ_hh of the reciprocal Phong n = 20 after 0…3 controlled pumpings; rule: the "
          "first two gains > 5 %, the third < 2 %.",
          _rho_sequence(_phong, "controlled"), _phong_worth_rule, None, _S5),
    Claim("neumann-3.2-blinn-second", PAPER, "§3.2",
          "For n = 20 the albedo of the Blinn model does not significantly increase with the "
          "second and consecutive (controlled) pumping-up operations.",
          "ρ_hh of the reciprocal Blinn n = 20 after 0…3 controlled pumpings; rule: the "
          "second and third gains < 2 %.",
          _rho_sequence(_blinn, "controlled"), _blinn_second_rule, None, _S5),
    Claim("neumann-5-controlled-bound", PAPER, "§3.2, §5 Conclusions",
          "The controlled albedo pumping-up guarantees that the output radiance does not "
          "exceed the input radiance (no super-metal).",
          "mirror radiance f(L, R(L)) cos θ_L (eq. 3) of Blinn and Phong (n = 20) after one "
          "and two controlled pumpings, ÷ the base's normal-incidence value c; rule: ≤ 1 + "
          "tol.", _mirror_bound, _mirror_bound_rule, 1e-6, _S5),
    Claim("neumann-3.2-eq22-bound", PAPER, "§3.2, eq. (22)",
          "c_n ≤ (n + 2)/2π must hold for the model of eq. (22) to preserve energy balance "
          "(i.e. c_n = (n + 2)/2π keeps the albedo ≤ 1).",
          "albedo engine of neumann-phong with c_n = (n + 2)/2π over θ_i = 0…89.9° (180 "
          "angles) for n = 1, 2, 5, 20, 100; rule: max albedo ≤ 1 + tol (exceeding only at "
          "n < 20, below the paper's exponents: confirmed with a correction).",
          _eq22, _eq22_rule, 1e-5, _S5),
    study_claim(id="neumann-1.1-perceptual", paper=PAPER, location="§1.1", section=_S1,
                statement="Perceptual fitting (the maximal relative errors of the BRDF × "
                "cosine and of the albedo minimised together) gives smaller maximal relative "
                "errors than least squares."),
    study_claim(id="neumann-3-pumped-fit-g1", paper=PAPER, location="§3, §5 (metals)",
                section=_S3,
                statement="Pumping up the albedo (g₁) makes the Phong model fit metals better "
                "(a better energy mirror at grazing angles)."),
    study_claim(id="neumann-3-pumped-fit-g2", paper=PAPER, location="§3.2, §5 (metals)",
                section=_S5,
                statement="Controlled pumping (g₂) makes the Phong model fit metals better."),
)
