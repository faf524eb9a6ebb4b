"""The energy verdicts of issue 22 §3: values against independent references, the CLI, the
figure.

References (none is the program's own output):

- Lambert: f = ρ/π, so a(θ) = ρ exactly at every θ and f(L,V) = f(V,L) (asymmetry 0).
- The original Phong (Lewis 1993 eqs. (5), (8)): f(S,V) = k_d + k_s max(0, R_S·V)ⁿ/(N·S),
  written here, over check's pair set written here (θ ∈ {0, 15, 30, 45, 60, 75, 85, 89,
  89.9}°, relative azimuths {0, 45, 90, 135, 180}°, L at azimuth 0). With k_d = 0, n = 1
  the largest relative asymmetry is, by hand, 1 − cos 89.9° (the pair θ_L = 0°,
  θ_V = 89.9°, Δφ = 0: R_L·V = R_V·L = cos 89.9°, f(L,V) = k_s cos 89.9°, f(V,L) = k_s).
- GGX (Walter et al. 2007 eqs. (20), (33), (34)) at α = 1 with F = 1, written here:
  E_avg = 2 ∫₀¹ E(μ) μ dμ by a direct product Gauss–Legendre quadrature over (μ_i, θ_o,
  φ_o) — a second method — and E(1) = 1 − ln 2 in closed form: at α = 1, D = 1/π and at
  normal incidence G₁(ω_i) = 1, so a(0) = ∫ G₁(ω_o)/(4π) dω_o = ½ ∫₀¹ 2μ/(1 + μ) dμ
  = 1 − ln 2 (G₁ = 2μ/(1 + μ) at α = 1).
- Turquin's factor at F₀ = 1 is 1/E(μ) at ω_i, so over a reciprocal base the asymmetry is
  1 − min E/max E over the pair set's angles (derived in the test's docstring).
- Disney's diffuse term (Burley 2012 notes §5.3, written in ``report/disney_diffuse.py``)
  against the registered ``disney`` (its reference's code) where Schlick's factor is 0
  (ω_i = ω_o), and F_D90 worked out by hand at normal incidence.
- An anisotropic model's furnace: the mean and range over the azimuths, against the
  albedo engine called at each azimuth.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner

import brdfkit
from brdfkit.analysis.energy_verdict import (
    FURNACE_DEG,
    bound_text,
    energy_reciprocity,
    energy_verdict,
    furnace,
)
from brdfkit.cli import main
from brdfkit.errors import BrdfkitError
from brdfkit.report.energy_findings import FINDINGS, findings
from brdfkit.report.energy_table import (
    FURNACE_TOL,
    ROWS,
    _agrees_energy,
    _num,
    energy_table,
    select_rows,
)


def run(*args: str):
    return CliRunner().invoke(main, list(args))


def assert_one_line_error(result, *fragments: str) -> None:
    assert result.exit_code == 2, (result.exit_code, result.output)
    err = result.stderr.strip().splitlines()
    assert len(err) == 1, result.stderr
    assert err[0].startswith("brdfkit: error: "), err[0]
    assert "Traceback" not in result.output
    for frag in fragments:
        assert frag in err[0], (frag, err[0])


# --------------------------------------------------------------------------- references
def test_lambert_albedo_is_rho_exactly_and_symmetric():
    rho = 0.7
    v = energy_verdict(brdfkit.model("lambert", rho_d=rho))
    assert v.max_asymmetry == 0.0 and v.reciprocal
    assert v.furnace["theta_deg"] == list(FURNACE_DEG)
    for a, d, e in zip(v.furnace["albedo"], v.furnace["deficit"], v.furnace["error"],
                       strict=True):
        assert abs(a - rho) <= 1e-12 and abs(d - (1 - rho)) <= 1e-12
        assert e < 1e-7  # the engine's estimate is honest and small
    assert abs(v.e_avg - rho) <= 1e-12 and v.energy == "conserves"
    assert abs(v.max_albedo - rho) <= 1e-12


def _phong_lewis(L, V, k_d, k_s, n):
    """Lewis eqs. (5), (8): k_d + k_s max(0, R_L·V)ⁿ / (N·L), R_L = 2 N (N·L) − L."""
    R = 2.0 * L[..., 2:3] * np.array([0.0, 0.0, 1.0]) - L
    rv = np.maximum(np.sum(R * V, axis=-1), 0.0)
    return k_d + k_s * rv ** n / L[..., 2]


def _dirs(theta_deg, phi_deg):
    t, p = np.radians(theta_deg), np.radians(phi_deg)
    return np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)


def test_phong_asymmetry_against_a_hand_computation():
    k_d, k_s, n = 0.0, 1.0, 1.0
    th = (0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0, 89.0, 89.9)
    ti, to, dp = np.meshgrid(th, th, (0.0, 45.0, 90.0, 135.0, 180.0), indexing="ij")
    L, V = _dirs(ti.ravel(), 0.0 * ti.ravel()), _dirs(to.ravel(), dp.ravel())
    a, b = _phong_lewis(L, V, k_d, k_s, n), _phong_lewis(V, L, k_d, k_s, n)
    scale = max(a.max(), b.max())
    ref = np.max(np.abs(a - b) / np.maximum(np.maximum(a, b), 1e-12 * scale))
    assert ref == pytest.approx(1.0 - math.cos(math.radians(89.9)), rel=1e-12)  # by hand
    v = energy_verdict(brdfkit.model("phong", k_d=k_d, k_s=k_s, n=n))
    assert v.max_asymmetry == pytest.approx(ref, rel=1e-9)
    assert v.reciprocity == "not reciprocal"
    # the diverging albedo (Lewis §4.1): Table 2's divergence, a ∝ (cos θ)^-1
    assert v.energy == "diverges" and v.divergence_exponent == pytest.approx(1.0, abs=0.01)


def _ggx_white(mu_i, theta_o, phi_o, alpha):
    """Walter eq. (20) with F = 1, GGX D (eq. 33) and the separable Smith G₁ (eq. 34)."""
    si = np.sqrt(1.0 - mu_i * mu_i)
    wi = np.stack([si, 0.0 * si, mu_i], axis=-1)
    wo = np.stack([np.sin(theta_o) * np.cos(phi_o), np.sin(theta_o) * np.sin(phi_o),
                   np.cos(theta_o)], axis=-1)
    h = wi + wo
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    c2 = h[..., 2] ** 2
    t2 = (1.0 - c2) / c2
    D = alpha ** 2 / (math.pi * c2 * c2 * (alpha ** 2 + t2) ** 2)

    def g1(mu):
        return 2.0 / (1.0 + np.sqrt(1.0 + alpha ** 2 * (1.0 - mu * mu) / (mu * mu)))

    mu_o = wo[..., 2]
    return D * g1(mu_i) * g1(mu_o) / (4.0 * mu_i * mu_o)


def test_ggx_e_avg_at_alpha_1_against_a_direct_quadrature():
    alpha = 1.0
    xm, wm = np.polynomial.legendre.leggauss(40)
    mu = (xm + 1) / 2  # μ_i ∈ (0, 1)
    xt, wt = np.polynomial.legendre.leggauss(96)
    to = (xt + 1) * math.pi / 4  # θ_o ∈ (0, π/2)
    xp, wp = np.polynomial.legendre.leggauss(96)
    po = (xp + 1) * math.pi / 2  # φ_o ∈ (0, π), doubled: f is even in φ_o
    M, T, P = np.meshgrid(mu, to, po, indexing="ij")
    f = _ggx_white(M, T, P, alpha)
    w2 = np.outer(wt * math.pi / 4, wp * math.pi / 2)
    E = 2.0 * np.sum(f * np.cos(T) * np.sin(T) * w2, axis=(1, 2))
    e_avg_ref = float(np.sum(2.0 * E * mu * wm / 2))
    v = energy_verdict(brdfkit.model("microfacet", distribution="ggx", alpha=alpha))
    assert v.e_avg == pytest.approx(e_avg_ref, abs=2e-6)
    assert v.e_avg_error < 1e-6
    # E(1) = 1 − ln 2 in closed form (module docstring)
    assert v.furnace["albedo"][0] == pytest.approx(1.0 - math.log(2.0), abs=1e-9)
    assert v.reciprocal and v.max_asymmetry <= 1e-15


def test_energy_reciprocity_point_is_the_largest_furnace_deviation():
    m = brdfkit.model("modified-phong", rho_d=0.0, rho_s=1.0, n=20.0)
    p = energy_reciprocity(m)
    grid = [*(3.0 * k for k in range(30)), 89.0]
    f = furnace(m, grid)
    assert p["deviation"] == pytest.approx(max(f["deficit"], key=abs), abs=0)
    assert p["theta_deg"] == 89.0 and p["asymmetry"] == 0.0  # the dark Phong mirror


# --------------------------------------------------------------------------- accuracy
def test_no_more_digits_than_the_accuracy():
    assert bound_text(3e-9, 2e-8) == "0 (±2e-08)"
    assert bound_text(0.25, 1e-8).startswith("0.25 ± 1e-08")
    assert _num(-4e-9, 1e-8) == "0"
    assert _num(0.123456, 1e-8) == "0.1235"
    # an error of 3e-3: the third decimal is the last shown (it is uncertain), no fourth
    assert _num(0.123456, 3e-3) == "0.123"
    assert _num(0.123456, 0.04) == "0.12"
    assert _num(0.5, 5e-5) == "0.5000"


def _fake(deficits, errors, energy="conserves"):
    return {"furnace": {"deficit": deficits, "error": errors}, "energy": energy}


def test_claims_are_judged_with_their_accuracy():
    assert _agrees_energy("a = 1", _fake([5e-6, -5e-6, 0, 0], [1e-8] * 4))
    assert not _agrees_energy("a = 1", _fake([2 * FURNACE_TOL, 0, 0, 0], [1e-8] * 4))
    # a loss within the engine's error is no loss
    assert not _agrees_energy("loses", _fake([1e-9, 0, 0, 0], [1e-8] * 4))
    assert _agrees_energy("loses", _fake([0.3, 0, 0, 0], [1e-8] * 4))
    assert not _agrees_energy("bounded", _fake([0, 0, 0, -5], [1e-8] * 4, "diverges"))
    assert _agrees_energy(None, _fake([0] * 4, [0] * 4)) is None


def test_rows_are_specs_with_unique_labels_and_known_claims():
    labels = [r["label"] for r in ROWS]
    assert len(labels) == len(set(labels))
    for r in ROWS:
        assert {"label", "group", "spec", "claim"} <= set(r) <= {"label", "group", "spec",
                                                                 "claim", "tol"}
        assert "model" in r["spec"]
    with pytest.raises(BrdfkitError, match="valid rows"):
        select_rows(["no such row"])
    with pytest.raises(BrdfkitError, match="twice"):
        energy_table(rows=[ROWS[0], ROWS[0]])


# --------------------------------------------------------------------------- CLI
def test_cli_verdicts_json_shape_and_findings():
    r = run("verdicts", "--json", "--row", "Lambert", "--row", "GGX a=1")
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert set(d) == {"rows", "findings"}
    assert [x["label"] for x in d["rows"]] == ["GGX a=1", "Lambert"]  # the table's order
    for x in d["rows"]:
        assert {"reciprocal", "max_asymmetry", "energy", "max_albedo", "max_albedo_error",
                "theta_max_deg", "furnace", "e_avg", "e_avg_error", "divergence_exponent",
                "paper", "agrees_with_paper", "spec", "status"} <= set(x)
        assert x["furnace"]["theta_deg"] == list(FURNACE_DEG)
        assert x["agrees_with_paper"] is True
    assert [f["key"] for f in d["findings"]] == [k for k, _, _ in FINDINGS]
    by_key = {f["key"]: f for f in d["findings"]}
    assert by_key["ggx-loses"]["verdict"] == "confirmed"
    assert by_key["eon"]["verdict"] == "not evaluated"  # its rows were not computed
    assert r.stderr == ""  # not a terminal: no progress


def test_cli_verdicts_spec_row_and_text_output():
    r = run("verdicts", "--spec",
            '{"model": "lambert", "params": {"rho_d": 1.0}, "label": "white"}')
    assert r.exit_code == 0, r.output
    assert "white" in r.stdout and "Findings" in r.stdout
    lines = [x for x in r.stdout.splitlines() if x.startswith("white ")]
    assert len(lines) == 1 and "conserves 1.0000 @ 0" in lines[0]


@pytest.mark.parametrize("args, fragment", [
    (("--row", "nope"), "unknown row 'nope'"),
    (("--spec", "{bad"), "--spec must be a JSON object"),
    (("--spec", "[1]"), "--spec must be a JSON object"),
    (("--spec", '{"model": "nope"}'), "unknown model 'nope'"),
    (("--spec", '{"model": "lambert", "label": 3}'), "label must be a string"),
    (("--json", "--markdown"), "at most one of --json and --markdown"),
    (("--list", "--row", "Lambert"), "--list prints the row labels only"),
])
def test_cli_verdicts_one_line_errors(args, fragment):
    assert_one_line_error(run("verdicts", *args), fragment)


def test_cli_verdicts_list():
    r = run("verdicts", "--list")
    assert r.exit_code == 0 and r.stdout.splitlines() == [x["label"] for x in ROWS]


# --------------------------------------------------------------------------- figure
def test_energy_reciprocity_figure_renders_small(tmp_path):
    import matplotlib.pyplot as plt

    from brdfkit.figures import FIGURES, save_atomic
    from brdfkit.figures.energy import energy_reciprocity as figure

    assert "energy-reciprocity" in FIGURES
    fig = figure(alphas=(1.0,), exponents=(20.0,))
    try:
        out = save_atomic(fig, tmp_path / "er.png", dpi=40)
    finally:
        plt.close(fig)
    data = open(out, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 2000


def test_findings_not_evaluated_without_rows():
    assert {f["verdict"] for f in findings([])} == {"not evaluated"}


# --------------------------------------------------------------------------- rows' models
def test_disney_diffuse_file_is_the_registered_diffuse_where_schlick_vanishes():
    """At ω_i = ω_o, cos θ_d = 1: the specular's Schlick factor (1 − cos θ_d)⁵ is 0, and
    with specular = metallic = sheen = clearcoat = subsurface = 0 the registered disney
    (its reference's code) is its diffuse term alone, which the file writes from Burley's
    notes §5.3. Elsewhere the registered model is larger (its specular is >= 0)."""
    from brdfkit.report.energy_table import DISNEY_DIFFUSE

    file_model = brdfkit.model(DISNEY_DIFFUSE, base_color=1.0, roughness=0.7)
    ref = brdfkit.model("disney", base_color=1.0, roughness=0.7, specular=0.0)
    w = _dirs(np.array([0.0, 20.0, 45.0, 70.0, 85.0, 89.5]), np.array([0, 30, 60, 90, 5, 0.0]))
    a = np.asarray(file_model.eval(w, w)).reshape(-1)
    b = np.asarray(ref.eval(w, w)).reshape(w.shape[0], -1)[:, 0]
    np.testing.assert_allclose(a, b, rtol=1e-12)
    L, V = _dirs(np.array([60.0, 80.0]), np.zeros(2)), _dirs(np.array([70.0, 85.0]),
                                                             np.array([180.0, 120.0]))
    fd = np.asarray(file_model.eval(L, V)).reshape(-1)
    assert np.all(np.asarray(ref.eval(L, V)).reshape(2, -1)[:, 0] > fd)
    # and at normal incidence, Burley's F_D90 − 1 multiplies (1 − cos θ)⁵ = 0 on the light
    # side: f_d(N, V) = (1/π)(1 + (F_D90 − 1)(1 − cos θ_v)⁵) with cos²θ_d = (1 + cos θ_v)/2
    cv = math.cos(math.radians(70.0))
    fd90m1 = 2 * 0.7 * (1 + cv) / 2 - 0.5
    n, v = np.array([[0.0, 0.0, 1.0]]), _dirs(np.array([70.0]), np.array([0.0]))
    assert float(file_model.eval(n, v)[0]) == pytest.approx(
        (1 + fd90m1 * (1 - cv) ** 5) / math.pi, rel=1e-14)


def test_anisotropic_furnace_is_the_azimuthal_mean_with_its_range():
    from brdfkit.analysis import albedo
    from brdfkit.analysis.energy_verdict import ANISO_PHI_DEG

    m = brdfkit.model("microfacet-anisotropic", distribution="ggx", alpha_x=0.6, alpha_y=0.2)
    f = furnace(m, (60.0,))
    a = np.asarray(albedo(m, np.radians(60.0), phi=np.radians(ANISO_PHI_DEG)).albedo)
    assert f["albedo"][0] == pytest.approx(a.mean(), abs=1e-14)
    assert f["deficit_min"][0] == pytest.approx(1 - a.max(), abs=1e-14)
    assert f["deficit_max"][0] == pytest.approx(1 - a.min(), abs=1e-14)
    assert a.max() - a.min() > 1e-3  # the azimuth matters for this model
    assert f["phi_deg"] == list(ANISO_PHI_DEG)


def test_turquin_asymmetry_is_one_minus_the_albedo_ratio():
    """Turquin's factor 1 + F₀(1 − E(μ))/E(μ) at F₀ = 1 is 1/E(μ), taken at ω_i: f_T(L,V) =
    f(L,V)/E(μ_L), f_T(V,L) = f(V,L)/E(μ_V), and f is reciprocal, so |f_T(L,V) − f_T(V,L)|
    / max = 1 − min(E(μ_L), E(μ_V))/max(...): over check's pair set (θ up to 89.9°) it is
    1 − min E/max E, where the pair has f > 0 in both orders. For GGX α = 1, E rises
    monotonically from θ = 0° to 89.9° (E(0) = 1 − ln 2)."""
    from brdfkit.analysis import albedo

    base = {"model": "microfacet", "params": {"distribution": "ggx", "alpha": 1.0}}
    m = brdfkit.ModelSpec.from_dict({**base, "compensate": {"method": "turquin"}}).build()
    e = np.asarray(albedo(brdfkit.ModelSpec.from_dict(base).build(),
                          np.radians([0.0, 89.9])).albedo)
    v = energy_verdict(m)
    assert v.max_asymmetry == pytest.approx(1.0 - e[0] / e[1], rel=1e-4)
    assert v.reciprocity == "not reciprocal"
