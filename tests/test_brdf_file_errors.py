"""Bad ``.brdf`` files and bad parameters give one clear error line (issue 21, §5).

Each file of ``tests/brdf_files/bad/`` through the CLI (``brdfkit eval FILE ...`` and
``brdfkit check FILE``) and through the API (``brdfkit.model(FILE)``): exactly one line
``brdfkit: error: ...`` on stderr naming ``FILE.brdf:LINE:COL`` (a malformed parameter
line: the file and its line), exit status 2, no traceback. The positions are read off
the files here (the offending token's line and first column, 1-based); for the two
files Mesa's compiler rejects, the line is also Mesa's (test_glsl_reference.test_mesa_
rejects: Mesa's columns are approximate, its lines exact). A parameter outside its range
or an unknown name names the parameter and the valid names/range. The file that makes
NaN (nan_normalize.brdf) gives a status, never a crash or a silent 0.
"""

from __future__ import annotations

import json
import os
import pathlib
import re
import subprocess
import sys

import pytest
from click.testing import CliRunner
from glsl_reference import CORPUS
from test_cli_inputs import assert_one_line_error  # the CLI's error contract

import brdfkit
from brdfkit.cli import main
from brdfkit.errors import BrdfkitError

BAD = CORPUS / "bad"
SRC = pathlib.Path(brdfkit.__file__).resolve().parent


def _position(name: str, line: int, token: str) -> tuple:
    """(line, 1-based column of *token*'s first occurrence on that line) of a bad file."""
    text = (BAD / name).read_text().splitlines()[line - 1]
    assert token in text, (name, line, token, text)
    return line, text.index(token) + 1


def _run(*args: str):
    return CliRunner().invoke(main, list(args))


def _where(line: str, name: str):
    """(line, col) of the 'FILE.brdf:LINE:COL' the message names (col None if absent)."""
    found = re.search(re.escape(name) + r":(\d+)(?::(\d+))?", line)
    assert found, f"the message does not name {name}:LINE:COL: {line}"
    return int(found.group(1)), (int(found.group(2)) if found.group(2) else None)


# (file, accepted (line, col) positions or a column range on one line, words of the message)
# positions: the offending construct's first character, read off the file by _position
CASES = {
    # an unclosed '(': the error is between the '(' and the ';' where ')' was expected
    "syntax_error.brdf": dict(line=15, cols=("(", ";"), words=("syntax",)),
    "unknown_identifier.brdf": dict(line=14, col="roughnes", words=("roughnes",)),
    # a texture needs a sampler uniform declared in the shader (BRDF Explorer's parameter
    # block has no sampler): either is the construct to name
    "texture_lookup.brdf": dict(line=(11, 16), words=(("texture", "sampler", "uniform"),)),
    "data_dependent_loop.brdf": dict(line=16, words=("loop",)),
    # the recursive call (line 15) or the function that makes it (line 12)
    "recursion.brdf": dict(line=(12, 15), words=(("recursion", "recursive"),)),
    "out_parameter.brdf": dict(line=12, words=("out",)),
    "no_brdf_function.brdf": dict(line=None, words=("BRDF",)),
}


def _check_message(line: str, name: str, case: dict) -> None:
    at_line, at_col = _where(line, name)
    assert at_col is not None and at_col >= 1, f"no column: {line}"
    expected = case["line"]
    if isinstance(expected, tuple):
        assert at_line in expected, line
    elif expected is not None:
        assert at_line == expected, line
    if "col" in case:
        assert (at_line, at_col) == _position(name, expected, case["col"]), line
    if "cols" in case:
        lo = _position(name, expected, case["cols"][0])[1]
        hi = _position(name, expected, case["cols"][1])[1]
        assert lo <= at_col <= hi, line
    for word in case["words"]:
        options = word if isinstance(word, tuple) else (word,)
        assert any(w in line for w in options), (options, line)


@pytest.mark.parametrize("command", ["eval", "check"])
@pytest.mark.parametrize("name", sorted(CASES))
def test_bad_fileassert_one_line_error(name, command):
    extra = ["--wi", "30,0", "--wo", "30,180"] if command == "eval" else []
    line = assert_one_line_error(_run(command, str(BAD / name), *extra))
    _check_message(line, name, CASES[name])


def test_malformed_parameter_line_names_the_file_and_line():
    line = assert_one_line_error(_run("eval", str(BAD / "malformed_parameter.brdf"),
                                "--wi", "30,0", "--wo", "30,180"))
    at_line, _ = _where(line, "malformed_parameter.brdf")
    assert at_line == 7 and "ks" in line and "one" in line, line


@pytest.mark.parametrize("name", sorted(CASES) + ["malformed_parameter.brdf"])
def test_bad_file_is_a_brdfkit_error_in_the_api(name):
    with pytest.raises(BrdfkitError, match=re.escape(name) + r":\d+"):
        brdfkit.model(str(BAD / name))


def _env() -> dict:
    # the subprocess imports the brdfkit under test, also from a worktree's src/
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC.parent),
                                                      env.get("PYTHONPATH", "")]))
    return env


def test_bad_file_in_a_real_process():
    # what a shell user sees: click's standalone mode, the real stderr
    name = "unknown_identifier.brdf"
    out = subprocess.run([sys.executable, "-m", "brdfkit", "eval", str(BAD / name),
                          "--wi", "30,0", "--wo", "30,180"], capture_output=True, text=True,
                         timeout=300, env=_env())
    assert out.returncode == 2, (out.returncode, out.stderr)
    assert out.stdout == "" and out.stderr.count("\n") == 1, out.stderr
    assert out.stderr.startswith("brdfkit: error: ")
    _check_message(out.stderr.strip(), name, CASES[name])


# --------------------------------------------------------------------------- parameters
GOOD_FILE = CORPUS / "cook_torrance.brdf"   # float m in [0.05, 1], metal; colours base, F0
BOOL_FILE = CORPUS / "oren_nayar.brdf"      # float sigma, bool qualitative, colour albedo


def test_parameter_outside_its_range_names_it_and_the_range():
    line = assert_one_line_error(_run("eval", str(GOOD_FILE), "-p", "m=2",
                                "--wi", "30,0", "--wo", "30,180"))
    assert "'m'" in line and "0.05" in line and "1" in line and "2" in line, line


def test_unknown_parameter_names_it_and_lists_the_valid_names():
    line = assert_one_line_error(_run("eval", str(GOOD_FILE), "-p", "nosuch=1",
                                "--wi", "30,0", "--wo", "30,180"))
    assert "nosuch" in line, line
    for valid in ("m", "metal", "base", "F0"):
        assert re.search(rf"\b{valid}\b", line.split("nosuch", 1)[1]), (valid, line)


@pytest.mark.parametrize("value", ["maybe", "2", "0.5"])
def test_bad_bool_value_names_the_parameter(value):
    line = assert_one_line_error(_run("eval", str(BOOL_FILE), "-p", f"qualitative={value}",
                                "--wi", "30,0", "--wo", "30,180"))
    assert "qualitative" in line and value in line, line


@pytest.mark.parametrize("value", ["true", "false", "1", "0"])
def test_bool_words_are_accepted(value):
    r = _run("eval", str(BOOL_FILE), "-p", f"qualitative={value}", "--wi", "30,0",
             "--wo", "30,180", "--json")
    assert r.exit_code == 0, r.output + r.stderr
    assert len(json.loads(r.stdout)["value"]) == 3  # a colour parameter: 3 channels


def test_unknown_parameter_in_the_api():
    with pytest.raises(BrdfkitError, match="nosuch") as info:
        brdfkit.model(str(GOOD_FILE), nosuch=1.0)
    for valid in ("metal", "base", "F0"):
        assert valid in str(info.value)


# --------------------------------------------------------------------------- NaN: a status
NAN_FILE = CORPUS / "nan_normalize.brdf"


def test_nan_file_albedo_reports_a_nonfinite_status():
    from brdfkit.analysis.albedo_engine import CONVERGED, NONFINITE

    r = _run("albedo", str(NAN_FILE), "--theta", "0,30", "--json")
    assert r.exit_code == 0, r.output + r.stderr
    assert "Traceback" not in r.output + r.stderr
    d = json.loads(r.stdout)
    assert d["albedo"][0] is None and d["albedo"][1] > 0.0  # NaN → null, never 0
    assert d["status"] == [NONFINITE, CONVERGED]
    assert "NaN" in d["message"]


def test_nan_file_albedo_text_output_warns():
    r = _run("albedo", str(NAN_FILE), "--theta", "0,30")
    assert r.exit_code == 0, r.output + r.stderr
    assert "Traceback" not in r.output + r.stderr
    assert r.stderr.startswith("brdfkit: warning: ") and "NaN" in r.stderr, r.stderr


def test_nan_file_eval_is_nan_not_zero():
    # at normal incidence the formula is NaN: JSON null (strict JSON has no NaN), exit 0
    r = _run("eval", str(NAN_FILE), "--wi", "0,0", "--wo", "30,90", "--json")
    assert r.exit_code == 0, r.output + r.stderr
    assert json.loads(r.stdout)["value"] is None
