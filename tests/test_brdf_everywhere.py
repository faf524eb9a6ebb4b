"""A BRDF Explorer ``.brdf`` file everywhere a model goes (issue 21 §3): every command of
the CLI, pumping, ``brdfkit.fitting.fit``, ``brdfkit models FILE``; the χ² tests of its
samplers and the Mitsuba routes are in tests/test_brdf_everywhere_mitsuba.py.

References, independent of the code under test:

- **closed forms**: Lambert's f_r = ρ/π and albedo ρ; the colour Lambert file's three
  channels albedo/π; Lambert's exact sphere E ρ/π n_z at each pixel centre (Φ_L = 0);
  the qualitative Oren–Nayar model (Oren & Nayar 1994, eq. 30) written in the test,
  A + B max(0, cos Δφ) sin α tan β, for the file's bool switched on;
- **the registered models** (their own kernels, written by the package's contributors):
  the Walter GGX file against ``microfacet`` (distribution ggx, F = 1): values, verdict,
  exact render, pumped albedo and values; a modified Phong file with colour albedos
  written here against the registered ``modified-phong``: its fit to a MERL material;
- **Ward's formula written in the test** (Walter's 2005 notes on the Ward BRDF, eq. 5a
  form) integrated by a product Gauss–Legendre × trapezoid rule: the anisotropic file's
  albedo at two incidence azimuths through ``albedo --phi``; its 1/√(cos θ_i cos θ_o)
  makes the albedo diverge as (cos θ_i)^(−1/2) at grazing incidence (``check --phi``);
- **the file's own text**: the line:col that ``brdfkit models`` gives for reading X holds
  an ``X``; the declared ranges bound the fitted values.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import brdfkit
from brdfkit.cli import main
from brdfkit.fitting import fit

CORPUS = Path(__file__).parent / "brdf_files"
LAMBERT = CORPUS / "lambert.brdf"
COLOUR = CORPUS / "lambert_sampled.brdf"  # color albedo 0.7 0.5 0.3, an isFunc section
WALTER = CORPUS / "walter_ggx.brdf"
WARD = CORPUS / "ward_anisotropic.brdf"
OREN_NAYAR = CORPUS / "oren_nayar.brdf"  # float sigma, bool qualitative, color albedo

#: Modified Phong (Nielsen et al. 2015, eq. 1) as a user writes it in a .brdf: colour
#: albedos, a float exponent and a bool (held by a fit); NARROW declares n in [1, 10].
PHONG = """analytic

# modified Phong, Nielsen et al. 2015 eq. (1): rho_d/pi + rho_s (n+2)/(2 pi) max(0, R.V)^n
::begin parameters
color rho_d 0.2 0.2 0.2
color rho_s 0.5 0.5 0.5
float n {range}
bool black 0
::end parameters

::begin shader
const float PI = 3.14159265358979323846;

vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)
{{
    if (black) return vec3(0.0);
    vec3 R = reflect(-L, N);
    return rho_d / PI + rho_s * (n + 2.0) / (2.0 * PI) * pow(max(0.0, dot(R, V)), n);
}}
::end shader
"""


@pytest.fixture(scope="module")
def phong(tmp_path_factory):
    d = tmp_path_factory.mktemp("brdf_everywhere")
    (d / "phong.brdf").write_text(PHONG.format(range="0 1000000 20"))
    (d / "narrow.brdf").write_text(PHONG.format(range="1 10 5"))
    return d


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def ok_json(*args):
    r = run(*args, "--json")
    assert r.exit_code == 0, r.output
    return json.loads(r.output)


def direction(theta_deg: float, phi_deg: float) -> np.ndarray:
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return np.array([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)])


# --------------------------------------------------------------------------- eval
def test_eval_lambert_is_rho_over_pi():
    d = ok_json("eval", LAMBERT, "-p", "rho=0.5", "--wi", "0,0", "--wo", "30,70")
    assert d["model"] == str(LAMBERT) and d["params"] == {"rho": 0.5}
    assert d["value"] == pytest.approx(0.5 / math.pi, rel=1e-15)
    r = run("eval", LAMBERT, "-p", "rho=0.5", "--wi", "40,0", "--wo", "95,0")
    assert r.exit_code == 0 and float(r.output) == 0.0  # below the horizon: 0


def test_eval_colour_file_has_three_channels():
    d = ok_json("eval", COLOUR, "--wi", "20,0", "--wo", "50,120")
    assert d["params"] == {"albedo": [0.7, 0.5, 0.3]}
    np.testing.assert_allclose(d["value"], np.array([0.7, 0.5, 0.3]) / math.pi, rtol=1e-15)
    d = ok_json("eval", COLOUR, "-p", "albedo=0.1,0.2,0.9", "--wi", "20,0", "--wo", "50,120")
    np.testing.assert_allclose(d["value"], np.array([0.1, 0.2, 0.9]) / math.pi, rtol=1e-15)


@pytest.mark.parametrize("wi, wo", [("40,10", "35,200"), ("70,0", "65,180"), ("5,0", "80,90")])
def test_eval_walter_file_is_the_registered_microfacet(wi, wo):
    ours = ok_json("eval", WALTER, "-p", "alpha=0.3", "-p", "rho_s=0.8", "--wi", wi, "--wo", wo)
    theirs = ok_json("eval", "microfacet", "-p", "distribution=ggx", "-p", "alpha=0.3",
                     "-p", "rho_s=0.8", "--wi", wi, "--wo", wo)
    assert ours["value"] > 0.0
    assert ours["value"] == pytest.approx(theirs["value"], rel=1e-12)


def oren_nayar_qualitative(sigma_deg, wi, wo):
    """Oren & Nayar 1994 eq. (30): A + B max(0, cos(φ_i − φ_o)) sin α tan β (times ρ/π)."""
    s2 = math.radians(sigma_deg) ** 2
    a, b = 1.0 - 0.5 * s2 / (s2 + 0.33), 0.45 * s2 / (s2 + 0.09)
    ti, to = math.acos(wi[2]), math.acos(wo[2])
    dphi = math.atan2(wi[1], wi[0]) - math.atan2(wo[1], wo[0])
    return a + b * max(0.0, math.cos(dphi)) * math.sin(max(ti, to)) * math.tan(min(ti, to))


def test_eval_bool_parameter_switches_the_formula():
    rho = np.array([0.75, 0.75, 0.75]) / math.pi
    for wi, wo in (((50, 10), (30, 40)), ((50, 0), (30, 180))):
        args = ("--wi", f"{wi[0]},{wi[1]}", "--wo", f"{wo[0]},{wo[1]}")
        want = oren_nayar_qualitative(30.0, direction(*wi), direction(*wo)) * rho
        on = ok_json("eval", OREN_NAYAR, "-p", "sigma=30", "-p", "qualitative=true", *args)
        assert on["params"]["qualitative"] is True
        np.testing.assert_allclose(on["value"], want, rtol=1e-12)
    off = ok_json("eval", OREN_NAYAR, "-p", "sigma=30", "-p", "qualitative=0", *args)
    assert off["params"]["qualitative"] is False
    # backscattering (cos Δφ = −1): the full model's C2 term, which eq. (30) drops
    assert abs(off["value"][0] - want[0]) > 1e-2 * want[0]


# --------------------------------------------------------------------------- albedo
def test_albedo_lambert_is_rho():
    d = ok_json("albedo", LAMBERT, "-p", "rho=0.37", "--theta", "0,45,85,89.9")
    np.testing.assert_allclose(d["albedo"], 0.37, rtol=0, atol=1e-9)  # ∫ ρ/π cos θ dω = ρ
    d = ok_json("albedo", COLOUR, "--theta", "0,60")
    np.testing.assert_allclose(d["albedo"], [[0.7, 0.5, 0.3]] * 2, rtol=0, atol=1e-9)


def ward(wi, wo, ax, ay, rho_d, rho_s):
    """Ward 1992 in Walter's form (2005): ρ_d/π + ρ_s exp(−(h_x²/a_x² + h_y²/a_y²)/h_z²)
    / (4π a_x a_y √(cos θ_i cos θ_o)), h = (ω_i + ω_o)/|ω_i + ω_o|; rows of directions."""
    h = wi + wo
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    e = -((h[..., 0] / ax) ** 2 + (h[..., 1] / ay) ** 2) / h[..., 2] ** 2
    spec = rho_s * np.exp(e) / (4 * math.pi * ax * ay * np.sqrt(wi[..., 2] * wo[..., 2]))
    return rho_d / math.pi + spec


def ward_albedo(theta, phi, n_t=400, n_phi=1024, **params):
    """∫ f cos θ_o dω_o, Gauss–Legendre in t = √cos θ_o (cos θ_o dω_o = 2t³ dt dφ, smooth
    for Ward's 1/√cos θ_o) × the trapezoid rule in φ (periodic)."""
    x, w = np.polynomial.legendre.leggauss(n_t)
    t, wt = 0.5 * (x + 1.0), 0.5 * w
    ph = np.arange(n_phi) * (2 * math.pi / n_phi)
    mu = t * t
    st = np.sqrt(1.0 - mu * mu)
    wo = np.stack([np.outer(st, np.cos(ph)), np.outer(st, np.sin(ph)),
                   np.outer(mu, np.ones(n_phi))], axis=-1)
    wi = np.broadcast_to(direction(math.degrees(theta), math.degrees(phi)), wo.shape)
    f = ward(wi, wo, **params)
    return float(np.sum(f * (2.0 * t ** 3 * wt)[:, None]) * (2 * math.pi / n_phi))


def test_albedo_phi_of_the_anisotropic_file():
    params = {"ax": 0.4, "ay": 0.15, "rho_d": 0.1, "rho_s": 0.6}  # the file's defaults
    got = {}
    for phi in (0.0, 90.0):
        d = ok_json("albedo", WARD, "--theta", "60", "--phi", phi)
        assert d["phi_deg"] == phi
        got[phi] = d["albedo"][0]
        want = ward_albedo(math.radians(60.0), math.radians(phi), **params)
        assert got[phi] == pytest.approx(want, abs=1e-6)
    assert abs(got[0.0] - got[90.0]) > 1e-2  # the azimuth matters, far beyond the accuracy
    r = run("albedo", LAMBERT, "--theta", "30", "--phi", "45")  # isotropic: a note, ρ
    assert r.exit_code == 0 and "has no effect" in r.output
    assert "0.800000000" in r.output


# --------------------------------------------------------------------------- check, table2
def test_check_and_table2_of_the_walter_file():
    ours = ok_json("check", WALTER, "-p", "alpha=0.5")
    theirs = ok_json("check", "microfacet", "-p", "distribution=ggx", "-p", "alpha=0.5")
    assert ours["model"] == str(WALTER)
    assert ours["reciprocity"] == theirs["reciprocity"] == "reciprocal"
    assert ours["energy"] == theirs["energy"] == "conserves"
    assert ours["max_albedo"] == pytest.approx(theirs["max_albedo"], abs=1e-6)
    (row,) = ok_json("table2", WALTER)
    assert row["row"] == "walter_ggx.brdf" and row["model"] == str(WALTER)
    assert row["energy"] == "conserves" and row["reciprocity"] == "reciprocal"
    # the file's default α = 0.1: the registered model's verdict at α = 0.1
    ref = ok_json("check", "microfacet", "-p", "distribution=ggx", "-p", "alpha=0.1")
    assert row["max_albedo"] == pytest.approx(ref["max_albedo"], abs=1e-6)


def test_check_phi_of_the_anisotropic_file():
    at = {phi: ok_json("check", WARD, "--phi", phi) for phi in (0.0, 90.0)}
    for phi, d in at.items():
        assert d["phi_deg"] == phi and d["reciprocity"] == "reciprocal"
        # Ward's 1/√(cos θ_i cos θ_o): the specular albedo grows as (cos θ_i)^(-1/2) at
        # grazing incidence (the rest of the integrand stays bounded), measured toward 1/2
        assert d["energy"] == "diverges"
        assert 0.4 < d["divergence_exponent"] <= 0.5
    # the lobe's ellipse: light along X or along Y reflects differently at grazing
    assert at[0.0]["max_albedo"] > 2.0 * at[90.0]["max_albedo"]


# --------------------------------------------------------------------------- figure, export
def test_figure_slices_of_files(tmp_path):
    out = tmp_path / "s.png"
    r = run("figure", "slices", WARD, "--compare", WALTER, "--out", out)
    assert r.exit_code == 0, r.output
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_export_of_a_colour_file(tmp_path):
    out = tmp_path / "c.binary"
    r = run("export", COLOUR, "-p", "albedo=0.6,0.4,0.2", "--out", out)
    assert r.exit_code == 0, r.output
    back = brdfkit.model(str(out))
    f = back.eval(direction(30, 0), direction(50, 140))
    # MERL stores float64 values per channel scaled by its channel factors
    np.testing.assert_allclose(np.ravel(f), np.array([0.6, 0.4, 0.2]) / math.pi, rtol=1e-6)


# --------------------------------------------------------------------------- render sphere
def test_render_sphere_exact_lambert_closed_form(tmp_path):
    out = tmp_path / "l.npy"
    r = run("render", "sphere", LAMBERT, "-p", "rho=0.6", "--phi-l", "0", "--size", "16",
            "--antialias", "1", "--out", out)
    assert r.exit_code == 0, r.output
    img = np.load(out)[..., 0]
    c = (np.arange(16) + 0.5) / 16 * 2.0 - 1.0
    x, y = np.meshgrid(c, c)
    inside = x * x + y * y < 1.0
    # the light behind the viewer: L = V = +z, E ρ/π N·L with N·L = n_z at each pixel centre
    want = np.where(inside, 0.6 / math.pi * np.sqrt(np.clip(1.0 - x * x - y * y, 0.0, 1.0)),
                    0.0)
    np.testing.assert_allclose(img, want, rtol=1e-12, atol=1e-15)


def test_render_sphere_exact_walter_is_the_registered_microfacet(tmp_path):
    a, b = tmp_path / "a.npy", tmp_path / "b.npy"
    common = ("--phi-l", "30", "--size", "16", "--ambient", "0.2")
    assert run("render", "sphere", WALTER, "-p", "alpha=0.3", *common, "--out", a).exit_code == 0
    r = run("render", "sphere", "microfacet", "-p", "distribution=ggx", "-p", "alpha=0.3",
            *common, "--out", b)
    assert r.exit_code == 0, r.output
    ia, ib = np.load(a), np.load(b)
    assert ia.max() > 0.1
    # ambient: ρ(V) of each engine run, within the albedo engine's 1e-9-class accuracy
    np.testing.assert_allclose(ia, ib, rtol=1e-7, atol=1e-9)


def test_render_sphere_mitsuba_engine_takes_a_file(tmp_path):
    """``--engine mitsuba`` on the Walter file (the traced route: the API test in
    test_brdf_everywhere_mitsuba.py asserts it): the image mean against the exact
    pixel-area average, within the render's own Monte-Carlo error."""
    pytest.importorskip("mitsuba")
    size, sub = 16, 8
    out = tmp_path / "m.npy"
    d = ok_json("render", "sphere", WALTER, "-p", "alpha=0.3", "--phi-l", "30", "--size", size,
                "--engine", "mitsuba", "--spp", "256", "--out", out)
    assert d["engine"] == "mitsuba" and d["success"], d
    img = np.load(out)
    from brdfkit.render import render_sphere

    fine = render_sphere(brdfkit.model(str(WALTER), alpha=0.3), phi_l=math.radians(30.0),
                         size=size * sub).radiance
    ref = fine.reshape(size, sub, size, sub, -1).mean(axis=(1, 3))
    # per-pixel standard errors ≤ mc_error_max, independent pixels: the mean's ≤ max/√N
    bound = 5.0 * d["mc_error_max"] / size
    assert bound < 0.05 * ref.mean()  # power: a 5 % bias of the render would be caught
    for ch in range(img.shape[-1]):  # a grey file: every channel the same image
        assert abs(img[..., ch].mean() - ref.mean()) < bound, (img[..., ch].mean(), ref.mean())


# --------------------------------------------------------------------------- pumping
def test_pumping_a_file_is_pumping_the_registered_model(tmp_path):
    theirs_m = ("microfacet", "-p", "distribution=ggx", "-p", "alpha=0.5", "--pump", "max")
    ours_m = (WALTER, "-p", "alpha=0.5", "--pump", "max")
    ours = ok_json("albedo", *ours_m, "--theta", "0,60,85")
    theirs = ok_json("albedo", *theirs_m, "--theta", "0,60,85")
    assert ours["pump"] == {"g": "max", "times": 1}
    np.testing.assert_allclose(ours["albedo"], theirs["albedo"], atol=1e-6)
    pair = ("--wi", "60,0", "--wo", "60,180")
    e1, e2 = ok_json("eval", *ours_m, *pair), ok_json("eval", *theirs_m, *pair)
    plain = ok_json("eval", WALTER, "-p", "alpha=0.5", *pair)
    assert e1["value"] > plain["value"]  # pumped up
    assert e1["value"] == pytest.approx(e2["value"], rel=1e-6)
    c1, c2 = ok_json("check", *ours_m), ok_json("check", *theirs_m)
    assert c1["max_albedo"] == pytest.approx(c2["max_albedo"], abs=1e-6)
    a, b = tmp_path / "a.npy", tmp_path / "b.npy"
    for m, out in ((ours_m, a), (theirs_m, b)):
        r = run("render", "sphere", *m, "--phi-l", "45", "--size", "8", "--out", out)
        assert r.exit_code == 0, r.output
    np.testing.assert_allclose(np.load(a), np.load(b), rtol=1e-6, atol=1e-12)
    out = tmp_path / "p.png"
    assert run("figure", "slices", WALTER, "--pump", "max", "--out", out).exit_code == 0
    x1, x2 = (ok_json("export", *m, "--out", tmp_path / f"{k}.binary")
              for k, m in (("a", ours_m), ("b", theirs_m)))
    assert x1["pump"] == {"g": "max", "times": 1}
    np.testing.assert_allclose(x1["normal_albedo"], x2["normal_albedo"], rtol=1e-6)


def test_pumping_the_anisotropic_file_is_one_error_line():
    r = run("albedo", WARD, "--pump", "max", "--theta", "0")
    assert r.exit_code == 2
    (line,) = r.stderr.strip().splitlines()
    assert line.startswith("brdfkit: error: pump: ward_anisotropic.brdf is anisotropic")


# --------------------------------------------------------------------------- fit
def test_cli_fit_of_a_file_with_colours_and_a_bool(phong):
    target = "merl:nickel"
    d = ok_json("fit", phong / "phong.brdf", "--to", target)
    assert d["model"] == str(phong / "phong.brdf") and d["success"], d["message"]
    assert d["params"]["black"] is False  # held at its default, never a fitted coordinate
    fitted = {p for s in d["convergence"]["stages"] for p in s["parameters"]}
    assert fitted == {"rho_d", "rho_s", "n"}
    assert len(d["params"]["rho_d"]) == len(d["params"]["rho_s"]) == 3  # colours per channel
    ref = fit(brdfkit.model("modified-phong"), brdfkit.model(target))
    assert d["value"] == pytest.approx(ref.value, rel=0.02)
    assert d["params"]["n"] == pytest.approx(ref.params["n"], rel=0.05)
    np.testing.assert_allclose(d["params"]["rho_s"], ref.params["rho_s"], rtol=0.05)


def test_api_fit_stays_within_the_files_ranges(phong):
    target = brdfkit.model("merl:nickel")
    wide = fit(brdfkit.model(str(phong / "phong.brdf")), target)
    assert wide.params["n"] > 10.0  # nickel wants a sharper lobe than the narrow file allows
    r = fit(brdfkit.model(str(phong / "narrow.brdf")), target)
    assert 1.0 <= r.params["n"] <= 10.0 and r.params["n"] == pytest.approx(10.0, rel=1e-6)
    assert "n = 10, at its upper bound 10" in r.message
    for name in ("rho_d", "rho_s"):  # a color's components: [0, 1]
        assert all(0.0 <= v <= 1.0 for v in r.params[name])
    assert r.value > wide.value  # the bound costs
    held = fit(brdfkit.model(str(phong / "phong.brdf"), black=True), target)
    assert held.params["black"] is True  # a bool is held, even where it zeroes the model


# --------------------------------------------------------------------------- models FILE
def test_models_file_shows_isotropy_with_its_location():
    r = run("models", WARD)
    assert r.exit_code == 0, r.output
    m = re.search(r"isotropic: no \(reads the tangent X \((.+):(\d+):(\d+)\)\)", r.output)
    assert m, r.output
    path, line, col = m.group(1), int(m.group(2)), int(m.group(3))
    assert path == str(WARD)
    assert WARD.read_text().splitlines()[line - 1][col - 1] == "X"  # 1-based, in the file
    for name, default in (("alpha_x", "0.4"), ("alpha_y", "0.15"), ("rho_d", "0.1")):
        assert re.search(rf"\n +{name} +{re.escape(default)} +\[", r.output), name
    (d,) = ok_json("models", WARD)
    assert d["isotropic"] is False and d["source"] == str(WARD)
    assert d["claims"] == {"reciprocal": None, "energy_conserving": None}  # a file claims nothing
    assert [p["name"] for p in d["params"]] == ["alpha_x", "alpha_y", "rho_d", "rho_s"]
    (iso,) = ok_json("models", WALTER)
    assert iso["isotropic"] is True and "rotation- and mirror-invariant" in iso["isotropy_reason"]


def test_models_file_notes_the_ignored_isfunc_and_the_colour():
    r = run("models", COLOUR)
    assert r.exit_code == 0, r.output
    assert "note: isFunc section ignored" in r.output
    assert re.search(r"\n +albedo +\[0\.7, 0\.5, 0\.3\] +\[0, 1\] +colour", r.output)
    (d,) = ok_json("models", COLOUR)
    assert any("isFunc" in n for n in d["notes"])
    assert not d["own_sampler"]


def test_models_of_a_broken_file_is_one_error_line(tmp_path):
    bad = tmp_path / "bad.brdf"
    bad.write_text(LAMBERT.read_text().replace("rho / PI", "rho / PI + texture2D(t, V.xy).x"))
    r = run("models", bad)
    assert r.exit_code == 2
    (line,) = r.stderr.strip().splitlines()
    assert line.startswith(f"brdfkit: error: {bad}:") and "texture2D" in line, line
