"""Rewrite the documentation's generated parts from the report's records (issue 24).

    PYTHONPATH=src python scripts/reproduce_docs.py [--check]

The figure blocks of docs/rendering.md and docs/energy.md (``<!-- reproduce:figure NAME
-->``) and the whole of docs/fitting-study.md (from the shipped batches in
docs/fitting-study-data/) are written by ``brdfkit.report.reproduce_docs``. ``--check``
writes nothing and exits 1 when a committed file differs from what the records give.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile

from brdfkit.report.reproduce_docs import DOCS, generated_docs

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--check", action="store_true", help="compare only; exit 1 on a difference")
    a = ap.parse_args(argv)
    study = os.path.join(ROOT, "docs", "fitting-study-data")
    with tempfile.TemporaryDirectory() as tmp:
        texts = generated_docs(ROOT, study_dir=study,
                               fitting_out=os.path.join(tmp, "fitting-study.md") if a.check
                               else None,
                               figures=os.path.join(tmp, "figures", "study") if a.check
                               else None)
    stale = []
    for rel, text in texts.items():
        path = os.path.join(ROOT, rel)
        with open(path, encoding="utf-8") as fh:
            old = fh.read()
        if old != text:
            stale.append(rel)
            if not a.check and rel in DOCS:
                with open(path, "w", encoding="utf-8") as fh:
                    fh.write(text)
    if a.check:
        print("stale: " + ", ".join(stale) if stale else "docs are what the records give")
        return 1 if stale else 0
    print("rewritten: " + (", ".join(stale) if stale else "nothing (up to date)"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
