"""Every shell block of the README and of docs/*.md runs as printed (issue 20).

Each ```` ```bash ````/``sh``/``shell``/``console`` block runs under ``bash -e -o pipefail``
in an empty directory holding links to the repository's ``tests/``, ``benchmarks/``,
``scripts/`` and ``src/`` (the files the blocks read) and an empty ``docs/figures/`` (where
some blocks write); ``.venv/bin/brdfkit`` and ``.venv/bin/python`` there, and ``brdfkit`` on
PATH, run this interpreter with this checkout's source. A block is one test (xdist spreads
them); each block is self-contained, its lines run in order. A block that cannot run in CI
(it installs .venv, serves until Ctrl-C, takes many minutes) is preceded by a visible
``<!-- not run in CI: REASON -->`` comment, which must give its reason; there are few.
docs/your-own-model.md runs whole in tests/test_your_own_model_guide.py. Outputs the
docs print beside a command are checked where they are closed forms (below).
"""

from __future__ import annotations

import json
import os
import pathlib
import re
import subprocess
import sys

import pytest
from test_your_own_model_guide import blocks

ROOT = pathlib.Path(__file__).resolve().parents[1]
SHELLS = ("bash", "sh", "shell", "console")
NOT_RUN = re.compile(r"<!-- not run in CI:(.*?)-->")
#: Most blocks not run (each with its reason): setup x2, explore x2, the full verdicts
#: table, the full fitting study, the shipped figures.
MAX_NOT_RUN = 7
#: Seconds one block may take (the slowest, README's fits, take ~20 s alone on 2 cores).
TIMEOUT_S = 300
DOCS = ["README.md", *sorted(str(p.relative_to(ROOT)) for p in ROOT.glob("docs/*.md")
                             if p.name != "your-own-model.md")]


def shell_blocks(name: str) -> list[tuple[int, str, str | None]]:
    """(index, body, not-run reason or None) of the shell blocks of *name*, in order."""
    text = (ROOT / name).read_text(encoding="utf-8")
    out, lines, k = [], text.splitlines(), 0
    fences = [i for i, line in enumerate(lines) if line.startswith("```")
              and line[3:].split()[:1] and line[3:].split()[0] in SHELLS]
    bodies = [b for lang, _, b in blocks(text) if lang in SHELLS]
    assert len(fences) == len(bodies), name
    for i, body in zip(fences, bodies, strict=True):
        j = i - 1  # the comments just above the fence (blank lines and other markers skipped)
        reason = None
        while j >= 0 and (not lines[j].strip() or lines[j].startswith("<!--")):
            m = NOT_RUN.search(lines[j])
            if m:
                reason = m.group(1).strip()
                assert reason, f"{name} line {j + 1}: 'not run in CI' needs a reason"
            j -= 1
        out.append((k, body, reason))
        k += 1
    return out


CASES = [(name, k) for name in DOCS for k, _, reason in shell_blocks(name) if reason is None]


def test_few_blocks_are_not_run_and_each_says_why():
    skipped = [(n, k, r) for n in DOCS for k, _, r in shell_blocks(n) if r is not None]
    assert len(skipped) <= MAX_NOT_RUN, skipped
    assert all(len(r.split()) >= 2 for *_, r in skipped), skipped
    assert len(CASES) >= 12  # the README's commands are run, not marked away


def _sandbox(tmp: pathlib.Path) -> dict:
    for d in ("tests", "benchmarks", "scripts", "src"):
        (tmp / d).symlink_to(ROOT / d)
    (tmp / "docs" / "figures").mkdir(parents=True)
    bin_ = tmp / ".venv" / "bin"
    bin_.mkdir(parents=True)
    for name, line in (("brdfkit", f'exec "{sys.executable}" -m brdfkit "$@"'),
                       ("python", f'exec "{sys.executable}" "$@"')):
        (bin_ / name).write_text(f"#!/bin/sh\n{line}\n")
        (bin_ / name).chmod(0o755)
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT / "src") + os.pathsep + env.get("PYTHONPATH", "")
    env["PATH"] = str(bin_) + os.pathsep + env["PATH"]
    return env


#: The blocks run in CI (xdist spreads them): 5 min 12 s with -n 2 while the rest of the
#: suite ran beside them (load ~4); the README prints fast forms of its long commands
#: (table2 of two models, one verdicts row, a two-target fit batch, neumann-fig8 small).


@pytest.mark.parametrize("name, k", CASES, ids=[f"{n}#{k}" for n, k in CASES])
def test_shell_block_runs_as_printed(name, k, tmp_path):
    body = shell_blocks(name)[k][1]
    env = _sandbox(tmp_path)
    r = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", body], cwd=tmp_path, env=env,
                       capture_output=True, text=True, timeout=TIMEOUT_S)
    assert r.returncode == 0, f"{name} shell block {k}:\n{body}\n--- stderr:\n{r.stderr[-3000:]}"
    assert "Traceback" not in r.stderr, r.stderr[-3000:]
    check = CHECKS.get((name, body.splitlines()[0]))
    if check:
        check(r.stdout, tmp_path)


def _pumped_albedo(out, tmp):
    # README: "the pumped albedo is at most 1" (Neumann et al. 1999 eq. 17: a* <= 1)
    d = json.loads(out)
    assert max(d["albedo"]) <= 1.0 + 1e-9


def _compensated_furnace(out, tmp):
    # README: the Kulla-Conty compensated white GGX (F = 1) conserves energy: a(theta) = 1
    rows = [line.split() for line in out.splitlines() if not line.startswith("#")]
    assert rows and all(abs(float(r[1]) - 1.0) < 1e-4 for r in rows), out


CHECKS = {
    ("README.md", ".venv/bin/brdfkit albedo modified-phong -p n=20 -p rho_d=0 --pump "
                  "controlled --times 2 --json"): _pumped_albedo,
    ("README.md", ".venv/bin/brdfkit albedo microfacet -p distribution=ggx -p alpha=1 "
                  "--compensate kulla-conty"): _compensated_furnace,
}


def test_the_checks_name_blocks_that_exist():
    firsts = {(n, b.splitlines()[0]) for n in DOCS for _, b, _ in shell_blocks(n)}
    assert set(CHECKS) <= firsts
