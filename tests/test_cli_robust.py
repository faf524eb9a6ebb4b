"""Issue 19 part C, "Robust under a stranger's hands": runaway memory within advertised
limits, and tracebacks or wrong messages made one-line errors. One test per case of the
issue; each failed before the change it covers (the reason is stated where it is not
plain: e.g. "before: a NumPy broadcast error", "before: exit 0 and inf in the file").

Reference values come from outside the code under test: the closed-form normal albedo 1
of a smooth GGX conductor without Fresnel (∫ D(h) (h·n) dω_h = 1, masking → 1 as α → 0);
float32's largest value (IEEE 754); Mitsuba's 32-bit seeds (its ``sample_tea_32``); the
shell's 128 + signal convention for exit statuses; the MERL grid's smallest θ_d, θ_h bin
centres (Matusik et al. 2003: θ_h = ((i + ½)/90)² · 90°, θ_d = j + ½ degrees).
"""

from __future__ import annotations

import math
import os
import pathlib
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest
from click.testing import CliRunner
from test_cli import assert_one_line_error as one_line_error

import brdfkit
import brdfkit.pumping
from brdfkit.cli import main
from brdfkit.errors import BrdfkitError, ParameterError

SRC = pathlib.Path(brdfkit.__file__).resolve().parent


def run(*args: str):
    return CliRunner().invoke(main, list(args))




def _env() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC.parent),
                                                      env.get("PYTHONPATH", "")]))
    return env


# ======================================================================= runaway memory
def test_pump_times_bound_is_four_everywhere():
    """`--times 4` took 36-140 s and `--times 5` ~155 s+ for the controlled modified-phong
    (measured, pumping.MAX_TIMES); the bound is 4, declared once (pumping.MAX_TIMES) and
    the same in pump(), ModelSpec and the CLI. Before: 8 ('about a minute', which did not
    finish in 200 s)."""
    from brdfkit.pumping import pump
    from brdfkit.spec import MAX_TIMES

    assert brdfkit.pumping.MAX_TIMES == MAX_TIMES == 4
    with pytest.raises(ParameterError, match="MAX_TIMES = 4 .*got times = 5"):
        pump(brdfkit.model("modified-phong"), "controlled", times=5)
    line = one_line_error(run("eval", "modified-phong", "--pump", "controlled", "--times",
                              "5", "--wi", "0,0", "--wo", "0,0"), "--times", "1 to 4")
    assert "times=4 takes 1-2.5 minutes" in line
    assert "1 to 4" in " ".join(run("eval", "--help").stdout.split())


def test_channel_count_is_capped():
    """`render sphere lambert -p rho_d=<20000 values>` took > 4 GB; now refused at once."""
    from brdfkit.models._param import MAX_CHANNELS

    values = ",".join(["0.5"] * (MAX_CHANNELS + 1))
    t0 = time.perf_counter()
    one_line_error(run("render", "sphere", "lambert", "-p", f"rho_d={values}", "--phi-l", "0",
                       "--out", "x.npy"), "rho_d", f"MAX_CHANNELS = {MAX_CHANNELS}",
                   str(MAX_CHANNELS + 1))
    assert time.perf_counter() - t0 < 30  # nothing rendered
    with pytest.raises(ParameterError, match="at most MAX_CHANNELS"):
        brdfkit.model("lambert", rho_d=np.full(20000, 0.5))
    assert brdfkit.model("lambert", rho_d=np.full(MAX_CHANNELS, 0.5)).n_channels == MAX_CHANNELS


def test_direct_render_values_are_bounded():
    """Pixels x channels above MAX_RENDER_VALUES are refused before any allocation; an
    RGB image of the largest size (the advertised limit) is within the bound."""
    from brdfkit.render import MAX_SIZE, render_sphere
    from brdfkit.render.sphere import MAX_RENDER_VALUES

    assert MAX_SIZE**2 * 3 <= MAX_RENDER_VALUES
    m = brdfkit.model("lambert", rho_d=[0.1, 0.2, 0.3, 0.4, 0.5])
    with pytest.raises(ParameterError, match="MAX_RENDER_VALUES") as info:
        render_sphere(m, phi_l=0.0, size=MAX_SIZE)
    limit = math.isqrt(MAX_RENDER_VALUES // 5)
    assert f"at most {limit}" in str(info.value)
    assert limit**2 * 5 <= MAX_RENDER_VALUES < (limit + 1) ** 2 * 5


@pytest.fixture(scope="module")
def mi():
    mitsuba = pytest.importorskip("mitsuba")
    from brdfkit.render.mitsuba_bridge import use_variant

    use_variant("llvm_ad_rgb")
    return mitsuba


def test_mitsuba_render_is_split_into_bounded_calls(mi, monkeypatch):
    """`--engine mitsuba --spp 65536 --size 16` took > 5 GB: Mitsuba traces every path of
    a call at once. Each call now has at most max(MAX_LANES, pixels) paths and the image
    is the sample-weighted mean of the calls' images. Before: one call of all the spp of
    a pass (here 32 x 64 = 2048 paths > 256)."""
    import brdfkit.render.mitsuba_bridge as bridge
    from brdfkit.render.mitsuba_sphere import render_sphere_mitsuba

    monkeypatch.setattr(bridge, "MAX_LANES", 256, raising=False)
    calls = []
    real = mi.render

    def recording(scene, spp, seed):
        image = np.array(real(scene, spp=spp, seed=seed), dtype=np.float64)
        calls.append((spp, seed, image))
        return image

    monkeypatch.setattr(mi, "render", recording)
    m = brdfkit.model("lambert", rho_d=0.5)
    img = render_sphere_mitsuba(m, phi_l=0.3, size=8, spp=32, seed=7)
    assert calls and all(n * 64 <= 256 for n, _, _ in calls), [c[:2] for c in calls]
    assert sum(n for n, _, _ in calls) == 32
    assert len({s for _, s, _ in calls}) == len(calls)  # distinct seeds
    weighted = sum(n * image for n, _, image in calls) / 32
    np.testing.assert_allclose(img, weighted.reshape(img.shape), rtol=1e-12, atol=0)


@pytest.mark.parametrize(("args", "fragments"), [
    # the old engine error "sample_count should be a multiple of samples_per_wavefront"
    (["--size", "4096", "--spp", "65536"], ["--size 4096", "at most 2048"]),
    (["--size", "256", "--spp", "65536"], ["2^30", "16384"]),
    # before: TypeError from Mitsuba's sample_tea_32
    (["--seed", "99999999999999999999"], ["--seed", "4294967295"]),
    (["--seed", "-1"], ["--seed", "4294967295"]),
])
def test_mitsuba_render_limits_are_one_line_errors(args, fragments):
    one_line_error(run("render", "sphere", "lambert", "--phi-l", "30", "--engine", "mitsuba",
                       *args, "--out", "x.npy"), *fragments)


def test_mitsuba_seed_range_in_the_api():
    """Mitsuba's seeds are 32-bit: 2^32 - 1 is the largest accepted, 2^32 is refused with
    the range (before: a TypeError from sample_tea_32)."""
    from brdfkit.render.mitsuba_bridge import check_seed
    from brdfkit.render.tank import check_render_options

    assert check_seed(2**32 - 1) == 2**32 - 1
    for bad in (2**32, 99999999999999999999, -1, 1.5, True):
        with pytest.raises(ParameterError, match="0 to 4294967295"):
            check_seed(bad)
        with pytest.raises(ParameterError, match="seed must be an integer from 0 to"):
            check_render_options(size=64, spp=4, seed=bad)


@pytest.mark.parametrize(("args", "fragments"), [
    (["--seed", "99999999999999999999"], ["seed", "4294967295"]),
    # 2048 x 1536 px x 4096 spp = 1.3e10 samples per render (> 5 GB and days before)
    (["--spp", "4096", "--panel-size", "2048"], ["2^30", "341"]),
])
def test_figure_fig8_limits_are_one_line_errors(tmp_path, args, fragments):
    out = tmp_path / "f.png"
    one_line_error(run("figure", "neumann-fig8", *args, "--out", str(out)), *fragments)
    assert not out.exists()


def test_size_help_states_the_mitsuba_limit():
    text = " ".join(run("render", "sphere", "--help").stdout.split())
    assert "1 to 8192 (direct" in text and "1 to 2048 (mitsuba)" in text
    assert "samples/s" in text  # the cost of --spp


def test_mitsuba_log_goes_to_stderr():
    """Mitsuba's WARN lines went to stdout (its StreamAppender), mixed with --json output."""
    pytest.importorskip("mitsuba")
    code = textwrap.dedent("""
        from brdfkit.render.mitsuba_variants import import_mitsuba
        mi, _ = import_mitsuba()
        mi.set_variant("scalar_rgb")
        mi.Log(mi.LogLevel.Warn, "probe-line")
        print("stdout-done")
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300, env=_env())
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "stdout-done"
    assert "probe-line" in out.stderr and "WARN" in out.stderr


# ======================================================================= render outputs
def test_exr_refuses_values_beyond_float32(tmp_path):
    """`render … --ambient 1e300 --out x.exr` wrote inf (float32 overflow, with a raw
    RuntimeWarning). Reference: IEEE float32 max 3.4028235e38."""
    out = tmp_path / "a.exr"
    with _no_warnings():
        line = one_line_error(run("render", "sphere", "lambert", "--phi-l", "30", "--size", "8",
                                  "--ambient", "1e300", "--out", str(out)), "--out", "3.40282e+38")
    assert "RuntimeWarning" not in line and not out.exists()
    assert not [p for p in tmp_path.iterdir()]  # no temp file either
    from brdfkit.render.image import write_exr

    write_exr(tmp_path / "ok.exr", np.full((2, 2, 1), 3.4e38))  # just representable
    with pytest.raises(BrdfkitError, match="EXR 32-bit float"):
        write_exr(tmp_path / "no.exr", np.full((2, 2, 1), 3.5e38))


class _no_warnings:
    """Turn every warning into an error inside the block."""

    def __enter__(self):
        import warnings

        self._cm = warnings.catch_warnings()
        self._cm.__enter__()
        warnings.simplefilter("error")

    def __exit__(self, *exc):
        return self._cm.__exit__(*exc)


def test_non_finite_render_is_refused(tmp_path):
    """E f_r cos beyond float64: the one pixel of a 1 x 1 image has N = V = L (Φ_L = 0),
    where modified-phong n = 50 is ρ_d/π + ρ_s (n + 2)/2π = 0.2/π + 0.5·52/2π ≈ 4.2/sr,
    times E = 1e308 → inf. Before: exit 0 and inf in the .npy."""
    out = tmp_path / "a.npy"
    one_line_error(run("render", "sphere", "modified-phong", "-p", "n=50", "--phi-l", "0",
                       "--size", "1", "--antialias", "1",  # the centre only: N = V = L
                       "--irradiance", "1e308", "--out", str(out)),
                   "not finite", "--irradiance")
    assert not out.exists()


# ======================================================================= export
def test_export_warns_when_the_grid_loses_the_lobe(tmp_path):
    """`export microfacet -p alpha=1e-8` wrote a table whose normal albedo is 0 where the
    model's is 1 (closed form for a smooth conductor without Fresnel), silently. Now one
    warning line; a lobe the grid represents (alpha = 0.3) gives none."""
    out = tmp_path / "thin.binary"
    r = run("export", "microfacet", "-p", "alpha=1e-8", "--out", str(out))
    assert r.exit_code == 0, r.stderr
    err = r.stderr.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("brdfkit: warning: "), r.stderr
    assert "0 in the file vs 1 of the model" in err[0] and "1e-08 rad" in err[0]
    assert out.exists()  # written, with the warning
    r = run("export", "microfacet", "-p", "alpha=0.3", "--out", str(tmp_path / "wide.binary"))
    assert r.exit_code == 0 and r.stderr == "", r.stderr


# ======================================================================= files
def test_symlink_loop_is_not_no_such_file(tmp_path):
    from brdfkit.data.merl import read_binary

    a, b = tmp_path / "a.binary", tmp_path / "b.binary"
    a.symlink_to(b)
    b.symlink_to(a)
    line = one_line_error(run("eval", str(a), "--wi", "0,0", "--wo", "0,0"), str(a))
    assert "no such file" not in line and "symbolic links" in line
    with pytest.raises(BrdfkitError, match="symbolic links"):
        read_binary(a)
    dangling = tmp_path / "d.binary"
    dangling.symlink_to(tmp_path / "missing.binary")
    with pytest.raises(BrdfkitError, match="symbolic link to a missing file"):
        read_binary(dangling)


# ======================================================================= signals
_SLOW = textwrap.dedent("""
    import sys, time
    import brdfkit.cli.model_commands as mc

    def slow(text, option="--wi"):  # a command that takes long enough to be stopped
        print("READY", flush=True)
        time.sleep(120)

    mc.parse_direction = slow
    from brdfkit.cli import main
    main(sys.argv[1:], prog_name="brdfkit")
""")


@pytest.mark.parametrize(("sig", "status", "word"), [
    (signal.SIGTERM, 143, "terminated"),  # before: exit 143, nothing said
    (signal.SIGINT, 130, "interrupted"),  # before: click's "Aborted!", exit 1
])
def test_signal_is_one_line(sig, status, word):
    proc = subprocess.Popen([sys.executable, "-c", _SLOW, "eval", "lambert", "--wi", "0,0",
                             "--wo", "0,0"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=_env())
    try:
        line = proc.stdout.readline()
        assert "READY" in line, proc.stderr.read()
        proc.send_signal(sig)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == status
    assert err == f"brdfkit: {word}\n", err


def test_batch_interrupt_is_one_line(tmp_path, monkeypatch):
    """Ctrl-C in a batch: 'brdfkit: interrupted: ...' naming the file, status 130 (before:
    'brdfkit: error: interrupted ...', status 2)."""
    import brdfkit.fitting.batch as batch

    def ctrl_c(job):
        raise KeyboardInterrupt  # as if Ctrl-C arrived during the first fit

    monkeypatch.setattr(batch, "fit_row", ctrl_c)
    out = tmp_path / "fits.csv"
    r = run("fit", "lambert", "--to", "merl:nickel", "--to", "merl:gold-paint", "--out", str(out))
    assert r.exit_code == 130, (r.exit_code, r.stderr)
    err = r.stderr.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("brdfkit: interrupted: "), r.stderr
    assert str(out) in err[0] and "Aborted" not in r.stderr


# ======================================================================= API: parameters
def test_parameter_too_large_for_a_float():
    """brdfkit.model('lambert', rho_d=10**400) raised OverflowError."""
    with pytest.raises(ParameterError, match="rho_d.*too large for a float"):
        brdfkit.model("lambert", rho_d=10**400)


def test_parameter_none_is_named_not_nan():
    with pytest.raises(ParameterError) as info:
        brdfkit.model("lambert", rho_d=None)
    assert "got None" in str(info.value) and "nan" not in str(info.value)
    assert brdfkit.model("microfacet", eta=None).values["eta"] is None  # optional: allowed


# ======================================================================= fit: API
@pytest.fixture(scope="module")
def rgb_target():
    return brdfkit.model("lambert", rho_d=[0.2, 0.4, 0.6])


@pytest.mark.parametrize(("kwargs", "fragment"), [
    ({"seed": -1}, "seed must be an integer >= 0"),  # before: NumPy ValueError
    ({"seed": 1.5}, "seed must be an integer >= 0"),  # before: TypeError (SeedSequence)
    ({"fixed": [1, 2]}, "fixed must be a dict"),  # before: TypeError from dict()
    ({"strides": "ab"}, "strides must be two integers"),  # before: int('a') ValueError
    ({"theta_max": 0.01}, "leaves no sample pair"),  # before: reshape ValueError
    ({"progress": 5}, "progress must be None or a callable"),  # before: 'int' not callable
    ({"max_evals": 0}, "max_evals must be an integer >= 1"),  # before: silently raised
    ({"max_evals": -5}, "max_evals must be an integer >= 1"),
])
def test_fit_arguments_are_checked(rgb_target, kwargs, fragment):
    from brdfkit.fitting import fit

    with pytest.raises(ParameterError, match=fragment):
        fit(brdfkit.model("lambert"), rgb_target, **kwargs)


def test_fit_theta_max_names_the_smallest_that_works(rgb_target):
    """MERL grid, strides (9, 15): the pair nearest the normal has θ_h = ((½)/90)²·90° =
    0.0028°, θ_d = 4.5° (the middle of the first 9-bin θ_d cell); its larger polar angle is
    ≈ 4.5°, so θ_max = 1° leaves nothing and the message asks for at least ~4.5°."""
    from brdfkit.fitting import fit

    with pytest.raises(ParameterError, match=r"at least 4\.50\d* deg") as info:
        fit(brdfkit.model("lambert"), rgb_target, theta_max=math.radians(1.0))
    least = float(str(info.value).split("at least ")[1].split(" deg")[0])
    r = fit(brdfkit.model("lambert"), rgb_target, theta_max=math.radians(least), n_starts=1)
    assert r.convergence["n_samples"] >= 1


def test_fit_channel_count_is_named(rgb_target):
    """A 2-channel model against an RGB target: before, a NumPy broadcast error."""
    from brdfkit.fitting import fit

    with pytest.raises(ParameterError, match="2 colour channels .* target has 3"):
        fit(brdfkit.model("lambert", rho_d=[0.1, 0.2]), rgb_target)


# ======================================================================= fit: CLI
@pytest.mark.parametrize(("args", "fragments"), [
    (["--start", "rho_d=0.1,0.2"], ["2 colour channels", "has 3"]),
    (["-p", "rho_d=0.1,0.2"], ["2 colour channels", "has 3"]),  # before: "refused by the model"
    (["--theta-max", "1"], ["no sample pair", "at least"]),  # before: reshape traceback
    (["--seed", "-1"], ["--seed", "-1"]),  # before: NumPy ValueError traceback
])
def test_fit_cli_inputs_are_one_line_errors(args, fragments):
    one_line_error(run("fit", "lambert", "--to", "merl:nickel", *args), *fragments)
