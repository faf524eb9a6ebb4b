"""Bad and edge inputs of the command line (issue 8, "Also fix"), one test per defect.

The promise under test (package docstring of :mod:`brdfkit.cli`): every error —
brdfkit's own or one that click detects while parsing — is exactly one line
``brdfkit: error: <message>`` on stderr with exit status 2, and never a
traceback. Reference values: the direction vector of THETA,PHI is
(sin θ cos φ, sin θ sin φ, cos θ) by the definition of the local frame (normal
+z); "0 below the horizon" is the package convention (:mod:`brdfkit`).
"""

from __future__ import annotations

import ast
import json
import math
import os
import pathlib
import signal
import subprocess
import sys
import textwrap
import time

import click
import numpy as np
import pytest
from click.testing import CliRunner

import brdfkit
import brdfkit.pumping
from brdfkit._array import as_directions, as_uniform
from brdfkit.cli import _progress, main
from brdfkit.cli._common import PUMP_MAX_TIMES, build_model, parse_direction
from brdfkit.cli.analysis import MAX_ANGLES, parse_theta
from brdfkit.errors import BrdfkitError
from brdfkit.figures import FIGURES, MODEL_FIGURES, check_output_path, save_atomic

SRC = pathlib.Path(brdfkit.__file__).resolve().parent


def run(*args: str):
    return CliRunner().invoke(main, list(args))


def assert_one_line_error(result, *fragments: str) -> str:
    """Exit status 2, exactly one line on stderr starting 'brdfkit: error:', no traceback;
    the line (each of *fragments* in it)."""
    assert result.exit_code == 2, (result.exit_code, result.output, result.stderr)
    err = result.stderr.strip().splitlines()
    assert len(err) == 1, result.stderr
    assert err[0].startswith("brdfkit: error: "), err[0]
    assert "Traceback" not in result.output + result.stderr
    assert "Usage:" not in result.output + result.stderr
    assert result.exception is None or isinstance(result.exception, SystemExit)
    for frag in fragments:
        assert frag in err[0], (frag, err[0])
    return err[0]


# --------------------------------------------------------------------------- click's own errors
@pytest.mark.parametrize(("args", "fragments"), [
    (["eval", "lambert", "--wi", "0,0"], ["Missing option", "--wo"]),
    (["eval"], ["Missing argument", "MODEL"]),
    (["eval", "lambert", "--pump", "most", "--wi", "0,0", "--wo", "0,0"],
     ["--pump", "most", "max", "controlled"]),
    (["no-such-command"], ["No such command", "no-such-command"]),
    (["eval", "lambert", "--no-such-option"], ["No such option", "--no-such-option"]),
    (["--no-such-option"], ["No such option", "--no-such-option"]),
    (["eval", "modified-phong", "--pump", "max", "--times", "0", "--wi", "0,0", "--wo", "0,0"],
     ["--times", "1 to 4", "got 0"]),
    (["eval", "modified-phong", "--pump", "max", "--times", "2.5", "--wi", "0,0", "--wo", "0,0"],
     ["--times", "2.5"]),
    (["figure", "lewis-fig5", "--out", "x.png", "--dpi", "5"], ["--dpi", "5", "30<=x<=1200"]),
    (["figure", "lewis-fig5", "--out", "x.png", "--dpi", "99999"], ["--dpi", "99999"]),
    (["figure"], ["Missing argument", "NAME"]),
    (["table2", "--json", "extra-argument"], ["extra-argument"]),
])
def test_click_usage_errors_are_one_line(args, fragments):
    assert_one_line_error(run(*args), *fragments)


def test_usage_error_points_to_the_commands_help():
    assert_one_line_error(run("albedo"), "brdfkit albedo --help")


@pytest.mark.parametrize("args", [["--help"], ["-h"], ["eval", "--help"], ["figure", "--help"],
                                  ["--version"]])
def test_help_and_version_exit_zero(args):
    r = run(*args)
    assert r.exit_code == 0, r.output
    assert r.stderr == ""
    assert ("Usage:" in r.stdout) or (brdfkit.__version__ in r.stdout)


def _brdfkit_cmd() -> list[str]:
    exe = pathlib.Path(sys.executable).parent / "brdfkit"
    return [str(exe)] if exe.exists() else [sys.executable, "-m", "brdfkit"]


def _env() -> dict:
    # the subprocess imports the brdfkit under test, also from a worktree's src/
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC.parent),
                                                      env.get("PYTHONPATH", "")]))
    return env


@pytest.mark.parametrize(("args", "fragment"), [
    (["no-such-command"], "No such command"),
    (["eval", "lambert", "--wi", "0,0"], "Missing option '--wo'"),
    (["eval", "lambert", "--pump", "most", "--wi", "0,0", "--wo", "0,0"], "--pump"),
    (["figure", "lewis-fig5", "--out", "x.png", "--dpi", "5"], "--dpi"),
])
def test_usage_errors_one_line_in_a_real_process(args, fragment):
    # A real process: what a shell user sees (click's standalone mode, real stderr).
    out = subprocess.run([sys.executable, "-m", "brdfkit", *args], capture_output=True,
                         text=True, timeout=300, env=_env())
    assert out.returncode == 2, (out.returncode, out.stderr)
    assert out.stdout == ""
    assert out.stderr.count("\n") == 1, out.stderr
    assert out.stderr.startswith("brdfkit: error: ") and fragment in out.stderr, out.stderr


def test_help_and_version_in_a_real_process():
    for args in (["--help"], ["--version"]):
        out = subprocess.run([sys.executable, "-m", "brdfkit", *args], capture_output=True,
                             text=True, timeout=300, env=_env())
        assert out.returncode == 0 and out.stderr == "", out.stderr


# --------------------------------------------------------------------------- directions
@pytest.mark.parametrize(("text", "value"), [("390,0", "390"), ("-30,0", "-30"),
                                             ("1e308,0", "1e308"), ("180.5,0", "180.5"),
                                             ("inf,0", "inf")])
def test_direction_theta_out_of_range(text, value):
    # 390 used to wrap around to 30 degrees; -30, 1e308 were accepted.
    r = run("eval", "lambert", "--wi", text, "--wo", "0,0")
    assert_one_line_error(r, "--wi", "THETA", "[0, 180]", value)
    r = run("eval", "lambert", "--wi", "0,0", "--wo", text)
    assert_one_line_error(r, "--wo", "[0, 180]", value)


@pytest.mark.parametrize("text", ["30,inf", "30,-inf", "30,nan"])
def test_direction_phi_must_be_finite(text):
    assert_one_line_error(run("eval", "lambert", "--wi", text, "--wo", "0,0"),
                          "--wi", "PHI", "finite", text.split(",")[1])


def test_direction_vectors_by_definition():
    # (sin θ cos φ, sin θ sin φ, cos θ): θ = 120°, φ = 0 → (√3/2, 0, −1/2); θ = 180° → −z;
    # the azimuth is periodic, so φ = 390° is φ = 30°.
    np.testing.assert_allclose(parse_direction("120,0"), [math.sqrt(3) / 2, 0.0, -0.5],
                               atol=1e-15)
    np.testing.assert_allclose(parse_direction("180,0"), [0.0, 0.0, -1.0], atol=1e-15)
    np.testing.assert_allclose(parse_direction("30,390"), parse_direction("30,30"), atol=1e-15)


_BELOW = (("120,0", "30,180"), ("30,0", "100,180"), ("180,0", "0,0"), ("90.001,45", "30,0"),
          ("95,0", "95,180"))


@pytest.mark.parametrize("name", list(brdfkit.MODELS))
def test_below_horizon_gives_zero_for_every_model(name):
    # The help's promise "THETA above 90 is below the horizon, the BRDF is 0 there", for the
    # directions the command line builds (one vectorised eval per model: the first eval of a
    # model compiles its kernel, which dominates the time).
    wi = np.array([parse_direction(a, "--wi") for a, _ in _BELOW])
    wo = np.array([parse_direction(b, "--wo") for _, b in _BELOW])
    value = np.asarray(brdfkit.model(name).eval(wi, wo))
    assert np.all(value == 0.0), (name, value)


def test_below_horizon_gives_zero_on_the_command_line():
    for wi, wo in _BELOW:
        r = run("eval", "modified-phong", "--wi", wi, "--wo", wo, "--json")
        assert r.exit_code == 0, r.stderr
        assert json.loads(r.stdout)["value"] == 0.0


def test_eval_help_states_the_range():
    r = run("eval", "--help")
    assert "[0, 180]" in " ".join(r.stdout.split()) and "below the horizon" in r.stdout


# --------------------------------------------------------------------------- --theta
def test_theta_count_is_bounded():
    # 0:89:1000000000000 used to end in a NumPy memory error.
    r = run("albedo", "lambert", "--theta", "0:89:1000000000000")
    assert_one_line_error(r, "--theta", str(MAX_ANGLES), "1000000000000")
    assert parse_theta(f"0:89:{MAX_ANGLES}").size == MAX_ANGLES
    with pytest.raises(BrdfkitError, match=str(MAX_ANGLES)):
        parse_theta(",".join(["1"] * (MAX_ANGLES + 1)))
    assert str(MAX_ANGLES) in " ".join(run("albedo", "--help").stdout.split())


@pytest.mark.parametrize("text", ["0,,30", "0,30,", ",0", " , "])
def test_theta_rejects_empty_items(text):
    assert_one_line_error(run("albedo", "lambert", "--theta", text), "--theta", "empty item")


@pytest.mark.parametrize("text", ["0:60:0", "0:60:-3", "0:60:2.5", "0:x:3"])
def test_theta_bad_count(text):
    assert_one_line_error(run("albedo", "lambert", "--theta", text), "--theta")


# --------------------------------------------------------------------------- --times
def test_times_without_pump_is_an_error():
    # It used to be silently ignored.
    r = run("eval", "modified-phong", "--times", "3", "--wi", "0,0", "--wo", "0,0")
    assert_one_line_error(r, "--times 3", "--pump")
    with pytest.raises(BrdfkitError, match="--pump"):
        build_model("modified-phong", [], times=2)


def test_times_is_bounded_with_its_reason():
    r = run("albedo", "modified-phong", "--pump", "controlled", "--times", "100")
    assert_one_line_error(r, "--times", f"1 to {PUMP_MAX_TIMES}", "100", "minutes on 2 cores")
    for bad in (PUMP_MAX_TIMES + 1, 0, 2.5, "x", True):
        with pytest.raises(BrdfkitError, match=f"1 to {PUMP_MAX_TIMES}"):
            build_model("modified-phong", [], pump="max", times=bad)
    assert "minutes on 2 cores" in " ".join(run("eval", "--help").stdout.split())


def test_pump_default_times_is_one():
    m = build_model("modified-phong", ["n=20", "rho_d=0"], pump="max")
    assert m.stages == ["max"]


def test_cli_times_bound_matches_pumping():
    assert PUMP_MAX_TIMES == brdfkit.pumping.MAX_TIMES


# --------------------------------------------------------------------------- output paths
def test_plot_wrong_suffix_names_plot_not_out(tmp_path):
    r = run("albedo", "lambert", "--theta", "0,30", "--plot", str(tmp_path / "a.pdf"))
    assert_one_line_error(r, "--plot", "a.pdf", ".png or .svg")
    assert "--out" not in r.stderr


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="needs Linux /proc")
def test_plot_into_proc_is_a_clean_error():
    # Used to be a traceback (mkstemp in /proc fails even for root).
    r = run("albedo", "lambert", "--theta", "0,30", "--plot", "/proc/a.png")
    assert_one_line_error(r, "--plot", "/proc/a.png")


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="needs Linux /proc")
def test_figure_out_unwritable_is_a_clean_error():
    r = run("figure", "lewis-fig5", "--out", "/proc/f.png")
    assert_one_line_error(r, "--out", "/proc/f.png")


def test_output_directory_missing_or_path_is_directory(tmp_path):
    r = run("figure", "lewis-fig5", "--out", str(tmp_path / "no" / "f.png"))
    assert_one_line_error(r, "--out", "does not exist")
    (tmp_path / "d.png").mkdir()
    r = run("albedo", "lambert", "--theta", "0", "--plot", str(tmp_path / "d.png"))
    assert_one_line_error(r, "--plot", "is a directory")


class _Fig:
    """A stand-in figure whose savefig does what the test says (no Matplotlib needed)."""

    def __init__(self, action):
        self.action = action

    def savefig(self, fh, **kwargs):
        fh.write(b"partial")
        self.action()


def _no_temp_files(directory: pathlib.Path) -> bool:
    return not [p for p in directory.iterdir() if p.name.startswith(".brdfkit-")]


def test_save_atomic_oserror_names_option_and_cleans_up(tmp_path):
    def full():
        raise OSError(28, "No space left on device")

    with pytest.raises(BrdfkitError, match=r"--out .*f\.png.*No space left"):
        save_atomic(_Fig(full), tmp_path / "f.png", option="--out")
    assert _no_temp_files(tmp_path) and not (tmp_path / "f.png").exists()


@pytest.mark.parametrize("exc", [SystemExit(143), KeyboardInterrupt()])
def test_save_atomic_removes_temp_on_exit(tmp_path, exc):
    def stop():
        raise exc

    with pytest.raises(type(exc)):
        save_atomic(_Fig(stop), tmp_path / "f.png")
    assert _no_temp_files(tmp_path) and not (tmp_path / "f.png").exists()


def test_check_output_path_api_names_path(tmp_path):
    with pytest.raises(BrdfkitError, match="path must end in .png or .svg"):
        check_output_path(tmp_path / "x.jpg")


_SLOW_WRITE = textwrap.dedent("""
    import sys, time
    import matplotlib.figure

    def slow_savefig(self, fh, **kwargs):  # a write that takes long enough to be interrupted
        fh.write(b"partial")
        fh.flush()
        print("WRITING", flush=True)
        time.sleep(120)

    matplotlib.figure.Figure.savefig = slow_savefig
    from brdfkit.cli import main
    main(sys.argv[1:], prog_name="brdfkit")
""")


def test_sigterm_during_figure_write_leaves_no_temp_file(tmp_path):
    # A real process gets SIGTERM while the atomic writer is inside savefig.
    out = tmp_path / "a.png"
    proc = subprocess.Popen([sys.executable, "-c", _SLOW_WRITE, "albedo", "lambert", "--theta",
                             "0,30", "--plot", str(out), "--json"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=_env())
    try:
        deadline = time.monotonic() + 240
        line = ""
        while "WRITING" not in line and time.monotonic() < deadline:
            line = proc.stdout.readline()
            if not line and proc.poll() is not None:
                break
        assert "WRITING" in line, proc.stderr.read()
        assert [p for p in tmp_path.iterdir() if p.name.startswith(".brdfkit-")]  # mid-write
        proc.send_signal(signal.SIGTERM)
        proc.wait(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 128 + signal.SIGTERM
    assert _no_temp_files(tmp_path) and not out.exists()


def test_sigterm_handler_is_restored_after_a_command():
    before = signal.getsignal(signal.SIGTERM)
    assert run("eval", "lambert", "--wi", "0,0", "--wo", "0,0").exit_code == 0
    assert signal.getsignal(signal.SIGTERM) is before


# --------------------------------------------------------------------------- figure command
def test_figure_list_needs_no_out():
    r = run("figure", "list")
    assert r.exit_code == 0, r.stderr
    assert r.stdout.split() == sorted([*FIGURES, *MODEL_FIGURES])


def test_figure_list_refuses_out_and_building_needs_out():
    assert_one_line_error(run("figure", "list", "--out", "-"), "figure list", "--out")
    assert_one_line_error(run("figure", "lewis-fig5"), "--out", "lewis-fig5")


# --------------------------------------------------------------------------- progress
def test_table2_progress_callback_does_not_change_rows():
    from brdfkit.analysis.lewis_table2 import table2

    calls = []
    rows = table2(models=["lambert", "minnaert"],
                  progress=lambda done, total, name: calls.append((done, total, name)))
    assert calls == [(0, 2, "lambert"), (1, 2, "minnaert"), (2, 2, "")]
    assert json.dumps(rows, default=str) == json.dumps(table2(models=["lambert", "minnaert"]),
                                                       default=str)


def test_table2_progress_on_interactive_stderr_only(monkeypatch):
    monkeypatch.setattr(_progress, "stderr_is_interactive", lambda: True)
    r = run("table2", "lambert")
    assert r.exit_code == 0
    assert "table2: 0/1 lambert" in r.stderr and r.stderr.endswith("\r")  # line erased at end
    assert "\r" not in r.stdout and "0/1" not in r.stdout  # progress never goes to stdout
    r = run("table2", "lambert", "--json")
    assert r.exit_code == 0 and r.stderr == ""  # never with --json
    json.loads(r.stdout)


def test_no_progress_when_not_interactive():
    r = run("table2", "lambert")  # CliRunner's stderr is not a terminal
    assert r.exit_code == 0 and r.stderr == ""


def test_figure_building_line_when_interactive(monkeypatch, tmp_path):
    import brdfkit.figures

    written = []
    monkeypatch.setattr(brdfkit.figures, "save_figure",
                        lambda name, path, **kw: written.append((name, path, kw)))
    monkeypatch.setattr(_progress, "stderr_is_interactive", lambda: True)
    out = str(tmp_path / "f.png")
    r = run("figure", "lewis-fig5", "--out", out)
    assert r.exit_code == 0, r.stderr
    assert r.stderr.startswith("building lewis-fig5 ...") and " done (" in r.stderr
    assert r.stdout.strip() == out
    assert written == [("lewis-fig5", out, {"dpi": 150, "option": "--out", "models": (),
                                            "options": {}})]
    # a Monte-Carlo figure gets its options and draws its own progress bar (no building line)
    written.clear()
    r = run("figure", "neumann-fig8", "--spp", "4", "--panel-size", "32", "--out", out)
    assert r.exit_code == 0, r.stderr
    assert "building" not in r.stderr
    assert written == [("neumann-fig8", out, {"dpi": 150, "option": "--out", "models": (),
                                              "options": {"spp": 4, "size": 32}})]


# --------------------------------------------------------------------------- structure
def _imports(path: pathlib.Path) -> set[str]:
    tree = ast.parse(path.read_text())
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            out.add(node.module)
            out.update(f"{node.module}.{a.name}" for a in node.names)
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
    return out


def test_figure_modules_import_downward_only():
    for name in ("lewis", "lewis_spheres", "neumann", "neumann_fig8", "pumping", "models",
                 "nielsen", "energy"):
        imported = _imports(SRC / "figures" / f"{name}.py")
        assert not {m for m in imported if m.startswith("brdfkit.figures")}, (name, imported)
    assert not {m for m in _imports(SRC / "figures" / "_save.py")
                if m.startswith("brdfkit.figures")}
    assert set(FIGURES) == {"lewis-fig3", "lewis-fig4", "lewis-fig5", "lewis-fig6",
                            "lewis-fig7", "lewis-fig8", "lewis-fig9", "lewis-fig10",
                            "neumann-fig1", "neumann-fig3", "neumann-fig4", "neumann-fig5",
                            "neumann-fig6", "neumann-fig7", "neumann-fig8", "nielsen-fig1",
                            "energy-reciprocity"}


def test_cli_command_modules_do_not_import_the_cli_package():
    for path in (SRC / "cli").glob("*.py"):
        if path.name == "__init__.py":
            continue
        bad = {m for m in _imports(path) if m in ("brdfkit.cli", "brdfkit.cli.main")}
        assert not bad, (path.name, bad)
    # through the group's own lookup: main.commands holds only the lazily registered
    # commands looked up so far in this process, so reading it depended on test order
    ctx = click.Context(main)
    assert set(main.list_commands(ctx)) == {"models", "eval", "albedo", "check", "table2",
                                            "figure", "render", "materials", "export",
                                            "explore", "fit", "verdicts", "reproduce"}
    assert set(main.get_command(ctx, "render").commands) == {"sphere"}


def test_cli_has_no_self_guarding_imports_and_one_brdfkit_error_handler():
    text = "".join(p.read_text() for p in (SRC / "cli").glob("*.py"))
    assert "except ImportError" not in text
    assert text.count("except BrdfkitError") == 1


# --------------------------------------------------------------------------- API: as_directions
@pytest.mark.parametrize(("value", "fragment"), [
    ("abc", "string"),
    (b"\x00\x00", "string"),
    ([["0", "0", "1"]], "strings"),
    ([[0, 0, 1], [0, 1]], "ragged"),
    ([0, 0, 1j], "complex"),
    ({"x": 0}, "non-numeric"),
    ([0, object(), 1], "non-numeric"),
])
def test_as_directions_raises_brdfkit_error(value, fragment):
    with pytest.raises(BrdfkitError, match=fragment) as info:
        as_directions(value, "wi")
    assert str(info.value).startswith("wi ")


def test_model_eval_with_non_numeric_input_names_the_argument():
    m = brdfkit.model("lambert")
    with pytest.raises(BrdfkitError, match="^wo "):
        m.eval([0.0, 0.0, 1.0], "up")
    with pytest.raises(BrdfkitError, match="^wi .*ragged"):
        m.eval([[0, 0, 1], [0, 1]], [0.0, 0.0, 1.0])


def test_as_directions_keeps_numeric_behaviour():
    a = np.array([[0.0, 0.0, 1.0]])
    assert as_directions(a, "wi") is a  # float64 arrays pass through, never copied or mutated
    out = as_directions([0, 0, 1], "wi")
    assert out.dtype == np.float64 and out.tolist() == [0.0, 0.0, 1.0]
    assert as_directions(np.array([0, 0, 1], np.float32), "wi").dtype == np.float64
    with pytest.raises(BrdfkitError, match=r"shape \(\.\.\., 3\)"):
        as_directions([0.0, 1.0], "wi")
    with pytest.raises(BrdfkitError, match="NaN"):
        as_directions([0.0, np.nan, 1.0], "wi")


def test_as_uniform_rejects_strings():
    with pytest.raises(BrdfkitError, match="^u "):
        as_uniform("0.5,0.5")


def test_unknown_figure_is_told_before_a_missing_out():
    # a misspelt name is the fault to fix first: asking for --out would send the user to
    # a second error after adding it
    assert_one_line_error(run("figure", "lewis-fig55"), "unknown figure 'lewis-fig55'",
                          "lewis-fig5")
    assert_one_line_error(run("figure", "lewis-fig5"), "needs --out")
