"""The ``brdfkit`` command line: models, eval and the error paths.

Reference values are computed here by hand from the closed forms (Lambert
ρ_d/π; Nielsen eq. (1) ρ_d/π + ρ_s (n+2)/(2π) (R·V)ⁿ with R·V worked out for
the chosen angles), not copied from the program's output.
"""

from __future__ import annotations

import json
import math
import pathlib
import subprocess
import sys

import numpy as np
import pytest
from click.testing import CliRunner

import brdfkit
from brdfkit.cli import main
from brdfkit.cli._common import build_model, parse_direction, parse_param_items, to_jsonable
from brdfkit.errors import BrdfkitError, ParameterError


def run(*args: str):
    return CliRunner().invoke(main, list(args))


def assert_one_line_error(result, *fragments: str) -> str:
    """Exit status 2, exactly one line on stderr starting 'brdfkit: error:', no traceback;
    returns that line."""
    assert result.exit_code == 2, (result.exit_code, result.output, result.stderr)
    err = result.stderr.strip().splitlines()
    assert len(err) == 1, result.stderr
    assert err[0].startswith("brdfkit: error: "), err[0]
    assert "Traceback" not in result.output + result.stderr
    assert result.exception is None or isinstance(result.exception, SystemExit)
    for frag in fragments:
        assert frag in err[0], (frag, err[0])
    return err[0]


# --------------------------------------------------------------------------- models
def test_models_json_lists_every_registered_model():
    result = run("models", "--json")
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert [d["name"] for d in data] == list(brdfkit.MODELS)
    for d in data:
        cls = brdfkit.MODELS[d["name"]]
        assert d["reciprocal"] is cls.reciprocal
        assert d["has_sampler"] is cls.has_sampler
        assert d["citation"] == cls.citation
        assert [p["name"] for p in d["params"]] == [p.name for p in cls.params]
        for p in d["params"]:
            assert {"default", "unit", "kind"} <= set(p)
            assert ("choices" in p) or ("bounds" in p)


def test_models_human_table_names_every_model_and_parameter():
    result = run("models")
    assert result.exit_code == 0
    for cls in brdfkit.MODELS.values():
        assert cls.name in result.stdout
        assert cls.citation in result.stdout
        for p in cls.params:
            assert p.name in result.stdout


# --------------------------------------------------------------------------- eval
def eval_json(*args: str):
    result = run("eval", *args, "--json")
    assert result.exit_code == 0, (result.output, result.stderr)
    return json.loads(result.stdout)


def test_eval_lambert_is_rho_over_pi():
    # Closed form: Lambert is ρ_d/π for every pair above the horizon.
    d = eval_json("lambert", "-p", "rho_d=0.6", "--wi", "10,20", "--wo", "70,250")
    assert d["model"] == "lambert"
    assert d["params"] == {"rho_d": 0.6}
    assert d["value"] == pytest.approx(0.6 / math.pi, rel=1e-14)


def test_eval_modified_phong_by_hand():
    # wi at θ=30°, φ=0; wo at θ=60°, φ=180° (plane of incidence, opposite side).
    # Mirror of wi: R = (−sin30, 0, cos30). wo = (−sin60, 0, cos60).
    # R·V = sin30 sin60 + cos30 cos60 = cos(60° − 30°) = cos 30° = √3/2.
    rd, rs, n = 0.25, 0.5, 8.0
    rv = math.sqrt(3.0) / 2.0
    expected = rd / math.pi + rs * (n + 2.0) / (2.0 * math.pi) * rv**n
    d = eval_json("modified-phong", "-p", f"rho_d={rd}", "-p", f"rho_s={rs}", "-p", f"n={n}",
                  "--wi", "30,0", "--wo", "60,180")
    assert d["value"] == pytest.approx(expected, rel=1e-12)
    # ... and the API, given the same directions, agrees.
    m = brdfkit.model("modified-phong", rho_d=rd, rho_s=rs, n=n)
    wi = [math.sin(math.pi / 6), 0.0, math.cos(math.pi / 6)]
    wo = [-math.sin(math.pi / 3), 0.0, math.cos(math.pi / 3)]
    assert d["value"] == pytest.approx(float(m.eval(wi, wo)), rel=1e-12)


def test_eval_colour_gives_one_value_per_channel():
    # Mirror configuration (R·V = 1): f = ρ_d/π + ρ_s (n+2)/2π per channel.
    rd, rs, n = [0.1, 0.2, 0.3], [0.5, 0.4, 0.3], 4.0
    d = eval_json("modified-phong", "-p", "rho_d=0.1,0.2,0.3", "-p", "rho_s=0.5,0.4,0.3",
                  "-p", "n=4", "--wi", "40,90", "--wo", "40,270")
    expected = [a / math.pi + b * (n + 2) / (2 * math.pi) for a, b in zip(rd, rs, strict=True)]
    assert d["value"] == pytest.approx(expected, rel=1e-12)
    assert d["params"]["rho_d"] == rd


def test_eval_plain_output_is_the_number():
    result = run("eval", "lambert", "-p", "rho_d=0.5", "--wi", "0,0", "--wo", "45,0")
    assert result.exit_code == 0
    assert float(result.stdout) == pytest.approx(0.5 / math.pi, rel=1e-15)


def test_eval_below_horizon_is_zero():
    d = eval_json("lambert", "--wi", "95,0", "--wo", "30,0")
    assert d["value"] == 0.0


def test_eval_beta_is_in_degrees():
    # β = 60° gives cosⁿ60° = 1/2, i.e. n = 1 (Lewis §3.1 half-angle definition).
    d = eval_json("modified-phong", "-p", "beta=60", "--wi", "0,0", "--wo", "0,0")
    assert d["params"]["n"] == pytest.approx(1.0, rel=1e-12)


def test_eval_choice_parameter():
    d = eval_json("microfacet", "-p", "distribution=ggx", "--wi", "20,0", "--wo", "20,180")
    assert d["params"]["distribution"] == "ggx"
    m = brdfkit.model("microfacet", distribution="ggx")
    wi = parse_direction("20,0")
    wo = parse_direction("20,180")
    assert d["value"] == pytest.approx(float(m.eval(wi, wo)), rel=1e-12)


def test_python_dash_m_and_installed_script_agree():
    # One real subprocess: the installed entry point (or `python -m brdfkit`).
    exe = pathlib.Path(sys.executable).parent / "brdfkit"
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "brdfkit"]
    out = subprocess.run([*cmd, "eval", "lambert", "-p", "rho_d=0.3", "--wi", "0,0",
                          "--wo", "0,0", "--json"], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout)["value"] == pytest.approx(0.3 / math.pi, rel=1e-15)
    bad = subprocess.run([*cmd, "eval", "no-such-model", "--wi", "0,0", "--wo", "0,0"],
                         capture_output=True, text=True, timeout=300)
    assert bad.returncode == 2
    assert bad.stderr.count("\n") == 1 and "Traceback" not in bad.stderr
    assert "lambert" in bad.stderr  # the valid names are listed


# --------------------------------------------------------------------------- error paths
def test_unknown_model_lists_valid_names():
    result = run("eval", "no-such-model", "--wi", "0,0", "--wo", "0,0")
    assert_one_line_error(result, "no-such-model", *brdfkit.MODELS)


def test_parameter_out_of_bounds_names_parameter_bounds_and_value():
    result = run("eval", "modified-phong", "-p", "rho_s=1.5", "--wi", "0,0", "--wo", "0,0")
    assert_one_line_error(result, "rho_s", "[0, 1]", "1.5")


def test_parameter_not_a_number():
    result = run("eval", "modified-phong", "-p", "n=lots", "--wi", "0,0", "--wo", "0,0")
    assert_one_line_error(result, "'n'", "lots")


def test_unknown_parameter_lists_valid_ones():
    result = run("eval", "lambert", "-p", "shininess=3", "--wi", "0,0", "--wo", "0,0")
    assert_one_line_error(result, "shininess", "rho_d")


def test_parameter_without_equals():
    result = run("eval", "lambert", "-p", "rho_d", "--wi", "0,0", "--wo", "0,0")
    assert_one_line_error(result, "NAME=VALUE")


def test_bad_choice():
    result = run("eval", "microfacet", "-p", "distribution=gauss", "--wi", "0,0", "--wo", "0,0")
    assert_one_line_error(result, "distribution", "beckmann", "ggx", "gauss")


def test_beta_out_of_range_in_degrees():
    result = run("eval", "modified-phong", "-p", "beta=95", "--wi", "0,0", "--wo", "0,0")
    assert_one_line_error(result, "beta", "(0, 90)", "95")


@pytest.mark.parametrize("text", ["30", "30,0,1", "a,b", "30;0", "nan,0", ""])
def test_malformed_direction(text):
    result = run("eval", "lambert", "--wi", text, "--wo", "0,0")
    assert_one_line_error(result, "--wi", "THETA,PHI")


def test_pump_flag_is_reported_when_unavailable_or_works():
    result = run("eval", "modified-phong", "--pump", "max", "--wi", "0,0", "--wo", "0,0")
    try:
        import brdfkit.pumping  # noqa: F401
    except ImportError:
        assert_one_line_error(result, "pumping is not available")
    else:
        assert result.exit_code == 0, result.stderr


# --------------------------------------------------------------------------- helpers
def test_parse_param_items_types():
    kw = parse_param_items("microfacet", ["distribution=ggx", "eta=none", "k=1,2,3",
                                          "alpha=0.25"])
    assert kw == {"distribution": "ggx", "eta": None, "k": [1.0, 2.0, 3.0], "alpha": 0.25}
    with pytest.raises(ParameterError, match="given twice"):
        parse_param_items("lambert", ["rho_d=0.1", "rho_d=0.2"])


def test_parse_param_items_scalar_param_rejects_list():
    # 'n' is a scalar parameter of modified-phong: a list is parsed as one number and fails.
    with pytest.raises(ParameterError, match="'n'"):
        parse_param_items("modified-phong", ["n=1,2"])


def test_build_model_returns_model():
    m = build_model("nielsen-phong", ["n=5"])
    assert m.name == "modified-phong" and m.values["n"] == 5.0


def test_parse_direction_values():
    np.testing.assert_allclose(parse_direction("90,90"), [0.0, 1.0, 0.0], atol=1e-15)
    with pytest.raises(BrdfkitError):
        parse_direction("1,2,3")


def test_to_jsonable_nan_and_numpy():
    out = to_jsonable({"a": np.array([1.0, np.nan]), "b": np.float32(2), "c": np.int64(3),
                       "d": (np.inf,), "e": np.bool_(True)})
    assert out == {"a": [1.0, None], "b": 2.0, "c": 3, "d": [None], "e": True}
    json.dumps(out, allow_nan=False)


# --------------------------------------------------------------------------- README
def test_readme_model_table_is_current():
    # The README's model table is generated from the registry; regenerate it with
    # `.venv/bin/python scripts/model_table.py --write` after adding a model.
    root = pathlib.Path(__file__).resolve().parent.parent
    readme = (root / "README.md").read_text()
    block = readme.split("<!-- models:start -->", 1)[1].split("<!-- models:end -->", 1)[0]
    listed = [line.split("`")[1] for line in block.splitlines() if line.startswith("| `")]
    assert listed == list(brdfkit.MODELS), "run scripts/model_table.py --write"


def test_readme_commands_are_marked():
    # .ci/run executes the block after <!-- cmd:test -->; the main job follows <!-- cmd:main -->.
    root = pathlib.Path(__file__).resolve().parent.parent
    readme = (root / "README.md").read_text()
    for marker, needle in (("<!-- cmd:main -->", "bash scripts/setup.sh && .venv/bin/brdfkit "),
                           ("<!-- cmd:test -->", "bash scripts/setup.sh --test && ")):
        after = readme.split(marker, 1)[1].lstrip()
        assert after.startswith("```bash\n"), marker
        assert after.split("\n")[1].startswith(needle), after.split("\n")[1]


def test_models_takes_a_name_and_shows_parameter_docs_under_a_header():
    # issue 20: `brdfkit models ward` was an error (while `materials SPEC` filters) and the
    # text output had no header and omitted the parameter docs that --json has
    r = run("models", "ward")
    assert r.exit_code == 0, r.output
    lines = r.output.splitlines()
    assert lines[0].startswith("ward  (aliases: ")
    header = next(ln for ln in lines if ln.strip().startswith("parameter"))
    assert header.split() == ["parameter", "default", "bounds", "unit", "meaning"]
    docs = {p["name"]: p["doc"] for p in brdfkit.MODELS["ward"].describe()["params"]}
    for name, doc in docs.items():
        assert any(ln.split()[:1] == [name] and ln.rstrip().endswith(doc) for ln in lines), name
    assert run("models", "ward92").output == r.output  # an alias names the same model
    bad = run("models", "wardd")
    assert bad.exit_code == 2 and "did you mean 'ward'" in bad.output
    mat = run("models", "merl:nickel")
    assert mat.exit_code == 2 and "brdfkit materials" in mat.output
    # every model's table has the header too
    every = run("models").output
    assert every.count("parameter  ") >= len(brdfkit.MODELS) - 1
