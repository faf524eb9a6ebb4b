"""Time of the README's main command, ``brdfkit reproduce`` (issue 24).

Targets on the 2-core machine: the report part ≤ 4 min with a fresh result cache, a
re-run ≤ 30 s; the whole main command on a fresh clone (installation, compiles and the
report) ≤ 7 min.

- ``report`` — ``brdfkit reproduce --out TMP --jobs 2`` in a fresh process with an empty
  result cache (``BRDFKIT_CACHE_DIR`` pointed at a new directory for the result cache;
  Numba's disk cache of the compiled loops stays where it is, so this is the report of a
  set-up machine), then the same command again (everything from the cache).
- ``--clone`` — also the whole main command on a fresh ``git clone`` of this repository
  (``bash scripts/setup.sh && .venv/bin/brdfkit reproduce --out report``: pip downloads,
  Numba compiles in a new cache, the report), with its own empty caches.

The machine is shared: the load average is printed before and after each run, and a
timing made under load is pessimistic.

Usage::

    .venv/bin/python benchmarks/bench_reproduce.py [--clone] [--jobs 2]
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: Issue 24: report part (fresh result cache), re-run, whole main command on a fresh clone.
TARGETS = {"report (fresh result cache)": 240.0, "re-run (cached)": 30.0,
           "main command on a fresh clone": 420.0}


def _load() -> str:
    return " ".join(f"{x:.1f}" for x in os.getloadavg())


def _timed(cmd, *, cwd, env) -> tuple[float, int, str]:
    t = time.perf_counter()
    p = subprocess.run(cmd, cwd=cwd, env=env, shell=isinstance(cmd, str),
                       capture_output=True, text=True)
    return time.perf_counter() - t, p.returncode, (p.stdout + p.stderr).strip().splitlines()[-1:]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--clone", action="store_true", help="also time a fresh clone")
    a = ap.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench-reproduce-") as tmp:
        env = dict(os.environ)
        env["PYTHONPATH"] = str(ROOT / "src") + os.pathsep + env.get("PYTHONPATH", "")
        # a new result cache; the drivers' Numba cache is the machine's (set up)
        drivers = Path(os.environ.get("BRDFKIT_CACHE_DIR") or
                       Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
                       / "brdfkit")
        cache = Path(tmp) / "cache"
        cache.mkdir()
        if (drivers / "drivers").is_dir():
            (cache / "drivers").symlink_to(drivers / "drivers")
        env["BRDFKIT_CACHE_DIR"] = str(cache)
        cmd = [sys.executable, "-m", "brdfkit", "reproduce", "--out", str(Path(tmp) / "r"),
               "--jobs", str(a.jobs)]
        for label in ("report (fresh result cache)", "re-run (cached)"):
            before = _load()
            sec, code, last = _timed(cmd, cwd=ROOT, env=env)
            rows.append((label, sec, code, before, _load(), last))
        if a.clone:
            clone = Path(tmp) / "clone"
            subprocess.run(["git", "clone", "-q", str(ROOT), str(clone)], check=True)
            cenv = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
            cenv["BRDFKIT_CACHE_DIR"] = str(Path(tmp) / "clone-cache")
            before = _load()
            sec, code, last = _timed("bash scripts/setup.sh && .venv/bin/brdfkit reproduce "
                                     "--out report", cwd=clone, env=cenv)
            rows.append(("main command on a fresh clone", sec, code, before, _load(), last))
            shutil.rmtree(clone, ignore_errors=True)
    print(f"{'what':32s} {'seconds':>8s} {'target':>7s} {'ok':>3s} {'exit':>4s}  load before "
          "-> after")
    for label, sec, code, before, after, last in rows:
        target = TARGETS[label]
        print(f"{label:32s} {sec:8.1f} {target:7.0f} {'yes' if sec <= target else 'NO':>3s} "
              f"{code:4d}  {before} -> {after}")
        if last:
            print(f"{'':32s} {last[0]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
