"""The fitting study (issue 10 §5): Ngan anchors, derived measures, and the report's verdicts.

Reference values: a Lafortune lobe evaluated by hand from its formula; the cosine-weighted
RMS of a constant offset from the closed-form mean of cos²θ_i over the 80° caps; identities
(a model against itself; a model scaled by a known factor); and, for the report, synthetic
batch files whose verdicts are known by construction.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import brdfkit
from brdfkit.errors import BrdfkitError
from brdfkit.fitting.batch import write_rows
from brdfkit.fitting.study import (
    is_metal,
    lobe_position,
    ngan_metric,
    ngan_model,
    read_ngan_table,
    relative_errors,
    study_batches,
)
from brdfkit.report.fit_study import claims, write_report

NGAN_ROW = "material,p0,p1,p2,p3,p4,p5,p6,p7,p8\ntest-metal,0.1,0.2,0.3,0.4,0.5,0.6,-0.6,0.5,40\n"


def test_ngan_table_and_lafortune_lobe_by_hand(tmp_path):
    p = tmp_path / "ngan.csv"
    p.write_text(NGAN_ROW)
    e = read_ngan_table(p)["test-metal"]
    # G and B scaled by MERL's 1.15 and 1.66 (SOURCES.md §6)
    assert e["rho_d"] == pytest.approx([0.1, 0.2 * 1.15, 0.3 * 1.66])
    assert e["rho_s"] == pytest.approx([0.4, 0.5 * 1.15, 0.6 * 1.66])
    ti, to, dphi = math.radians(30.0), math.radians(35.0), math.radians(170.0)
    wi = np.array([[math.sin(ti), 0.0, math.cos(ti)]])
    wo = np.array([[math.sin(to) * math.cos(dphi), math.sin(to) * math.sin(dphi),
                    math.cos(to)]])
    # by hand: f = ρ_d/π + ρ_s (C_xy (ix ox + iy oy) + C_z iz oz)^n
    dot_xy = wi[0, 0] * wo[0, 0] + wi[0, 1] * wo[0, 1]
    dot_z = wi[0, 2] * wo[0, 2]
    for conv, cxy, cz, scale in (("as-printed", -0.6, 0.5, 1.0),
                                 ("peak-one", -1.0, 0.5 / 0.6, 1.0),
                                 ("normalised", -1.0, 0.5 / 0.6, 42.0 / (2 * math.pi))):
        want = [e["rho_d"][c] / math.pi + e["rho_s"][c] * scale * (cxy * dot_xy + cz * dot_z)
                ** 40 for c in range(3)]
        got = np.asarray(ngan_model(e, conv).eval(wi, wo)).reshape(-1)
        assert got == pytest.approx(want, rel=1e-9), conv
    with pytest.raises(BrdfkitError, match="convention must be one of"):
        ngan_model(e, "other")
    with pytest.raises(BrdfkitError, match="does not exist"):
        read_ngan_table(tmp_path / "missing.csv")


def test_ngan_metric_of_a_constant_offset():
    # f − f̂ = Δ/π everywhere, so the cosine-weighted RMS over θ_i, θ_o ≤ 80° is
    # (Δ/π)·√E[cos²θ_i] with, for directions uniform in the cap, E[cos²θ_i] =
    # (1 − c³) / (3 (1 − c)), c = cos 80° (∫cos² dω = 2π(1 − c³)/3, ∫dω = 2π(1 − c))
    target = brdfkit.model("lafortune", rho_d=0.3, rho_s=0.5, n=10.0)
    delta = 0.1
    model = target.with_params(rho_d=0.3 + delta)
    c = math.cos(math.radians(80.0))
    want = delta / math.pi * math.sqrt((1 - c ** 3) / (3 * (1 - c)))
    # 1 %: the samples are cells cut at the cap by their centres
    assert ngan_metric(model, target) == pytest.approx(want, rel=1e-2)
    assert ngan_metric(target, target) == 0.0


def test_lobe_position_and_relative_errors_identities():
    target = brdfkit.model("lafortune", rho_d=0.0, rho_s=0.8, C_xy=-1.0, C_z=1.0, n=50.0)
    assert lobe_position(target, target) == (1.0, 1.0)
    top, base = lobe_position(target.with_params(rho_s=1.6), target)
    assert top == pytest.approx(2.0, rel=1e-12)  # twice the lobe: twice its top
    assert base > 1.0  # and wider above the same base level
    assert relative_errors(target, target) == (0.0, 0.0)
    grey = brdfkit.model("lafortune", rho_d=0.2, rho_s=0.8, n=50.0)
    e_point, e_albedo = relative_errors(grey.with_params(rho_d=0.3, rho_s=1.2), grey)
    # f scaled by 1.5: the albedo ratio is 1.5 exactly; the floored point ratio
    # (1.5 y + τ)/(y + τ) stays below 1.5 and tends to it where y ≫ τ
    assert e_albedo == pytest.approx(math.log(1.5), rel=1e-9)
    assert 0.9 * math.log(1.5) < e_point < math.log(1.5)


def test_batches_and_metal_rule():
    assert [is_metal(f"merl:{n}") for n in ("nickel", "chrome-steel", "two-layer-silver",
                                            "gold-metallic-paint", "hematite", "gray-plastic")] \
        == [True, True, True, False, False, False]
    b = study_batches(("merl:nickel", "merl:gray-plastic"), ngan_names={"nickel"})
    names = [(x.part, x.name, x.targets) for x in b]
    assert ("anchors", "lafortune-ngan", ("merl:nickel",)) in names
    assert ("neumann", "pumped-phong-l2", ("merl:nickel",)) in names
    assert sum(x.part == "nielsen" for x in b) == 6
    with pytest.raises(BrdfkitError, match="parts must be among"):
        study_batches((), parts=("bogus",))


def _row(target, loss, params, metric, **extra):
    return {"model": "nielsen", "target": target, "loss": loss, "procedure": "nielsen",
            "status": "ok", "fit_status": 0, "params": json.dumps(params),
            f"metric_{loss}": metric, "seconds": 2.0, "at_bounds": "[]", **extra}


def test_report_verdicts_from_synthetic_files(tmp_path):
    """Two materials: A Phong-like, B Blinn–Phong-like, the α-mix better on both, the L2
    fits nearer the tops and the L1 fits nearer the bases: every Nielsen claim supported.
    Then the α-mix made worse than Phong on B: the α-mix claim is not supported."""
    from brdfkit.fitting.study import params_hash

    d = tmp_path / "study"
    (d / "nielsen").mkdir(parents=True)
    (d / "derived").mkdir()
    A, B = "merl:gray-plastic", "merl:chrome"
    l1 = {"phong": {A: 1.0, B: 3.0}, "blinn-phong": {A: 2.0, B: 2.0},
          "alpha-mix": {A: 0.9, B: 1.5}}
    pos = {"l1": (0.5, 1.0), "l2": (0.95, 0.5)}  # (top ratio, base ratio)
    for v, vals in l1.items():
        for loss in ("l1", "l2"):
            rows = [_row(t, loss, {"alpha": 0.3 if t == A else 0.8}, x) for t, x in
                    vals.items()]
            write_rows(d / "nielsen" / f"{v}-{loss}.csv", rows)
            derived = [{"model": "nielsen", "target": r["target"], "loss": loss,
                        "procedure": f"nielsen@{params_hash(r['params'])}", "status": "ok",
                        "energy": "conserves", "top_ratio": pos[loss][0],
                        "base_ratio": pos[loss][1], "job_seconds": 1.0} for r in rows]
            write_rows(d / "derived" / f"nielsen-{v}-{loss}.csv", derived)
    out = tmp_path / "report.md"
    write_report(d, out=out, figures=tmp_path / "fig")
    text = out.read_text()
    assert "Subset run: 2 of 100" in text
    from brdfkit.fitting.study import read_study

    verdicts = {c["claim"][:20]: c["verdict"] for c in claims(read_study(d))}
    assert verdicts == {"some materials are f": "supported", "the α-mix (eq. 3) fi": "supported",
                        "L2 fits the lobe to ": "supported", "the three-stage proc": "supported"}
    assert (tmp_path / "fig" / "alpha-histogram.png").stat().st_size > 1000
    # the α-mix above Phong on B (an optimiser failure): not supported
    write_rows(d / "nielsen" / "alpha-mix-l1.csv",
               [_row(A, "l1", {"alpha": 0.3}, 1.2), _row(B, "l1", {"alpha": 0.8}, 2.5)])
    verdicts = {c["claim"][:20]: c["verdict"] for c in claims(read_study(d))}
    assert verdicts["the α-mix (eq. 3) fi"] == "not supported"


def test_the_study_script_without_ngans_table_says_so_in_one_line(tmp_path):
    # Regression (issue 20): `scripts/fit_study.py run` died with a raw traceback when the
    # Ngan table's path was absent; now one line naming the path and the way round it.
    import pathlib
    import subprocess
    import sys

    script = pathlib.Path(__file__).resolve().parents[1] / "scripts" / "fit_study.py"
    r = subprocess.run([sys.executable, str(script), "run", "--dir", str(tmp_path / "s"),
                        "--materials", "merl:nickel", "--parts", "anchors", "--ngan",
                        str(tmp_path / "absent.csv")], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("fit_study.py: error: ngan_csv"), r.stderr
    assert "absent.csv" in lines[0] and "--parts nielsen,neumann" in lines[0]
