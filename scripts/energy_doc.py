"""Rewrite the computed part of docs/energy.md: the energy table and its findings.

    .venv/bin/python scripts/energy_doc.py            # ~1.5 min on the 2-core machine

Runs :func:`brdfkit.report.energy_table.energy_table` once (what ``brdfkit verdicts
--markdown`` prints) and replaces the text between ``<!-- verdicts:begin -->`` and
``<!-- verdicts:end -->`` in ``docs/energy.md`` with the table, its notes and the
findings, and the line after ``<!-- verdicts:time -->`` with the run's wall time. The
prose around them is written by hand from these numbers.
"""

from __future__ import annotations

import pathlib
import re
import sys
import time

from brdfkit.report.energy_findings import findings, format_findings
from brdfkit.report.energy_table import energy_table, format_markdown

DOC = pathlib.Path(__file__).resolve().parents[1] / "docs" / "energy.md"
BEGIN, END, TIME = "<!-- verdicts:begin -->", "<!-- verdicts:end -->", "<!-- verdicts:time -->"


def main() -> int:
    text = DOC.read_text()
    if BEGIN not in text or END not in text or TIME not in text:
        print(f"{DOC}: the markers {BEGIN}, {END} and {TIME} are missing", file=sys.stderr)
        return 2
    t = time.perf_counter()
    rows = energy_table(progress=lambda k, n, what: print(f"\r{k}/{n} {what:60s}",
                                                          end="", file=sys.stderr))
    seconds = time.perf_counter() - t
    print(file=sys.stderr)
    body = (f"{format_markdown(rows)}\n\n**Findings, computed** "
            f"(`brdfkit.report.energy_findings`):\n\n{format_findings(findings(rows))}\n")
    text = re.sub(re.escape(BEGIN) + ".*?" + re.escape(END),
                  lambda m: f"{BEGIN}\n{body}{END}", text, flags=re.S)
    text = re.sub(re.escape(TIME) + r"\n[^\n]*",
                  lambda m: f"{TIME}\nComputed in {seconds:.0f} s (this run).", text)
    DOC.write_text(text)
    print(f"{DOC}: {len(rows)} rows, {seconds:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
