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
    md = run("table2", "--markdown", "lambert").output
    plain = run("table2", "lambert").output
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
    bad = run("figure", "slices", "lambert", "--compare", "nielsen -q 1", "--out",
              tmp_path / "s.png")
    assert bad.exit_code == 2 and "--compare 'nielsen -q 1': the word '-q'" in bad.output
    ok = run("figure", "slices", "lambert", "--compare", "nielsen -p k_s=5",
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


# ---------------------------------------------------------------- one way to name a model
def test_figure_takes_its_model_as_an_argument_and_the_old_words_with_a_note(tmp_path):
    # the model was '--model SPEC' in figure but a positional MODEL in eval, albedo, check,
    # render, export, fit; the panel width was '--size' where render's --size is the image
    # side (issue 20)
    new = run("figure", "slices", "nielsen", "-p", "k_s=5", "--out", tmp_path / "a.svg")
    assert new.exit_code == 0 and new.stderr == "", new.output
    old = run("figure", "slices", "--model", "nielsen", "-p", "k_s=5", "--out",
              tmp_path / "b.svg")
    assert old.exit_code == 0, old.output
    assert old.stderr.count("\n") == 1 and "brdfkit: note: --model is deprecated" in old.stderr
    both = run("figure", "slices", "lambert", "--model", "ward", "--out", tmp_path / "c.svg")
    assert both.exit_code == 2 and "give the model once" in both.output
    unused = run("figure", "lewis-fig5", "lambert", "--out", tmp_path / "d.png")
    assert unused.exit_code == 2 and "takes no model" in unused.output
    help_ = run("figure", "--help").output
    assert "--panel-size" in help_ and "--size" not in help_ and "--model" not in help_
    assert "Usage: brdfkit figure [OPTIONS] NAME [MODEL]" in help_


def test_figure_size_is_kept_as_a_deprecated_panel_size(monkeypatch, tmp_path):
    import brdfkit.figures as figures

    seen = []
    monkeypatch.setattr(figures, "save_figure", lambda key, out, **kw: seen.append(kw["options"]))
    r = run("figure", "neumann-fig8", "--size", 64, "--out", tmp_path / "f.png")
    assert r.exit_code == 0 and "--size is deprecated; use --panel-size" in r.stderr, r.output
    r = run("figure", "neumann-fig8", "--panel-size", 48, "--out", tmp_path / "f.png")
    assert r.exit_code == 0 and r.stderr == "", r.output
    assert seen == [{"size": 64}, {"size": 48}]


def test_table2_takes_models_as_arguments_with_their_words():
    from brdfkit.analysis.lewis_table2 import table2

    got = json.loads(run("table2", "lambert", "nielsen -p k_s=5 -p s=200", "--json").output)
    import brdfkit

    want = json.loads(json.dumps(table2(models=["lambert", brdfkit.model(
        "nielsen", k_s=5.0, s=200.0)]), default=float))
    assert [r["model"] for r in got] == [r["model"] for r in want]
    assert [r["max_albedo"] for r in got] == pytest.approx([r["max_albedo"] for r in want])
    old = run("table2", "--model", "lambert", "--json")
    assert old.exit_code == 0 and "--model is deprecated" in old.stderr
    assert json.loads(old.stdout)[0]["model"] == "lambert"


def test_explore_opens_a_model_with_its_parameters_and_pumping(monkeypatch):
    # explore took model specs only: no -p, no --pump (issue 20). The state it hands the page
    # is read back by the explorer's own reader (compute.entry_spec) into the model that
    # build_model makes of the same words.
    import urllib.parse

    import brdfkit.cli.explore_commands as ec
    from brdfkit.cli._common import build_model
    from brdfkit.explorer.compute import entry_spec
    from brdfkit.explorer.serve import start_url

    calls = []
    monkeypatch.setattr(ec, "serve", lambda **kw: calls.append(kw))
    r = run("explore", "modified-phong", "-p", "n=20", "--pump", "max", "--times", "2",
            "--no-browser")
    assert r.exit_code == 0, r.output
    url = start_url("127.0.0.1", 8765, calls[0]["specs"], calls[0]["models"])
    state = json.loads(urllib.parse.unquote(url.split("#", 1)[1]))
    got = entry_spec(state["models"][0]).build()
    want = build_model("modified-phong", ["n=20"], pump="max", times=2)
    assert got.to_dict() == want.to_dict()
    r = run("explore", "'nielsen -p k_s=5'", "merl:nickel", "--no-browser")
    assert r.exit_code == 2  # a quoted word list is one argument, not a shell-quoted string
    r = run("explore", "nielsen -p k_s=5", "merl:nickel", "--no-browser")
    assert r.exit_code == 0, r.output
    assert calls[-1]["models"][0]["params"] == {"k_s": 5.0}
    plain = run("explore", "ward", "merl:nickel", "--no-browser")
    assert plain.exit_code == 0 and calls[-1]["models"] is None  # the short #m= state
    two = run("explore", "ward", "lambert", "-p", "rho_d=0.5", "--no-browser")
    assert two.exit_code == 2 and "describe one MODEL; got 2" in two.output
    bad = run("explore", "ward", "-p", "nope=1", "--no-browser")
    assert bad.exit_code == 2 and bad.output.startswith("brdfkit: error:")
