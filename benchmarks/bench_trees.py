"""Run one benchmark script against two source trees, alternating, in one run.

A refactor's "no slowdown" is measured this way: the same script, the same machine, the
same minute, the two trees taking turns (``before, after, before, after, ...``) so that a
change of load hits both. Each run is a fresh process whose ``PYTHONPATH`` puts that tree's
``src`` first (the venv's editable install is overridden); the script's own table is
printed for every run, labelled.

    git worktree add /tmp/before <commit>
    .venv/bin/python benchmarks/bench_trees.py --before /tmp/before --after . \\
        --rounds 2 -- bench_fit.py --repeats 5

A relative script path is taken from each tree's own ``benchmarks/`` (a script may reach
into the internals it times, which a refactor moves); an absolute one is used for both.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path


def _run(tree: Path, script: Path, args: list[str]) -> tuple[str, float, int]:
    env = dict(os.environ, PYTHONPATH=str(tree / "src"))
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, str(script), *args], env=env, cwd=tree,
                          capture_output=True, text=True)
    return proc.stdout + proc.stderr, time.perf_counter() - t0, proc.returncode


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", type=Path, required=True, help="the source tree before")
    ap.add_argument("--after", type=Path, required=True, help="the source tree after")
    ap.add_argument("--rounds", type=int, default=2, help="alternations (>= 1)")
    ap.add_argument("script", help="benchmark script (relative: in each tree's benchmarks/)")
    ap.add_argument("args", nargs=argparse.REMAINDER, help="the script's arguments")
    ns = ap.parse_args(argv)
    if ns.rounds < 1:
        ap.error(f"--rounds must be >= 1; got {ns.rounds}")
    trees = {"before": ns.before.resolve(), "after": ns.after.resolve()}
    for label, tree in trees.items():
        if not (tree / "src" / "brdfkit").is_dir():
            ap.error(f"--{label} {tree}: no src/brdfkit there")
    script = Path(ns.script)
    args = [a for a in ns.args if a != "--"]
    status = 0
    for k in range(ns.rounds):
        for label, tree in trees.items():
            path = script if script.is_absolute() else tree / "benchmarks" / script
            out, dt, rc = _run(tree, path, args)
            print(f"===== round {k + 1}, {label} ({tree}), {dt:.1f} s, exit {rc}")
            print(out.rstrip())
            status = status or rc
    return status


if __name__ == "__main__":
    sys.exit(main())
