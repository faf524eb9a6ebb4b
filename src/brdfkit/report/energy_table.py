"""
The energy table: today's answers beside the papers', measured (issue 22 §3)
============================================================================

A table like Lewis's Table 2 for the models production rendering uses today to answer the
papers' question — energy compensation of microfacet models (Kulla & Conty 2017,
Turquin 2019), an energy-preserving rough diffuse (EON, beside Oren–Nayar and FON),
Disney's principled BRDF, Ashikhmin–Shirley — and for Neumann's own answer, pumping, on
the same Phong lobe. Every row is computed by
:func:`~brdfkit.analysis.energy_verdict.energy_verdict` (reciprocity, energy and where,
the white furnace 1 − a(θ) at 0, 60, 80, 89°, E_avg, divergence, each with its
accuracy); beside it the row's *claim*, what its paper says of it, and whether the
computation agrees. Only the claims are typed in here; every number is computed.

**The rows are data**: :data:`ROWS` is a tuple of dicts ``{"label", "group", "spec",
"claim"}`` (and ``"tol"``, the albedo engine's goal, where a row needs another than the
table's, with the reason beside it); ``spec`` is the dict form of
:class:`brdfkit.ModelSpec` (model, params, operators: ``"pump"``, ``"compensate"``), at
the model's white settings (ρ = 1, F = 1 as it has them: a microfacet model with ``eta``
None, a Phong lobe with ρ_s = 1, a diffuse with ρ = 1); ``claim`` a key of
:data:`CLAIMS`. To add a row, add a dict.

Claims (:data:`CLAIMS`): ``reciprocal`` "yes" / "no" / None (not claimed); ``energy``
"conserves" (a ≤ 1 everywhere), "a = 1" (the white furnace is passed: |1 − a| ≤
:data:`FURNACE_TOL` at every furnace angle, beyond the engine's error), "loses" (1 − a
exceeds its accuracy somewhere), "bounded" (does not diverge) or None.

Public objects
--------------
- :data:`ROWS`, :data:`CLAIMS`, :data:`FURNACE_TOL`.
- :func:`select_rows` — rows by label (the CLI's ``--row``).
- :func:`energy_table` — the computed rows (dicts).
- :func:`format_table`, :func:`format_markdown` — the table and its notes.

References
----------
- [Lewis1993] Table 2; [Neumann1999] eqs. (6), (16)–(21).
- Walter et al. 2007 eq. (20); Kulla & Conty 2017 (f_ms, E(μ), E_avg); Turquin 2019.
- Oren & Nayar 1994; Fujii (FON); Portsmouth, Kutz, Hill 2025 (EON, JCGT).
- Burley 2012 ("Physically-based shading at Disney"); Ashikhmin & Shirley 2000.
"""

from __future__ import annotations

import math
import pathlib
import time
from collections.abc import Callable, Iterable

from brdfkit.analysis.energy_verdict import FURNACE_DEG, FURNACE_TOL, energy_verdict
from brdfkit.errors import BrdfkitError
from brdfkit.spec import ModelSpec

__all__ = ["CLAIMS", "DISNEY_DIFFUSE", "FURNACE_TOL", "ROWS", "energy_table", "format_markdown",
           "format_table", "select_rows", "spec_row"]


#: What each method's paper says of it (the claims checked; None: the paper claims nothing).
CLAIMS = {
    "walter": {"source": "Walter et al. 2007 eq. (20): reciprocal; single scattering only, "
                         "so energy is lost (Kulla & Conty 2017)",
               "reciprocal": "yes", "energy": "loses"},
    "kulla-conty": {"source": "Kulla & Conty 2017: f_ms symmetric; white furnace a = 1",
                    "reciprocal": "yes", "energy": "a = 1"},
    "turquin": {"source": "Turquin 2019: white furnace a = 1; reciprocity not claimed",
                "reciprocal": None, "energy": "a = 1"},
    "phong": {"source": "Neumann 1999 eq. (6) / Nielsen eq. (1): reciprocal, a <= 1 "
                        "(dark at grazing, Neumann §1.2)",
              "reciprocal": "yes", "energy": "conserves"},
    "pumped": {"source": "Neumann 1999 eqs. (16)-(21): reciprocal, a <= a* <= 1",
               "reciprocal": "yes", "energy": "conserves"},
    "lambert": {"source": "Lambert: a = rho", "reciprocal": "yes", "energy": "a = 1"},
    "oren-nayar": {"source": "Oren & Nayar 1994: reciprocal; no energy claim",
                   "reciprocal": "yes", "energy": None},
    "oren-nayar-qualitative": {"source": "Oren & Nayar 1994 (qualitative model): reciprocal; "
                                         "loses energy (Portsmouth et al. 2025)",
                               "reciprocal": "yes", "energy": "loses"},
    "fon": {"source": "Fujii (FON): reciprocal; single scattering, loses energy when rough "
                      "(Portsmouth et al. 2025)",
            "reciprocal": "yes", "energy": "loses"},
    "eon": {"source": "Portsmouth, Kutz, Hill 2025: energy-preserving, a = 1 for white rho",
            "reciprocal": "yes", "energy": "a = 1"},
    "disney": {"source": "Burley 2012: claims neither reciprocity nor energy conservation",
               "reciprocal": None, "energy": None},
    "ashikhmin-shirley": {"source": "Ashikhmin & Shirley 2000: reciprocal, energy bounded",
                          "reciprocal": "yes", "energy": "bounded"},
}


def _micro(dist: str, alpha: float, method: str | None) -> dict:
    spec = {"model": "microfacet", "params": {"distribution": dist, "alpha": alpha}}
    if method is not None:
        spec["compensate"] = {"method": method}
    name = {"ggx": "GGX", "beckmann": "Beckmann"}[dist]
    label = f"{name} a={alpha:g}" + ("" if method is None else f" + {method}")
    return {"label": label, "group": "microfacet", "spec": spec,
            "claim": method or "walter"}


#: Burley's diffuse term alone, a model file beside this module (its docstring says why).
DISNEY_DIFFUSE = str(pathlib.Path(__file__).with_name("disney_diffuse.py"))

_PHONG = {"model": "modified-phong", "params": {"rho_d": 0.0, "rho_s": 1.0, "n": 20.0}}

#: The table's rows (module docstring): labels unique, specs at white settings.
ROWS: tuple[dict, ...] = (
    # the microfacet family, plain and compensated
    *(_micro(d, a, m) for d, alphas in (("ggx", (0.1, 0.3, 0.6, 1.0)),
                                        ("beckmann", (0.1, 0.3, 0.6, 1.0)))
      for a in alphas for m in (None, "kulla-conty", "turquin")),
    {"label": "GGX ax=0.6 ay=0.2 (anisotropic)", "group": "microfacet",
     "spec": {"model": "microfacet-anisotropic",
              "params": {"distribution": "ggx", "alpha_x": 0.6, "alpha_y": 0.2}},
     "claim": "walter"},
    # a Phong lobe: Neumann's answer (pumping) beside today's (compensation)
    {"label": "Phong n=20", "group": "phong", "spec": _PHONG, "claim": "phong"},
    {"label": "Phong n=20 + pump g1", "group": "phong",
     "spec": {**_PHONG, "pump": {"g": "max", "times": 1}}, "claim": "pumped"},
    {"label": "Phong n=20 + pump g2", "group": "phong",
     "spec": {**_PHONG, "pump": {"g": "controlled", "times": 1}}, "claim": "pumped"},
    {"label": "Phong n=20 + kulla-conty", "group": "phong",
     "spec": {**_PHONG, "compensate": {"method": "kulla-conty"}}, "claim": "kulla-conty"},
    {"label": "Phong n=20 + turquin", "group": "phong",
     "spec": {**_PHONG, "compensate": {"method": "turquin"}}, "claim": "turquin"},
    # rough diffuse
    {"label": "Lambert", "group": "diffuse",
     "spec": {"model": "lambert", "params": {"rho_d": 1.0}}, "claim": "lambert"},
    {"label": "Oren-Nayar full s=0.5", "group": "diffuse",
     "spec": {"model": "oren-nayar", "params": {"rho": 1.0, "sigma": 0.5, "form": "full"}},
     "claim": "oren-nayar"},
    {"label": "Oren-Nayar qualitative s=0.5", "group": "diffuse",
     "spec": {"model": "oren-nayar",
              "params": {"rho": 1.0, "sigma": 0.5, "form": "qualitative"}},
     "claim": "oren-nayar-qualitative"},
    *({"label": f"{name} r={r:g}", "group": "diffuse",
       "spec": {"model": name.lower(), "params": {"rho": 1.0, "r": r}},
       "claim": name.lower()} for name in ("FON", "EON") for r in (0.5, 1.0)),
    # Disney principled at a rough setting: all of it, and its diffuse alone
    {"label": "Disney rough", "group": "disney",
     "spec": {"model": "disney", "params": {"base_color": 1.0, "roughness": 1.0}},
     "claim": "disney"},
    {"label": "Disney rough, specular 0", "group": "disney",
     "spec": {"model": "disney",
              "params": {"base_color": 1.0, "roughness": 1.0, "specular": 0.0}},
     "claim": "disney"},
    # its diffuse term alone (the registered model keeps a Schlick specular at F0 = 0)
    {"label": "Disney rough, diffuse term", "group": "disney",
     "spec": {"model": DISNEY_DIFFUSE, "params": {"base_color": 1.0, "roughness": 1.0}},
     "claim": "disney"},
    # Ashikhmin-Shirley: F = 1 (R_s = 1: the specular alone) and a white diffuse
    # (tol 1e-5: beyond 85° its albedo does not converge below ~1e-5 at 1e-7 either — the
    # engine's own estimate, reported — and 1e-5 costs a seventh of the time)
    {"label": "Ashikhmin-Shirley nu=100 nv=10 Rs=1", "group": "ashikhmin-shirley",
     "spec": {"model": "ashikhmin-shirley",
              "params": {"n_u": 100.0, "n_v": 10.0, "R_s": 1.0, "R_d": 0.0}},
     "claim": "ashikhmin-shirley", "tol": 1e-5},
    {"label": "Ashikhmin-Shirley nu=100 nv=10 Rs=0.05 Rd=1", "group": "ashikhmin-shirley",
     "spec": {"model": "ashikhmin-shirley",
              "params": {"n_u": 100.0, "n_v": 10.0, "R_s": 0.05, "R_d": 1.0}},
     "claim": "ashikhmin-shirley", "tol": 1e-5},
)


def spec_row(spec: dict, label: str | None = None) -> dict:
    """A row for a spec of the caller's (the CLI's ``--spec``): no claim, group "given"."""
    if not isinstance(spec, dict):
        raise BrdfkitError(f"a row's spec must be the dict form of a model spec "
                           f"({{\"model\": NAME, \"params\": {{...}}, ...}}); got {spec!r}")
    return {"label": label or ModelSpec.from_dict(spec).name, "group": "given", "spec": spec,
            "claim": None}


def select_rows(labels: Iterable[str], rows=ROWS) -> list[dict]:
    """The rows whose label is one of *labels* (case and blanks ignored), in table order;
    an unknown label is an error listing the valid ones."""
    want = {str(x).strip().lower(): x for x in labels}
    known = {r["label"].lower(): r for r in rows}
    unknown = [x for k, x in want.items() if k not in known]
    if unknown:
        raise BrdfkitError(f"unknown row {unknown[0]!r}; valid rows: "
                           + ", ".join(r["label"] for r in rows))
    return [r for r in rows if r["label"].lower() in want]


def _agrees_energy(claim: str | None, row: dict) -> bool | None:
    if claim is None:
        return None
    f = row["furnace"]
    beyond = [d - e for d, e in zip(f["deficit"], f["error"], strict=True)]
    if claim == "conserves":
        return row["energy"] == "conserves"
    if claim == "a = 1":
        return all(abs(d) <= FURNACE_TOL + e
                   for d, e in zip(f["deficit"], f["error"], strict=True))
    if claim == "loses":
        return row["energy"] != "diverges" and max(beyond) > 0.0
    if claim == "bounded":
        return row["energy"] not in ("diverges", "undetermined")
    raise BrdfkitError(f"unknown energy claim {claim!r}")


def _row(entry: dict, tol: float) -> dict:
    spec = ModelSpec.from_dict(entry["spec"])
    model = spec.build()
    tol = entry.get("tol", tol)
    row = {"group": entry["group"], "tol": tol,
           **energy_verdict(model, label=entry["label"], tol=tol).to_dict()}
    row["spec"] = spec.to_dict()
    claim = CLAIMS[entry["claim"]] if entry.get("claim") else None
    if claim is None:
        row.update(paper=None, agrees_with_paper=None)
        return row
    recip = claim["reciprocal"]
    agree_r = None if recip is None else (recip == "yes") == row["reciprocal"]
    agree_e = _agrees_energy(claim["energy"], row)
    parts = [a for a in (agree_r, agree_e) if a is not None]
    row["paper"] = dict(claim)
    row["agrees_with_paper"] = all(parts) if parts else None
    if agree_r is False:
        row["notes"].append(f"DISAGREES with the claim (reciprocal: {recip}): max relative "
                            f"asymmetry {row['max_asymmetry']:.3g}")
    if agree_e is False:
        row["notes"].append(f"DISAGREES with the claim (energy: {claim['energy']}): "
                            f"{_energy_text(row)}, 1 - a = "
                            + ", ".join(f"{d:.3g}" for d in row["furnace"]["deficit"]))
    return row


def energy_table(*, rows=ROWS, tol: float = 1e-7,
                 progress: Callable[[int, int, str], None] | None = None) -> list[dict]:
    """The computed rows.

    Parameters
    ----------
    rows : sequence of dict, keyword-only
        Row entries (:data:`ROWS`' form; default: all of them).
    tol : float, keyword-only
        The albedo engine's accuracy goal.
    progress : callable, keyword-only, optional
        ``progress(done, total, label)`` before each row and ``progress(total, total, "")``
        at the end (as :func:`brdfkit.analysis.lewis_table2.table2`).

    Returns
    -------
    list of dict
        :meth:`EnergyVerdict.to_dict` plus ``group``, ``spec`` (the dict form), ``paper``
        (the claim, or None) and ``agrees_with_paper`` (None without a claim).
    """
    rows = list(rows)
    labels = [r["label"] for r in rows]
    if len(set(labels)) != len(labels):
        dup = next(x for x in labels if labels.count(x) > 1)
        raise BrdfkitError(f"energy table: row label {dup!r} appears twice; labels are unique")
    out = []
    for k, entry in enumerate(rows):
        if progress is not None:
            progress(k, len(rows), entry["label"])
        out.append(_row(entry, tol))
    if progress is not None:
        progress(len(rows), len(rows), "")
    return out


def timed_energy_table(**kwargs) -> tuple[list[dict], float]:
    """:func:`energy_table` and its wall time in seconds."""
    t = time.perf_counter()
    rows = energy_table(**kwargs)
    return rows, time.perf_counter() - t


# --------------------------------------------------------------------------- formatting
def _num(v: float, err: float) -> str:
    """*v* to the digits its error supports: "0" when |v| ≤ err; else up to the decimal
    where the error is (that last digit uncertain), at most 4 decimals; an infinite error
    (not converged) marks the value with "?"."""
    if not math.isfinite(v):
        return f"{v}"
    if not math.isfinite(err):  # not converged: the engine's last estimate, marked
        return f"{v:.4g}?"
    if abs(v) <= err:
        return "0"
    if abs(v) < 1e-3:
        return f"{v:.2g}"
    decimals = 4 if err <= 5e-5 else max(0, min(4, -math.floor(math.log10(err))))
    return f"{v:.{decimals}f}"


def _energy_text(r: dict) -> str:
    where = f"{r['theta_max_deg']:g}" + ("" if r["phi_max_deg"] is None
                                         else f",{r['phi_max_deg']:g}")
    if r["energy"] == "diverges":
        return f"diverges p={r['divergence_exponent']:g}"
    return f"{r['energy']} {_num(r['max_albedo'], r['max_albedo_error'])} @ {where}"


def _paper_text(r: dict) -> str:
    p = r["paper"]
    if not p:
        return "-"
    return f"R:{p['reciprocal'] or '-'} E:{p['energy'] or '-'}"


def _accuracy(r: dict) -> float:
    return max([*r["furnace"]["error"], r["e_avg_error"], r["max_albedo_error"]])


def _cells(r: dict) -> list[str]:
    agree = {True: "yes", False: "NO", None: "-"}[r["agrees_with_paper"]]
    f = r["furnace"]
    recip = "yes" if r["reciprocal"] else ("no" if r["reciprocity"] == "not reciprocal"
                                           else r["reciprocity"])
    asym = r["max_asymmetry"]
    return [r["label"], f"{recip} {asym:.3g}" if asym >= 0.01 else f"{recip} {asym:.2g}",
            _energy_text(r),
            *(_num(d, e) for d, e in zip(f["deficit"], f["error"], strict=True)),
            _num(r["e_avg"], r["e_avg_error"]), f"{_accuracy(r):.0e}", _paper_text(r), agree]


HEADER = ["row", "reciprocal (asym)", "energy: max a @ deg",
          *(f"1-a({t:g})" for t in FURNACE_DEG), "E_avg", "acc.", "paper", "agrees"]

_LEGEND = ("asym: max relative |f(L,V) - f(V,L)| / max (reciprocal when <= 1e-6); max a @ "
           "theta[,phi] deg; 1-a(theta): white furnace deficit (negative: a gain; 0: within "
           "the accuracy; anisotropic: averaged over phi); E_avg = 2 int a(mu) mu dmu; acc.: "
           "the largest albedo-engine error estimate of the row (inf, and ? after a value: not "
           "converged to the tolerance, the engine's last estimate); paper R/E: the claim "
           f"(a = 1: |1-a| <= {FURNACE_TOL:g} at every furnace angle)")


def format_table(rows: list[dict]) -> str:
    """Fixed-width table, its legend and the notes under it."""
    cells = [HEADER] + [_cells(r) for r in rows]
    widths = [max(len(c[i]) for c in cells) for i in range(len(HEADER))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip()
             for row in cells]
    lines.insert(1, "  ".join("-" * w for w in widths))
    lines += ["", _LEGEND, "", "Notes"]
    lines += [f"- {r['label']}: {n}" for r in rows for n in r["notes"]]
    return "\n".join(lines)


def format_markdown(rows: list[dict]) -> str:
    """GitHub-flavoured Markdown table, legend and notes."""
    def esc(s: str) -> str:
        return s.replace("|", "\\|")

    lines = ["| " + " | ".join(HEADER) + " |", "|" + "---|" * len(HEADER)]
    lines += ["| " + " | ".join(esc(c) for c in _cells(r)) + " |" for r in rows]
    lines += ["", esc(_LEGEND), ""]
    lines += [f"- **{esc(r['label'])}**: {esc(n)}" for r in rows for n in r["notes"]]
    return "\n".join(lines)
