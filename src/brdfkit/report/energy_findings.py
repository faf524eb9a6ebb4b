"""
The findings of issue 22 §3, tested on the energy table's rows
==============================================================

Each finding is a statement and a test on the computed rows of
:func:`brdfkit.report.energy_table.energy_table`, which answers "confirmed", "refuted"
or "not evaluated" (a row it needs was not computed) with the numbers it rests on and
their accuracy (the albedo engine's error estimates; reciprocity is exact up to
rounding). No verdict is typed by hand; the thresholds are stated where they are
defined.

Public objects
--------------
- :data:`FINDINGS` — ``(key, statement, test)``; ``test(rows_by_label)`` returns
  ``(verdict, evidence)``.
- :func:`findings` — every finding's verdict (dicts) for a list of rows.
- :func:`format_findings` — a Markdown list.
- :data:`FAR_BELOW`, :data:`VISIBLE_LOSS`.
"""

from __future__ import annotations

from collections.abc import Callable

from brdfkit.analysis.plausibility import RECIPROCITY_TOL
from brdfkit.report.energy_table import FURNACE_TOL

__all__ = ["FAR_BELOW", "FINDINGS", "VISIBLE_LOSS", "findings", "format_findings"]

#: "E_avg far below 1": more than a quarter of the energy lost under uniform light.
FAR_BELOW = 0.25
#: A deficit 1 − a larger than this at some furnace angle is a visible loss (1%).
VISIBLE_LOSS = 0.01


class _Missing(Exception):
    """A row the finding needs was not computed."""


def _get(rows: dict, label: str) -> dict:
    if label not in rows:
        raise _Missing(label)
    return rows[label]


def _group(rows: dict, prefix: str, suffix: str) -> list[dict]:
    out = [r for k, r in rows.items() if k.startswith(prefix) and k.endswith(suffix)]
    if not out:
        raise _Missing(f"{prefix}…{suffix}")
    return out


def _worst_abs_deficit(r: dict) -> tuple[float, float, float]:
    """(largest |1 − a| over the furnace angles, its angle, its error)."""
    f = r["furnace"]
    k = max(range(len(f["deficit"])), key=lambda i: abs(f["deficit"][i]))
    return abs(f["deficit"][k]), f["theta_deg"][k], f["error"][k]


def _deficits(r: dict) -> str:
    f = r["furnace"]
    return ", ".join(f"1-a({t:g}) = {d:.4g}" for t, d in zip(f["theta_deg"], f["deficit"],
                                                               strict=True))


def _ggx_loses(rows: dict) -> tuple[str, str]:
    plain = sorted((r for k, r in rows.items() if k.startswith("GGX a=") and "+" not in k),
                   key=lambda r: r["spec"]["params"]["alpha"])
    top = _get(rows, "GGX a=1")
    if not plain:
        raise _Missing("GGX a=...")
    e = [(r["spec"]["params"]["alpha"], r["e_avg"], r["e_avg_error"]) for r in plain]
    decreasing = all(b[1] < a[1] - a[2] - b[2] for a, b in zip(e, e[1:], strict=False))
    ok = 1.0 - top["e_avg"] > FAR_BELOW + top["e_avg_error"] and decreasing
    return ("confirmed" if ok else "refuted",
            f"E_avg(alpha = 1) = {top['e_avg']:.4f} ± {top['e_avg_error']:.0e} (1 - E_avg = "
            f"{1 - top['e_avg']:.4f}; 'far below' = more than {FAR_BELOW:g} lost); E_avg by "
            "alpha: " + ", ".join(f"{a:g}: {v:.4f}" for a, v, _ in e)
            + ("" if decreasing else " (NOT decreasing in alpha)")
            + f"; at alpha = 1, {_deficits(top)}")


def _passes_furnace(r: dict) -> bool:
    return all(abs(d) <= FURNACE_TOL + e for d, e in zip(r["furnace"]["deficit"],
                                                          r["furnace"]["error"], strict=True))


def _compensated(rows: dict, method: str) -> tuple[list[dict], float, float, tuple]:
    rs = _group(rows, "", f" + {method}")
    worst = max(rs, key=lambda r: _worst_abs_deficit(r)[0])
    d, _, e = _worst_abs_deficit(worst)
    asym = [r["max_asymmetry"] for r in rs]
    return rs, d, e, (min(asym), max(asym))


def _beyond(rs: list[dict]) -> str:
    """What check's grid (to 89.999°, beyond the furnace angles) says of the rows' energy."""
    top = max(rs, key=lambda r: r["max_albedo"])
    where = f"max a = {top['max_albedo']:.7f} ± {top['max_albedo_error']:.0e} at " \
            f"{top['theta_max_deg']:g} deg ({top['label']})"
    over = [r for r in rs if r["energy"] != "conserves"]
    if not over:
        return f"; on check's whole grid (to 89.999 deg) every row conserves: {where}"
    return (f"; on check's grid (to 89.999 deg) {len(over)} of {len(rs)} rows do not conserve "
            f"({', '.join(sorted({r['energy'] for r in over}))}): {where}")


def _kulla_conty(rows: dict) -> tuple[str, str]:
    rs, d, e, (lo, hi) = _compensated(rows, "kulla-conty")
    ok = all(_passes_furnace(r) for r in rs) and all(r["reciprocal"] for r in rs)
    return ("confirmed" if ok else "refuted",
            f"over {len(rs)} rows ({', '.join(r['label'] for r in rs)}): largest |1 - a| at "
            f"0/60/80/89 deg = {d:.2g} (engine error {e:.0e}; criterion {FURNACE_TOL:g}); "
            f"max relative asymmetry {hi:.2g} (reciprocal when <= {RECIPROCITY_TOL:g})"
            + _beyond(rs))


def _turquin(rows: dict) -> tuple[str, str]:
    rs, d, e, (lo, hi) = _compensated(rows, "turquin")
    restores = all(_passes_furnace(r) for r in rs)
    nonrecip = all(not r["reciprocal"] for r in rs)
    verdict = "confirmed" if restores and nonrecip else "refuted"
    which = [r["label"] for r in rs if r["reciprocal"]]
    return (verdict,
            f"over {len(rs)} rows: largest |1 - a| at 0/60/80/89 deg = {d:.2g} (engine error "
            f"{e:.0e}); max relative asymmetry from {lo:.2g} to {hi:.2g}" + _beyond(rs)
            + (f"; reciprocal (asymmetry <= {RECIPROCITY_TOL:g}): {', '.join(which)}"
               if which else ""))


def _eon(rows: dict) -> tuple[str, str]:
    eon = _group(rows, "EON", "")
    qual = _group(rows, "Oren-Nayar qualitative", "")
    e_worst = max(_worst_abs_deficit(r)[0] for r in eon)
    q = max(qual, key=lambda r: max(r["furnace"]["deficit"]))
    q_loss = max(q["furnace"]["deficit"])
    ok = (all(r["energy"] == "conserves" for r in eon) and e_worst <= VISIBLE_LOSS
          and q_loss > VISIBLE_LOSS)
    return ("confirmed" if ok else "refuted",
            "EON (" + "; ".join(f"{r['label']}: {_deficits(r)}, E_avg = {r['e_avg']:.5f}"
                                for r in eon)
            + f"); largest |1 - a| {e_worst:.2g}; {q['label']}: {_deficits(q)}, E_avg = "
            f"{q['e_avg']:.4f} (a visible loss: > {VISIBLE_LOSS:g})")


def _disney(rows: dict) -> tuple[str, str]:
    r = _get(rows, "Disney rough, diffuse term")
    f = r["furnace"]
    over = [(t, -d, e) for t, d, e in zip(f["theta_deg"], f["deficit"], f["error"],
                                           strict=True) if -d > e]
    grazing = r["max_albedo"] > 1.0 + r["max_albedo_error"] and r["theta_max_deg"] >= 60.0
    return ("confirmed" if grazing else "refuted",
            f"{r['label']}: max a = {r['max_albedo']:.4f} ± {r['max_albedo_error']:.0e} at "
            f"theta = {r['theta_max_deg']:g} deg; {_deficits(r)}"
            + (f"; a > 1 at {', '.join(f'{t:g}' for t, _, _ in over)} deg" if over else ""))


def _ashikhmin(rows: dict) -> tuple[str, str]:
    rs = _group(rows, "Ashikhmin-Shirley", "")
    ok = all(r["reciprocal"] and r["energy"] not in ("diverges", "undetermined") for r in rs)
    return ("confirmed" if ok else "refuted",
            "; ".join(f"{r['label']}: asymmetry {r['max_asymmetry']:.2g}, {r['energy']}, max a "
                      f"= {r['max_albedo']:.4f} ± {r['max_albedo_error']:.0e} at (theta, phi) = "
                      f"({r['theta_max_deg']:g}, {r['phi_max_deg']}) deg" for r in rs))


#: (key, statement, test): issue 22 §3's findings, in its order.
FINDINGS: tuple[tuple[str, str, Callable], ...] = (
    ("ggx-loses", "GGX single scattering loses most at high roughness (E_avg far below 1 at "
                  "alpha = 1)", _ggx_loses),
    ("kulla-conty", "Kulla-Conty restores a = 1 at F = 1 and stays reciprocal", _kulla_conty),
    ("turquin", "Turquin restores energy and is not reciprocal", _turquin),
    ("eon", "EON conserves energy for white albedo where the qualitative Oren-Nayar loses it",
     _eon),
    ("disney", "Disney's diffuse exceeds 1 at grazing on rough surfaces", _disney),
    ("ashikhmin-shirley", "Ashikhmin-Shirley is reciprocal and bounded", _ashikhmin),
)


def findings(rows: list[dict]) -> list[dict]:
    """``{"key", "statement", "verdict", "evidence"}`` per finding of :data:`FINDINGS`."""
    by_label = {r["label"]: r for r in rows}
    out = []
    for key, statement, test in FINDINGS:
        try:
            verdict, evidence = test(by_label)
        except _Missing as missing:
            verdict, evidence = "not evaluated", f"row {missing.args[0]!r} was not computed"
        out.append({"key": key, "statement": statement, "verdict": verdict,
                    "evidence": evidence})
    return out


def format_findings(items: list[dict]) -> str:
    """A Markdown list: statement — **verdict**: evidence."""
    return "\n".join(f"- {f['statement']} — **{f['verdict']}**: {f['evidence']}"
                     for f in items)
