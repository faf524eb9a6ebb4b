"""Wall time of the material commands of issue 23: ``check`` and ``render sphere --ambient``.

Runs, as subprocesses and one after the other in one run:

- ``brdfkit check merl:nickel``;
- ``brdfkit render sphere merl:nickel --phi-l 30 --ambient 0.5 --size 64 --out …png``;

for this tree, first **cold** (an empty store of results, ``brdfkit.analysis.stored``)
then **warm** (the same commands again: the albedo curve and the ambient table read from
disk), and, with ``--before SRC``, for another source tree (e.g. ``git archive <commit>
src | tar -x -C /tmp/before``) the same way. Compiled code is warm in every run: each run
gets its own ``BRDFKIT_CACHE_DIR`` with the ``drivers`` directory of the user's cache
linked in (so only results are cold), and one untimed ``brdfkit eval`` of the material
first. Prints a table of wall seconds and the load average.

Targets (issue 23): both ≤ 10 s from a warm cache.

Usage::

    .venv/bin/python benchmarks/bench_material_commands.py
    .venv/bin/python benchmarks/bench_material_commands.py --before /tmp/before/src
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SRC = str(Path(__file__).resolve().parents[1] / "src")
MATERIAL = "merl:nickel"


def _commands(out_png: str) -> dict[str, list[str]]:
    return {"check": ["check", MATERIAL],
            "render --ambient 0.5": ["render", "sphere", MATERIAL, "--phi-l", "30",
                                     "--ambient", "0.5", "--size", "64", "--out", out_png]}


def _run(src: str, args: list[str], cache: str) -> tuple[float, str]:
    """(wall seconds, "" or the last line of stderr when the command failed)."""
    env = {**os.environ, "PYTHONPATH": src, "BRDFKIT_CACHE_DIR": cache}
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "brdfkit", *args], env=env,
                       capture_output=True, text=True)
    seconds = time.perf_counter() - t0
    failed = "" if p.returncode == 0 else (p.stderr.strip().splitlines() or ["?"])[-1]
    return seconds, failed


def _trees(src: str, label: str, user_cache: Path, states=("cold", "warm")) -> list[tuple]:
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench-material-") as tmp:
        cache = Path(tmp) / "cache"
        cache.mkdir()
        drivers = user_cache / "drivers"
        if drivers.is_dir():
            (cache / "drivers").symlink_to(drivers)
        _run(src, ["eval", MATERIAL, "--wi", "30,0", "--wo", "30,180"], str(cache))  # warm-up
        for state in states:
            for name, args in _commands(str(Path(tmp) / "s.png")).items():
                rows.append((label, name, state, *_run(src, args, str(cache))))
                print(f"  {label} {name} {state}: {rows[-1][3]:.1f} s {rows[-1][4]}",
                      file=sys.stderr)
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--before", metavar="SRC", help="another tree's src directory to compare")
    args = ap.parse_args(argv)
    root = os.environ.get("BRDFKIT_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "brdfkit")
    print("load average (1, 5, 15 min): {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
    rows = []
    if args.before:
        # a tree before the store has no warm state: its second run costs the same
        rows += _trees(args.before, "before", Path(root), states=("cold",))
    rows += _trees(SRC, "this tree", Path(root))
    print()
    print(f"| {'tree':<10} | {'command':<22} | {'results':<7} | {'wall (s)':>8} | outcome |")
    print(f"|{'-' * 12}|{'-' * 24}|{'-' * 9}|{'-' * 10}|---------|")
    for label, name, state, seconds, failed in rows:
        print(f"| {label:<10} | {name:<22} | {state:<7} | {seconds:8.1f} | "
              f"{('failed: ' + failed) if failed else 'ok'} |")
    print()
    print("load average (1, 5, 15 min): {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
