"""The documentation's generated parts equal what the report's records give (issue 24):
the figure blocks of docs/rendering.md and docs/energy.md and the whole of
docs/fitting-study.md (from the shipped batches). A hand edit of a verdict there, or a
record changed without `scripts/reproduce_docs.py`, fails here."""

from __future__ import annotations

from pathlib import Path

from brdfkit.report.reproduce_docs import DOCS, FIGURE_CLAIMS, generated_docs, update_text

ROOT = Path(__file__).resolve().parents[1]


def test_committed_docs_are_what_the_records_give(tmp_path):
    texts = generated_docs(str(ROOT), study_dir=str(ROOT / "docs" / "fitting-study-data"),
                           fitting_out=str(tmp_path / "fitting-study.md"),
                           figures=str(tmp_path / "figures" / "study"))
    assert set(texts) == {*DOCS, "docs/fitting-study.md"}
    stale = [rel for rel, text in texts.items()
             if (ROOT / rel).read_text(encoding="utf-8") != text]
    assert stale == [], "run: PYTHONPATH=src python scripts/reproduce_docs.py"


def test_every_figure_with_claims_has_its_block_and_an_edit_is_undone():
    text = (ROOT / "docs" / "rendering.md").read_text(encoding="utf-8")
    for name in FIGURE_CLAIMS:
        assert f"<!-- reproduce:figure {name} -->" in text
    # a verdict typed over by hand is replaced by the computed one
    edited = text.replace("**refuted**", "**confirmed**", 1)
    assert edited != text
    assert update_text(edited, study_dir=str(ROOT / "docs" / "fitting-study-data")) == text
