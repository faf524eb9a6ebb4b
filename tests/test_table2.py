"""Lewis's Table 2, regenerated: the six printed rows by computation, plus notes."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from brdfkit.analysis.lewis_table2 import LEWIS_ROWS, format_markdown, format_table, table2
from brdfkit.cli import main

LEWIS_MODELS = [r[1] for r in LEWIS_ROWS]


@pytest.fixture(scope="module")
def rows():
    return table2(models=[*LEWIS_MODELS, "ward", "cook-torrance"])


def test_lewis_rows_reproduced(rows):
    """Every Lewis row agrees with the computation (Phong: diverges & non-reciprocal;
    energy-conserving Phong: conserves, non-reciprocal; the others bounded & reciprocal;
    Neumann-Neumann and Minnaert peak at the normal). Reasons: test_plausibility.py."""
    by = {r["model"]: r for r in rows if r["paper"].get("source") == "Lewis 1993 Table 2"}
    assert set(by) == set(LEWIS_MODELS)
    for shader, name, energy, recip, _ in LEWIS_ROWS:
        r = by[name]
        assert r["agrees_with_paper"], (shader, r["notes"])
        assert (r["energy"] == "diverges") == (energy == "no")
        assert r["reciprocal"] == (recip == "yes")


def test_cook_torrance_disagreement_is_explained(rows):
    ct = next(r for r in rows if r["model"] == "cook-torrance")
    assert ct["agrees_with_paper"] is False
    assert any("critical region" in n and "2(N.H)(N.L)/(L.H)" in n for n in ct["notes"])
    ward = next(r for r in rows if r["model"] == "ward")
    assert ward["agrees_with_paper"] and ward["energy"] == "diverges"


def test_formats(rows):
    t = format_table(rows)
    assert "phong [Lewis: Phong]" in t and "Notes" in t
    md = format_markdown(rows)
    assert md.splitlines()[0].startswith("| model |")


def test_cli_table2_json_subset():
    r = CliRunner().invoke(main, ["table2", "--json", "minnaert"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.output)
    assert d[0]["model"] == "minnaert" and d[0]["agrees_with_paper"] is True


def test_cli_table2_exclusive_flags():
    r = CliRunner().invoke(main, ["table2", "--json", "--markdown", "lambert"])
    assert r.exit_code == 2
