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
