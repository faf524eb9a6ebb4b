"""One command-line vocabulary (issue 20): the options one command has where its siblings
have them too, each help stated once. References are the commands' own definitions of the
same thing elsewhere: `albedo --tol`, the engine's validated `tol`, Mitsuba's variant list."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from brdfkit.cli import main
from brdfkit.render.mitsuba_bridge import VARIANTS


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def test_fit_param_help_says_it_once():
    # the -p help repeated itself ("Hold a parameter ... Model parameter NAME=VALUE
    # (repeatable)") where it appended the shared help to its own
    out = " ".join(run("fit", "--help").output.split())
    assert "Model parameter NAME=VALUE" not in out  # the shared -p sentence, appended before
    assert "Hold parameter NAME of MODEL fixed at VALUE (repeatable; one MODEL only)" in out


def test_check_takes_tol_as_albedo_does():
    ok = run("check", "lambert", "--tol", "1e-5", "--json")
    assert ok.exit_code == 0, ok.output
    assert json.loads(ok.output)["energy"] == "conserves"  # ρ_d = default ≤ 1 (closed form)
    bad = run("check", "lambert", "--tol", "-1")
    assert bad.exit_code == 2 and "tol must be a positive number" in bad.output
    assert "--tol" in run("albedo", "--help").output and "--tol" in run("check", "--help").output


@pytest.mark.parametrize("args, words", [
    (("--engine", "mitsuba", "--variant", "foo"), "--variant must be one of"),
    (("--variant", "scalar_rgb"), "the direct engine is exact and runs no Mitsuba"),
])
def test_render_variant_is_an_option_with_one_line_errors(tmp_path, args, words):
    r = run("render", "sphere", "lambert", "--phi-l", "30", *args, "--out", tmp_path / "x.png")
    assert r.exit_code == 2 and words in r.output, r.output
    assert all(v in " ".join(run("render", "sphere", "--help").output.split())
               for v in VARIANTS)


def test_table2_markdown_has_the_legend_the_plain_table_has():
    md = run("table2", "--markdown", "--model", "lambert").output
    plain = run("table2", "--model", "lambert").output
    legend = plain.splitlines()[0]
    assert legend.startswith("Lewis 1993 Table 2") and md.splitlines()[0] == legend
    assert "| model |" in md


def test_compare_takes_a_models_own_words_in_figure_and_render(tmp_path):
    # `figure --compare` took specs at their defaults only, and `render sphere` had no way
    # to put two models side by side at one exposure (issue 20)
    import math

    import numpy as np

    import brdfkit
    from brdfkit.cli._common import build_model_words
    from brdfkit.render import exposure_phi0, render_sphere
    from brdfkit.render.image import panel_gap

    m = build_model_words("nielsen -p k_s=5 -p s=200 --pump max --times 2")
    want = brdfkit.pumping.pump(brdfkit.model("nielsen", k_s=5.0, s=200.0), g="max", times=2)
    assert m.to_dict() == want.to_dict()
    bad = run("figure", "slices", "--model", "lambert", "--compare", "nielsen -q 1", "--out",
              tmp_path / "s.png")
    assert bad.exit_code == 2 and "--compare 'nielsen -q 1': the word '-q'" in bad.output
    ok = run("figure", "slices", "--model", "lambert", "--compare", "nielsen -p k_s=5",
             "--out", tmp_path / "s.png")
    assert ok.exit_code == 0, ok.output

    # side by side: each panel is the model's own render (the API's, independently), the
    # panels S/32 black pixels apart; a PNG's one exposure is the brightest panel's phi0 rule
    S, phi = 32, 30.0
    out = tmp_path / "two.npy"
    r = run("render", "sphere", "microfacet", "-p", "alpha=0.2", "--compare",
            "lambert -p rho_d=0.5", "--phi-l", phi, "--size", S, "--out", out)
    assert r.exit_code == 0, r.output
    img = np.load(out)
    a = render_sphere(brdfkit.model("microfacet", alpha=0.2), phi_l=math.radians(phi),
                      size=S).radiance
    b = render_sphere(brdfkit.model("lambert", rho_d=0.5), phi_l=math.radians(phi),
                      size=S).radiance
    g = panel_gap(S)
    assert img.shape == (S, 2 * S + g, 1)
    np.testing.assert_array_equal(img[:, :S], a)
    np.testing.assert_array_equal(img[:, S:S + g], 0.0)
    np.testing.assert_array_equal(img[:, S + g:], b)
    r = run("render", "sphere", "microfacet", "-p", "alpha=0.2", "--compare",
            "lambert -p rho_d=0.5", "--phi-l", phi, "--size", S, "--out", tmp_path / "t.png",
            "--json")
    meta = json.loads(r.output)
    k = min(exposure_phi0(brdfkit.model("microfacet", alpha=0.2), size=S),
            exposure_phi0(brdfkit.model("lambert", rho_d=0.5), size=S))
    assert meta["exposure"] == pytest.approx(k, rel=1e-12) and len(meta["panels"]) == 2
    assert [p["model"]["model"] for p in meta["panels"]] == ["microfacet", "lambert"]
    four = run("render", "sphere", "lambert", *sum((["--compare", "lambert"] for _ in range(4)),
                                                   []), "--phi-l", 0, "--out", tmp_path / "f.png")
    assert four.exit_code == 2 and "--compare takes at most 3 models" in four.output


def test_a_metal_under_one_light_gets_a_note_that_ambient_shows_it(tmp_path):
    # issue 20: metals under one directional light are a black disc with a dot. A smooth
    # conductor (α = 0.05, no diffuse term) lights only its highlight; a Lambertian sphere
    # lights half the disc (N·L > 0 at Φ_L = 30°): the note for the first only.
    metal = run("render", "sphere", "microfacet", "-p", "alpha=0.05", "--phi-l", 30,
                "--size", 64, "--out", tmp_path / "m.png")
    assert metal.exit_code == 0 and "--ambient 0.5" in metal.stderr
    lit = run("render", "sphere", "microfacet", "-p", "alpha=0.05", "--phi-l", 30,
              "--size", 64, "--ambient", "0.5", "--out", tmp_path / "a.png")
    assert lit.exit_code == 0 and lit.stderr == ""
    diffuse = run("render", "sphere", "lambert", "--phi-l", 30, "--size", 64, "--out",
                  tmp_path / "l.png")
    assert diffuse.exit_code == 0 and diffuse.stderr == ""
