"""Print (or write into README.md) the Markdown table of registered models.

    .venv/bin/python scripts/model_table.py           # print the table
    .venv/bin/python scripts/model_table.py --write   # replace the block in README.md

The table sits between ``<!-- models:start -->`` and ``<!-- models:end -->``
in README.md; it is generated from :data:`brdfkit.MODELS`, so it never needs
editing by hand.
"""

from __future__ import annotations

import pathlib
import sys

import brdfkit

START, END = "<!-- models:start -->", "<!-- models:end -->"


def table() -> str:
    rows = ["| model | aliases | reciprocal | sampler | paper / equation |",
            "|---|---|---|---|---|"]
    for cls in brdfkit.MODELS.values():
        rows.append(f"| `{cls.name}` | {', '.join(cls.aliases) or '-'} | "
                    f"{'yes' if cls.reciprocal else 'no'} | {'yes' if cls.has_sampler else '-'} | "
                    f"{cls.citation} |")
    return "\n".join(rows)


def main() -> int:
    text = table()
    if "--write" not in sys.argv[1:]:
        print(text)
        return 0
    readme = pathlib.Path(__file__).resolve().parent.parent / "README.md"
    s = readme.read_text()
    if START not in s or END not in s:
        print(f"model_table.py: markers {START} / {END} not found in {readme}", file=sys.stderr)
        return 1
    head, rest = s.split(START, 1)
    _, tail = rest.split(END, 1)
    readme.write_text(f"{head}{START}\n{text}\n{END}{tail}")
    print(f"model_table.py: wrote {len(brdfkit.MODELS)} models into {readme}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
