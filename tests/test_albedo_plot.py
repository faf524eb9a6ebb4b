"""`brdfkit albedo --plot` draws what a researcher would show (issue 20): a dense curve with
the asked angles marked on it, R/G/B in red/green/blue, the bound a = 1, an axis from 0,
the parameters in the title. References: the closed form a(θ) = ρ_d of a Lambertian
surface (Lewis 1993 eq. (8) with k_s = 0) and the asked values the command printed."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.colors as mcolors  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import brdfkit  # noqa: E402
from brdfkit.analysis import albedo  # noqa: E402
from brdfkit.figures.albedo import CURVE_THETA_DEG, albedo_figure  # noqa: E402


def test_rgb_albedo_figure():
    rho = [0.6, 0.3, 0.1]
    m = brdfkit.model("lambert", rho_d=rho)
    th = np.array([0.0, 45.0, 80.0])
    a = albedo(m, np.radians(th)).albedo
    fig = albedo_figure(m, th, a)
    try:
        ax = fig.axes[0]
        curves = [ln for ln in ax.lines if len(ln.get_xdata()) >= len(CURVE_THETA_DEG)]
        assert [ln.get_label() for ln in curves] == ["R", "G", "B"]
        for ln, want, r in zip(curves, ("tab:red", "tab:green", "tab:blue"), rho, strict=True):
            assert mcolors.same_color(ln.get_color(), want)
            np.testing.assert_allclose(ln.get_ydata(), r, atol=1e-5)  # a = ρ_d (closed form)
        marks = [ln for ln in ax.lines if ln.get_marker() == "o" and len(ln.get_xdata()) == 3]
        assert len(marks) == 3
        np.testing.assert_array_equal(marks[0].get_xdata(), th)
        # the bound a = 1 as a horizontal line, inside an axis that starts at 0
        assert any(np.all(np.asarray(ln.get_ydata()) == 1.0) for ln in ax.lines)
        lo, hi = ax.get_ylim()
        assert lo == 0.0 and hi > 1.0
        assert "rho_d=(0.6, 0.3, 0.1)" in ax.get_title() and "lambert" in ax.get_title()
    finally:
        plt.close(fig)


def test_the_cli_plot_is_written(tmp_path):
    from click.testing import CliRunner

    from brdfkit.cli import main

    out = tmp_path / "a.png"
    r = CliRunner().invoke(main, ["albedo", "modified-phong", "-p", "n=20", "--theta",
                                  "0,60,85", "--plot", str(out)])
    assert r.exit_code == 0, r.output
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_fit_figure_draws_f_r_and_keeps_slice_colours_apart_from_channels():
    # `fit --plot` drew f_r·cos θ_i beside `figure slices`' f_r, and θ_i = 60° in the red of
    # the R channel (issue 20). Reference: the target's own f_r at θ_i = 0, θ_o = 0 (normal
    # incidence and view: the first slice's value at its middle).
    from brdfkit.figures.fitting import SLICE_THETA_DEG, fit_figure
    from brdfkit.fitting import fit

    target = brdfkit.model("modified-phong", rho_d=[0.3, 0.2, 0.1], rho_s=0.5, n=30)
    r = fit(brdfkit.model("modified-phong"), target, strides=(15, 45))
    fig = fit_figure(r, target)
    try:
        ax, bx = fig.axes[:2]
        assert "cos" not in ax.get_ylabel() and "f_r" in ax.get_ylabel()
        first = ax.lines[0]
        x, y = np.asarray(first.get_xdata()), np.asarray(first.get_ydata())
        n = np.array([0.0, 0.0, 1.0])
        want = float(np.mean(target.eval(n, n)))
        np.testing.assert_allclose(np.interp(0.0, x, y), want, rtol=1e-3)
        slice_colours = [ln.get_color() for ln in ax.lines][:2 * len(SLICE_THETA_DEG)]
        for c in ("tab:red", "tab:green", "tab:blue"):
            assert not any(mcolors.same_color(s, c) for s in slice_colours)
        assert [ln.get_label() for ln in bx.lines][::2] == ["R measured", "G measured",
                                                            "B measured"]
    finally:
        plt.close(fig)
