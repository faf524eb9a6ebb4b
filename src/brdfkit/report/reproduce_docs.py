"""
The documentation's generated parts, from the report's records
==============================================================

The figure sections of ``docs/rendering.md`` and ``docs/energy.md`` hold blocks between
``<!-- reproduce:figure NAME -->`` and ``<!-- reproduce:end -->`` written here from the
same records as ``brdfkit reproduce``'s report: the figure's entry of
:data:`~brdfkit.report.reproduce_items.FIGURE_INFO` (the paper's caption, what was chosen,
the remake command) and the verdicts of the ledger's claims about it
(:data:`FIGURE_CLAIMS`, computed now). ``docs/fitting-study.md`` is written whole by
:func:`brdfkit.report.fit_study.write_report` from the shipped batches. So no verdict in
these files is typed by hand; ``scripts/reproduce_docs.py`` rewrites them and
``tests/test_reproduce_docs.py`` checks the committed files equal what the records give.

Public objects
--------------
- :data:`FIGURE_CLAIMS`, :func:`figure_block`, :func:`update_text`, :func:`generated_docs`.
"""

from __future__ import annotations

import os
import re

from brdfkit.report.claim_record import Context, evaluate
from brdfkit.report.reproduce_items import FIGURE_INFO

__all__ = ["DOCS", "FIGURE_CLAIMS", "figure_block", "generated_docs", "update_text"]

#: figure → the ledger's claims about what it shows (their verdicts go under it).
FIGURE_CLAIMS = {
    "lewis-fig4": ("lewis-3.4-nn-minnaert-2pct",),
    "nielsen-fig1": ("nielsen-fig1a-silver-phong", "nielsen-fig1c-nickel-blinn"),
}
#: the documents with generated figure blocks (relative to the repository root).
DOCS = ("docs/rendering.md", "docs/energy.md")

_BLOCK = re.compile(r"<!-- reproduce:figure (?P<name>[a-z0-9-]+) -->\n.*?<!-- reproduce:end -->",
                    re.S)


def figure_block(name: str, *, study_dir: str) -> str:
    """The Markdown of one figure's block (the markers included)."""
    from brdfkit.report.claims import claim

    info = FIGURE_INFO[name]
    lines = [f"<!-- reproduce:figure {name} -->",
             f"![{name}: {info.caption}](figures/{name}.png)", "",
             f"**`{name}`** — *the paper:* {info.caption} *Chosen where the paper gives no "
             f"value:* {info.chosen} *Remake:* `brdfkit figure {name} --out "
             f"docs/figures/{name}.png`"]
    ctx = Context(study_dir=study_dir)
    for cid in FIGURE_CLAIMS.get(name, ()):
        rec = evaluate(claim(cid), ctx)
        lines += ["", f"- {rec['location']} — *{rec['statement']}* **{rec['verdict']}**: "
                  f"{rec['reason']} (ledger: `{cid}`)"]
    lines.append("<!-- reproduce:end -->")
    return "\n".join(lines)


def update_text(text: str, *, study_dir: str) -> str:
    """*text* with every generated figure block rewritten."""
    return _BLOCK.sub(lambda m: figure_block(m.group("name"), study_dir=study_dir), text)


def generated_docs(root: str, *, study_dir: str, fitting_out: str | None = None,
                   figures: str | None = None) -> dict[str, str]:
    """path → the text the records give: the figure-block documents and
    ``docs/fitting-study.md`` (written to *fitting_out*, its figures to *figures*; default:
    the repository's own paths)."""
    from brdfkit.report.fit_study import write_report

    out = {}
    for rel in DOCS:
        with open(os.path.join(root, rel), encoding="utf-8") as fh:
            out[rel] = update_text(fh.read(), study_dir=study_dir)
    target = fitting_out or os.path.join(root, "docs", "fitting-study.md")
    here = os.getcwd()
    try:  # the report names the batch directory relative to the working directory
        os.chdir(root)
        write_report(os.path.relpath(study_dir, root), out=os.path.abspath(target),
                     figures=os.path.abspath(figures or os.path.join(root, "docs", "figures",
                                                                     "study")))
    finally:
        os.chdir(here)
    with open(target, encoding="utf-8") as fh:
        out["docs/fitting-study.md"] = fh.read()
    return out
