"""Every command of the README, and per registered model an ``eval`` and an ``albedo``
command, plus pumped ones, timed from fresh processes once the cache is warm (issue 18).

Each command runs in a new process (the console script, as a user types it) in one
scratch directory (so the README's ``export … --out phong.binary`` is there for the
``eval phong.binary`` after it): first once to warm the caches (Numba's and brdfkit's
generated loops, the pumping tables), then ``--repeat`` times; the table gives the median
of the warm runs and passes a command at ≤ ``--limit`` seconds (3 s, the issue's
criterion).

Not timed, with the reason printed (jobs, not answers; the criterion is for commands
that answer): the server ``explore``; ``table2`` (the plausibility verdict of every
registered model, minutes); figures other than ``figure list`` (image jobs, seconds to
minutes; ``neumann-fig8`` ~3 min of Mitsuba); the database fit ``--to merl:all`` (100
materials); Monte-Carlo renders ``--engine mitsuba``; the set-up line. ``--all`` times
them too (except ``explore`` and the set-up).

Usage::

    PYTHONPATH=src python benchmarks/bench_readme.py [--repeat 3] [--limit 3] [--all]
        [--only SUBSTRING] [--brdfkit PATH]
"""

from __future__ import annotations

import argparse
import os
import re
import shlex
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: (pattern, reason) of README commands that are jobs rather than answers.
EXCLUDED = (
    (r"^explore\b", "a server: it never answers, it serves"),
    (r"^table2\b", "Table 2: every registered model's full verdict (minutes)"),
    (r"^figure (?!list\b)", "a figure: an image job (seconds to minutes)"),
    (r"--to merl:all\b", "a database fit: 100 materials (a batch job)"),
    (r"--engine mitsuba\b", "a Monte-Carlo render (a job)"),
)
ALWAYS_EXCLUDED = (r"^explore\b", r"setup\.sh")


def readme_commands(path: Path) -> list[str]:
    """The ``brdfkit …`` command lines of the README's code blocks (continuations joined,
    comments and the ``.venv/bin/`` prefix dropped), in order."""
    out, block, pending = [], False, ""
    for raw in path.read_text().splitlines():
        line = raw.rstrip()
        if line.startswith("```"):
            block = not block
            continue
        if not block:
            continue
        line = pending + line.strip()
        pending = ""
        if line.endswith("\\"):
            pending = line[:-1] + " "
            continue
        m = re.search(r"(?:^|&& |\.venv/bin/)brdfkit (.*)$", line)
        if m and "setup.sh" not in line:
            words = shlex.split(m.group(1), comments=True)
            out.append(shlex.join(words))
    return out


def model_commands() -> list[str]:
    """Per registered model an eval and an albedo command; pumped ones (max, controlled ×2)."""
    from brdfkit.models import MODELS  # noqa: PLC0415 - only for the names

    out = []
    for name in MODELS:
        out.append(f"eval {name} --wi 30,0 --wo 30,180 --json")
        out.append(f"albedo {name} --theta 0,45,80 --json")
    out += ["eval modified-phong -p n=200 --pump max --wi 30,0 --wo 30,180 --json",
            "eval microfacet -p alpha=0.2 --pump max --wi 60,0 --wo 45,180 --json",
            "albedo modified-blinn-phong -p n=50 --pump controlled --times 2 --theta 0,60 --json"]
    return out


def _excluded(cmd: str, timed_all: bool) -> str | None:
    for pattern, reason in EXCLUDED:
        if re.search(pattern, cmd) and (not timed_all or pattern in ALWAYS_EXCLUDED):
            return reason
    return None


def _run(exe: str, cmd: str, cwd: str, env: dict) -> tuple[float, int, str]:
    t = time.perf_counter()
    p = subprocess.run([exe, *shlex.split(cmd)], cwd=cwd, env=env, capture_output=True,
                       text=True, timeout=1800)
    return time.perf_counter() - t, p.returncode, (p.stderr or p.stdout).strip()[-200:]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="warm runs per command (median)")
    ap.add_argument("--limit", type=float, default=3.0, help="pass at or below (seconds)")
    ap.add_argument("--all", action="store_true", help="time the long jobs too")
    ap.add_argument("--only", default="", help="only commands containing this text")
    ap.add_argument("--brdfkit", default=str(Path(sys.executable).with_name("brdfkit")),
                    help="the console script to run")
    args = ap.parse_args(argv)
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT / "src") + os.pathsep + env.get("PYTHONPATH", "")
    commands = readme_commands(ROOT / "README.md") + model_commands()
    commands = [c for c in dict.fromkeys(commands) if args.only in c]
    rows, skipped = [], []
    with tempfile.TemporaryDirectory(prefix="bench_readme_") as cwd:
        for cmd in commands:
            reason = _excluded(cmd, args.all)
            if reason:
                skipped.append((cmd, reason))
                continue
            first, rc, err = _run(args.brdfkit, cmd, cwd, env)  # warms the caches
            warm = [_run(args.brdfkit, cmd, cwd, env) for _ in range(args.repeat)]
            t = statistics.median(w[0] for w in warm)
            rc = rc or max(w[1] for w in warm)
            ok = rc == 0 and t <= args.limit
            rows.append((cmd, first, t, rc, ok, err if rc else ""))
            print(f"{'PASS' if ok else 'FAIL'} {t:6.2f} s (first {first:6.2f} s) "
                  f"rc={rc}  brdfkit {cmd}" + (f"\n      {err}" if rc else ""), flush=True)
    width = max((len(r[0]) for r in rows), default=10)
    print(f"\n{'command':<{width + 8}}  first s  warm s (median of {args.repeat})  result")
    for cmd, first, t, rc, ok, _ in rows:
        result = "pass" if ok else (f"fail (exit {rc})" if rc else "fail (slow)")
        print(f"brdfkit {cmd:<{width}}  {first:7.2f}  {t:7.2f}  {result}")
    for cmd, reason in skipped:
        print(f"not timed: brdfkit {cmd}  — {reason}")
    n_fail = sum(not r[4] for r in rows)
    print(f"\n{len(rows) - n_fail}/{len(rows)} commands answer in <= {args.limit:g} s warm; "
          f"{len(skipped)} not timed")
    return 1 if n_fail else 0


if __name__ == "__main__":
    sys.exit(main())
