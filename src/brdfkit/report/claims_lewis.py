"""
Lewis (1993), "Making Shaders More Physically Plausible": its claims as records
==============================================================================

Each :class:`~brdfkit.report.claim_record.Claim` below states what the paper says (with
its section or equation), how brdfkit computes it and the rule giving the verdict; the
numbers come from the library (models, the albedo engine, ``H_s``, ``check``, the exact
sphere renderer), never from this file. :data:`CLAIMS` lists them in the paper's order.
"""

from __future__ import annotations

import math

import numpy as np

from brdfkit.report.claim_record import Claim, Outcome

__all__ = ["CLAIMS"]

PAPER = "lewis"
#: Half-angles (degrees) at which the half-angle formulas are checked: the sphere figures'.
BETAS = (5.0, 15.0, 30.0)
LN2 = math.log(2.0)


def _dir(theta_deg, phi_deg=0.0) -> np.ndarray:
    t, p = np.radians(theta_deg), np.radians(phi_deg)
    return np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p),
                     np.cos(t) * np.ones_like(p)], axis=-1)


def _ratio_rule(numbers, tol) -> Outcome:
    """All printed ratios at β are 1/2 within *tol*: confirmed; else, if the derived ones
    are: confirmed with the derived formula as the correction; else refuted."""
    printed = numbers["printed_ratio"]
    worst = max(abs(r - 0.5) for r in printed)
    if worst <= tol:
        return Outcome("confirmed", f"the printed formula puts the half value at β: f(β)/f(0) "
                       f"= {', '.join(f'{r:.12g}' for r in printed)} for β = "
                       f"{', '.join(f'{b:g}°' for b in BETAS)} (|· − 1/2| ≤ {worst:.1e}).")
    derived = numbers.get("derived_ratio") or []
    if derived and max(abs(r - 0.5) for r in derived) <= tol:
        return Outcome("confirmed with a correction",
                       f"as printed, f(β)/f(0) = {', '.join(f'{r:.4g}' for r in printed)} "
                       f"(not 1/2); with the corrected formula "
                       f"{', '.join(f'{r:.12g}' for r in derived)}.", numbers["correction"])
    return Outcome("refuted", f"f(β)/f(0) = {', '.join(f'{r:.4g}' for r in printed)}, "
                   "not 1/2, and no derived formula is known.")


# ----------------------------------------------------------------- §3.2 c₃ (Trowbridge)
def _c3(ctx):
    out = []
    for b in np.radians(BETAS):
        cb2 = math.cos(b) ** 2
        c = math.sqrt((cb2 - 1.0) / (cb2 - math.sqrt(2.0)))  # as printed in §3.2

        def d3(ca, c=c):
            return (c * c / (ca * ca * (c * c - 1.0) + 1.0)) ** 2
        out.append(d3(math.cos(b)) / d3(1.0))
    return {"printed_ratio": out}


# ----------------------------------------------------------------- §3.2 m (Beckmann)
def _beckmann_m(ctx):
    out = []
    for b in np.radians(BETAS):
        m = math.tan(b) / math.sqrt(LN2 - 4.0 * math.log(math.cos(b)))  # as printed

        def d4(ca, m=m):
            return math.exp(-(1.0 - ca * ca) / (m * m * ca * ca)) / (4 * m * m * ca ** 4)
        out.append(d4(math.cos(b)) / d4(1.0))
    return {"printed_ratio": out}


# ----------------------------------------------------------------- §3.3 s (Neumann–Neumann)
def _nn_s(ctx):
    import brdfkit

    printed, derived = [], []
    normal = np.array([0.0, 0.0, 1.0])
    for bd in BETAS:
        b = math.radians(bd)
        s_printed = -LN2 / (1.0 + math.cos(b))  # Lewis §3.3 as printed
        s_derived = LN2 * math.cos(b) / (1.0 - math.cos(b))  # from f(β) = f(0)/2, S = N
        for s, out in ((s_printed, printed), (s_derived, derived)):
            m = brdfkit.model("neumann-neumann", b_N=1.0, s=max(s, 0.0))
            if s < 0.0:  # the model's range is s ≥ 0: the printed s evaluated by its formula
                out.append(math.exp(-s * (1.0 / math.cos(b) - 1.0)))
            else:
                out.append(float(m.eval(normal, _dir(bd)) / m.eval(normal, normal)))
    return {"printed_ratio": printed, "derived_ratio": derived,
            "correction": "s = ln 2 · cos β / (1 − cos β) (Lewis prints s = −ln 2/(1 + cos β), "
            "negative for every β: the lobe would grow away from the normal)"}


# ----------------------------------------------------------------- §3.4 k (Minnaert)
def _minnaert_k(ctx):
    import brdfkit

    out = []
    normal = np.array([0.0, 0.0, 1.0])
    for bd in BETAS:
        k = 1.0 - LN2 / math.log(math.cos(math.radians(bd)))  # as printed
        m = brdfkit.model("minnaert", b_M=1.0, k=k)
        out.append(float(m.eval(normal, _dir(bd)) / m.eval(normal, normal)))
    return {"printed_ratio": out}


# ----------------------------------------------------------------- §3.3/§3.4 peaks at N
def _peaks(ctx):
    import brdfkit

    models = {"neumann-neumann": brdfkit.model("neumann-neumann", b_N=1.0, beta=math.radians(15.0)),
              "minnaert": brdfkit.model("minnaert", b_M=1.0, beta=math.radians(15.0)),
              "blinn (control)": brdfkit.model("blinn", k_d=0.0, k_s=1.0, beta=math.radians(15.0))}
    theta_r = np.linspace(-89.0, 89.0, 3561)  # 0.05° steps in the plane of incidence
    out = {}
    for name, m in models.items():
        peaks = []
        for ti in (20.0, 40.0, 60.0, 80.0):
            s = _dir(ti, 180.0)  # light on the -x side, mirror direction at +ti
            v = _dir(np.abs(theta_r), np.where(theta_r >= 0.0, 0.0, 180.0))
            f = np.asarray(m.eval(np.broadcast_to(s, v.shape), v), dtype=float)
            peaks.append(float(theta_r[int(np.argmax(f))]))
        out[name] = peaks
    return {"theta_i": [20.0, 40.0, 60.0, 80.0], "peak_theta_r": out}


def _peaks_rule(numbers, tol) -> Outcome:
    p = numbers["peak_theta_r"]
    sep = [abs(x) <= tol for k in ("neumann-neumann", "minnaert") for x in p[k]]
    ctrl = [abs(x) > tol for x in p["blinn (control)"]]
    text = "; ".join(f"{k}: peak at θ_r = " + ", ".join(f"{x:g}°" for x in v)
                     for k, v in p.items()) + " for θ_i = 20, 40, 60, 80°"
    if all(sep) and any(ctrl):
        return Outcome("confirmed", text + " (the control, Blinn, peaks off the normal).")
    return Outcome("refuted", text + ".")


# ----------------------------------------------------------------- §3.4 "differ by ≤ 2 %"
def _nn_vs_minnaert(ctx):
    import brdfkit
    from brdfkit.render import render_sphere

    size = 96 if not ctx.full else 160
    out = {}
    for bd in BETAS:
        nn = brdfkit.model("neumann-neumann", b_N=1.0, beta=math.radians(bd))
        mi = brdfkit.model("minnaert", b_M=1.0, beta=math.radians(bd))
        worst = 0.0
        for phi in (0.0, 30.0, 60.0):
            a = np.nan_to_num(render_sphere(nn, phi_l=math.radians(phi), size=size).radiance)
            b = np.nan_to_num(render_sphere(mi, phi_l=math.radians(phi), size=size).radiance)
            if phi == 0.0:
                scale = max(float(np.max(a)), float(np.max(b)))  # the figure's exposure
            worst = max(worst, float(np.max(np.abs(a - b))) / scale)
        out[f"{bd:g}"] = worst
    return {"max_difference_of_peak": out, "size": size}


def _nn_vs_minnaert_rule(numbers, tol) -> Outcome:
    d = numbers["max_difference_of_peak"]
    text = ("largest |L_NN − L_M| on the sphere over Φ_L = 0, 30, 60°, relative to the "
            "Φ_L = 0 peak (the figure's exposure): " + ", ".join(
                f"β = {b}°: {100 * v:.2f} %" for b, v in d.items()))
    return Outcome("confirmed" if max(d.values()) <= tol else "refuted", text + ".")


# ----------------------------------------------------------------- §3.3 dimming, dark limb
def _spheres(model, phis, size):
    from brdfkit.render import render_sphere

    out = []
    for phi in phis:
        r = render_sphere(model, phi_l=math.radians(phi), size=size)
        out.append((np.nan_to_num(np.asarray(r.radiance, dtype=float)[..., 0]),
                    np.asarray(r.mask, dtype=bool)))
    return out


def _limb(img, mask, size) -> float:
    """Largest radiance in the outermost ring of the sphere (N·V < 0.15)."""
    y, x = np.mgrid[0:size, 0:size]
    c = (size - 1) / 2.0
    rr = np.hypot(x - c, y - c) / (size / 2.0)
    ring = mask & (rr > math.sqrt(1.0 - 0.15 ** 2))
    return float(np.max(img[ring])) if np.any(ring) else 0.0


def _dimming(ctx):
    import brdfkit

    size, phis = 96, (0.0, 30.0, 60.0)
    beta = math.radians(15.0)
    models = {"neumann-neumann": brdfkit.model("neumann-neumann", b_N=1.0, beta=beta),
              "minnaert": brdfkit.model("minnaert", b_M=1.0, beta=beta),
              "blinn (eq. 8, control)": brdfkit.model("blinn", k_d=0.0, k_s=1.0, beta=beta)}
    out = {}
    for name, m in models.items():
        imgs = _spheres(m, phis, size)
        peak0 = max(float(np.max(imgs[0][0])), 1e-300)
        out[name] = {"peak_over_phi0": [float(np.max(i)) / peak0 for i, _ in imgs],
                     "limb_over_phi0": [_limb(i, k, size) / peak0 for i, k in imgs]}
    return {"phi_l_deg": list(phis), "beta_deg": 15.0, "size": size, "models": out}


def _dimming_rule(numbers, tol) -> Outcome:
    d = numbers["models"]
    sep = [d[k] for k in ("neumann-neumann", "minnaert")]
    dims = all(all(b < a for a, b in zip(v["peak_over_phi0"], v["peak_over_phi0"][1:],
                                         strict=False)) for v in sep)
    dark = all(max(v["limb_over_phi0"]) <= tol for v in sep)
    ctrl = d["blinn (eq. 8, control)"]["peak_over_phi0"]
    phong_keeps = min(ctrl) >= 1.0 - tol  # "unlike Phong shaders"
    text = ("peak radiance ÷ its Φ_L = 0 value at Φ_L = " + ", ".join(
        f"{p:g}°" for p in numbers["phi_l_deg"]) + ": " + "; ".join(
        f"{k}: " + ", ".join(f"{x:.3f}" for x in v["peak_over_phi0"])
        + f" (limb ≤ {max(v['limb_over_phi0']):.1e})" for k, v in d.items()))
    ok = dims and dark and phong_keeps
    return Outcome("confirmed" if ok else "refuted", text + f" (rule: decreasing, limb ≤ "
                   f"{tol:g} of the peak; the Phong shader's peak does not decrease).")


# ----------------------------------------------------------------- §6 eq. (24) dimmer
def _eq24_dimmer(ctx):
    import brdfkit

    size, phis = 96, (0.0, 60.0, 90.0, 120.0)
    out = {}
    for bd in BETAS:
        b = math.radians(bd)
        pairs = {"eq. 8 (Fig. 3)": brdfkit.model("blinn", k_d=0.5, k_s=0.5, beta=b),
                 "eq. 24 (Fig. 10)": brdfkit.model("phong-blinn-reciprocal", k_d=0.5,
                                                   k_s=0.5, beta=b)}
        peaks = {k: [float(np.max(i)) for i, _ in _spheres(m, phis, size)]
                 for k, m in pairs.items()}
        out[f"{bd:g}"] = [a / c for a, c in zip(peaks["eq. 24 (Fig. 10)"],
                                                peaks["eq. 8 (Fig. 3)"], strict=True)]
    return {"phi_l_deg": list(phis), "k_s": 0.5, "size": size,
            "peak_radiance_ratio_eq24_over_eq8": out}


def _eq24_dimmer_rule(numbers, tol) -> Outcome:
    d = numbers["peak_radiance_ratio_eq24_over_eq8"]
    large = [v[i] for v in d.values() for i, p in enumerate(numbers["phi_l_deg"]) if p >= 90]
    ok = max(large) < 1.0 - tol
    return Outcome("confirmed" if ok else "refuted",
                   "peak (highlight) radiance of eq. (24) ÷ eq. (8) (k_d = k_s = 0.5) at Φ_L = "
                   + ", ".join(f"{p:g}°" for p in numbers["phi_l_deg"]) + ": " + "; ".join(
                       f"β = {b}°: " + ", ".join(f"{x:.3f}" for x in v) for b, v in d.items())
                   + f" (rule: < 1 − {tol:g} at Φ_L ≥ 90°).")


# ----------------------------------------------------------------- §4.1 eq. (19)
def _phong_diverges(ctx):
    from brdfkit.analysis import H_s

    theta = np.array([60.0, 80.0, 89.0, 89.9, 89.99])
    k_s, n = 0.01, 20.0  # a small specular coefficient: still k_ρ > 1 near grazing
    out = {"theta_deg": theta.tolist(), "k_s": k_s, "n": n}
    for lobe in ("phong", "blinn"):
        h = np.asarray(H_s(np.radians(theta), n, lobe=lobe).albedo, dtype=float)
        out[lobe] = {"H_s": h.tolist(),
                     "k_rho_specular": (k_s * h / np.cos(np.radians(theta))).tolist()}
    return out


def _phong_diverges_rule(numbers, tol) -> Outcome:
    parts, ok = [], True
    for lobe in ("phong", "blinn"):
        k = numbers[lobe]["k_rho_specular"]
        h = numbers[lobe]["H_s"]
        ok &= min(h) > 0.0 and k[-1] > 1.0
        parts.append(f"F_s^{'P' if lobe == 'phong' else 'B'}: H_s > 0 (min {min(h):.3g}), "
                     f"k_s H_s/(N·S) = " + ", ".join(f"{x:.3g}" for x in k))
    return Outcome("confirmed" if ok else "refuted",
                   f"with k_s = {numbers['k_s']}, n = {numbers['n']:g}, at θ_i = "
                   + ", ".join(f"{t:g}°" for t in numbers["theta_deg"]) + ": "
                   + "; ".join(parts) + " (exceeds 1 before 90°).")


# ----------------------------------------------------------------- eq. (16)
def _eq16(ctx):
    from scipy.integrate import quad

    out = {}
    for g in (0.0, 1.0, 20.0, 151.0):
        val, _ = quad(lambda t, g=g: math.cos(t) ** g * math.sin(t), 0.0, math.pi / 2,
                      epsabs=1e-13, epsrel=1e-13)
        out[f"{g:g}"] = {"quadrature": 2 * math.pi * val, "closed_form": 2 * math.pi / (g + 1)}
    return {"gamma": out}


def _eq16_rule(numbers, tol) -> Outcome:
    rel = {g: abs(v["quadrature"] / v["closed_form"] - 1.0) for g, v in numbers["gamma"].items()}
    return Outcome("confirmed" if max(rel.values()) <= tol else "refuted",
                   "relative difference of quadrature and 2π/(γ + 1): " + ", ".join(
                       f"γ = {g}: {r:.1e}" for g, r in rel.items()) + ".")


# ----------------------------------------------------------------- §4.2 T1/T2 bounded
def _ts_bounded(ctx):
    import brdfkit
    from brdfkit.analysis import albedo

    theta = np.radians([89.0, 89.9, 89.99])
    beta = math.radians(15.0)
    models = {"T1 (D1 Phong)": brdfkit.model("torrance-sparrow", distribution="phong",
                                             beta=beta),
              "T2 (D2 Gaussian)": brdfkit.model("torrance-sparrow", distribution="gaussian",
                                                beta=beta),
              "Phong (eq. 8, F_s^P)": brdfkit.model("phong", k_d=0.0, k_s=1.0, beta=beta),
              "Blinn (eq. 8, F_s^B)": brdfkit.model("blinn", k_d=0.0, k_s=1.0, beta=beta)}
    return {"theta_deg": [89.0, 89.9, 89.99],
            "albedo": {k: np.asarray(albedo(m, theta).albedo, dtype=float).tolist()
                       for k, m in models.items()}}


def _ts_bounded_rule(numbers, tol) -> Outcome:
    a = numbers["albedo"]
    growth = {k: v[-1] / v[0] for k, v in a.items()}
    ts = [growth[k] for k in a if k.startswith("T")]
    shaders = [growth[k] for k in a if not k.startswith("T")]
    # a diverging k_ρ ∝ 1/cos θ grows ×100 from 89° to 89.99°; bounded ones by < 1 + tol
    ok = max(ts) <= 1.0 + tol and min(shaders) > 10.0
    return Outcome("confirmed" if ok else "refuted",
                   "k_ρ(89.99°)/k_ρ(89°): " + ", ".join(f"{k} {g:.3g}"
                                                         for k, g in growth.items()) + ".")


# ----------------------------------------------------------------- §4.3 Minnaert, k_ρ form
def _minnaert_ec(ctx):
    import brdfkit
    from brdfkit.analysis import albedo

    out = {}
    theta = np.array([0.0, 30.0, 60.0, 85.0])
    for bd in BETAS:
        m = brdfkit.model("minnaert-energy-conserving", k_rho=1.0, beta=math.radians(bd))
        k = float(m.values["k"])
        a = np.asarray(albedo(m, np.radians(theta)).albedo, dtype=float)
        out[f"{bd:g}"] = {"k": k, "albedo": a.tolist(),
                          "closed_form": (np.cos(np.radians(theta)) ** (k - 1.0)).tolist()}
    return {"theta_deg": theta.tolist(), "beta": out}


def _minnaert_ec_rule(numbers, tol) -> Outcome:
    worst_max = max(max(v["albedo"]) for v in numbers["beta"].values())
    worst_dev = max(abs(a - c) for v in numbers["beta"].values()
                    for a, c in zip(v["albedo"], v["closed_form"], strict=True))
    text = (f"with k_ρ = 1 the albedo is at most {worst_max:.9f} (at θ_i = 0) and follows "
            f"k_ρ cos^(k−1) θ_i within {worst_dev:.1e}; so k_ρ is the albedo at normal "
            "incidence and the bound at every other angle.")
    return Outcome("confirmed" if worst_max <= 1.0 + tol else "refuted", text)


# ----------------------------------------------------------------- §5 reciprocity
_RECIP = {"phong": ("phong", {}, False), "blinn": ("blinn", {}, False),
          "phong-energy-conserving (eq. 22, F_s^B)": ("phong-energy-conserving", {}, False),
          "phong-energy-conserving (eq. 22, F_s^P)": ("phong-energy-conserving",
                                                      {"lobe": "phong"}, False),
          "torrance-sparrow": ("torrance-sparrow", {}, True),
          "neumann-neumann": ("neumann-neumann", {}, True), "minnaert": ("minnaert", {}, True),
          "phong-blinn-reciprocal (eq. 24)": ("phong-blinn-reciprocal", {}, True)}


def _reciprocity(ctx):
    import brdfkit

    rng = np.random.default_rng(1993)  # explicit seed: the same pairs every run
    n = 4000
    z = rng.uniform(0.05, 1.0, (2, n))
    ph = rng.uniform(0.0, 2 * math.pi, (2, n))
    r = np.sqrt(1.0 - z * z)
    d = np.stack([r * np.cos(ph), r * np.sin(ph), z], axis=-1)
    out = {}
    for label, (name, params, _) in _RECIP.items():
        m = brdfkit.model(name, **params)
        a = np.asarray(m.eval(d[0], d[1]), dtype=float)
        b = np.asarray(m.eval(d[1], d[0]), dtype=float)
        out[label] = float(np.max(np.abs(a - b) / np.maximum(np.maximum(a, b), 1e-300)))
    return {"pairs": n, "seed": 1993, "max_relative_asymmetry": out}


def _reciprocity_rule(numbers, tol) -> Outcome:
    asym = numbers["max_relative_asymmetry"]
    wrong = [k for k, (_, _, recip) in _RECIP.items() if (asym[k] <= tol) != recip]
    text = (f"max |f(S,V) − f(V,S)|/max over {numbers['pairs']} random pairs: "
            + ", ".join(f"{k} {v:.1e}" for k, v in asym.items()))
    return Outcome("refuted" if wrong else "confirmed",
                   text + (f"; disagrees for {', '.join(wrong)}." if wrong else "."))


# ----------------------------------------------------------------- §6 eq. (24) bounded
def _eq24(ctx):
    import brdfkit
    from brdfkit.analysis import albedo

    theta = np.array([0.0, 60.0, 85.0, 89.0, 89.9, 89.99])
    out = {}
    for bd in BETAS:
        m = brdfkit.model("phong-blinn-reciprocal", k_d=0.0, k_s=1.0, beta=math.radians(bd))
        out[f"{bd:g}"] = np.asarray(albedo(m, np.radians(theta)).albedo, dtype=float).tolist()
    return {"theta_deg": theta.tolist(), "albedo_over_k_s": out}


def _eq24_rule(numbers, tol) -> Outcome:
    a = numbers["albedo_over_k_s"]
    growth = {b: v[-1] / v[-3] for b, v in a.items()}  # 89.99° vs 89°
    ok = all(g <= 1.0 + tol for g in growth.values())
    return Outcome("confirmed" if ok else "refuted",
                   "k_ρ^H/k_s: max " + ", ".join(f"β = {b}°: {max(v):.4g}" for b, v in a.items())
                   + "; k_ρ(89.99°)/k_ρ(89°) " + ", ".join(f"{g:.3g}" for g in growth.values())
                   + " (bounded: a scale k_s ≤ 1/max conserves energy).")


# ----------------------------------------------------------------- Table 2
def _table2(ctx):
    from brdfkit.analysis.lewis_table2 import LEWIS_ROWS, table2

    rows = table2(models=[r[1] for r in LEWIS_ROWS])
    # the six printed rows (table2 adds Fig. 7's parameterisations, which Table 2 lacks)
    return {"rows": [{"row": r["row"], "energy": r["energy"], "reciprocal": r["reciprocal"],
                      "paper": r["paper"], "agrees": r["agrees_with_paper"]} for r in rows
                     if "conserves_energy" in r["paper"]]}


def _table2_rule(numbers, tol) -> Outcome:
    rows = numbers["rows"]
    bad = [r["row"] for r in rows if not r["agrees"]]
    text = "; ".join(f"{r['row']}: computed energy {r['energy']}, reciprocal "
                     f"{'yes' if r['reciprocal'] else 'no'} (paper: E "
                     f"{r['paper']['conserves_energy']}, R {r['paper']['reciprocal']})"
                     for r in rows)
    return Outcome("refuted" if bad else "confirmed", text + ".")


_S3 = "§3 Some typical shaders"
_S4 = "§4 Energy conservation"
_S5 = "§5 Reciprocity"
_S6 = "§6–7 The reciprocal shader and the summary"

CLAIMS = (
    Claim("lewis-3.2-c3", PAPER, "§3.2, c₃ of D₃ (Trowbridge–Reitz)",
          "c₃ = √((cos²β − 1)/(cos²β − √2)) puts D₃ at half its peak at α = β.",
          "D₃(cos β)/D₃(1) with the printed c₃, β = 5°, 15°, 30°; rule: |ratio − 1/2| ≤ tol.",
          _c3, _ratio_rule, 1e-9, _S3),
    Claim("lewis-3.2-beckmann-m", PAPER, "§3.2, m of D₄ (Beckmann)",
          "m = tan β/√(ln 2 − 4 ln cos β) puts D₄ at half its peak at α = β.",
          "D₄(cos β)/D₄(1) with the printed m, β = 5°, 15°, 30°; rule: |ratio − 1/2| ≤ tol.",
          _beckmann_m, _ratio_rule, 1e-9, _S3),
    Claim("lewis-3.3-neumann-s", PAPER, "§3.3, s of the Neumann–Neumann shader",
          "With S = N, f_r drops to half its value at V = N when V is tilted by β, for "
          "s = −ln 2/(1 + cos β).",
          "f_r(N, V(β))/f_r(N, N) of model neumann-neumann with the printed s, and with s "
          "derived from the same definition; rule: |ratio − 1/2| ≤ tol.",
          _nn_s, _ratio_rule, 1e-9, _S3),
    Claim("lewis-3.4-minnaert-k", PAPER, "§3.4, k of the Minnaert shader",
          "k = 1 − ln 2/ln cos β puts the Minnaert shader at half its peak at β (definition "
          "of §3.3).",
          "f_r(N, V(β))/f_r(N, N) of model minnaert with the printed k; rule: |ratio − 1/2| "
          "≤ tol.", _minnaert_k, _ratio_rule, 1e-9, _S3),
    Claim("lewis-3.3-peak-normal", PAPER, "§3.3, §3.4, §5.3",
          "Neumann–Neumann and Minnaert shaders: for a given incident angle the reflected "
          "radiance always peaks in the normal direction.",
          "argmax over θ_r (plane of incidence, 0.05° steps) of f_r(S, V) at θ_i = 20–80°, "
          "β = 15°; Blinn as a control that must peak elsewhere; rule: |θ_r,peak| ≤ tol "
          "degrees.", _peaks, _peaks_rule, 0.05, _S3),
    Claim("lewis-3.4-nn-minnaert-2pct", PAPER, "§3.4, Fig. 4",
          "Neumann–Neumann and Minnaert shaders are difficult to tell apart: their numerical "
          "values in the images differ by no more than 2 %.",
          "both rendered exactly on the test configuration (b_N = b_M = 1, same β, Φ_L = 0, "
          "30, 60°); largest |L_NN − L_M| relative to the Φ_L = 0 peak (one exposure, as "
          "the figure); rule: ≤ tol.", _nn_vs_minnaert, _nn_vs_minnaert_rule, 0.02, _S3),
    Claim("lewis-3.3-dimming-limb", PAPER, "§3.3, Fig. 4",
          "For Neumann–Neumann (and Minnaert) shaders the image radiance decreases as Φ_L "
          "increases, unlike Phong shaders; the limb of the sphere (N·V = 0) is always dark.",
          "exact sphere renders (96 px, β = 15°, b = 1) at Φ_L = 0, 30, 60°: the peak ÷ its "
          "Φ_L = 0 value, and the largest radiance where N·V < 0.15 ÷ that peak; the Phong "
          "shader with F_s^B (eq. 8) as the contrast; rule: decreasing, limb ≤ tol.",
          _dimming, _dimming_rule, 0.01, _S3),
    Claim("lewis-4-eq16", PAPER, "§4.1, eq. (16)",
          "∫_Ω (N·V)^γ dω = 2π/(γ + 1).",
          "adaptive quadrature (SciPy quad) of 2π∫cos^γ θ sin θ dθ for γ = 0, 1, 20, 151; "
          "rule: relative difference ≤ tol.", _eq16, _eq16_rule, 1e-10, _S4),
    Claim("lewis-4.1-phong-diverges", PAPER, "§4.1, eq. (19), Fig. 5",
          "H_s > 0 for every S, so with any k_s > 0 the Phong shaders' k_ρ = k_d π + "
          "k_s H_s/(N·S) exceeds 1 at incident angles close enough to 90°: they do not "
          "conserve energy.",
          "H_s(θ_i) by its own quadrature (brdfkit.analysis.H_s) for F_s^P and F_s^B, n = 20, "
          "and k_s H_s/(N·S) with k_s = 0.01; rule: H_s > 0 and the term > 1 before 90°.",
          _phong_diverges, _phong_diverges_rule, None, _S4),
    Claim("lewis-4.2-ts-bounded", PAPER, "§4.2, Fig. 7",
          "k_ρ^T1 (Torrance–Sparrow with the Phong distribution) does not diverge as θ_i → "
          "90°, although the corresponding Phong shader does; the same holds for T2 against "
          "Blinn.",
          "albedo engine at θ_i = 89°, 89.9°, 89.99° (β = 15°, F = 1); a diverging k_ρ ∝ "
          "1/cos θ_i grows ×100 there; rule: T1, T2 grow ≤ 1 + tol, the shaders > ×10.",
          _ts_bounded, _ts_bounded_rule, 0.05, _S4),
    Claim("lewis-4.3-minnaert-energy", PAPER, "§4.3, the k_ρ form of the Minnaert shader",
          "f_r = k_ρ (k + 1)/(2π) ((N·S)(N·V))^(k−1): any k_ρ between 0 and 1 guarantees "
          "energy conservation.",
          "albedo engine at θ_i = 0, 30, 60, 85° with k_ρ = 1, β = 5°, 15°, 30°, beside the "
          "closed form k_ρ cos^(k−1) θ_i; rule: max albedo ≤ 1 + tol.",
          _minnaert_ec, _minnaert_ec_rule, 1e-6, _S4),
    Claim("lewis-5-reciprocity", PAPER, "§5.1–§5.3, eq. (23)",
          "Phong shaders with F_s^P or F_s^B (eq. 8) and the energy-conserving Phong (eq. 22) "
          "are not reciprocal; Torrance–Sparrow, Neumann–Neumann, Minnaert and eq. (24) are.",
          "largest relative |f(S,V) − f(V,S)| over 4000 random direction pairs (seed 1993), "
          "models at their defaults; rule: reciprocal ⇔ asymmetry ≤ tol.",
          _reciprocity, _reciprocity_rule, 1e-12, _S5),
    Claim("lewis-6-eq24-bounded", PAPER, "§6, eq. (24), Fig. 9",
          "The reciprocal shader f_r = k_d + k_s F_s^B has a bounded k_ρ, so limiting k_s and "
          "k_d conserves energy.",
          "albedo engine of k_s (N·H)^n up to θ_i = 89.99° for β = 5°, 15°, 30°; rule: "
          "k_ρ(89.99°)/k_ρ(89°) ≤ 1 + tol.", _eq24, _eq24_rule, 0.05, _S6),
    Claim("lewis-6-eq24-dimmer", PAPER, "§6, Fig. 10",
          "While resembling Fig. 3, the images of the reciprocal shader (eq. 24) for large Φ_L "
          "are dimmer (no (N·S) in the specular denominator).",
          "exact sphere renders (96 px, k_d = k_s = 0.5, β = 5°, 15°, 30°) of eq. (24) and "
          "eq. (8) with F_s^B at Φ_L = 0, 60, 90, 120°: ratio of the peak (highlight) "
          "radiance; rule: "
          "< 1 − tol at Φ_L ≥ 90°.", _eq24_dimmer, _eq24_dimmer_rule, 0.05, _S6),
    Claim("lewis-table2", PAPER, "§7, Table 2",
          "Conserves energy / reciprocal: Phong no/no; energy-conserving Phong yes/no; "
          "Torrance–Sparrow, Neumann–Neumann, Minnaert, reciprocal Phong–Blinn yes/yes "
          "(\"yes\" for energy: k_ρ bounded, so a scale makes it conserve).",
          "brdfkit.analysis.check on the six registered models (lewis_table2.table2); rule: "
          "every row agrees.", _table2, _table2_rule, None, _S6),
)
