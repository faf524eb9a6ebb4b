"""Figures: registry, PNG/SVG output (atomic), CLI, and the albedo command's formats."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

from brdfkit.cli import main
from brdfkit.cli.analysis import parse_theta
from brdfkit.errors import BrdfkitError
from brdfkit.figures import FIGURES, figure_names, save_figure


def test_registry_has_paper_figures():
    for name in ("lewis-fig5", "lewis-fig7", "lewis-fig8", "lewis-fig9", "neumann-fig1"):
        assert name in FIGURES


@pytest.mark.parametrize("name", ["lewis-fig5", "lewis-fig9"])
@pytest.mark.parametrize("ext", ["png", "svg"])
def test_save_figure(tmp_path, name, ext):
    out = tmp_path / f"{name}.{ext}"
    save_figure(name, str(out))
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" if ext == "png" else b"<svg" in data[:2000]
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".brdfkit-")]


def test_figure_labels_and_caption():
    fig = FIGURES["lewis-fig8"]()
    ax = fig.axes[0]
    assert "theta" in ax.get_xlabel() and ax.get_ylabel()
    assert ax.get_legend() is not None
    assert any("Lewis (1993) Fig. 8" in t.get_text() for t in fig.texts)


def test_cli_figure_errors(tmp_path):
    r = CliRunner().invoke(main, ["figure", "nope", "--out", str(tmp_path / "x.png")])
    assert r.exit_code == 2 and "valid names" in r.output
    r = CliRunner().invoke(main, ["figure", "lewis-fig9", "--out", str(tmp_path / "x.pdf")])
    assert r.exit_code == 2
    # options of the Monte-Carlo figures are refused, naming them, before any work
    r = CliRunner().invoke(main, ["figure", "lewis-fig9", "--spp", "4", "--out",
                                  str(tmp_path / "x.png")])
    assert r.exit_code == 2 and "has no option spp" in r.output and "neumann-fig8" in r.output
    assert not (tmp_path / "x.png").exists()


def test_parse_theta():
    assert np.allclose(parse_theta("0:89.9:90"), np.linspace(0, 89.9, 90))
    assert np.allclose(parse_theta("0,30, 60"), [0, 30, 60])
    for bad in ("0:90", "a,b", "0:95:3", "-1", ""):
        with pytest.raises(BrdfkitError):
            parse_theta(bad)


def test_cli_albedo_json_and_csv(tmp_path):
    r = CliRunner().invoke(main, ["albedo", "lambert", "-p", "rho_d=0.4", "--theta", "0,60",
                                  "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.output)
    assert d["theta_deg"] == [0.0, 60.0] and np.allclose(d["albedo"], 0.4)  # closed form ρ_d
    assert set(d) >= {"model", "params", "theta_deg", "albedo", "error"}
    plot = tmp_path / "a.png"
    r = CliRunner().invoke(main, ["albedo", "lambert", "-p", "rho_d=0.1,0.2,0.3", "--theta",
                                  "0:60:3", "--csv", "--plot", str(plot)])
    assert r.exit_code == 0, r.output
    lines = r.output.strip().splitlines()
    assert lines[0].startswith("theta_deg,albedo_0,albedo_1,albedo_2") and len(lines) == 4
    assert plot.read_bytes()[:4] == b"\x89PNG"


def test_figure_names_sorted():
    assert figure_names() == sorted(figure_names())
